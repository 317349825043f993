//! The detrending rules of SurfaceTopography and contact.engineering (`detrend_mode` of a
//! surface container's measurement), applied to a height map as a container asks for it.
//!
//! Every rule subtracts a polynomial fitted to the *valid* (finite) heights; invalid points
//! (NaN) stay invalid. The fitted residual does not depend on where the coordinates' origin is
//! or on their scale, so the fits here use centred coordinates scaled by the map's size, which
//! keeps the normal equations well conditioned:
//!
//! | mode | what is subtracted |
//! |---|---|
//! | `center`, `mean` | the mean height |
//! | `height`, `rms-tilt` | the least-squares plane `a + b·x + c·y` |
//! | `curvature`, `rms-curvature` | the least-squares quadric `a + b·x + c·y + d·x² + e·y² + f·x·y` |
//! | `slope` | the plane whose slopes are the mean forward-difference slopes along x and y, placed so that the mean of the result is zero |
//! | `median` | the median height of the piecewise-linear surface ([`super::bearing::median_height`]) |
//!
//! For `slope` SurfaceTopography takes the forward differences of a non-periodic map on the
//! grid that both derivatives share, (nx − 1) × (ny − 1) points: the x differences leave out the
//! last row and the y differences the last column; so does [`ContainerDetrend::Slope`]. Where a
//! reader stores the lines in the opposite order to SurfaceTopography's y (the Nanosurf `.nid`
//! reader, top line first), the line left out is the other one, and the slope differs by about
//! one line's share (1e-4 relative on a 256-line map).
//!
//! `median` is SurfaceTopography's median: the height at which the bearing area of the
//! piecewise-linear surface is one half, found by bisection to 1e-6 of the height range (not a
//! median of the points); a periodic map's surface closes across its edges.
//!
//! Not provided, and refused by name ([`ContainerDetrend::from_mode`]): `mad-tilt` and
//! `mad-curvature` (the polynomial minimising the residual's median absolute deviation, which
//! SurfaceTopography finds with scipy's Nelder–Mead from the least-squares fit: a result that
//! is the optimiser's, to its own tolerances, more than the data's — its tolerances are absolute
//! in the container's height unit, so the same map stored in m keeps the least-squares tilt and
//! in µm or nm gets another, `docs/formats.md`).

use nalgebra::{DMatrix, DVector};
use ndarray::Array2;

use crate::error::{Error, Result};

/// One of SurfaceTopography's detrend modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContainerDetrend {
    /// Subtract the mean (`center`, `mean`).
    Mean,
    /// Subtract the least-squares plane (`height`, `rms-tilt`).
    Plane,
    /// Subtract the least-squares quadric (`curvature`, `rms-curvature`).
    Quadric,
    /// Subtract the mean-slope plane (`slope`).
    Slope,
    /// Subtract the median height of the piecewise-linear surface (`median`).
    Median,
}

impl ContainerDetrend {
    /// The rule of a `detrend_mode`, or an error naming the mode.
    pub fn from_mode(mode: &str) -> Result<ContainerDetrend> {
        Ok(match mode.trim() {
            "center" | "mean" => ContainerDetrend::Mean,
            "height" | "rms-tilt" => ContainerDetrend::Plane,
            "curvature" | "rms-curvature" => ContainerDetrend::Quadric,
            "slope" => ContainerDetrend::Slope,
            "median" => ContainerDetrend::Median,
            mad @ ("mad-tilt" | "mad-curvature") => {
                return Err(Error::InvalidArgument(format!(
                    "detrend mode '{mad}' is not applied by contactscope: SurfaceTopography's \
                     result for it is its optimiser's, whose tolerances are absolute in the \
                     container's height unit (the same map in m and in nm is detrended \
                     differently); set the measurement's detrend_mode to '{}' (the \
                     least-squares {}) or 'median' in the container",
                    if mad == "mad-tilt" {
                        "height"
                    } else {
                        "curvature"
                    },
                    if mad == "mad-tilt" {
                        "plane"
                    } else {
                        "quadric"
                    }
                )))
            }
            other => {
                return Err(Error::InvalidArgument(format!(
                    "detrend mode '{other}' is not applied by contactscope (it applies center, \
                     mean, median, height, rms-tilt, slope, curvature and rms-curvature)"
                )))
            }
        })
    }

    /// Subtract the trend from `heights` (rows = y, NaN = invalid; `periodic`: the map repeats,
    /// which only [`ContainerDetrend::Median`]'s surface depends on). Refused without a valid
    /// point, and for [`ContainerDetrend::Slope`] with an invalid one (its finite differences
    /// need every height).
    pub fn apply(self, heights: &mut Array2<f64>, periodic: bool) -> Result<()> {
        let valid: Vec<f64> = heights.iter().copied().filter(|h| h.is_finite()).collect();
        if valid.is_empty() {
            return Err(Error::InvalidArgument(
                "the height map has no valid point to detrend".into(),
            ));
        }
        match self {
            ContainerDetrend::Mean => {
                let mean = valid.iter().sum::<f64>() / valid.len() as f64;
                heights.mapv_inplace(|h| h - mean);
            }
            ContainerDetrend::Plane => subtract_least_squares(heights, 1)?,
            ContainerDetrend::Quadric => subtract_least_squares(heights, 2)?,
            ContainerDetrend::Slope => subtract_mean_slope(heights)?,
            ContainerDetrend::Median => {
                let median = super::bearing::median_height(heights, periodic).ok_or_else(|| {
                    Error::InvalidArgument(
                        "detrend mode 'median' needs two neighbouring valid heights".into(),
                    )
                })?;
                heights.mapv_inplace(|h| h - median);
            }
        }
        Ok(())
    }
}

/// Centred, size-scaled coordinates of a pixel: (x, y) in about [−½, ½].
fn coordinates(shape: (usize, usize), (row, col): (usize, usize)) -> (f64, f64) {
    let (ny, nx) = shape;
    let x = (col as f64 - (nx as f64 - 1.0) / 2.0) / nx as f64;
    let y = (row as f64 - (ny as f64 - 1.0) / 2.0) / ny as f64;
    (x, y)
}

/// The polynomial terms of `degree` (1: plane, 2: quadric) that the map's shape can carry: a
/// term along an axis with too few points to fit it is left out (a single row has no y term).
fn terms(shape: (usize, usize), degree: usize) -> Vec<fn(f64, f64) -> f64> {
    let (ny, nx) = shape;
    let mut t: Vec<fn(f64, f64) -> f64> = vec![|_, _| 1.0];
    if nx > 1 {
        t.push(|x, _| x);
    }
    if ny > 1 {
        t.push(|_, y| y);
    }
    if degree >= 2 {
        if nx > 2 {
            t.push(|x, _| x * x);
        }
        if ny > 2 {
            t.push(|_, y| y * y);
        }
        if nx > 1 && ny > 1 {
            t.push(|x, y| x * y);
        }
    }
    t
}

/// Subtract the least-squares polynomial of `degree` over the valid points (normal equations
/// in centred coordinates, solved by a Cholesky factorisation, else an SVD).
fn subtract_least_squares(heights: &mut Array2<f64>, degree: usize) -> Result<()> {
    let shape = heights.dim();
    let basis = terms(shape, degree);
    let k = basis.len();
    let mut normal = DMatrix::<f64>::zeros(k, k);
    let mut rhs = DVector::<f64>::zeros(k);
    let mut row = vec![0.0; k];
    for (at, &h) in heights.indexed_iter() {
        if !h.is_finite() {
            continue;
        }
        let (x, y) = coordinates(shape, at);
        for (r, f) in row.iter_mut().zip(&basis) {
            *r = f(x, y);
        }
        for a in 0..k {
            rhs[a] += row[a] * h;
            for b in 0..k {
                normal[(a, b)] += row[a] * row[b];
            }
        }
    }
    let coefficients = match normal.clone().cholesky() {
        Some(c) => c.solve(&rhs),
        None => normal
            .svd(true, true)
            .solve(&rhs, 1e-12)
            .map_err(|e| Error::InvalidArgument(format!("the trend fit failed: {e}")))?,
    };
    for (at, h) in heights.indexed_iter_mut() {
        if h.is_finite() {
            let (x, y) = coordinates(shape, at);
            let trend: f64 = basis
                .iter()
                .zip(coefficients.iter())
                .map(|(f, c)| c * f(x, y))
                .sum();
            *h -= trend;
        }
    }
    Ok(())
}

/// Subtract the plane with the mean forward-difference slope along each axis (per pixel), then
/// the mean, as SurfaceTopography's `slope` mode does.
fn subtract_mean_slope(heights: &mut Array2<f64>) -> Result<()> {
    if heights.iter().any(|h| !h.is_finite()) {
        return Err(Error::InvalidArgument(
            "detrend mode 'slope' needs every height (fill the invalid points first)".into(),
        ));
    }
    let (ny, nx) = heights.dim();
    // The mean of the forward differences along a line telescopes to (last − first)/(n − 1);
    // the lines averaged are those of the shared (nx − 1) × (ny − 1) grid (module docs).
    let rows = if ny > 1 { ny - 1 } else { ny };
    let columns = if nx > 1 { nx - 1 } else { nx };
    let per_pixel_x = if nx > 1 {
        (0..rows)
            .map(|i| heights[[i, nx - 1]] - heights[[i, 0]])
            .sum::<f64>()
            / (rows * (nx - 1)) as f64
    } else {
        0.0
    };
    let per_pixel_y = if ny > 1 {
        (0..columns)
            .map(|j| heights[[ny - 1, j]] - heights[[0, j]])
            .sum::<f64>()
            / (columns * (ny - 1)) as f64
    } else {
        0.0
    };
    for ((i, j), h) in heights.indexed_iter_mut() {
        *h -= per_pixel_x * j as f64 + per_pixel_y * i as f64;
    }
    let mean = heights.iter().sum::<f64>() / heights.len() as f64;
    heights.mapv_inplace(|h| h - mean);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quadric(ny: usize, nx: usize) -> Array2<f64> {
        Array2::from_shape_fn((ny, nx), |(i, j)| {
            let (x, y) = (j as f64 * 0.1, i as f64 * 0.2);
            3.0 + 0.5 * x - 0.25 * y + 0.125 * x * x - 0.0625 * y * y + 0.03 * x * y
        })
    }

    fn worst(h: &Array2<f64>) -> f64 {
        h.iter()
            .filter(|v| v.is_finite())
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn modes_by_name() {
        assert_eq!(
            ContainerDetrend::from_mode("center").unwrap(),
            ContainerDetrend::Mean
        );
        assert_eq!(
            ContainerDetrend::from_mode("rms-curvature").unwrap(),
            ContainerDetrend::Quadric
        );
        let err = ContainerDetrend::from_mode("mad-tilt")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("mad-tilt") && err.contains("'height'"),
            "{err}"
        );
        let err = ContainerDetrend::from_mode("mad-curvature")
            .unwrap_err()
            .to_string();
        assert!(err.contains("'curvature'"), "{err}");
    }

    #[test]
    fn a_quadric_is_removed_exactly_and_a_plane_leaves_the_curvature() {
        let mut h = quadric(9, 13);
        h[[3, 4]] = f64::NAN;
        let mut q = h.clone();
        ContainerDetrend::Quadric.apply(&mut q, false).unwrap();
        assert!(worst(&q) < 1e-12, "{}", worst(&q));
        assert!(q[[3, 4]].is_nan());
        let mut p = h.clone();
        ContainerDetrend::Plane.apply(&mut p, false).unwrap();
        assert!(worst(&p) > 1e-3, "a plane cannot remove x², y², xy");
        // The residual of a plane fit is orthogonal to 1, x and y: zero mean over valid points.
        let valid: Vec<f64> = p.iter().copied().filter(|v| v.is_finite()).collect();
        assert!(valid.iter().sum::<f64>().abs() / (valid.len() as f64) < 1e-12);
    }

    #[test]
    fn slope_uses_the_shared_difference_grid() {
        let mut h = Array2::from_shape_fn((4, 5), |(i, j)| 1.0 + 2.0 * j as f64 - 0.5 * i as f64);
        ContainerDetrend::Slope.apply(&mut h, false).unwrap();
        assert!(worst(&h) < 1e-12, "{}", worst(&h));
        // Only the last row differs from a plane: the x slope ignores it, the y slope does not.
        let mut h =
            Array2::from_shape_fn((3, 3), |(i, j)| j as f64 + if i == 2 { 6.0 } else { 0.0 });
        ContainerDetrend::Slope.apply(&mut h, false).unwrap();
        // x slope 1 per pixel (rows 0, 1), y slope (6 + 0)/2 = 3 per pixel (columns 0, 1).
        assert!((h[(0, 1)] - h[(0, 0)]).abs() < 1e-12);
        assert!(((h[(1, 0)] - h[(0, 0)]) + 3.0).abs() < 1e-12, "{h:?}");
        assert_eq!(
            ContainerDetrend::from_mode("median").unwrap(),
            ContainerDetrend::Median
        );
        let mut bad = quadric(3, 3);
        bad[[1, 1]] = f64::NAN;
        assert!(ContainerDetrend::Slope.apply(&mut bad, false).is_err());
        let mut empty = Array2::from_elem((2, 2), f64::NAN);
        assert!(ContainerDetrend::Mean.apply(&mut empty, false).is_err());
    }

    #[test]
    fn single_row_and_column_maps() {
        for shape in [(1, 6), (6, 1), (2, 2)] {
            let mut h = Array2::from_shape_fn(shape, |(i, j)| 2.0 + i as f64 + 3.0 * j as f64);
            ContainerDetrend::Plane.apply(&mut h, false).unwrap();
            assert!(worst(&h) < 1e-12, "{shape:?}: {}", worst(&h));
            let mut h = Array2::from_shape_fn(shape, |(i, j)| 2.0 + i as f64 + 3.0 * j as f64);
            ContainerDetrend::Quadric.apply(&mut h, false).unwrap();
            assert!(worst(&h) < 1e-12, "{shape:?}: {}", worst(&h));
        }
    }
}
