//! Height maps from files, as [`HeightMap`]s in metres with heights positive towards the
//! counter-surface (stored values are kept as they are: an AFM map of a sphere's top already has
//! its apex as the maximum).
//!
//! Every format is recognised by its content, never by its extension ([`read_height_map`],
//! `content.rs`): the vendor formats below by their magic bytes ([`detect_file`]), then NumPy
//! (`\x93NUMPY`), float TIFF, Gwyddion Simple Field, gzip-compressed text, and text (`text/`:
//! matrices with or without a Gwyddion or `h=`/`w=` header, `x y z` points on a grid; profiles
//! are refused as line scans). Formats known but not read are refused saying what they are.
//!
//! | format | pixel size | height unit |
//! |---|---|---|
//! | NumPy `.npy`, float32/float64, 2-D, C or Fortran order, either byte order | argument (required) | argument (default m) |
//! | float32/float64 TIFF, first page ([`crate::tiff`]) | metadata, or the argument | stated, else the argument (default m) |
//! | Gwyddion Simple Field `.gsf` | `XReal`/`YReal`, or the argument | `ZUnits` (default m) |
//! | text with a header | the header | the header |
//! | text matrix without one | argument (required) | argument (default m) |
//! | `x y z` points on a regular grid | the points' spacing | argument (default m, all three columns) |
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
//! | Alicona `.al3d` | [`al3d`] | `AliconaImaging\0\r\n` | float32 (m) | `PixelSizeXMeter`, `PixelSizeYMeter` | `InvalidPixelValue`, NaN |
//! | TrueMap `.tmd` | [`tmd`] | `Binary TrueMap Data File v` | float32 (mm) | lengths (mm) / points | NaN |
//! | NanoFocus µsurf `.nms` | [`nms`] | `OM_MS_` at byte 32 | `z_low + (raw − raw_low)·Δz/Δraw` (µm) | spacings (nm) | intensity 0 |
//! | Image Metrology `.bcr`, `.bcrf` | [`bcr`] | `fileformat = bcr` (8-bit or UTF-16LE) | int16 · `bit2nm` or float32, in `zunit` | `xlength/xpixels` in `xunit` | 32767, > 1.7e38 |
//! | Zygo MetroPro `.dat` | [`metropro`] | `0x881B036F`, `…70`, `…71` | `phase·S·O·λ/R` (m) | camera resolution | phase ≥ 2147483640 |
//! | NetCDF `.nc` (classic, 64-bit offset) | [`netcdf`] | `CDF\x01`, `CDF\x02`, `CDF\x05` | variable `heights` in its `unit` | `length` of the `x`/`y` variables / points | `mask`, `_FillValue` |
//! | HDF5 `.h5` | [`hdf5`] | `\x89HDF\r\n\x1a\n` | 2-D datasets as stored, m (or the height unit given) | none: the argument is required | NaN |
//! | JPK Instruments TIFF `.jpk`, `.jpk-qi-image` | [`jpk`] | TIFF + tags 32768, 32834, 32838 | `raw·multiplier + offset` of the default slot, in its unit; lines flipped | grid lengths / points | none |
//! | JPK HDF5 export `.h5-jpk` | [`jpk_h5`] | HDF5 with root attribute `file-format-info` = `JPK SCAN` | `raw·multiplier + offset` of `net-encoder.scaling`, in its unit; lines flipped; one channel per frame | `ulength/ilength`, `vlength/jlength` | none |
//! | TopoStats `.topostats` | [`hdf5`] | HDF5 with `image` and `pixel_to_nm_scaling` | `image` or `image_original`, nm | `pixel_to_nm_scaling` (nm) | NaN |
//! | Digital Surf MountainsMap `.mnt` | [`mnt`] | OLE2 (`D0 CF 11 E0`) with a `ScopedContents` stream | `count·step + origin` of the z axis | x and y axis steps | mask value ≠ 9 |
//! | Bruker/Veeco Vision64 `.opdx` | [`opdx`] | `VCA DATA\x01\x00\x00\x55` | float32 · `DataScale` (a 1-D profile is refused) | `Dimension2Extent`/(columns − 1), `Dimension1Extent`/(rows − 1) | NaN |
//! | Bruker/Veeco Nanoscope `.di`, `.spm`, `.001`… | `nanoscope` | `\*File list` | `raw·(V_z/65536)·S` | scan size / samples | none |
//! | WSxM images `.top`, `.stp`, … | `wsxm` | `WSxM file copyright` | integers: `raw·Z amplitude/(max − min)`; floats as stored | X/Y amplitude / points | none |
//! | surfalize `.sflz` | [`sflz`] | `SFLZ` | the height layer in the file's unit; integer layers mapped onto their stated range | `step_x`, `step_y` | NaN; the integer sentinel |
//! | Createc `.dat` | [`createc`] | `[Paramco32]` | float32 DAC counts × `Dacto[A]z` (nm) × `GainZ`/10; first column dropped | `Length x[A]`/`Num.X` | lines not scanned dropped |
//! | Keyence `.zon` | [`zon`] | `KPK0`, `KPK1` | int32 × `MeterPerUnit` (m) | `MeterPerPixel` | validity bits 0–1 |
//! | Nanonis `.sxm` | [`sxm`] | `:NANONIS_VERSION:` | float32 as stored, in the `DATA_INFO` unit; backward lines mirrored, scans `up` flipped | `SCAN_RANGE` / `SCAN_PIXELS` | NaN (not scanned) |
//!
//! A file that states no pixel size (HDF5; a MetroPro file with a camera resolution of 0; a
//! NetCDF file without `length` attributes) is read with a pixel size of NaN, and
//! [`read_height_map`] then requires the pixel size argument. HDF5 files state no height unit
//! either: their heights are metres unless a height unit is given
//! ([`TopographyFormat::states_height_unit`]).
//!
//! **Invalid points** are stored as NaN in [`HeightMap::heights`] and counted in
//! [`HeightMap::invalid_points`]; [`HeightMap::check_usable`] refuses a map with invalid
//! points (a contact calculation needs every height), naming the count.
//!
//! **Channels**: [`read`] takes an optional channel name. An exact (case-insensitive) match wins,
//! else the first channel whose name contains the request; without one, the only channel of a
//! one-channel file whatever its name, else the first height-like name ("height", "topograph",
//! "z-axis", "zsensor") in a length unit, else the first channel in a length unit not named as
//! another signal (deflection, amplitude, phase, error, …). When no channel matches, the error
//! lists them all. The chosen channel's unit must still be a length.

pub mod al3d;
pub mod bcr;
pub mod container;
pub mod container_write;
pub mod createc;
pub mod frt;
pub mod gwy;
pub mod hdf5;
pub mod ibw;
pub mod jpk;
pub mod jpk_h5;
pub mod metropro;
pub mod mi;
pub mod mnt;
pub mod netcdf;
pub mod netcdf_write;
pub mod nid;
pub mod nms;
pub mod opd;
pub mod opdx;
pub mod park;
pub mod plu;
pub mod sdf;
pub mod sflz;
pub mod sur;
pub mod sxm;
pub mod tmd;
mod vendor;
pub mod x3p;
pub mod zon;

mod content;
mod gsf;
mod nanoscope;
mod npy;
mod text;
mod wsxm;

#[cfg(test)]
mod test_support;

use std::path::Path;

use ndarray::Array2;

use crate::error::{Error, Location, Result};
use crate::image::{SampleType, Samples};
use crate::ranges::Quantity;
use crate::tiff::metadata::length_unit_factor;
use crate::tiff::{TiffInfo, TiffReader};

pub use content::{read_height_map, READ_FORMATS};
pub use gsf::{encode_gsf, read_gsf};
pub use npy::{encode_npy, read_npy};
pub use vendor::MAX_FILE_BYTES;
pub(crate) use vendor::{
    choose, count, grid_bytes, height_like, height_map, length_factor, length_scale, line_scan,
    positive, ChannelEntry,
};
pub use vendor::{detect, detect_file, read, HeightMap, TopographyFormat};

/// How to read a height-map file: overrides for what the file does not say (or says wrongly).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// Pixel size (x, y), m, overriding the file's.
    pub pixel_size_m: Option<(f64, f64)>,
    /// Metres per stored height unit, for formats that state none (default: metres).
    pub height_unit_m: Option<f64>,
    /// Channel of a multi-channel vendor file, by name or by its place in the file's list (0,
    /// 1, …) (default: its height channel).
    pub channel: Option<String>,
}

impl HeightMap {
    /// Whether the map can be used for a contact calculation as it is: every point valid, the
    /// pixel size and the heights within their plausible ranges. The error names the file.
    pub fn check_usable(&self, path: &Path) -> Result<()> {
        if self.invalid_points > 0 {
            return Err(bad(
                path,
                format!(
                    "{} of {} points of channel '{}' are invalid (not measured); a contact \
                     calculation needs every height",
                    self.invalid_points,
                    self.heights.len(),
                    self.channel
                ),
            ));
        }
        let at = Location::file(path);
        Quantity::PixelSize.check_at(self.dx_m, &at)?;
        Quantity::PixelSize.check_at(self.dy_m, &at)?;
        // Which channel, where the file has several (a phase or potential channel whose
        // values are not heights).
        let channel = (self.channels.len() > 1).then_some(self.channel.as_str());
        plausible_heights(path, &self.heights, channel)
    }
}

/// The metres per stored value of a TIFF height map: the length unit its ImageJ description
/// states (`vunit=`, as contactscope's maps write it), else `height_unit_m`, else 1. A file that says
/// its values are something other than heights (`quantity=pressure`, a contact map, a
/// micrograph) is refused naming what it holds, and so is a `height_unit_m` beside a stated unit.
fn tiff_height_scale(path: &Path, info: &TiffInfo, height_unit_m: Option<f64>) -> Result<f64> {
    use crate::tiff::write::quantity;
    if let Some(q) = info.quantity.as_deref().filter(|q| *q != quantity::HEIGHT) {
        let unit = info
            .value_unit
            .as_deref()
            .map_or(String::new(), |u| format!(" in {u}"));
        let hint = match q {
            quantity::INTENSITY => "a micrograph: analyse it with `contactscope analyze`",
            quantity::CONTACT | quantity::CONTACT_MASK => {
                "a contact map: compare it with micrographs through `contactscope compare`"
            }
            _ => "the deformed surface of a simulation is its load_NNN_deformed_um.tif",
        };
        return Err(bad(
            path,
            format!(
                "the file holds {}{unit}, not heights ({hint})",
                q.replace('_', " ")
            ),
        ));
    }
    let Some(unit) = info.value_unit.as_deref() else {
        return unitless_scale(height_unit_m);
    };
    match (length_unit_factor(unit), info.quantity.is_some()) {
        (Some(factor), _) => {
            refuse_height_unit(path, height_unit_m, unit)?;
            Ok(factor)
        }
        (None, true) => Err(bad(
            path,
            format!("the file says its heights are in '{unit}', which is not a length"),
        )),
        // Another program's calibration unit that is not a length ("Gray Value"): it says
        // nothing about heights, which are then in the unit given, as for any TIFF.
        (None, false) => unitless_scale(height_unit_m),
    }
}

/// Read the first page of a float32/float64 TIFF. Pixel size: `pixel_size_m`, else the file's
/// calibration (`docs/conventions.md`, "Pixel size"), else an error. Heights are in the unit the
/// file states ([`tiff_height_scale`]), else multiplied by `height_unit_m` (default 1: metres).
pub fn read_tiff(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<HeightMap> {
    let mut reader = TiffReader::open(path)?;
    let info = reader.info().clone();
    let scale = tiff_height_scale(path, &info, height_unit_m)?;
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
    let mut map = topography(
        path,
        TopographyFormat::Tiff,
        (plane.height, plane.width),
        heights,
        (dx, dy),
    )?;
    if let (Some(_), Some(stated)) = (pixel_size_m, info.pixel_size) {
        map.dx_m = stated.x_m;
        map.dy_m = stated.y_m;
        map.replace_pixel_size((dx, dy));
    }
    Ok(map)
}

pub(crate) use crate::binary::bad;

/// Read a whole file.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    crate::inputs::note_input(path);
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
            format!(
                "{format} files carry no pixel size; give it with {}",
                crate::param::Param::PixelSize
            ),
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
    crate::binary::slice(path, data, offset, len, "the data")
}

/// Largest height magnitude of a height map read from a file, m: no rough surface reaches it,
/// and a map that does was almost always stored in another unit than the one assumed.
pub const MAX_FILE_HEIGHT_M: f64 = 1.0;

/// An error naming the file when a height lies beyond ±[`MAX_FILE_HEIGHT_M`].
pub(crate) fn plausible_heights(
    path: &Path,
    heights: &Array2<f64>,
    channel: Option<&str>,
) -> Result<()> {
    let nx = heights.ncols().max(1);
    let channel = channel.map_or(String::new(), |c| format!("channel '{c}': "));
    match heights.iter().position(|h| h.abs() > MAX_FILE_HEIGHT_M) {
        None => Ok(()),
        Some(k) => Err(bad(
            path,
            format!(
                "{channel}height at row {}, column {} is {:e} m, beyond ±{MAX_FILE_HEIGHT_M} m \
                 (heights in another unit, or not heights? see --height-unit)",
                k / nx,
                k % nx,
                heights.iter().nth(k).copied().unwrap_or(f64::NAN)
            ),
        )),
    }
}

/// Build the [`HeightMap`] of a format read by extension (one channel, "height"): the data must
/// fill the grid, every height must be finite and within ±[`MAX_FILE_HEIGHT_M`], the pixel size
/// within its plausible range; each error names the file.
pub(crate) fn topography(
    path: &Path,
    format: TopographyFormat,
    shape: (usize, usize),
    heights: Vec<f64>,
    pixel_size_m: (f64, f64),
) -> Result<HeightMap> {
    let array = Array2::from_shape_vec(shape, heights).map_err(|e| {
        bad(
            path,
            format!("data do not fill a {}×{} grid: {e}", shape.0, shape.1),
        )
    })?;
    let at = Location::file(path);
    Quantity::PixelSize.check_at(pixel_size_m.0, &at)?;
    Quantity::PixelSize.check_at(pixel_size_m.1, &at)?;
    plausible_heights(path, &array, None)?;
    if array.is_empty() {
        return Err(bad(path, "topography has no pixels"));
    }
    if let Some(k) = array.iter().position(|h| !h.is_finite()) {
        let nx = array.ncols();
        return Err(bad(
            path,
            format!(
                "height at row {}, column {} is not finite (NaN or ∞)",
                k / nx,
                k % nx
            ),
        ));
    }
    Ok(HeightMap {
        format,
        channel: "height".into(),
        channels: vec!["height".into()],
        height_channels: vec![true],
        heights: array,
        dx_m: pixel_size_m.0,
        dy_m: pixel_size_m.1,
        invalid_points: 0,
        replaced_pixel_size_m: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_file_names_it() {
        let err = read_height_map(Path::new("/nonexistent/a.gsf"), &ReadOptions::default())
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
