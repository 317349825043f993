//! Statistics of a height map over its valid points: a map as an instrument stored it may hold
//! invalid (unmeasured, NaN) points, which the estimators of [`super::stats`] refuse. Here:
//! the height range and mean, h_rms about the mean of the valid heights (no detrending, as
//! SurfaceTopography's `rms_height_from_area`), and the rms slope (central differences) and
//! rms full Laplacian (5-point stencil) of `docs/conventions.md`, "Roughness statistics", over
//! the interior points whose whole stencil is valid. On a map without invalid points they equal
//! [`super::stats::rms_slope`], [`super::stats::rms_laplacian`] and
//! [`super::Topography::rms_height`]. What `contactscope topography` reports of a file as stored.

use ndarray::Array2;

/// Statistics of the valid points of a height map, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaskedStats {
    /// Points with a finite height.
    pub valid_points: usize,
    /// Lowest valid height, m (+∞ without a valid point).
    pub min_m: f64,
    /// Highest valid height, m (−∞ without a valid point).
    pub max_m: f64,
    /// Mean valid height, m (NaN without a valid point).
    pub mean_m: f64,
    /// rms height about the mean, m.
    pub rms_m: f64,
    /// rms slope (central differences), dimensionless; `None` without an interior point whose
    /// stencil is valid.
    pub slope_rms: Option<f64>,
    /// rms full Laplacian (5-point), 1/m; `None` as for the slope.
    pub curvature_rms_per_m: Option<f64>,
}

/// The statistics of heights (m, NaN where invalid) on a grid of `(dx, dy)` metres.
pub fn masked_stats(heights: &Array2<f64>, (dx_m, dy_m): (f64, f64)) -> MaskedStats {
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
    MaskedStats {
        valid_points: valid.len(),
        min_m: min,
        max_m: max,
        mean_m: mean,
        rms_m: rms,
        slope_rms: per(s2),
        curvature_rms_per_m: per(c2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{stats, Topography};

    #[test]
    fn masked_statistics_equal_the_library_estimators_on_full_maps() {
        let (ny, nx) = (9, 11);
        let h = Array2::from_shape_fn((ny, nx), |(i, j)| {
            let (i, j) = (i as f64, j as f64);
            1e-7 * (0.7 * j).sin() + 3e-8 * (0.4 * i).cos() * j
        });
        let s = masked_stats(&h, (2e-7, 3e-7));
        let t = Topography::new(h.clone(), 2e-7, 3e-7).unwrap();
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        assert!(rel(s.slope_rms.unwrap(), stats::rms_slope(&t).unwrap()) < 1e-12);
        assert!(
            rel(
                s.curvature_rms_per_m.unwrap(),
                stats::rms_laplacian(&t).unwrap()
            ) < 1e-12
        );
        assert!(rel(s.rms_m, t.rms_height()) < 1e-12);
        // One invalid point drops its own and its neighbours' stencils and its height.
        let mut holed = h;
        holed[[4, 5]] = f64::NAN;
        let s2 = masked_stats(&holed, (2e-7, 3e-7));
        assert_eq!(s2.valid_points, ny * nx - 1);
        assert!(s2.slope_rms.unwrap().is_finite() && s2.slope_rms != s.slope_rms);
    }
}
