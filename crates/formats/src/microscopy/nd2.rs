//! Nikon ND2 (NIS-Elements, versions 2.x and 3.x "chunked" files), read by our own code from the
//! public description of the layout (nd2 Python package documentation, Bio-Formats
//! `NativeND2Reader`). The legacy JPEG-2000 ND2 (version 1) is refused.
//!
//! The `nd2` crate (1.0.0, MIT/Apache) was measured first on `cluster.nd2`: its plane sums
//! agree with the nd2 Python package (e.g. t = 1, z = 3, c = 0: 413 082), but it reports no
//! pixel size (`scaling: None` although the file is calibrated at 0.1678 µm), no channel names,
//! and its API returns only `u16` planes; so it is not used.
//!
//! Layout: the file is a sequence of chunks, each a 16-byte header (magic `0x0ABECEDA`, name
//! length u32, data length u64), the name, then the data. The last 40 bytes are the signature
//! `ND2 CHUNK MAP SIGNATURE 0000001!` and the position of the chunk map, whose entries are
//! `name!` + position (u64) + data length (u64). Metadata chunks hold CLX-lite trees
//! (`clx` module): `ImageAttributesLV!` (width, row bytes, height, components, bits per
//! component, sequence count, compression), `ImageMetadataLV!` (the experiment loops, outermost
//! first: time `T`, stage positions `P`, `Z`; the frame number is row-major over them) and
//! `ImageMetadataSeqLV|0!` (`dCalibration`, µm per pixel, and the channel names in
//! `sPicturePlanes/sPlaneNew/a<i>/sDescription`). Frame `i` is the chunk `ImageDataSeq|i!`:
//! an 8-byte time stamp, then rows of `uiWidthBytes` bytes with the components (channels)
//! interleaved per pixel; lossless files store these bytes as a zlib stream.
//!
//! Pixel size: `dCalibration` (µm/px, x = y) when `bCalibrated` is not 0; Z step: `dZStep` of
//! the Z loop (µm).

use std::collections::{BTreeMap, HashMap};
use std::io::Read;

use super::clx::{self, Clx};
use super::{plane_from_le, Axes, ChannelInfo, PlaneIndex, SeriesInfo, VoxelSize};
use crate::binary::{bad, checked_bytes, unsupported, FileSource, Reader};
use crate::error::Result;
use crate::image::{Plane, SampleType};

const MAP_SIGNATURE: &[u8] = b"ND2 CHUNK MAP SIGNATURE 0000001!";
const CHUNK_MAGIC: u32 = 0x0ABE_CEDA;
/// Largest chunk map or metadata chunk accepted (bytes).
const MAX_META_BYTES: usize = 64 << 20;

/// An experiment loop: axis name and count.
#[derive(Debug, Clone)]
struct Loop {
    axis: &'static str,
    count: usize,
}

/// An open ND2 file.
pub struct Nd2Reader {
    source: FileSource,
    chunks: HashMap<String, (u64, u64)>,
    loops: Vec<Loop>,
    width: usize,
    height: usize,
    row_bytes: usize,
    components: usize,
    dtype: SampleType,
    lossless: bool,
    series: SeriesInfo,
}

impl Nd2Reader {
    /// Whether the frames are zlib streams (lossless compression).
    pub(crate) fn compressed(&self) -> bool {
        self.lossless
    }

    /// Read the chunk map and the metadata chunks.
    pub(crate) fn open(mut source: FileSource) -> Result<Self> {
        let path = source.path.clone();
        if source.len < 40 + 16 {
            return Err(bad(&path, "file too short for an ND2"));
        }
        let tail = source.read_at(source.len - 40, 40, "the chunk-map signature")?;
        if &tail[..32] != MAP_SIGNATURE {
            return Err(unsupported(
                &path,
                "no ND2 chunk map at the end of the file (legacy JPEG-2000 ND2, or truncated)",
            ));
        }
        let map_pos = Reader::new(&path, &tail, 32).u64()?;
        let map = read_chunk_at(&mut source, map_pos, "the chunk map")?;
        let chunks = parse_map(&path, &map)?;
        let mut meta = |name: &str| -> Result<Option<Clx>> {
            match chunks.get(name) {
                None => Ok(None),
                Some(&(pos, _)) => {
                    let data = read_chunk_at(&mut source, pos, name)?;
                    clx::parse(&path, &data).map(Some)
                }
            }
        };
        let attributes = meta("ImageAttributesLV!")?.ok_or_else(|| {
            unsupported(
                &path,
                "no ImageAttributesLV! chunk (ND2 older than version 3 metadata)",
            )
        })?;
        let experiment = meta("ImageMetadataLV!")?;
        let picture = meta("ImageMetadataSeqLV|0!")?;
        let a = attributes
            .get("SLxImageAttributes")
            .ok_or_else(|| bad(&path, "ImageAttributesLV! has no SLxImageAttributes"))?;
        let num = |k: &str| -> Result<usize> {
            a.get(k)
                .and_then(Clx::number)
                .filter(|v| *v >= 0.0 && *v < 1e9)
                .map(|v| v as usize)
                .ok_or_else(|| bad(&path, format!("ND2 attributes lack {k}")))
        };
        let (width, height, components) = (num("uiWidth")?, num("uiHeight")?, num("uiComp")?);
        let bits = num("uiBpcInMemory")?;
        let sequences = num("uiSequenceCount")?;
        let row_bytes = num("uiWidthBytes").unwrap_or(width * components * bits / 8);
        let float = a.get("ePixelType").and_then(Clx::number) == Some(2.0);
        let dtype = match (bits, float) {
            (8, false) => SampleType::U8,
            (16, false) => SampleType::U16,
            (32, true) => SampleType::F32,
            _ => {
                return Err(unsupported(
                    &path,
                    format!(
                        "{bits}-bit {} ND2 pixels",
                        if float { "float" } else { "integer" }
                    ),
                ))
            }
        };
        let lossless = match a.get("eCompression").and_then(Clx::number) {
            Some(0.0) => true,
            Some(1.0) => {
                return Err(unsupported(
                    &path,
                    "lossy-compressed ND2 (JPEG 2000 frames)",
                ))
            }
            _ => false,
        };
        let bytes = bits / 8;
        if components == 0 || row_bytes < width * components * bytes {
            return Err(bad(
                &path,
                format!(
                    "ND2 row of {row_bytes} bytes for {width} pixels × {components} components"
                ),
            ));
        }
        checked_bytes(&path, "ND2 frame", &[row_bytes, height], 1)?;
        let mut loops = experiment
            .as_ref()
            .map(|e| experiment_loops(e.get("SLxExperiment").unwrap_or(e)))
            .unwrap_or_default();
        loops.retain(|l| l.count > 1);
        if loops.iter().map(|l| l.count).product::<usize>() != sequences {
            // Loops that do not account for the frames (interrupted acquisitions): one T axis.
            loops = vec![Loop {
                axis: "T",
                count: sequences,
            }];
        }
        let series = series_info(
            &loops,
            (width, height, components),
            dtype,
            picture.as_ref(),
            experiment.as_ref(),
        );
        Ok(Nd2Reader {
            source,
            chunks,
            loops,
            width,
            height,
            row_bytes,
            components,
            dtype,
            lossless,
            series,
        })
    }

    /// The one series.
    pub(crate) fn series(&self) -> Vec<SeriesInfo> {
        vec![self.series.clone()]
    }

    /// Decode channel `c` of the frame at `(t, z, P)`.
    pub(crate) fn read_plane(&mut self, _info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let path = self.source.path.clone();
        let mut frame = 0;
        for l in &self.loops {
            let i = match l.axis {
                "T" => index.t,
                "Z" => index.z,
                other => index.get(other),
            };
            frame = frame * l.count + i;
        }
        let name = format!("ImageDataSeq|{frame}!");
        let &(pos, _) = self
            .chunks
            .get(&name)
            .ok_or_else(|| bad(&path, format!("frame {frame} ({name}) is missing")))?;
        let data = read_chunk_at(&mut self.source, pos, &name)?;
        let expected = self.row_bytes * self.height;
        let pixels = match data.get(8..) {
            Some(rest) if self.lossless => {
                let mut out = Vec::with_capacity(expected);
                flate2::read::ZlibDecoder::new(rest)
                    .take(expected as u64)
                    .read_to_end(&mut out)
                    .map_err(|e| bad(&path, format!("{name}: zlib data do not decode: {e}")))?;
                out
            }
            Some(rest) => rest.to_vec(),
            None => Vec::new(),
        };
        if pixels.len() < expected {
            return Err(bad(
                &path,
                format!(
                    "{name} holds {} bytes, the frame needs {expected}",
                    pixels.len()
                ),
            ));
        }
        let bytes = match self.dtype {
            SampleType::U8 => 1,
            SampleType::F32 => 4,
            _ => 2,
        };
        // Pick channel c out of the interleaved components.
        let (w, comps) = (self.width, self.components);
        let mut packed = Vec::with_capacity(w * self.height * bytes);
        for row in pixels.chunks(self.row_bytes).take(self.height) {
            for x in 0..w {
                let at = (x * comps + index.c) * bytes;
                packed.extend_from_slice(&row[at..at + bytes]);
            }
        }
        plane_from_le(&path, (w, self.height), self.dtype, &packed, w * bytes)
    }
}

/// The data of the chunk whose header is at `pos`.
fn read_chunk_at(source: &mut FileSource, pos: u64, what: &str) -> Result<Vec<u8>> {
    let path = source.path.clone();
    let head = source.read_at(pos, 16, what)?;
    let mut r = Reader::new(&path, &head, 0);
    if r.u32()? != CHUNK_MAGIC {
        return Err(bad(&path, format!("no ND2 chunk at offset {pos} ({what})")));
    }
    let name_len = u64::from(r.u32()?);
    let data_len = r.usize_u64()?;
    if data_len > MAX_META_BYTES.max(1 << 30) {
        return Err(bad(&path, format!("{what}: chunk of {data_len} bytes")));
    }
    source.read_at(pos + 16 + name_len, data_len, what)
}

/// Chunk map entries: name → (position, length).
fn parse_map(path: &std::path::Path, map: &[u8]) -> Result<HashMap<String, (u64, u64)>> {
    if map.len() > MAX_META_BYTES {
        return Err(bad(path, "ND2 chunk map too large"));
    }
    let mut out = HashMap::new();
    let mut r = Reader::new(path, map, 0);
    while r.remaining() > 0 {
        let rest = &map[r.pos..];
        let end = rest
            .iter()
            .position(|&b| b == b'!')
            .ok_or_else(|| bad(path, "ND2 chunk map entry without '!'"))?;
        let name = r.take(end + 1)?;
        if name == MAP_SIGNATURE {
            break;
        }
        let name = String::from_utf8_lossy(name).into_owned();
        let (pos, len) = (r.u64()?, r.u64()?);
        out.insert(name, (pos, len));
    }
    Ok(out)
}

/// The experiment loops, outermost first.
fn experiment_loops(level: &Clx) -> Vec<Loop> {
    let mut loops = Vec::new();
    let mut node = Some(level);
    while let Some(n) = node {
        if loops.len() > 16 {
            break;
        }
        let kind = n.get("eType").and_then(Clx::number).unwrap_or(0.0) as i64;
        let count = n
            .at(&["uLoopPars", "uiCount"])
            .and_then(Clx::number)
            .unwrap_or(1.0)
            .max(1.0) as usize;
        let axis = match kind {
            1 | 8 => Some("T"),
            2 => Some("P"),
            4 => Some("Z"),
            _ => None,
        };
        if let Some(axis) = axis {
            loops.push(Loop { axis, count });
        }
        node = n
            .get("ppNextLevelEx")
            .and_then(|l| l.children().first())
            .map(|(_, v)| v);
    }
    loops
}

/// The Z step (µm) of the first Z loop.
fn z_step(level: &Clx) -> Option<f64> {
    let mut node = Some(level);
    let mut depth = 0;
    while let (Some(n), true) = (node, depth < 16) {
        if n.get("eType").and_then(Clx::number) == Some(4.0) {
            return n.at(&["uLoopPars", "dZStep"]).and_then(Clx::number);
        }
        node = n
            .get("ppNextLevelEx")
            .and_then(|l| l.children().first())
            .map(|(_, v)| v);
        depth += 1;
    }
    None
}

fn series_info(
    loops: &[Loop],
    (width, height, components): (usize, usize, usize),
    dtype: SampleType,
    picture: Option<&Clx>,
    experiment: Option<&Clx>,
) -> SeriesInfo {
    let count = |axis: &str| loops.iter().find(|l| l.axis == axis).map_or(1, |l| l.count);
    let mut extra = BTreeMap::new();
    if count("P") > 1 {
        extra.insert("P".to_string(), count("P"));
    }
    let meta = picture.and_then(|p| p.get("SLxPictureMetadata"));
    let calibrated = meta
        .and_then(|m| m.get("bCalibrated"))
        .and_then(Clx::number)
        != Some(0.0);
    let xy = meta
        .and_then(|m| m.get("dCalibration"))
        .and_then(Clx::number)
        .filter(|_| calibrated)
        .map(|um| um * 1e-6);
    let xy = VoxelSize::valid(xy);
    let z = experiment
        .map(|e| e.get("SLxExperiment").unwrap_or(e))
        .and_then(z_step)
        .map(|um| um.abs() * 1e-6);
    let planes = meta.and_then(|m| m.at(&["sPicturePlanes", "sPlaneNew"]));
    let channels = (0..components)
        .map(|i| ChannelInfo {
            name: planes
                .and_then(|p| p.get(&format!("a{i}")))
                .and_then(|p| p.get("sDescription"))
                .and_then(Clx::text)
                .map(str::to_string),
            ..ChannelInfo::default()
        })
        .collect();
    SeriesInfo {
        index: 0,
        name: String::new(),
        axes: Axes {
            t: count("T"),
            z: count("Z"),
            c: components,
            y: height,
            x: width,
            extra,
        },
        dtype,
        pixel_size: VoxelSize {
            x_m: xy,
            y_m: xy,
            z_m: VoxelSize::valid(z),
            source: xy.map(|_| "ND2 ImageMetadataSeqLV|0! SLxPictureMetadata/dCalibration".into()),
        },
        channels,
        rows: super::Rows::Y,
        tiff_axes: None,
    }
}
