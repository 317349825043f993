//! Roughness statistics: rms height, rms slope, rms curvature and the power spectral density.
//!
//! # Estimators (recorded in `docs/conventions.md`, "Roughness statistics")
//! Weber et al. (2018) use the asperity radius `β = 1/h''_rms` and `η·h_rms·β ≈ 0.05` without
//! defining the estimators (docs/methods.md §4.1, §5.4, §10 item 6). The choices made here:
//!
//! * `h_rms`: rms about the mean over every pixel ([`Topography::rms_height`]); detrend first
//!   where needed (the caller records which [`super::Detrend`]).
//! * `h'_rms = sqrt(⟨|∇h|²⟩)` with **central differences** on **interior points**
//!   (`(h[i][j+1] − h[i][j−1])/(2Δx)`, likewise in y; rows and columns `1..n−1`). Central rather
//!   than forward differences because both components then sit on the same point; for a
//!   spectrum that reaches the grid scale it underestimates more than forward differences do
//!   (docs/methods.md §5.4: 0.85 vs 0.95 of the spectral value at H = 0.8 with q_s at Nyquist).
//! * `h''_rms` = rms of the **full Laplacian** `∂²h/∂x² + ∂²h/∂y²` with the **5-point stencil**
//!   on interior points, as PyCo's `compute_rms_curvature` did in January 2018 (before the
//!   November 2019 change to half the Laplacian; docs/methods.md §4.1). The paper predates the change.
//!   For an isotropic Gaussian surface, rms(∇²h) = sqrt(8/3)·rms(∂²h/∂x²).
//! * Spectral estimators for periodic maps ([`SurfaceStats::spectral`]):
//!   `h'_rms² = (1/A₀) Σ_q q² C(q)`, `h''_rms² = (1/A₀) Σ_q q⁴ C(q)`, summed over the full
//!   discrete spectrum including the Nyquist bins with their `|q|` (Jacobs, Junge, Pastewka 2017,
//!   Surf. Topogr. Metrol. Prop. 5, 013001, Eqs. for the spectral moments). On a non-periodic
//!   map the jump at the boundary inflates them; use the finite-difference estimators there.
//!
//! # PSD normalisation (docs/methods.md §5.1)
//! `C(q) = |ĥ(q)|²/A₀` with `ĥ(q) = ΔA·DFT(h)` (unnormalised DFT, ΔA = ΔxΔy, A₀ = nx·ny·ΔA),
//! `q = 2π(mx/Lx, my/Ly)` in rad/m. Parseval: `h_rms² = (1/A₀) Σ_{q≠0} C(q)` over the full
//! spectrum, i.e. `(2π)⁻² ∫ d²q C(q)` in the continuum. Persson's (2006) C differs by (2π)²
//! but gives the same rms values.

use crate::error::{Error, Result};
use crate::spectral::RealFft2;

use super::Topography;

/// Roughness statistics of one map. Which estimator produced them is stated by the constructor
/// used ([`SurfaceStats::finite_differences`] or [`SurfaceStats::spectral`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceStats {
    /// rms height about the mean, metres.
    pub h_rms_m: f64,
    /// rms slope `sqrt(⟨|∇h|²⟩)`, dimensionless.
    pub h_prime_rms: f64,
    /// rms of the full Laplacian `∇²h`, 1/m (the paper's asperity radius is β = 1/h''_rms).
    pub h_double_prime_rms_per_m: f64,
}

impl SurfaceStats {
    /// The default estimators: rms height, central-difference slope and 5-point Laplacian on
    /// interior points (see the module docs). Needs at least 3 × 3 pixels.
    pub fn finite_differences(topography: &Topography) -> Result<Self> {
        Ok(SurfaceStats {
            h_rms_m: topography.rms_height(),
            h_prime_rms: rms_slope(topography)?,
            h_double_prime_rms_per_m: rms_laplacian(topography)?,
        })
    }

    /// Spectral estimators, exact for band-limited periodic maps (module docs). `h_rms_m` is the
    /// real-space value, which equals the spectral one by Parseval.
    pub fn spectral(topography: &Topography) -> Self {
        let m = spectral_moments(topography);
        SurfaceStats {
            h_rms_m: topography.rms_height(),
            h_prime_rms: m.slope2.sqrt(),
            h_double_prime_rms_per_m: m.laplacian2.sqrt(),
        }
    }
}

fn need_interior(topography: &Topography, what: &str) -> Result<()> {
    if topography.nx() < 3 || topography.ny() < 3 {
        return Err(Error::InvalidArgument(format!(
            "{what} by finite differences needs at least 3 × 3 pixels (map is {} × {})",
            topography.nx(),
            topography.ny()
        )));
    }
    Ok(())
}

/// Mean over interior points `(i, j) ∈ [1, ny−1) × [1, nx−1)` of `f(h, i, j)`.
fn interior_mean(
    topography: &Topography,
    f: impl Fn(&ndarray::Array2<f64>, usize, usize) -> f64,
) -> f64 {
    let h = &topography.heights;
    let (ny, nx) = (topography.ny(), topography.nx());
    let mut sum = 0.0;
    for i in 1..ny - 1 {
        let mut row = 0.0;
        for j in 1..nx - 1 {
            row += f(h, i, j);
        }
        sum += row;
    }
    sum / ((ny - 2) * (nx - 2)) as f64
}

/// rms slope `sqrt(⟨|∇h|²⟩)` by central differences on interior points (dimensionless).
pub fn rms_slope(topography: &Topography) -> Result<f64> {
    need_interior(topography, "the rms slope")?;
    let (a, b) = (0.5 / topography.dx_m, 0.5 / topography.dy_m);
    let mean = interior_mean(topography, |h, i, j| {
        let gx = (h[[i, j + 1]] - h[[i, j - 1]]) * a;
        let gy = (h[[i + 1, j]] - h[[i - 1, j]]) * b;
        gx * gx + gy * gy
    });
    Ok(mean.sqrt())
}

/// rms of the full Laplacian `∂²h/∂x² + ∂²h/∂y²` by the 5-point stencil on interior points,
/// in 1/m (PyCo 2018 definition; docs/methods.md §4.1).
pub fn rms_laplacian(topography: &Topography) -> Result<f64> {
    need_interior(topography, "the rms curvature")?;
    let a = 1.0 / (topography.dx_m * topography.dx_m);
    let b = 1.0 / (topography.dy_m * topography.dy_m);
    let mean = interior_mean(topography, |h, i, j| {
        let c = h[[i, j]];
        let l = (h[[i, j + 1]] - 2.0 * c + h[[i, j - 1]]) * a
            + (h[[i + 1, j]] - 2.0 * c + h[[i - 1, j]]) * b;
        l * l
    });
    Ok(mean.sqrt())
}

/// One element of the half spectrum with the number of full-spectrum bins it stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PsdSample {
    /// Wavevector x component, rad/m (`2π·mx/Lx`, `mx ≥ 0`).
    pub qx_per_m: f64,
    /// Wavevector y component, rad/m (`2π·my/Ly`, `my ∈ (−ny/2, ny/2]`).
    pub qy_per_m: f64,
    /// `C(q) = ΔA·|DFT(h)|²/(nx·ny)` in m⁴ (module docs).
    pub c_m4: f64,
    /// How many bins of the full spectrum this element represents: 2 for `mx` strictly between
    /// 0 and the Nyquist column, else 1 (Hermitian symmetry). `Σ weight·C` is the full sum.
    pub weight: f64,
}

impl PsdSample {
    /// `|q|` in rad/m.
    pub fn q_per_m(&self) -> f64 {
        self.qx_per_m.hypot(self.qy_per_m)
    }
}

/// The 2-D PSD on the half spectrum (q = 0 included, as the first element), normalised as in
/// the module docs, so that `(1/A₀)·Σ weight·C` over `q ≠ 0` equals `h_rms²` (Parseval).
pub fn psd(topography: &Topography) -> Vec<PsdSample> {
    let (nx, ny) = (topography.nx(), topography.ny());
    let fft = RealFft2::new(ny, nx);
    let mut input: Vec<f64> = topography.heights.iter().copied().collect();
    let mut spectrum = fft.make_spectrum();
    fft.forward(&mut input, &mut spectrum);
    let scale = topography.dx_m * topography.dy_m / fft.len() as f64;
    let (lx, ly) = topography.size_m();
    let tau = 2.0 * std::f64::consts::PI;
    spectrum
        .iter()
        .enumerate()
        .map(|(index, value)| {
            let (mx, my) = fft.wavenumbers(index);
            let self_conjugate = mx == 0 || (nx % 2 == 0 && mx as usize == nx / 2);
            PsdSample {
                qx_per_m: tau * mx as f64 / lx,
                qy_per_m: tau * my as f64 / ly,
                c_m4: scale * value.norm_sqr(),
                weight: if self_conjugate { 1.0 } else { 2.0 },
            }
        })
        .collect()
}

/// Mean-square slope and Laplacian from the spectrum.
struct Moments {
    slope2: f64,
    laplacian2: f64,
}

fn spectral_moments(topography: &Topography) -> Moments {
    let area = topography.area_m2();
    let (mut slope2, mut laplacian2) = (0.0, 0.0);
    for s in psd(topography) {
        let q2 = s.qx_per_m * s.qx_per_m + s.qy_per_m * s.qy_per_m;
        slope2 += s.weight * q2 * s.c_m4;
        laplacian2 += s.weight * q2 * q2 * s.c_m4;
    }
    Moments {
        slope2: slope2 / area,
        laplacian2: laplacian2 / area,
    }
}

/// rms slope from the spectrum, `sqrt((1/A₀) Σ q² C(q))` (periodic maps).
pub fn rms_slope_spectral(topography: &Topography) -> f64 {
    spectral_moments(topography).slope2.sqrt()
}

/// rms Laplacian from the spectrum, `sqrt((1/A₀) Σ q⁴ C(q))`, 1/m (periodic maps).
pub fn rms_laplacian_spectral(topography: &Topography) -> f64 {
    spectral_moments(topography).laplacian2.sqrt()
}

/// Radially averaged PSD: `bins` equal-width annuli over `0 < |q| ≤ q_max` (the largest `|q|`
/// on the grid, the corner of the spectrum), each giving `(mean |q|, mean C)` over the
/// full-spectrum bins it holds, in (rad/m, m⁴). Empty annuli are left out; q = 0 is excluded.
/// Same normalisation as [`psd`], so that for an isotropic surface
/// `h_rms² ≈ (1/2π) ∫ q C(q) dq` (docs/methods.md §5.1).
pub fn radial_psd(topography: &Topography, bins: usize) -> Result<Vec<(f64, f64)>> {
    if bins == 0 {
        return Err(Error::InvalidArgument(
            "the radial PSD needs at least one bin".into(),
        ));
    }
    let samples = psd(topography);
    let q_max = samples.iter().map(PsdSample::q_per_m).fold(0.0, f64::max);
    let mut sums = vec![(0.0, 0.0, 0.0); bins];
    for s in samples.iter().filter(|s| s.q_per_m() > 0.0) {
        let q = s.q_per_m();
        let bin = ((q / q_max * bins as f64) as usize).min(bins - 1);
        let acc = &mut sums[bin];
        acc.0 += s.weight * q;
        acc.1 += s.weight * s.c_m4;
        acc.2 += s.weight;
    }
    Ok(sums
        .into_iter()
        .filter(|acc| acc.2 > 0.0)
        .map(|(q, c, w)| (q / w, c / w))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;
    use rand::{Rng, SeedableRng};
    use std::f64::consts::PI;

    fn random(ny: usize, nx: usize, seed: u64) -> Topography {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let h = Array2::from_shape_fn((ny, nx), |_| rng.random_range(-1e-6..1e-6));
        Topography::new(h, 2e-8, 3e-8).unwrap()
    }

    #[test]
    fn parseval_on_the_full_spectrum() {
        for (ny, nx) in [(16, 16), (9, 12), (10, 7), (1, 8)] {
            let t = random(ny, nx, 3);
            let sum: f64 = psd(&t)
                .iter()
                .filter(|s| s.q_per_m() > 0.0)
                .map(|s| s.weight * s.c_m4)
                .sum();
            let h2 = t.rms_height().powi(2);
            let rel = (sum / t.area_m2() - h2).abs() / h2;
            assert!(rel < 1e-12, "{ny}×{nx}: {rel}");
        }
    }

    #[test]
    fn weights_count_the_full_spectrum() {
        for (ny, nx) in [(6, 8), (5, 7)] {
            let t = random(ny, nx, 1);
            let total: f64 = psd(&t).iter().map(|s| s.weight).sum();
            assert_eq!(total, (nx * ny) as f64);
        }
    }

    #[test]
    fn sinusoid_along_y_spectral_statistics_are_exact() {
        // h = a·cos(2π y/λ), λ = 8 px, periodic in 32 rows; Δy ≠ Δx.
        let (a, dy) = (3e-9, 5e-8);
        let h = Array2::from_shape_fn((32, 6), |(i, _)| a * (2.0 * PI * i as f64 / 8.0).cos());
        let t = Topography::new(h, 1e-7, dy).unwrap();
        let k = 2.0 * PI / (8.0 * dy);
        let s = SurfaceStats::spectral(&t);
        assert!((s.h_rms_m / (a / 2f64.sqrt()) - 1.0).abs() < 1e-12);
        assert!((s.h_prime_rms / (a * k / 2f64.sqrt()) - 1.0).abs() < 1e-12);
        assert!((s.h_double_prime_rms_per_m / (a * k * k / 2f64.sqrt()) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn finite_differences_need_three_by_three() {
        let t = random(2, 8, 1);
        assert!(rms_slope(&t).is_err());
        assert!(SurfaceStats::finite_differences(&t).is_err());
        assert!(radial_psd(&t, 0).is_err());
    }

    #[test]
    fn radial_psd_of_white_noise_is_flat() {
        let t = random(64, 64, 5);
        let radial = radial_psd(&t, 16).unwrap();
        assert_eq!(radial.len(), 16);
        // Uniform noise on (−1, 1) µm: C = ΔA·σ², σ² = 1/3 µm².
        let expected = 2e-8 * 3e-8 * 1e-12 / 3.0;
        let mean: f64 = radial.iter().map(|&(_, c)| c).sum::<f64>() / radial.len() as f64;
        assert!((mean / expected - 1.0).abs() < 0.1, "{mean} vs {expected}");
        assert!(radial.windows(2).all(|w| w[0].0 < w[1].0));
    }
}
