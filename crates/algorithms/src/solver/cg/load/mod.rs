//! Load control for every model in one constrained-CG run (Polonsky & Keer, Wear 231, 206 (1999),
//! §2, generalised to the bounded and hardening problems of docs/methods.md §2.3 and §3.4).
//!
//! All three models minimise a convex energy of the pressure under the load constraint
//! ΔA·Σp = W:
//!
//! * elastic: E(p) = ½pᵀGp + sᵀp, p ≥ 0;
//! * penetration hardness: the same with 0 ≤ p ≤ p_Y;
//! * implicit hardening (§3.4): ½pᵀGp + sᵀp + Σ(p − p_Y,prev)₊²/(2k), p ≥ 0.
//!
//! Their optimality conditions share one form: with the effective gap e = s + G∗p
//! (+ (p − p_Y,prev)₊/k where the hardening spring acts) and the approach δ as the Lagrange
//! multiplier of the load, g = e − δ vanishes on the free pixels F = {0 < p < cap}, is ≥ 0 where
//! p = 0 and ≤ 0 where p = cap. One iteration:
//!
//! 1. u = G∗p; δ = mean of e over F; g = e − δ is the residual (PK's mean-gap δ);
//! 2. direction t = g + β·t_old on F, 0 elsewhere (Fletcher–Reeves β = Σg²/Σg²_old, as PK),
//!    made mean-free on F: a step along t keeps the load, i.e. t lies in the load constraint's
//!    tangent space;
//! 3. r = G∗t (+ t/k where the spring acts); exact line minimum τ = Σg·t / Σr·t over F;
//! 4. p ← clamp(p − τt, 0, cap) on F; pixels that violate complementarity join the free set:
//!    p = −τg where p = 0 and g < 0 (they penetrate), p = cap − τg where p = cap and g > 0;
//! 5. the load is restored by the Euclidean projection onto ΔA·Σp = W restricted to F:
//!    p ← clip(p + μ, 0, cap) on F, μ found exactly (usually μ alone, with no pixel crossing a
//!    bound; else Newton on the piecewise-linear load inside a bracket). PK rescale p ← λp
//!    instead; with an upper bound that rescale cycles (it pushes pixels onto the cap, the next
//!    step releases them: a 3-cycle seen at 512² with p_Y = 370 MPa), the projection does not.
//!
//! Stopping (the previous solver's rule): the gap residual — the largest |g| on F and the largest
//! complementarity violation elsewhere (−g where p = 0, g where p = cap), relative to the range of
//! the separation — and the relative pressure change ΔA·Σ|Δp|/W both below the tolerance, and no
//! pixel joined in the last step. The force balance ΔA·Σp = W holds to round-off after every step.
//!
//! Restarts ([`Restart::Adaptive`], the default): the conjugate direction is kept unless more
//! than a tenth of the free pixels joined (or switched between elastic and plastic) in the
//! last step, the energy E(p) rose (the step stopped reducing the error), or t is not a descent
//! direction. [`Restart::EveryChange`] restarts whenever any pixel joins, as PK.
//!
//! **Window.** With free boundaries u ≥ 0, so a pixel whose separation s is at least δ can
//! neither carry load nor penetrate. The fields live on a window, the bounding box of
//! {s < δ + margin} and of the loaded pixels, solved with a smaller zero-padded transform
//! ([`ElasticOperator::window`]; exact, because the operator is translation-invariant). The
//! window is checked every iteration from per-row and per-column minima of s (O(N)): it grows
//! when δ comes within reach of a pixel outside it and shrinks when the contact fits a smaller
//! transform; either way CG restarts on the new window. At 4 mN on the paper's 2048² map the
//! transform is 16 times smaller than the whole padded grid. Periodic maps use the whole grid.
//!
//! Cost per iteration: two operator applications and five fused, parallel passes over the
//! window's fields with deterministic sums (`cg::sums`); nothing is allocated inside the
//! loop except when the window changes.
//!
//! [`ElasticOperator::window`]: crate::solver::halfspace::ElasticOperator::window

#[cfg(feature = "cuda")]
mod device;
mod fields;
mod passes;
mod restore;
mod window;

use rayon::prelude::*;

use crate::error::{Error, Result};

use super::{assemble, reference, Method, Plasticity, Problem, Restart, Solution, SolverOptions};
use fields::{Fields, Gaps};
use passes::HostFields;
use window::{Reach, Window};

/// Elastic contact under load control (`force` in the unit of pressure × pixel area).
pub fn solve_load(problem: &Problem, force: f64, options: &SolverOptions) -> Result<Solution> {
    solve_load_with(problem, force, Plasticity::Elastic, None, options)
}

/// Contact under load control with any [`Plasticity`]. `warm` is a starting pressure (the previous
/// load's, say); it is projected onto the bounds and the load. With [`Method::Reference`] the
/// previous algorithms solve it instead (and `warm` is not used).
pub fn solve_load_with(
    problem: &Problem,
    force: f64,
    plasticity: Plasticity,
    warm: Option<&[f64]>,
    options: &SolverOptions,
) -> Result<Solution> {
    super::check_load(problem, force, plasticity)?;
    match (options.method, plasticity) {
        (Method::Reference, Plasticity::Elastic) => {
            reference::solve_load_pk(problem, force, options)
        }
        (Method::Reference, _) => {
            reference::solve_load_bounded(problem, force, plasticity, options)
        }
        (Method::Standard, _) => {
            let start = initial_pressure(problem, force, plasticity, warm);
            let run = match options.gpu {
                None => {
                    let fields = HostFields::new(problem, plasticity, start);
                    Solver::new(problem, force, plasticity, fields)?.run(options)?
                }
                #[cfg(feature = "cuda")]
                Some(gpu) => {
                    let fields = device::DeviceFields::new(gpu, problem, plasticity, &start)?;
                    drop(start);
                    Solver::new(problem, force, plasticity, fields)?.run(options)?
                }
                #[cfg(not(feature = "cuda"))]
                Some(gpu) => gpu.unreachable(),
            };
            match run {
                Run::Done(solution) => Ok(solution),
                Run::Stalled(spent) => {
                    // The reference algorithms are slower but cannot cycle (an outer root-find on δ
                    // around inner solves for the bounded models).
                    let rest = SolverOptions {
                        max_iterations: options.max_iterations.saturating_sub(spent).max(1),
                        ..*options
                    };
                    let mut solution = match plasticity {
                        Plasticity::Elastic => reference::solve_load_pk(problem, force, &rest)?,
                        _ => reference::solve_load_bounded(problem, force, plasticity, &rest)?,
                    };
                    solution.iterations += spent;
                    Ok(solution)
                }
            }
        }
    }
}

/// Iterations without halving the best residual after which a solve counts as stalled
/// ([`Run::Stalled`]). A converging solve halves it every 10–30 iterations (2048², 400 mN:
/// 274 iterations for 27 halvings); the cycle this guards against (nearly every loaded pixel at
/// a low hardness, the active set swapping ~14,000 pixels back and forth with a period of 150
/// iterations) never does.
const STALL_ITERATIONS: usize = 300;

/// How a [`Solver::run`] ended.
enum Run {
    Done(Solution),
    /// No progress in [`STALL_ITERATIONS`]: the iterations spent.
    Stalled(usize),
}

/// One load-controlled solve: the problem, the window, and the fields on the window (row-major
/// `h × w`) in a backend ([`Fields`]).
struct Solver<'a, F: Fields> {
    problem: &'a Problem<'a>,
    plasticity: Plasticity<'a>,
    /// W/ΔA: the pressure sum the load requires.
    target: f64,
    window: Window,
    /// Pixels every later window must hold: those the whole-grid check found penetrating.
    keep: Option<Window>,
    reach: Reach,
    fields: F,
}

/// The starting pressure: `warm` projected onto the bounds, or uniform.
fn initial_pressure(
    problem: &Problem,
    force: f64,
    plasticity: Plasticity,
    warm: Option<&[f64]>,
) -> Vec<f64> {
    let n = problem.len();
    let target = force / problem.pixel_area;
    match warm {
        Some(w) if w.len() == n && w.iter().any(|v| *v > 0.0) => w
            .par_iter()
            .enumerate()
            .map(|(i, v)| v.clamp(0.0, plasticity.cap(i)))
            .collect(),
        _ => (0..n)
            .into_par_iter()
            .map(|i| (target / n as f64).min(plasticity.cap(i)))
            .collect(),
    }
}

impl<'a, F: Fields> Solver<'a, F> {
    /// The solve of `force` on `fields`, which hold the whole grid with the starting pressure
    /// ([`initial_pressure`]).
    fn new(
        problem: &'a Problem<'a>,
        force: f64,
        plasticity: Plasticity<'a>,
        fields: F,
    ) -> Result<Self> {
        let op = problem.operator;
        let reach = Reach::new(problem.separation, op.nx(), op.ny(), op.boundary());
        let mut solver = Solver {
            problem,
            plasticity,
            target: force / problem.pixel_area,
            window: reach.whole(),
            keep: None,
            reach,
            fields,
        };
        solver.start_on_the_load()?;
        Ok(solver)
    }

    /// Move the fields to `next`: the pressure is carried over (it is zero outside the old
    /// window, and `next` holds every loaded pixel), the CG state starts afresh.
    fn rewindow(&mut self, next: Window) -> Result<()> {
        self.fields
            .rewindow(&self.window, &next, &self.reach.whole())?;
        self.window = next;
        Ok(())
    }

    /// The solution on the whole grid ([`super::assemble`]).
    fn finish(&mut self, delta: f64, iteration: usize, residual: (f64, f64)) -> Result<Solution> {
        let (pressure, displacement) = self.fields.solution(&self.window, &self.reach.whole())?;
        Ok(assemble(
            self.problem,
            pressure,
            displacement,
            delta,
            self.plasticity,
            iteration,
            residual,
        ))
    }

    /// Σg² over F. From the shifted sums Σg'² − n·m² when n·m² ≤ ½Σg'² (then the subtraction
    /// loses at most a bit or two; δ moved by less than the residual), else by a second, exact pass
    /// with the new δ.
    fn residual_norm(&mut self, gaps: &Gaps, m: f64, delta: f64) -> Result<f64> {
        let count = gaps.count as f64;
        let shifted = gaps.sum_sq - count * m * m;
        if count * m * m <= 0.5 * gaps.sum_sq {
            return Ok(shifted);
        }
        self.fields.residual_sq(delta)
    }

    fn run(mut self, options: &SolverOptions) -> Result<Run> {
        let scale = self.problem.gap_scale(options);
        let tau0 = 1.0 / self.problem.operator.self_coefficient();
        let (mut delta, mut g_old, mut energy_old) = (0.0, f64::INFINITY, f64::INFINITY);
        let (mut conjugate, mut since_move) = (false, 0usize);
        let mut residual = (f64::INFINITY, f64::INFINITY);
        let mut loaded = Some(self.window);
        let (mut best, mut best_at) = (f64::INFINITY, 0usize);
        for iteration in 1..=options.max_iterations {
            self.fields.apply_pressure(&self.window)?;
            let gaps = self.fields.gaps(delta)?;
            let count = gaps.count as f64;
            // With no free pixel (every loaded one at its cap, as with a tiny hardness early on)
            // δ is the perfectly plastic approach: the pixels that penetrate at δ, all at their
            // cap, carry the load. They join (and capped ones that do not penetrate leave) on the
            // step below.
            let m = if gaps.count > 0 {
                gaps.sum / count
            } else {
                self.plastic_approach()? - delta
            };
            delta += m;
            since_move += 1;
            if let Some(next) =
                self.reach
                    .next_window(&self.window, union(loaded, self.keep), delta, since_move)
            {
                self.rewindow(next)?;
                (g_old, energy_old, conjugate, since_move) =
                    (f64::INFINITY, f64::INFINITY, false, 0);
                continue;
            }
            let g_sq = if gaps.count > 0 {
                self.residual_norm(&gaps, m, delta)?
            } else {
                0.0
            };
            // Σg·t_old over F, and the largest complementarity violation.
            let g_t_old = gaps.sum_gt - m * gaps.sum_t;
            let worst = (gaps.free_max - m)
                .max(m - gaps.free_min)
                .max(m - gaps.zero_min)
                .max(gaps.capped_max - m)
                .max(0.0);
            let restart = match options.restart {
                Restart::EveryChange => !conjugate,
                Restart::Adaptive { .. } => !conjugate || gaps.energy > energy_old,
            };
            energy_old = gaps.energy;
            let mut beta = if restart || !positive(g_old) {
                0.0
            } else {
                g_sq / g_old
            };
            let mut num = g_sq + beta * g_t_old;
            if beta > 0.0 && !positive(num) {
                // Not a descent direction: steepest descent instead.
                beta = 0.0;
                num = g_sq;
            }
            g_old = g_sq;
            // t = g + β(t_old − mean_F t_old): mean-free on F because Σ_F g = 0.
            self.fields
                .direction(delta, beta, beta * gaps.sum_t / count.max(1.0))?;
            self.fields.apply_direction(&self.window)?;
            let den = self.fields.curvature()?;
            let tau = if den > 0.0 && num > 0.0 {
                num / den
            } else {
                tau0
            };
            let step = self.fields.step(delta, tau, self.window.w)?;
            if !positive(step.total) {
                return Err(Error::NotConverged {
                    what: "load-controlled contact (no pixel carries load)".into(),
                    iterations: iteration,
                    residual: f64::INFINITY,
                    tolerance: options.tolerance,
                });
            }
            loaded = (step.rows.0 <= step.rows.1).then(|| Window {
                y0: self.window.y0 + step.rows.0,
                x0: self.window.x0 + step.cols.0,
                h: step.rows.1 - step.rows.0 + 1,
                w: step.cols.1 - step.cols.0 + 1,
            });
            let (change, load) = match self.load_shift(&step)? {
                Some(shift) => self.fields.apply_shift(shift)?,
                None => {
                    // Nothing loaded is left: start again from a uniform pressure.
                    self.fields.fill(self.target / self.window.len() as f64)?;
                    self.start_on_the_load()?;
                    loaded = Some(self.window);
                    self.fields.change()?
                }
            };
            let change = change / self.target;
            let balanced = (load - self.target).abs() <= options.tolerance * self.target;
            conjugate = match options.restart {
                Restart::EveryChange => step.joined() == 0,
                Restart::Adaptive { fraction } => {
                    ((step.joined() + step.flipped) as f64) <= fraction * count
                }
            };
            residual = (worst / scale, change);
            options.report(iteration, residual);
            let worst_of_both = residual.0.max(residual.1);
            if worst_of_both < 0.5 * best {
                (best, best_at) = (worst_of_both, iteration);
            } else if iteration - best_at > STALL_ITERATIONS
                && options.max_iterations > 2 * STALL_ITERATIONS
            {
                return Ok(Run::Stalled(iteration));
            }
            if step.joined() == 0
                && balanced
                && residual.0 < options.tolerance
                && residual.1 < options.tolerance
            {
                let solution = self.finish(delta, iteration, residual)?;
                // Pixels outside the window were assumed not to touch: check on the whole grid.
                let tolerance = options.tolerance * scale;
                match self
                    .reach
                    .violations(&self.window, &solution.gap, tolerance)
                {
                    None => return Ok(Run::Done(solution)),
                    Some(next) => {
                        self.keep = Some(next);
                        self.rewindow(next)?;
                        (g_old, energy_old, conjugate, since_move) =
                            (f64::INFINITY, f64::INFINITY, false, 0);
                    }
                }
            }
        }
        Err(Error::NotConverged {
            what: "Polonsky–Keer load control".into(),
            iterations: options.max_iterations,
            residual: residual.0.max(residual.1),
            tolerance: options.tolerance,
        })
    }
}

/// x > 0, false for NaN (the guards above must also reject NaN).
fn positive(x: f64) -> bool {
    x > 0.0
}

/// The smallest window holding both, if either exists.
fn union(a: Option<Window>, b: Option<Window>) -> Option<Window> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.union(&b)),
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::halfspace::{Boundary, ElasticOperator};

    #[test]
    fn a_contact_outside_the_window_is_found_by_the_whole_grid_check() {
        // A sphere (R = 20, E* = 102, 128² over 5 length units; Hertz a ≈ 1.30 ≈ 33 px at
        // N = 15) with a narrow asperity 0.4 δ high at 1.35 a, where the Hertz gap is ≈ 0.25 δ:
        // it touches. The solve is confined to a 80-pixel window around the centre that leaves the
        // asperity out; only the check on the whole grid can find it.
        let (n, side, radius, e_star, force) = (128usize, 5.0, 20.0, 102.0, 15.0_f64);
        let dx = side / n as f64;
        let a = (3.0 * force * radius / (4.0 * e_star)).cbrt();
        let delta = a * a / radius;
        let centre = n as f64 / 2.0;
        let (bx, by) = (centre + 1.35 * a / dx, centre);
        let separation: Vec<f64> = (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f64 + 0.5, (i / n) as f64 + 0.5);
                let r2 = ((x - centre) * dx).powi(2) + ((y - centre) * dx).powi(2);
                let bump = 0.4 * delta * (-((x - bx).powi(2) + (y - by).powi(2)) / 2.0).exp();
                r2 / (2.0 * radius) - bump
            })
            .collect();
        let top = separation.iter().copied().fold(f64::INFINITY, f64::min);
        let separation: Vec<f64> = separation.iter().map(|s| s - top).collect();
        let op = ElasticOperator::new(n, n, dx, dx, e_star, Boundary::Free);
        let problem = Problem {
            operator: &op,
            separation: &separation,
            pixel_area: dx * dx,
        };
        let options = SolverOptions {
            max_iterations: 2000,
            tolerance: 1e-10,
            ..SolverOptions::default()
        };
        let start = initial_pressure(&problem, force, Plasticity::Elastic, None);
        let fields = HostFields::new(&problem, Plasticity::Elastic, start);
        let mut solver = Solver::new(&problem, force, Plasticity::Elastic, fields).unwrap();
        let confined = Window {
            y0: 24,
            x0: 24,
            h: 80,
            w: 80,
        };
        assert!(
            bx as usize >= 24 + 80,
            "the asperity lies outside the window"
        );
        solver.rewindow(confined).unwrap();
        let Ok(Run::Done(windowed)) = solver.run(&options) else {
            panic!("the windowed solve converges without stalling");
        };
        let reference = reference::solve_load_pk(&problem, force, &options).unwrap();
        let bump = (by as usize) * n + bx as usize;
        assert!(reference.pressure[bump] > 0.0, "the asperity touches");
        assert!(windowed.pressure[bump] > 0.0, "the windowed solve finds it");
        let differing = (0..n * n)
            .filter(|&i| (windowed.pressure[i] > 0.0) != (reference.pressure[i] > 0.0))
            .count();
        assert_eq!(differing, 0, "contact maps differ in {differing} pixels");
        assert!((windowed.approach - reference.approach).abs() < 1e-8 * delta);
    }
}
