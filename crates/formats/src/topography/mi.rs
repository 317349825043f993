//! Molecular Imaging / Agilent PicoView `.mi` images: a text header of lines with a 14-character
//! key field and a value (`xPixels`, `yPixels`, `xLength`, `yLength` in m), one block per
//! buffer (`bufferLabel`, `bufferRange`, `bufferUnit`, …), closed by `data          BINARY`
//! (int16) or `BINARY_32` (int32) and a newline; the buffers follow one after the other,
//! little-endian. A value is `raw · bufferRange / 2^(b−1)` in `bufferUnit`. ASCII data
//! (`data          ASCII`) is refused.

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_factor, length_scale, positive, ChannelEntry,
    HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported};
use crate::error::Result;

/// Header lines as (key, value).
type Fields = Vec<(String, String)>;

/// Read one buffer of a PicoView image.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let marker = b"data          ";
    let at = data
        .windows(marker.len())
        .position(|w| w == marker)
        .ok_or_else(|| bad(path, "no 'data' line ending the MI header"))?;
    let line_end = data[at..]
        .iter()
        .position(|&b| b == b'\n')
        .map(|p| at + p + 1)
        .ok_or_else(|| bad(path, "MI header is truncated"))?;
    let kind = String::from_utf8_lossy(&data[at + marker.len()..line_end])
        .trim()
        .to_string();
    let width = match kind.as_str() {
        "BINARY" => 2,
        "BINARY_32" => 4,
        other => return Err(unsupported(path, format!("MI data stored as '{other}'"))),
    };
    let text: String = data[..at].iter().map(|&b| char::from(b)).collect();
    let (mut global, mut buffers): (Fields, Vec<Fields>) = (vec![], vec![]);
    for line in text.lines() {
        let line = line.trim_end_matches('\r');
        let (k, v) = (
            line.get(..14).unwrap_or(line).trim(),
            line.get(14..).unwrap_or("").trim(),
        );
        if k == "bufferLabel" {
            buffers.push(Vec::new());
        }
        match buffers.last_mut() {
            Some(b) => b.push((k.to_string(), v.to_string())),
            None => global.push((k.to_string(), v.to_string())),
        }
    }
    let get = |list: &[(String, String)], k: &str| {
        list.iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.clone())
    };
    let num = |list: &[(String, String)], k: &str| -> Result<f64> {
        get(list, k)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| bad(path, format!("MI header lacks {k}")))
    };
    let nx = count(path, "xPixels", num(&global, "xPixels")?)?;
    let ny = count(path, "yPixels", num(&global, "yPixels")?)?;
    let bytes = grid_bytes(path, nx, ny, width)?;
    let channels: Vec<ChannelEntry> = buffers
        .iter()
        .map(|b| {
            let label = get(b, "bufferLabel").unwrap_or_default();
            let name = match get(b, "trace").or_else(|| get(b, "direction")) {
                Some(t) if !t.is_empty() => format!("{label} ({t})"),
                _ => label,
            };
            let height = get(b, "bufferUnit").is_some_and(|u| length_factor(&u).is_some());
            ChannelEntry { name, height }
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let unit = get(&buffers[index], "bufferUnit").unwrap_or_default();
    let scale = length_scale(path, &channels[index], &unit)?;
    let range = num(&buffers[index], "bufferRange")?;
    let raw = slice(path, data, line_end + index * bytes, bytes, "buffer data")?;
    let lsb = range / 2f64.powi(8 * width as i32 - 1) * scale;
    let heights = decode_values(raw, width, false, true, false)
        .into_iter()
        .map(|v| v * lsb)
        .collect();
    let dx = positive(path, "xLength", num(&global, "xLength")?)? / nx as f64;
    let dy = positive(path, "yLength", num(&global, "yLength")?)? / ny as f64;
    height_map(
        path,
        TopographyFormat::Mi,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}
