//! Zygo MetroPro `.dat` (binary), as the *MetroPro Reference Guide* (Zygo OMP-0347) lays it out:
//! a big-endian header that starts with the magic number `0x881B036F`, `0x881B0370` or
//! `0x881B0371` (header formats 1, 2 and 3), then the intensity data, then the phase data.
//!
//! The fields read, at their byte offsets in the header: header size (u32 at 6; 834 bytes for
//! formats 1 and 2, 4096 for format 3), the intensity array's width, height and bucket count
//! (u16 at 52, 54, 56) and byte count (u32 at 60), the phase array's width and height (u16 at
//! 68, 70), the interferometric scale factor `S` (f32 at 164), the wavelength `λ` in metres
//! (f32 at 168), the obliquity factor `O` (f32 at 176), the camera resolution (f32 at 184: the
//! distance between pixels in metres, 0 when not calibrated), the phase resolution code (i16 at
//! 218: 0, 1 or 2 for `R` = 4096, 32768 or 131072) and the phase sign (i16 at 232).
//!
//! The intensity data (`2 · buckets · width · height` bytes) start at the header size; the
//! phase data follow them: `width · height` big-endian i32 values, row by row from the top of
//! the camera image. As the guide defines it, a phase value `p` is `p · S · O / R` waves, so the
//! height is `p · S · O · λ / R` metres, negated when the sign field is set; a value of
//! 2147483640 or more marks a point that was not measured (NaN here). The pixel size is the
//! camera resolution along both axes; a file with a resolution of 0 states no pixel size (see
//! [`read_height_map`](super::read_height_map)).

use std::path::Path;

use super::{choose, count, grid_bytes, height_map, ChannelEntry, HeightMap, TopographyFormat};
use crate::binary::{bad, slice, unsupported, Reader};
use crate::error::Result;

/// The three magic numbers (header formats 1, 2, 3), big-endian.
pub(crate) const MAGICS: [[u8; 4]; 3] = [
    [0x88, 0x1b, 0x03, 0x6f],
    [0x88, 0x1b, 0x03, 0x70],
    [0x88, 0x1b, 0x03, 0x71],
];

/// Bytes of the header fields read (the format 1 and 2 header).
const MIN_HEADER: usize = 834;

/// Phase values at or above this mark invalid points.
const INVALID_PHASE: i32 = 2_147_483_640;

/// Whether the file starts with a MetroPro magic number.
pub(crate) fn is_metropro(head: &[u8]) -> bool {
    MAGICS.iter().any(|m| head.starts_with(m))
}

/// Read the phase data of a MetroPro file as heights.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    if !is_metropro(data) {
        return Err(bad(path, "not a MetroPro file (no magic number)"));
    }
    let header = slice(path, data, 0, MIN_HEADER, "the MetroPro header")?;
    let at = |o: usize| Reader::new(path, header, o).big_endian(true);
    let header_size = at(6).usize_u32()?;
    if header_size < MIN_HEADER {
        return Err(bad(
            path,
            format!("MetroPro header size {header_size} is below {MIN_HEADER} bytes"),
        ));
    }
    let intensity_bytes = at(60).usize_u32()?;
    let nx = usize::from(at(68).u16()?);
    let ny = usize::from(at(70).u16()?);
    if nx == 0 || ny == 0 {
        return Err(unsupported(
            path,
            format!("the MetroPro file holds no phase data ({nx}×{ny}): an intensity image only"),
        ));
    }
    let scale_factor = f64::from(at(164).f32()?);
    let wavelength = f64::from(at(168).f32()?);
    let obliquity = f64::from(at(176).f32()?);
    let resolution = f64::from(at(184).f32()?);
    let phase_resolution = match at(218).i16()? {
        0 => 4096.0,
        1 => 32768.0,
        2 => 131072.0,
        other => {
            return Err(bad(
                path,
                format!("MetroPro phase resolution code {other} (expected 0, 1 or 2)"),
            ))
        }
    };
    let sign = if at(232).i16()? != 0 { -1.0 } else { 1.0 };
    let scale = sign * scale_factor * obliquity * wavelength / phase_resolution;
    if !(scale.is_finite() && scale != 0.0) {
        return Err(bad(
            path,
            format!(
                "MetroPro height scale is {scale} (scale factor {scale_factor}, obliquity \
                 {obliquity}, wavelength {wavelength} m)"
            ),
        ));
    }
    let channels = [ChannelEntry {
        name: "Default".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    // Checked against the size limit before the phase data's offset is computed from it.
    let ny = count(path, "MetroPro phase height", ny as f64)?;
    let bytes = grid_bytes(path, nx, ny, 4)?;
    let start = header_size
        .checked_add(intensity_bytes)
        .ok_or_else(|| bad(path, "MetroPro data offset overflows"))?;
    let phase = slice(path, data, start, bytes, "the MetroPro phase data")?;
    let heights = phase
        .chunks_exact(4)
        .map(|c| {
            let p = i32::from_be_bytes([c[0], c[1], c[2], c[3]]);
            if p >= INVALID_PHASE {
                f64::NAN
            } else {
                f64::from(p) * scale
            }
        })
        .collect();
    // A camera resolution of 0 (not calibrated): the file states no pixel size.
    let pixel = if resolution == 0.0 {
        f64::NAN
    } else {
        resolution
    };
    height_map(
        path,
        TopographyFormat::MetroPro,
        (&channels, index),
        (ny, nx),
        heights,
        (pixel, pixel),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_support::{
        assert_close, assert_stats, truncations_and_corruptions,
    };

    /// A format-1 file of `nx × ny` phase values with one bucket of intensity data.
    fn synthetic(nx: u16, ny: u16, phase: &[i32], resolution: f32) -> Vec<u8> {
        let mut h = vec![0u8; MIN_HEADER];
        let mut put = |o: usize, b: &[u8]| h[o..o + b.len()].copy_from_slice(b);
        put(0, &MAGICS[0]);
        put(4, &1u16.to_be_bytes());
        put(6, &(MIN_HEADER as u32).to_be_bytes());
        put(52, &nx.to_be_bytes());
        put(54, &ny.to_be_bytes());
        put(56, &1u16.to_be_bytes());
        let intensity = 2 * u32::from(nx) * u32::from(ny);
        put(60, &intensity.to_be_bytes());
        put(68, &nx.to_be_bytes());
        put(70, &ny.to_be_bytes());
        put(72, &(4 * u32::from(nx) * u32::from(ny)).to_be_bytes());
        put(164, &0.5f32.to_be_bytes());
        put(168, &6.0e-7f32.to_be_bytes());
        put(176, &1.0f32.to_be_bytes());
        put(184, &resolution.to_be_bytes());
        put(218, &0i16.to_be_bytes());
        h.extend(std::iter::repeat_n(7u8, intensity as usize));
        for p in phase {
            h.extend(p.to_be_bytes());
        }
        h
    }

    #[test]
    fn synthetic_file_reads_back() {
        let p = Path::new("s.dat");
        let data = synthetic(3, 2, &[0, 4096, -8192, 100, INVALID_PHASE, i32::MAX], 2e-6);
        let m = read(p, &data, None).unwrap();
        assert_eq!((m.ny(), m.nx(), m.invalid_points), (2, 3, 2));
        let wave = 0.5 * f64::from(6.0e-7f32);
        assert!((m.heights[[0, 1]] - wave).abs() < 1e-20);
        assert!((m.heights[[0, 2]] + 2.0 * wave).abs() < 1e-20);
        assert!((m.heights[[1, 0]] - 100.0 * wave / 4096.0).abs() < 1e-20);
        assert!(m.heights[[1, 1]].is_nan() && m.heights[[1, 2]].is_nan());
        assert_eq!((m.dx_m, m.dy_m), (f64::from(2e-6f32), f64::from(2e-6f32)));
        assert_eq!(m.channel, "Default");
        // Uncalibrated: no pixel size stated.
        let m = read(p, &synthetic(1, 1, &[1], 0.0), None).unwrap();
        assert!(m.dx_m.is_nan() && m.dy_m.is_nan());
        for cut in [0, 3, 100, MIN_HEADER, data.len() - 1] {
            let err = read(p, &data[..cut], None).unwrap_err().to_string();
            assert!(err.contains("s.dat"), "{err}");
        }
        let mut bad_res = data.clone();
        bad_res[218..220].copy_from_slice(&7i16.to_be_bytes());
        assert!(read(p, &bad_res, None).is_err());
    }

    #[test]
    fn a_file_without_pixel_size_needs_one_given() {
        use crate::topography::{detect, read_height_map, ReadOptions};
        let data = synthetic(2, 1, &[1, 2], 0.0);
        assert_eq!(detect(&data), Some(TopographyFormat::MetroPro));
        // Serialised as its name.
        for f in [
            TopographyFormat::MetroPro,
            TopographyFormat::NetCdf,
            TopographyFormat::Hdf5,
        ] {
            assert_eq!(
                serde_json::to_string(&f).unwrap(),
                format!("\"{}\"", f.name())
            );
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("uncalibrated.dat");
        std::fs::write(&path, &data).unwrap();
        let err = read_height_map(&path, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("uncalibrated.dat") && err.contains("no pixel size"),
            "{err}"
        );
        assert!(
            err.contains(&crate::param::Param::PixelSize.to_string()),
            "{err}"
        );
        let given = ReadOptions {
            pixel_size_m: Some((1e-6, 2e-6)),
            ..ReadOptions::default()
        };
        let m = read_height_map(&path, &given).unwrap();
        assert_eq!((m.dx_m, m.dy_m), (1e-6, 2e-6));
        // MetroPro states its height unit: another one is refused.
        let unit = ReadOptions {
            height_unit_m: Some(1e-6),
            ..given
        };
        assert!(read_height_map(&path, &unit).is_err());
    }

    #[test]
    fn real_file_matches_surface_topography() {
        let path = &crate::topography::test_support::sample("metropro-1.dat");
        let Ok(data) = std::fs::read(path) else {
            return;
        };
        assert_eq!(
            crate::topography::detect(&data),
            Some(TopographyFormat::MetroPro)
        );
        let m = read(path, &data, None).unwrap();
        // SurfaceTopography 1.27.1: nx 640, ny 480, 307200 valid points.
        assert_eq!((m.nx(), m.ny(), m.valid_points()), (640, 480, 307200));
        assert_close(m.dx_m, 1.0982520279867458e-06);
        assert_close(m.dy_m, 1.0982520279867458e-06);
        assert_stats(
            &m.heights,
            [
                5.010827568297134e-05,
                5.147133201226055e-05,
                5.074040590166325e-05,
                7.52882220473459e-08,
            ],
        );
        truncations_and_corruptions(path, &data, |d| read(path, d, None).map(|_| ()));
    }
}
