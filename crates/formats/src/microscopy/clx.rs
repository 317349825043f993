//! The binary "CLX-lite" variant tree that ND2 files (version 3) use for their metadata chunks,
//! read from the public descriptions of the format (nd2 Python package documentation,
//! Bio-Formats `NativeND2Reader` notes). An item is: type (u8), name length in UTF-16 units
//! including the terminating NUL (u8), the name (UTF-16LE), then the value: 1 bool (u8),
//! 2 i32, 3 u32, 4 i64, 5 u64, 6 f64, 7 pointer (u64), 8 NUL-terminated UTF-16LE string,
//! 9 byte array (u64 length, bytes), 11 level: item count (u32), length in bytes from the start
//! of the level item to the end of its children (u64), the children, then one u64 offset per
//! child (skipped).

use std::path::Path;

use crate::binary::{bad, utf16le, Reader};
use crate::error::Result;

/// Deepest nesting accepted.
const MAX_DEPTH: usize = 32;

/// One value of the tree.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Clx {
    /// Integers and booleans.
    Int(i64),
    /// Doubles.
    Float(f64),
    /// Strings.
    Str(String),
    /// A byte array or pointer (content not kept).
    Other,
    /// A nested level: named children in file order.
    Level(Vec<(String, Clx)>),
}

impl Clx {
    /// The child named `name` of a level.
    pub(crate) fn get(&self, name: &str) -> Option<&Clx> {
        match self {
            Clx::Level(items) => items.iter().find(|(n, _)| n == name).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Follow a path of names.
    pub(crate) fn at(&self, path: &[&str]) -> Option<&Clx> {
        path.iter().try_fold(self, |node, name| node.get(name))
    }

    /// The children of a level (empty otherwise).
    pub(crate) fn children(&self) -> &[(String, Clx)] {
        match self {
            Clx::Level(items) => items,
            _ => &[],
        }
    }

    /// A number.
    pub(crate) fn number(&self) -> Option<f64> {
        match self {
            Clx::Int(i) => Some(*i as f64),
            Clx::Float(f) => Some(*f),
            _ => None,
        }
    }

    /// A string.
    pub(crate) fn text(&self) -> Option<&str> {
        match self {
            Clx::Str(s) => Some(s),
            _ => None,
        }
    }
}

/// Parse a whole chunk: a sequence of items, returned as one level.
pub(crate) fn parse(path: &Path, data: &[u8]) -> Result<Clx> {
    if data.first() == Some(&76) {
        return Err(bad(
            path,
            "compressed (deflated) ND2 metadata is not supported",
        ));
    }
    let mut r = Reader::new(path, data, 0);
    let mut items = Vec::new();
    while r.pos < data.len() {
        items.push(item(path, &mut r, 0)?);
    }
    Ok(Clx::Level(items))
}

fn item(path: &Path, r: &mut Reader, depth: usize) -> Result<(String, Clx)> {
    if depth > MAX_DEPTH {
        return Err(bad(path, "ND2 metadata nested too deeply"));
    }
    let kind = r.u8()?;
    let name_len = r.u8()? as usize;
    let name = utf16le(r.take(2 * name_len)?)
        .trim_end_matches('\0')
        .to_string();
    let value = match kind {
        1 => Clx::Int(i64::from(r.u8()?)),
        2 => Clx::Int(i64::from(r.i32()?)),
        3 => Clx::Int(i64::from(r.u32()?)),
        4 => Clx::Int(r.i64()?),
        5 => Clx::Int(r.u64()? as i64),
        6 => Clx::Float(r.f64()?),
        7 => {
            r.u64()?;
            Clx::Other
        }
        8 => {
            let mut units = Vec::new();
            loop {
                let u = r.u16()?;
                if u == 0 {
                    break;
                }
                units.push(u);
            }
            Clx::Str(String::from_utf16_lossy(&units))
        }
        9 => {
            let n = r.usize_u64()?;
            r.take(n)?;
            Clx::Other
        }
        11 => {
            let count = r.usize_u32()?;
            let _length = r.u64()?;
            // Each child takes at least 4 bytes: a count beyond that is corrupt.
            let left = r.remaining();
            if count.saturating_mul(4) > left {
                return Err(bad(
                    path,
                    format!("ND2 metadata level '{name}' claims {count} items in {left} bytes"),
                ));
            }
            let children = (0..count)
                .map(|_| item(path, r, depth + 1))
                .collect::<Result<Vec<_>>>()?;
            r.take(8 * count)?;
            Clx::Level(children)
        }
        other => {
            return Err(bad(
                path,
                format!("unknown ND2 metadata item type {other} ('{name}')"),
            ))
        }
    };
    Ok((name, value))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(s: &str) -> Vec<u8> {
        let mut v = vec![(s.len() + 1) as u8];
        for u in s.encode_utf16().chain([0]) {
            v.extend(u.to_le_bytes());
        }
        v
    }

    #[test]
    fn parses_levels_and_values() {
        let mut inner = vec![6u8];
        inner.extend(name("d"));
        inner.extend(0.5f64.to_le_bytes());
        let mut data = vec![11u8];
        data.extend(name("L"));
        data.extend(1u32.to_le_bytes());
        data.extend(0u64.to_le_bytes());
        data.extend(&inner);
        data.extend(0u64.to_le_bytes());
        data.push(3);
        data.extend(name("u"));
        data.extend(7u32.to_le_bytes());
        let p = Path::new("x.nd2");
        let tree = parse(p, &data).unwrap();
        assert_eq!(tree.at(&["L", "d"]).and_then(Clx::number), Some(0.5));
        assert_eq!(tree.get("u").and_then(Clx::number), Some(7.0));
        assert!(parse(p, &data[..data.len() - 1]).is_err());
        let mut bad_count = data.clone();
        bad_count[6] = 0xff;
        assert!(parse(p, &bad_count).is_err());
    }
}
