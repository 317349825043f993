//! Plain-text matrices: one row of heights per line (row 0 first), values separated by
//! whitespace or commas, `#` starts a comment, blank lines are skipped.

use std::path::Path;

use super::{HeightMap, TopographyFormat};
use crate::error::{Error, Result};

use super::{bad, required_pixel_size, to_metres, topography, unitless_scale};

/// Read a text matrix. The pixel size must be given; heights are multiplied by
/// `height_unit_m` (default 1: metres). Rows of unequal length and unparsable values are errors
/// naming the line.
pub fn read_text(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<HeightMap> {
    let convert = to_metres(unitless_scale(height_unit_m)?);
    crate::inputs::note_input(path);
    let text = std::fs::read_to_string(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::InvalidData => bad(path, "not a text file (invalid UTF-8)"),
        _ => Error::io(path, e),
    })?;
    let pixel = required_pixel_size(path, pixel_size_m, "text")?;
    let mut heights = Vec::new();
    let (mut rows, mut nx) = (0, 0);
    for (number, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let before = heights.len();
        parse_row(content, &convert, &mut heights)
            .map_err(|reason| bad(path, format!("line {}: {reason}", number + 1)))?;
        let width = heights.len() - before;
        if rows == 0 {
            nx = width;
        } else if width != nx {
            return Err(bad(
                path,
                format!(
                    "line {} has {width} values, the first row has {nx}",
                    number + 1
                ),
            ));
        }
        rows += 1;
    }
    if rows == 0 {
        return Err(bad(path, "no numbers found"));
    }
    topography(path, TopographyFormat::Text, (rows, nx), heights, pixel)
}

fn parse_row(
    content: &str,
    convert: &impl Fn(f64) -> f64,
    out: &mut Vec<f64>,
) -> std::result::Result<(), String> {
    let tokens: Vec<&str> = if content.contains(',') {
        content.split(',').map(str::trim).collect()
    } else {
        content.split_whitespace().collect()
    };
    for token in tokens {
        let value: f64 = token
            .parse()
            .map_err(|_| format!("'{token}' is not a number"))?;
        out.push(convert(value));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(text: &str) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.txt");
        std::fs::write(&path, text).unwrap();
        (dir, path)
    }

    #[test]
    fn reads_whitespace_and_comma_rows_with_comments() {
        let (_dir, path) = file("# AFM export\n1 2 3\n\n4,5, 6  # last row\n");
        let t = read_text(&path, Some((1e-8, 1e-8)), Some(1e-9)).unwrap();
        assert_eq!((t.ny(), t.nx()), (2, 3));
        assert_eq!(t.heights[[1, 2]], 6e-9);
    }

    #[test]
    fn rejects_ragged_rows_bad_numbers_nan_and_missing_pixel_size() {
        for (text, needle) in [
            ("1 2\n3\n", "line 2 has 1 values"),
            ("1 x\n", "line 1: 'x' is not a number"),
            ("1,,2\n", "'' is not a number"),
            ("1 nan\n", "not finite"),
            ("# nothing\n", "no numbers"),
        ] {
            let (_dir, path) = file(text);
            let err = read_text(&path, Some((1e-6, 1e-6)), None)
                .unwrap_err()
                .to_string();
            assert!(err.contains(needle) && err.contains("m.txt"), "{err}");
        }
        let (_dir, path) = file("1 2\n");
        assert!(read_text(&path, None, None)
            .unwrap_err()
            .to_string()
            .contains("pixel size"));
    }
}
