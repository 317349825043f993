//! NanoFocus µsurf `.nms` (header version `OM_MS_2.0`), layout as read by the `musurf-reader`
//! project (D. Mendroch) and SurfaceTopography's NMS reader; all fields little-endian. At 0 the
//! data type (u32, 2 = uint16), at 4 the dimension (u32, 0 = profile, 1 = area), at 8 and 12
//! the raw values of the lowest and highest height (u32, 0 and 65535), at 16 and 24 those
//! heights (f64, µm), at 32 the version text `OM_MS_2.0`, at 52 the title (`Confocal Height
//! Image`), at 1352 the header size (u32, 3468), at 1368 and 1372 the points per line and the
//! lines (u32), at 1376 and 1384 the x and y spacings (f64, nm), at 1416 whether an intensity
//! image follows (u32). The heights follow the header, line by line, as uint16:
//! height = z_low + (raw − raw_low)·(z_high − z_low)/(raw_high − raw_low) µm; then, when
//! flagged, one intensity byte per point, and a point of intensity 0 (no light returned) is
//! invalid. Rows are the stored lines, row 0 the first.
//!
//! Two readings differ from SurfaceTopography 1.27.1: it scales by 65534 instead of the
//! header's `raw_high − raw_low` (65535), so that raw 65535 lies above the stated z_high, and
//! it takes the spacing for mm, giving 0.3125 m pixels where the file's 312.5 nm (a 160 µm
//! field of 512 points) is meant.

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, line_scan, positive, ChannelEntry, HeightMap,
    TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

/// Version text at byte 32 of a NanoFocus file.
pub(crate) const VERSION: &[u8] = b"OM_MS_";

/// Offset of the version text.
pub(crate) const VERSION_AT: usize = 32;

/// End of the header fields read here.
const FIELDS_END: usize = 1420;

/// Read the height image of a NanoFocus NMS file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let at = |o: usize| Reader::new(path, data, o);
    let version = slice(path, data, VERSION_AT, 20, "the NMS version")?;
    let version: String = version
        .iter()
        .take_while(|&&b| b != 0)
        .map(|&b| char::from(b))
        .collect();
    if version != "OM_MS_2.0" {
        return Err(unsupported(
            path,
            format!("NanoFocus file version '{version}'; only OM_MS_2.0 is read"),
        ));
    }
    let head = slice(path, data, 0, FIELDS_END, "the NMS header")?;
    let kind = at(0).u32()?;
    if kind != 2 {
        return Err(unsupported(
            path,
            format!("NMS data type {kind} (only 2, 16-bit heights, is read)"),
        ));
    }
    let dimension = at(4).u32()?;
    let (raw_lo, raw_hi) = (f64::from(at(8).u32()?), f64::from(at(12).u32()?));
    let (z_lo, z_hi) = (at(16).f64()?, at(24).f64()?);
    if !(raw_hi > raw_lo && z_lo.is_finite() && z_hi.is_finite()) {
        return Err(bad(
            path,
            format!("NMS height range: raw {raw_lo}..{raw_hi} for {z_lo}..{z_hi} µm"),
        ));
    }
    let header = at(1352).u32()? as usize;
    let nx = count(path, "NMS points per line", f64::from(at(1368).u32()?))?;
    let ny = count(path, "NMS lines", f64::from(at(1372).u32()?))?;
    let dx = positive(path, "NMS x spacing", at(1376).f64()?)? * 1e-9;
    let dy = positive(path, "NMS y spacing", at(1384).f64()?)? * 1e-9;
    let intensity = at(1416).u32()? > 0;
    if header < FIELDS_END {
        return Err(bad(
            path,
            format!("NMS header size {header} is below the {FIELDS_END} bytes of its fields"),
        ));
    }
    let bytes = grid_bytes(path, nx, ny, 2)?;
    let raw = slice(path, data, header, bytes, "the NMS heights")?;
    let light = if intensity {
        Some(slice(
            path,
            data,
            header + bytes,
            nx * ny,
            "the NMS intensity image",
        )?)
    } else {
        None
    };
    match dimension {
        1 => {}
        0 => return Err(line_scan(path, nx * ny, Some(dx))),
        d => return Err(unsupported(path, format!("NMS dimension type {d}"))),
    }
    let scale = (z_hi - z_lo) / (raw_hi - raw_lo);
    let heights = decode_values(raw, 2, false, false, false)
        .into_iter()
        .enumerate()
        .map(|(i, v)| {
            if light.is_some_and(|l| l.get(i) == Some(&0)) {
                f64::NAN
            } else {
                (z_lo + (v - raw_lo) * scale) * 1e-6
            }
        })
        .collect();
    let title: String = head[52..]
        .iter()
        .take_while(|&&b| b != 0)
        .take(256)
        .map(|&b| char::from(b))
        .filter(|c| !c.is_control())
        .collect();
    let channels = [ChannelEntry {
        name: match title.trim() {
            "" => "Default".to_string(),
            t => t.to_string(),
        },
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    height_map(
        path,
        TopographyFormat::Nms,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal NMS file: 2 lines of 3 points, raw 0..1000 ↔ 1..3 µm, 500 nm × 250 nm pixels.
    fn nms(dimension: u32, raw: &[u16; 6], light: &[u8; 6]) -> Vec<u8> {
        let header = 1500usize;
        let mut out = vec![0u8; header];
        let mut put = |at: usize, b: &[u8]| out[at..at + b.len()].copy_from_slice(b);
        put(0, &2u32.to_le_bytes());
        put(4, &dimension.to_le_bytes());
        put(8, &0u32.to_le_bytes());
        put(12, &1000u32.to_le_bytes());
        put(16, &1.0f64.to_le_bytes());
        put(24, &3.0f64.to_le_bytes());
        put(32, b"OM_MS_2.0");
        put(52, b"Confocal Height Image");
        put(1352, &(header as u32).to_le_bytes());
        put(1368, &3u32.to_le_bytes());
        put(1372, &2u32.to_le_bytes());
        put(1376, &500.0f64.to_le_bytes());
        put(1384, &250.0f64.to_le_bytes());
        put(1416, &1u32.to_le_bytes());
        for v in raw {
            out.extend(v.to_le_bytes());
        }
        out.extend(light);
        out
    }

    #[test]
    fn reads_a_synthetic_file() {
        let p = Path::new("synthetic.nms");
        let bytes = nms(1, &[0, 500, 1000, 250, 750, 100], &[9, 9, 9, 9, 0, 9]);
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.ny(), m.nx()), (2, 3));
        assert_eq!(m.channel, "Confocal Height Image");
        let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-18, "{a} vs {b}");
        close(m.dx_m, 500e-9);
        close(m.dy_m, 250e-9);
        close(m.heights[[0, 0]], 1e-6);
        close(m.heights[[0, 1]], 2e-6);
        close(m.heights[[0, 2]], 3e-6);
        close(m.heights[[1, 0]], 1.5e-6);
        assert!(m.heights[[1, 1]].is_nan());
        assert_eq!(m.invalid_points, 1);
        for cut in [0, 20, 40, 1000, 1400, 1500, 1505, bytes.len() - 1] {
            let err = read(p, &bytes[..cut], None).unwrap_err().to_string();
            assert!(err.contains("synthetic.nms"), "{cut}: {err}");
        }
        let profile = nms(0, &[0; 6], &[1; 6]);
        let err = read(p, &profile, None).unwrap_err().to_string();
        assert!(
            err.contains("line scan") && err.contains("6 points"),
            "{err}"
        );
    }

    #[test]
    fn real_files_match_the_header() {
        let close = |a: f64, b: f64, tol: f64| assert!((a - b).abs() <= tol, "{a} vs {b}");
        // SurfaceTopography (surface_topography_maps.csv, nms-1): 512 × 512, 262144 valid,
        // min 2.689124584197998e-06, max 6.0074530544907334e-06, mean 4.344685260505125e-06,
        // rms 7.187185984110469e-07, with its 65534 divisor; the values below use the header's
        // 65535, so that raw 0 and 65535 give exactly its z_low and z_high. nms-2 is not
        // read by SurfaceTopography's open_topography (taken for a MATLAB file).
        let expected = [
            (
                "nms-1.nms",
                (2.689124584197998e-6, 6.007402420043945e-6),
                (4.344659998268515e-6, 7.187076314682163e-7),
            ),
            (
                "nms-2.nms",
                (6.320938587188721e-6, 8.28036880493164e-6),
                (7.278152776065301e-6, 4.17745056072178e-7),
            ),
        ];
        for (file, (min, max), (mean, rms)) in expected {
            let path = &crate::topography::test_support::sample(file);
            let Ok(bytes) = std::fs::read(path) else {
                continue;
            };
            let detected = super::super::detect_file(path).unwrap();
            assert_eq!(detected, Some(TopographyFormat::Nms));
            let m = read(path, &bytes, None).unwrap();
            assert_eq!((m.nx(), m.ny()), (512, 512));
            close(m.dx_m, 312.4999911618964e-9, 1e-9 * 312.5e-9);
            close(m.dy_m, 312.4999911618964e-9, 1e-9 * 312.5e-9);
            assert_eq!(m.valid_points(), 262144);
            crate::topography::test_support::assert_stats(&m.heights, [min, max, mean, rms]);
            crate::topography::test_support::truncations_and_corruptions(path, &bytes, |d| {
                read(path, d, None).map(|_| ())
            });
        }
    }
}
