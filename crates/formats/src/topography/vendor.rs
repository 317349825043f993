//! The vendor AFM/profilometer formats of this folder, recognised by their content: the
//! [`HeightMap`] they read into, format detection, channel choice and the checks their readers
//! share. The table of formats is in the [parent module](super).

use std::path::Path;

use super::{
    al3d, bcr, createc, frt, gwy, hdf5, ibw, jpk, metropro, mi, mnt, nanoscope, netcdf, nid, nms,
    opd, opdx, park, plu, sdf, sflz, sur, sxm, tmd, wsxm, x3p, zon,
};

use ndarray::Array2;
use serde::Serialize;

use crate::binary::{bad, unsupported, FileSource};
use crate::error::Result;

/// Largest height-map file read whole into memory (bytes).
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// The AFM/profilometer formats of this module.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TopographyFormat {
    /// Igor binary wave (Asylum Research).
    Ibw,
    /// Nanosurf NID.
    Nid,
    /// Molecular Imaging / Agilent PicoView.
    Mi,
    /// Park Systems TIFF.
    ParkTiff,
    /// Gwyddion native.
    Gwy,
    /// ISO 25178-72 XML 3D surface profile.
    X3p,
    /// ISO 25178-71 surface data file (ASCII).
    Sdf,
    /// Wyko OPD.
    Opd,
    /// Sensofar PLU.
    Plu,
    /// Digital Surf SUR.
    Sur,
    /// FRT MicroProf.
    Frt,
    /// Alicona Imaging AL3D.
    Al3d,
    /// TrueMap TMD.
    Tmd,
    /// NanoFocus µsurf NMS.
    Nms,
    /// Image Metrology BCR-STM / BCRF.
    Bcr,
    /// Zygo MetroPro `.dat`.
    #[serde(rename = "metropro")]
    MetroPro,
    /// NetCDF classic / 64-bit offset (as SurfaceTopography writes height maps).
    #[serde(rename = "netcdf")]
    NetCdf,
    /// HDF5 (datasets as channels; no pixel size, no height unit).
    Hdf5,
    /// Digital Surf MountainsMap studiable (OLE2 container).
    Mnt,
    /// Bruker/Veeco Vision64 OPDx.
    Opdx,
    /// NumPy `.npy` array.
    Npy,
    /// float32/float64 TIFF.
    Tiff,
    /// Gwyddion Simple Field `.gsf`.
    Gsf,
    /// Text matrix, with or without a header (also gzip-compressed).
    Text,
    /// Keyence ZON (VR-series 3D macroscopes).
    Zon,
    /// `x y z` points on a regular grid (text).
    Xyz,
    /// WSxM image (`.top`, `.stp`, …).
    Wsxm,
    /// Bruker/Veeco Nanoscope (`.di`, `.spm`, `.001`, …).
    Nanoscope,
    /// Nanonis scan (`.sxm`).
    Sxm,
    /// JPK Instruments TIFF (`.jpk`, `.jpk-qi-image`).
    Jpk,
    /// TopoStats HDF5 (`.topostats`).
    #[serde(rename = "topostats")]
    TopoStats,
    /// surfalize's own `.sflz`.
    Sflz,
    /// Createc STM/AFM image (`.dat`, `[Paramco32]`).
    Createc,
    /// JPK Instruments HDF5 export (`.h5-jpk`).
    #[serde(rename = "jpk-h5")]
    JpkHdf5,
}

impl TopographyFormat {
    /// Short name, as `topography --json` prints it.
    pub fn name(self) -> &'static str {
        match self {
            TopographyFormat::Ibw => "ibw",
            TopographyFormat::Nid => "nid",
            TopographyFormat::Mi => "mi",
            TopographyFormat::ParkTiff => "park-tiff",
            TopographyFormat::Gwy => "gwy",
            TopographyFormat::X3p => "x3p",
            TopographyFormat::Sdf => "sdf",
            TopographyFormat::Opd => "opd",
            TopographyFormat::Plu => "plu",
            TopographyFormat::Sur => "sur",
            TopographyFormat::Frt => "frt",
            TopographyFormat::Al3d => "al3d",
            TopographyFormat::Tmd => "tmd",
            TopographyFormat::Nms => "nms",
            TopographyFormat::Bcr => "bcr",
            TopographyFormat::MetroPro => "metropro",
            TopographyFormat::NetCdf => "netcdf",
            TopographyFormat::Hdf5 => "hdf5",
            TopographyFormat::Mnt => "mnt",
            TopographyFormat::Opdx => "opdx",
            TopographyFormat::Npy => "npy",
            TopographyFormat::Tiff => "tiff",
            TopographyFormat::Gsf => "gsf",
            TopographyFormat::Text => "text",
            TopographyFormat::Xyz => "xyz",
            TopographyFormat::Wsxm => "wsxm",
            TopographyFormat::Nanoscope => "nanoscope",
            TopographyFormat::Sxm => "sxm",
            TopographyFormat::TopoStats => "topostats",
            TopographyFormat::Jpk => "jpk",
            TopographyFormat::Sflz => "sflz",
            TopographyFormat::Createc => "createc",
            TopographyFormat::JpkHdf5 => "jpk-h5",
            TopographyFormat::Zon => "zon",
        }
    }

    /// The name with its article as spoken (`an ibw`, `a gwy`, `a nanoscope`): abbreviations are
    /// spelt letter by letter.
    pub fn with_article(self) -> String {
        use TopographyFormat as F;
        let name = self.name();
        let word = matches!(
            self,
            F::ParkTiff | F::MetroPro | F::NetCdf | F::Tiff | F::Text | F::Nanoscope | F::TopoStats
        );
        let sounds = match word {
            true => "aeiou",
            // The letters whose spoken names start with a vowel (eff, aitch, el, em, …).
            false => "aefhilmnorsx",
        };
        let article = match name.starts_with(|c: char| sounds.contains(c)) {
            true => "an",
            false => "a",
        };
        format!("{article} {name}")
    }

    /// Whether files of this format state the unit of their heights (HDF5 files do not: their
    /// heights are in metres unless a height unit is given).
    pub fn states_height_unit(self) -> bool {
        !matches!(self, TopographyFormat::Hdf5)
    }
}

/// A height map read from a file, with the channel it came from and its invalid points.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightMap {
    /// The file's format.
    pub format: TopographyFormat,
    /// The channel read.
    pub channel: String,
    /// Every channel of the file.
    pub channels: Vec<String>,
    /// Whether each of `channels` holds heights (a length unit, or a height-like name where the
    /// file states no unit).
    pub height_channels: Vec<bool>,
    /// Heights in metres, shape `(ny, nx)`; NaN where the instrument marked no valid point.
    pub heights: Array2<f64>,
    /// Pixel size along x (columns), m; NaN (with `dy_m`) when the file states none, as
    /// [`read`] returns it (`read_height_map` then requires one).
    pub dx_m: f64,
    /// Pixel size along y (rows), m; NaN when the file states none.
    pub dy_m: f64,
    /// Number of NaN heights.
    pub invalid_points: usize,
    /// The pixel size (x, y) the file states, m, when a pixel size given as an argument replaced
    /// it (`dx_m`, `dy_m` are then the argument's); `None` otherwise.
    pub replaced_pixel_size_m: Option<(f64, f64)>,
}

impl HeightMap {
    /// Use `pixel_size_m` instead of the file's own, recording the file's when it states one
    /// that differs.
    pub(crate) fn replace_pixel_size(&mut self, (dx, dy): (f64, f64)) {
        let stated = (self.dx_m, self.dy_m);
        if stated.0.is_finite() && stated.1.is_finite() && stated != (dx, dy) {
            self.replaced_pixel_size_m = Some(stated);
        }
        self.dx_m = dx;
        self.dy_m = dy;
    }

    /// Columns.
    pub fn nx(&self) -> usize {
        self.heights.ncols()
    }

    /// Rows.
    pub fn ny(&self) -> usize {
        self.heights.nrows()
    }

    /// Points with a height.
    pub fn valid_points(&self) -> usize {
        self.heights.len() - self.invalid_points
    }
}

/// The format of a file from its first bytes (at least 64; Park TIFFs need the whole first IFD,
/// see [`detect_file`]), or `None`.
pub fn detect(head: &[u8]) -> Option<TopographyFormat> {
    let starts = |m: &[u8]| head.starts_with(m);
    if starts(b"GWYP") {
        Some(TopographyFormat::Gwy)
    } else if starts(b"DIGITAL SURF") {
        Some(TopographyFormat::Sur)
    } else if starts(b"FRTM_GLIDERV") {
        Some(TopographyFormat::Frt)
    } else if starts(b"aISO-1.0") {
        Some(TopographyFormat::Sdf)
    } else if starts(b"[DataSet]") {
        Some(TopographyFormat::Nid)
    } else if starts(b"fileType      Image") {
        Some(TopographyFormat::Mi)
    } else if head.get(2..11) == Some(b"Directory") {
        Some(TopographyFormat::Opd)
    } else if starts(b"\\*File list") || starts(b"\\*Force file list") {
        Some(TopographyFormat::Nanoscope)
    } else if starts(b"WSxM file copyright") {
        Some(TopographyFormat::Wsxm)
    } else if sxm::is_sxm(head) {
        Some(TopographyFormat::Sxm)
    } else if starts(al3d::MAGIC) {
        Some(TopographyFormat::Al3d)
    } else if starts(tmd::MAGIC) {
        Some(TopographyFormat::Tmd)
    } else if starts(sflz::MAGIC) {
        Some(TopographyFormat::Sflz)
    } else if starts(createc::MAGIC) {
        Some(TopographyFormat::Createc)
    } else if starts(b"KPK0") || starts(b"KPK1") {
        Some(TopographyFormat::Zon)
    } else if head.get(nms::VERSION_AT..nms::VERSION_AT + nms::VERSION.len()) == Some(nms::VERSION)
    {
        Some(TopographyFormat::Nms)
    } else if bcr::is_bcr(head) {
        Some(TopographyFormat::Bcr)
    } else if starts(b"PK\x03\x04") {
        Some(TopographyFormat::X3p)
    } else if starts(opdx::MAGIC) {
        Some(TopographyFormat::Opdx)
    } else if starts(&mnt::OLE2_MAGIC) {
        // Any OLE2 compound file: the MNT reader refuses those that are not studiables.
        Some(TopographyFormat::Mnt)
    } else if ibw::is_ibw(head) {
        Some(TopographyFormat::Ibw)
    } else if metropro::is_metropro(head) {
        Some(TopographyFormat::MetroPro)
    } else if netcdf::is_netcdf(head) {
        Some(TopographyFormat::NetCdf)
    } else if starts(hdf5::SIGNATURE) {
        Some(TopographyFormat::Hdf5)
    } else {
        None
    }
}

/// The format of a file from its content: [`detect`], then Park TIFF (a TIFF whose first IFD
/// has tag 50432 = `0x0E031301`), then Sensofar PLU (whose layout has no magic: recognised when
/// its header's sizes account for the file).
pub fn detect_file(path: &Path) -> Result<Option<TopographyFormat>> {
    let mut source = FileSource::open(path)?;
    let head = source.read_up_to(0, 64)?;
    if let Some(f) = detect(&head) {
        return Ok(Some(f));
    }
    let tiff = head.starts_with(b"II*\0") || head.starts_with(b"MM\0*");
    if tiff && park::is_park(&mut source)? {
        return Ok(Some(TopographyFormat::ParkTiff));
    }
    if tiff && jpk::is_jpk(&mut source)? {
        return Ok(Some(TopographyFormat::Jpk));
    }
    if plu::is_plu(&mut source)? {
        return Ok(Some(TopographyFormat::Plu));
    }
    Ok(None)
}

/// Read a height map, detecting the format from the content; `channel` selects a channel by
/// name (module docs).
pub fn read(path: &Path, channel: Option<&str>) -> Result<HeightMap> {
    let format = detect_file(path)?.ok_or_else(|| {
        unsupported(
            path,
            "not a height-map format contactscope recognises from its content (ibw, nid, mi, \
             Park TIFF, gwy, x3p, sdf, opd, plu, sur, frt, al3d, tmd, nms, bcr/bcrf, metropro, netcdf, hdf5, mnt, opdx, \
             nanoscope, wsxm, sxm, jpk, sflz, createc, zon)",
        )
    })?;
    match format {
        TopographyFormat::X3p => x3p::read(path, channel),
        TopographyFormat::Mnt => mnt::read(path, channel),
        other => {
            let bytes = read_whole(path)?;
            match other {
                TopographyFormat::Ibw => ibw::read(path, &bytes, channel),
                TopographyFormat::Nid => nid::read(path, &bytes, channel),
                TopographyFormat::Mi => mi::read(path, &bytes, channel),
                TopographyFormat::ParkTiff => park::read(path, &bytes, channel),
                TopographyFormat::Gwy => gwy::read(path, &bytes, channel),
                TopographyFormat::Sdf => sdf::read(path, &bytes, channel),
                TopographyFormat::Opd => opd::read(path, &bytes, channel),
                TopographyFormat::Plu => plu::read(path, &bytes, channel),
                TopographyFormat::Sur => sur::read(path, &bytes, channel),
                TopographyFormat::Frt => frt::read(path, &bytes, channel),
                TopographyFormat::Nanoscope => nanoscope::read(path, &bytes, channel),
                TopographyFormat::Wsxm => wsxm::read(path, &bytes, channel),
                TopographyFormat::Sxm => sxm::read(path, &bytes, channel),
                TopographyFormat::Jpk => jpk::read(path, &bytes, channel),
                TopographyFormat::Al3d => al3d::read(path, &bytes, channel),
                TopographyFormat::Tmd => tmd::read(path, &bytes, channel),
                TopographyFormat::Sflz => sflz::read(path, &bytes, channel),
                TopographyFormat::Createc => createc::read(path, &bytes, channel),
                TopographyFormat::Nms => nms::read(path, &bytes, channel),
                TopographyFormat::Bcr => bcr::read(path, &bytes, channel),
                TopographyFormat::MetroPro => metropro::read(path, &bytes, channel),
                TopographyFormat::NetCdf => netcdf::read(path, &bytes, channel),
                TopographyFormat::Hdf5 => hdf5::read(path, &bytes, channel),
                TopographyFormat::Opdx => opdx::read(path, &bytes, channel),
                TopographyFormat::Zon => zon::read(path, &bytes, channel),
                TopographyFormat::X3p
                | TopographyFormat::Mnt
                | TopographyFormat::Npy
                | TopographyFormat::Tiff
                | TopographyFormat::Gsf
                | TopographyFormat::Text
                | TopographyFormat::Xyz
                | TopographyFormat::TopoStats
                | TopographyFormat::JpkHdf5 => unreachable!("not detected by content"),
            }
        }
    }
}

/// The file opened for reading, refused above [`MAX_FILE_BYTES`].
pub(crate) fn open_limited(path: &Path) -> Result<FileSource> {
    let source = FileSource::open(path)?;
    if source.len > MAX_FILE_BYTES {
        return Err(unsupported(
            path,
            format!(
                "file of {} bytes is larger than the {} GiB limit",
                source.len,
                MAX_FILE_BYTES >> 30
            ),
        ));
    }
    Ok(source)
}

/// The whole file, refused above [`MAX_FILE_BYTES`].
fn read_whole(path: &Path) -> Result<Vec<u8>> {
    let mut source = open_limited(path)?;
    source.read_at(0, source.len as usize, "the file")
}

/// One channel as a reader lists it.
#[derive(Debug, Clone)]
pub(crate) struct ChannelEntry {
    /// Name shown to the user.
    pub name: String,
    /// Whether its values are heights (a length unit, or a height-like name).
    pub height: bool,
}

/// Pick a channel (module docs); the error lists every channel.
pub(crate) fn choose(
    path: &Path,
    channels: &[ChannelEntry],
    request: Option<&str>,
) -> Result<usize> {
    let list = || {
        channels
            .iter()
            .map(|c| format!("'{}'", c.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if channels.is_empty() {
        return Err(bad(path, "the file holds no data channel"));
    }
    match request {
        // The exact name first, then a position in the list (0, 1, …: what a SurfaceTopography
        // container's `data_source` and a file with two channels of one name need), then the
        // first name containing the text.
        Some(want) => {
            let want_l = want.to_lowercase();
            let exact = channels
                .iter()
                .position(|c| c.name.to_lowercase() == want_l);
            let place = want.trim().parse::<usize>().ok();
            exact
                .or_else(|| place.filter(|&k| k < channels.len()))
                .or_else(|| {
                    channels
                        .iter()
                        .position(|c| c.name.to_lowercase().contains(&want_l))
                })
                .ok_or_else(|| {
                    let reason = match place {
                        Some(k) => format!(
                            "no channel {k} (channels count from 0); the file has {} \
                             channel(s): {}",
                            channels.len(),
                            list()
                        ),
                        None => format!("no channel '{want}'; the file has {}", list()),
                    };
                    bad(path, reason)
                })
        }
        // A file of one channel holds nothing else to choose: its channel is read whatever its
        // name (the reader still refuses a unit that is not a length).
        None if channels.len() == 1 => Ok(0),
        // A height-like name first; then any channel in a length unit that is not named as
        // another signal (an amplitude error or a deflection can be in nm too).
        None => channels
            .iter()
            .position(|c| c.height && height_like(&c.name))
            .or_else(|| {
                channels
                    .iter()
                    .position(|c| c.height && !signal_like(&c.name))
            })
            .ok_or_else(|| {
                bad(
                    path,
                    format!(
                        "no height channel; the file has {} (choose one by name)",
                        list()
                    ),
                )
            }),
    }
}

/// Whether a channel name names a signal other than the height (never chosen by default).
pub(crate) fn signal_like(name: &str) -> bool {
    let n = name.to_lowercase();
    [
        "deflection",
        "amplitude",
        "phase",
        "error",
        "friction",
        "current",
        "force",
        "potential",
        "adhesion",
        "modulus",
        "dissipation",
        "lateral",
        "intensity",
        "frequency",
    ]
    .iter()
    .any(|k| n.contains(k))
}

/// Whether a channel name looks like heights.
pub(crate) fn height_like(name: &str) -> bool {
    let n = name.to_lowercase();
    ["height", "topograph", "z-axis", "zsensor", "z sensor"]
        .iter()
        .any(|k| n.contains(k))
}

/// Metres per unit of a length unit string, or `None` (accepts `µm`, `um`, `\u{e6}m`, `~m`).
pub(crate) fn length_factor(unit: &str) -> Option<f64> {
    let u = unit.trim().trim_end_matches('\0').trim();
    let u = match u {
        "\u{e6}m" | "~m" | "um" => "µm",
        other => other,
    };
    crate::tiff::metadata::length_unit_factor(u)
}

/// Metres per unit of the chosen channel's unit, or an error naming the channel: a channel in
/// volts, degrees or newtons is refused rather than scaled as metres.
pub(crate) fn length_scale(path: &Path, channel: &ChannelEntry, unit: &str) -> Result<f64> {
    length_factor(unit).ok_or_else(|| {
        bad(
            path,
            format!("channel '{}' is in '{unit}', not a length", channel.name),
        )
    })
}

/// Build a [`HeightMap`] from row-major values (NaN = invalid), checking the size. A pixel size
/// of (NaN, NaN) says the file states none.
pub(crate) fn height_map(
    path: &Path,
    format: TopographyFormat,
    (channels, index): (&[ChannelEntry], usize),
    (ny, nx): (usize, usize),
    heights: Vec<f64>,
    (dx_m, dy_m): (f64, f64),
) -> Result<HeightMap> {
    if nx == 0 || ny == 0 {
        return Err(bad(path, format!("empty {nx}×{ny} height map")));
    }
    let stated_positive = dx_m.is_finite() && dy_m.is_finite() && dx_m > 0.0 && dy_m > 0.0;
    if !(stated_positive || dx_m.is_nan() && dy_m.is_nan()) {
        return Err(bad(
            path,
            format!("pixel size {dx_m} × {dy_m} m is not positive"),
        ));
    }
    let heights = Array2::from_shape_vec((ny, nx), heights)
        .map_err(|_| bad(path, format!("data do not fill a {ny}×{nx} grid")))?;
    let invalid_points = heights.iter().filter(|h| !h.is_finite()).count();
    let heights = heights.mapv(|h| if h.is_finite() { h } else { f64::NAN });
    Ok(HeightMap {
        format,
        channel: channels[index].name.clone(),
        channels: channels.iter().map(|c| c.name.clone()).collect(),
        height_channels: channels.iter().map(|c| c.height).collect(),
        heights,
        dx_m,
        dy_m,
        invalid_points,
        replaced_pixel_size_m: None,
    })
}

/// `nx·ny` samples of `width` bytes: checks the size limit first.
pub(crate) fn grid_bytes(path: &Path, nx: usize, ny: usize, width: usize) -> Result<usize> {
    crate::limits::Limits::DEFAULT
        .plane_bytes(nx, ny, width)
        .map_err(|reason| unsupported(path, format!("height map: {reason} (header corrupt?)")))
}

/// The refusal of a one-dimensional profile: what the file holds and what a contact calculation
/// needs, in one line. `dx_m` is the point spacing when the file states one.
pub(crate) fn line_scan(path: &Path, points: usize, dx_m: Option<f64>) -> crate::error::Error {
    let spacing = dx_m.map_or(String::new(), |d| format!(" spaced {d:e} m"));
    unsupported(
        path,
        format!(
            "the file holds a line scan (one profile of {points} points{spacing}), not a height \
             map; topography and simulate need a 2-D map of heights"
        ),
    )
}

/// Positive finite size or an error naming it.
pub(crate) fn positive(path: &Path, what: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(bad(path, format!("{what} is {v}; it must be positive")))
    }
}

/// A count read from a header, as usize, checked to be positive and below 2^28.
pub(crate) fn count(path: &Path, what: &str, v: f64) -> Result<usize> {
    if v.is_finite() && v >= 1.0 && v < f64::from(1u32 << 28) {
        Ok(v as usize)
    } else {
        Err(bad(path, format!("{what} is {v}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(names: &[(&str, bool)]) -> Vec<ChannelEntry> {
        names
            .iter()
            .map(|(n, h)| ChannelEntry {
                name: n.to_string(),
                height: *h,
            })
            .collect()
    }

    #[test]
    fn channel_choice() {
        let p = Path::new("a.ibw");
        let c = entries(&[
            ("Amplitude", false),
            ("HeightTrace", true),
            ("HeightRetrace", true),
        ]);
        assert_eq!(choose(p, &c, None).unwrap(), 1);
        assert_eq!(choose(p, &c, Some("heightretrace")).unwrap(), 2);
        assert_eq!(choose(p, &c, Some("Height")).unwrap(), 1);
        let err = choose(p, &c, Some("Phase")).unwrap_err().to_string();
        assert!(
            err.contains("'Amplitude', 'HeightTrace', 'HeightRetrace'"),
            "{err}"
        );
        // One channel is read whatever its name; of several, a height channel is needed.
        assert_eq!(choose(p, &entries(&[("layer 0", false)]), None).unwrap(), 0);
        let two = entries(&[("layer 0", false), ("layer 1", false)]);
        let err = choose(p, &two, None).unwrap_err().to_string();
        assert!(
            err.contains("no height channel") && err.contains("a.ibw"),
            "{err}"
        );
        assert!(choose(p, &entries(&[]), None).is_err());
        // A deflection or amplitude error in nm is never the default.
        let signals = entries(&[("Deflection", true), ("AmplitudeError", true), ("Z", true)]);
        assert_eq!(choose(p, &signals, None).unwrap(), 2);
        let only = entries(&[("Deflection", true), ("Phase", false)]);
        assert!(choose(p, &only, None).is_err());
        // By position: after an exact name (a channel named "1" is that channel), before a
        // name containing the digits (which a number beyond the list still finds); else an
        // error that counts them.
        assert_eq!(choose(p, &c, Some("2")).unwrap(), 2);
        assert_eq!(choose(p, &c, Some(" 0 ")).unwrap(), 0);
        let numbered = entries(&[("Height 2", true), ("Phase", false), ("0", true)]);
        assert_eq!(choose(p, &numbered, Some("0")).unwrap(), 2);
        assert_eq!(choose(p, &numbered, Some("2")).unwrap(), 2);
        assert_eq!(choose(p, &numbered, Some("1")).unwrap(), 1);
        let seventh = entries(&[("Height 7", true), ("Phase", false)]);
        assert_eq!(choose(p, &seventh, Some("7")).unwrap(), 0);
        let err = choose(p, &c, Some("3")).unwrap_err().to_string();
        assert!(
            err.contains("no channel 3 (channels count from 0)") && err.contains("3 channel(s)"),
            "{err}"
        );
    }

    #[test]
    fn detection_by_magic() {
        assert_eq!(detect(b"GWYPGwyContainer"), Some(TopographyFormat::Gwy));
        assert_eq!(detect(b"\x01\x00Directory"), Some(TopographyFormat::Opd));
        assert_eq!(detect(b"FRTM_GLIDERV1.00"), Some(TopographyFormat::Frt));
        assert_eq!(
            detect(b"AliconaImaging\0\r\nVersion"),
            Some(TopographyFormat::Al3d)
        );
        assert_eq!(
            detect(b"Binary TrueMap Data File v2.0\r\n\0"),
            Some(TopographyFormat::Tmd)
        );
        let mut nms = [0u8; 64];
        nms[32..41].copy_from_slice(b"OM_MS_2.0");
        assert_eq!(detect(&nms), Some(TopographyFormat::Nms));
        assert_eq!(detect(b"fileformat = bcrf\n"), Some(TopographyFormat::Bcr));
        let wide: Vec<u8> = "fileformat = bcrf_unicode"
            .encode_utf16()
            .flat_map(u16::to_le_bytes)
            .collect();
        assert_eq!(detect(&wide), Some(TopographyFormat::Bcr));
        assert_eq!(detect(b"fileformat = other"), None);
        assert_eq!(
            detect(b"VCA DATA\x01\x00\x00\x55"),
            Some(TopographyFormat::Opdx)
        );
        assert_eq!(
            detect(b"\xD0\xCF\x11\xE0\xA1\xB1\x1A\xE1\0\0"),
            Some(TopographyFormat::Mnt)
        );
        assert_eq!(detect(b"%PDF-1.4"), None);
        assert_eq!(length_factor("\u{e6}m"), Some(1e-6));
        assert_eq!(length_factor("V"), None);
    }

    #[test]
    fn invalid_points_are_counted() {
        let c = entries(&[("h", true)]);
        let p = Path::new("m.sur");
        let m = height_map(
            p,
            TopographyFormat::Sur,
            (&c, 0),
            (2, 2),
            vec![1.0, f64::NAN, 2.0, f64::INFINITY],
            (1e-6, 1e-6),
        )
        .unwrap();
        assert_eq!((m.invalid_points, m.valid_points()), (2, 2));
        assert!(height_map(
            p,
            TopographyFormat::Sur,
            (&c, 0),
            (2, 2),
            vec![0.0; 3],
            (1e-6, 1e-6)
        )
        .is_err());
    }
}

#[cfg(test)]
mod article_tests {
    use super::TopographyFormat as F;

    #[test]
    fn names_take_the_article_they_are_spoken_with() {
        assert_eq!(F::Ibw.with_article(), "an ibw");
        assert_eq!(F::Sdf.with_article(), "an sdf");
        assert_eq!(F::Gwy.with_article(), "a gwy");
        assert_eq!(F::Nanoscope.with_article(), "a nanoscope");
        assert_eq!(F::MetroPro.with_article(), "a metropro");
        assert_eq!(F::Opdx.with_article(), "an opdx");
    }
}
