//! Zeiss CZI, read by our own code from the public format description ("ZISRAW (CZI) File
//! Format Design Specification", Carl Zeiss Microscopy, v1.2; libCZI documentation).
//!
//! The `czi` crate (1.0.0, MIT/Apache) was measured first on five real sample CZI files
//! (`docs/formats.md`) and is not used: it averages the three samples of a Bgr24
//! pixel into one grey value (RGB-multichannel.czi: 1 403 058 for channel 0 where the blue,
//! green and red planes sum to 1 407 155, 1 404 252 and 1 409 920), its public API returns only
//! `u16` (no float or per-sample planes), and it reports four of the eight Airyscan channels as
//! Gray8 from the metadata where every subblock is Gray16. Its plane sums of grey images did
//! match pylibCZIrw.
//!
//! Layout: a file is a sequence of segments, each a 32-byte header (16-byte ASCII id, allocated
//! and used size as i64) and data. `ZISRAWFILE` (at 0) gives the positions of the subblock
//! directory (`ZISRAWDIRECTORY`) and of the metadata (`ZISRAWMETADATA`, UTF-8 XML). Each
//! directory entry (`DV` schema) gives a subblock's pixel type, compression, file position and
//! its coordinate along every dimension (X and Y with logical and stored size). A series is a
//! scene (`S`); its planes are composed of the layer-0 subblocks (stored size = logical size) at
//! that (T, Z, C, …) coordinate, placed at their X/Y offsets relative to the scene's bounding
//! box in increasing mosaic index `M` (a later tile covers an earlier one); pixels no tile
//! covers are 0, as pylibCZIrw's default background.
//!
//! Compression: uncompressed, `zstd0` (plain zstd) and `zstd1` (a small header, optionally the
//! low bytes of 16-bit samples stored before the high bytes). JPEG, LZW, JPEG-XR and
//! camera-specific modes are refused naming the mode. Pixel types: Gray8, Gray16, Gray32Float,
//! Bgr24, Bgr48, Bgr96Float and Bgra32 (colour samples become the `S` axis: 0 = B, 1 = G,
//! 2 = R, 3 = A, as stored); complex and 32/64-bit integer types are refused.
//!
//! Pixel size: `ImageDocument/Metadata/Scaling/Items/Distance[@Id=X|Y|Z]/Value`, in metres
//! (0 means not calibrated and is reported as absent).

use std::collections::BTreeMap;

use super::{Axes, ChannelInfo, PlaneIndex, SeriesInfo, VoxelSize};
use crate::binary::{bad, checked_bytes, unsupported, FileSource, Reader};
use crate::error::Result;
use crate::image::{Plane, SampleType, Samples};

/// Largest metadata XML accepted (bytes).
const MAX_XML_BYTES: usize = 64 << 20;
/// Size of a segment header.
const SEGMENT_HEADER: u64 = 32;

/// One dimension of a directory entry.
#[derive(Debug, Clone)]
struct DimEntry {
    name: String,
    start: i32,
    size: i32,
    stored: i32,
}

/// One directory entry (`DV` schema).
#[derive(Debug, Clone)]
struct Entry {
    pixel_type: i32,
    position: u64,
    compression: i32,
    dims: Vec<DimEntry>,
}

impl Entry {
    fn dim(&self, name: &str) -> Option<&DimEntry> {
        self.dims.iter().find(|d| d.name == name)
    }

    fn start(&self, name: &str) -> i32 {
        self.dim(name).map_or(0, |d| d.start)
    }

    /// X, Y, width, height, stored width, stored height.
    fn rect(&self) -> (i64, i64, i64, i64, usize, usize) {
        let x = self.dim("X");
        let y = self.dim("Y");
        let g = |d: Option<&DimEntry>| d.map_or((0, 1, 1), |d| (d.start, d.size, d.stored));
        let (x0, w, sw) = g(x);
        let (y0, h, sh) = g(y);
        (
            i64::from(x0),
            i64::from(y0),
            i64::from(w),
            i64::from(h),
            sw.max(0) as usize,
            sh.max(0) as usize,
        )
    }

    /// Layer 0 of a pyramid: stored size equals logical size.
    fn is_layer0(&self) -> bool {
        let (_, _, w, h, sw, sh) = self.rect();
        w == sw as i64 && h == sh as i64
    }
}

/// The layout of a pixel type: sample type, samples per pixel.
fn pixel_layout(code: i32) -> std::result::Result<(SampleType, usize), String> {
    Ok(match code {
        0 => (SampleType::U8, 1),
        1 => (SampleType::U16, 1),
        2 => (SampleType::F32, 1),
        3 => (SampleType::U8, 3),
        4 => (SampleType::U16, 3),
        8 => (SampleType::F32, 3),
        9 => (SampleType::U8, 4),
        10 => return Err("Gray64ComplexFloat".into()),
        11 => return Err("Bgr192ComplexFloat".into()),
        12 => return Err("Gray32 (32-bit integer)".into()),
        13 => return Err("Gray64 (64-bit integer)".into()),
        other => return Err(format!("pixel type code {other}")),
    })
}

fn compression_name(code: i32) -> String {
    match code {
        0 => "uncompressed".into(),
        1 => "JPEG".into(),
        2 => "LZW".into(),
        4 => "JPEG-XR".into(),
        5 => "zstd0".into(),
        6 => "zstd1".into(),
        c if c >= 100 => format!("camera-specific ({c})"),
        c => format!("code {c}"),
    }
}

/// One scene: its entries (indices into the directory), bounding box and dimension origins.
#[derive(Debug, Clone)]
struct Scene {
    entries: Vec<usize>,
    bbox: (i64, i64, usize, usize),
    /// For each frame dimension (T, Z, C, H, …): the smallest start.
    origin: BTreeMap<String, i32>,
    samples: usize,
}

/// An open CZI file.
pub struct CziReader {
    source: FileSource,
    entries: Vec<Entry>,
    scenes: Vec<Scene>,
    series: Vec<SeriesInfo>,
}

impl CziReader {
    /// Whether any subblock is compressed (zstd), so that decoding a plane costs more than
    /// reading it.
    pub(crate) fn compressed(&self) -> bool {
        self.entries.iter().any(|e| e.compression != 0)
    }

    /// Read the file header, the subblock directory and the metadata.
    pub(crate) fn open(mut source: FileSource) -> Result<Self> {
        let path = source.path.clone();
        let head = source.read_at(0, 32 + 80, "the file header")?;
        if !head.starts_with(b"ZISRAWFILE") {
            return Err(bad(&path, "not a CZI file (no ZISRAWFILE segment)"));
        }
        let mut r = Reader::new(&path, &head, 32 + 52);
        let dir_pos = r.usize_i64("directory position")? as u64;
        let meta_pos = r.usize_i64("metadata position")? as u64;
        let entries = read_directory(&mut source, dir_pos)?;
        let xml = read_metadata(&mut source, meta_pos)?;
        let scenes = group_scenes(&path, &entries)?;
        let meta = Metadata::parse(&path, &xml)?;
        let series = scenes
            .iter()
            .enumerate()
            .map(|(i, s)| series_info(&path, i, s, &entries, &meta))
            .collect::<Result<Vec<_>>>()?;
        Ok(CziReader {
            source,
            entries,
            scenes,
            series,
        })
    }

    /// The scenes as series.
    pub(crate) fn series(&self) -> Vec<SeriesInfo> {
        self.series.clone()
    }

    /// Compose one plane from its tiles.
    pub(crate) fn read_plane(&mut self, info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let path = self.source.path.clone();
        let scene = self.scenes[info.index].clone();
        let want = |name: &str| -> i32 {
            let rel = match name {
                "T" => index.t,
                "Z" => index.z,
                "C" => index.c,
                other => index.get(other),
            };
            scene.origin.get(name).copied().unwrap_or(0) + rel as i32
        };
        let mut tiles: Vec<Entry> = scene
            .entries
            .iter()
            .map(|&i| self.entries[i].clone())
            .filter(|e| scene.origin.keys().all(|name| e.start(name) == want(name)))
            .collect();
        tiles.sort_by_key(|e| (e.start("M"), e.position));
        let (bx, by, width, height) = scene.bbox;
        let bytes = info.dtype.bytes();
        let n = checked_bytes(&path, "plane", &[width, height], bytes)? / bytes;
        let mut plane = vec![0u8; n * bytes];
        let sample = index.get("S");
        for tile in tiles {
            let (tx, ty, _, _, sw, sh) = tile.rect();
            let (dtype, spp) = pixel_layout(tile.pixel_type).map_err(|e| unsupported(&path, e))?;
            if dtype != info.dtype || spp != scene.samples {
                return Err(bad(
                    &path,
                    "subblocks of one plane have different pixel types",
                ));
            }
            let data = self.read_tile(&tile, sw, sh, spp * bytes)?;
            let pixel = spp * bytes;
            for y in 0..sh {
                let py = ty + y as i64 - by;
                if py < 0 || py >= height as i64 {
                    continue;
                }
                for x in 0..sw {
                    let px = tx + x as i64 - bx;
                    if px < 0 || px >= width as i64 {
                        continue;
                    }
                    let src = (y * sw + x) * pixel + sample * bytes;
                    let dst = (py as usize * width + px as usize) * bytes;
                    plane[dst..dst + bytes].copy_from_slice(&data[src..src + bytes]);
                }
            }
        }
        Ok(to_plane(width, height, info.dtype, &plane))
    }

    /// Read and decode the data of one subblock: `sw × sh` pixels of `pixel` bytes.
    fn read_tile(&mut self, e: &Entry, sw: usize, sh: usize, pixel: usize) -> Result<Vec<u8>> {
        let path = self.source.path.clone();
        let expected = checked_bytes(&path, "subblock", &[sw, sh], pixel)?;
        let head = self
            .source
            .read_at(e.position, 32 + 16, "a subblock header")?;
        if !head.starts_with(b"ZISRAWSUBBLOCK") {
            return Err(bad(
                &path,
                format!("no ZISRAWSUBBLOCK segment at offset {}", e.position),
            ));
        }
        let mut r = Reader::new(&path, &head, 32);
        let meta_size = r.i32()?.max(0) as u64;
        let _attachment = r.i32()?;
        let data_size = r.usize_i64("subblock data size")?;
        let entry_len = 32 + 20 * e.dims.len() as u64;
        let data_pos = e.position + SEGMENT_HEADER + (16 + entry_len).max(256) + meta_size;
        let raw = self.source.read_at(data_pos, data_size, "subblock data")?;
        let decoded = match e.compression {
            0 => raw,
            5 => zstd_decode(&path, &raw, expected)?,
            6 => zstd1_decode(&path, &raw, expected, pixel)?,
            c => {
                return Err(unsupported(
                    &path,
                    format!(
                        "{} compressed subblocks (contactscope reads uncompressed, zstd0 and \
                         zstd1 CZI; re-save the file uncompressed or as TIFF)",
                        compression_name(c)
                    ),
                ))
            }
        };
        if decoded.len() < expected {
            return Err(bad(
                &path,
                format!(
                    "subblock at offset {} holds {} bytes, {sw}×{sh} pixels need {expected}",
                    e.position,
                    decoded.len()
                ),
            ));
        }
        Ok(decoded)
    }
}

fn zstd_decode(path: &std::path::Path, raw: &[u8], expected: usize) -> Result<Vec<u8>> {
    zstd::bulk::decompress(raw, expected)
        .map_err(|e| bad(path, format!("zstd subblock does not decode: {e}")))
}

/// `zstd1`: a header (its first byte is its size; a 3-byte header with chunk type 1 carries
/// the hi/lo packing flag in bit 0 of the third byte), then a zstd frame.
fn zstd1_decode(
    path: &std::path::Path,
    raw: &[u8],
    expected: usize,
    pixel: usize,
) -> Result<Vec<u8>> {
    let header = *raw
        .first()
        .ok_or_else(|| bad(path, "empty zstd1 subblock"))? as usize;
    if header == 0 || header > raw.len() {
        return Err(bad(path, format!("zstd1 header of {header} bytes")));
    }
    let hilo = header == 3 && raw[1] == 1 && raw[2] & 1 == 1;
    let data = zstd_decode(path, &raw[header..], expected)?;
    if !hilo {
        return Ok(data);
    }
    if !pixel.is_multiple_of(2) || data.len() % 2 != 0 {
        return Err(bad(path, "zstd1 hi/lo packing of 8-bit samples"));
    }
    let half = data.len() / 2;
    let mut out = vec![0u8; data.len()];
    for i in 0..half {
        out[2 * i] = data[i];
        out[2 * i + 1] = data[half + i];
    }
    Ok(out)
}

fn to_plane(width: usize, height: usize, dtype: SampleType, bytes: &[u8]) -> Plane {
    let samples = match dtype {
        SampleType::U8 => Samples::Int {
            codes: bytes.iter().map(|&b| u16::from(b)).collect(),
            offset: 0,
        },
        SampleType::F32 => Samples::Float(
            bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect(),
        ),
        _ => Samples::Int {
            codes: bytes
                .chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect(),
            offset: 0,
        },
    };
    Plane {
        width,
        height,
        sample_type: dtype,
        samples,
    }
}

/// The `ZISRAWDIRECTORY` segment's entries.
fn read_directory(source: &mut FileSource, pos: u64) -> Result<Vec<Entry>> {
    let path = source.path.clone();
    let head = source.read_at(pos, 32 + 128, "the subblock directory")?;
    if !head.starts_with(b"ZISRAWDIRECTORY") {
        return Err(bad(&path, format!("no subblock directory at offset {pos}")));
    }
    let mut r = Reader::new(&path, &head, 32);
    let count = r.i32()?;
    let count = usize::try_from(count)
        .map_err(|_| bad(&path, format!("negative subblock count {count}")))?;
    // Each entry takes at least 32 bytes: the count must fit in the file.
    let min_len = (count as u64).saturating_mul(32);
    if min_len > source.len.saturating_sub(pos + 160) {
        return Err(bad(
            &path,
            format!("directory lists {count} subblocks, more than the file can hold"),
        ));
    }
    let available = (source.len - pos - 160).min(count as u64 * (32 + 20 * 16)) as usize;
    let data = source.read_at(pos + 160, available, "the subblock directory")?;
    let mut r = Reader::new(&path, &data, 0);
    (0..count).map(|_| read_entry(&path, &mut r)).collect()
}

fn read_entry(path: &std::path::Path, r: &mut Reader) -> Result<Entry> {
    let schema = r.take(2)?;
    if schema != b"DV" {
        return Err(bad(
            path,
            format!(
                "unknown subblock directory entry schema {:?}",
                String::from_utf8_lossy(schema)
            ),
        ));
    }
    let pixel_type = r.i32()?;
    let position = r.usize_i64("subblock position")? as u64;
    let _file_part = r.i32()?;
    let compression = r.i32()?;
    let _pyramid = r.u8()?;
    r.take(5)?;
    let n = r.i32()?;
    if !(0..=64).contains(&n) {
        return Err(bad(path, format!("directory entry with {n} dimensions")));
    }
    let dims = (0..n)
        .map(|_| {
            let name = String::from_utf8_lossy(r.take(4)?)
                .trim_end_matches('\0')
                .to_string();
            let start = r.i32()?;
            let size = r.i32()?;
            let _coord = r.f32()?;
            let stored = r.i32()?;
            Ok(DimEntry {
                name,
                start,
                size,
                stored,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Entry {
        pixel_type,
        position,
        compression,
        dims,
    })
}

/// The metadata XML (empty when the file has none).
fn read_metadata(source: &mut FileSource, pos: u64) -> Result<String> {
    if pos == 0 {
        return Ok(String::new());
    }
    let path = source.path.clone();
    let head = source.read_at(pos, 32 + 8, "the metadata segment")?;
    if !head.starts_with(b"ZISRAWMETADATA") {
        return Err(bad(&path, format!("no metadata segment at offset {pos}")));
    }
    let size = Reader::new(&path, &head, 32).i32()?;
    let size = usize::try_from(size)
        .ok()
        .filter(|&s| s <= MAX_XML_BYTES)
        .ok_or_else(|| bad(&path, format!("metadata XML of {size} bytes")))?;
    let xml = source.read_at(pos + 32 + 256, size, "the metadata XML")?;
    String::from_utf8(xml).map_err(|_| bad(&path, "metadata XML is not UTF-8"))
}

/// Layer-0 entries grouped by scene, with bounding boxes and dimension origins.
fn group_scenes(path: &std::path::Path, entries: &[Entry]) -> Result<Vec<Scene>> {
    let mut by_scene: BTreeMap<i32, Vec<usize>> = BTreeMap::new();
    for (i, e) in entries.iter().enumerate() {
        if e.is_layer0() {
            by_scene.entry(e.start("S")).or_default().push(i);
        }
    }
    if by_scene.is_empty() {
        return Err(bad(path, "the CZI holds no full-resolution subblocks"));
    }
    by_scene
        .into_values()
        .map(|ids| {
            let (mut x0, mut y0, mut x1, mut y1) = (i64::MAX, i64::MAX, i64::MIN, i64::MIN);
            let mut origin: BTreeMap<String, i32> = BTreeMap::new();
            let mut samples = 0;
            for &i in &ids {
                let e = &entries[i];
                let (x, y, w, h, _, _) = e.rect();
                (x0, y0) = (x0.min(x), y0.min(y));
                (x1, y1) = (x1.max(x + w), y1.max(y + h));
                for d in &e.dims {
                    if !matches!(d.name.as_str(), "X" | "Y" | "M" | "S") {
                        let o = origin.entry(d.name.clone()).or_insert(d.start);
                        *o = (*o).min(d.start);
                    }
                }
                samples = pixel_layout(e.pixel_type).map_or(0, |l| l.1);
            }
            let (w, h) = ((x1 - x0).max(0) as usize, (y1 - y0).max(0) as usize);
            checked_bytes(path, "scene bounding box", &[w, h], 1)?;
            Ok(Scene {
                entries: ids,
                bbox: (x0, y0, w, h),
                origin,
                samples,
            })
        })
        .collect()
}

/// What the XML metadata says.
#[derive(Default)]
struct Metadata {
    scaling: [Option<f64>; 3],
    channels: Vec<ChannelInfo>,
    scene_names: Vec<String>,
}

fn find<'a, 'i>(parent: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    parent.children().find(|n| n.has_tag_name(name))
}

impl Metadata {
    fn parse(path: &std::path::Path, xml: &str) -> Result<Self> {
        if xml.is_empty() {
            return Ok(Metadata::default());
        }
        let doc = roxmltree::Document::parse(xml)
            .map_err(|e| bad(path, format!("metadata XML does not parse: {e}")))?;
        let mut meta = Metadata::default();
        let number = |n: Option<roxmltree::Node>| n.and_then(|n| n.text()?.trim().parse().ok());
        for d in doc.descendants().filter(|n| n.has_tag_name("Distance")) {
            if !d.parent().is_some_and(|p| p.has_tag_name("Items")) {
                continue;
            }
            let k = match d.attribute("Id") {
                Some("X") => 0,
                Some("Y") => 1,
                Some("Z") => 2,
                _ => continue,
            };
            meta.scaling[k] = VoxelSize::valid(number(find(d, "Value")));
        }
        if let Some(dims) = doc.descendants().find(|n| {
            n.has_tag_name("Dimensions") && n.parent().is_some_and(|p| p.has_tag_name("Image"))
        }) {
            if let Some(chs) = find(dims, "Channels") {
                for ch in chs.children().filter(|n| n.has_tag_name("Channel")) {
                    let nm = |tag| number(find(ch, tag)).map(|v: f64| v * 1e-9);
                    meta.channels.push(ChannelInfo {
                        name: ch
                            .attribute("Name")
                            .filter(|n| !n.is_empty())
                            .map(str::to_string),
                        emission_wavelength_m: nm("EmissionWavelength"),
                        excitation_wavelength_m: nm("ExcitationWavelength"),
                    });
                }
            }
            if let Some(scenes) = find(dims, "S").and_then(|s| find(s, "Scenes")) {
                meta.scene_names = scenes
                    .children()
                    .filter(|n| n.has_tag_name("Scene"))
                    .map(|n| n.attribute("Name").unwrap_or_default().to_string())
                    .collect();
            }
        }
        Ok(meta)
    }
}

fn series_info(
    path: &std::path::Path,
    index: usize,
    scene: &Scene,
    entries: &[Entry],
    meta: &Metadata,
) -> Result<SeriesInfo> {
    let first = &entries[scene.entries[0]];
    let (dtype, spp) = pixel_layout(first.pixel_type).map_err(|e| {
        unsupported(
            path,
            format!("{e} pixels (contactscope reads grey and BGR 8/16-bit and float32 CZI)"),
        )
    })?;
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for name in scene.origin.keys() {
        let starts: std::collections::BTreeSet<i32> = scene
            .entries
            .iter()
            .map(|&i| entries[i].start(name))
            .collect();
        let (lo, hi) = (
            starts.first().copied().unwrap_or(0),
            starts.last().copied().unwrap_or(0),
        );
        counts.insert(name.clone(), (i64::from(hi) - i64::from(lo) + 1) as usize);
    }
    let take = |counts: &mut BTreeMap<String, usize>, k: &str| counts.remove(k).unwrap_or(1);
    let (t, z, c) = (
        take(&mut counts, "T"),
        take(&mut counts, "Z"),
        take(&mut counts, "C"),
    );
    counts.retain(|_, n| *n > 1);
    if spp > 1 {
        counts.insert("S".into(), spp);
    }
    let axes = Axes {
        t,
        z,
        c,
        y: scene.bbox.3,
        x: scene.bbox.2,
        extra: counts,
    };
    // Corrupt coordinates show as axes far longer than the subblocks can fill, or a bounding
    // box far larger than its tiles: refuse before planes of zeros are decoded.
    let (total, tiles) = (axes.planes() / spp, scene.entries.len());
    if total > 2 * tiles {
        return Err(bad(
            path,
            format!("the subblock coordinates span {total} planes for {tiles} subblocks (corrupt directory?)"),
        ));
    }
    let tile_area: u64 = scene
        .entries
        .iter()
        .map(|&i| {
            let (_, _, w, h, _, _) = entries[i].rect();
            (w.max(0) as u64).saturating_mul(h.max(0) as u64)
        })
        .fold(0u64, u64::saturating_add);
    let box_area = (axes.x as u64).saturating_mul(axes.y as u64);
    if box_area > (64 * tile_area / total.max(1) as u64).max(1 << 20) {
        return Err(bad(
            path,
            format!(
                "scene bounding box of {}×{} pixels is far larger than its tiles (corrupt directory?)",
                axes.x, axes.y
            ),
        ));
    }
    let [x, y, z_m] = meta.scaling;
    let source = (x.is_some() || y.is_some())
        .then(|| "CZI metadata Scaling/Items/Distance[@Id=X|Y]/Value".to_string());
    let mut channels = meta.channels.clone();
    channels.resize(c, ChannelInfo::default());
    Ok(SeriesInfo {
        index,
        name: meta.scene_names.get(index).cloned().unwrap_or_default(),
        axes,
        dtype,
        pixel_size: VoxelSize {
            x_m: x,
            y_m: y.or(x),
            z_m,
            source,
        },
        channels,
        rows: super::Rows::Y,
        tiff_axes: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zstd1_undoes_the_hi_lo_packing() {
        let p = std::path::Path::new("x.czi");
        // Two 16-bit samples 0x0201 and 0x0403: low bytes first, then high bytes.
        let packed = [0x01u8, 0x03, 0x02, 0x04];
        let mut raw = vec![3u8, 1, 1];
        raw.extend(zstd::bulk::compress(&packed, 3).unwrap());
        assert_eq!(
            zstd1_decode(p, &raw, 4, 2).unwrap(),
            vec![0x01, 0x02, 0x03, 0x04]
        );
        let mut plain = vec![1u8];
        plain.extend(zstd::bulk::compress(&packed, 3).unwrap());
        assert_eq!(zstd1_decode(p, &plain, 4, 2).unwrap(), packed.to_vec());
        // A frame that decodes to more than the tile needs is an error, not a large buffer.
        assert!(zstd_decode(p, &zstd::bulk::compress(&[0u8; 64], 3).unwrap(), 8).is_err());
        assert!(zstd1_decode(p, &[9u8, 1], 4, 2).is_err());
    }

    #[test]
    fn pixel_types_and_compression_names() {
        assert_eq!(pixel_layout(3).unwrap(), (SampleType::U8, 3));
        assert!(pixel_layout(12).unwrap_err().contains("Gray32"));
        assert_eq!(compression_name(4), "JPEG-XR");
    }
}
