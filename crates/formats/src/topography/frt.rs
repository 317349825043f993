//! FRT MicroProf `.frt` (`FRTM_GLIDERV1.00` / `1.01`): after the 16-byte magic and version,
//! a block count (u16) and that many blocks, each a tag (u16), a size (u32 for 1.00, u64 for
//! 1.01) and the payload. Block 0x66 gives x size, y size and bits per point (16: uint16,
//! 32: int32); 0x67 the scan sizes x and y (f64, m); 0x6C the height scale (f64, m per unit)
//! after a u32; 0x0B the heights row by row. A raw value of 1 marks an invalid point. Files
//! with only the multi-image block (0x7D) are refused.

use std::collections::HashMap;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

/// Read the topography of an FRT file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let version = slice(path, data, 12, 4, "the FRT version")?;
    let wide = match version {
        b"1.00" => false,
        b"1.01" => true,
        v => {
            return Err(unsupported(
                path,
                format!("FRT version {}", String::from_utf8_lossy(v)),
            ))
        }
    };
    let mut r = Reader::new(path, data, 16);
    let n = r.u16()?;
    let mut blocks: HashMap<u16, (usize, usize)> = HashMap::new();
    for _ in 0..n {
        let tag = r.u16()?;
        let size = if wide { r.usize_u64()? } else { r.usize_u32()? };
        slice(path, data, r.pos, size, "an FRT block")?;
        blocks.entry(tag).or_insert((r.pos, size));
        r.pos += size;
    }
    let block = |t: u16| {
        blocks.get(&t).copied().ok_or_else(|| {
            if t == 0x0B && blocks.contains_key(&0x7D) {
                unsupported(path, "FRT file with only a multi-image block (0x7D)")
            } else {
                bad(path, format!("FRT block {t:#x} is missing"))
            }
        })
    };
    let (g, _) = block(0x66)?;
    let mut gr = Reader::new(path, data, g);
    let (nx, ny, bits) = (gr.u32()?, gr.u32()?, gr.u32()?);
    let (nx, ny) = (
        count(path, "x size", f64::from(nx))?,
        count(path, "y size", f64::from(ny))?,
    );
    let (width, signed) = match bits {
        16 => (2, false),
        32 => (4, true),
        b => return Err(unsupported(path, format!("FRT points of {b} bits"))),
    };
    let (s, _) = block(0x67)?;
    let mut sr = Reader::new(path, data, s);
    let (size_x, size_y) = (sr.f64()?, sr.f64()?);
    let (z, _) = block(0x6C)?;
    let scale = Reader::new(path, data, z + 4).f64()?;
    let (d, len) = block(0x0B)?;
    let bytes = grid_bytes(path, nx, ny, width)?;
    if len < bytes {
        return Err(bad(
            path,
            format!("FRT height block of {len} bytes, {nx}×{ny} points need {bytes}"),
        ));
    }
    let channels = [ChannelEntry {
        name: "default".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let raw = decode_values(&data[d..d + bytes], width, false, signed, false);
    let heights = raw
        .into_iter()
        .map(|v| if v == 1.0 { f64::NAN } else { v * scale })
        .collect();
    let dx = positive(path, "x scan size", size_x)? / nx as f64;
    let dy = positive(path, "y scan size", size_y)? / ny as f64;
    height_map(
        path,
        TopographyFormat::Frt,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}
