//! Wyko (Veeco/Bruker) Vision `.opd`: 2 bytes, then a directory of 24-byte block headers (name
//! 16 bytes, type i16, length i32, attribute u16; the first is `Directory` itself, its length
//! the directory's size); block payloads follow in directory order. Arrays (type 3) start with
//! x size, y size and item size (u16 each), then the values with y fastest (int16 or float32;
//! item size 1 is a mask); the height arrays are `RAW DATA`, `RAW_DATA`, `OPD`, `Raw` or
//! `SAMPLE_DATA`. `Wavelength` (nm, float), `Mult` (short, default 1), `Pixel_size` (mm,
//! float) and `Aspect` (default 1) scale them: height = raw · λ / Mult (nm), pixel size x =
//! `Pixel_size`, y = `Pixel_size · Aspect`. Values ≥ 32766 (int16) or ≥ 1e38 (float) are
//! invalid points. The map is returned with rows along y, row 0 the last stored y (as Vision
//! displays it).

use std::collections::HashMap;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

const HEIGHT_ARRAYS: [&str; 5] = ["RAW DATA", "RAW_DATA", "OPD", "Raw", "SAMPLE_DATA"];

/// Read the height array of a Wyko OPD file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let mut r = Reader::new(path, data, 2);
    let name = |b: &[u8]| {
        String::from_utf8_lossy(b)
            .trim_end_matches('\0')
            .trim()
            .to_string()
    };
    let first = name(r.take(16)?);
    let _ = r.i16()?;
    let dir_len = r.i32()?;
    r.u16()?;
    if first != "Directory" || dir_len < 24 || dir_len % 24 != 0 || dir_len as usize > data.len() {
        return Err(bad(path, format!("OPD directory of {dir_len} bytes")));
    }
    let mut pos = 2 + dir_len as usize;
    let mut arrays = Vec::new();
    let mut meta: HashMap<String, f64> = HashMap::new();
    for _ in 1..dir_len / 24 {
        let block = name(r.take(16)?);
        let (kind, len, _attr) = (r.i16()?, r.i32()?.max(0) as usize, r.u16()?);
        let payload = slice(path, data, pos, len, "an OPD block")?;
        let mut p = Reader::new(path, payload, 0);
        match (kind, len) {
            (3, _) if HEIGHT_ARRAYS.contains(&block.as_str()) => arrays.push((block, pos)),
            (6, 2) => {
                meta.insert(block, f64::from(p.i16()?));
            }
            (7, 2) => {
                meta.insert(block, f64::from(p.i16()?));
            }
            (7, 4..) => {
                meta.insert(block, f64::from(p.f32()?));
            }
            (8, 8..) => {
                meta.insert(block, p.f64()?);
            }
            (12, 4..) | (6, 4) => {
                meta.insert(block, f64::from(p.i32()?));
            }
            _ => {}
        }
        pos += len;
    }
    let channels: Vec<ChannelEntry> = arrays
        .iter()
        .map(|(n, _)| ChannelEntry {
            name: n.clone(),
            height: true,
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let at = arrays[index].1;
    let mut a = Reader::new(path, data, at);
    let nx = count(path, "OPD x size", f64::from(a.u16()?))?;
    let ny = count(path, "OPD y size", f64::from(a.u16()?))?;
    let item = a.u16()? as usize;
    let (float, limit) = match item {
        2 => (false, 32766.0),
        4 => (true, 1e38),
        other => {
            return Err(unsupported(
                path,
                format!("OPD height array of {other}-byte items"),
            ))
        }
    };
    let bytes = grid_bytes(path, nx, ny, item)?;
    let raw = decode_values(
        slice(path, data, at + 6, bytes, "the OPD array")?,
        item,
        float,
        true,
        false,
    );
    let wavelength = meta
        .get("Wavelength")
        .copied()
        .ok_or_else(|| bad(path, "OPD without a Wavelength block"))?;
    let mult = meta
        .get("Mult")
        .copied()
        .filter(|m| *m != 0.0)
        .unwrap_or(1.0);
    let scale = wavelength / mult * 1e-9;
    let mut heights = vec![0.0; nx * ny];
    for x in 0..nx {
        for y in 0..ny {
            let v = raw[x * ny + y];
            let h = if v.is_finite() && v < limit {
                v * scale
            } else {
                f64::NAN
            };
            heights[(ny - 1 - y) * nx + x] = h;
        }
    }
    let pixel = positive(
        path,
        "Pixel_size",
        meta.get("Pixel_size").copied().unwrap_or(f64::NAN),
    )? * 1e-3;
    let aspect = meta
        .get("Aspect")
        .copied()
        .filter(|a| *a > 0.0)
        .unwrap_or(1.0);
    height_map(
        path,
        TopographyFormat::Opd,
        (&channels, index),
        (ny, nx),
        heights,
        (pixel, pixel * aspect),
    )
}
