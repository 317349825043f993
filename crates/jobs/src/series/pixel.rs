//! The pixel size of a series of micrographs: a given one, or the files' own when they agree,
//! and what is doubtful about it (a given size far from the metadata's, a pixel far below what a
//! light microscope resolves).

use contactscope_formats::image::{PixelSize, PixelSizeSource};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::{short, Quantity};

use super::Series;
use crate::error::{Error, Location, Result};

/// The pixel size for the whole series: the override, or the files' metadata if they agree,
/// or else `default_m` (for files that state none; never replacing one they state).
///
/// Notes from the files' metadata, and the lack of any pixel size, are added to `warnings`.
pub fn pixel_size(
    series: &Series,
    override_m: Option<(f64, f64)>,
    default_m: Option<(f64, f64)>,
    warnings: &mut Vec<String>,
) -> Result<Option<PixelSize>> {
    let default = default_m.map(|(x_m, y_m)| PixelSize {
        x_m,
        y_m,
        source: PixelSizeSource::DefaultForUncalibrated,
    });
    if let Some((x_m, y_m)) = override_m {
        warnings.extend(pixel_size_warnings(series, (x_m, y_m), true));
        return Ok(Some(PixelSize {
            x_m,
            y_m,
            source: PixelSizeSource::CommandLine,
        }));
    }
    let Some(first) = series.files.first() else {
        // Planes in memory: no metadata.
        if default.is_none() {
            warnings.push(format!(
                "no pixel size given ({}): areas are in pixels",
                Param::PixelSize
            ));
        }
        return Ok(default);
    };
    for other in &series.files[1..] {
        let agree = match (&first.pixel_size, &other.pixel_size) {
            (Some(a), Some(b)) => a.same_size(b),
            (None, None) => true,
            _ => false,
        };
        if !agree {
            let show = |p: &Option<PixelSize>| {
                p.map_or("no pixel size".to_string(), |p| {
                    format!("{:.6}×{:.6} µm", p.x_m * 1e6, p.y_m * 1e6)
                })
            };
            return Err(Error::SeriesMismatch {
                at: Location::file(&other.path),
                reason: format!("pixel size is {}", show(&other.pixel_size)),
                expected: format!(
                    "{}; give {} to override",
                    show(&first.pixel_size),
                    Param::PixelSize
                ),
            });
        }
    }
    for f in &series.files {
        warnings.extend(f.notes.iter().map(|n| format!("{}: {n}", f.path.display())));
    }
    if let Some(p) = &first.pixel_size {
        let at = Location::file(&first.path);
        Quantity::PixelSize.check_at(p.x_m, &at)?;
        Quantity::PixelSize.check_at(p.y_m, &at)?;
    }
    match (first.pixel_size, default) {
        (Some(p), _) => warnings.extend(pixel_size_warnings(series, (p.x_m, p.y_m), false)),
        (None, Some(d)) => warnings.extend(pixel_size_warnings(series, (d.x_m, d.y_m), true)),
        (None, None) => warnings.push(format!(
            "no pixel size in the files' metadata and no {}: areas are in pixels",
            Param::PixelSize
        )),
    }
    Ok(first.pixel_size.or(default))
}

/// Given pixel sizes that differ from the file's metadata by more than this factor are warned of.
pub const PIXEL_SIZE_CONTRADICTION: f64 = 1.5;

/// Pixels smaller than this (m) are far below what a light microscope resolves (about 200 nm):
/// almost surely a unit mistake (nm for µm, or a file's calibration lost).
pub const SUB_DIFFRACTION_PIXEL_M: f64 = 10e-9;

/// What is doubtful about the pixel size `used` (m) of a series of micrographs: a `given` size
/// that contradicts the first file's metadata by more than [`PIXEL_SIZE_CONTRADICTION`] (both
/// named; the given one is used, as documented for `--pixel-size`), and a pixel below
/// [`SUB_DIFFRACTION_PIXEL_M`].
pub fn pixel_size_warnings(series: &Series, used: (f64, f64), given: bool) -> Vec<String> {
    let mut out = Vec::new();
    let length = |m: f64| match m {
        m if m < 1e-6 => format!("{} nm", short(m * 1e9)),
        m if m < 1e-3 => format!("{} µm", short(m * 1e6)),
        m => format!("{} mm", short(m * 1e3)),
    };
    let show = |(x, y): (f64, f64)| {
        if x == y {
            length(x)
        } else {
            format!("{} × {}", length(x), length(y))
        }
    };
    if let (true, Some(file)) = (given, series.files.first()) {
        if let Some(meta) = file.pixel_size {
            let ratio = |a: f64, b: f64| (a / b).max(b / a);
            let worst = ratio(used.0, meta.x_m).max(ratio(used.1, meta.y_m));
            if worst > PIXEL_SIZE_CONTRADICTION {
                let way = match used.0 * used.1 < meta.x_m * meta.y_m {
                    true => "smaller",
                    false => "larger",
                };
                out.push(format!(
                    "{} {} is {}× {way} than the {} of {}'s metadata ({}): areas scale with its \
                     square; the given size is used",
                    Param::PixelSize,
                    show(used),
                    short((worst * 10.0).round() / 10.0),
                    show((meta.x_m, meta.y_m)),
                    file.path.display(),
                    meta.source.describe()
                ));
            }
        }
    }
    if used.0.min(used.1) < SUB_DIFFRACTION_PIXEL_M {
        out.push(format!(
            "pixel size {} is far below what a light microscope resolves (about 200 nm): is its \
             unit right{}?",
            show(used),
            if given {
                String::new()
            } else {
                " in the files' metadata".to_string()
            }
        ));
    }
    out
}
