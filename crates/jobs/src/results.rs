//! What one command wrote, read back as the input of another: `analyze`'s `areas.csv`
//! ([`read_areas_csv`] for `friction`, [`read_measured`] with the intervals for
//! `fit-hardening`), a `simulate` output folder's contact maps ([`simulated_maps`], for
//! `compare`) and the FWHM in `psf`'s `psf.json` ([`fwhm_from_psf_json`]).

use std::path::Path;

use serde_json::Value;

use super::table::Table;
use crate::error::{Error, Location, Result};
use contactscope::analysis::bootstrap::calibration_bounds;
use contactscope::compare::SimulatedMap;
use contactscope::model_fit::Measured;
use contactscope::optics::blur::Grid;
use contactscope_formats::ranges::Quantity;
use contactscope_formats::tiff::read_image;
use contactscope_formats::tiff::write::quantity;

/// (force N, area m²) rows of an `analyze` areas.csv (columns `force_mN` or `force_N`, and
/// `area_um2`); a table in pixels is refused with a hint, as is one without rows. Rows at 0 N
/// (reference frames recorded before loading) are left out.
pub fn read_areas_csv(path: &Path) -> Result<Vec<(f64, f64)>> {
    Ok(read_area_rows(&Table::read(path)?, path)?
        .into_iter()
        .map(|(_, f, a)| (f, a))
        .collect())
}

/// The measured curve of an `analyze` areas.csv ([`read_areas_csv`]) with each area's interval
/// (`area_um2_lo`, `area_um2_hi`) where the table has them, and the pixel size's uncertainty
/// (`pixel_size_uncertainty_pct`, the same on every row; 0 without the column), which the
/// intervals carry and which is taken out of them here so that the fit's bootstrap can share
/// it among the loads ([`contactscope::model_fit::interval`]). The interval is on the true
/// area and holds `area_corrected_um2`; the contact-pixel area `area_um2` (what a model counted
/// as imaged is compared with) may lie outside it where the PSF biases the count, and the
/// interval taken is widened to hold it ([`interval_holding`]).
pub fn read_measured(path: &Path) -> Result<Measured> {
    let table = Table::read(path)?;
    let rows = read_area_rows(&table, path)?;
    let has = |name: &str| table.header().iter().any(|h| h == name);
    let bad = |e: contactscope::Error| Error::bad_input(Location::file(path), e.to_string());
    if !(has("area_um2_lo") && has("area_um2_hi")) {
        return Measured::new(rows.into_iter().map(|(_, f, a)| (f, a)).collect()).map_err(bad);
    }
    let lo = table.numbers("area_um2_lo", 1e-12)?;
    let hi = table.numbers("area_um2_hi", 1e-12)?;
    let u = if has("pixel_size_uncertainty_pct") {
        let values = table.numbers("pixel_size_uncertainty_pct", 0.01)?;
        let first = values.first().copied().unwrap_or(0.0);
        if let Some(k) = values.iter().position(|&v| v != first) {
            return Err(Error::bad_input(
                Location::file(format!("{}:{}", path.display(), table.line(k))),
                "pixel_size_uncertainty_pct differs from the first row's: one series has one \
                 pixel size",
            ));
        }
        crate::analyze::check_pixel_size_uncertainty(first)
            .map_err(|e| Error::bad_input(Location::file(path), e.to_string()))?;
        first
    } else {
        0.0
    };
    let (shrink, grow) = calibration_bounds(u);
    let mut points = Vec::with_capacity(rows.len());
    for (k, force, area) in rows {
        let (l, h) = (lo[k] / shrink, hi[k] / grow);
        // An interval is ordered and not negative (NaN: none, an image without contact light).
        if l < 0.0 || l > h * (1.0 + 1e-9) || (l.is_nan() != h.is_nan()) {
            return Err(Error::bad_input(
                Location::file(format!("{}:{}", path.display(), table.line(k))),
                format!(
                    "area_um2_lo..area_um2_hi = {:e}..{:e} µm² is not an interval",
                    lo[k] * 1e12,
                    hi[k] * 1e12,
                ),
            ));
        }
        let (l, h) = interval_holding(area, l, h);
        points.push((force, area, l, h));
    }
    Measured::with_intervals(points, u).map_err(bad)
}

/// The interval [`lo`, `hi`] widened to hold `area` (the point itself where there is none).
pub fn interval_holding(area: f64, lo: f64, hi: f64) -> (f64, f64) {
    if lo.is_nan() || hi.is_nan() {
        return (area, area);
    }
    (lo.min(area), hi.max(area))
}

/// (data row, force N, area m²) of the rows with a positive force ([`read_areas_csv`]).
fn read_area_rows(table: &Table, path: &Path) -> Result<Vec<(usize, f64, f64)>> {
    let force_column = table
        .one_of(&["force_mN", "force_N"])?
        .ok_or_else(|| table.missing("force", &["force_mN", "force_N"]))?;
    if !table.header().iter().any(|h| h == "area_um2") {
        let hint = if table.header().iter().any(|h| h == "area_px") {
            format!(
                " (areas are in pixels: run analyze with {})",
                contactscope_formats::param::Param::PixelSize
            )
        } else {
            String::new()
        };
        return Err(Error::bad_input(
            table.location(),
            format!("no area_um2 column{hint}; columns found: {}", table.found()),
        ));
    }
    let unit = if force_column == "force_mN" {
        1e-3
    } else {
        1.0
    };
    let forces = table.numbers(force_column, unit)?;
    let areas = table.numbers("area_um2", 1e-12)?;
    let mut rows = Vec::new();
    for (k, (&force, &area)) in forces.iter().zip(&areas).enumerate() {
        if force == 0.0 {
            continue;
        }
        let at = Location::file(format!("{}:{}", path.display(), table.line(k)));
        Quantity::Force.check_at(force, &at)?;
        // A load without contact gives an infinite stress (friction) and no size to fit; an
        // area below one pixel of the smallest plausible size is no measurement either.
        let smallest = Quantity::PixelSize.range().0.powi(2);
        if !(area >= smallest && area <= 1.0) {
            return Err(Error::bad_input(
                at,
                format!(
                    "area_um2 = {:e} µm²: an area must lie between {:e} µm² (one pixel of \
                     0.1 nm) and 1 m² (remove a row without contact)",
                    area * 1e12,
                    smallest * 1e12
                ),
            ));
        }
        rows.push((k, force, area));
    }
    if rows.is_empty() {
        return Err(Error::bad_input(
            table.location(),
            "no rows with a positive force",
        ));
    }
    Ok(rows)
}

/// The loads of a `simulate` output folder: `areas.csv` rows and `load_NNN_contact.tif`.
pub fn simulated_maps(dir: &Path) -> Result<Vec<SimulatedMap>> {
    let table = dir.join("areas.csv");
    let at = Location::file(&table);
    crate::staging::note_input(&table);
    let text = std::fs::read_to_string(&table).map_err(|e| {
        Error::bad_input(
            Location::file(dir),
            format!("not a `contactscope simulate` output folder (areas.csv: {e})"),
        )
    })?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| Error::bad_input(at.clone(), format!("bad CSV header: {e}")))?
        .clone();
    let col = headers
        .iter()
        .position(|h| h == "force_mN")
        .ok_or_else(|| Error::bad_input(at.clone(), "no force_mN column"))?;
    let mut loads = Vec::new();
    for (i, record) in reader.records().enumerate() {
        let record =
            record.map_err(|e| Error::bad_input(at.clone(), format!("row {}: {e}", i + 1)))?;
        let force_mn: f64 = record
            .get(col)
            .and_then(|v| v.trim().parse().ok())
            .ok_or_else(|| {
                Error::bad_input(
                    at.clone(),
                    format!("row {}: force_mN is not a number", i + 1),
                )
            })?;
        let line = Location::file(format!("{}:{}", table.display(), i + 2));
        Quantity::Force.check_at(force_mn * 1e-3, &line)?;
        let map = dir.join(format!("load_{:03}_contact.tif", i + 1));
        if !map.is_file() {
            return Err(Error::bad_input(
                Location::file(&map),
                "contact map listed in areas.csv is missing",
            ));
        }
        loads.push(read_map(&map, force_mn * 1e-3)?);
    }
    if loads.is_empty() {
        return Err(Error::bad_input(at, "lists no loads"));
    }
    Ok(loads)
}

fn read_map(path: &Path, force_n: f64) -> Result<SimulatedMap> {
    let info = contactscope_formats::tiff::TiffReader::open(path)?
        .info()
        .clone();
    if let Some(q) = info.quantity.as_deref().filter(|q| *q != quantity::CONTACT) {
        return Err(Error::bad_input(
            Location::file(path),
            format!(
                "holds {}{}, not a contact map (1 in contact, 0 elsewhere)",
                q.replace('_', " "),
                info.value_unit
                    .as_deref()
                    .map_or(String::new(), |u| format!(" in {u}"))
            ),
        ));
    }
    let image = read_image(path, None, None)?;
    let px = image.require_pixel_size()?;
    let at = Location::file(path);
    Quantity::PixelSize.check_at(px.x_m, &at)?;
    Quantity::PixelSize.check_at(px.y_m, &at)?;
    let map = Grid::new(image.values, image.width, image.height, px.x_m, px.y_m)
        .map_err(|e| Error::bad_input(Location::file(path), e.to_string()))?;
    Ok(SimulatedMap {
        force_n,
        map,
        source: path.display().to_string(),
    })
}

/// The PSF FWHM (m) recorded by `contactscope psf` in its `psf.json` (`fwhm_nm_mean`).
pub fn fwhm_from_psf_json(path: &Path) -> Result<f64> {
    let at = Location::file(path);
    crate::staging::note_input(path);
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let value: Value = serde_json::from_str(&text)
        .map_err(|e| Error::bad_input(at.clone(), format!("not JSON: {e}")))?;
    match value.get("fwhm_nm_mean").and_then(Value::as_f64) {
        Some(nm) => Ok(Quantity::Fwhm.check_at(nm * 1e-9, &at)?),
        None => Err(Error::bad_input(
            at,
            "no number fwhm_nm_mean (expected the psf.json written by `contactscope psf`)",
        )),
    }
}
