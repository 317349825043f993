//! Image Metrology BCR-STM `.bcr` / BCRF `.bcrf` (SPIP's interchange format), layout as
//! documented by Image Metrology and read by Gwyddion's `bcrfile` module: a text header of
//! `key = value` lines (`%` or `#` starts a comment line), beginning `fileformat = bcrstm`
//! (16-bit integers), `bcrf` (float32), or `bcrstm_unicode` / `bcrf_unicode` (the same with the
//! header in UTF-16LE, two bytes a character). The header is `headersize` characters long
//! (2048 when the key is absent); the data follow it: `ypixels` lines of `xpixels` values,
//! little-endian unless `intelmode = 0`. Integers are scaled by `bit2nm` (default 1) into
//! `zunit`; floats are in `zunit` (default nm). The image is `xlength` × `ylength` in `xunit`
//! and `yunit` (default nm). The integer 32767 and floats above 1.7e38 (or NaN) are void
//! (invalid) points. Rows are the stored lines, row 0 the first. `zmin`, the offsets and
//! `voidpixels` (a count in some files, the marker in others) are not used.

use std::collections::HashMap;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_factor, length_scale, line_scan, positive,
    ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, utf16le};
use crate::error::Result;

/// The start of the 8-bit header.
pub(crate) const MAGIC: &[u8] = b"fileformat = bcr";

/// Characters of a header without `headersize`.
const DEFAULT_HEADER: usize = 2048;

/// Whether `head` starts a BCR header, 8-bit or UTF-16LE (with or without a byte-order mark).
pub(crate) fn is_bcr(head: &[u8]) -> bool {
    let head = head.strip_prefix(b"\xff\xfe").unwrap_or(head);
    head.starts_with(MAGIC)
        || (head.len() >= 2 * MAGIC.len()
            && MAGIC
                .iter()
                .zip(head.chunks_exact(2))
                .all(|(&m, c)| c == [m, 0]))
}

/// The header's `key = value` lines, keys lower-cased; the first of a repeated key wins.
fn parse(text: &str) -> HashMap<String, String> {
    let mut keys = HashMap::new();
    for line in text.split(['\n', '\r']) {
        let line = line.trim_matches(|c: char| c.is_whitespace() || c == '\0' || c == '\u{feff}');
        if line.starts_with('%') || line.starts_with('#') {
            continue;
        }
        if let Some((k, v)) = line.split_once('=') {
            let (k, v) = (k.trim().to_ascii_lowercase(), v.trim());
            if !k.is_empty() && !v.is_empty() {
                keys.entry(k).or_insert_with(|| v.to_string());
            }
        }
    }
    keys
}

/// Read the height map of a BCR-STM or BCRF file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let body = data.strip_prefix(b"\xff\xfe").unwrap_or(data);
    let wide = body.get(1) == Some(&0);
    let width = if wide { 2 } else { 1 };
    let decode = |b: &[u8]| -> String {
        if wide {
            utf16le(b)
        } else {
            b.iter().map(|&c| char::from(c)).collect()
        }
    };
    let probe = &data[..data.len().min(DEFAULT_HEADER * width)];
    let first = parse(&decode(probe));
    let chars = match first.get("headersize") {
        Some(v) => v
            .parse::<usize>()
            .map_err(|_| bad(path, format!("BCR headersize is '{v}'")))?,
        None => DEFAULT_HEADER,
    };
    let header_bytes = chars
        .checked_mul(width)
        .filter(|&b| b >= MAGIC.len() * width)
        .ok_or_else(|| bad(path, format!("BCR headersize {chars} is not a header")))?;
    let keys = parse(&decode(slice(
        path,
        data,
        0,
        header_bytes,
        "the BCR header",
    )?));
    let get = |k: &str| keys.get(k).map(String::as_str);
    let number = |k: &str| -> Result<f64> {
        let v = get(k).ok_or_else(|| bad(path, format!("BCR header without '{k}'")))?;
        v.parse::<f64>()
            .map_err(|_| bad(path, format!("BCR '{k}' is '{v}', not a number")))
    };
    let format = get("fileformat").unwrap_or("");
    let integer = match format {
        "bcrstm" | "bcrstm_unicode" => true,
        "bcrf" | "bcrf_unicode" => false,
        other => return Err(unsupported(path, format!("BCR file format '{other}'"))),
    };
    let nx = count(path, "BCR xpixels", number("xpixels")?)?;
    let ny = count(path, "BCR ypixels", number("ypixels")?)?;
    let unit = |k: &str| -> Result<f64> {
        let u = get(k).unwrap_or("nm");
        length_factor(u).ok_or_else(|| bad(path, format!("BCR {k} '{u}' is not a length")))
    };
    let dx = positive(path, "BCR xlength", number("xlength")?)? * unit("xunit")? / nx as f64;
    let dy = positive(path, "BCR ylength", number("ylength")?)? * unit("yunit")? / ny as f64;
    let little = match get("intelmode") {
        Some(v) => {
            v.parse::<i64>()
                .map_err(|_| bad(path, format!("BCR intelmode is '{v}'")))?
                != 0
        }
        None => true,
    };
    let channels = [ChannelEntry {
        name: "Default".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let mut scale = length_scale(path, &channels[index], get("zunit").unwrap_or("nm"))?;
    if integer {
        let bit2nm = match get("bit2nm") {
            Some(_) => number("bit2nm")?,
            None => 1.0,
        };
        if !(bit2nm.is_finite() && bit2nm != 0.0) {
            return Err(bad(path, format!("BCR bit2nm is {bit2nm}")));
        }
        scale *= bit2nm;
    }
    let size = if integer { 2 } else { 4 };
    let bytes = grid_bytes(path, nx, ny, size)?;
    let raw = slice(path, data, header_bytes, bytes, "the BCR data")?;
    if ny == 1 {
        return Err(line_scan(path, nx, Some(dx)));
    }
    let heights = decode_values(raw, size, !integer, true, !little)
        .into_iter()
        .map(|v| {
            let void = if integer {
                v == 32767.0
            } else {
                v.is_nan() || v > 1.7e38
            };
            if void {
                f64::NAN
            } else {
                v * scale
            }
        })
        .collect();
    height_map(
        path,
        TopographyFormat::Bcr,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A header padded to `chars` characters, in 8 bits or UTF-16LE.
    fn header(lines: &str, chars: usize, wide: bool) -> Vec<u8> {
        let mut text = lines.to_string();
        while text.chars().count() < chars {
            text.push(' ');
        }
        if wide {
            text.encode_utf16().flat_map(u16::to_le_bytes).collect()
        } else {
            text.into_bytes()
        }
    }

    #[test]
    fn reads_integer_and_float_files() {
        let p = Path::new("synthetic.bcr");
        let stm = "fileformat = bcrstm\nxpixels = 3\nypixels = 2\nxlength = 6\nylength = 2\n\
                   xunit = um\nyunit = um\nzunit = nm\nbit2nm = 0.5\n";
        let mut bytes = header(stm, 2048, false);
        for v in [0i16, 2, 4, -2, 32767, 10] {
            bytes.extend(v.to_le_bytes());
        }
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.ny(), m.nx()), (2, 3));
        assert_eq!((m.dx_m, m.dy_m), (2e-6, 1e-6));
        assert_eq!(m.heights[[0, 1]], 1e-9);
        assert_eq!(m.heights[[1, 0]], -1e-9);
        assert!(m.heights[[1, 1]].is_nan());
        assert_eq!(m.invalid_points, 1);
        for cut in [0, 10, 100, 2048, bytes.len() - 1] {
            let err = read(p, &bytes[..cut], None).unwrap_err().to_string();
            assert!(err.contains("synthetic.bcr"), "{cut}: {err}");
        }

        // The UTF-16LE variant, big-endian floats, a 4096-character header.
        let f = "fileformat = bcrf_unicode\n%\nheadersize = 4096\nxpixels = 2\nypixels = 2\n\
                 intelmode = 0\nxlength = 4\nylength = 2\nzunit = um\n";
        let mut bytes = header(f, 4096, true);
        assert!(is_bcr(&bytes) && is_bcr(b"fileformat = bcrstm\n"));
        for v in [1.5f32, 2.0, 3.4e38, -1.0] {
            bytes.extend(v.to_be_bytes());
        }
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.dx_m, m.dy_m), (2e-9, 1e-9));
        assert_eq!(m.heights[[0, 0]], 1.5e-6);
        assert_eq!(m.heights[[1, 1]], -1e-6);
        assert!(m.heights[[1, 0]].is_nan());
        for cut in [0, 3, 4096, 8192, bytes.len() - 1] {
            let err = read(p, &bytes[..cut], None).unwrap_err().to_string();
            assert!(err.contains("synthetic.bcr"), "{cut}: {err}");
        }

        let volts = header(&stm.replace("zunit = nm", "zunit = V"), 2048, false);
        let err = read(p, &volts, None).unwrap_err().to_string();
        assert!(err.contains("'V', not a length"), "{err}");
    }

    #[test]
    fn real_file_matches_surface_topography() {
        let path = &crate::topography::test_support::sample("bcrf-1.bcrf");
        let Ok(bytes) = std::fs::read(path) else {
            return;
        };
        let detected = super::super::detect_file(path).unwrap();
        assert_eq!(detected, Some(TopographyFormat::Bcr));
        let m = read(path, &bytes, None).unwrap();
        // surface_topography_maps.csv: nx 960, ny 600, valid 576000.
        assert_eq!((m.nx(), m.ny(), m.valid_points()), (960, 600, 576000));
        let close = |a: f64, b: f64, tol: f64| assert!((a - b).abs() <= tol, "{a} vs {b}");
        close(m.dx_m, 1.8514625e-06, 1e-9 * 1.85e-6);
        close(m.dy_m, 1.8514633333333334e-06, 1e-9 * 1.85e-6);
        crate::topography::test_support::assert_stats(
            &m.heights,
            [
                4.9368610382080084e-05,
                5.1592369079589844e-05,
                5.063154553455115e-05,
                2.4560210667743558e-08,
            ],
        );
        crate::topography::test_support::truncations_and_corruptions(path, &bytes, |d| {
            read(path, d, None).map(|_| ())
        });
    }
}
