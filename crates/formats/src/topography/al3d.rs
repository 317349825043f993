//! Alicona Imaging `.al3d` (InfiniteFocus focus-variation microscopes), layout as documented in
//! Alicona's AL3D specification 1.0 and as read by Gwyddion's `alicona` module: the 17-byte
//! magic `AliconaImaging\0\r\n`, then 52-byte tags (a NUL-padded key of 20 bytes, a NUL-padded
//! ASCII value of 30 bytes, CR LF): `Version`, `TagCount`, and `TagCount` more tags, then a
//! 256-byte comment. The depth image is float32 little-endian in metres at `DepthImageOffset`,
//! `Rows` lines of `Cols` values, each line padded to a multiple of 8 bytes; `PixelSizeXMeter`
//! and `PixelSizeYMeter` give the pixel size. A point equal to `InvalidPixelValue` (compared as
//! float32, the type it is stored in) or NaN is invalid. The `NumberOfPlanes` texture planes
//! (one byte per point) at `TextureImageOffset` must be in the file too, so that a truncated
//! file is refused rather than read as a whole one. Rows are the stored lines, row 0 the first.

use std::collections::HashMap;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice};
use crate::error::Result;

/// The magic at the start of an AL3D file.
pub(crate) const MAGIC: &[u8] = b"AliconaImaging\0\r\n";

const KEY: usize = 20;
const VALUE: usize = 30;
const TAG: usize = KEY + VALUE + 2;
const COMMENT: usize = 256;

/// The text of a NUL-padded field (Latin-1).
fn field(bytes: &[u8]) -> String {
    bytes
        .iter()
        .take_while(|&&b| b != 0)
        .map(|&b| char::from(b))
        .collect::<String>()
        .trim()
        .to_string()
}

/// The tag at `offset`: key and value, or an error naming what is wrong.
fn tag(path: &Path, data: &[u8], offset: usize, index: usize) -> Result<(String, String)> {
    let t = slice(path, data, offset, TAG, "an AL3D header tag")?;
    if &t[KEY + VALUE..] != b"\r\n" {
        return Err(bad(
            path,
            format!("AL3D header tag {index} at offset {offset} lacks its CR LF (corrupt header)"),
        ));
    }
    Ok((field(&t[..KEY]), field(&t[KEY..KEY + VALUE])))
}

/// Read the depth image of an Alicona AL3D file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let magic = slice(path, data, 0, MAGIC.len(), "the AL3D magic")?;
    if magic != MAGIC {
        return Err(bad(path, "not an AL3D file (no AliconaImaging magic)"));
    }
    let mut tags: HashMap<String, String> = HashMap::new();
    for (i, want) in ["Version", "TagCount"].into_iter().enumerate() {
        let (key, value) = tag(path, data, MAGIC.len() + i * TAG, i)?;
        if key != want {
            return Err(bad(
                path,
                format!("AL3D tag {i} is '{key}', expected '{want}'"),
            ));
        }
        tags.insert(key, value);
    }
    let number = |tags: &HashMap<String, String>, key: &str| -> Result<f64> {
        let v = tags
            .get(key)
            .ok_or_else(|| bad(path, format!("AL3D header without a '{key}' tag")))?;
        v.parse::<f64>()
            .map_err(|_| bad(path, format!("AL3D tag '{key}' is '{v}', not a number")))
    };
    let ntags = number(&tags, "TagCount")?;
    if !(ntags >= 0.0 && ntags.fract() == 0.0) {
        return Err(bad(path, format!("AL3D TagCount is {ntags}")));
    }
    // Each tag is sliced from the file before the next is read: a huge count stops at the end.
    let mut pos = MAGIC.len() + 2 * TAG;
    let mut i = 0usize;
    while (i as f64) < ntags {
        let (key, value) = tag(path, data, pos, i + 2)?;
        tags.entry(key).or_insert(value);
        pos += TAG;
        i += 1;
    }
    let header_end = pos + COMMENT;
    slice(path, data, pos, COMMENT, "the AL3D comment")?;

    let nx = count(path, "AL3D Cols", number(&tags, "Cols")?)?;
    let ny = count(path, "AL3D Rows", number(&tags, "Rows")?)?;
    let dx = positive(
        path,
        "AL3D PixelSizeXMeter",
        number(&tags, "PixelSizeXMeter")?,
    )?;
    let dy = positive(
        path,
        "AL3D PixelSizeYMeter",
        number(&tags, "PixelSizeYMeter")?,
    )?;
    let offset = number(&tags, "DepthImageOffset")?;
    if offset == 0.0 {
        return Err(bad(
            path,
            "the AL3D file holds no depth image (DepthImageOffset 0)",
        ));
    }
    if !(offset >= header_end as f64 && offset.fract() == 0.0 && offset <= data.len() as f64) {
        return Err(bad(
            path,
            format!(
                "AL3D DepthImageOffset {offset} is outside the file's {} bytes after its {header_end}-byte header",
                data.len()
            ),
        ));
    }
    let offset = offset as usize;
    // Lines are padded to a multiple of 8 bytes; the last line's padding need not be there.
    let stride = (nx * 4).div_ceil(8) * 8;
    grid_bytes(path, stride / 4, ny, 4)?;
    let depth_len = (ny - 1) * stride + nx * 4;
    let depth = slice(path, data, offset, depth_len, "the AL3D depth image")?;
    check_texture(path, data, &tags, nx, ny)?;

    let marker = tags
        .get("InvalidPixelValue")
        .and_then(|v| v.parse::<f64>().ok())
        .map(|v| v as f32)
        .filter(|v| !v.is_nan());
    let mut heights = Vec::with_capacity(nx * ny);
    for line in depth.chunks(stride) {
        for v in decode_values(&line[..nx * 4], 4, true, false, false) {
            let invalid = v.is_nan() || marker.is_some_and(|m| v as f32 == m);
            heights.push(if invalid { f64::NAN } else { v });
        }
    }
    let channels = [ChannelEntry {
        name: "Default".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    height_map(
        path,
        TopographyFormat::Al3d,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

/// The texture planes the header declares must be in the file (one byte per point at least).
fn check_texture(
    path: &Path,
    data: &[u8],
    tags: &HashMap<String, String>,
    nx: usize,
    ny: usize,
) -> Result<()> {
    let get = |k: &str| tags.get(k).and_then(|v| v.parse::<f64>().ok());
    let (Some(offset), Some(planes)) = (get("TextureImageOffset"), get("NumberOfPlanes")) else {
        return Ok(());
    };
    if offset <= 0.0 || planes <= 0.0 {
        return Ok(());
    }
    let need = (planes * (nx * ny) as f64) + offset;
    if need > data.len() as f64 {
        return Err(bad(
            path,
            format!(
                "file is truncated: the AL3D header declares {planes} texture planes of {ny}×{nx} \
                 bytes at offset {offset}, the file has {} bytes",
                data.len()
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal AL3D file: 2 rows of 3 values (lines padded to 16 bytes), one texture plane.
    fn al3d(values: &[f32; 6]) -> Vec<u8> {
        let tags = [
            ("Version", "1".to_string()),
            ("TagCount", "8".into()),
            ("Cols", "3".into()),
            ("Rows", "2".into()),
            ("PixelSizeXMeter", "2e-06".into()),
            ("PixelSizeYMeter", "3e-06".into()),
            ("InvalidPixelValue", "3.000000028082e+15".into()),
            ("NumberOfPlanes", "1".into()),
            ("DepthImageOffset", "0".into()),
            ("TextureImageOffset", "0".into()),
        ];
        let header_len = MAGIC.len() + tags.len() * TAG + COMMENT;
        let depth = header_len;
        let texture = depth + 2 * 16;
        let mut out = MAGIC.to_vec();
        for (k, v) in tags {
            let v = match k {
                "DepthImageOffset" => depth.to_string(),
                "TextureImageOffset" => texture.to_string(),
                _ => v,
            };
            let mut t = [0u8; TAG];
            t[..k.len()].copy_from_slice(k.as_bytes());
            t[KEY..KEY + v.len()].copy_from_slice(v.as_bytes());
            t[TAG - 2..].copy_from_slice(b"\r\n");
            out.extend(t);
        }
        let mut comment = [0u8; COMMENT];
        comment[COMMENT - 2..].copy_from_slice(b"\r\n");
        out.extend(comment);
        for row in values.chunks(3) {
            for v in row {
                out.extend(v.to_le_bytes());
            }
            out.extend([0u8; 4]);
        }
        out.extend([7u8; 6]);
        out
    }

    #[test]
    fn reads_a_synthetic_file() {
        let p = Path::new("synthetic.al3d");
        let bytes = al3d(&[1e-6, 2e-6, 3e15, 4e-6, f32::NAN, 6e-6]);
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.ny(), m.nx()), (2, 3));
        assert_eq!((m.dx_m, m.dy_m), (2e-6, 3e-6));
        assert_eq!(m.heights[[0, 1]], f64::from(2e-6f32));
        assert_eq!(m.heights[[1, 2]], f64::from(6e-6f32));
        assert!(m.heights[[0, 2]].is_nan() && m.heights[[1, 1]].is_nan());
        assert_eq!(m.invalid_points, 2);
        assert_eq!(m.channel, "Default");
        for cut in [0, 5, 17, 60, 200, bytes.len() - 40, bytes.len() - 1] {
            let err = read(p, &bytes[..cut], None).unwrap_err().to_string();
            assert!(err.contains("synthetic.al3d"), "{cut}: {err}");
        }
    }

    #[test]
    fn real_file_matches_surface_topography() {
        let path = &crate::topography::test_support::sample("al3d-1.al3d");
        let Ok(bytes) = std::fs::read(path) else {
            return;
        };
        let detected = super::super::detect_file(path).unwrap();
        assert_eq!(detected, Some(TopographyFormat::Al3d));
        let m = read(path, &bytes, None).unwrap();
        // surface_topography_maps.csv: nx 200, ny 296, valid 59200.
        assert_eq!((m.nx(), m.ny(), m.valid_points()), (200, 296, 59200));
        let close = |a: f64, b: f64, tol: f64| assert!((a - b).abs() <= tol, "{a} vs {b}");
        close(m.dx_m, 4.38027e-07, 1e-9 * 4.38027e-07);
        close(m.dy_m, 4.38027e-07, 1e-9 * 4.38027e-07);
        crate::topography::test_support::assert_stats(
            &m.heights,
            [
                0.07632320374250412,
                0.07635815441608429,
                0.07634093332028873,
                7.688265843362921e-06,
            ],
        );
        crate::topography::test_support::truncations_and_corruptions(path, &bytes, |d| {
            read(path, d, None).map(|_| ())
        });
    }
}
