//! Gwyddion native `.gwy` files (the "GWYP" serialisation described in Gwyddion's user guide,
//! "Gwyddion Native File Format"): the magic `GWYP`, then one serialised object: its type name
//! (NUL-terminated), the size of its components (u32), and the components, each a name
//! (NUL-terminated), a type character and the value (`b`/`c` 1 byte, `i` i32, `q` i64, `d` f64,
//! `s` NUL-terminated string, `o` a nested object; upper-case letters are arrays: a u32 count,
//! then the items). All numbers are little-endian.
//!
//! Channels are the container's `/N/data` `GwyDataField` objects (`xres`, `yres`, `xreal`,
//! `yreal`, `si_unit_xy`, `si_unit_z`, `data` as doubles, row by row), named by `/N/data/title`;
//! a `/N/mask` field marks invalid points where its value is non-zero. Gwyddion stores values in
//! base SI units, so a length unit is `m`; **an empty unit string (dimensionless, as in data
//! imported without units) is taken as metres**; other units make a channel non-height.

use std::collections::BTreeMap;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_scale, positive, ChannelEntry, HeightMap,
    TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, Reader};
use crate::error::Result;

const MAX_DEPTH: usize = 16;

/// A deserialised value (arrays of doubles are kept as their position).
#[derive(Debug, Clone)]
enum Value {
    Num(f64),
    Str(String),
    Object(String, Vec<(String, Value)>),
    Doubles(usize, usize),
    Other,
}

impl Value {
    fn get(&self, name: &str) -> Option<&Value> {
        match self {
            Value::Object(_, items) => items.iter().find(|(n, _)| n == name).map(|(_, v)| v),
            _ => None,
        }
    }

    fn num(&self, name: &str) -> Option<f64> {
        match self.get(name)? {
            Value::Num(v) => Some(*v),
            _ => None,
        }
    }

    fn unit(&self, name: &str) -> String {
        match self.get(name).and_then(|u| u.get("unitstr")) {
            Some(Value::Str(s)) => s.clone(),
            _ => String::new(),
        }
    }
}

fn cstring(r: &mut Reader, data: &[u8]) -> Result<String> {
    let start = r.pos;
    let len = data
        .get(start..)
        .and_then(|d| d.iter().position(|&b| b == 0))
        .ok_or_else(|| crate::error::Error::InvalidArgument("unterminated string".into()))?;
    let s = String::from_utf8_lossy(r.take(len)?).into_owned();
    r.take(1)?;
    Ok(s)
}

fn object(path: &Path, r: &mut Reader, data: &[u8], depth: usize) -> Result<Value> {
    if depth > MAX_DEPTH {
        return Err(bad(path, "GWY objects nested too deeply"));
    }
    let name = cstring(r, data).map_err(|_| bad(path, "unterminated GWY object name"))?;
    let size = r.usize_u32()?;
    let end = r
        .pos
        .checked_add(size)
        .filter(|&e| e <= data.len())
        .ok_or_else(|| {
            bad(
                path,
                format!("file is truncated: GWY object '{name}' of {size} bytes"),
            )
        })?;
    let mut items = Vec::new();
    while r.pos < end {
        let key = cstring(r, data).map_err(|_| bad(path, "unterminated GWY component name"))?;
        let kind = r.u8()?;
        let value = match kind {
            b'b' | b'c' => Value::Num(f64::from(r.u8()?)),
            b'i' => Value::Num(f64::from(r.i32()?)),
            b'q' => Value::Num(r.i64()? as f64),
            b'd' => Value::Num(r.f64()?),
            b's' => Value::Str(cstring(r, data).map_err(|_| bad(path, "unterminated GWY string"))?),
            b'o' => object(path, r, data, depth + 1)?,
            b'B' | b'C' | b'I' | b'Q' | b'D' => {
                let n = r.usize_u32()?;
                let w = match kind {
                    b'B' | b'C' => 1,
                    b'I' => 4,
                    _ => 8,
                };
                let at = r.pos;
                r.take(
                    n.checked_mul(w)
                        .ok_or_else(|| bad(path, "GWY array too large"))?,
                )?;
                if kind == b'D' {
                    Value::Doubles(at, n)
                } else {
                    Value::Other
                }
            }
            b'S' | b'O' => {
                let n = r.usize_u32()?;
                if n > r.remaining() {
                    return Err(bad(
                        path,
                        format!("GWY array of {n} items in {} bytes", r.remaining()),
                    ));
                }
                for _ in 0..n {
                    if kind == b'S' {
                        cstring(r, data).map_err(|_| bad(path, "unterminated GWY string"))?;
                    } else {
                        object(path, r, data, depth + 1)?;
                    }
                }
                Value::Other
            }
            k => {
                return Err(bad(
                    path,
                    format!("unknown GWY component type '{}' ({key})", char::from(k)),
                ))
            }
        };
        items.push((key, value));
    }
    Ok(Value::Object(name, items))
}

/// Read one data field of a Gwyddion file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    if !data.starts_with(b"GWYP") {
        return Err(bad(path, "not a Gwyddion GWYP file"));
    }
    let mut r = Reader::new(path, data, 4);
    let root = object(path, &mut r, data, 0)?;
    let Value::Object(_, items) = &root else {
        unreachable!()
    };
    // Channel numbers in order, with their field, title and mask.
    let mut fields: BTreeMap<u32, (&Value, Option<String>, Option<&Value>)> = BTreeMap::new();
    for (key, value) in items {
        let Some(rest) = key.strip_prefix('/') else {
            continue;
        };
        let Some((n, tail)) = rest.split_once('/') else {
            continue;
        };
        let Ok(n) = n.parse::<u32>() else { continue };
        match (tail, value) {
            ("data", Value::Object(t, _)) if t == "GwyDataField" => {
                fields.entry(n).or_insert((value, None, None)).0 = value;
            }
            ("data/title", Value::Str(s)) => {
                if let Some(f) = fields.get_mut(&n) {
                    f.1 = Some(s.clone());
                }
            }
            ("mask", Value::Object(t, _)) if t == "GwyDataField" => {
                if let Some(f) = fields.get_mut(&n) {
                    f.2 = Some(value);
                }
            }
            _ => {}
        }
    }
    // Titles may precede their field: look them up again.
    let title = |n: u32| {
        items.iter().find_map(|(k, v)| match v {
            Value::Str(s) if *k == format!("/{n}/data/title") => Some(s.clone()),
            _ => None,
        })
    };
    let list: Vec<(u32, &Value, Option<&Value>)> =
        fields.iter().map(|(n, f)| (*n, f.0, f.2)).collect();
    let channels: Vec<ChannelEntry> = list
        .iter()
        .map(|(n, f, _)| {
            let unit = f.unit("si_unit_z");
            ChannelEntry {
                name: title(*n).unwrap_or_else(|| format!("/{n}/data")),
                height: unit.is_empty() || unit == "m",
            }
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let (_, field, mask) = list[index];
    let unit = field.unit("si_unit_z");
    if !unit.is_empty() {
        length_scale(path, &channels[index], &unit)?;
    }
    let num = |v: &Value, k: &str| {
        v.num(k)
            .ok_or_else(|| bad(path, format!("GwyDataField lacks {k}")))
    };
    let nx = count(path, "xres", num(field, "xres")?)?;
    let ny = count(path, "yres", num(field, "yres")?)?;
    grid_bytes(path, nx, ny, 8)?;
    let doubles = |v: &Value| -> Result<Vec<f64>> {
        match v.get("data") {
            Some(Value::Doubles(at, n)) if *n == nx * ny => Ok(decode_values(
                slice(path, data, *at, n * 8, "GWY data")?,
                8,
                true,
                true,
                false,
            )),
            _ => Err(bad(
                path,
                format!("GwyDataField data do not hold {nx}×{ny} values"),
            )),
        }
    };
    let mut heights = doubles(field)?;
    if let Some(mask) = mask {
        for (h, m) in heights.iter_mut().zip(doubles(mask)?) {
            if m != 0.0 {
                *h = f64::NAN;
            }
        }
    }
    let xy = field.unit("si_unit_xy");
    if !(xy.is_empty() || xy == "m") {
        return Err(bad(path, format!("lateral unit '{xy}' is not a length")));
    }
    let dx = positive(path, "xreal", num(field, "xreal")?)? / nx as f64;
    let dy = positive(path, "yreal", num(field, "yreal")?)? / ny as f64;
    height_map(
        path,
        TopographyFormat::Gwy,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}
