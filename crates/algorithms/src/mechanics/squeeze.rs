//! Squeeze test of a single sphere between two parallel plates: the contact modulus E* from
//! Hertz theory (Weber et al. 2018, Methods, "Mechanical testing", Eq. 2; K. L. Johnson,
//! *Contact Mechanics*, 1985, eq. 4.23).
//!
//! The plates approach by 2δ because two sphere-on-flat contacts act in series, each with
//! approach δ = (9P² / (16 R E*²))^(1/3), i.e. P = (4/3)·E*·R^(1/2)·δ^(3/2). The paper prints
//! Eq. 2 with E* instead of E*² under the cube root, which is not dimensionally consistent; the
//! form used here is Johnson's (see `docs/mechanics.md`).
//!
//! # Input CSV (`contactscope_jobs::mechanics_csv::read_squeeze`)
//! `force_mN` (or `force_N`) and `displacement_um`, the total plate displacement 2δ measured
//! from first contact, one row per sample of the loading curve. Rows with P ≤ 0 (before contact)
//! are ignored; among the rest, force must not decrease and displacement must increase from row
//! to row (an unloading branch is refused, naming the row).
//!
//! # Fit
//! Least squares of P on x = δ^(3/2) **through the origin** (the contact point is taken as
//! known): s = Σ P·x / Σ x², E* = 3s / (4√R), se(E*) from sqrt(SS_res/(n−1)/Σx²). Unweighted, so
//! the high loads dominate. A second fit with a free contact offset δ₀,
//! P = (4/3)E*√R (δ − δ₀)^(3/2), minimises the same residual over δ₀ and is reported separately.

use crate::error::{Error, Result};
use crate::numerics::golden::golden_section;

/// Fewest loaded points (P > 0) a fit needs.
pub const MIN_POINTS: usize = 3;

/// One loaded sample of a squeeze curve, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SqueezePoint {
    /// Force P, N.
    pub force_n: f64,
    /// Total plate displacement 2δ, m.
    pub displacement_m: f64,
    /// Line in the CSV (header = 1), for messages; 0 when not from a file.
    pub line: u64,
}

impl SqueezePoint {
    /// Approach of one contact, δ = displacement / 2, m.
    pub fn delta_m(&self) -> f64 {
        0.5 * self.displacement_m
    }
}

/// Enough points, positive displacements, loading order; the reason as text otherwise.
pub fn check_points(points: &[SqueezePoint]) -> std::result::Result<(), String> {
    if points.len() < MIN_POINTS {
        return Err(format!(
            "{} points with positive force; the Hertz fit needs at least {MIN_POINTS}",
            points.len()
        ));
    }
    let row = |p: &SqueezePoint| {
        if p.line > 0 {
            format!("line {}", p.line)
        } else {
            "a point".into()
        }
    };
    if let Some(p) = points.iter().find(|p| p.displacement_m <= 0.0) {
        return Err(format!(
            "{}: force {:.6} mN at displacement {:.6} µm; displacement is measured from first contact and must be positive under load",
            row(p),
            p.force_n * 1e3,
            p.displacement_m * 1e6
        ));
    }
    for w in points.windows(2) {
        if w[1].displacement_m <= w[0].displacement_m || w[1].force_n < w[0].force_n {
            return Err(format!(
                "{}: not monotonic (force {:.6} → {:.6} mN, displacement {:.6} → {:.6} µm); displacement must increase with force on loading — give the loading branch only",
                row(&w[1]),
                w[0].force_n * 1e3,
                w[1].force_n * 1e3,
                w[0].displacement_m * 1e6,
                w[1].displacement_m * 1e6
            ));
        }
    }
    Ok(())
}

/// Result of a Hertz fit.
#[derive(Debug, Clone, PartialEq)]
pub struct HertzFit {
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// Its standard error, Pa.
    pub e_star_se_pa: f64,
    /// 1 − SS_res / Σ(P − P̄)² (about the mean).
    pub r_squared: f64,
    /// Contact offset δ₀ per contact, m (0 for the fit through the origin).
    pub offset_m: f64,
    /// Fitted force per point, N.
    pub fitted_n: Vec<f64>,
}

impl HertzFit {
    /// Residuals P − P_fit, N.
    pub fn residuals(&self, points: &[SqueezePoint]) -> Vec<f64> {
        points
            .iter()
            .zip(&self.fitted_n)
            .map(|(p, f)| p.force_n - f)
            .collect()
    }
}

/// Fit E* through the origin (δ measured from first contact). Errors: fewer than
/// [`MIN_POINTS`] points, a non-positive radius, or unordered points.
pub fn fit_hertz(points: &[SqueezePoint], radius_m: f64) -> Result<HertzFit> {
    check_radius(radius_m)?;
    check_points(points).map_err(Error::InvalidArgument)?;
    fit_with_offset(points, radius_m, 0.0, 1).ok_or_else(no_fit)
}

/// Fit E* and a contact offset δ₀ (per contact) by minimising the residual over δ₀ ∈
/// [−δ_max, δ_min): a grid search, then golden-section refinement. Needs four points.
pub fn fit_hertz_with_offset(points: &[SqueezePoint], radius_m: f64) -> Result<HertzFit> {
    check_radius(radius_m)?;
    check_points(points).map_err(Error::InvalidArgument)?;
    if points.len() < MIN_POINTS + 1 {
        return Err(Error::TooFew {
            what: "the fit with a contact offset",
            needed: MIN_POINTS + 1,
            got: points.len(),
        });
    }
    let d_min = points[0].delta_m();
    let d_max = points[points.len() - 1].delta_m();
    // δ₀ must stay below the first loaded δ (all points in contact); the tiny margin keeps
    // (δ − δ₀)^(3/2) of the first point away from 0.
    let (lo, hi) = (-d_max, d_min * (1.0 - 1e-9));
    let cost = |d0: f64| {
        fit_with_offset(points, radius_m, d0, 2).map_or(f64::INFINITY, |f| ss_res(points, &f))
    };
    let best = minimise(cost, lo, hi);
    fit_with_offset(points, radius_m, best, 2).ok_or_else(no_fit)
}

fn no_fit() -> Error {
    Error::InvalidArgument(
        "the squeeze data give no finite Hertz fit (all δ^(3/2) are zero, or the numbers overflow)"
            .into(),
    )
}

/// The sphere radius of a squeeze test must be positive and finite.
pub fn check_radius(radius_m: f64) -> Result<()> {
    if radius_m.is_finite() && radius_m > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "sphere radius {radius_m:e} m must be positive"
        )))
    }
}

/// Linear least squares of P on (δ − δ₀)^(3/2) through the origin for a fixed δ₀.
fn fit_with_offset(
    points: &[SqueezePoint],
    radius_m: f64,
    d0: f64,
    parameters: usize,
) -> Option<HertzFit> {
    let x: Vec<f64> = points
        .iter()
        .map(|p| (p.delta_m() - d0).max(0.0).powf(1.5))
        .collect();
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    if sxx <= 0.0 || !sxx.is_finite() {
        return None;
    }
    let slope = x
        .iter()
        .zip(points)
        .map(|(a, p)| a * p.force_n)
        .sum::<f64>()
        / sxx;
    let fitted_n: Vec<f64> = x.iter().map(|a| slope * a).collect();
    let n = points.len();
    let res: f64 = points
        .iter()
        .zip(&fitted_n)
        .map(|(p, f)| (p.force_n - f).powi(2))
        .sum();
    let mean = points.iter().map(|p| p.force_n).sum::<f64>() / n as f64;
    let tot: f64 = points.iter().map(|p| (p.force_n - mean).powi(2)).sum();
    // Degrees of freedom: one parameter through the origin, two with the offset.
    let dof = n.saturating_sub(parameters).max(1);
    let slope_se = (res / dof as f64 / sxx).sqrt();
    // P = (4/3)E*√R·δ^{3/2}: E* = 3s/(4√R).
    let scale = 3.0 / (4.0 * radius_m.sqrt());
    let fit = HertzFit {
        e_star_pa: scale * slope,
        e_star_se_pa: scale * slope_se,
        r_squared: if tot > 0.0 { 1.0 - res / tot } else { 1.0 },
        offset_m: d0,
        fitted_n,
    };
    // A fit that overflowed (absurd forces or vanishing displacements) is no fit.
    let finite = [fit.e_star_pa, fit.e_star_se_pa, fit.r_squared]
        .iter()
        .chain(&fit.fitted_n)
        .all(|v| v.is_finite());
    finite.then_some(fit)
}

fn ss_res(points: &[SqueezePoint], fit: &HertzFit) -> f64 {
    fit.residuals(points).iter().map(|r| r * r).sum()
}

/// Minimum of `f` on [lo, hi]: the best of 200 grid points, then golden section in its bracket
/// down to 1e-12 of the range (below the rounding of δ for any loaded squeeze curve).
fn minimise(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    const GRID: usize = 200;
    let at = |i: usize| lo + (hi - lo) * i as f64 / GRID as f64;
    let best = (0..=GRID)
        .min_by(|&a, &b| f(at(a)).total_cmp(&f(at(b))))
        .unwrap_or(0);
    let (a, b) = (at(best.saturating_sub(1)), at((best + 1).min(GRID)));
    let width = 1e-12 * (hi - lo);
    let found = golden_section(a, b, width, &mut |x| {
        Ok::<f64, std::convert::Infallible>(f(x))
    });
    match found {
        Ok(m) => m.x,
        Err(never) => match never {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::hertz;

    fn exact(e_star: f64, r: f64, d0: f64) -> Vec<SqueezePoint> {
        (1..=8)
            .map(|i| {
                let p = 5e-3 * i as f64;
                SqueezePoint {
                    force_n: p,
                    displacement_m: 2.0 * (hertz::approach(p, r, e_star) + d0),
                    line: 0,
                }
            })
            .collect()
    }

    #[test]
    fn exact_data_give_exact_modulus() {
        let pts = exact(3.7e9, 290e-6, 0.0);
        let fit = fit_hertz(&pts, 290e-6).unwrap();
        assert!((fit.e_star_pa / 3.7e9 - 1.0).abs() < 1e-9);
        assert!((fit.r_squared - 1.0).abs() < 1e-12);
    }

    #[test]
    fn offset_fit_finds_a_shifted_contact_point() {
        let pts = exact(3.7e9, 290e-6, 0.05e-6);
        let through_origin = fit_hertz(&pts, 290e-6).unwrap();
        let free = fit_hertz_with_offset(&pts, 290e-6).unwrap();
        assert!(
            (free.offset_m / 0.05e-6 - 1.0).abs() < 1e-4,
            "{}",
            free.offset_m
        );
        assert!((free.e_star_pa / 3.7e9 - 1.0).abs() < 1e-4);
        assert!((through_origin.e_star_pa / 3.7e9 - 1.0).abs() > 0.01);
    }

    #[test]
    fn refuses_bad_radius_and_unloading() {
        let pts = exact(3.7e9, 290e-6, 0.0);
        assert!(fit_hertz(&pts, 0.0).is_err());
        assert!(fit_hertz(&pts, -1.0).is_err());
        let mut back = pts.clone();
        back[5].displacement_m = back[3].displacement_m;
        assert!(fit_hertz(&back, 290e-6).is_err());
        assert!(fit_hertz(&pts[..2], 290e-6).is_err());
    }
}
