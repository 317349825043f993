//! Confocal microscopy files as one model: Zeiss CZI ([`czi`]), Nikon ND2 ([`nd2`]), Leica LIF
//! ([`lif`]) and, described the same way, TIFF ([`crate::tiff`]).
//!
//! A [`MicroscopyFile`] holds a list of [`SeriesInfo`] (CZI scenes, LIF images; ND2 and TIFF
//! have one series) read from the headers only; [`MicroscopyFile::read_plane`] decodes one 2-D
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
//! The format is detected from the first bytes of the file ([`detect`]), not the extension.

mod clx;
pub mod czi;
pub mod lif;
pub mod nd2;
pub mod select;
pub mod summary;
mod tiff;

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
}

impl MicroscopyFormat {
    /// Lowercase name, as `info --json` prints it.
    pub fn name(self) -> &'static str {
        match self {
            MicroscopyFormat::Czi => "czi",
            MicroscopyFormat::Nd2 => "nd2",
            MicroscopyFormat::Lif => "lif",
            MicroscopyFormat::Tiff => "tiff",
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

/// One series (CZI scene, LIF image, the whole ND2 or TIFF file).
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
}

/// An open microscopy file: its series, and a reader of their planes.
pub struct MicroscopyFile {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: MicroscopyFormat,
    /// Its series.
    pub series: Vec<SeriesInfo>,
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
        let mut source = super::binary::FileSource::open(path)?;
        let head = source.read_up_to(0, 16)?;
        let format = detect(&head).ok_or_else(|| {
            unsupported(
                path,
                "not a CZI, ND2, LIF or TIFF file (unknown magic bytes at the start)",
            )
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
        };
        Ok(MicroscopyFile {
            path: path.to_path_buf(),
            format,
            series,
            backend,
        })
    }

    /// Whether decoding a plane costs more than reading its bytes (CZI zstd subblocks, ND2
    /// lossless frames); LIF and TIFF planes count as uncompressed here.
    pub fn compressed(&self) -> bool {
        match &self.backend {
            Backend::Czi(r) => r.compressed(),
            Backend::Nd2(r) => r.compressed(),
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
        match &mut self.backend {
            Backend::Czi(r) => r.read_plane(info, index),
            Backend::Nd2(r) => r.read_plane(info, index),
            Backend::Lif(r) => r.read_plane(info, index),
            Backend::Tiff(r) => r.read_plane(info, index),
        }
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
    let size = match dtype {
        SampleType::U8 => 1,
        SampleType::U16 | SampleType::I16 => 2,
        SampleType::F32 => 4,
        SampleType::F64 => 8,
    };
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
}
