//! TrueMap `.tmd` (TrueGage TrueMap, GelSight), layout as documented by Gwyddion's `rmitmd`
//! module and the `tmd` project: the 32-byte line `Binary TrueMap Data File v2.0\r\n\0`, a
//! NUL-terminated comment (`Created by TrueMap v6\r\n\0` in the files seen, 24 bytes; its length
//! is found from its NUL, not assumed), then little-endian x size and y size (u32), x and y
//! lengths, x and y offsets (f32, mm), then the heights: y size lines of x size float32 values
//! in mm. The map has no invalid-point marker; a NaN is invalid. Rows are the stored lines,
//! row 0 the first. Only version 2.0 is read.

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

/// The start of every TrueMap file; the version follows.
pub(crate) const MAGIC: &[u8] = b"Binary TrueMap Data File v";

const LINE: &[u8] = b"Binary TrueMap Data File v2.0\r\n\0";

/// Longest comment looked through for its NUL (bytes).
const MAX_COMMENT: usize = 4096;

/// Read the height map of a TrueMap TMD file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let first = slice(path, data, 0, LINE.len(), "the TMD header line")?;
    if first != LINE {
        let line: String = first
            .iter()
            .take_while(|&&b| b != b'\r' && b != 0)
            .map(|&b| char::from(b))
            .collect();
        return Err(unsupported(
            path,
            format!("'{line}': only TrueMap files of version 2.0 are read"),
        ));
    }
    let rest = &data[LINE.len()..];
    let nul = rest
        .iter()
        .take(MAX_COMMENT)
        .position(|&b| b == 0)
        .ok_or_else(|| {
            bad(
                path,
                "file is truncated or corrupt: the TMD comment has no terminating NUL",
            )
        })?;
    let mut r = Reader::new(path, data, LINE.len() + nul + 1);
    let nx = count(path, "TMD x size", f64::from(r.u32()?))?;
    let ny = count(path, "TMD y size", f64::from(r.u32()?))?;
    let lx = positive(path, "TMD x length", f64::from(r.f32()?))?;
    let ly = positive(path, "TMD y length", f64::from(r.f32()?))?;
    let _offsets = (r.f32()?, r.f32()?);
    let bytes = grid_bytes(path, nx, ny, 4)?;
    let raw = slice(path, data, r.pos, bytes, "the TMD heights")?;
    let heights = decode_values(raw, 4, true, false, false)
        .into_iter()
        .map(|v| v * 1e-3)
        .collect();
    let channels = [ChannelEntry {
        name: "Default".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    height_map(
        path,
        TopographyFormat::Tmd,
        (&channels, index),
        (ny, nx),
        heights,
        (lx * 1e-3 / nx as f64, ly * 1e-3 / ny as f64),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmd(comment: &str, values: &[f32]) -> Vec<u8> {
        let mut out = LINE.to_vec();
        out.extend(comment.as_bytes());
        out.push(0);
        out.extend(3u32.to_le_bytes());
        out.extend(2u32.to_le_bytes());
        for v in [0.6f32, 0.4, 1.0, 2.0] {
            out.extend(v.to_le_bytes());
        }
        for v in values {
            out.extend(v.to_le_bytes());
        }
        out
    }

    #[test]
    fn reads_a_synthetic_file() {
        let p = Path::new("synthetic.tmd");
        let values = [0.5f32, 0.25, 0.0, 1.0, f32::NAN, 2.0];
        for comment in [
            "",
            "Created by TrueMap v6\r\n",
            "a longer comment, 40 bytes",
        ] {
            let bytes = tmd(comment, &values);
            let m = read(p, &bytes, None).unwrap();
            assert_eq!((m.ny(), m.nx()), (2, 3));
            assert!((m.dx_m - 0.2e-3).abs() < 1e-10 && (m.dy_m - 0.2e-3).abs() < 1e-10);
            assert_eq!(m.heights[[0, 0]], 0.5e-3);
            assert_eq!(m.heights[[1, 2]], 2e-3);
            assert_eq!(m.invalid_points, 1);
            for cut in [0, 10, 32, 40, bytes.len() - 30, bytes.len() - 1] {
                let err = read(p, &bytes[..cut], None).unwrap_err().to_string();
                assert!(err.contains("synthetic.tmd"), "{cut}: {err}");
            }
        }
        let mut v1 = tmd("", &values);
        v1[26] = b'1';
        let err = read(p, &v1, None).unwrap_err().to_string();
        assert!(err.contains("version 2.0") && err.contains("v1.0"), "{err}");
    }

    #[test]
    fn real_file_matches_surface_topography() {
        let path = &crate::topography::test_support::sample("tmd-1.tmd");
        let Ok(bytes) = std::fs::read(path) else {
            return;
        };
        let detected = super::super::detect_file(path).unwrap();
        assert_eq!(detected, Some(TopographyFormat::Tmd));
        let m = read(path, &bytes, None).unwrap();
        // surface_topography_maps.csv: nx 300, ny 300, valid 90000.
        assert_eq!((m.nx(), m.ny(), m.valid_points()), (300, 300, 90000));
        let close = |a: f64, b: f64, tol: f64| assert!((a - b).abs() <= tol, "{a} vs {b}");
        close(m.dx_m, 6.318866729736329e-05, 1e-9 * 6.32e-5);
        close(m.dy_m, 6.318866729736329e-05, 1e-9 * 6.32e-5);
        crate::topography::test_support::assert_stats(
            &m.heights,
            [
                0.0,
                0.0003509870171546936,
                0.00017287914127574167,
                7.434134067352182e-05,
            ],
        );
        crate::topography::test_support::truncations_and_corruptions(path, &bytes, |d| {
            read(path, d, None).map(|_| ())
        });
    }
}
