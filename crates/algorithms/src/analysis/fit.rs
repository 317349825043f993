//! Area–load fits (Weber et al. 2018, Fig. 3a): a power law A = c·N^β by least squares in
//! log–log space, and a proportional law A = N/p (constant mean pressure p) by least squares in A.

use serde::Serialize;

/// A = c·N^β fitted to ln A = ln c + β ln N.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerLawFit {
    /// Prefactor c, in the area unit per (force unit)^β of the data given.
    pub prefactor: f64,
    /// Exponent β.
    pub exponent: f64,
    /// Standard error of β (needs at least 3 points; `None` otherwise).
    pub exponent_se: Option<f64>,
    /// Coefficient of determination of the log–log regression; `None` with fewer than three
    /// distinct forces (a line through two force levels passes through their means, so R² then
    /// measures only the scatter of replicates, and two points always give 1) or when every area
    /// is the same (no variance to explain).
    pub r_squared: Option<f64>,
    /// Points used (positive force and area).
    pub points: usize,
    /// Distinct forces among them (repeated loads are replicates, not new points of the law).
    pub distinct_forces: usize,
}

impl PowerLawFit {
    /// The fitted area at force `n`.
    pub fn eval(&self, n: f64) -> f64 {
        self.prefactor * n.powf(self.exponent)
    }
}

/// Ordinary least squares of ln y on ln x over the points where both are positive and finite.
/// `None` with fewer than two such points or no spread in x.
pub fn fit_power_law(x: &[f64], y: &[f64]) -> Option<PowerLawFit> {
    let pts: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .filter(|(a, b)| a.is_finite() && b.is_finite() && **a > 0.0 && **b > 0.0)
        .map(|(a, b)| (a.ln(), b.ln()))
        .collect();
    let n = pts.len();
    if n < 2 {
        return None;
    }
    let mean_x = pts.iter().map(|p| p.0).sum::<f64>() / n as f64;
    let mean_y = pts.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    let syy: f64 = pts.iter().map(|p| (p.1 - mean_y).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let beta = sxy / sxx;
    let intercept = mean_y - beta * mean_x;
    let ss_res: f64 = pts
        .iter()
        .map(|p| (p.1 - intercept - beta * p.0).powi(2))
        .sum();
    let mut xs: Vec<f64> = pts.iter().map(|p| p.0).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let r_squared = (xs.len() > 2 && syy > 0.0).then(|| 1.0 - ss_res / syy);
    let exponent_se = (n > 2).then(|| (ss_res / (n - 2) as f64 / sxx).sqrt());
    Some(PowerLawFit {
        prefactor: intercept.exp(),
        exponent: beta,
        exponent_se,
        r_squared,
        points: n,
        distinct_forces: xs.len(),
    })
}

/// y = s·x through the origin, least squares in y: s = Σxy / Σx². Points with non-finite values
/// are skipped; `None` if no point has x ≠ 0.
pub fn fit_proportional(x: &[f64], y: &[f64]) -> Option<(f64, usize)> {
    let (mut sxy, mut sxx, mut n) = (0.0, 0.0, 0);
    for (a, b) in x.iter().zip(y) {
        if a.is_finite() && b.is_finite() {
            sxy += a * b;
            sxx += a * a;
            n += 1;
        }
    }
    (sxx > 0.0).then_some((sxy / sxx, n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::hertz::contact_radius;

    #[test]
    fn hertz_areas_give_two_thirds() {
        // docs/validation.md B19: Hertz A(N) at N = 1…100 (log-spaced) gives β = 2/3 to 1e-12.
        let forces: Vec<f64> = (0..12).map(|i| 10f64.powf(2.0 * i as f64 / 11.0)).collect();
        let areas: Vec<f64> = forces
            .iter()
            .map(|n| std::f64::consts::PI * contact_radius(n * 1e-3, 290e-6, 3.7e9).powi(2))
            .collect();
        let fit = fit_power_law(&forces, &areas).unwrap();
        assert!((fit.exponent - 2.0 / 3.0).abs() < 1e-12);
        assert!(fit.exponent_se.unwrap() < 1e-12);
        assert!((fit.r_squared.unwrap() - 1.0).abs() < 1e-12);
        assert_eq!(fit.distinct_forces, 12);
        assert!((fit.eval(50.0) / areas[0] - (50.0f64).powf(2.0 / 3.0)).abs() < 1e-9);
    }

    #[test]
    fn noisy_power_law_has_a_standard_error() {
        let x = [1.0, 2.0, 4.0, 8.0, 16.0];
        let y: Vec<f64> = x
            .iter()
            .zip([1.05, 0.95, 1.02, 0.98, 1.01])
            .map(|(n, e): (&f64, f64)| 3.0 * n.powf(0.8) * e)
            .collect();
        let fit = fit_power_law(&x, &y).unwrap();
        assert!((fit.exponent - 0.8).abs() < 0.03);
        let se = fit.exponent_se.unwrap();
        assert!(se > 1e-4 && se < 0.05, "se = {se}");
        let r2 = fit.r_squared.unwrap();
        assert!(r2 > 0.99 && r2 < 1.0);
    }

    #[test]
    fn two_forces_or_constant_areas_have_no_r_squared() {
        let two = fit_power_law(&[1.0, 2.0], &[1.0, 3.0]).unwrap();
        assert_eq!(
            (two.r_squared, two.exponent_se, two.points),
            (None, None, 2)
        );
        let flat = fit_power_law(&[1.0, 2.0, 4.0], &[5.0, 5.0, 5.0]).unwrap();
        assert_eq!((flat.exponent, flat.r_squared), (0.0, None));
        let repeated = fit_power_law(&[1.0, 1.0, 2.0, 2.0], &[1.0, 1.1, 2.0, 2.1]).unwrap();
        assert_eq!((repeated.points, repeated.distinct_forces), (4, 2));
        // Replicates give β a standard error, but two force levels cannot test the law: no R².
        assert!(repeated.exponent_se.is_some() && repeated.r_squared.is_none());
    }

    #[test]
    fn degenerate_inputs_give_no_fit() {
        assert!(fit_power_law(&[1.0], &[2.0]).is_none());
        assert!(fit_power_law(&[2.0, 2.0], &[1.0, 3.0]).is_none());
        assert!(fit_power_law(&[0.0, -1.0], &[1.0, 3.0]).is_none());
        assert!(fit_proportional(&[0.0], &[1.0]).is_none());
    }

    #[test]
    fn proportional_fit_recovers_slope() {
        let (s, n) = fit_proportional(&[1.0, 2.0, 3.0], &[2.0, 4.0, 6.0]).unwrap();
        assert_eq!(n, 3);
        assert!((s - 2.0).abs() < 1e-15);
    }
}
