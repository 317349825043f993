//! Height maps as text: a matrix of heights (one row per line, row 0 first; values separated by
//! whitespace, commas, semicolons or tabs; `#` starts a comment; blank lines skipped), with or
//! without a header that states the calibration ([`header`]: Gwyddion's ASCII export in any
//! language, `h=`/`w=`/`pixel size=` headers), and `x y z` points on a regular grid
//! ([`columns`]). UTF-8, UTF-16 (with its byte-order mark) and Latin-1 text are read; a gzip
//! file is decompressed first (by the caller, [`super::read_height_map`]).
//!
//! What the numbers are is decided from the file, never silently:
//! * a header → a matrix of the stated size and units;
//! * three columns without a header → `x y z` points (a map when on a regular grid, else
//!   refused);
//! * one or two columns, or a single row → a profile, refused as a line scan;
//! * otherwise a matrix; its pixel size must then be given (`--pixel-size`), its heights are in
//!   metres unless `--height-unit` says otherwise.
//!
//! Leading lines that are not numbers (column titles, units) are skipped, at most
//! [`MAX_TITLE_LINES`]; after the first row of numbers every line must be numbers. `NaN` marks
//! an invalid point.

mod columns;
mod header;

use std::path::Path;

use super::vendor::{choose, height_map, ChannelEntry};
use super::{bad, line_scan, HeightMap, ReadOptions, TopographyFormat};
use crate::error::Result;
use crate::param::Param;

use header::Stated;

/// Most lines of titles or units before the numbers.
pub const MAX_TITLE_LINES: usize = 20;

/// Decode a text file: UTF-8, UTF-16 with a byte-order mark, else Latin-1 (every byte a
/// character). `None` when the bytes look binary (a NUL byte outside UTF-16).
pub(crate) fn decode(bytes: &[u8]) -> Option<String> {
    let utf16 = |le: bool| {
        let units: Vec<u16> = bytes[2..]
            .chunks_exact(2)
            .map(|c| {
                if le {
                    u16::from_le_bytes([c[0], c[1]])
                } else {
                    u16::from_be_bytes([c[0], c[1]])
                }
            })
            .collect();
        Some(String::from_utf16_lossy(&units))
    };
    if bytes.starts_with(&[0xFF, 0xFE]) {
        return utf16(true);
    }
    if bytes.starts_with(&[0xFE, 0xFF]) {
        return utf16(false);
    }
    if bytes.contains(&0) {
        return None;
    }
    match std::str::from_utf8(bytes) {
        Ok(s) => Some(s.trim_start_matches('\u{feff}').to_string()),
        Err(_) => Some(super::latin1(bytes)),
    }
}

/// Whether the first bytes of a file look like text (no NUL byte, or a UTF-16 byte-order mark).
pub(crate) fn looks_like_text(head: &[u8]) -> bool {
    head.starts_with(&[0xFF, 0xFE]) || head.starts_with(&[0xFE, 0xFF]) || !head.contains(&0)
}

/// The numbers of one line, or `None` when a token is not a number.
fn numbers(line: &str) -> Option<Vec<f64>> {
    let tokens: Vec<&str> = if line.contains(';') {
        line.split(';').map(str::trim).collect()
    } else if line.contains(',') {
        line.split(',').map(str::trim).collect()
    } else {
        line.split_whitespace().collect()
    };
    tokens.iter().map(|t| t.parse::<f64>().ok()).collect()
}

/// The parsed file: what its header states, its numbers row by row, the row length, and the
/// columns' units where a title line gives them ([`column_units`]).
struct Parsed {
    stated: Stated,
    rows: Vec<Vec<f64>>,
    columns: usize,
    units: Option<Vec<Option<f64>>>,
}

/// A title line of bracketed units, one per column (`[mm];[mm];[µm]`, as profilometer exports
/// write under the column names): metres per unit of each column, `None` for a column that is
/// not a length (`[1/0]`); `None` for any other line.
fn column_units(line: &str) -> Option<Vec<Option<f64>>> {
    let tokens: Vec<&str> = line
        .split([';', ',', '\t', ' '])
        .map(str::trim)
        .filter(|t| !t.is_empty())
        .collect();
    if tokens.is_empty() {
        return None;
    }
    tokens
        .iter()
        .map(|t| {
            let unit = t.strip_prefix('[')?.strip_suffix(']')?;
            Some(super::length_factor(unit))
        })
        .collect()
}

fn parse(path: &Path, text: &str) -> Result<Parsed> {
    let mut stated = Stated::default();
    let mut comments = Vec::new();
    let mut rows: Vec<Vec<f64>> = Vec::new();
    let mut titles = 0;
    let mut columns = 0;
    let mut units = None;
    for (index, line) in text.lines().enumerate() {
        let number = index + 1;
        let trimmed = line.trim();
        if trimmed.starts_with('#') {
            if rows.is_empty() {
                comments.push(trimmed);
            }
            continue;
        }
        let content = trimmed.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        if rows.is_empty() && header::is_key_value(content) {
            header::key_value(content, &mut stated)
                .map_err(|reason| bad(path, format!("line {number}: {reason}")))?;
            continue;
        }
        match numbers(content) {
            Some(values) if !values.is_empty() => {
                if rows.is_empty() {
                    columns = values.len();
                } else if values.len() != columns {
                    return Err(bad(
                        path,
                        format!(
                            "line {number} has {} values, the first row has {columns}",
                            values.len()
                        ),
                    ));
                }
                rows.push(values);
            }
            _ if rows.is_empty() && titles < MAX_TITLE_LINES => {
                titles += 1;
                if let Some(found) = column_units(content) {
                    units = Some(found);
                }
            }
            _ => {
                let token = content
                    .split([';', ',', ' ', '\t'])
                    .map(str::trim)
                    .find(|t| !t.is_empty() && t.parse::<f64>().is_err())
                    .unwrap_or(content);
                return Err(bad(
                    path,
                    format!("line {number}: '{token}' is not a number"),
                ));
            }
        }
    }
    header::gwyddion(&comments, &mut stated).map_err(|reason| bad(path, reason))?;
    if rows.is_empty() {
        return Err(bad(path, "no numbers found"));
    }
    Ok(Parsed {
        stated,
        rows,
        columns,
        units,
    })
}

/// Read a text height map from its decoded content (module docs); `format` is what to call it
/// ([`TopographyFormat::Text`], or gzip-compressed text).
pub(crate) fn read_str(
    path: &Path,
    text: &str,
    options: &ReadOptions,
    format: TopographyFormat,
) -> Result<HeightMap> {
    let Parsed {
        stated,
        rows,
        columns,
        units,
    } = parse(path, text)?;
    let unit = match (stated.unit_m, options.height_unit_m) {
        (Some(_), Some(_)) => {
            return Err(bad(
                path,
                format!(
                    "the file states its height unit ({}); do not give another one",
                    stated.unit_text.as_deref().unwrap_or("in its header")
                ),
            ))
        }
        (Some(u), None) => u,
        (None, given) => super::unitless_scale(given)?,
    };
    let name = stated.channel.clone().unwrap_or_else(|| "Default".into());
    let channels = [ChannelEntry { name, height: true }];
    let index = choose(path, &channels, options.channel.as_deref())?;
    let convert = super::to_metres(unit);
    if !stated.any() && columns == 3 && rows.len() > 3 {
        // Units under the column titles: each column in its own where it is a length (a
        // height unit may then not be given for z), else as the unit above says.
        let (ux, uy, uz) = match units.as_deref() {
            Some(&[ux, uy, uz]) => {
                if uz.is_some() && options.height_unit_m.is_some() {
                    return Err(bad(
                        path,
                        "the file states its columns' units ([…] under the titles); do not \
                         give a height unit",
                    ));
                }
                // x and y stated in something other than a length (`[px]`): their spacing
                // says nothing in metres, so the pixel size must be given.
                if (ux.is_none() || uy.is_none()) && options.pixel_size_m.is_none() {
                    return Err(bad(
                        path,
                        format!(
                            "the x and y columns are not in a length unit ([…] under the \
                             titles); give the pixel size with {}",
                            Param::PixelSize
                        ),
                    ));
                }
                (ux.unwrap_or(unit), uy.unwrap_or(unit), uz.unwrap_or(unit))
            }
            _ => (unit, unit, unit),
        };
        let (to_x, to_y, to_z) = (
            super::to_metres(ux),
            super::to_metres(uy),
            super::to_metres(uz),
        );
        let points: Vec<[f64; 3]> = rows
            .iter()
            .map(|r| [to_x(r[0]), to_y(r[1]), to_z(r[2])])
            .collect();
        let (heights, shape, spacing) = columns::xyz_grid(path, &points)?;
        let mut map = height_map(
            path,
            TopographyFormat::Xyz,
            (&channels, index),
            shape,
            heights,
            spacing,
        )?;
        if let Some(pixel) = options.pixel_size_m {
            map.replace_pixel_size(pixel);
        }
        return Ok(map);
    }
    if columns <= 2 || rows.len() == 1 {
        return Err(line_scan(path, rows.len().max(columns), None));
    }
    let (ny, nx) = (rows.len(), columns);
    for (what, promised, found) in [("h", stated.shape.0, ny), ("w", stated.shape.1, nx)] {
        if let Some(p) = promised.filter(|&p| p != found) {
            return Err(bad(
                path,
                format!("the header says {what}={p}, the file has {found}"),
            ));
        }
    }
    let stated_pixel = match (stated.size_m, stated.pixel_m) {
        (Some((w, h)), _) => Some((w / nx as f64, h / ny as f64)),
        (None, Some(p)) => Some((p, p)),
        (None, None) => None,
    };
    let pixel = match (stated_pixel, options.pixel_size_m) {
        (Some(p), _) | (None, Some(p)) => p,
        (None, None) => {
            return Err(bad(
                path,
                format!(
                    "the text file states no pixel size; give it with {}",
                    Param::PixelSize
                ),
            ))
        }
    };
    let heights = rows.into_iter().flatten().map(&convert).collect();
    let mut map = height_map(path, format, (&channels, index), (ny, nx), heights, pixel)?;
    if let Some(given) = options.pixel_size_m {
        map.replace_pixel_size(given);
    }
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str, options: &ReadOptions) -> Result<HeightMap> {
        read_str(Path::new("m.txt"), text, options, TopographyFormat::Text)
    }

    #[test]
    fn units_under_the_column_titles_scale_x_y_and_z() {
        assert_eq!(
            column_units("[mm];[mm];[1/0]"),
            Some(vec![Some(1e-3), Some(1e-3), None])
        );
        assert_eq!(column_units("X;Y;Z"), None);
        assert_eq!(column_units("[um] height"), None);
        let mut text = String::from("X;Y;Z\n[mm];[mm];[um]\n");
        for y in 0..3 {
            for x in 0..4 {
                text.push_str(&format!(
                    "{};{};{}\n",
                    0.01 * f64::from(x),
                    0.02 * f64::from(y),
                    x + y
                ));
            }
        }
        let m = read(&text, &ReadOptions::default()).unwrap();
        assert_eq!((m.nx(), m.ny()), (4, 3));
        assert!((m.dx_m - 1e-5).abs() < 1e-15 && (m.dy_m - 2e-5).abs() < 1e-15);
        assert!((m.heights[(2, 3)] - 5e-6).abs() < 1e-18);
        let given = ReadOptions {
            height_unit_m: Some(1e-9),
            ..ReadOptions::default()
        };
        let err = read(&text, &given).unwrap_err().to_string();
        assert!(err.contains("states its columns' units"), "{err}");
        // A z column that is not a length takes the height unit given.
        let flagless = text.replace("[um]", "[a.u.]");
        let m = read(&flagless, &given).unwrap();
        assert!((m.dx_m - 1e-5).abs() < 1e-15);
        assert!((m.heights[(2, 3)] - 5e-9).abs() < 1e-21);
        // x and y in pixels: refused without a pixel size (they were read as metres); with
        // one, z keeps its stated unit.
        let pixels = text.replace("[mm];[mm]", "[px];[px]");
        let err = read(&pixels, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("not in a length unit"), "{err}");
        let m = read(&pixels, &sized()).unwrap();
        assert!((m.heights[(2, 3)] - 5e-6).abs() < 1e-18);
        assert!((m.dx_m - 1e-8).abs() < 1e-20);
    }

    fn sized() -> ReadOptions {
        ReadOptions {
            pixel_size_m: Some((1e-8, 1e-8)),
            ..ReadOptions::default()
        }
    }

    #[test]
    fn reads_whitespace_and_comma_rows_with_comments() {
        let options = ReadOptions {
            height_unit_m: Some(1e-9),
            ..sized()
        };
        let t = read("# AFM export\n1 2 3\n\n4,5, 6  # last row\n", &options).unwrap();
        assert_eq!((t.ny(), t.nx()), (2, 3));
        assert_eq!(t.heights[[1, 2]], 6e-9);
        assert_eq!(t.channel, "Default");
    }

    #[test]
    fn rejects_ragged_rows_bad_numbers_and_missing_pixel_size() {
        for (text, needle) in [
            ("1 2 3\n3 4\n", "line 2 has 2 values"),
            ("1 2 3\n1 x 3\n", "line 2: 'x' is not a number"),
            ("1 2 3\n4 5 6\n", "states no pixel size"),
            ("# nothing\n", "no numbers"),
        ] {
            let options = if needle.contains("pixel") {
                ReadOptions::default()
            } else {
                sized()
            };
            let err = read(text, &options).unwrap_err().to_string();
            assert!(err.contains(needle) && err.contains("m.txt"), "{err}");
        }
        // NaN is an invalid point, counted.
        let t = read("1 nan 3\n4 5 6\n", &sized()).unwrap();
        assert_eq!(t.invalid_points, 1);
    }

    #[test]
    fn a_header_gives_the_calibration_and_refuses_a_second_unit() {
        let text = "# Channel: Main\n# Width: 10 µm\n# Height: 10 µm\n# Value units: nm\n\
                    1 2 3 4\n5 6 7 8\n9 10 11 12\n";
        let t = read(text, &ReadOptions::default()).unwrap();
        assert_eq!((t.ny(), t.nx(), t.channel.as_str()), (3, 4, "Main"));
        assert!((t.dx_m - 2.5e-6).abs() < 1e-18 && (t.dy_m - 10e-6 / 3.0).abs() < 1e-18);
        assert_eq!(t.heights[[2, 3]], 12e-9);
        let options = ReadOptions {
            height_unit_m: Some(1e-9),
            ..ReadOptions::default()
        };
        assert!(read(text, &options)
            .unwrap_err()
            .to_string()
            .contains("states its height unit"));
        let options = ReadOptions {
            channel: Some("Phase".into()),
            ..ReadOptions::default()
        };
        assert!(read(text, &options)
            .unwrap_err()
            .to_string()
            .contains("no channel 'Phase'"));
        let kv = "h=2 w=3\npixel size=2 nm\ndata unit=rad\nheight conversion factor (-> nm)=0.5\n\
                  1 2 3\n4 5 6\n";
        let t = read(kv, &ReadOptions::default()).unwrap();
        assert_eq!(t.heights[[1, 2]], 3e-9);
        assert_eq!((t.dx_m, t.dy_m), (2e-9, 2e-9));
        let err = read(&kv.replace("h=2", "h=3"), &ReadOptions::default()).unwrap_err();
        assert!(err.to_string().contains("h=3, the file has 2"), "{err}");
    }

    #[test]
    fn columns_are_points_or_profiles_never_a_matrix() {
        let xyz = "0 0 1\n1 0 2\n0 1 3\n1 1 4\n";
        let t = read(xyz, &ReadOptions::default()).unwrap();
        assert_eq!(
            (t.format, t.ny(), t.nx(), t.dx_m),
            (TopographyFormat::Xyz, 2, 2, 1.0)
        );
        assert_eq!(t.heights[[1, 0]], 3.0);
        for text in [
            "1\n2\n3\n4\n",
            "0 1\n1 2\n2 3\n",
            "x,z\n0,1\n1,2\n",
            "1 2 3 4 5\n",
        ] {
            let err = read(text, &sized()).unwrap_err().to_string();
            assert!(err.contains("line scan"), "{text}: {err}");
        }
    }

    #[test]
    fn decodes_utf16_and_latin1() {
        let mut utf16 = vec![0xFF, 0xFE];
        utf16.extend("1 2\n".encode_utf16().flat_map(u16::to_le_bytes));
        assert_eq!(decode(&utf16).unwrap(), "1 2\n");
        assert_eq!(decode(b"\xb5m 1\n").unwrap(), "µm 1\n");
        assert!(decode(b"\x00\x01").is_none());
        assert!(looks_like_text(b"# Channel") && !looks_like_text(b"MM\x00*"));
    }
}
