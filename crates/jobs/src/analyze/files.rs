//! The outputs of `analyze` as the command line writes them, through a staging folder (nothing
//! appears unless everything succeeded): `areas.csv` (the outcome's rows), `summary.json` (the
//! rest of the outcome), `area_vs_load.png/.svg` (feature `plots`; only when an image has a
//! positive force and contact area: 0 mN frames and images without contact are not on log axes)
//! and, on request, one overlay
//! PNG and one mask TIFF per image, written as the images are measured.

use std::path::{Path, PathBuf};

use contactscope::analysis::{ImageSink, Progress};
use contactscope::image::Plane;
use contactscope::measure::Mask;
use contactscope_formats::tiff::write::encode_u8_stack;

use super::zarr_out::ZarrOut;
use super::{run_open, AnalyzeOutcome, AnalyzeRequest};
use crate::error::Result;
use crate::series::{ImageRef, OpenSeries};
use crate::staging::Staging;
use crate::summary::summary_json_without;
use crate::table::rows_csv;

/// Per-image outputs of the folder.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ImageOutputs {
    /// One PNG per image with the contact edges in green.
    pub overlays: bool,
    /// The contact masks as TIFF.
    pub masks: bool,
    /// The masks and the table into an OME-Zarr store ([`super::zarr_out`]): a new one, or
    /// the one store analysed.
    pub zarr: Option<PathBuf>,
}

/// Run `analyze` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &AnalyzeRequest,
    out_dir: &Path,
    command_line: &[String],
    images: ImageOutputs,
    progress: Progress,
) -> Result<(AnalyzeOutcome, Vec<PathBuf>)> {
    request.check()?;
    let open = request.micrographs.open()?;
    run_open_to_folder(
        request,
        &open,
        out_dir,
        command_line,
        images,
        progress,
        &|_, _, _| Ok(()),
    )
}

/// [`run_to_folder`] on a series already opened, with `observer` also told of every image's
/// plane and mask as it is measured (the batch's thumbnails and edge checks).
pub fn run_open_to_folder(
    request: &AnalyzeRequest,
    open: &OpenSeries,
    out_dir: &Path,
    command_line: &[String],
    images: ImageOutputs,
    progress: Progress,
    observer: ImageSink,
) -> Result<(AnalyzeOutcome, Vec<PathBuf>)> {
    let inputs: Vec<PathBuf> = open
        .series
        .files
        .iter()
        .map(|f| f.path.clone())
        .chain(open.series.manifest.clone())
        .collect();
    let staging = Staging::new(out_dir, &inputs)?;
    let zarr = match &images.zarr {
        Some(path) => Some(ZarrOut::prepare(path, open, pixel_size_m(request, open))?),
        None => None,
    };
    let sink = |i: usize, plane: &Plane, mask: &Mask| -> contactscope::Result<()> {
        write_image_outputs(&staging, request, open, &images, i, plane, mask)?;
        if let Some(z) = &zarr {
            z.write(i, plane, mask)?;
        }
        observer(i, plane, mask)
    };
    let sink: ImageSink = &sink;
    let outcome = run_open(request, open, progress, sink)?;
    staging.write("areas.csv", &areas_csv(&outcome)?)?;
    #[cfg(feature = "plots")]
    if outcome.rows.rows.iter().any(super::Row::on_log_axes) {
        let plot = area_plot(&outcome, "Contact area versus normal force");
        staging.write("area_vs_load.png", &plot.to_png()?)?;
        staging.write("area_vs_load.svg", plot.to_svg()?.as_bytes())?;
    }
    staging.write(
        "summary.json",
        &summary_json_without(command_line, &outcome, &["rows"])?,
    )?;
    let zarr_path = match zarr {
        Some(z) => Some(z.finish(&outcome.rows)?),
        None => None,
    };
    let mut written = staging.commit()?;
    written.extend(zarr_path);
    Ok((outcome, written))
}

/// The pixel size the masks are measured in, (x, y) m: the one given, else the first file's.
fn pixel_size_m(request: &AnalyzeRequest, open: &OpenSeries) -> Option<(f64, f64)> {
    request.pixel_size_m.or_else(|| {
        let file = open.series.files.first()?;
        let size = file.pixel_size.map(|p| (p.x_m, p.y_m));
        size.or(request.pixel_size_default_m)
    })
}

/// `areas.csv`: one row per image, every column named with its unit.
pub fn areas_csv(outcome: &AnalyzeOutcome) -> Result<Vec<u8>> {
    rows_csv(&outcome.rows, &[])
}

/// Output file stem for image `index`: `003_name_p2`.
fn image_stem(index: usize, image: &ImageRef) -> String {
    let stem = image
        .path
        .file_stem()
        .map_or("image".into(), |s| s.to_string_lossy().into_owned());
    let clean: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{:03}_{clean}_p{}", index + 1, image.page)
}

/// Scale factor that makes small micrographs legible in overlays.
#[cfg(feature = "plots")]
fn overlay_scale(width: usize) -> usize {
    (512 / width.max(1)).clamp(1, 4)
}

fn write_image_outputs(
    staging: &Staging,
    request: &AnalyzeRequest,
    open: &OpenSeries,
    images: &ImageOutputs,
    index: usize,
    plane: &Plane,
    mask: &Mask,
) -> Result<()> {
    let image = &open.series.images[index];
    let stem = image_stem(index, image);
    #[cfg(feature = "plots")]
    if images.overlays {
        let png = crate::plot::overlay_png(
            &plane.to_f64(),
            plane.width,
            plane.height,
            &mask.as_bools(),
            overlay_scale(plane.width),
        )?;
        staging.write(&format!("overlay_{stem}.png"), &png)?;
    }
    #[cfg(not(feature = "plots"))]
    let _ = plane;
    if images.masks {
        let bytes: Vec<u8> = mask.data.iter().map(|&m| m * 255).collect();
        let size = request.pixel_size_m.or_else(|| {
            open.series
                .info_of(&image.path)?
                .pixel_size
                .map(|p| (p.x_m, p.y_m))
        });
        let tiff = encode_u8_stack(&[&bytes], mask.width, mask.height, size)?;
        staging.write(&format!("mask_{stem}.tif"), &tiff)?;
    }
    Ok(())
}

/// Log–log plot of area against force with both fits (and the Hertz area if known).
#[cfg(feature = "plots")]
pub fn area_plot(outcome: &AnalyzeOutcome, title: &str) -> crate::plot::Chart {
    use crate::plot::{Axes, Chart, Curve, Legend};
    use contactscope::mechanics::hertz;
    let table = &outcome.rows;
    let fits = &outcome.fits;
    let measured: Vec<(f64, f64)> = table
        .rows
        .iter()
        .filter(|r| r.on_log_axes())
        .filter_map(|r| r.force_mn.map(|f| (f, r.area)))
        .collect();
    let forces: Vec<f64> = measured.iter().map(|p| p.0).collect();
    let (lo, hi) = forces
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &f| {
            (a.min(f), b.max(f))
        });
    let grid: Vec<f64> = if lo < hi {
        (0..=40)
            .map(|i| lo * (hi / lo).powf(f64::from(i) / 40.0))
            .collect()
    } else {
        forces.clone()
    };
    let mut curves = Vec::new();
    // Each image's 95 % interval on the true area as a vertical bar (a non-finite vertex breaks
    // the line between bars; an interval reaching 0 has no bar on log axes).
    let bars: Vec<(f64, f64)> = table
        .rows
        .iter()
        .filter(|r| r.on_log_axes() && r.area_lo > 0.0 && r.area_hi > r.area_lo)
        .filter_map(|r| {
            r.force_mn
                .map(|f| [(f, r.area_lo), (f, r.area_hi), (f, f64::NAN)])
        })
        .flatten()
        .collect();
    if !bars.is_empty() {
        curves.push(Curve {
            label: if table.rows.iter().any(|r| r.area_corrected.is_finite()) {
                "95 % interval of the true area (light budget)"
            } else {
                "95 % interval of the area (edge band)"
            }
            .into(),
            xy: bars,
        });
    }
    if let Some(f) = fits.power_law {
        curves.push(Curve {
            label: format!(
                "power law A ∝ N^β, β = {}",
                crate::table::value_pm_or(f.exponent, f.exponent_se, 3)
            ),
            xy: grid.iter().map(|&n| (n, f.eval(n))).collect(),
        });
    }
    if let Some((p, _)) = fits.proportional_mpa {
        curves.push(Curve {
            label: format!("proportional A = N/p, p = {p:.1} MPa"),
            xy: grid.iter().map(|&n| (n, n / p * 1e3)).collect(),
        });
    }
    if let (Some(h), super::AreaUnit::SquareMicrometre) = (outcome.hertz, table.unit) {
        curves.push(Curve {
            label: "Hertz area πa²".into(),
            xy: grid
                .iter()
                .map(|&n| {
                    (
                        n,
                        hertz::contact_area(n * 1e-3, h.radius_m, h.modulus_pa) * 1e12,
                    )
                })
                .collect(),
        });
    }
    Chart {
        title: title.to_string(),
        x_label: "normal force N (mN)".into(),
        y_label: table.unit.axis_label().into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points: crate::fits::point_sets(
            &table
                .rows
                .iter()
                .map(super::Row::load_point)
                .collect::<Vec<_>>(),
            "measured (Otsu contact pixels × pixel area)",
        ),
        curves,
        ..Chart::default()
    }
}
