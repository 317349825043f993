//! Seeded self-affine random surfaces by Fourier filtering (Ramisetti et al. 2011, J. Phys.:
//! Condens. Matter 23, 215004; Jacobs, Junge, Pastewka 2017, Surf. Topogr. Metrol. Prop. 5,
//! 013001; docs/methods.md §5.2).
//!
//! Recipe: real Gaussian white noise `w ~ N(0, 1)` on the `ny × nx` grid → forward FFT →
//! multiply by `sqrt(C(|q|))` with the isotropic PSD
//!
//! * `C(q) = q_r^(−2−2H)` for `0 < q < q_r` (roll-off, flat below `q_r = 2π/λ_r`),
//! * `C(q) = q^(−2−2H)` for `q_r ≤ q ≤ q_s`,
//! * `C(q) = 0` for `q > q_s = 2π/λ_s` and for `q = 0`,
//!
//! → inverse FFT → rescale to the target. Multiplying the transform of real noise by a real
//! function of `|q|` keeps the Hermitian symmetry, so the inverse is real and the map is
//! periodic by construction. The prefactor of C is irrelevant: the rescaling fixes it.
//!
//! The noise is drawn from `ChaCha8Rng::seed_from_u64(seed)` with `StandardNormal`, one value
//! per pixel in row-major order, so a seed gives the same surface on every platform.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use ndarray::Array2;

use crate::error::{Error, Result};
use crate::spectral::RealFft2;

use super::stats::{rms_slope, rms_slope_spectral};
use super::Topography;

/// What the generated surface is scaled to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RmsTarget {
    /// rms height about the mean, metres (real space, [`Topography::rms_height`]).
    Height(f64),
    /// rms slope by the default statistics estimator: central differences on interior points
    /// ([`super::stats::rms_slope`]), so that [`super::stats::SurfaceStats::finite_differences`]
    /// returns exactly this value.
    Slope(f64),
    /// rms slope by the spectral estimator ([`super::stats::rms_slope_spectral`]), as in the
    /// B6 set-up of docs/validation.md ("spectral h'_rms normalised to 0.1").
    SpectralSlope(f64),
}

/// Parameters of a self-affine surface. Pixels are square (`dx_m` along both axes).
#[derive(Debug, Clone, PartialEq)]
pub struct SelfAffineParams {
    /// Columns (x), at least 4.
    pub nx: usize,
    /// Rows (y), at least 4.
    pub ny: usize,
    /// Pixel size, metres.
    pub dx_m: f64,
    /// Hurst exponent H ∈ (0, 1]; the PSD falls as q^(−2−2H).
    pub hurst: f64,
    /// Roll-off wavelength λ_r (C is flat for q < 2π/λ_r); `None`: no roll-off.
    pub rolloff_wavelength_m: Option<f64>,
    /// Short-wavelength cutoff λ_s (C = 0 for q > 2π/λ_s); `None`: every wavevector of the grid.
    pub short_cutoff_wavelength_m: Option<f64>,
    /// The rms value the surface is scaled to.
    pub target: RmsTarget,
    /// Seed of the white noise.
    pub seed: u64,
}

fn invalid(message: String) -> Error {
    Error::InvalidArgument(message)
}

impl SelfAffineParams {
    /// Check the parameters; errors say which value is wrong and why.
    pub fn validate(&self) -> Result<()> {
        if self.nx < 4 || self.ny < 4 {
            return Err(invalid(format!(
                "{}: a self-affine surface needs at least 4 × 4 pixels (got {} × {})",
                contactscope_formats::param::Param::Size,
                self.nx,
                self.ny
            )));
        }
        // The spectrum is complex (16 bytes per value).
        crate::limits::Limits::DEFAULT
            .plane_bytes(self.nx, self.ny, 16)
            .map_err(|reason| {
                invalid(format!(
                    "{}: {reason}",
                    contactscope_formats::param::Param::Size
                ))
            })?;
        if !(self.dx_m.is_finite() && self.dx_m > 0.0) {
            return Err(invalid(format!(
                "pixel size must be positive and finite (got {} m)",
                self.dx_m
            )));
        }
        if !(self.hurst > 0.0 && self.hurst <= 1.0) {
            return Err(invalid(format!(
                "Hurst exponent must lie in (0, 1] (got {})",
                self.hurst
            )));
        }
        self.validate_wavelengths()?;
        let value = match self.target {
            RmsTarget::Height(v) | RmsTarget::Slope(v) | RmsTarget::SpectralSlope(v) => v,
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(invalid(format!(
                "target rms must be positive and finite (got {value})"
            )));
        }
        // A finite target whose square overflows would make every height infinite.
        if value > 1.0 {
            return Err(invalid(format!(
                "target rms {value:e} is above 1 (an rms height above 1 m or an rms slope above 1; a unit typo?)"
            )));
        }
        Ok(())
    }

    fn validate_wavelengths(&self) -> Result<()> {
        let longest = self.nx.max(self.ny) as f64 * self.dx_m;
        use contactscope_formats::param::Param;
        let named = [
            ("roll-off", Param::Rolloff, self.rolloff_wavelength_m),
            (
                "short cutoff",
                Param::Cutoff,
                self.short_cutoff_wavelength_m,
            ),
        ];
        for (name, param, value) in named {
            let Some(lambda) = value else { continue };
            if !(lambda.is_finite() && lambda >= 2.0 * self.dx_m) {
                return Err(invalid(format!(
                    "{param}: the {name} wavelength must be at least 2 pixels ({} m; got \
                     {lambda} m; {} is {} m)",
                    2.0 * self.dx_m,
                    Param::PixelSize,
                    self.dx_m
                )));
            }
            if lambda > longest * (1.0 + 1e-12) {
                return Err(invalid(format!(
                    "{param}: the {name} wavelength {lambda} m is longer than the map ({longest} \
                     m: {} × {})",
                    Param::Size,
                    Param::PixelSize
                )));
            }
        }
        if let (Some(r), Some(s)) = (self.rolloff_wavelength_m, self.short_cutoff_wavelength_m) {
            if s >= r {
                return Err(invalid(format!(
                    "{}: the short cutoff wavelength ({s} m) must be shorter than the roll-off \
                     wavelength ({r} m, {})",
                    Param::Cutoff,
                    Param::Rolloff
                )));
            }
        }
        Ok(())
    }

    /// The unscaled isotropic PSD shape `C(q)` (module docs), q in rad/m.
    pub fn psd_shape(&self, q: f64) -> f64 {
        let tau = 2.0 * std::f64::consts::PI;
        if q <= 0.0 {
            return 0.0;
        }
        if let Some(ls) = self.short_cutoff_wavelength_m {
            if q > tau / ls * (1.0 + 1e-12) {
                return 0.0;
            }
        }
        let q_eff = match self.rolloff_wavelength_m {
            Some(lr) => q.max(tau / lr),
            None => q,
        };
        q_eff.powf(-2.0 - 2.0 * self.hurst)
    }
}

/// Generate a periodic self-affine surface (module docs). The heights have zero mean (q = 0 is
/// removed) and are scaled so that the estimator named by [`RmsTarget`] returns the target.
pub fn self_affine(params: &SelfAffineParams) -> Result<Topography> {
    params.validate()?;
    let (nx, ny) = (params.nx, params.ny);
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let mut field: Vec<f64> = (0..nx * ny).map(|_| rng.sample(StandardNormal)).collect();
    let fft = RealFft2::new(ny, nx);
    let mut spectrum = fft.make_spectrum();
    fft.forward(&mut field, &mut spectrum);
    let tau = 2.0 * std::f64::consts::PI;
    let (lx, ly) = (nx as f64 * params.dx_m, ny as f64 * params.dx_m);
    for (index, value) in spectrum.iter_mut().enumerate() {
        let (mx, my) = fft.wavenumbers(index);
        let q = (tau * mx as f64 / lx).hypot(tau * my as f64 / ly);
        *value *= params.psd_shape(q).sqrt();
    }
    fft.inverse(&mut spectrum, &mut field);
    let heights = Array2::from_shape_vec((ny, nx), field).expect("field has ny·nx values");
    let mut topography = Topography::new(heights, params.dx_m, params.dx_m)?;
    rescale(&mut topography, params.target)?;
    Ok(topography)
}

fn rescale(topography: &mut Topography, target: RmsTarget) -> Result<()> {
    topography.remove_mean();
    let (current, wanted) = match target {
        RmsTarget::Height(v) => (topography.rms_height(), v),
        RmsTarget::Slope(v) => (rms_slope(topography)?, v),
        RmsTarget::SpectralSlope(v) => (rms_slope_spectral(topography), v),
    };
    if !(current > 0.0 && current.is_finite()) {
        return Err(invalid(
            "the filtered surface is flat (no wavevector passes the filter)".into(),
        ));
    }
    let factor = wanted / current;
    topography.heights.mapv_inplace(|h| h * factor);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> SelfAffineParams {
        SelfAffineParams {
            nx: 64,
            ny: 48,
            dx_m: 1e-8,
            hurst: 0.8,
            rolloff_wavelength_m: Some(16e-8),
            short_cutoff_wavelength_m: Some(4e-8),
            target: RmsTarget::Height(1e-9),
            seed: 7,
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        let cases: Vec<(SelfAffineParams, &str)> = vec![
            (
                SelfAffineParams {
                    hurst: 0.0,
                    ..params()
                },
                "Hurst",
            ),
            (
                SelfAffineParams {
                    hurst: 1.2,
                    ..params()
                },
                "Hurst",
            ),
            (SelfAffineParams { nx: 3, ..params() }, "4 × 4"),
            (
                SelfAffineParams {
                    dx_m: 0.0,
                    ..params()
                },
                "pixel size",
            ),
            (
                SelfAffineParams {
                    short_cutoff_wavelength_m: Some(1.5e-8),
                    ..params()
                },
                "at least 2 pixels",
            ),
            (
                SelfAffineParams {
                    rolloff_wavelength_m: Some(1e-6),
                    ..params()
                },
                "longer than the map",
            ),
            (
                SelfAffineParams {
                    rolloff_wavelength_m: Some(3e-8),
                    ..params()
                },
                "must be shorter",
            ),
            (
                SelfAffineParams {
                    target: RmsTarget::Slope(-1.0),
                    ..params()
                },
                "target",
            ),
            (
                SelfAffineParams {
                    target: RmsTarget::Height(f64::NAN),
                    ..params()
                },
                "target",
            ),
        ];
        for (p, needle) in cases {
            let err = self_affine(&p).unwrap_err().to_string();
            assert!(err.contains(needle), "{err} (wanted '{needle}')");
        }
    }

    #[test]
    fn zero_mean_and_target_height() {
        let t = self_affine(&params()).unwrap();
        assert_eq!((t.ny(), t.nx()), (48, 64));
        assert!(t.mean().abs() < 1e-12 * 1e-9);
        assert!((t.rms_height() / 1e-9 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn psd_shape_has_rolloff_and_cutoff() {
        let p = params();
        let tau = 2.0 * std::f64::consts::PI;
        let (qr, qs) = (tau / 16e-8, tau / 4e-8);
        assert_eq!(p.psd_shape(0.0), 0.0);
        assert_eq!(p.psd_shape(qr / 3.0), p.psd_shape(qr));
        assert!(p.psd_shape(qs) > 0.0);
        assert_eq!(p.psd_shape(qs * 1.01), 0.0);
        let ratio = p.psd_shape(2.0 * qr) / p.psd_shape(qr);
        assert!((ratio - 2f64.powf(-3.6)).abs() < 1e-12);
    }
}
