//! Polonsky–Keer constrained conjugate gradients (I. A. Polonsky & L. M. Keer, Wear 231, 206
//! (1999)), with the bounded-pressure modification of Weber et al. 2018 (Methods: Plasticity
//! models; Almqvist et al. 2007) and the implicit hardening step of docs/methods.md §3.4.
//!
//! Sign conventions (`docs/conventions.md`): separation s ≥ 0, approach δ > 0 pushes the bodies
//! together, compressive pressure p ≥ 0, displacement u = G∗p ≥ 0 away from the counter-surface,
//! gap g = s − δ + u. Complementarity: g ≥ 0, p ≥ 0, g·p = 0; with a cap p ≤ p_Y, g ≤ 0 where
//! p = p_Y (the overlap is the plastic penetration).
//!
//! * [`load`] — load control for every model in one CG run: the approach δ is the Lagrange
//!   multiplier of the load (the mean gap over the free pixels, as Polonsky & Keer), the pressure
//!   is projected onto the bounds and rescaled to the load each iteration, and the conjugate
//!   direction survives small changes of the active set ([`Restart::Adaptive`]).
//! * [`displacement`] — imposed approach δ, with any bound ([`solve_displacement`]).
//! * [`reference`](mod@reference) — the previous algorithms, kept to check the fast ones: PK with a restart
//!   whenever any pixel engages, and, for bounded models, a root-find on δ over
//!   displacement-controlled solves ([`Method::Reference`]).
//!
//! Every result says how many iterations it took, what the final residuals were, and why it
//! stopped; the iteration limit gives [`Error::NotConverged`] with the residual.
//!
//! [`Error::NotConverged`]: crate::error::Error::NotConverged

pub mod displacement;
pub mod load;
pub mod reference;
mod sums;

pub use displacement::solve_displacement;
pub use load::{solve_load, solve_load_with};
pub use reference::solve_load_bounded;

use rayon::prelude::*;

use super::halfspace::ElasticOperator;

/// Called after every CG iteration with (iteration, relative residual), e.g. for a progress bar.
pub type Monitor<'a> = &'a (dyn Fn(usize, f64) + Sync);

/// Which algorithm solves a load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Method {
    /// One load-controlled CG run per load for every model ([`solve_load_with`]), with
    /// [`Restart::Adaptive`].
    #[default]
    Standard,
    /// The previous solver, slower, kept as the reference the standard one is tested against:
    /// PK restarting on every engagement (elastic), a root-find on δ over displacement-controlled
    /// solves (bounded models).
    Reference,
}

/// When the conjugate direction is dropped for steepest descent.
///
/// Polonsky & Keer (and Tamaas, and this solver before) restart CG whenever a single pixel
/// enters the contact. On large contacts almost every iteration engages a few pixels at the
/// edge, so CG degenerates to steepest descent: at 1024² and 400 mN, 677 of 717 iterations were
/// restarts. Keeping the direction through small changes of the active set costs nothing in
/// accuracy (the stopping rule is unchanged) and cuts the iterations several-fold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Restart {
    /// Restart when any pixel enters the contact (Polonsky & Keer 1999).
    EveryChange,
    /// Restart when more than `fraction` of the free pixels join or leave the free set (engage,
    /// leave or reach the cap) or change between elastic and plastic in one step, when the
    /// energy rose (the step stopped reducing the error: the energy, not the residual, is what
    /// CG decreases; restarting whenever the residual grew tripled the iterations), or when the
    /// conjugate direction is not a descent direction.
    Adaptive {
        /// Share of the loaded pixels, e.g. 0.01.
        fraction: f64,
    },
}

/// The default fraction of [`Restart::Adaptive`]: 10 %. Measured on the paper's ramp
/// (`benches/paper.rs`, 1024² and 512², 4 / 40 / 400 mN, gap residual relative to the roughness):
/// iterations at 400 mN for fractions 0.3 % / 1 % / 3 % / 10 % / 100 % were 269 / 205 / 190 /
/// 192 / 192 (elastic, 1024²) and — / 142 / — / 112 / 112 (hardness, 512²); hardening did not
/// change (48–51). Above a few per cent the energy safeguard alone decides; 10 % still restarts
/// when the active set changes wholesale (the first iterations from the uniform start).
pub const RESTART_FRACTION: f64 = 0.1;

impl Default for Restart {
    fn default() -> Self {
        Restart::Adaptive {
            fraction: RESTART_FRACTION,
        }
    }
}

/// Iteration limits and tolerances.
#[derive(Clone, Copy)]
pub struct SolverOptions<'a> {
    /// Most CG iterations per solve.
    pub max_iterations: usize,
    /// Relative tolerance: on the gap residual (the largest |g| where the pressure is free and
    /// the largest complementarity violation elsewhere, relative to [`SolverOptions::gap_scale_m`])
    /// and on the pressure change between iterations ΔA·Σ|Δp|/W.
    pub tolerance: f64,
    /// Progress callback.
    pub monitor: Option<Monitor<'a>>,
    /// Algorithm.
    pub method: Method,
    /// Restart rule of [`Method::Standard`].
    pub restart: Restart,
    /// The length the gap residual is measured against, m: the roughness h_rms when the caller
    /// knows it (`simulate` passes the rms height of the detrended map). The residual is
    /// relative to the smaller of this and the range of the separation, so that giving it never
    /// loosens the rule; `None`: the range of the separation.
    pub gap_scale_m: Option<f64>,
    /// The GPU the standard load solver runs on ([`crate::solver::gpu`]); `None`: the CPU.
    /// The reference algorithms and displacement control always run on the CPU.
    pub gpu: Option<&'a crate::solver::gpu::Gpu>,
}

impl std::fmt::Debug for SolverOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolverOptions")
            .field("max_iterations", &self.max_iterations)
            .field("tolerance", &self.tolerance)
            .field("method", &self.method)
            .field("restart", &self.restart)
            .field("gap_scale_m", &self.gap_scale_m)
            .field("gpu", &self.gpu.map(|g| g.name()))
            .finish()
    }
}

impl Default for SolverOptions<'_> {
    fn default() -> Self {
        SolverOptions {
            max_iterations: 2000,
            tolerance: 1e-10,
            monitor: None,
            method: Method::Standard,
            restart: Restart::default(),
            gap_scale_m: None,
            gpu: None,
        }
    }
}

impl SolverOptions<'_> {
    fn report(&self, iteration: usize, residual: (f64, f64)) {
        if let Some(monitor) = self.monitor {
            monitor(iteration, residual.0.max(residual.1));
        }
    }
}

/// How the pressure is bounded above.
#[derive(Debug, Clone, Copy)]
pub enum Plasticity<'a> {
    /// Purely elastic: 0 ≤ p.
    Elastic,
    /// Penetration hardness: 0 ≤ p ≤ cap (per pixel).
    Cap(&'a [f64]),
    /// Implicit linear hardening within one load step (docs/methods.md §3.4): pressure above
    /// `yield_pressure` compresses a local spring of compliance `compliance` (= 1/k) in series
    /// with the half-space.
    Hardening {
        /// p_Y at the start of the step, per pixel.
        yield_pressure: &'a [f64],
        /// 1/k in length per pressure.
        compliance: f64,
    },
}

impl Plasticity<'_> {
    fn cap(&self, i: usize) -> f64 {
        match self {
            Plasticity::Cap(c) => c[i],
            _ => f64::INFINITY,
        }
    }

    /// Extra gap from the hardening spring at pressure p on pixel i.
    fn spring(&self, i: usize, p: f64) -> f64 {
        match self {
            Plasticity::Hardening {
                yield_pressure,
                compliance,
            } => (p - yield_pressure[i]).max(0.0) * compliance,
            _ => 0.0,
        }
    }

    /// The hardening spring's energy per unit area at pressure p: (p − p_Y)₊²/(2k).
    fn spring_energy(&self, i: usize, p: f64) -> f64 {
        match self {
            Plasticity::Hardening {
                yield_pressure,
                compliance,
            } => {
                let over = (p - yield_pressure[i]).max(0.0);
                0.5 * over * over * compliance
            }
            _ => 0.0,
        }
    }

    fn spring_compliance(&self, i: usize, p: f64) -> f64 {
        match self {
            Plasticity::Hardening {
                yield_pressure,
                compliance,
            } if p > yield_pressure[i] => *compliance,
            _ => 0.0,
        }
    }
}

/// Why a solve stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StopReason {
    /// All tolerances met.
    Converged,
}

/// A solved contact.
#[derive(Debug, Clone)]
pub struct Solution {
    /// Pressure per pixel (pressure unit of E*).
    pub pressure: Vec<f64>,
    /// Elastic displacement u = G∗p.
    pub displacement: Vec<f64>,
    /// Gap g = s − δ + u (+ the hardening spring's compression where it acts).
    pub gap: Vec<f64>,
    /// Rigid approach δ.
    pub approach: f64,
    /// Total force Σ p·ΔA.
    pub force: f64,
    /// CG iterations (summed over inner solves for root-found loads).
    pub iterations: usize,
    /// Final relative gap residual on the loaded, unbounded pixels.
    pub gap_residual: f64,
    /// Final relative pressure change.
    pub pressure_change: f64,
    /// Why it stopped.
    pub reason: StopReason,
}

impl Solution {
    /// Pixels with p > 0.
    pub fn contact_pixels(&self) -> usize {
        self.pressure.iter().filter(|p| **p > 0.0).count()
    }
}

/// The geometry of one contact problem.
#[derive(Debug)]
pub struct Problem<'a> {
    /// The elastic operator (grid, modulus, boundaries).
    pub operator: &'a ElasticOperator,
    /// Undeformed separation s per pixel (including plastic displacement).
    pub separation: &'a [f64],
    /// Pixel area.
    pub pixel_area: f64,
}

impl Problem<'_> {
    fn len(&self) -> usize {
        self.separation.len()
    }

    /// The length the gap residual is measured against: the range of the separation, or the
    /// caller's scale (the roughness) when that is smaller.
    fn gap_scale(&self, options: &SolverOptions) -> f64 {
        let range = self.separation_range();
        match options.gap_scale_m {
            Some(scale) if scale > 0.0 && scale.is_finite() => scale.min(range),
            _ => range,
        }
    }

    /// max s − min s.
    fn separation_range(&self) -> f64 {
        let (lo, hi) = self
            .separation
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &s| {
                (a.min(s), b.max(s))
            });
        (hi - lo).max(f64::MIN_POSITIVE)
    }

    fn min_separation(&self) -> f64 {
        self.separation
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min)
    }
}

/// The solution at pressure `pressure` and approach `approach`: u = G∗p, g = s − δ + u (plus the
/// hardening spring), and the force.
fn finish(
    problem: &Problem,
    pressure: Vec<f64>,
    approach: f64,
    plasticity: Plasticity,
    iterations: usize,
    residuals: (f64, f64),
) -> Solution {
    let mut work = problem.operator.workspace();
    let mut displacement = vec![0.0; problem.len()];
    problem
        .operator
        .apply(&pressure, &mut displacement, &mut work);
    assemble(
        problem,
        pressure,
        displacement,
        approach,
        plasticity,
        iterations,
        residuals,
    )
}

/// The solution from its pressure and displacement u = G∗p: the gap g = s − δ + u (plus the
/// hardening spring) and the force.
fn assemble(
    problem: &Problem,
    pressure: Vec<f64>,
    displacement: Vec<f64>,
    approach: f64,
    plasticity: Plasticity,
    iterations: usize,
    (gap_residual, pressure_change): (f64, f64),
) -> Solution {
    let gap = (0..problem.len())
        .into_par_iter()
        .map(|i| {
            problem.separation[i] - approach + displacement[i] + plasticity.spring(i, pressure[i])
        })
        .collect();
    let force = pressure.iter().sum::<f64>() * problem.pixel_area;
    Solution {
        pressure,
        displacement,
        gap,
        approach,
        force,
        iterations,
        gap_residual,
        pressure_change,
        reason: StopReason::Converged,
    }
}

/// A load the solvers can take: positive and finite, and for a capped model below what every
/// pixel at its cap carries.
fn check_load(problem: &Problem, force: f64, plasticity: Plasticity) -> crate::error::Result<()> {
    if !(force > 0.0 && force.is_finite()) {
        return Err(crate::error::Error::not_positive("load", force, "N"));
    }
    if let Plasticity::Cap(cap) = plasticity {
        let capacity = cap.iter().sum::<f64>() * problem.pixel_area;
        if force >= capacity {
            return Err(crate::error::Error::ExceedsCapacity {
                load_n: force,
                capacity_n: capacity,
            });
        }
    }
    Ok(())
}
