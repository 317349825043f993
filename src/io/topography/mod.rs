//! Height maps from files, as [`Topography`] in metres with heights positive towards the
//! counter-surface (stored values are kept as they are: an AFM map of a sphere's top already has
//! its apex as the maximum).
//!
//! | extension | format | pixel size | height unit |
//! |---|---|---|---|
//! | `.npy` | NumPy array, float32/float64, 2-D, C or Fortran order, either byte order | argument (required) | argument (default m) |
//! | `.tif`, `.tiff` | float32/float64 TIFF, first page ([`crate::io::tiff`]) | metadata, or the argument | argument (default m) |
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
//!
//! ## Vendor AFM and profilometer formats
//!
//! Recognised from their content (magic bytes) before the extension table above is consulted,
//! and read into a [`HeightMap`]: heights in metres, positive towards the counter-surface as
//! stored by the instrument, pixel size in metres, row-major `(y, x)` in the order the file
//! stores its lines ([`read`], [`detect_file`]).
//!
//! | format | module | magic | heights | pixel size | invalid points |
//! |---|---|---|---|---|---|
//! | Igor binary wave (Asylum) `.ibw` | [`ibw`] | version 5 header | wave data × data units | `sfA` (dimension deltas) | NaN |
//! | Nanosurf `.nid` | [`nid`] | `[DataSet]` | `Dim2Min + Dim2Range·(raw + 2^(b−1))/2^b` | `Dim0Range/Points` | none |
//! | Molecular Imaging / Agilent `.mi` | [`mi`] | `fileType      Image` | `raw·bufferRange/2^(b−1)` in `bufferUnit` | `xLength/xPixels` | none |
//! | Park Systems TIFF | [`park`] | TIFF + tag 50432 = `0x0E031301` | `(raw + offset/scale)·scale·gain` in the header's unit | scan size / pixels | none |
//! | Gwyddion `.gwy` | [`gwy`] | `GWYP` | data field in `si_unit_z` | `xreal/xres` | mask field → NaN |
//! | ISO 25178-72 `.x3p` | [`x3p`] | zip with `main.xml` | `CZ` data × increment (m) | `CX/CY` increments | NaN or `valid.bin` |
//! | ISO 25178-71 `.sdf` (ASCII) | [`sdf`] | `aISO-1.0` | value × `Zscale` (m) | `Xscale`, `Yscale` | `BAD` / non-numbers |
//! | Wyko `.opd` | [`opd`] | `Directory` at byte 2 | `raw·λ/Mult` (λ in nm) | `Pixel_size` (mm), `Aspect` | ≥ 32766 / ≥ 1e38 |
//! | Sensofar `.plu` | [`plu`] | (none: size check of the 2012 layout) | µm | `micrometers_per_pixel` | 1000001 |
//! | Digital Surf `.sur` | [`sur`] | `DIGITAL SURF` | `raw·scale` in `delta_data_unit` | grid spacing | `zmin − 2` when flagged |
//! | FRT MicroProf `.frt` | [`frt`] | `FRTM_GLIDERV1.0` | `raw·scale` (m) | block 0x67 size / pixels | raw = 1 |
//!
//! **Invalid points** are stored as NaN in [`HeightMap::heights`] and counted in
//! [`HeightMap::invalid_points`]; [`HeightMap::into_topography`] refuses a map with invalid
//! points (a contact calculation needs every height), naming the count.
//!
//! **Channels**: [`read`] takes an optional channel name. An exact (case-insensitive) match wins,
//! else the first channel whose name contains the request; without one, the first channel whose
//! values are heights (a length unit, or a name with "height", "topograph" or "z-axis"). When no
//! channel matches, the error lists them all.

pub mod fill;
pub mod frt;
pub mod gwy;
pub mod ibw;
pub mod mi;
pub mod nid;
pub mod opd;
pub mod park;
pub mod plu;
pub mod sdf;
pub mod summary;
pub mod sur;
mod vendor;
pub mod x3p;

mod gsf;
mod nanoscope;
mod npy;
mod text;
mod wsxm;

use std::path::{Path, PathBuf};

use ndarray::Array2;

use crate::error::{Error, Location, Result};
use crate::image::{SampleType, Samples};
use crate::io::ranges::Quantity;
use crate::io::tiff::metadata::length_unit_factor;
use crate::io::tiff::TiffReader;

use crate::surface::{Detrend, Topography};

pub use fill::FillInvalid;
pub use gsf::{read_gsf, write_gsf};
pub use nanoscope::read_nanoscope;
pub use npy::{read_npy, write_npy};
pub use text::read_text;
pub use vendor::MAX_FILE_BYTES;
pub(crate) use vendor::{
    choose, count, grid_bytes, height_like, height_map, length_factor, length_scale, positive,
    ChannelEntry,
};
pub use vendor::{
    detect, detect_file, read, read_for_surface, read_for_surface_with, HeightMap, TopographyFormat,
};
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
    /// Channel of a multi-channel vendor file, by name (default: its height channel).
    pub channel: Option<String>,
    /// Fill a vendor map's invalid points this way (default: refuse such a map).
    pub fill_invalid: Option<FillInvalid>,
}

impl TopographySource {
    /// A file with the default channel, no filling and no detrending.
    pub fn new(path: PathBuf) -> Self {
        TopographySource {
            path,
            pixel_size_m: None,
            height_unit_m: None,
            detrend: Detrend::None,
            channel: None,
            fill_invalid: None,
        }
    }

    /// Read the file ([`read_topography`]) and detrend it.
    pub fn read(&self) -> Result<Topography> {
        Ok(self.read_with_notes()?.0)
    }

    /// [`Self::read`], with notes for the user (how many invalid points were filled).
    pub fn read_with_notes(&self) -> Result<(Topography, Vec<String>)> {
        let vendor = read_for_surface_with(
            &self.path,
            self.pixel_size_m,
            self.height_unit_m,
            self.channel.as_deref(),
            self.fill_invalid,
        )?;
        let mut notes = Vec::new();
        let mut topography = match vendor {
            Some((t, filled)) => {
                if let (Some(how), true) = (self.fill_invalid, filled > 0) {
                    notes.push(format!(
                        "{}: {filled} invalid point(s) filled with the {} valid height",
                        self.path.display(),
                        how.name()
                    ));
                }
                t
            }
            None => {
                if let Some(channel) = &self.channel {
                    return Err(Error::bad_input(
                        Location::file(&self.path),
                        format!(
                            "channel '{channel}' asked for, but this format holds one height map"
                        ),
                    ));
                }
                read_topography(&self.path, self.pixel_size_m, self.height_unit_m)?
            }
        };
        topography.detrend(self.detrend);
        Ok((topography, notes))
    }
}

/// The name of the extension reader [`read_topography`] uses for `path` (`npy`, `tiff`, `gsf`,
/// `text`, `wsxm`, `nanoscope`), for summaries; `None` for an unknown extension.
pub fn extension_format(path: &Path) -> Option<&'static str> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    Some(match ext.as_str() {
        "npy" => "npy",
        "tif" | "tiff" => "tiff",
        "gsf" => "gsf",
        "txt" | "csv" | "dat" => "text",
        "top" => "wsxm",
        "di" | "spm" => "nanoscope",
        e if e.len() == 3 && e.bytes().all(|b| b.is_ascii_digit()) => "nanoscope",
        _ => return None,
    })
}

/// Read a height map, choosing the reader by the file extension (table in the module docs).
/// `pixel_size_m` = (x, y) in metres overrides the file's; `height_unit_m` gives metres per
/// stored unit for formats without a unit (default 1: metres).
pub fn read_topography(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<Topography> {
    // Vendor AFM/profilometer formats, recognised by content (the second table above).
    if let Some(t) = read_for_surface(path, pixel_size_m, height_unit_m)? {
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

pub(crate) use crate::io::binary::bad;

/// Read a whole file.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    crate::io::staging::note_input(path);
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
/// (multiplying by the inexact `1e-9` would not; as in [`crate::io::units`]).
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

/// Bytes `offset..offset + len` of `data`, or a "truncated" error.
pub(crate) fn slice<'a>(
    path: &Path,
    data: &'a [u8],
    offset: usize,
    len: usize,
) -> Result<&'a [u8]> {
    crate::io::binary::slice(path, data, offset, len, "the data")
}

/// Largest height magnitude of a height map read from a file, m: no rough surface reaches it,
/// and a map that does was almost always stored in another unit than the one assumed.
pub const MAX_FILE_HEIGHT_M: f64 = 1.0;

/// An error naming the file when a height lies beyond ±[`MAX_FILE_HEIGHT_M`].
pub(crate) fn plausible_heights(path: &Path, heights: &Array2<f64>) -> Result<()> {
    let nx = heights.ncols().max(1);
    match heights.iter().position(|h| h.abs() > MAX_FILE_HEIGHT_M) {
        None => Ok(()),
        Some(k) => Err(bad(
            path,
            format!(
                "height at row {}, column {} is {:e} m, beyond ±{MAX_FILE_HEIGHT_M} m (heights \
                 in another unit? see --height-unit)",
                k / nx,
                k % nx,
                heights.iter().nth(k).copied().unwrap_or(f64::NAN)
            ),
        )),
    }
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
    let at = Location::file(path);
    Quantity::PixelSize.check_at(pixel_size_m.0, &at)?;
    Quantity::PixelSize.check_at(pixel_size_m.1, &at)?;
    plausible_heights(path, &array)?;
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
