//! The machine-readable summary that `contactscope topography FILE --json` prints (issue 14,
//! item 3), over the valid points of the map:
//!
//! ```json
//! {"file": "…", "format": "ibw", "channel": "HeightTrace", "nx": 256, "ny": 256,
//!  "pixel_size_um": {"x": 0.0784, "y": 0.0784}, "valid_points": 65536,
//!  "height_min_um": -0.7046, "height_max_um": -0.3312, "height_mean_um": -0.5387,
//!  "h_rms_um": 0.08945, "slope_rms": 0.61, "curvature_rms": 1.9e7}
//! ```
//!
//! `h_rms_um` is the rms about the mean of the valid heights (no detrending, as
//! SurfaceTopography's `rms_height_from_area`); `slope_rms` (dimensionless) and
//! `curvature_rms` (1/m, full 5-point Laplacian) follow `docs/conventions.md` (central
//! differences on interior points), over the interior points whose whole stencil is valid.
//! On a map without invalid points they equal [`crate::surface::stats::rms_slope`] and
//! [`crate::surface::stats::rms_laplacian`].

use std::path::Path;

use ndarray::Array2;
use serde::Serialize;

use super::{read, HeightMap};
use crate::error::Result;

/// `topography --json` for one file.
#[derive(Debug, Clone, Serialize)]
pub struct TopographySummary {
    /// The file as named.
    pub file: String,
    /// Format name (`ibw`, `park-tiff`, …).
    pub format: String,
    /// Channel read.
    pub channel: String,
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Pixel size in µm.
    pub pixel_size_um: PixelSizeXy,
    /// Points with a height.
    pub valid_points: usize,
    /// Lowest valid height, µm.
    pub height_min_um: f64,
    /// Highest valid height, µm.
    pub height_max_um: f64,
    /// Mean valid height, µm.
    pub height_mean_um: f64,
    /// rms height about the mean, µm.
    pub h_rms_um: f64,
    /// rms slope (central differences), dimensionless; `null` without an interior point.
    pub slope_rms: Option<f64>,
    /// rms full Laplacian (5-point), 1/m; `null` without an interior point.
    pub curvature_rms: Option<f64>,
}

/// Lateral pixel size in µm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PixelSizeXy {
    /// Along x.
    pub x: f64,
    /// Along y.
    pub y: f64,
}

impl TopographySummary {
    /// An error naming `path` when a statistic is not finite (no valid point, or heights or
    /// pixel sizes so extreme that sums of squares overflow): nothing non-finite is printed.
    pub fn check_finite(&self, path: &std::path::Path) -> crate::error::Result<()> {
        let values = [
            ("pixel size x", Some(self.pixel_size_um.x)),
            ("pixel size y", Some(self.pixel_size_um.y)),
            ("minimum height", Some(self.height_min_um)),
            ("maximum height", Some(self.height_max_um)),
            ("mean height", Some(self.height_mean_um)),
            ("rms height", Some(self.h_rms_um)),
            ("rms slope", self.slope_rms),
            ("rms curvature", self.curvature_rms),
        ];
        match values
            .iter()
            .find(|(_, v)| v.is_some_and(|v| !v.is_finite()))
        {
            None => Ok(()),
            Some((what, v)) => Err(crate::error::Error::bad_input(
                crate::error::Location::file(path),
                format!(
                    "the {what} of the stored heights is {} ({} valid of {} points; heights up \
                     to {:e} µm): not a usable height map",
                    v.unwrap_or(f64::NAN),
                    self.valid_points,
                    self.nx * self.ny,
                    self.height_min_um.abs().max(self.height_max_um.abs())
                ),
            )),
        }
    }
}

/// Statistics of a height map over its valid points.
pub fn summarise(file: &str, map: &HeightMap) -> TopographySummary {
    summarise_heights(
        file,
        map.format.name(),
        &map.channel,
        &map.heights,
        (map.dx_m, map.dy_m),
    )
}

/// Statistics of heights (m, NaN where invalid) on a grid of `(dx, dy)` metres, for a map of
/// any format (`format` and `channel` are only reported).
pub fn summarise_heights(
    file: &str,
    format: &str,
    channel: &str,
    heights: &Array2<f64>,
    (dx_m, dy_m): (f64, f64),
) -> TopographySummary {
    let valid: Vec<f64> = heights.iter().copied().filter(|h| h.is_finite()).collect();
    let n = valid.len() as f64;
    let mean = valid.iter().sum::<f64>() / n;
    let rms = (valid.iter().map(|h| (h - mean) * (h - mean)).sum::<f64>() / n).sqrt();
    let min = valid.iter().copied().fold(f64::INFINITY, f64::min);
    let max = valid.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let h = heights;
    let (ny, nx) = h.dim();
    let (mut s2, mut c2, mut count) = (0.0, 0.0, 0usize);
    let (a, b) = (0.5 / dx_m, 0.5 / dy_m);
    let (ax, by) = (1.0 / (dx_m * dx_m), 1.0 / (dy_m * dy_m));
    for i in 1..ny.saturating_sub(1) {
        for j in 1..nx.saturating_sub(1) {
            let (c, l, r, u, d) = (
                h[[i, j]],
                h[[i, j - 1]],
                h[[i, j + 1]],
                h[[i - 1, j]],
                h[[i + 1, j]],
            );
            if !(c.is_finite() && l.is_finite() && r.is_finite() && u.is_finite() && d.is_finite())
            {
                continue;
            }
            let (gx, gy) = ((r - l) * a, (d - u) * b);
            let lap = (r - 2.0 * c + l) * ax + (d - 2.0 * c + u) * by;
            s2 += gx * gx + gy * gy;
            c2 += lap * lap;
            count += 1;
        }
    }
    let per = |s: f64| (count > 0).then(|| (s / count as f64).sqrt());
    TopographySummary {
        file: file.to_string(),
        format: format.to_string(),
        channel: channel.to_string(),
        nx,
        ny,
        pixel_size_um: PixelSizeXy {
            x: dx_m * 1e6,
            y: dy_m * 1e6,
        },
        valid_points: valid.len(),
        height_min_um: min * 1e6,
        height_max_um: max * 1e6,
        height_mean_um: mean * 1e6,
        h_rms_um: rms * 1e6,
        slope_rms: per(s2),
        curvature_rms: per(c2),
    }
}

/// Read a file ([`read`]) and summarise it.
pub fn topography_summary(path: &Path, channel: Option<&str>) -> Result<TopographySummary> {
    let map = read(path, channel)?;
    Ok(summarise(&path.display().to_string(), &map))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::topography::{height_map, ChannelEntry, TopographyFormat};
    use crate::surface::stats;

    #[test]
    fn masked_statistics_equal_the_library_estimators_on_full_maps() {
        let (ny, nx) = (9, 11);
        let h: Vec<f64> = (0..ny * nx)
            .map(|k| {
                let (i, j) = ((k / nx) as f64, (k % nx) as f64);
                1e-7 * (0.7 * j).sin() + 3e-8 * (0.4 * i).cos() * j
            })
            .collect();
        let c = [ChannelEntry {
            name: "h".into(),
            height: true,
        }];
        let p = Path::new("m");
        let map = height_map(
            p,
            TopographyFormat::Sur,
            (&c, 0),
            (ny, nx),
            h.clone(),
            (2e-7, 3e-7),
        )
        .unwrap();
        let s = summarise("m", &map);
        let t = map.clone().into_topography(p, None).unwrap();
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        assert!(rel(s.slope_rms.unwrap(), stats::rms_slope(&t).unwrap()) < 1e-12);
        assert!(rel(s.curvature_rms.unwrap(), stats::rms_laplacian(&t).unwrap()) < 1e-12);
        assert!(rel(s.h_rms_um * 1e-6, t.rms_height()) < 1e-12);
        // One invalid point drops its own and its neighbours' stencils and its height.
        let mut holed = h;
        holed[4 * nx + 5] = f64::NAN;
        let m2 = height_map(
            p,
            TopographyFormat::Sur,
            (&c, 0),
            (ny, nx),
            holed,
            (2e-7, 3e-7),
        )
        .unwrap();
        let s2 = summarise("m", &m2);
        assert_eq!(s2.valid_points, ny * nx - 1);
        assert!(s2.slope_rms.unwrap().is_finite() && s2.slope_rms != s.slope_rms);
    }
}
