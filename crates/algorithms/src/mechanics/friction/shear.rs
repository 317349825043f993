//! The interfacial shear strength τ of F = τ·A and how μ = F/N changes with the normal force.

use super::slip::min_max;
use crate::analysis::fit::fit_power_law;

/// F = τ·A fitted through the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearFit {
    /// Interfacial shear strength τ = Σ F·A / Σ A², Pa.
    pub tau_pa: f64,
    /// Standard error sqrt(SS_res / (n − 1) / Σ A²), Pa; `None` for one point.
    pub tau_se_pa: Option<f64>,
    /// 1 − SS_res / Σ(F − F̄)², about the mean (negative when a line through the origin fits
    /// worse than a constant); `None` if all F are equal.
    pub r_squared: Option<f64>,
    /// Points used.
    pub points: usize,
}

/// Least squares in F of F = τ·A through the origin (Weber et al. 2018, Fig. 3b), areas in m²,
/// forces in N. `None` without a positive area.
pub fn fit_shear_strength(areas_m2: &[f64], forces_n: &[f64]) -> Option<ShearFit> {
    let pts: Vec<(f64, f64)> = areas_m2
        .iter()
        .zip(forces_n)
        .filter(|(a, f)| a.is_finite() && f.is_finite())
        .map(|(a, f)| (*a, *f))
        .collect();
    let saa: f64 = pts.iter().map(|p| p.0 * p.0).sum();
    if saa <= 0.0 || !saa.is_finite() {
        return None;
    }
    let tau = pts.iter().map(|p| p.0 * p.1).sum::<f64>() / saa;
    let n = pts.len();
    let ss_res: f64 = pts.iter().map(|p| (p.1 - tau * p.0).powi(2)).sum();
    let mean_f = pts.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let ss_tot: f64 = pts.iter().map(|p| (p.1 - mean_f).powi(2)).sum();
    Some(ShearFit {
        tau_pa: tau,
        tau_se_pa: (n > 1).then(|| (ss_res / (n - 1) as f64 / saa).sqrt()),
        r_squared: (ss_tot > 0.0).then(|| 1.0 - ss_res / ss_tot),
        points: n,
    })
}

/// How μ = F/N changes with N: the exponent of μ ∝ N^m (log–log least squares; Amontons' law is
/// m = 0, F ∝ A ∝ N^β gives m = β − 1) and the relative spread (max − min)/mean.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuTrend {
    /// Fitted exponent m.
    pub exponent: f64,
    /// Its standard error (three or more distinct loads).
    pub exponent_se: Option<f64>,
    /// (max μ − min μ) / mean μ.
    pub relative_spread: f64,
    /// `Some(true)` when |m| > 2·se: μ depends on N beyond the scatter; `None` without an se.
    pub varies: Option<bool>,
}

/// μ's dependence on the normal force; `None` with fewer than two distinct positive loads.
pub fn mu_trend(normal_n: &[f64], mu: &[f64]) -> Option<MuTrend> {
    let fit = fit_power_law(normal_n, mu)?;
    let (lo, hi) = min_max(mu);
    let mean = mu.iter().sum::<f64>() / mu.len() as f64;
    Some(MuTrend {
        exponent: fit.exponent,
        exponent_se: fit.exponent_se,
        relative_spread: (hi - lo) / mean,
        varies: fit.exponent_se.map(|se| fit.exponent.abs() > 2.0 * se),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shear_fit_through_origin() {
        let a = [1e-10, 2e-10, 4e-10];
        let f: Vec<f64> = a.iter().map(|x| 5e7 * x).collect();
        let fit = fit_shear_strength(&a, &f).unwrap();
        assert!((fit.tau_pa / 5e7 - 1.0).abs() < 1e-12);
        assert!(fit.tau_se_pa.unwrap() < 1e-3);
        assert!((fit.r_squared.unwrap() - 1.0).abs() < 1e-12);
        assert!(fit_shear_strength(&[0.0], &[1.0]).is_none());
    }

    #[test]
    fn mu_trend_of_amontons_and_of_a_power_law() {
        let n = [4.0, 10.0, 20.0, 40.0];
        let constant = mu_trend(&n, &[0.3, 0.3, 0.3, 0.3]).unwrap();
        assert!(constant.exponent.abs() < 1e-12 && constant.relative_spread < 1e-12);
        let mu: Vec<f64> = n.iter().map(|x: &f64| 0.5 * x.powf(-0.2)).collect();
        let falling = mu_trend(&n, &mu).unwrap();
        assert!((falling.exponent + 0.2).abs() < 1e-12);
    }
}
