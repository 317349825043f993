//! Height maps from files, as [`Topography`] in metres with heights positive towards the
//! counter-surface (stored values are kept as they are: an AFM map of a sphere's top already has
//! its apex as the maximum).
//!
//! | extension | format | pixel size | height unit |
//! |---|---|---|---|
//! | `.npy` | NumPy array, float32/float64, 2-D, C or Fortran order, either byte order | argument (required) | argument (default m) |
//! | `.tif`, `.tiff` | float32/float64 TIFF, first page ([`crate::stack::tiff`]) | metadata, or the argument | argument (default m) |
//! | `.gsf` | Gwyddion Simple Field | `XReal`/`YReal`, or the argument | `ZUnits` (default m) |
//! | `.txt`, `.csv`, `.dat` | text matrix, one row per line, `#` comments | argument (required) | argument (default m) |
//! | `.top` | WSxM (Nanotec) image | header | header |
//! | `.di`, `.spm`, `.001`… | Bruker/Veeco Nanoscope, first channel with a length unit | header | header |
//!
//! Arrays are row-major `(y, x)` as a NumPy image: rows are y, columns x. (SurfaceTopography
//! keeps `(x, y)`: transpose its arrays before saving them.) A pixel size given as an argument
//! overrides the file's. A height unit may only be given for formats that do not state one;
//! for the others it is an error, because two units for one number is a contradiction.
//! Every error names the file.

mod gsf;
mod nanoscope;
mod npy;
mod text;
mod wsxm;

use std::path::{Path, PathBuf};

use ndarray::Array2;

use crate::error::{Error, Location, Result};
use crate::stack::metadata::length_unit_factor;
use crate::stack::tiff::TiffReader;
use crate::stack::{SampleType, Samples};

use super::{Detrend, Topography};

pub use gsf::{read_gsf, write_gsf};
pub use nanoscope::read_nanoscope;
pub use npy::{read_npy, write_npy};
pub use text::read_text;
pub use wsxm::read_wsxm;

/// Extensions [`read_topography`] knows (Nanoscope files also use three-digit extensions).
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "npy", "tif", "tiff", "gsf", "txt", "csv", "dat", "top", "di", "spm", "001",
];

/// A height-map file with how to read and level it: what `simulate` and `fit-hardening` take.
#[derive(Debug, Clone, PartialEq)]
pub struct TopographySource {
    /// The file.
    pub path: PathBuf,
    /// Pixel size override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// Height unit override, m per stored unit.
    pub height_unit_m: Option<f64>,
    /// Detrending applied after reading.
    pub detrend: Detrend,
}

impl TopographySource {
    /// Read the file ([`read_topography`]) and detrend it.
    pub fn read(&self) -> Result<Topography> {
        let mut topography = read_topography(&self.path, self.pixel_size_m, self.height_unit_m)?;
        topography.detrend(self.detrend);
        Ok(topography)
    }
}

/// Read a height map, choosing the reader by the file extension (table in the module docs).
/// `pixel_size_m` = (x, y) in metres overrides the file's; `height_unit_m` gives metres per
/// stored unit for formats without a unit (default 1: metres).
pub fn read_topography(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<Topography> {
    // Vendor AFM/profilometer formats, recognised by content (crate::io::topography).
    if let Some(t) = crate::io::topography::read_for_surface(path, pixel_size_m, height_unit_m)? {
        return Ok(t);
    }
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "npy" => read_npy(path, pixel_size_m, height_unit_m),
        "tif" | "tiff" => read_tiff(path, pixel_size_m, height_unit_m),
        "gsf" => read_gsf(path, pixel_size_m, height_unit_m),
        "txt" | "csv" | "dat" => read_text(path, pixel_size_m, height_unit_m),
        "top" => read_wsxm(path, pixel_size_m, height_unit_m),
        "di" | "spm" => read_nanoscope(path, pixel_size_m, height_unit_m),
        e if e.len() == 3 && e.bytes().all(|b| b.is_ascii_digit()) => {
            read_nanoscope(path, pixel_size_m, height_unit_m)
        }
        _ => Err(Error::Unsupported {
            at: Location::file(path),
            reason: format!(
                "unknown height-map extension '{}'; supported: .{} (Nanoscope also .002, .003, …)",
                ext,
                SUPPORTED_EXTENSIONS.join(", .")
            ),
        }),
    }
}

/// Read the first page of a float32/float64 TIFF. Pixel size: `pixel_size_m`, else the file's
/// calibration (`docs/conventions.md`, "Pixel size"), else an error. Heights are multiplied by
/// `height_unit_m` (default 1: the file holds metres).
pub fn read_tiff(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<Topography> {
    let scale = unitless_scale(height_unit_m)?;
    let mut reader = TiffReader::open(path)?;
    let info = reader.info().clone();
    let (dx, dy) = match (pixel_size_m, info.pixel_size) {
        (Some(p), _) => p,
        (None, Some(p)) => (p.x_m, p.y_m),
        (None, None) => {
            return Err(bad(
                path,
                "the TIFF has no pixel-size calibration; give the pixel size",
            ))
        }
    };
    let page = *info
        .pages
        .first()
        .ok_or_else(|| bad(path, "the TIFF has no pages"))?;
    let plane = reader.read_page(page, 0)?;
    let values = match (&plane.samples, plane.sample_type) {
        (Samples::Float(v), SampleType::F32 | SampleType::F64) => v,
        _ => {
            return Err(Error::Unsupported {
                at: Location::page(path, page),
                reason: format!(
                    "{} TIFF: a height map must be float32 or float64 (integer data carries no \
                     height scale)",
                    plane.sample_type.name()
                ),
            })
        }
    };
    let convert = to_metres(scale);
    let heights: Vec<f64> = values.iter().map(|&v| convert(f64::from(v))).collect();
    topography(path, (plane.height, plane.width), heights, (dx, dy))
}

/// A bad-input error naming the file.
pub(crate) fn bad(path: &Path, reason: impl Into<String>) -> Error {
    Error::bad_input(Location::file(path), reason)
}

/// Read a whole file.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// `height_unit_m` for a format without a height unit: default 1 (metres), must be positive.
pub(crate) fn unitless_scale(height_unit_m: Option<f64>) -> Result<f64> {
    match height_unit_m {
        None => Ok(1.0),
        Some(u) if u.is_finite() && u > 0.0 => Ok(u),
        Some(u) => Err(Error::InvalidArgument(format!(
            "height unit must be positive and finite (got {u} m)"
        ))),
    }
}

/// Conversion of stored heights to metres. For sub-metre units that are an exact power of ten
/// (nm, µm) it divides by the integer `1/unit`, so that `6` nm gives exactly the literal `6e-9`
/// (multiplying by the inexact `1e-9` would not; as in [`crate::units`]).
pub(crate) fn to_metres(unit_m: f64) -> impl Fn(f64) -> f64 {
    let inverse = (1.0 / unit_m).round();
    let divide = unit_m < 1.0 && inverse * unit_m == 1.0;
    move |v| if divide { v / inverse } else { v * unit_m }
}

/// Refuse a height unit argument for a format that states its own.
pub(crate) fn refuse_height_unit(
    path: &Path,
    height_unit_m: Option<f64>,
    file_unit: &str,
) -> Result<()> {
    match height_unit_m {
        None => Ok(()),
        Some(_) => Err(bad(
            path,
            format!("the file states its height unit ({file_unit}); do not give another one"),
        )),
    }
}

/// The pixel size argument, required for formats without one.
pub(crate) fn required_pixel_size(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    format: &str,
) -> Result<(f64, f64)> {
    pixel_size_m.ok_or_else(|| {
        bad(
            path,
            format!("{format} files carry no pixel size; give the pixel size"),
        )
    })
}

/// Metres per unit of a length unit as microscope software writes it; DI files write `~m` for
/// µm.
pub(crate) fn length_unit(path: &Path, unit: &str, what: &str) -> Result<f64> {
    let unit = unit.trim();
    let normalised = match unit.strip_prefix('~') {
        Some(rest) => format!("µ{rest}"),
        None => unit.to_string(),
    };
    length_unit_factor(&normalised)
        .ok_or_else(|| bad(path, format!("{what} unit '{unit}' is not a length unit")))
}

/// Latin-1 bytes as text (every byte is one char).
pub(crate) fn latin1(bytes: &[u8]) -> String {
    bytes.iter().map(|&b| char::from(b)).collect()
}

/// Bytes `offset..offset + len` of `data`, or a "truncated" error ([`crate::io::binary::slice`]).
pub(crate) fn slice<'a>(
    path: &Path,
    data: &'a [u8],
    offset: usize,
    len: usize,
) -> Result<&'a [u8]> {
    crate::io::binary::slice(path, data, offset, len, "the data")
}

/// Build the [`Topography`], turning its argument errors into errors naming the file.
pub(crate) fn topography(
    path: &Path,
    shape: (usize, usize),
    heights: Vec<f64>,
    pixel_size_m: (f64, f64),
) -> Result<Topography> {
    let array = Array2::from_shape_vec(shape, heights).map_err(|e| {
        bad(
            path,
            format!("data do not fill a {}×{} grid: {e}", shape.0, shape.1),
        )
    })?;
    Topography::new(array, pixel_size_m.0, pixel_size_m.1).map_err(|e| match e {
        Error::InvalidArgument(reason) => bad(path, reason),
        other => other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_extension_lists_the_supported_ones() {
        let err = read_topography(Path::new("map.xyz"), None, None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("map.xyz") && err.contains(".gsf") && err.contains(".npy"),
            "{err}"
        );
    }

    #[test]
    fn missing_file_names_it() {
        let err = read_topography(Path::new("/nonexistent/a.gsf"), None, None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("/nonexistent/a.gsf"), "{err}");
    }

    #[test]
    fn units() {
        let p = Path::new("x");
        assert_eq!(length_unit(p, "nm", "z").unwrap(), 1e-9);
        assert_eq!(length_unit(p, "~m", "z").unwrap(), 1e-6);
        assert_eq!(length_unit(p, "µm", "z").unwrap(), 1e-6);
        assert!(length_unit(p, "V", "z").is_err());
        assert!(unitless_scale(Some(0.0)).is_err());
        assert_eq!(unitless_scale(None).unwrap(), 1.0);
        assert_eq!(to_metres(1e-9)(6.0), 6e-9);
        assert_eq!(to_metres(1e-6)(0.3), 0.3e-6);
        assert_eq!(to_metres(2.0)(0.5), 1.0);
    }
}
