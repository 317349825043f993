//! Leica LIF (LAS AF / LAS X), read by our own code. The layout was learnt from the public
//! descriptions in liffile (BSD-3) and readlif (GPL-3.0, read only, nothing taken over):
//!
//! * The file starts with a block `0x70` (u32), the block length (u32), `0x2A`, the number of
//!   UTF-16 units (u32) and the XML header (UTF-16LE).
//! * Memory blocks follow: `0x70`, a u32, `0x2A`, the data size (u32 in version 1, u64 in
//!   version 2, from `LMSDataContainerHeader@Version`), `0x2A`, the id length (u32), the id
//!   (UTF-16LE, e.g. `MemBlock_2699`), then the data.
//! * Every XML `Element` whose `Data` holds an `Image` is a series; its `Memory@MemoryBlockID`
//!   names its block. `ImageDescription/Channels/ChannelDescription` gives per channel the
//!   data type (0 integer, 1 float), bits (`Resolution`) and byte offset (`BytesInc`);
//!   `ImageDescription/Dimensions/DimensionDescription` gives per dimension `DimID`,
//!   `NumberOfElements`, `Length`, `Unit` and the byte stride `BytesInc`. DimIDs: 1 X, 2 Y, 3 Z,
//!   4 T, 5 emission λ (`lambda_emission`), 6 rotation (`A`), 7 XT slices (`N`), 8 T slices
//!   (`Q`), 9 excitation λ (`lambda_excitation`), 10 mosaic tile (`M`, kept as an axis: tiles
//!   are not placed).
//!
//! Pixel size: `Length / (NumberOfElements − 1)` of dimensions 1 and 2 (and 3 for z), in
//! `Unit` (m in LAS X files), as liffile computes it; absent for a dimension of one element.
//! Images whose memory block is empty (size 0) are listed by LAS X but hold no pixels: they
//! are skipped.

use std::collections::{BTreeMap, HashMap};

use super::{plane_from_le, Axes, ChannelInfo, PlaneIndex, SeriesInfo, VoxelSize};
use crate::binary::{bad, checked_bytes, unsupported, utf16le, FileSource, Reader};
use crate::error::Result;
use crate::image::{Plane, SampleType};
use crate::tiff::metadata::length_unit_factor;

/// Largest XML header accepted (bytes).
const MAX_XML_BYTES: usize = 256 << 20;

/// One dimension of an image.
#[derive(Debug, Clone)]
struct Dim {
    axis: String,
    count: usize,
    stride: usize,
}

/// Where a series' data are and how they are laid out.
#[derive(Debug, Clone)]
struct Layout {
    data_offset: u64,
    data_len: u64,
    dims: Vec<Dim>,
    channel_offsets: Vec<usize>,
    sample_bytes: usize,
}

/// An open LIF file.
pub struct LifReader {
    source: FileSource,
    layouts: Vec<Layout>,
    series: Vec<SeriesInfo>,
}

impl LifReader {
    /// Read the XML header and index the memory blocks.
    pub(crate) fn open(mut source: FileSource) -> Result<Self> {
        let path = source.path.clone();
        let head = source.read_at(0, 13, "the LIF header")?;
        let mut r = Reader::new(&path, &head, 0);
        let (magic, size, mark, units) = (r.u32()?, r.usize_u32()?, r.u8()?, r.usize_u32()?);
        if magic != 0x70 || mark != 0x2a {
            return Err(bad(&path, "not a LIF file (bad header block)"));
        }
        let xml_bytes = units.saturating_mul(2);
        if xml_bytes > MAX_XML_BYTES || xml_bytes + 5 > size {
            return Err(bad(&path, format!("LIF XML header of {units} characters")));
        }
        let xml = utf16le(&source.read_at(13, xml_bytes, "the XML header")?);
        let doc = roxmltree::Document::parse(&xml)
            .map_err(|e| bad(&path, format!("LIF XML header does not parse: {e}")))?;
        let version = doc
            .descendants()
            .find(|n| n.has_tag_name("LMSDataContainerHeader"))
            .and_then(|n| n.attribute("Version"))
            .and_then(|v| v.parse::<u32>().ok())
            .unwrap_or(2);
        let blocks = index_blocks(&mut source, 8 + size as u64, version)?;
        let mut layouts = Vec::new();
        let mut series = Vec::new();
        for element in doc.descendants().filter(|n| n.has_tag_name("Element")) {
            let Some(image) = child(element, "Data").and_then(|d| child(d, "Image")) else {
                continue;
            };
            let Some(&(offset, len)) = child(element, "Memory")
                .and_then(|m| m.attribute("MemoryBlockID"))
                .and_then(|id| blocks.get(id))
            else {
                continue;
            };
            if len == 0 {
                continue;
            }
            let name = element
                .ancestors()
                .filter(|n| n.has_tag_name("Element"))
                .filter_map(|n| n.attribute("Name"))
                .collect::<Vec<_>>();
            // Drop the root element (the project) from the path.
            let name = name[..name.len().saturating_sub(1)]
                .iter()
                .rev()
                .copied()
                .collect::<Vec<_>>()
                .join("/");
            let (info, layout) = describe(&path, series.len(), name, image, (offset, len))?;
            layouts.push(layout);
            series.push(info);
        }
        if series.is_empty() {
            return Err(bad(&path, "the LIF holds no image with pixel data"));
        }
        Ok(LifReader {
            source,
            layouts,
            series,
        })
    }

    /// The images as series.
    pub(crate) fn series(&self) -> Vec<SeriesInfo> {
        self.series.clone()
    }

    /// Read one plane.
    pub(crate) fn read_plane(&mut self, info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let l = &self.layouts[info.index];
        let mut offset = l.channel_offsets[index.c];
        let (mut x_stride, mut y_stride) = (l.sample_bytes, 0);
        for d in &l.dims {
            let i = match d.axis.as_str() {
                "X" => {
                    x_stride = d.stride;
                    0
                }
                "Y" => {
                    y_stride = d.stride;
                    0
                }
                "T" => index.t,
                "Z" => index.z,
                other => index.get(other),
            };
            offset += i * d.stride;
        }
        let (w, h) = (info.axes.x, info.axes.y);
        if x_stride != l.sample_bytes {
            return Err(unsupported(
                &self.source.path,
                format!(
                    "LIF X stride of {x_stride} bytes for {}-byte samples",
                    l.sample_bytes
                ),
            ));
        }
        let y_stride = if h > 1 { y_stride } else { w * l.sample_bytes };
        let len = y_stride * (h - 1) + w * l.sample_bytes;
        if (offset + len) as u64 > l.data_len {
            return Err(bad(
                &self.source.path,
                format!(
                    "series {}: plane at byte {offset} runs past its memory block of {} bytes",
                    info.index, l.data_len
                ),
            ));
        }
        let data = self
            .source
            .read_at(l.data_offset + offset as u64, len, "LIF plane data")?;
        plane_from_le(&self.source.path, (w, h), info.dtype, &data, y_stride)
    }
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, tag: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children().find(|n| n.has_tag_name(tag))
}

/// Memory block id → (data offset, data length).
fn index_blocks(
    source: &mut FileSource,
    mut pos: u64,
    version: u32,
) -> Result<HashMap<String, (u64, u64)>> {
    let path = source.path.clone();
    let mut blocks = HashMap::new();
    let size_len = if version >= 2 { 8 } else { 4 };
    while pos < source.len {
        let head = source.read_at(pos, 9 + size_len + 5, "a memory block header")?;
        let mut r = Reader::new(&path, &head, 0);
        if r.u32()? != 0x70 {
            return Err(bad(&path, format!("no LIF memory block at offset {pos}")));
        }
        r.u32()?;
        r.u8()?;
        let len = if size_len == 8 {
            r.u64()?
        } else {
            u64::from(r.u32()?)
        };
        r.u8()?;
        let units = r.usize_u32()?;
        let id_pos = pos + head.len() as u64;
        if units > 1024 {
            return Err(bad(&path, format!("memory block id of {units} characters")));
        }
        let id = utf16le(&source.read_at(id_pos, 2 * units, "a memory block id")?);
        let data = id_pos + 2 * units as u64;
        if data.checked_add(len).is_none_or(|end| end > source.len) {
            return Err(bad(
                &path,
                format!(
                    "file is truncated: memory block {id} needs {len} bytes at offset {data}, the file has {}",
                    source.len
                ),
            ));
        }
        blocks.insert(id, (data, len));
        pos = data + len;
    }
    Ok(blocks)
}

fn axis_name(id: &str) -> String {
    match id {
        "1" => "X",
        "2" => "Y",
        "3" => "Z",
        "4" => "T",
        "5" => "lambda_emission",
        "6" => "A",
        "7" => "N",
        "8" => "Q",
        "9" => "lambda_excitation",
        "10" => "M",
        other => return format!("dim{other}"),
    }
    .to_string()
}

fn describe(
    path: &std::path::Path,
    index: usize,
    name: String,
    image: roxmltree::Node,
    (data_offset, data_len): (u64, u64),
) -> Result<(SeriesInfo, Layout)> {
    let desc = child(image, "ImageDescription")
        .ok_or_else(|| bad(path, format!("image '{name}' has no ImageDescription")))?;
    let num = |n: roxmltree::Node, k: &str| -> Option<f64> { n.attribute(k)?.trim().parse().ok() };
    let channels: Vec<roxmltree::Node> = child(desc, "Channels")
        .map(|c| {
            c.children()
                .filter(|n| n.has_tag_name("ChannelDescription"))
                .collect()
        })
        .unwrap_or_default();
    let first = channels
        .first()
        .ok_or_else(|| bad(path, format!("image '{name}' has no channels")))?;
    let bits = num(*first, "Resolution").unwrap_or(8.0) as usize;
    let float = num(*first, "DataType") == Some(1.0);
    let (dtype, sample_bytes) = match (float, bits) {
        (false, 1..=8) => (SampleType::U8, 1),
        (false, 9..=16) => (SampleType::U16, 2),
        (true, 32) => (SampleType::F32, 4),
        _ => {
            return Err(unsupported(
                path,
                format!(
                    "image '{name}': {bits}-bit {} samples",
                    if float { "float" } else { "integer" }
                ),
            ))
        }
    };
    let mut dims = Vec::new();
    let mut sizes = BTreeMap::new();
    let mut step: HashMap<String, f64> = HashMap::new();
    for d in child(desc, "Dimensions")
        .map(|c| {
            c.children()
                .filter(|n| n.has_tag_name("DimensionDescription"))
                .collect::<Vec<_>>()
        })
        .unwrap_or_default()
    {
        let axis = axis_name(d.attribute("DimID").unwrap_or(""));
        let count = num(d, "NumberOfElements").unwrap_or(0.0);
        let stride = num(d, "BytesInc").unwrap_or(-1.0);
        if !((1.0..1e9).contains(&count) && (0.0..1e15).contains(&stride)) {
            return Err(bad(
                path,
                format!("image '{name}': dimension {axis} with {count} elements, stride {stride}"),
            ));
        }
        let unit = length_unit_factor(d.attribute("Unit").unwrap_or("m")).unwrap_or(f64::NAN);
        if count > 1.0 {
            if let Some(len) = num(d, "Length") {
                step.insert(axis.clone(), (len * unit / (count - 1.0)).abs());
            }
        }
        sizes.insert(axis.clone(), count as usize);
        dims.push(Dim {
            axis,
            count: count as usize,
            stride: stride as usize,
        });
    }
    let channel_offsets: Vec<usize> = channels
        .iter()
        .map(|c| num(*c, "BytesInc").unwrap_or(0.0).max(0.0) as usize)
        .collect();
    let mut take = |k: &str| sizes.remove(k).unwrap_or(1);
    let (x, y, z, t) = (take("X"), take("Y"), take("Z"), take("T"));
    checked_bytes(path, "LIF plane", &[x, y], sample_bytes)?;
    sizes.retain(|_, n| *n > 1);
    // The last byte any plane reaches must lie inside the memory block.
    let reach: usize = dims
        .iter()
        .map(|d| (d.count - 1).saturating_mul(d.stride))
        .fold(0usize, usize::saturating_add)
        + channel_offsets.iter().max().copied().unwrap_or(0)
        + sample_bytes;
    if reach as u64 > data_len {
        return Err(bad(
            path,
            format!("image '{name}' needs {reach} bytes, its memory block holds {data_len}"),
        ));
    }
    let xy = (
        VoxelSize::valid(step.get("X").copied()),
        VoxelSize::valid(step.get("Y").copied()),
    );
    let info = SeriesInfo {
        index,
        name,
        axes: Axes {
            t,
            z,
            c: channels.len(),
            y,
            x,
            extra: sizes,
        },
        dtype,
        pixel_size: VoxelSize {
            x_m: xy.0,
            y_m: xy.1,
            z_m: VoxelSize::valid(step.get("Z").copied()),
            source: (xy.0.is_some() || xy.1.is_some()).then(|| {
                "LIF DimensionDescription DimID=1|2 Length/(NumberOfElements-1)".to_string()
            }),
        },
        channels: vec![ChannelInfo::default(); channels.len()],
        rows: super::Rows::Y,
        tiff_axes: None,
    };
    Ok((
        info,
        Layout {
            data_offset,
            data_len,
            dims,
            channel_offsets,
            sample_bytes,
        },
    ))
}
