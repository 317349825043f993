//! Confocal microscopy files as one model: Zeiss CZI ([`czi`]), Nikon ND2 ([`nd2`]), Leica LIF
//! ([`lif`]) and, described the same way, TIFF ([`crate::tiff`]).
//!
//! A [`MicroscopyFile`] holds a list of [`SeriesInfo`] (CZI scenes, LIF images, the images of
//! a multi-image OME-TIFF; ND2 and other TIFFs have one series) read from the headers only; [`MicroscopyFile::read_plane`] decodes one 2-D
//! plane on request into a [`Plane`] (u16 codes plus offset, or f32), reading just the bytes it
//! needs. Every count and size taken from a header is checked against the file length and
//! against [`MAX_PLANE_BYTES`] before anything is allocated.
//!
//! Axes: `T` (time), `Z`, `C` (channel), `Y`, `X`, and extra axes named in [`Axes::extra`]:
//! `H` (Airyscan detector phase), `S` (colour samples of a BGR pixel, 0 = blue, 1 = green,
//! 2 = red, in the stored order), `lambda_emission`, `lambda_excitation` (LIF spectral sweeps) and
//! any other CZI dimension (`R`, `I`, `V`, `B`). CZI mosaic tiles (`M`) are not an axis: they are
//! placed at their stage offsets into the series' bounding box.
//!
//! Scans without a y axis ([`Rows`]): a series of one-pixel-high lines (Y absent or of one
//! element) along a Z or T axis longer than 1 is an X–Z section or an X–T line scan, as the
//! acquisition software shows it (LAS X for `XZ`/`XT` modes, ZEN, NIS-Elements): one image per
//! channel (and per remaining t) whose rows are the scanned axis, read line by line from the
//! reader's planes. The y pixel size of an X–Z image is the z step; an X–T image has none (a
//! line time is no length).
//!
//! The format is detected from the first bytes of the file ([`detect`]), not the extension.

mod clx;
pub mod czi;
pub mod lif;
pub mod nd2;
mod ngff;
pub mod select;
pub mod summary;
mod tiff;
pub mod zarr;
mod zarr_ahead;
pub mod zarr_write;

pub use tiff::{series_of_tiff, set_member, tiff_series, LoadDefault, TiffPage};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

pub use super::binary::MAX_PLANE_BYTES;
use super::binary::{bad, checked_bytes, unsupported};
use crate::error::Result;
use crate::image::{Plane, SampleType, Samples};

/// Which reader a file needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MicroscopyFormat {
    /// Zeiss CZI (`ZISRAWFILE` segment first).
    Czi,
    /// Nikon ND2, version 2 or 3 (chunked; `0x0ABECEDA` chunk magic first).
    Nd2,
    /// Leica LIF (`0x70` block magic, then an XML header).
    Lif,
    /// TIFF, classic or BigTIFF, either byte order.
    Tiff,
    /// OME-Zarr (OME-NGFF 0.4 on Zarr v2, 0.5 on Zarr v3): a folder, not a file ([`zarr`]).
    #[serde(rename = "ome-zarr")]
    OmeZarr,
}

impl MicroscopyFormat {
    /// Lowercase name, as `info --json` prints it.
    pub fn name(self) -> &'static str {
        match self {
            MicroscopyFormat::Czi => "czi",
            MicroscopyFormat::Nd2 => "nd2",
            MicroscopyFormat::Lif => "lif",
            MicroscopyFormat::Tiff => "tiff",
            MicroscopyFormat::OmeZarr => "ome-zarr",
        }
    }
}

/// The format of a file from its first bytes (at least 16 are needed for CZI), or `None`.
pub fn detect(head: &[u8]) -> Option<MicroscopyFormat> {
    if head.starts_with(b"ZISRAWFILE") {
        Some(MicroscopyFormat::Czi)
    } else if head.starts_with(&[0xda, 0xce, 0xbe, 0x0a]) {
        Some(MicroscopyFormat::Nd2)
    } else if head.len() >= 9 && head[..4] == [0x70, 0, 0, 0] && head[8] == 0x2a {
        Some(MicroscopyFormat::Lif)
    } else if head.starts_with(b"II*\0")
        || head.starts_with(b"MM\0*")
        || head.starts_with(b"II+\0")
        || head.starts_with(b"MM\0+")
    {
        Some(MicroscopyFormat::Tiff)
    } else {
        None
    }
}

/// Sizes of the axes of one series. `T`, `Z` and `C` are always present (1 when the file has no
/// such axis); other axes are listed in `extra` by name.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Axes {
    /// Time points.
    #[serde(rename = "T")]
    pub t: usize,
    /// Focal planes.
    #[serde(rename = "Z")]
    pub z: usize,
    /// Channels.
    #[serde(rename = "C")]
    pub c: usize,
    /// Rows.
    #[serde(rename = "Y")]
    pub y: usize,
    /// Columns.
    #[serde(rename = "X")]
    pub x: usize,
    /// Further axes (`H`, `S`, `lambda_emission`, …) with more than one element.
    #[serde(flatten)]
    pub extra: BTreeMap<String, usize>,
}

impl Axes {
    /// Number of 2-D planes.
    pub fn planes(&self) -> usize {
        self.extra.values().product::<usize>() * self.t * self.z * self.c
    }
}

/// Voxel size in metres (each optional) and the metadata element it came from.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct VoxelSize {
    /// Along x (columns).
    pub x_m: Option<f64>,
    /// Along y (rows).
    pub y_m: Option<f64>,
    /// Between focal planes.
    pub z_m: Option<f64>,
    /// Which metadata element gave x and y (`None` when absent).
    pub source: Option<String>,
}

impl VoxelSize {
    /// A size from metadata: non-finite or non-positive values count as absent (CZI writes 0
    /// for "not calibrated").
    pub(crate) fn valid(v: Option<f64>) -> Option<f64> {
        v.filter(|v| v.is_finite() && *v > 0.0)
    }
}

/// What is known of one channel.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct ChannelInfo {
    /// Name as the acquisition software wrote it.
    pub name: Option<String>,
    /// Emission wavelength, m.
    pub emission_wavelength_m: Option<f64>,
    /// Excitation wavelength, m.
    pub excitation_wavelength_m: Option<f64>,
}

/// What the rows of a series' images are (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub enum Rows {
    /// Lines along y: an X–Y image.
    #[default]
    Y,
    /// Focal planes: an X–Z section (a scan without a y axis); `axes.z` is then 1.
    Z,
    /// Time points: an X–T line scan (no y axis, no z); `axes.t` is then 1.
    T,
}

impl Rows {
    /// Whether rows are y (the usual image).
    pub fn is_y(&self) -> bool {
        *self == Rows::Y
    }

    /// `X–Y image`, `X–Z section`, `X–T line scan`, for summaries.
    pub fn describe(self) -> &'static str {
        match self {
            Rows::Y => "X–Y image",
            Rows::Z => "X–Z section (rows are focal planes)",
            Rows::T => "X–T line scan (rows are time points)",
        }
    }
}

/// One series (CZI scene, LIF image, OME-TIFF image, the whole ND2 or other TIFF file).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeriesInfo {
    /// Zero-based index in the file.
    pub index: usize,
    /// Name (LIF element path, CZI scene name), or empty.
    pub name: String,
    /// Axis sizes.
    pub axes: Axes,
    /// Sample type of one plane.
    pub dtype: SampleType,
    /// Voxel size and its source.
    pub pixel_size: VoxelSize,
    /// One entry per channel (`axes.c` of them).
    pub channels: Vec<ChannelInfo>,
    /// What the image rows are: y, or the scanned axis of a scan without y (module docs).
    #[serde(skip_serializing_if = "Rows::is_y")]
    pub rows: Rows,
    /// Where a TIFF's axes come from (OME-XML, ImageJ, plain pages); `None` for other formats.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tiff_axes: Option<crate::tiff::AxesSource>,
}

impl SeriesInfo {
    /// The series as images whose rows are the scanned axis when it has no y axis (Y of one
    /// element) but a Z (else T) axis longer than 1 (module docs); any other series as it is.
    /// The y pixel size of an X–Z section is the z step; an X–T scan has none.
    pub fn as_line_scan(mut self) -> SeriesInfo {
        let a = &mut self.axes;
        if a.y != 1 || !self.rows.is_y() {
            return self;
        }
        let p = &mut self.pixel_size;
        if a.z > 1 {
            (a.y, a.z, self.rows) = (a.z, 1, Rows::Z);
            p.y_m = p.z_m.take();
            if p.y_m.is_some() {
                let x = p.source.as_deref().unwrap_or("the file");
                p.source = Some(format!("{x}; y: the z step of the X–Z scan"));
            }
        } else if a.t > 1 {
            (a.y, a.t, self.rows) = (a.t, 1, Rows::T);
            p.y_m = None;
        }
        self
    }
}

/// Which plane of a series: `t`, `z`, `c` and the extra axes by name (missing ones are 0).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct PlaneIndex {
    /// Time point.
    pub t: usize,
    /// Focal plane.
    pub z: usize,
    /// Channel.
    pub c: usize,
    /// Indices along the extra axes.
    #[serde(flatten)]
    pub extra: BTreeMap<String, usize>,
}

impl PlaneIndex {
    /// Index `(t, z, c)` with every extra axis at 0.
    pub fn tzc(t: usize, z: usize, c: usize) -> Self {
        PlaneIndex {
            t,
            z,
            c,
            extra: BTreeMap::new(),
        }
    }

    /// The index along an extra axis (0 when not given).
    pub fn get(&self, axis: &str) -> usize {
        self.extra.get(axis).copied().unwrap_or(0)
    }

    /// Every plane of `axes`, in the order t, z, c, then the extra axes by name (last fastest).
    pub fn all(axes: &Axes) -> Vec<PlaneIndex> {
        let mut out = Vec::with_capacity(axes.planes());
        let extra: Vec<(&String, &usize)> = axes.extra.iter().collect();
        let n_extra: usize = extra.iter().map(|(_, n)| **n).product();
        for t in 0..axes.t {
            for z in 0..axes.z {
                for c in 0..axes.c {
                    for mut k in 0..n_extra {
                        let mut idx = PlaneIndex::tzc(t, z, c);
                        for (name, n) in extra.iter().rev() {
                            idx.extra.insert((*name).clone(), k % **n);
                            k /= **n;
                        }
                        out.push(idx);
                    }
                }
            }
        }
        out
    }

    /// Check the index against the series' axes.
    fn check(&self, path: &Path, series: &SeriesInfo) -> Result<()> {
        let a = &series.axes;
        let mut checks = vec![("T", self.t, a.t), ("Z", self.z, a.z), ("C", self.c, a.c)];
        for (name, &n) in &a.extra {
            checks.push((name.as_str(), self.get(name), n));
        }
        for (name, i, n) in checks {
            if i >= n {
                return Err(bad(
                    path,
                    format!(
                        "series {}: {name} = {i} requested, the series has {n}",
                        series.index
                    ),
                ));
            }
        }
        if let Some(name) = self.extra.keys().find(|k| !a.extra.contains_key(*k)) {
            return Err(bad(
                path,
                format!("series {} has no axis '{name}'", series.index),
            ));
        }
        Ok(())
    }
}

enum Backend {
    Czi(Box<czi::CziReader>),
    Nd2(Box<nd2::Nd2Reader>),
    Lif(Box<lif::LifReader>),
    Tiff(Box<tiff::TiffBackend>),
    Zarr(Box<zarr::ZarrReader>),
}

/// An open microscopy file: its series, and a reader of their planes.
pub struct MicroscopyFile {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: MicroscopyFormat,
    /// Its series.
    pub series: Vec<SeriesInfo>,
    /// The series as the reader describes them (line scans still one plane per line).
    stored: Vec<SeriesInfo>,
    backend: Backend,
}

impl std::fmt::Debug for MicroscopyFile {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MicroscopyFile")
            .field("path", &self.path)
            .field("format", &self.format)
            .field("series", &self.series)
            .finish_non_exhaustive()
    }
}

impl MicroscopyFile {
    /// Open a file, detecting its format from its first bytes, and read its headers.
    pub fn open(path: &Path) -> Result<Self> {
        if zarr::is_store(path) {
            let r = zarr::ZarrReader::open(path)?;
            let series: Vec<SeriesInfo> = r.series();
            return Ok(MicroscopyFile {
                path: path.to_path_buf(),
                format: MicroscopyFormat::OmeZarr,
                series: series
                    .iter()
                    .cloned()
                    .map(SeriesInfo::as_line_scan)
                    .collect(),
                stored: series,
                backend: Backend::Zarr(Box::new(r)),
            });
        }
        if crate::topography::container::is_container(path) {
            return Err(unsupported(
                path,
                "a contact.engineering surface container of height maps, not a micrograph: \
                 read it with `contactscope topography` (or `simulate --topography`)",
            ));
        }
        if path.is_dir() {
            return Err(unsupported(
                path,
                "a folder that is not a Zarr store (no zarr.json, .zgroup or .zattrs in it)",
            ));
        }
        let mut source = super::binary::FileSource::open(path)?;
        let head = source.read_up_to(0, 64)?;
        // An OME companion file: the TIFF set it describes ([`crate::tiff::companion`]).
        let mut companion = || -> Result<bool> {
            Ok(!crate::remote::is_url(path)
                && crate::tiff::companion::looks_like_ome_xml(
                    &source.read_up_to(0, crate::tiff::companion::HEAD_BYTES)?,
                ))
        };
        let format = match detect(&head) {
            None if companion()? => Some(MicroscopyFormat::Tiff),
            found => found,
        };
        let format = format.ok_or_else(|| match crate::topography::detect(&head) {
            // A height map given where a micrograph is expected: say which command reads it.
            Some(map) => {
                // Its channels, when the map reads, so that `--channel` can be chosen from here.
                let channels = crate::topography::read(path, None)
                    .map(|m| {
                        let names: Vec<String> =
                            m.channels.iter().map(|c| format!("'{c}'")).collect();
                        format!(" with channels {}", names.join(", "))
                    })
                    .unwrap_or_default();
                unsupported(
                    path,
                    format!(
                        "{} height map{channels}, not a CZI, ND2, LIF or TIFF micrograph: read \
                         it with `contactscope topography` (or `simulate --topography`)",
                        map.with_article()
                    ),
                )
            }
            None => unsupported(
                path,
                "not a CZI, ND2, LIF or TIFF file nor an OME-Zarr folder (unknown magic bytes \
                 at the start)",
            ),
        })?;
        let (series, backend) = match format {
            MicroscopyFormat::Czi => {
                let r = czi::CziReader::open(source)?;
                (r.series(), Backend::Czi(Box::new(r)))
            }
            MicroscopyFormat::Nd2 => {
                let r = nd2::Nd2Reader::open(source)?;
                (r.series(), Backend::Nd2(Box::new(r)))
            }
            MicroscopyFormat::Lif => {
                let r = lif::LifReader::open(source)?;
                (r.series(), Backend::Lif(Box::new(r)))
            }
            MicroscopyFormat::Tiff => {
                let r = tiff::TiffBackend::open(path)?;
                (r.series(), Backend::Tiff(Box::new(r)))
            }
            MicroscopyFormat::OmeZarr => return Err(unsupported(path, "a Zarr store is a folder")),
        };
        // TIFF files keep their own model (one page, one image).
        let shown = if format == MicroscopyFormat::Tiff {
            series.clone()
        } else {
            series
                .iter()
                .cloned()
                .map(SeriesInfo::as_line_scan)
                .collect()
        };
        Ok(MicroscopyFile {
            path: path.to_path_buf(),
            format,
            series: shown,
            stored: series,
            backend,
        })
    }

    /// The TIFF header facts, for a TIFF.
    pub fn tiff_info(&self) -> Option<&crate::tiff::TiffInfo> {
        match &self.backend {
            Backend::Tiff(r) => Some(r.info()),
            _ => None,
        }
    }

    /// Whether decoding a plane costs more than reading its bytes (CZI zstd subblocks, ND2
    /// lossless frames); LIF and TIFF planes count as uncompressed here.
    pub fn compressed(&self) -> bool {
        match &self.backend {
            Backend::Czi(r) => r.compressed(),
            Backend::Nd2(r) => r.compressed(),
            Backend::Zarr(r) => r.compressed(),
            Backend::Lif(_) | Backend::Tiff(_) => false,
        }
    }

    /// Decode one plane of series `series`.
    pub fn read_plane(&mut self, series: usize, index: &PlaneIndex) -> Result<Plane> {
        let info = self.series.get(series).ok_or_else(|| {
            bad(
                &self.path,
                format!(
                    "series {series} requested, the file has {}",
                    self.series.len()
                ),
            )
        })?;
        index.check(&self.path, info)?;
        let stored = &self.stored[series];
        let axis = info.rows;
        if axis.is_y() {
            return self.backend.read_plane(stored, index);
        }
        // One line per row: the plane at z (or t) = row of the stored series.
        let (width, height) = (info.axes.x, info.axes.y);
        checked_bytes(&self.path, "plane", &[width, height], 4)?;
        let mut lines = Vec::with_capacity(height);
        for row in 0..height {
            let mut at = index.clone();
            match axis {
                Rows::Z => at.z = row,
                Rows::T | Rows::Y => at.t = row,
            }
            lines.push(self.backend.read_plane(stored, &at)?);
        }
        stack_lines(&self.path, width, lines)
    }
}

impl Backend {
    fn read_plane(&mut self, info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        match self {
            Backend::Czi(r) => r.read_plane(info, index),
            Backend::Nd2(r) => r.read_plane(info, index),
            Backend::Lif(r) => r.read_plane(info, index),
            Backend::Tiff(r) => r.read_plane(info, index),
            Backend::Zarr(r) => r.read_plane(info, index),
        }
    }
}

/// One image from lines (planes of `width` × 1) of one sample type, the first line on top.
fn stack_lines(path: &Path, width: usize, lines: Vec<Plane>) -> Result<Plane> {
    let height = lines.len();
    let first = lines
        .first()
        .ok_or_else(|| bad(path, "a line scan of no lines"))?;
    let (sample_type, offset) = (first.sample_type, int_offset(&first.samples));
    let mut codes = Vec::new();
    let mut floats = Vec::new();
    for line in lines {
        if line.width != width || line.height != 1 || line.sample_type != sample_type {
            return Err(bad(
                path,
                format!(
                    "a line of the scan is {}×{} {}, not {width}×1 {}",
                    line.width,
                    line.height,
                    line.sample_type.name(),
                    sample_type.name()
                ),
            ));
        }
        match line.samples {
            Samples::Int {
                codes: c,
                offset: o,
            } if Some(o) == offset => codes.extend(c),
            Samples::Float(v) if offset.is_none() => floats.extend(v),
            _ => return Err(bad(path, "the lines of a scan hold different sample kinds")),
        }
    }
    let samples = match offset {
        Some(offset) => Samples::Int { codes, offset },
        None => Samples::Float(floats),
    };
    Ok(Plane {
        width,
        height,
        sample_type,
        samples,
    })
}

/// The code offset of integer samples, `None` for floats.
fn int_offset(samples: &Samples) -> Option<i32> {
    match samples {
        Samples::Int { offset, .. } => Some(*offset),
        Samples::Float(_) => None,
    }
}

/// A plane from packed little-endian samples of `dtype`, rows `stride` bytes apart (the first
/// `width` samples of each row are used).
pub(crate) fn plane_from_le(
    path: &Path,
    (width, height): (usize, usize),
    dtype: SampleType,
    bytes: &[u8],
    stride: usize,
) -> Result<Plane> {
    let size = dtype.bytes();
    checked_bytes(path, "plane", &[width, height], size)?;
    let row = width * size;
    if height > 0 && (stride < row || bytes.len() < stride * (height - 1) + row) {
        return Err(bad(
            path,
            format!(
                "plane data hold {} bytes, {width}×{height} {} samples need more",
                bytes.len(),
                dtype.name()
            ),
        ));
    }
    let rows = (0..height).map(|y| &bytes[y * stride..y * stride + row]);
    let samples = match dtype {
        SampleType::U8 => Samples::Int {
            codes: rows.flat_map(|r| r.iter().map(|&b| u16::from(b))).collect(),
            offset: 0,
        },
        SampleType::U16 => Samples::Int {
            codes: rows
                .flat_map(|r| r.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])))
                .collect(),
            offset: 0,
        },
        SampleType::I16 => Samples::Int {
            codes: rows
                .flat_map(|r| {
                    r.chunks_exact(2)
                        .map(|c| (i32::from(i16::from_le_bytes([c[0], c[1]])) + 32768) as u16)
                })
                .collect(),
            offset: -32768,
        },
        SampleType::F32 => Samples::Float(
            rows.flat_map(|r| {
                r.chunks_exact(4)
                    .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            })
            .collect(),
        ),
        SampleType::F64 => Samples::Float(
            rows.flat_map(|r| {
                r.chunks_exact(8).map(|c| {
                    let mut a = [0u8; 8];
                    a.copy_from_slice(c);
                    f64::from_le_bytes(a) as f32
                })
            })
            .collect(),
        ),
    };
    Ok(Plane {
        width,
        height,
        sample_type: dtype,
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_by_magic() {
        assert_eq!(
            detect(b"ZISRAWFILE\0\0\0\0\0\0"),
            Some(MicroscopyFormat::Czi)
        );
        assert_eq!(
            detect(&[0xda, 0xce, 0xbe, 0x0a, 0]),
            Some(MicroscopyFormat::Nd2)
        );
        assert_eq!(
            detect(&[0x70, 0, 0, 0, 1, 2, 3, 4, 0x2a]),
            Some(MicroscopyFormat::Lif)
        );
        assert_eq!(detect(b"II*\0"), Some(MicroscopyFormat::Tiff));
        assert_eq!(detect(b"GWYP"), None);
    }

    #[test]
    fn plane_order_and_checks() {
        let axes = Axes {
            t: 2,
            z: 1,
            c: 2,
            y: 1,
            x: 1,
            extra: [("H".to_string(), 3)].into_iter().collect(),
        };
        let all = PlaneIndex::all(&axes);
        assert_eq!(all.len(), 12);
        assert_eq!((all[4].t, all[4].c, all[4].get("H")), (0, 1, 1));
        let series = SeriesInfo {
            index: 0,
            name: String::new(),
            axes,
            dtype: SampleType::U8,
            pixel_size: VoxelSize::default(),
            channels: vec![],
            rows: Rows::Y,
            tiff_axes: None,
        };
        let p = Path::new("x.czi");
        assert!(all[11].check(p, &series).is_ok());
        let mut over = PlaneIndex::tzc(0, 0, 0);
        over.extra.insert("H".into(), 3);
        assert!(over
            .check(p, &series)
            .unwrap_err()
            .to_string()
            .contains("H = 3"));
        assert!(PlaneIndex::tzc(0, 1, 0).check(p, &series).is_err());
    }

    #[test]
    fn planes_from_strided_bytes() {
        let p = Path::new("x");
        let bytes = [1u8, 0, 2, 0, 9, 3, 0, 4, 0];
        let plane = plane_from_le(p, (2, 2), SampleType::U16, &bytes, 5).unwrap();
        assert_eq!(plane.to_f64(), vec![1.0, 2.0, 3.0, 4.0]);
        let plane = plane_from_le(p, (1, 1), SampleType::I16, &[0xfe, 0xff], 2).unwrap();
        assert_eq!(plane.value(0), -2.0);
        assert!(plane_from_le(p, (2, 2), SampleType::U16, &bytes[..8], 5).is_err());
    }

    #[test]
    fn scans_without_y_become_images_whose_rows_are_z_or_t() {
        let series = |(t, z, y): (usize, usize, usize)| SeriesInfo {
            index: 0,
            name: String::new(),
            axes: Axes {
                t,
                z,
                c: 2,
                y,
                x: 128,
                extra: BTreeMap::new(),
            },
            dtype: SampleType::U8,
            pixel_size: VoxelSize {
                x_m: Some(1e-7),
                y_m: None,
                z_m: Some(5e-7),
                source: Some("DimID=1".into()),
            },
            channels: vec![],
            rows: Rows::Y,
            tiff_axes: None,
        };
        // X–Z–T: one X–Z image per t, y pixel size the z step.
        let xz = series((3, 128, 1)).as_line_scan();
        assert_eq!(
            (xz.rows, xz.axes.t, xz.axes.z, xz.axes.y),
            (Rows::Z, 3, 1, 128)
        );
        assert_eq!((xz.pixel_size.y_m, xz.pixel_size.z_m), (Some(5e-7), None));
        assert!(xz.pixel_size.source.as_ref().unwrap().contains("z step"));
        assert_eq!(xz.axes.planes(), 6);
        // X–T: rows are time points, no y length.
        let xt = series((40, 1, 1)).as_line_scan();
        assert_eq!((xt.rows, xt.axes.t, xt.axes.y), (Rows::T, 1, 40));
        assert_eq!(xt.pixel_size.y_m, None);
        // An X–Y image, or a single line, stays as it is.
        assert_eq!(series((2, 5, 64)).as_line_scan(), series((2, 5, 64)));
        assert_eq!(series((1, 1, 1)).as_line_scan(), series((1, 1, 1)));
        // Transforming twice changes nothing more.
        assert_eq!(xz.clone().as_line_scan(), xz);
    }

    #[test]
    fn lines_stack_into_one_plane() {
        let p = Path::new("x.lif");
        let line = |v: u16| Plane::from_u16(2, 1, vec![v, v + 1]);
        let stacked = stack_lines(p, 2, vec![line(1), line(5), line(9)]).unwrap();
        assert_eq!((stacked.width, stacked.height), (2, 3));
        assert_eq!(stacked.to_f64(), vec![1.0, 2.0, 5.0, 6.0, 9.0, 10.0]);
        let err = stack_lines(p, 3, vec![line(1)]).unwrap_err().to_string();
        assert!(err.contains("x.lif") && err.contains("not 3×1"), "{err}");
        assert!(stack_lines(p, 2, vec![]).is_err());
    }
}
