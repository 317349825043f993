//! NumPy `.npy` files (format versions 1.0, 2.0 and 3.0): magic `\x93NUMPY`, version bytes, a
//! little-endian header length (u16 for 1.x, u32 for 2.x/3.x), and a Python dict literal with
//! `'descr'`, `'fortran_order'` and `'shape'`, followed by the raw array.
//!
//! Kept rather than taken from `ndarray-npy` (0.10), measured on hostile and ordinary files
//! (`docs/performance.md`, "Numerics from crates"): a 224-byte file whose header claims a
//! 200 000 × 200 000 float64 array makes `ndarray-npy` allocate 320 GB and abort the process,
//! where this reader checks the size against the file first and reports it as truncated; a
//! float32 map is refused by `Array2::<f64>::read_npy` (a second, typed attempt would be needed);
//! and its errors carry neither the file nor the offset. Reading a 1024² float64 map takes
//! 14 ms here.

use std::path::Path;

use super::{HeightMap, TopographyFormat};
use crate::error::{Error, Location, Result};

use super::{bad, read_bytes, required_pixel_size, slice, to_metres, topography, unitless_scale};

const MAGIC: &[u8] = b"\x93NUMPY";

/// A value of the header dict (only the kinds npy headers use).
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Str(String),
    Bool(bool),
    Tuple(Vec<usize>),
}

/// Element type of the array.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Dtype {
    size: usize,
    big_endian: bool,
}

#[derive(Debug)]
struct Header {
    dtype: Dtype,
    fortran_order: bool,
    shape: (usize, usize),
    data_offset: usize,
}

/// Read a 2-D float32/float64 `.npy` array (rows = y, columns = x) as a [`HeightMap`]. The
/// pixel size must be given; heights are multiplied by `height_unit_m` (default 1: metres).
pub fn read_npy(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<HeightMap> {
    let convert = to_metres(unitless_scale(height_unit_m)?);
    let bytes = read_bytes(path)?;
    let header = parse_header(path, &bytes)?;
    let pixel = required_pixel_size(path, pixel_size_m, "npy")?;
    let (ny, nx) = header.shape;
    let len = super::vendor::grid_bytes(path, nx, ny, header.dtype.size)?;
    let count = nx * ny;
    let data = slice(path, &bytes, header.data_offset, len)?;
    let values = decode(data, header.dtype);
    let heights = if header.fortran_order {
        (0..count)
            .map(|k| convert(values[(k % nx) * ny + k / nx]))
            .collect()
    } else {
        values.into_iter().map(convert).collect()
    };
    topography(path, TopographyFormat::Npy, (ny, nx), heights, pixel)
}

/// The heights (metres, rows = y) as the bytes of a little-endian float64 C-order `.npy`
/// (version 1.0). The pixel size is not stored: pass it again when reading.
pub fn encode_npy(heights: &ndarray::Array2<f64>) -> Vec<u8> {
    let mut dict = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {}), }}",
        heights.nrows(),
        heights.ncols()
    );
    // Pad with spaces so that magic + version + length + dict + '\n' is a multiple of 64.
    while !(MAGIC.len() + 4 + dict.len() + 1).is_multiple_of(64) {
        dict.push(' ');
    }
    dict.push('\n');
    let mut out = Vec::with_capacity(10 + dict.len() + heights.len() * 8);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    for h in heights.iter() {
        out.extend_from_slice(&h.to_le_bytes());
    }
    out
}

fn decode(data: &[u8], dtype: Dtype) -> Vec<f64> {
    match (dtype.size, dtype.big_endian) {
        (4, false) => data
            .chunks_exact(4)
            .map(|c| f64::from(f32::from_le_bytes(c.try_into().unwrap())))
            .collect(),
        (4, true) => data
            .chunks_exact(4)
            .map(|c| f64::from(f32::from_be_bytes(c.try_into().unwrap())))
            .collect(),
        (_, false) => data
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect(),
        (_, true) => data
            .chunks_exact(8)
            .map(|c| f64::from_be_bytes(c.try_into().unwrap()))
            .collect(),
    }
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(bad(
            path,
            "not a .npy file (the magic \\x93NUMPY is missing)",
        ));
    }
    let (major, minor) = (bytes[6], bytes[7]);
    let (len, start) = match major {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 => {
            let raw = slice(path, bytes, 8, 4)?;
            (u32::from_le_bytes(raw.try_into().unwrap()) as usize, 12)
        }
        _ => {
            return Err(Error::Unsupported {
                at: Location::file(path),
                reason: format!("npy format version {major}.{minor} (1.0, 2.0 and 3.0 are read)"),
            })
        }
    };
    let text = std::str::from_utf8(slice(path, bytes, start, len)?)
        .map_err(|_| bad(path, "npy header is not text"))?;
    let dict = parse_dict(text).map_err(|reason| bad(path, format!("npy header: {reason}")))?;
    let get = |key: &str| {
        dict.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.clone())
            .ok_or_else(|| bad(path, format!("npy header has no '{key}'")))
    };
    let dtype = match get("descr")? {
        Value::Str(s) => parse_descr(path, &s)?,
        _ => return Err(bad(path, "npy 'descr' is not a string")),
    };
    let fortran_order = match get("fortran_order")? {
        Value::Bool(b) => b,
        _ => return Err(bad(path, "npy 'fortran_order' is not True or False")),
    };
    let shape = match get("shape")? {
        Value::Tuple(dims) if dims.len() == 2 => (dims[0], dims[1]),
        Value::Tuple(dims) => {
            return Err(bad(
                path,
                format!(
                    "a height map must be a 2-D array (shape has {} axes)",
                    dims.len()
                ),
            ))
        }
        _ => return Err(bad(path, "npy 'shape' is not a tuple")),
    };
    Ok(Header {
        dtype,
        fortran_order,
        shape,
        data_offset: start + len,
    })
}

fn parse_descr(path: &Path, descr: &str) -> Result<Dtype> {
    let big_endian = match descr.chars().next() {
        Some('<') => false,
        Some('>') => true,
        Some('=') => cfg!(target_endian = "big"),
        _ => return Err(unsupported_dtype(path, descr)),
    };
    let size = match &descr[1..] {
        "f4" => 4,
        "f8" => 8,
        _ => return Err(unsupported_dtype(path, descr)),
    };
    Ok(Dtype { size, big_endian })
}

fn unsupported_dtype(path: &Path, descr: &str) -> Error {
    Error::Unsupported {
        at: Location::file(path),
        reason: format!("npy dtype '{descr}'; save the heights as float32 or float64"),
    }
}

/// Parse `{'key': value, ...}` with string, boolean and integer-tuple values.
fn parse_dict(text: &str) -> std::result::Result<Vec<(String, Value)>, String> {
    let mut p = Parser {
        s: text.as_bytes(),
        i: 0,
    };
    p.expect(b'{')?;
    let mut entries = Vec::new();
    loop {
        p.skip_ws();
        if p.eat(b'}') {
            return Ok(entries);
        }
        let key = p.string()?;
        p.skip_ws();
        p.expect(b':')?;
        let value = p.value()?;
        entries.push((key, value));
        p.skip_ws();
        if !p.eat(b',') {
            p.skip_ws();
            p.expect(b'}')?;
            return Ok(entries);
        }
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn eat(&mut self, c: u8) -> bool {
        let hit = self.s.get(self.i) == Some(&c);
        if hit {
            self.i += 1;
        }
        hit
    }

    fn expect(&mut self, c: u8) -> std::result::Result<(), String> {
        self.skip_ws();
        if self.eat(c) {
            Ok(())
        } else {
            Err(format!(
                "expected '{}' at character {}",
                char::from(c),
                self.i
            ))
        }
    }

    fn string(&mut self) -> std::result::Result<String, String> {
        self.skip_ws();
        let quote = match self.s.get(self.i) {
            Some(&q @ (b'\'' | b'"')) => q,
            _ => return Err(format!("expected a quoted string at character {}", self.i)),
        };
        let start = self.i + 1;
        let len = self.s[start..]
            .iter()
            .position(|&c| c == quote)
            .ok_or("unterminated string")?;
        self.i = start + len + 1;
        Ok(String::from_utf8_lossy(&self.s[start..start + len]).into_owned())
    }

    fn word(&mut self) -> &[u8] {
        let start = self.i;
        while self.i < self.s.len() && self.s[self.i].is_ascii_alphanumeric() {
            self.i += 1;
        }
        &self.s[start..self.i]
    }

    fn value(&mut self) -> std::result::Result<Value, String> {
        self.skip_ws();
        match self.s.get(self.i) {
            Some(b'\'' | b'"') => self.string().map(Value::Str),
            Some(b'(') => self.tuple().map(Value::Tuple),
            _ => match self.word() {
                b"True" => Ok(Value::Bool(true)),
                b"False" => Ok(Value::Bool(false)),
                other => Err(format!(
                    "unexpected value '{}'",
                    String::from_utf8_lossy(other)
                )),
            },
        }
    }

    fn tuple(&mut self) -> std::result::Result<Vec<usize>, String> {
        self.expect(b'(')?;
        let mut items = Vec::new();
        loop {
            self.skip_ws();
            if self.eat(b')') {
                return Ok(items);
            }
            let word = String::from_utf8_lossy(self.word()).into_owned();
            let n = word
                .trim_end_matches('L')
                .parse()
                .map_err(|_| format!("'{word}' is not a dimension"))?;
            items.push(n);
            self.skip_ws();
            if !self.eat(b',') {
                self.expect(b')')?;
                return Ok(items);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    fn file(bytes: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.npy");
        std::fs::write(&path, bytes).unwrap();
        (dir, path)
    }

    /// An npy file with a given header dict and payload (version 1.0 or 2.0).
    fn npy(dict: &str, payload: &[u8], major: u8) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&[major, 0]);
        if major == 1 {
            out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
        } else {
            out.extend_from_slice(&(dict.len() as u32).to_le_bytes());
        }
        out.extend_from_slice(dict.as_bytes());
        out.extend_from_slice(payload);
        out
    }

    #[test]
    fn parses_header_dicts() {
        let d = parse_dict("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }").unwrap();
        assert_eq!(d[0], ("descr".into(), Value::Str("<f8".into())));
        assert_eq!(d[1].1, Value::Bool(false));
        assert_eq!(d[2].1, Value::Tuple(vec![3, 4]));
        let d = parse_dict("{\"shape\": (5,), \"fortran_order\": True}").unwrap();
        assert_eq!(d[0].1, Value::Tuple(vec![5]));
        assert!(parse_dict("{'descr': <f8}").is_err());
        assert!(parse_dict("{'shape': (3, 4)").is_err());
    }

    #[test]
    fn reads_f4_big_endian_fortran_order_version_2() {
        // 2 rows × 3 columns [[1, 2, 3], [4, 5, 6]] stored column by column.
        let payload: Vec<u8> = [1.0f32, 4.0, 2.0, 5.0, 3.0, 6.0]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        let dict = "{'descr': '>f4', 'fortran_order': True, 'shape': (2, 3), }\n";
        let (_dir, path) = file(&npy(dict, &payload, 2));
        let t = read_npy(&path, Some((1e-9, 2e-9)), Some(1e-9)).unwrap();
        let expected =
            Array2::from_shape_vec((2, 3), vec![1e-9, 2e-9, 3e-9, 4e-9, 5e-9, 6e-9]).unwrap();
        assert!(t
            .heights
            .iter()
            .zip(&expected)
            .all(|(a, b)| (a - b).abs() < 1e-24));
        assert_eq!((t.dx_m, t.dy_m), (1e-9, 2e-9));
    }

    #[test]
    fn round_trips_and_rejects_bad_files() {
        let h = Array2::from_shape_fn((3, 5), |(i, j)| (i * 5 + j) as f64 * 1e-9);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.npy");
        std::fs::write(&path, encode_npy(&h)).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!((bytes.len() - 15 * 8) % 64, 0);
        let back = read_npy(&path, Some((1e-8, 1e-8)), None).unwrap();
        assert_eq!((back.heights, back.dx_m, back.dy_m), (h, 1e-8, 1e-8));
        // No pixel size.
        let err = read_npy(&path, None, None).unwrap_err().to_string();
        assert!(err.contains("pixel size") && err.contains("t.npy"), "{err}");
        // Truncated.
        std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
        let err = read_npy(&path, Some((1e-6, 1e-6)), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("truncated"), "{err}");
        // Wrong magic.
        let mut wrong = bytes.clone();
        wrong[1] = b'X';
        std::fs::write(&path, &wrong).unwrap();
        assert!(read_npy(&path, Some((1e-6, 1e-6)), None)
            .unwrap_err()
            .to_string()
            .contains("magic"));
        // Truncated inside the preamble.
        std::fs::write(&path, &bytes[..7]).unwrap();
        assert!(read_npy(&path, Some((1e-6, 1e-6)), None).is_err());
    }

    #[test]
    fn rejects_unsupported_dtypes_shapes_and_nan() {
        let cases = [
            (
                "{'descr': '<i2', 'fortran_order': False, 'shape': (1, 1), }",
                vec![0u8; 2],
                "dtype",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }",
                vec![0u8; 16],
                "2-D",
            ),
            (
                "{'descr': '<f8', 'shape': (1, 1), }",
                vec![0u8; 8],
                "fortran_order",
            ),
            (
                "{'descr': '<f8', 'fortran_order': False, 'shape': (1, 1), }",
                f64::NAN.to_le_bytes().to_vec(),
                "not finite",
            ),
        ];
        for (dict, payload, needle) in cases {
            let (_dir, path) = file(&npy(dict, &payload, 1));
            let err = read_npy(&path, Some((1e-6, 1e-6)), None)
                .unwrap_err()
                .to_string();
            assert!(err.contains(needle) && err.contains("m.npy"), "{err}");
        }
        // A header that claims far more data than the file holds is an error, not an allocation;
        // a byte count that overflows usize is caught too (it used to wrap around).
        for shape in ["(200000, 200000)", "(4000000000, 4000000000)"] {
            let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': {shape}, }}");
            let (_dir, path) = file(&npy(&dict, &[0u8; 64], 1));
            let err = read_npy(&path, Some((1e-6, 1e-6)), None)
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("m.npy") && (err.contains("truncated") || err.contains("limit")),
                "{err}"
            );
        }
        let (_dir, path) = file(&npy("{}", &[], 9));
        assert!(read_npy(&path, Some((1e-6, 1e-6)), None)
            .unwrap_err()
            .to_string()
            .contains("version"));
    }
}
