//! Park Systems TIFF (SmartScan, XEI): a classic TIFF whose first page is a preview; the
//! measurement is in private tags of the first IFD: 50432 magic (`0x0E031301`), 50433 version
//! (`0x01000001` or `0x01000002`), 50434 the raw data (int16 for version 1; int16, int32 or
//! float32 by the header's data type for version 2), 50435 the header (little-endian: image
//! type, source name (32 UTF-16 units), image mode, …, width and height at bytes 100 and 104,
//! scan sizes x/y (f64) at 140 and 148, data gain, scale factor and offset (f64) at 220, 228,
//! 236, the data unit (8 UTF-16 units) at 244, and, for version 2, the data type at 348). The
//! layout follows Park Systems' published TIFF description as SurfaceTopography documents it.
//!
//! Heights: `(raw + offset/scale) · scale · gain` in the data unit (µm when empty; a scale of 0
//! means 1). Pixel size: scan size (µm) / pixels. Line profiles (image type 1) are refused.

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_factor, length_scale, positive, ChannelEntry,
    HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, utf16le, FileSource, Reader};
use crate::error::Result;

const MAGIC: u32 = 0x0E03_1301;

/// The tags of the first IFD of a classic TIFF: (tag, type, count, value-or-offset).
fn first_ifd(path: &Path, head: &[u8], ifd: &[u8]) -> Result<Vec<(u16, u16, u32, u32)>> {
    let big = head.starts_with(b"MM");
    let mut r = Reader::new(path, ifd, 0).big_endian(big);
    let n = r.u16()? as usize;
    (0..n)
        .map(|_| Ok((r.u16()?, r.u16()?, r.u32()?, r.u32()?)))
        .collect()
}

/// The first IFD's entries read from a file (at most 4096 of them).
pub(crate) fn entries_of(source: &mut FileSource) -> Result<Vec<(u16, u16, u32, u32)>> {
    let path = source.path.clone();
    let head = source.read_up_to(0, 8)?;
    if head.len() < 8 {
        return Ok(Vec::new());
    }
    let offset = Reader::new(&path, &head, 4)
        .big_endian(head.starts_with(b"MM"))
        .u32()? as u64;
    let n = source.read_up_to(offset, 2)?;
    if n.len() < 2 {
        return Ok(Vec::new());
    }
    let count = Reader::new(&path, &n, 0)
        .big_endian(head.starts_with(b"MM"))
        .u16()? as usize;
    let ifd = source.read_up_to(offset, 2 + 12 * count.min(4096))?;
    first_ifd(&path, &head, &ifd).or(Ok(Vec::new()))
}

/// Whether a TIFF's first IFD carries the Park Systems magic tag.
pub(crate) fn is_park(source: &mut FileSource) -> Result<bool> {
    Ok(entries_of(source)?
        .iter()
        .any(|e| e.0 == 50432 && e.3 == MAGIC))
}

/// Read the height map of a Park Systems TIFF.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let head = slice(path, data, 0, 8, "the TIFF header")?;
    let big = head.starts_with(b"MM");
    if big {
        return Err(unsupported(path, "big-endian Park Systems TIFF"));
    }
    let offset = Reader::new(path, data, 4).u32()? as usize;
    let n = Reader::new(path, data, offset).u16()? as usize;
    let tags = first_ifd(
        path,
        head,
        slice(path, data, offset, 2 + 12 * n, "the first IFD")?,
    )?;
    let tag = |t: u16| tags.iter().find(|e| e.0 == t).copied();
    if tag(50432).map(|e| e.3) != Some(MAGIC) {
        return Err(bad(path, "not a Park Systems TIFF (tag 50432 is missing)"));
    }
    let version = tag(50433).map_or(0, |e| e.3);
    let blob = |t: u16, what: &str| -> Result<&[u8]> {
        let e = tag(t).ok_or_else(|| bad(path, format!("Park TIFF without tag {t} ({what})")))?;
        slice(path, data, e.3 as usize, e.2 as usize, what)
    };
    let header = blob(50435, "the Park header")?;
    let mut r = Reader::new(path, header, 0);
    let image_type = r.u32()?;
    if image_type == 1 {
        return Err(unsupported(path, "Park Systems line profiles"));
    }
    let source_name = utf16le(r.take(64)?).trim_end_matches('\0').to_string();
    let num = |at: usize| Reader::new(path, header, at).f64();
    let int = |at: usize| Reader::new(path, header, at).u32();
    let nx = count(path, "width", f64::from(int(100)?))?;
    let ny = count(path, "height", f64::from(int(104)?))?;
    let (size_x, size_y) = (num(140)?, num(148)?);
    let (gain, scale, z_offset) = (num(220)?, num(228)?, num(236)?);
    let unit = utf16le(slice(path, header, 244, 16, "the data unit")?)
        .trim_end_matches('\0')
        .to_string();
    let unit = if unit.is_empty() {
        "µm".to_string()
    } else {
        unit
    };
    let data_type = if version == 0x0100_0002 { int(348)? } else { 0 };
    let (width, float) = match data_type {
        0 => (2, false),
        1 => (4, false),
        2 => (4, true),
        t => return Err(unsupported(path, format!("Park data type {t}"))),
    };
    let name = if source_name.is_empty() {
        "Height".to_string()
    } else {
        source_name
    };
    let unit_m = length_factor(&unit);
    let channels = [ChannelEntry {
        name,
        height: unit_m.is_some(),
    }];
    let index = choose(path, &channels, channel)?;
    let unit_m = length_scale(path, &channels[0], &unit)?;
    let bytes = grid_bytes(path, nx, ny, width)?;
    let raw = blob(50434, "the Park data")?;
    let raw = slice(path, raw, 0, bytes, "the Park data")?;
    let scale = if scale == 0.0 { 1.0 } else { scale };
    let heights = decode_values(raw, width, float, true, false)
        .into_iter()
        .map(|v| (v + z_offset / scale) * scale * gain * unit_m)
        .collect();
    let dx = positive(path, "x scan size", size_x)? * 1e-6 / nx as f64;
    let dy = positive(path, "y scan size", size_y)? * 1e-6 / ny as f64;
    height_map(
        path,
        TopographyFormat::ParkTiff,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}
