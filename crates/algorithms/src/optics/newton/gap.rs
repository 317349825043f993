//! The two formulas behind the Newton-ring analysis and the fit that joins them:
//! ring gaps d_m (Weber et al. 2018, Eq. 1) and the Hertz exterior gap g(r; a, R)
//! (K. L. Johnson, *Contact Mechanics*, 1985, §4.2; `docs/methods.md` §6.1). SI units.

use std::f64::consts::PI;

use serde::Serialize;

/// Which interface carries the π phase flip, i.e. where the reflection maxima lie.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// One π flip (n_glass > n_medium < n_sphere: PS, PMMA, glass in formamide): maxima at
    /// d_m = (m + ½)·λ/(2n), the paper's Eq. 1; the contact itself is dark.
    Half,
    /// No net flip (n_sphere < n_medium, e.g. PTFE in formamide): maxima at d_m = m·λ/(2n); the
    /// m = 0 maximum is the contact itself, so the first ring outside it is m = 1.
    Zero,
}

impl Phase {
    /// Name used on the command line and in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Half => "half",
            Phase::Zero => "zero",
        }
    }

    /// Order of the innermost ring outside the contact: 0 for [`Phase::Half`] (the paper's rule:
    /// no reflected light inside the smallest ring, so it is m = 0), 1 for [`Phase::Zero`],
    /// whose m = 0 maximum (d = 0) is the bright contact rather than a ring.
    pub fn first_order(self) -> u32 {
        match self {
            Phase::Half => 0,
            Phase::Zero => 1,
        }
    }
}

/// Gap (m) at the intensity maximum of order `m`: (m + ½)·λ/(2n) for [`Phase::Half`]
/// (Weber et al. 2018, Eq. 1), m·λ/(2n) for [`Phase::Zero`]. Illumination at normal incidence;
/// a high-NA cone stretches the spacing by 1/cos θ, which this ignores, as the paper does.
pub fn ring_gap(m: u32, wavelength_m: f64, medium_index: f64, phase: Phase) -> f64 {
    let half = match phase {
        Phase::Half => 0.5,
        Phase::Zero => 0.0,
    };
    (f64::from(m) + half) * wavelength_m / (2.0 * medium_index)
}

/// Hertz gap times the sphere radius: G(r; a) = R·g(r; a, R), which does not depend on R.
/// Splitting off 1/R makes g linear in 1/R, which the fit uses.
fn gap_times_radius(r: f64, a: f64) -> f64 {
    if r <= a {
        return 0.0;
    }
    let root = (r * r - a * a).sqrt();
    // acos(a/r) written as atan(√(r²−a²)/a): the same angle, accurate for r close to a.
    let angle = root.atan2(a);
    ((a * root + (r * r - 2.0 * a * a) * angle) / PI).max(0.0)
}

/// Gap between a sphere of radius R and a flat outside a Hertz contact of radius a:
/// g(r) = [a·√(r² − a²) + (r² − 2a²)·arccos(a/r)]/(πR) for r ≥ a, 0 inside
/// (Johnson 1985, §4.2). For a = 0 it is the parabola r²/(2R).
pub fn hertz_gap(r: f64, a: f64, radius: f64) -> f64 {
    gap_times_radius(r, a) / radius
}

/// Hertz exterior gap fitted to ring points (r_i, d_i).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GapFit {
    /// Contact radius a, m.
    pub contact_radius_m: f64,
    /// Sphere radius R, m.
    pub sphere_radius_m: f64,
    /// Root-mean-square residual of the gaps, m.
    pub rms_residual_m: f64,
}

impl GapFit {
    /// Fitted gap at radius `r_m`.
    pub fn gap_at(&self, r_m: f64) -> f64 {
        hertz_gap(r_m, self.contact_radius_m, self.sphere_radius_m)
    }
}

/// Grid of trial contact radii before the golden-section refinement: fine enough that the
/// residual has one minimum between neighbours for ring data (it is smooth in a).
const A_GRID: usize = 400;

/// Least-squares fit of the Hertz exterior gap with free a and R to points (r_i, d_i), under
/// 0 ≤ a ≤ `a_max` (the fluorescent edge: the Hertz contact cannot extend beyond it).
///
/// g is linear in 1/R, so for each a the best 1/R is Σ G·d / Σ G² (variable projection); the
/// remaining one-dimensional residual in a is scanned on a grid and refined by golden section.
/// This needs no starting values and cannot diverge, unlike a general Levenberg–Marquardt fit.
/// `None` with fewer than 3 points (two parameters leave no residual with two) or when no a
/// gives a positive R.
pub fn fit_hertz_gap(points: &[(f64, f64)], a_max: f64) -> Option<GapFit> {
    if points.len() < 3 || a_max.is_nan() || a_max <= 0.0 {
        return None;
    }
    let r_min = points.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let upper = a_max.min(r_min);
    if !(upper > 0.0 && upper.is_finite()) {
        return None;
    }
    let cost = |a: f64| projected_cost(points, a).map_or(f64::INFINITY, |(_, s)| s);
    let step = upper / A_GRID as f64;
    let best = (0..=A_GRID)
        .map(|i| i as f64 * step)
        .min_by(|x, y| cost(*x).total_cmp(&cost(*y)))?;
    let a = golden_section(&cost, (best - step).max(0.0), (best + step).min(upper));
    let (inverse_radius, sum_sq) = projected_cost(points, a)?;
    Some(GapFit {
        contact_radius_m: a,
        sphere_radius_m: 1.0 / inverse_radius,
        rms_residual_m: (sum_sq / points.len() as f64).sqrt(),
    })
}

/// Best 1/R for a given a and the sum of squared residuals; `None` if 1/R would not be positive.
fn projected_cost(points: &[(f64, f64)], a: f64) -> Option<(f64, f64)> {
    let (gd, gg) = points.iter().fold((0.0, 0.0), |(gd, gg), &(r, d)| {
        let g = gap_times_radius(r, a);
        (gd + g * d, gg + g * g)
    });
    let k = gd / gg;
    if !(k > 0.0 && k.is_finite()) {
        return None;
    }
    let sum_sq = points
        .iter()
        .map(|&(r, d)| (d - k * gap_times_radius(r, a)).powi(2))
        .sum();
    Some((k, sum_sq))
}

/// Minimum of `f` on [lo, hi] by golden-section search (f unimodal there).
fn golden_section(f: &dyn Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = hi - ratio * (hi - lo);
    let mut x2 = lo + ratio * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..100 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - ratio * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + ratio * (hi - lo);
            f2 = f(x2);
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a / b - 1.0).abs()
    }

    /// docs/validation.md B13: λ = 488 nm, n = 1.447.
    #[test]
    fn b13_ring_gaps() {
        let expected = [84.31, 252.94, 421.56, 590.19, 758.81, 927.44];
        for (m, e) in expected.iter().enumerate() {
            let d = ring_gap(m as u32, 488e-9, 1.447, Phase::Half) * 1e9;
            assert!((d - e).abs() < 0.005 + 1e-9, "m = {m}: {d} vs {e}");
            let exact = (m as f64 + 0.5) * 488.0 / (2.0 * 1.447);
            assert!(rel(d, exact) < 1e-9);
        }
        let spacing =
            ring_gap(1, 488e-9, 1.447, Phase::Half) - ring_gap(0, 488e-9, 1.447, Phase::Half);
        assert!((spacing * 1e9 - 168.62).abs() < 0.005);
        assert!(rel(spacing * 1e9, 488.0 / 2.894) < 1e-9);
        assert_eq!(ring_gap(0, 488e-9, 1.447, Phase::Zero), 0.0);
        assert!(rel(ring_gap(3, 488e-9, 1.447, Phase::Zero), 3.0 * spacing) < 1e-9);
        assert_eq!(
            (Phase::Half.first_order(), Phase::Zero.first_order()),
            (0, 1)
        );
    }

    /// docs/validation.md B14: a = R = 1, g(10) = 49.042484; near the edge
    /// g / (a^½ (r − a)^{3/2} / R) → 8√2/(3π) = 1.20042.
    #[test]
    fn b14_hertz_exterior_gap() {
        // The printed value has 8 digits (half a unit in the last is 5e-7); the closed form
        // itself is checked to 1e-12.
        assert!((hertz_gap(10.0, 1.0, 1.0) - 49.042484).abs() < 5e-7);
        let exact_10 = (99f64.sqrt() + 98.0 * (0.1f64).acos()) / PI;
        assert!(rel(hertz_gap(10.0, 1.0, 1.0), exact_10) < 1e-12);
        let limit = 8.0 * 2f64.sqrt() / (3.0 * PI);
        assert!((limit - 1.20042).abs() < 5e-6);
        let ratio = |e: f64| hertz_gap(1.0 + e, 1.0, 1.0) / e.powf(1.5);
        // The ratio approaches the limit linearly in ε = (r − a)/a; two Richardson steps on
        // ε, ε/2, ε/4 remove the ε and ε² terms and leave 1e-9.
        for e in [1e-2, 1e-3, 1e-4] {
            assert!((ratio(e) - limit).abs() < e, "ε = {e}: {}", ratio(e));
        }
        let e = 1e-3;
        let (r1, r2, r4) = (ratio(e), ratio(e / 2.0), ratio(e / 4.0));
        let first = [2.0 * r2 - r1, 2.0 * r4 - r2];
        let second = (4.0 * first[1] - first[0]) / 3.0;
        assert!(rel(second, limit) < 1e-9, "{second} vs {limit}");
        assert_eq!(hertz_gap(0.5, 1.0, 1.0), 0.0);
        assert!(
            rel(hertz_gap(3.0, 0.0, 2.0), 9.0 / 4.0) < 1e-12,
            "a = 0: parabola"
        );
    }

    #[test]
    fn fit_recovers_a_and_r_from_exact_points() {
        let (a, r) = (12e-6, 290e-6);
        let points: Vec<(f64, f64)> = [14.9e-6, 17.3e-6, 19.6e-6, 22.0e-6]
            .iter()
            .map(|&x| (x, hertz_gap(x, a, r)))
            .collect();
        let fit = fit_hertz_gap(&points, 13e-6).unwrap();
        assert!(rel(fit.contact_radius_m, a) < 1e-6, "{fit:?}");
        assert!(rel(fit.sphere_radius_m, r) < 1e-6, "{fit:?}");
        assert!(fit.rms_residual_m < 1e-15);
        assert!(fit_hertz_gap(&points[..2], 13e-6).is_none());
        // The bound holds: with a_max below the true a the fit stops at the bound and misfits.
        let bounded = fit_hertz_gap(&points, 8e-6).unwrap();
        assert!(bounded.contact_radius_m <= 8e-6 && bounded.rms_residual_m > 1e-10);
    }
}
