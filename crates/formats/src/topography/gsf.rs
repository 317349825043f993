//! Gwyddion Simple Field (`.gsf`, Gwyddion user guide, "Simple Field Files"): the magic line
//! `Gwyddion Simple Field 1.0`, `name = value` header lines, one to four NUL bytes aligning the
//! data to a multiple of 4, then `XRes·YRes` little-endian float32 values, row by row from the
//! top. Units are base SI units (`XYUnits = m`, `ZUnits = m`).

use std::path::Path;

use super::{HeightMap, TopographyFormat};
use crate::error::Result;

use super::vendor::grid_bytes;
use super::{
    bad, length_unit, read_bytes, refuse_height_unit, slice, to_metres, topography, unitless_scale,
};

const MAGIC: &str = "Gwyddion Simple Field 1.0\n";

/// Read a `.gsf` height map. Pixel size: `pixel_size_m`, else `XReal/XRes` and `YReal/YRes` in
/// `XYUnits` (metres when absent). Heights in `ZUnits`; when the file has no `ZUnits`, in
/// `height_unit_m` (default metres). A `ZUnits` that is not a length is an error.
pub fn read_gsf(
    path: &Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<HeightMap> {
    let bytes = read_bytes(path)?;
    if !bytes.starts_with(MAGIC.as_bytes()) {
        return Err(bad(
            path,
            "not a Gwyddion Simple Field file (first line is not 'Gwyddion Simple Field 1.0')",
        ));
    }
    let end = bytes
        .iter()
        .position(|&b| b == 0)
        .ok_or_else(|| bad(path, "GSF header has no NUL terminator (file truncated?)"))?;
    let header = std::str::from_utf8(&bytes[MAGIC.len()..end])
        .map_err(|_| bad(path, "GSF header is not UTF-8 text"))?;
    let fields = parse_fields(header);
    let get = |key: &str| {
        fields
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    };
    let res = |key: &str| -> Result<usize> {
        let text = get(key).ok_or_else(|| bad(path, format!("GSF header has no {key}")))?;
        match text.parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(bad(
                path,
                format!("GSF {key} = '{text}' is not a positive integer"),
            )),
        }
    };
    let (nx, ny) = (res("XRes")?, res("YRes")?);
    let pixel = match pixel_size_m {
        Some(p) => p,
        None => file_pixel_size(path, &get, nx, ny)?,
    };
    let z = to_metres(match get("ZUnits") {
        Some(unit) => {
            refuse_height_unit(path, height_unit_m, unit)?;
            length_unit(path, unit, "GSF ZUnits")?
        }
        None => unitless_scale(height_unit_m)?,
    });
    let data_start = (end / 4 + 1) * 4;
    if slice(path, &bytes, end, data_start - end)?
        .iter()
        .any(|&b| b != 0)
    {
        return Err(bad(path, "GSF header padding is not NUL bytes"));
    }
    let data = slice(path, &bytes, data_start, grid_bytes(path, nx, ny, 4)?)?;
    let heights = data
        .chunks_exact(4)
        .map(|c| z(f64::from(f32::from_le_bytes(c.try_into().unwrap()))))
        .collect();
    let mut map = topography(path, TopographyFormat::Gsf, (ny, nx), heights, pixel)?;
    // The file's own size, when it states one, is recorded as replaced.
    if let (Some(_), Ok(stated)) = (pixel_size_m, file_pixel_size(path, &get, nx, ny)) {
        map.dx_m = stated.0;
        map.dy_m = stated.1;
        map.replace_pixel_size(pixel);
    }
    Ok(map)
}

fn file_pixel_size<'a>(
    path: &Path,
    get: &impl Fn(&str) -> Option<&'a str>,
    nx: usize,
    ny: usize,
) -> Result<(f64, f64)> {
    let unit = match get("XYUnits") {
        Some(u) => length_unit(path, u, "GSF XYUnits")?,
        None => 1.0,
    };
    let real = |key: &str| -> Result<f64> {
        let text = get(key).ok_or_else(|| {
            bad(
                path,
                format!("GSF header has no {key}; give the pixel size"),
            )
        })?;
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                bad(
                    path,
                    format!("GSF {key} = '{text}' is not a positive number"),
                )
            })
    };
    Ok((
        real("XReal")? * unit / nx as f64,
        real("YReal")? * unit / ny as f64,
    ))
}

fn parse_fields(header: &str) -> Vec<(String, String)> {
    header
        .lines()
        .filter_map(|line| line.split_once('='))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect()
}

/// The bytes of a `.gsf` file of heights (m, rows = y) on pixels of `(dx, dy)` m, stored as
/// float32: heights keep about 7 significant digits.
pub fn encode_gsf(heights: &ndarray::Array2<f64>, (dx_m, dy_m): (f64, f64)) -> Vec<u8> {
    let (ny, nx) = heights.dim();
    let (lx, ly) = (nx as f64 * dx_m, ny as f64 * dy_m);
    let mut out = format!(
        "{MAGIC}XRes = {}\nYRes = {}\nXReal = {lx:e}\nYReal = {ly:e}\nXYUnits = m\nZUnits = m\n\
         Title = contactscope height map\n",
        nx, ny
    )
    .into_bytes();
    let padding = 4 - out.len() % 4;
    out.extend(std::iter::repeat_n(0u8, padding));
    for h in heights.iter() {
        out.extend_from_slice(&(*h as f32).to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    fn write(dir: &Path, header: &str, values: &[f32]) -> std::path::PathBuf {
        let path = dir.join("m.gsf");
        let mut out = format!("{MAGIC}{header}").into_bytes();
        let padding = 4 - out.len() % 4;
        out.extend(std::iter::repeat_n(0u8, padding));
        for v in values {
            out.extend_from_slice(&v.to_le_bytes());
        }
        std::fs::write(&path, out).unwrap();
        path
    }

    #[test]
    fn round_trip_in_f32_precision() {
        let h = Array2::from_shape_fn((4, 6), |(i, j)| (i as f64 - j as f64 * 0.3) * 1e-8);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.gsf");
        std::fs::write(&path, encode_gsf(&h, (2e-8, 3e-8))).unwrap();
        let back = read_gsf(&path, None, None).unwrap();
        assert_eq!((back.nx(), back.ny()), (6, 4));
        assert!((back.dx_m / 2e-8 - 1.0).abs() < 1e-12 && (back.dy_m / 3e-8 - 1.0).abs() < 1e-12);
        for (a, b) in back.heights.iter().zip(&h) {
            assert!((a - b).abs() <= 1e-7 * b.abs());
        }
    }

    #[test]
    fn units_from_the_header_and_the_override() {
        let dir = tempfile::tempdir().unwrap();
        let header = "XRes = 2\nYRes = 1\nXReal = 4\nYReal = 2\nXYUnits = um\nZUnits = nm\n";
        let path = write(dir.path(), header, &[1.0, 2.0]);
        let t = read_gsf(&path, None, None).unwrap();
        assert_eq!(t.heights.as_slice().unwrap(), &[1e-9, 2e-9]);
        assert_eq!((t.dx_m, t.dy_m), (2e-6, 2e-6));
        let t = read_gsf(&path, Some((1e-9, 1e-9)), None).unwrap();
        assert_eq!(t.dx_m, 1e-9);
        let err = read_gsf(&path, None, Some(1e-6)).unwrap_err().to_string();
        assert!(err.contains("height unit (nm)"), "{err}");
        // No XReal: the pixel size must be given.
        let path = write(dir.path(), "XRes = 2\nYRes = 1\n", &[1.0, 2.0]);
        assert!(read_gsf(&path, None, None)
            .unwrap_err()
            .to_string()
            .contains("XReal"));
        let t = read_gsf(&path, Some((1e-6, 1e-6)), Some(1e-6)).unwrap();
        assert_eq!(t.heights[[0, 1]], 2e-6);
    }

    #[test]
    fn rejects_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let cases = [
            (
                "XRes = 2\nYRes = 2\nXReal = 1e-6\nYReal = 1e-6\n",
                vec![1.0f32; 3],
                "truncated",
            ),
            ("XRes = 0\nYRes = 2\n", vec![], "XRes"),
            (
                "XRes = 1\nYRes = 1\nXReal = 1e-6\nYReal = 1e-6\nZUnits = V\n",
                vec![1.0],
                "not a length",
            ),
            (
                "XRes = 1\nYRes = 1\nXReal = 1e-6\nYReal = 1e-6\n",
                vec![f32::NAN],
                "not finite",
            ),
        ];
        for (header, values, needle) in cases {
            let path = write(dir.path(), header, &values);
            let err = read_gsf(&path, None, None).unwrap_err().to_string();
            assert!(err.contains(needle) && err.contains("m.gsf"), "{err}");
        }
        let path = dir.path().join("x.gsf");
        std::fs::write(&path, b"Gwyddion Simple Field 2.0\nXRes = 1\n\0\0").unwrap();
        assert!(read_gsf(&path, None, None)
            .unwrap_err()
            .to_string()
            .contains("not a Gwyddion"));
        std::fs::write(&path, b"Gwyddion Simple Field 1.0\nXRes = 1\n").unwrap();
        assert!(read_gsf(&path, None, None)
            .unwrap_err()
            .to_string()
            .contains("NUL"));
    }
}
