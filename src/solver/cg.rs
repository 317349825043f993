//! Polonsky–Keer constrained conjugate gradients (I. A. Polonsky & L. M. Keer, Wear 231, 206
//! (1999)), with the bounded-pressure modification of Weber et al. 2018 (Methods: Plasticity
//! models; Almqvist et al. 2007) and the implicit hardening step of methods.md §3.4.
//!
//! Sign conventions (`docs/conventions.md`): separation s ≥ 0, approach δ > 0 pushes the bodies
//! together, compressive pressure p ≥ 0, displacement u = G∗p ≥ 0 away from the counter-surface,
//! gap g = s − δ + u. Complementarity: g ≥ 0, p ≥ 0, g·p = 0; with a cap p ≤ p_Y, g ≤ 0 where
//! p = p_Y (the overlap is the plastic penetration).
//!
//! The unknown is the pressure; CG runs on the free set {0 < p < cap} with the gap as residual and
//! restarts whenever the active set changes. Every result says how many iterations it took, what
//! the final residuals were, and why it stopped; the iteration limit gives
//! [`Error::NotConverged`] with the residual.

use rayon::prelude::*;

use crate::error::{Error, Result};

use super::halfspace::{ElasticOperator, Workspace};

/// Called after every CG iteration with (iteration, relative residual), e.g. for a progress bar.
pub type Monitor<'a> = &'a (dyn Fn(usize, f64) + Sync);

/// Iteration limits and tolerances.
#[derive(Clone, Copy)]
pub struct SolverOptions<'a> {
    /// Most CG iterations per solve.
    pub max_iterations: usize,
    /// Relative tolerance: on the gap (relative to the separation's range) over loaded pixels,
    /// on the complementarity violation, and on the pressure change between iterations.
    pub tolerance: f64,
    /// Progress callback.
    pub monitor: Option<Monitor<'a>>,
}

impl std::fmt::Debug for SolverOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SolverOptions")
            .field("max_iterations", &self.max_iterations)
            .field("tolerance", &self.tolerance)
            .finish()
    }
}

impl Default for SolverOptions<'_> {
    fn default() -> Self {
        SolverOptions {
            max_iterations: 2000,
            tolerance: 1e-10,
            monitor: None,
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
    /// Implicit linear hardening within one load step (methods.md §3.4): pressure above
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

    fn gap_scale(&self) -> f64 {
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

/// Elastic contact under load control (Polonsky & Keer 1999, §2): the approach δ is the mean gap
/// over the contact, and pressures are rescaled to the load each iteration.
pub fn solve_load(problem: &Problem, force: f64, options: &SolverOptions) -> Result<Solution> {
    if !(force > 0.0 && force.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "load must be positive (got {force})"
        )));
    }
    let n = problem.len();
    let op = problem.operator;
    let mut work = op.workspace();
    let area = problem.pixel_area;
    let scale = problem.gap_scale();
    let mut p = vec![force / (area * n as f64); n];
    let (mut u, mut r, mut t) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut g, mut previous) = (vec![0.0; n], vec![0.0; n]);
    let (mut g_old, mut conjugate) = (1.0, false);
    let mut residual = (f64::INFINITY, f64::INFINITY);
    let s = problem.separation;
    // The loaded set {p > 0} and the support {p ≠ 0} as ascending index lists. Sums run over
    // them in index order: the same additions, in the same order, as a sum over all pixels
    // (adding 0 to a sum that starts at +0 changes nothing), so the result is bit for bit that of
    // one serial pass per quantity. The element-wise passes over all pixels run in parallel.
    let mut loaded: Vec<usize> = (0..n).collect();
    let mut support = loaded.clone();
    for iteration in 1..=options.max_iterations {
        op.apply(&p, &mut u, &mut work);
        // δ is the mean gap over the loaded set.
        let count = loaded.len().max(1);
        let delta = loaded.iter().fold(0.0, |a, &i| a + (s[i] + u[i])) / count as f64;
        g.par_iter_mut()
            .zip(s)
            .zip(&u)
            .for_each(|((g, s), u)| *g = s + u - delta);
        let g_sq = loaded.iter().fold(0.0, |a, &i| a + g[i] * g[i]);
        let beta = if conjugate { g_sq / g_old } else { 0.0 };
        g_old = g_sq;
        t.par_iter_mut()
            .zip(&g)
            .zip(&p)
            .for_each(|((t, g), p)| *t = if *p > 0.0 { g + beta * *t } else { 0.0 });
        op.apply(&t, &mut r, &mut work);
        let (r_sum, num) = loaded
            .iter()
            .fold((0.0, 0.0), |(a, b), &i| (a + r[i], b + g[i] * t[i]));
        let r_mean = r_sum / count as f64;
        let den = loaded.iter().fold(0.0, |a, &i| a + (r[i] - r_mean) * t[i]);
        let tau = if den > 0.0 {
            num / den
        } else {
            1.0 / op.self_coefficient()
        };
        // Step on the loaded set, project onto p ≥ 0, and load overlapping unloaded pixels.
        let overlap = p
            .par_iter_mut()
            .zip(&mut previous)
            .zip(&t)
            .zip(&g)
            .map(|(((p, previous), t), g)| {
                *previous = *p;
                if *previous > 0.0 {
                    *p = (*p - tau * t).max(0.0);
                }
                let engage = *p == 0.0 && *g < 0.0;
                if engage {
                    *p = -tau * g;
                }
                engage
            })
            .reduce(|| false, |a, b| a || b);
        conjugate = !overlap;
        let old_support = std::mem::take(&mut support);
        support = (0..n).into_par_iter().filter(|&i| p[i] != 0.0).collect();
        let total = support.iter().fold(0.0, |a, &i| a + p[i]) * area;
        p.par_iter_mut().for_each(|v| *v *= force / total);
        let change =
            sum_over_union(&old_support, &support, |i| (p[i] - previous[i]).abs()) * area / force;
        let gap_residual = loaded.iter().fold(0.0, |m: f64, &i| m.max(g[i].abs())) / scale;
        loaded = support.iter().copied().filter(|&i| p[i] > 0.0).collect();
        residual = (gap_residual, change);
        options.report(iteration, residual);
        if !overlap && gap_residual < options.tolerance && change < options.tolerance {
            return Ok(finish(problem, p, delta, iteration, residual, &mut work));
        }
    }
    Err(Error::NotConverged {
        what: "Polonsky–Keer load control".into(),
        iterations: options.max_iterations,
        residual: residual.0.max(residual.1),
        tolerance: options.tolerance,
    })
}

/// Σ f(i) over the union of two ascending index lists, in ascending order, each index once.
fn sum_over_union(a: &[usize], b: &[usize], f: impl Fn(usize) -> f64) -> f64 {
    let (mut i, mut j, mut sum) = (0, 0, 0.0);
    loop {
        let k = match (a.get(i), b.get(j)) {
            (Some(&x), Some(&y)) if x == y => {
                (i, j) = (i + 1, j + 1);
                x
            }
            (Some(&x), Some(&y)) if x < y => {
                i += 1;
                x
            }
            (Some(&x), None) => {
                i += 1;
                x
            }
            (_, Some(&y)) => {
                j += 1;
                y
            }
            (None, None) => return sum,
        };
        sum += f(k);
    }
}

fn finish(
    problem: &Problem,
    pressure: Vec<f64>,
    approach: f64,
    iterations: usize,
    (gap_residual, pressure_change): (f64, f64),
    work: &mut Workspace,
) -> Solution {
    let n = problem.len();
    let mut displacement = vec![0.0; n];
    problem.operator.apply(&pressure, &mut displacement, work);
    let gap = (0..n)
        .map(|i| problem.separation[i] - approach + displacement[i])
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

/// Contact at imposed approach δ (methods.md §2.2), with the pressure bounded as `plasticity`
/// says (§2.3, §3.4). `warm` is a starting pressure (e.g. the previous load step's).
pub fn solve_displacement(
    problem: &Problem,
    delta: f64,
    plasticity: Plasticity,
    warm: Option<&[f64]>,
    options: &SolverOptions,
) -> Result<Solution> {
    let n = problem.len();
    let op = problem.operator;
    let mut work = op.workspace();
    let scale = problem.gap_scale();
    let tau0 = 1.0 / op.self_coefficient();
    let mut p = warm.map_or_else(|| vec![0.0; n], <[f64]>::to_vec);
    let (mut u, mut r, mut t, mut g) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let (mut g_old, mut conjugate) = (1.0, false);
    let mut residual = (f64::INFINITY, f64::INFINITY);
    let mut working = vec![false; n];
    let mut previous = vec![0.0; n];
    for iteration in 1..=options.max_iterations {
        op.apply(&p, &mut u, &mut work);
        for i in 0..n {
            g[i] = problem.separation[i] - delta + u[i] + plasticity.spring(i, p[i]);
        }
        // The working set: free pixels, plus bound pixels whose gap says they must move
        // (engage where p = 0 and g < 0, release where p = cap and g > 0). Searching over both
        // makes every step an exact line minimisation; CG restarts when the set changes.
        let mut changed = false;
        let mut gap_residual = 0.0f64;
        for i in 0..n {
            let v = violation(g[i], p[i], plasticity.cap(i));
            gap_residual = gap_residual.max(v);
            let member = (p[i] > 0.0 && p[i] < plasticity.cap(i)) || v > 0.0;
            changed |= member != working[i];
            working[i] = member;
        }
        let gap_residual = gap_residual / scale;
        let g_sq: f64 = (0..n).filter(|&i| working[i]).map(|i| g[i] * g[i]).sum();
        let beta = if conjugate && !changed {
            g_sq / g_old
        } else {
            0.0
        };
        g_old = g_sq;
        for i in 0..n {
            t[i] = if working[i] { g[i] + beta * t[i] } else { 0.0 };
        }
        op.apply(&t, &mut r, &mut work);
        let (num, den) = (0..n)
            .filter(|&i| working[i])
            .fold((0.0, 0.0), |(a, b), i| {
                let rt = r[i] + plasticity.spring_compliance(i, p[i]) * t[i];
                (a + g[i] * t[i], b + rt * t[i])
            });
        let tau = if den > 0.0 { num / den } else { tau0 };
        // Reused buffer: a fresh copy per iteration cost an 8 MB allocation at 1024².
        previous.copy_from_slice(&p);
        let mut clipped = false;
        for i in (0..n).filter(|&i| working[i]) {
            let cap = plasticity.cap(i);
            let stepped = previous[i] - tau * t[i];
            p[i] = stepped.clamp(0.0, cap);
            clipped |= p[i] != stepped;
            let was_soft = plasticity.spring_compliance(i, previous[i]) > 0.0;
            clipped |= was_soft != (plasticity.spring_compliance(i, p[i]) > 0.0);
        }
        conjugate = !clipped;
        let total = p.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        let change = p
            .iter()
            .zip(&previous)
            .map(|(a, b)| (a - b).abs())
            .sum::<f64>()
            / total;
        residual = (gap_residual, change);
        options.report(iteration, residual);
        if gap_residual < options.tolerance && change < options.tolerance {
            return Ok(finish_displacement(
                problem, previous, delta, plasticity, iteration, residual, &mut work,
            ));
        }
        if p.iter().all(|v| *v == 0.0) && previous.iter().all(|v| *v == 0.0) {
            return Ok(finish_displacement(
                problem,
                p,
                delta,
                plasticity,
                iteration,
                (0.0, 0.0),
                &mut work,
            ));
        }
    }
    Err(Error::NotConverged {
        what: "Polonsky–Keer displacement control".into(),
        iterations: options.max_iterations,
        residual: residual.0.max(residual.1),
        tolerance: options.tolerance,
    })
}

/// How far a pixel is from complementarity: |g| where 0 < p < cap, −g where p = 0 and g < 0,
/// g where p = cap and g > 0.
fn violation(g: f64, p: f64, cap: f64) -> f64 {
    if p <= 0.0 {
        (-g).max(0.0)
    } else if p >= cap {
        g.max(0.0)
    } else {
        g.abs()
    }
}

fn finish_displacement(
    problem: &Problem,
    pressure: Vec<f64>,
    delta: f64,
    plasticity: Plasticity,
    iterations: usize,
    residual: (f64, f64),
    work: &mut Workspace,
) -> Solution {
    let mut solution = finish(problem, pressure, delta, iterations, residual, work);
    for (i, g) in solution.gap.iter_mut().enumerate() {
        *g += plasticity.spring(i, solution.pressure[i]);
    }
    solution
}

/// Load control with a bounded pressure: an outer Illinois (regula falsi) root-find on δ for
/// W(δ) = force, warm-starting each inner displacement-controlled solve (methods.md §2.3(a)).
/// W(δ) is non-decreasing, so the bracket never fails for a feasible load.
pub fn solve_load_bounded(
    problem: &Problem,
    force: f64,
    plasticity: Plasticity,
    options: &SolverOptions,
) -> Result<Solution> {
    if !(force > 0.0 && force.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "load must be positive (got {force})"
        )));
    }
    if let Plasticity::Cap(cap) = plasticity {
        let capacity = cap.iter().sum::<f64>() * problem.pixel_area;
        if force >= capacity {
            return Err(Error::InvalidArgument(format!(
                "load {force:.6e} exceeds what the hardness can carry on the whole map ({capacity:.6e})"
            )));
        }
    }
    let mut iterations = 0;
    let mut solve = |delta: f64, warm: Option<&[f64]>| -> Result<Solution> {
        let s = solve_displacement(problem, delta, plasticity, warm, options)?;
        iterations += s.iterations;
        Ok(s)
    };
    let lo_delta = problem.min_separation();
    let mut step = problem.gap_scale() * 1e-3;
    let (mut lo, mut f_lo) = (lo_delta, -force);
    let mut hi = solve(lo_delta + step, None)?;
    while hi.force < force {
        (lo, f_lo) = (hi.approach, hi.force - force);
        step *= 2.0;
        if step > 1e3 * problem.gap_scale() {
            return Err(Error::InvalidArgument(format!(
                "no approach carries the load {force:.6e}"
            )));
        }
        hi = solve(lo_delta + step, Some(&hi.pressure))?;
    }
    let (mut hi_delta, mut f_hi) = (hi.approach, hi.force - force);
    let mut best = hi;
    let mut side = 0i8;
    for _ in 0..200 {
        if (best.force - force).abs() <= options.tolerance * force {
            best.iterations = iterations;
            return Ok(best);
        }
        let delta = (lo * f_hi - hi_delta * f_lo) / (f_hi - f_lo);
        let trial = solve(delta, Some(&best.pressure))?;
        let f = trial.force - force;
        if f > 0.0 {
            (hi_delta, f_hi) = (delta, f);
            if side == 1 {
                f_lo /= 2.0;
            }
            side = 1;
        } else {
            (lo, f_lo) = (delta, f);
            if side == -1 {
                f_hi /= 2.0;
            }
            side = -1;
        }
        best = trial;
        if (hi_delta - lo).abs() <= f64::EPSILON * hi_delta.abs().max(1e-300) * 4.0 {
            break;
        }
    }
    Err(Error::NotConverged {
        what: "load root-find on the approach".into(),
        iterations,
        residual: (best.force - force).abs() / force,
        tolerance: options.tolerance,
    })
}

#[cfg(test)]
mod tests {
    use super::sum_over_union;

    #[test]
    fn union_sum_visits_each_index_once_in_order() {
        let order = std::cell::RefCell::new(Vec::new());
        let f = |i: usize| {
            order.borrow_mut().push(i);
            i as f64
        };
        assert_eq!(sum_over_union(&[0, 2, 5, 9], &[1, 2, 9, 11], f), 28.0);
        assert_eq!(*order.borrow(), [0, 1, 2, 5, 9, 11]);
        assert_eq!(sum_over_union(&[], &[3], |i| i as f64), 3.0);
        assert_eq!(sum_over_union(&[4], &[], |i| i as f64), 4.0);
        assert_eq!(sum_over_union(&[], &[], |i| i as f64), 0.0);
    }
}
