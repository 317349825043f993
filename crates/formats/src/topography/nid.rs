//! Nanosurf `.nid`: an INI-style text header (`[DataSet]` lists groups `GrG-ChC=DataSet-G:C`;
//! each `[DataSet-G:C]` section gives `Points`, `Lines`, the axis ranges `DimNRange`/`DimNUnit`,
//! the value axis `Dim2Name`, `Dim2Min`, `Dim2Range`, `Dim2Unit` and `SaveBits`, `SaveSign`),
//! then `#!` and the channels' binary data in the order the groups list them (little-endian).
//! A signed b-bit value maps to `Dim2Min + Dim2Range · (raw + 2^(b−1)) / 2^b` (the full range
//! of the integer spans `Dim2Range`), as Nanosurf's documentation describes. Channel names are
//! `<group name> (<Dim2Name>)`, e.g. `Scan forward (Z-Axis)`. Pixel size: `Dim0Range/Points`,
//! `Dim1Range/Lines`.

use std::collections::HashMap;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_factor, length_scale, positive, ChannelEntry,
    HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported};
use crate::error::Result;

/// Read one channel of a Nanosurf `.nid` file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let split = data
        .windows(2)
        .position(|w| w == b"#!")
        .ok_or_else(|| bad(path, "no '#!' marker ending the NID header"))?;
    let text: String = data[..split].iter().map(|&b| char::from(b)).collect();
    let mut sections: HashMap<String, HashMap<String, String>> = HashMap::new();
    let mut current = String::new();
    for line in text.lines() {
        let line = line.trim();
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            current = name.to_string();
        } else if let Some((k, v)) = line.split_once('=') {
            sections
                .entry(current.clone())
                .or_default()
                .insert(k.trim().to_string(), v.trim().to_string());
        }
    }
    let top = sections
        .get("DataSet")
        .ok_or_else(|| bad(path, "no [DataSet] section"))?;
    let groups = top
        .get("GroupCount")
        .and_then(|v| v.parse::<usize>().ok())
        .unwrap_or(0)
        .min(64);
    // Channels in file order: groups in order, channels by index.
    let mut list = Vec::new();
    for g in 0..groups {
        let group = top.get(&format!("Gr{g}-Name")).cloned().unwrap_or_default();
        let n = top
            .get(&format!("Gr{g}-Count"))
            .and_then(|v| v.parse::<usize>().ok())
            .unwrap_or(0)
            .min(1024);
        for c in 0..n {
            if let Some(section) = top.get(&format!("Gr{g}-Ch{c}")) {
                let s = sections
                    .get(section)
                    .ok_or_else(|| bad(path, format!("section [{section}] is missing")))?;
                list.push((group.clone(), s));
            }
        }
    }
    let num = |s: &HashMap<String, String>, k: &str| -> Result<f64> {
        s.get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| bad(path, format!("NID channel lacks a number for {k}")))
    };
    let mut channels = Vec::new();
    let mut layout = Vec::new();
    let mut offset = split + 2;
    for (group, s) in &list {
        let (nx, ny) = (
            count(path, "Points", num(s, "Points")?)?,
            count(path, "Lines", num(s, "Lines")?)?,
        );
        let bits = num(s, "SaveBits")? as usize;
        if ![16, 32].contains(&bits) {
            return Err(unsupported(path, format!("NID data of {bits} bits")));
        }
        let bytes = grid_bytes(path, nx, ny, bits / 8)?;
        let name = format!("{group} ({})", s.get("Dim2Name").map_or("", String::as_str));
        let unit = s.get("Dim2Unit").cloned().unwrap_or_default();
        channels.push(ChannelEntry {
            name,
            height: length_factor(&unit).is_some(),
        });
        layout.push((offset, nx, ny, bits, unit, *s));
        offset += bytes;
    }
    let index = choose(path, &channels, channel)?;
    let (offset, nx, ny, bits, unit, s) = &layout[index];
    let scale = length_scale(path, &channels[index], unit)?;
    let signed = s.get("SaveSign").is_none_or(|v| v == "Signed");
    let raw = slice(path, data, *offset, nx * ny * bits / 8, "channel data")?;
    let (min, range) = (num(s, "Dim2Min")?, num(s, "Dim2Range")?);
    let full = 2f64.powi(*bits as i32);
    let shift = if signed { full / 2.0 } else { 0.0 };
    let heights = decode_values(raw, bits / 8, false, signed, false)
        .into_iter()
        .map(|v| (min + range * (v + shift) / full) * scale)
        .collect();
    let x_unit = length_factor(s.get("Dim0Unit").map_or("m", String::as_str)).unwrap_or(1.0);
    let y_unit = length_factor(s.get("Dim1Unit").map_or("m", String::as_str)).unwrap_or(1.0);
    let dx = positive(path, "Dim0Range", num(s, "Dim0Range")?)? * x_unit / *nx as f64;
    let dy = positive(path, "Dim1Range", num(s, "Dim1Range")?)? * y_unit / *ny as f64;
    height_map(
        path,
        TopographyFormat::Nid,
        (&channels, index),
        (*ny, *nx),
        heights,
        (dx, dy),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nid(unit: &str) -> Vec<u8> {
        let header = format!(
            "[DataSet]\r\nGroupCount=1\r\nGr0-Name=Scan forward\r\nGr0-Count=1\r\n\
             Gr0-Ch0=DataSet-0:0\r\n\r\n[DataSet-0:0]\r\nPoints=2\r\nLines=1\r\nDim0Range=4e-06\r\n\
             Dim0Unit=m\r\nDim1Range=1e-06\r\nDim1Unit=m\r\nDim2Name=Z-Axis\r\nDim2Unit={unit}\r\n\
             Dim2Range=2e-06\r\nDim2Min=-1e-06\r\nSaveBits=16\r\nSaveSign=Signed\r\n#!"
        );
        let mut bytes = header.into_bytes();
        bytes.extend(i16::MIN.to_le_bytes());
        bytes.extend(0i16.to_le_bytes());
        bytes
    }

    #[test]
    fn the_integer_range_spans_dim2_range() {
        let p = Path::new("n.nid");
        let m = read(p, &nid("m"), None).unwrap();
        assert_eq!(m.channel, "Scan forward (Z-Axis)");
        assert!((m.heights[[0, 0]] + 1e-6).abs() < 1e-20);
        assert!(m.heights[[0, 1]].abs() < 1e-20);
        assert_eq!((m.dx_m, m.dy_m), (2e-6, 1e-6));
        let err = read(p, &nid("V"), None).unwrap_err().to_string();
        assert!(err.contains("'V', not a length"), "{err}");
        let truncated = nid("m");
        assert!(read(p, &truncated[..truncated.len() - 1], None).is_err());
    }
}
