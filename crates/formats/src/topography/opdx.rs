//! Bruker/Veeco Vision64 `.opdx` (Dektak stylus and optical profilers): the magic
//! `VCA DATA\x01\x00\x00\x55`, then a tree of items. An item is a name (`u32` length, UTF-8
//! bytes), a type byte and a value whose layout the type fixes:
//!
//! | type | value |
//! |---|---|
//! | `0x01` | boolean, 1 byte |
//! | `0x04`/`0x05`, `0x06`/`0x07`, `0x0A`/`0x0B` | signed/unsigned 16-, 32-, 64-bit integer |
//! | `0x0C`, `0x0D` | float32, float64 |
//! | `0x15` | time stamp, 9 bytes |
//! | `0x12` | string: a variable length, UTF-8 bytes |
//! | `0x13` | quantity: a variable length, then value (f64), unit name and symbol (names) |
//! | `0x18` | unit: a variable length, then name, symbol, factor (f64), 12 bytes |
//! | `0x0E`, `0x40`, `0x42`, `0x7C` | a type name (a name), a variable length and that many bytes: a type id, an array of doubles (a type byte `0x0D` and the `u32` element size 8, then the values), a list of names, positions |
//! | `0x00` | matrix: type name, a `u32`, a name, a variable length (which counts the next two), `u32` rows, `u32` columns, float32 values, x fastest |
//! | `0x45` | matrix without the `u32` and the name |
//! | `0x7D`, `0x46`, `0x47` | container: a variable length, then items and a terminator |
//! | `0x7F` | terminator (followed by a few `0xFF` bytes): closes each container and the file |
//!
//! A variable length is a byte giving its own size (1, 2 or 4), then the little-endian length.
//! Items are named by their path, as `/1D_Data/Raw/Array` or `/2D_Data/Height/Matrix`.
//!
//! A 2-D map is `/2D_Data/<channel>/Matrix`, `rows = Dimension1Points` (y),
//! `columns = Dimension2Points` (x); height = value · `DataScale` (a quantity in a length unit);
//! `Dimension2Extent` and `Dimension1Extent` are the distances from the first to the last point
//! along x and y, so the pixel size is extent / (points − 1); NaN marks an invalid point. The
//! channels are every matrix under `/2D_Data`, `/MetaData/PrimaryData2D` first; those listed in
//! `/MetaData/2D_Channels/Height` are heights. A 1-D profile (`/1D_Data/<channel>/Array`, the
//! channel named by `/MetaData/1D_Channels/Height`, with `NumPoints` and `Extent`) is refused as
//! a line scan, with its point count and spacing.
//!
//! Sources (read, not copied): Gwyddion's `modules/file/dektakvca.c` (David Nečas, GPL-2.0+), the
//! description of the item types; SurfaceTopography's `SurfaceTopography/IO/OPDx.py` (MIT), the
//! pixel size as extent / (points − 1), which the sample profile confirms
//! (`ScanResolution` = `Extent` / 3000 for 3001 points). The 2-D reading follows both but is
//! tested only on synthetic files: no 2-D sample was available.

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_like, height_map, length_scale, line_scan, positive,
    ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

/// First bytes of an OPDx file.
pub const MAGIC: &[u8; 12] = b"VCA DATA\x01\x00\x00\x55";

/// Deepest nesting of containers followed (the sample nests 4 deep).
const MAX_DEPTH: usize = 64;

/// Extra bytes before the values of an array of doubles (type byte and element size).
const ARRAY_EXTRA: usize = 5;

/// The value of an item, as far as the reader needs it.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Number(f64),
    Text(String),
    Quantity {
        value: f64,
        symbol: String,
    },
    Names(Vec<String>),
    /// Bytes of an array of doubles (with its 5-byte prefix) in the file.
    Doubles {
        offset: usize,
        len: usize,
    },
    /// A float32 matrix in the file.
    Matrix {
        rows: usize,
        cols: usize,
        offset: usize,
        len: usize,
    },
    Other,
}

/// One item: its path and value.
#[derive(Debug)]
struct Item {
    path: String,
    value: Value,
}

/// Read an OPDx file: a 2-D height map, or the refusal of a 1-D profile.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let items = parse(path, data)?;
    let get = |p: &str| items.iter().find(|i| i.path == p).map(|i| &i.value);
    let matrices: Vec<&str> = items
        .iter()
        .filter(|i| matches!(i.value, Value::Matrix { .. }))
        .filter_map(|i| {
            let name = i.path.strip_prefix("/2D_Data/")?.strip_suffix("/Matrix")?;
            (!name.contains('/')).then_some(name)
        })
        .collect();
    if !matrices.is_empty() {
        return read_map(path, data, &get, matrices, channel);
    }
    match profile(path, data, &items)? {
        Some(p) => Err(line_scan(path, p.points, p.spacing_m)),
        None => Err(unsupported(
            path,
            "the OPDx file holds neither a 2-D height map (/2D_Data/…/Matrix) nor a profile \
             (/1D_Data/…/Array)",
        )),
    }
}

/// A 1-D profile: its point count and spacing (m).
#[derive(Debug)]
struct Profile {
    points: usize,
    spacing_m: Option<f64>,
}

/// The profile the metadata names (`/MetaData/1D_Channels/Height`), else the first one; `None`
/// when the file holds none.
fn profile(path: &Path, data: &[u8], items: &[Item]) -> Result<Option<Profile>> {
    let get = |p: &str| items.iter().find(|i| i.path == p).map(|i| &i.value);
    let listed = match get("/MetaData/1D_Channels/Height") {
        Some(Value::Names(n)) => n.first().cloned(),
        _ => None,
    };
    let Some(name) = listed.or_else(|| {
        items.iter().find_map(|i| {
            let name = i.path.strip_prefix("/1D_Data/")?.strip_suffix("/Array")?;
            matches!(i.value, Value::Doubles { .. }).then(|| name.to_string())
        })
    }) else {
        return Ok(None);
    };
    let prefix = format!("/1D_Data/{name}");
    let Some(&Value::Doubles { offset, len }) = get(&format!("{prefix}/Array")) else {
        return Err(bad(path, format!("OPDx profile '{name}' has no Array")));
    };
    let points = match get(&format!("{prefix}/NumPoints")) {
        Some(&Value::Number(n)) => count(path, "OPDx NumPoints", n)?,
        _ => count(
            path,
            "OPDx profile length",
            (len.saturating_sub(ARRAY_EXTRA) / 8) as f64,
        )?,
    };
    if len != ARRAY_EXTRA + 8 * points {
        return Err(bad(
            path,
            format!("OPDx profile array of {len} bytes for {points} points"),
        ));
    }
    // The array starts with its element type (0x0D, a double) and size (8).
    let head = slice(path, data, offset, ARRAY_EXTRA, "the OPDx profile")?;
    if head != [0x0D, 8, 0, 0, 0] {
        return Err(unsupported(
            path,
            format!("OPDx profile of elements {head:02x?} (doubles expected)"),
        ));
    }
    let spacing_m = match get(&format!("{prefix}/Extent")) {
        Some(Value::Quantity { value, symbol }) if points > 1 => {
            super::length_factor(symbol).map(|f| value * f / (points - 1) as f64)
        }
        _ => None,
    };
    Ok(Some(Profile { points, spacing_m }))
}

/// Read a 2-D map: `names` are the channels with a matrix, in file order.
fn read_map<'a>(
    path: &Path,
    data: &[u8],
    get: &dyn Fn(&str) -> Option<&'a Value>,
    mut names: Vec<&str>,
    channel: Option<&str>,
) -> Result<HeightMap> {
    if let Some(Value::Text(primary)) = get("/MetaData/PrimaryData2D") {
        if let Some(k) = names.iter().position(|n| n == primary) {
            let p = names.remove(k);
            names.insert(0, p);
        }
    }
    let heights_listed = match get("/MetaData/2D_Channels/Height") {
        Some(Value::Names(n)) => n.clone(),
        _ => Vec::new(),
    };
    let channels: Vec<ChannelEntry> = names
        .iter()
        .map(|&n| {
            let kind = match get(&format!("/2D_Data/{n}/DataKind")) {
                Some(Value::Text(k)) => k.as_str(),
                _ => "",
            };
            ChannelEntry {
                name: n.to_string(),
                height: heights_listed.iter().any(|h| h == n) || height_like(kind),
            }
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let prefix = format!("/2D_Data/{}", names[index]);
    let quantity = |key: &str| match get(&format!("{prefix}/{key}")) {
        Some(Value::Quantity { value, symbol }) => Ok((*value, symbol.as_str())),
        _ => Err(bad(
            path,
            format!("OPDx channel has no quantity {prefix}/{key}"),
        )),
    };
    let Some(&Value::Matrix {
        rows,
        cols,
        offset,
        len,
    }) = get(&format!("{prefix}/Matrix"))
    else {
        return Err(bad(path, format!("OPDx {prefix}/Matrix is missing")));
    };
    let ny = count(path, "OPDx matrix rows", rows as f64)?;
    let nx = count(path, "OPDx matrix columns", cols as f64)?;
    for (key, n) in [("Dimension1Points", ny), ("Dimension2Points", nx)] {
        if let Some(&Value::Number(v)) = get(&format!("{prefix}/{key}")) {
            if v != n as f64 {
                return Err(bad(
                    path,
                    format!("OPDx {prefix}/{key} is {v}, the matrix has {n}"),
                ));
            }
        }
    }
    let bytes = grid_bytes(path, nx, ny, 4)?;
    if len != bytes {
        return Err(unsupported(
            path,
            format!("OPDx matrix of {len} bytes for {nx}×{ny} points (float32 expected)"),
        ));
    }
    let (scale, unit) = quantity("DataScale")?;
    let z = scale * length_scale(path, &channels[index], unit)?;
    let pixel = |key: &str, n: usize| -> Result<f64> {
        let (extent, unit) = quantity(key)?;
        let f = super::length_factor(unit).ok_or_else(|| {
            bad(
                path,
                format!("OPDx {prefix}/{key} is in '{unit}', not a length"),
            )
        })?;
        positive(path, key, extent * f / n.saturating_sub(1).max(1) as f64)
    };
    let (dx, dy) = (
        pixel("Dimension2Extent", nx)?,
        pixel("Dimension1Extent", ny)?,
    );
    let values = decode_values(
        slice(path, data, offset, len, "the OPDx matrix")?,
        4,
        true,
        true,
        false,
    );
    let heights = values.into_iter().map(|v| v * z).collect();
    height_map(
        path,
        TopographyFormat::Opdx,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

/// Every item of the file, depth first.
fn parse(path: &Path, data: &[u8]) -> Result<Vec<Item>> {
    if !data.starts_with(MAGIC) {
        return Err(bad(path, "not an OPDx file (no VCA DATA magic)"));
    }
    let mut items = Vec::new();
    parse_block(path, data, (MAGIC.len(), data.len()), "", 0, &mut items)?;
    Ok(items)
}

/// A name: `u32` length and UTF-8 bytes.
fn name(r: &mut Reader<'_>) -> Result<String> {
    let n = r.usize_u32()?;
    Ok(String::from_utf8_lossy(r.take(n)?).into_owned())
}

/// A variable length: its own size (1, 2 or 4 bytes), then the length.
fn varlen(path: &Path, r: &mut Reader<'_>) -> Result<usize> {
    let at = r.pos;
    match r.u8()? {
        1 => Ok(usize::from(r.u8()?)),
        2 => Ok(usize::from(r.u16()?)),
        4 => r.usize_u32(),
        n => Err(bad(
            path,
            format!("OPDx length of {n} bytes at byte {at} (1, 2 or 4 expected)"),
        )),
    }
}

/// The items of `data[start..end]`, up to the terminator that must close it.
fn parse_block(
    path: &Path,
    data: &[u8],
    (start, end): (usize, usize),
    prefix: &str,
    depth: usize,
    items: &mut Vec<Item>,
) -> Result<()> {
    let block = slice(path, data, 0, end, "an OPDx container")?;
    let mut r = Reader::new(path, block, start);
    while r.pos < end {
        let at = r.pos;
        let item_path = format!("{prefix}/{}", name(&mut r)?);
        let kind = r.u8()?;
        let value = match kind {
            0x7F => return Ok(()),
            0x7D | 0x46 | 0x47 => {
                let len = varlen(path, &mut r)?;
                let inner = r.pos;
                r.take(len)?;
                if depth >= MAX_DEPTH {
                    return Err(bad(
                        path,
                        format!("OPDx containers nested deeper than {MAX_DEPTH} at byte {at}"),
                    ));
                }
                parse_block(
                    path,
                    data,
                    (inner, inner + len),
                    &item_path,
                    depth + 1,
                    items,
                )?;
                continue;
            }
            0x01 => Value::Number(f64::from(r.u8()?)),
            0x04 => Value::Number(f64::from(r.i16()?)),
            0x05 => Value::Number(f64::from(r.u16()?)),
            0x06 => Value::Number(f64::from(r.i32()?)),
            0x07 => Value::Number(f64::from(r.u32()?)),
            0x0A => Value::Number(r.i64()? as f64),
            0x0B => Value::Number(r.u64()? as f64),
            0x0C => Value::Number(f64::from(r.f32()?)),
            0x0D => Value::Number(r.f64()?),
            0x15 => {
                r.take(9)?;
                Value::Other
            }
            0x12 => {
                let len = varlen(path, &mut r)?;
                Value::Text(String::from_utf8_lossy(r.take(len)?).into_owned())
            }
            0x13 => {
                let len = varlen(path, &mut r)?;
                let content = r.take(len)?;
                let mut q = Reader::new(path, content, 0);
                let value = q.f64()?;
                name(&mut q)?;
                Value::Quantity {
                    value,
                    symbol: name(&mut q)?,
                }
            }
            0x18 => {
                let len = varlen(path, &mut r)?;
                r.take(len)?;
                Value::Other
            }
            0x0E | 0x40 | 0x42 | 0x7C => {
                name(&mut r)?;
                let len = varlen(path, &mut r)?;
                let offset = r.pos;
                let content = r.take(len)?;
                match kind {
                    0x40 => Value::Doubles { offset, len },
                    0x42 => {
                        let mut q = Reader::new(path, content, 0);
                        let mut names = Vec::new();
                        while q.remaining() > 0 {
                            names.push(name(&mut q)?);
                        }
                        Value::Names(names)
                    }
                    _ => Value::Other,
                }
            }
            0x00 | 0x45 => {
                name(&mut r)?;
                if kind == 0x00 {
                    r.u32()?;
                    name(&mut r)?;
                }
                let len = varlen(path, &mut r)?;
                let rows = r.usize_u32()?;
                let cols = r.usize_u32()?;
                let len = len.checked_sub(8).ok_or_else(|| {
                    bad(path, format!("OPDx matrix '{item_path}' of {len} bytes"))
                })?;
                let offset = r.pos;
                r.take(len)?;
                Value::Matrix {
                    rows,
                    cols,
                    offset,
                    len,
                }
            }
            other => {
                return Err(unsupported(
                    path,
                    format!(
                        "OPDx item '{item_path}' at byte {at} has the unknown type {other:#04x}"
                    ),
                ))
            }
        };
        items.push(Item {
            path: item_path,
            value,
        });
    }
    let what = if prefix.is_empty() {
        "the file"
    } else {
        prefix
    };
    Err(bad(
        path,
        format!("OPDx: {what} ends without its terminator item (truncated?)"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(s: &str) -> Vec<u8> {
        [
            (s.len() as u32).to_le_bytes().to_vec(),
            s.as_bytes().to_vec(),
        ]
        .concat()
    }

    fn sized(content: &[u8]) -> Vec<u8> {
        let n = content.len();
        let mut v = match n {
            0..=255 => vec![1, n as u8],
            256..=65535 => [vec![2], (n as u16).to_le_bytes().to_vec()].concat(),
            _ => [vec![4], (n as u32).to_le_bytes().to_vec()].concat(),
        };
        v.extend(content);
        v
    }

    fn item(n: &str, kind: u8, value: &[u8]) -> Vec<u8> {
        [name(n), vec![kind], value.to_vec()].concat()
    }

    fn terminator() -> Vec<u8> {
        item("", 0x7F, &[0xFF, 0xFF])
    }

    fn container(n: &str, items: &[Vec<u8>]) -> Vec<u8> {
        item(n, 0x7D, &sized(&[items.concat(), terminator()].concat()))
    }

    fn string(n: &str, s: &str) -> Vec<u8> {
        item(n, 0x12, &sized(s.as_bytes()))
    }

    fn quantity(n: &str, v: f64, symbol: &str) -> Vec<u8> {
        let content = [v.to_le_bytes().to_vec(), name("Unit"), name(symbol)].concat();
        item(n, 0x13, &sized(&content))
    }

    fn names(n: &str, list: &[&str]) -> Vec<u8> {
        let content: Vec<u8> = list.iter().flat_map(|s| name(s)).collect();
        item(n, 0x42, &[name("StringList"), sized(&content)].concat())
    }

    fn matrix(n: &str, rows: u32, cols: u32, values: &[f32]) -> Vec<u8> {
        let mut content = [rows.to_le_bytes(), cols.to_le_bytes()].concat();
        content.extend(values.iter().flat_map(|v| v.to_le_bytes()));
        let head = [name("Matrix<float>"), 0u32.to_le_bytes().to_vec(), name("")].concat();
        item(n, 0x00, &[head, sized(&content)].concat())
    }

    fn file(items: &[Vec<u8>]) -> Vec<u8> {
        [MAGIC.to_vec(), items.concat(), terminator()].concat()
    }

    fn map_file() -> Vec<u8> {
        let nan = f32::NAN;
        file(&[
            container(
                "2D_Data",
                &[
                    container(
                        "Intensity",
                        &[
                            string("DataKind", "Intensity"),
                            quantity("DataScale", 1.0, "V"),
                            quantity("Dimension1Extent", 3.0, "µm"),
                            quantity("Dimension2Extent", 4.0, "µm"),
                            matrix("Matrix", 2, 3, &[1.0; 6]),
                        ],
                    ),
                    container(
                        "Height",
                        &[
                            string("DataKind", "Height"),
                            item("Dimension1Points", 0x0B, &2u64.to_le_bytes()),
                            item("Dimension2Points", 0x0B, &3u64.to_le_bytes()),
                            quantity("DataScale", 2.0, "nm"),
                            quantity("Dimension1Extent", 3.0, "µm"),
                            quantity("Dimension2Extent", 4.0, "µm"),
                            matrix("Matrix", 2, 3, &[0.0, 1.0, 2.0, 3.0, nan, 5.0]),
                        ],
                    ),
                ],
            ),
            container(
                "MetaData",
                &[
                    string("DataKind", "Surface Height"),
                    string("PrimaryData2D", "Height"),
                    container("2D_Channels", &[names("Height", &["Height"])]),
                ],
            ),
        ])
    }

    #[test]
    fn reads_a_synthetic_map() {
        let p = Path::new("s.opdx");
        let data = map_file();
        let m = read(p, &data, None).unwrap();
        assert_eq!(m.channels, ["Height", "Intensity"]);
        assert_eq!((m.nx(), m.ny(), m.invalid_points), (3, 2, 1));
        // Extents are first-to-last distances: 4 µm over 3 columns, 3 µm over 2 rows.
        assert!((m.dx_m - 2e-6).abs() < 1e-20 && (m.dy_m - 3e-6).abs() < 1e-20);
        assert!((m.heights[[1, 0]] - 6e-9).abs() < 1e-22);
        assert!(m.heights[[1, 1]].is_nan());
        let err = read(p, &data, Some("Intensity")).unwrap_err().to_string();
        assert!(err.contains("'V', not a length"), "{err}");
        // Every cut is an error naming the file; so is an unknown item type.
        for cut in 0..data.len() - 3 {
            let err = read(p, &data[..cut], None).unwrap_err().to_string();
            assert!(err.contains("s.opdx"), "{cut}: {err}");
        }
        let odd = file(&[item("Odd", 0x33, &[0; 8])]);
        let err = read(p, &odd, None).unwrap_err().to_string();
        assert!(err.contains("unknown type 0x33"), "{err}");
    }

    #[test]
    fn refuses_a_profile_with_its_length_and_spacing() {
        let values: Vec<u8> = [0.0f64, 1.0, 2.0, 3.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let array = [vec![0x0D, 8, 0, 0, 0], values].concat();
        let data = file(&[
            container(
                "1D_Data",
                &[container(
                    "Raw",
                    &[
                        item("NumPoints", 0x0B, &4u64.to_le_bytes()),
                        quantity("Extent", 3.0, "µm"),
                        item("Array", 0x40, &[name("double"), sized(&array)].concat()),
                    ],
                )],
            ),
            container(
                "MetaData",
                &[container("1D_Channels", &[names("Height", &["Raw"])])],
            ),
        ]);
        let err = read(Path::new("p.opdx"), &data, None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("line scan (one profile of 4 points spaced 1e-6 m)"),
            "{err}"
        );
        let empty = file(&[container("MetaData", &[])]);
        let err = read(Path::new("e.opdx"), &empty, None).unwrap_err();
        assert!(err.to_string().contains("neither"), "{err}");
    }

    #[test]
    fn damaged_files_give_errors_not_panics() {
        let good = map_file();
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        for round in 0..3000 {
            let mut d = good.clone();
            for _ in 0..1 + round % 4 {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                let at = (seed as usize >> 8) % d.len();
                d[at] = (seed >> 40) as u8;
            }
            let _ = read(Path::new("d.opdx"), &d, None);
        }
    }

    fn sample() -> std::path::PathBuf {
        crate::topography::test_support::sample("opdx-3.opdx")
    }

    #[test]
    fn sample_profile_matches_surface_topography() {
        let Ok(data) = std::fs::read(sample()) else {
            return;
        };
        let p = &sample();
        let err = super::super::read(p, None).unwrap_err().to_string();
        assert!(err.contains("one profile of 3001 points spaced"), "{err}");
        let items = parse(p, &data).unwrap();
        let prof = profile(p, &data, &items).unwrap().unwrap();
        assert_eq!(prof.points, 3001);
        let dx = prof.spacing_m.unwrap();
        assert!((dx - 1.6655562954266104e-08).abs() < 1e-9 * dx, "{dx:e}");
        // The heights, as SurfaceTopography reads them: doubles · DataScale (µm).
        let get = |k: &str| items.iter().find(|i| i.path == k).map(|i| &i.value);
        let Some(&Value::Doubles { offset, .. }) = get("/1D_Data/Raw/Array") else {
            panic!("no array");
        };
        let Some(Value::Quantity { value: scale, .. }) = get("/1D_Data/Raw/DataScale") else {
            panic!("no scale");
        };
        let h: Vec<f64> = decode_values(
            &data[offset + 5..offset + 5 + 8 * 3001],
            8,
            true,
            true,
            false,
        )
        .into_iter()
        .map(|v| v * scale * 1e-6)
        .collect();
        let n = h.len() as f64;
        let mean = h.iter().sum::<f64>() / n;
        let rms = (h.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        let min = h.iter().copied().fold(f64::INFINITY, f64::min);
        let max = h.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
        assert!(close(min, -2.1191196462672696e-09) && close(max, 1.5032701602608974e-08));
        assert!(
            (mean - 5.589902230514956e-09).abs() <= 1e-9 * rms,
            "{mean:e}"
        );
        assert!(close(rms, 5.307508577129646e-09), "{rms:e}");
        // Cut at 10 points, or the first 4 KiB scrambled: an error, never a panic.
        for i in 1..=10 {
            assert!(read(p, &data[..data.len() * i / 11], None).is_err());
        }
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        for _ in 0..200 {
            let mut d = data.clone();
            for b in d.iter_mut().take(4096) {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                if seed.is_multiple_of(7) {
                    *b = (seed >> 24) as u8;
                }
            }
            let _ = read(p, &d, None);
        }
    }
}
