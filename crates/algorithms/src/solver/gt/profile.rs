//! The GT profile in SI units: parameters, the load search over the central separation, and the
//! separation and pressure profiles it gives.

use std::f64::consts::PI;

use super::functions::*;
use super::kernel::*;
use crate::error::{Error, Result};

/// Material and roughness parameters of the GT model, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GtParams {
    /// Sphere radius R, m.
    pub sphere_radius_m: f64,
    /// Contact modulus E* (`docs/methods.md` §0), Pa.
    pub e_star_pa: f64,
    /// Rms roughness height h_rms, m; used as the summit-height deviation σ.
    pub h_rms_m: f64,
    /// Rms curvature h''_rms, 1/m; the summit radius is β = 1/h''_rms (Weber et al.).
    pub h_double_prime_rms_per_m: f64,
    /// The product η·h_rms·β fixing the summit density η; Weber et al. use 0.05.
    pub eta_h_beta: f64,
}

impl GtParams {
    /// Weber et al.'s η·h_rms·β.
    pub const DEFAULT_ETA_H_BETA: f64 = 0.05;

    /// Parameters with η·h_rms·β = 0.05.
    pub fn new(
        sphere_radius_m: f64,
        e_star_pa: f64,
        h_rms_m: f64,
        h_double_prime_rms_per_m: f64,
    ) -> Self {
        GtParams {
            sphere_radius_m,
            e_star_pa,
            h_rms_m,
            h_double_prime_rms_per_m,
            eta_h_beta: Self::DEFAULT_ETA_H_BETA,
        }
    }

    /// Every parameter must be finite and positive.
    pub fn validate(&self) -> Result<()> {
        let named = [
            ("Greenwood–Tripp: sphere radius", self.sphere_radius_m, "m"),
            ("Greenwood–Tripp: contact modulus E*", self.e_star_pa, "Pa"),
            ("Greenwood–Tripp: h_rms", self.h_rms_m, "m"),
            (
                "Greenwood–Tripp: h''_rms",
                self.h_double_prime_rms_per_m,
                "1/m",
            ),
            ("Greenwood–Tripp: η·h_rms·β", self.eta_h_beta, ""),
        ];
        for (name, value, unit) in named {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::not_positive(name, value, unit));
            }
        }
        Ok(())
    }

    /// Summit-height deviation σ = h_rms, m.
    pub fn sigma_m(&self) -> f64 {
        self.h_rms_m
    }

    /// Summit radius β = 1/h''_rms, m.
    pub fn asperity_radius_m(&self) -> f64 {
        1.0 / self.h_double_prime_rms_per_m
    }

    /// Summit density η = (η·h_rms·β)/(σβ), 1/m².
    pub fn summit_density_per_m2(&self) -> f64 {
        self.eta_h_beta / (self.sigma_m() * self.asperity_radius_m())
    }

    /// μ = (8/3)·η·σ·√(2Rβ) (dimensionless).
    pub fn mu(&self) -> f64 {
        8.0 / 3.0
            * self.summit_density_per_m2()
            * self.sigma_m()
            * (2.0 * self.sphere_radius_m * self.asperity_radius_m()).sqrt()
    }

    /// Length unit of ρ: √(2Rσ), m.
    pub fn length_scale_m(&self) -> f64 {
        (2.0 * self.sphere_radius_m * self.sigma_m()).sqrt()
    }

    /// Pressure unit of p̃: E*·√(σ/(8R)), Pa.
    pub fn pressure_scale_pa(&self) -> f64 {
        self.e_star_pa * (self.sigma_m() / (8.0 * self.sphere_radius_m)).sqrt()
    }

    /// Load unit of P̃: E*·σ^{3/2}·√(R/2), N.
    pub fn load_scale_n(&self) -> f64 {
        self.e_star_pa * self.sigma_m().powf(1.5) * (0.5 * self.sphere_radius_m).sqrt()
    }
}

/// Numerical settings of [`gt_profile_with`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GtNumerics {
    /// Radial grid points (uniform on [0, ρ_max]).
    pub points: usize,
    /// Newton tolerance on max |Δp̃| relative to the central pressure.
    pub rel_tol: f64,
    /// Newton iterations allowed per solve at fixed d.
    pub max_iter: usize,
    /// Accepted relative mismatch between the computed and the requested load.
    pub load_rtol: f64,
}

impl Default for GtNumerics {
    /// 256 points, rel_tol 1e-10, 100 Newton iterations, load to 1e-9.
    fn default() -> Self {
        GtNumerics {
            points: 256,
            rel_tol: 1e-10,
            max_iter: 100,
            load_rtol: 1e-9,
        }
    }
}

/// The GT solution for one load, SI units, on a radial grid from the sphere's axis.
#[derive(Debug, Clone, PartialEq)]
pub struct GtProfile {
    /// Radii r, m, from 0 on the axis.
    pub r_m: Vec<f64>,
    /// Asperity pressure p(r), Pa.
    pub pressure_pa: Vec<f64>,
    /// Mean-plane separation u_GT(r) = d + r²/(2R) + w(r) − w(0), m (negative where the mean
    /// planes interpenetrate).
    pub separation_m: Vec<f64>,
    /// Central separation d = u_GT(0), m.
    pub central_separation_m: f64,
    /// Rigid-body approach δ = w(0) − d, m: the compression Hertz's δ = a²/R corresponds to.
    pub approach_m: f64,
    /// Load 2π ∫ p r dr of this profile, N (the requested force within the load tolerance).
    pub load_n: f64,
    /// GT's own real contact area 2π ∫ π·η·β·σ·F₁(u/σ) r dr, m².
    pub gt_area_m2: f64,
    /// Sphere radius R, m (continues u_GT beyond the grid, see [`GtProfile::separation_at`]).
    pub sphere_radius_m: f64,
    /// Newton iterations over all solves of the load search.
    pub iterations: usize,
}

impl GtProfile {
    /// u_GT at radius `r_m` (m): linear between grid points; beyond the last grid radius r_max,
    /// u_GT(r_max) + (r² − r_max²)/(2R), i.e. the sphere's parabola with the bulk deflection
    /// frozen at its r_max value (the pressure there is below 1e-6 of the central one).
    /// NaN for an empty profile.
    pub fn separation_at(&self, r_m: f64) -> f64 {
        let r = r_m.abs();
        let n = self.r_m.len().min(self.separation_m.len());
        if n == 0 {
            return f64::NAN;
        }
        let (r_max, u_max) = (self.r_m[n - 1], self.separation_m[n - 1]);
        if r >= r_max || n == 1 {
            return u_max + (r * r - r_max * r_max) / (2.0 * self.sphere_radius_m);
        }
        let j = self.r_m[..n].partition_point(|&x| x <= r).clamp(1, n - 1) - 1;
        let t = (r - self.r_m[j]) / (self.r_m[j + 1] - self.r_m[j]);
        self.separation_m[j] + t * (self.separation_m[j + 1] - self.separation_m[j])
    }

    pub(super) fn check(&self) -> Result<()> {
        let n = self.r_m.len();
        let radius_ok = self.sphere_radius_m > 0.0;
        if n < 2 || self.separation_m.len() != n || !radius_ok {
            return Err(Error::InvalidArgument(
                "GT profile needs at least 2 radii, one separation per radius and R > 0".into(),
            ));
        }
        Ok(())
    }
}

/// GT profile for `force_n` (N) with [`GtNumerics::default`]; see [`gt_profile_with`].
pub fn gt_profile(params: &GtParams, force_n: f64) -> Result<GtProfile> {
    gt_profile_with(params, force_n, &GtNumerics::default())
}

/// Solves the GT model of a rough sphere under the normal force `force_n` (N).
///
/// The central separation d is found by a bracketing root search on ln N(d), which decreases
/// monotonically with d (`docs/methods.md` §4.3 item 3); every solve at fixed d uses Newton's method,
/// warm-started from the previous one. The grid runs to ρ_max = 2·ρ_Hertz + 5 (ρ_Hertz: the
/// Hertz radius in units of √(2Rσ); the 5 covers the rough tail at light loads) and is extended
/// by half until the pressure at ρ_max is below 1e-6 of the central pressure.
///
/// Errors: invalid parameters or force (not positive and finite, or so small that the pressure
/// underflows), and non-convergence.
///
/// ```
/// use contactscope::solver::gt::{gt_bearing_area, gt_profile, GtParams};
/// use contactscope::surface::Topography;
/// use ndarray::Array2;
///
/// // The PS sphere of Weber et al. (R = 290 µm, E* = 3.7 GPa), 50 nm rms roughness, β = 1 µm.
/// let params = GtParams::new(290e-6, 3.7e9, 50e-9, 1e6);
/// let profile = gt_profile(&params, 4e-3)?;
/// assert!((profile.load_n / 4e-3 - 1.0).abs() < 1e-6);
///
/// // A roughness map that is flat at u_GT(5 µm) touches inside r = 5 µm.
/// let level = profile.separation_at(5e-6);
/// let roughness = Topography::new(Array2::from_elem((100, 100), level), 0.2e-6, 0.2e-6)?;
/// let map = gt_bearing_area(&roughness, &profile, None)?;
/// let disc = std::f64::consts::PI * 25e-12;
/// assert!((map.area_m2 / disc - 1.0).abs() < 0.05);
/// # Ok::<(), contactscope::Error>(())
/// ```
pub fn gt_profile_with(
    params: &GtParams,
    force_n: f64,
    numerics: &GtNumerics,
) -> Result<GtProfile> {
    params.validate()?;
    check_numerics(numerics)?;
    if !(force_n.is_finite() && force_n > 0.0) {
        return Err(Error::not_positive("Greenwood–Tripp: force", force_n, "N"));
    }
    let target = force_n / params.load_scale_n();
    if target.is_nan() || target <= 1e-250 {
        return Err(Error::InvalidArgument(format!(
            "Greenwood–Tripp: force {force_n} N is negligible against E*·σ^(3/2)·√(R/2) = {} N",
            params.load_scale_n()
        )));
    }
    let mut rho_max = 2.0 * hertz_rho(target) + 5.0;
    for _ in 0..8 {
        let kernel = RadialKernel::uniform(rho_max, numerics.points)?;
        let mut search = LoadSearch::new(&kernel, params.mu(), target, numerics);
        let solution = search.run()?;
        let centre = solution.pressure[0];
        if solution.pressure[solution.pressure.len() - 1] < 1e-6 * centre {
            return Ok(dimensional(params, &solution, search.iterations));
        }
        rho_max *= 1.5;
    }
    Err(Error::InvalidArgument(format!(
        "Greenwood–Tripp: pressure still above 1e-6 of the centre at ρ_max = {rho_max:.3}"
    )))
}

pub(super) fn check_numerics(numerics: &GtNumerics) -> Result<()> {
    let ok = numerics.points >= 3
        && numerics.rel_tol > 0.0
        && numerics.max_iter > 0
        && numerics.load_rtol > 0.0;
    if !ok {
        return Err(Error::InvalidArgument(format!(
            "Greenwood–Tripp numerics: need ≥ 3 points and positive tolerances (got {numerics:?})"
        )));
    }
    Ok(())
}

/// Hertz contact radius in units of √(2Rσ) for the scaled load: P̃ = (16/3)·ρ_a³.
pub(super) fn hertz_rho(scaled_load: f64) -> f64 {
    (3.0 * scaled_load / 16.0).cbrt()
}

pub(super) fn dimensional(params: &GtParams, s: &ScaledSolution, iterations: usize) -> GtProfile {
    let (sigma, length) = (params.sigma_m(), params.length_scale_m());
    let area_density = PI * params.summit_density_per_m2() * params.asperity_radius_m() * sigma;
    // The load weights integrate 2π ∫ f ρ dρ; r = ρ·√(2Rσ) brings the factor length².
    let f1: Vec<f64> = s.separation.iter().map(|u| f_one(*u)).collect();
    let weights = load_weights(&s.rho);
    GtProfile {
        r_m: s.rho.iter().map(|r| r * length).collect(),
        pressure_pa: s
            .pressure
            .iter()
            .map(|p| p * params.pressure_scale_pa())
            .collect(),
        separation_m: s.separation.iter().map(|u| u * sigma).collect(),
        central_separation_m: s.d_star * sigma,
        approach_m: (s.displacement[0] - s.d_star) * sigma,
        load_n: s.load * params.load_scale_n(),
        gt_area_m2: area_density * length * length * dot(&weights, &f1),
        sphere_radius_m: params.sphere_radius_m,
        iterations,
    }
}

/// Load control: a bracket on d* by marching from a Hertz-based guess with growing steps, then
/// Illinois regula falsi on f(d*) = ln(P̃(d*)/P̃_target), every solve warm-started.
pub(super) struct LoadSearch<'a> {
    kernel: &'a RadialKernel,
    mu: f64,
    target: f64,
    numerics: &'a GtNumerics,
    iterations: usize,
}

impl<'a> LoadSearch<'a> {
    fn new(kernel: &'a RadialKernel, mu: f64, target: f64, numerics: &'a GtNumerics) -> Self {
        LoadSearch {
            kernel,
            mu,
            target,
            numerics,
            iterations: 0,
        }
    }

    fn run(&mut self) -> Result<ScaledSolution> {
        let d0 = self.initial_d();
        let first = self.solve(d0, &self.initial_pressure(d0))?;
        if self.mismatch(&first).abs() < self.numerics.load_rtol {
            return Ok(first);
        }
        let (heavy, light) = self.bracket(first)?;
        self.refine(heavy, light)
    }

    /// d* at which the central pressure μF_{3/2}(d*) equals the Hertz p̃₀ = (8/π)ρ_a.
    fn initial_d(&self) -> f64 {
        let y = 8.0 / PI * hertz_rho(self.target) / self.mu;
        let (mut lo, mut hi) = (-(y.powf(2.0 / 3.0) + 1.0), 38.0);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if f_half_orders(mid).1 > y {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// max(rigid-sphere pressure, Hertz pressure with the same centre): right in both limits.
    fn initial_pressure(&self, d_star: f64) -> Vec<f64> {
        let p0 = self.mu * f_half_orders(d_star).1;
        let a = PI * p0 / 8.0;
        self.kernel
            .rho()
            .iter()
            .map(|r| {
                let rigid = self.mu * f_half_orders(d_star + r * r).1;
                let hertz = 8.0 / PI * (a * a - r * r).max(0.0).sqrt();
                rigid.max(hertz)
            })
            .collect()
    }

    fn solve(&mut self, d_star: f64, start: &[f64]) -> Result<ScaledSolution> {
        let centre = self.mu * f_half_orders(d_star).1;
        let options = ScaledOptions {
            method: ScaledMethod::Newton,
            tol: (self.numerics.rel_tol * centre).max(f64::MIN_POSITIVE),
            max_iter: self.numerics.max_iter,
        };
        let solution = self.kernel.solve(self.mu, d_star, Some(start), &options)?;
        self.iterations += solution.iterations;
        Ok(solution)
    }

    fn mismatch(&self, s: &ScaledSolution) -> f64 {
        (s.load.max(1e-300) / self.target).ln()
    }

    /// (heavier solution at smaller d*, lighter solution at larger d*).
    fn bracket(&mut self, first: ScaledSolution) -> Result<(ScaledSolution, ScaledSolution)> {
        let upwards = self.mismatch(&first) > 0.0;
        let (mut current, mut step) = (first, 0.5);
        for _ in 0..200 {
            let d = current.d_star + if upwards { step } else { -step };
            match self.solve(d, &current.pressure) {
                Ok(next) => {
                    if (self.mismatch(&next) > 0.0) != upwards {
                        return Ok(if upwards {
                            (current, next)
                        } else {
                            (next, current)
                        });
                    }
                    (current, step) = (next, 2.0 * step);
                }
                Err(e) if step < 1e-6 => return Err(e),
                Err(_) => step *= 0.25,
            }
        }
        Err(Error::InvalidArgument(
            "Greenwood–Tripp: no central separation brackets the load".into(),
        ))
    }

    fn refine(
        &mut self,
        mut heavy: ScaledSolution,
        mut light: ScaledSolution,
    ) -> Result<ScaledSolution> {
        let (mut f_heavy, mut f_light) = (self.mismatch(&heavy), self.mismatch(&light));
        let mut last_side = 0;
        for _ in 0..200 {
            let (a, b) = (heavy.d_star, light.d_star);
            let mut d = (a * f_light - b * f_heavy) / (f_light - f_heavy);
            if !(d > a && d < b) {
                d = 0.5 * (a + b);
            }
            let start = if d - a < b - d {
                &heavy.pressure
            } else {
                &light.pressure
            };
            let next = self.solve(d, start)?;
            let f = self.mismatch(&next);
            if f.abs() < self.numerics.load_rtol || b - a < 1e-13 * (1.0 + d.abs()) {
                return Ok(next);
            }
            // Illinois: halve the value kept at the end that survived twice.
            if f > 0.0 {
                (heavy, f_heavy) = (next, f);
                if last_side == 1 {
                    f_light *= 0.5;
                }
                last_side = 1;
            } else {
                (light, f_light) = (next, f);
                if last_side == -1 {
                    f_heavy *= 0.5;
                }
                last_side = -1;
            }
        }
        Err(Error::NotConverged {
            what: "Greenwood–Tripp load search".into(),
            iterations: 200,
            residual: f_heavy.abs().min(f_light.abs()),
            tolerance: self.numerics.load_rtol,
        })
    }
}
