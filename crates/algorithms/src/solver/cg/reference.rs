//! The solver's previous algorithms, kept as the slow reference the standard ones are checked
//! against ([`super::Method::Reference`]; `tests/mechanics/solver.rs` compares contact and plastic maps of
//! whole ramps):
//!
//! * [`solve_load_pk`] — elastic load control as Polonsky & Keer 1999 (§2) wrote it, restarting
//!   CG whenever any pixel enters the contact (Tamaas has the same rule).
//! * [`solve_load_bounded`] — load control with a bounded pressure by an outer Illinois root-find
//!   on the approach δ over displacement-controlled solves (docs/methods.md §2.3(a)).

use rayon::prelude::*;

use crate::error::{Error, Result};

use super::displacement::solve_displacement;
use super::{finish, Plasticity, Problem, Solution, SolverOptions};

/// Elastic contact under load control exactly as Polonsky & Keer 1999 (§2) and this solver
/// before: the approach δ is the mean gap over the contact, pressures are rescaled to the load
/// each iteration, and CG restarts whenever any pixel enters the contact.
pub fn solve_load_pk(problem: &Problem, force: f64, options: &SolverOptions) -> Result<Solution> {
    if !(force > 0.0 && force.is_finite()) {
        return Err(Error::not_positive("load", force, "N"));
    }
    let n = problem.len();
    let op = problem.operator;
    let mut work = op.workspace();
    let area = problem.pixel_area;
    let scale = problem.gap_scale(options);
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
            return Ok(finish(
                problem,
                p,
                delta,
                Plasticity::Elastic,
                iteration,
                residual,
            ));
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

/// Load control with a bounded pressure: an outer Illinois (regula falsi) root-find on δ for
/// W(δ) = force, warm-starting each inner displacement-controlled solve (docs/methods.md §2.3(a)).
/// W(δ) is non-decreasing, so the bracket never fails for a feasible load.
pub fn solve_load_bounded(
    problem: &Problem,
    force: f64,
    plasticity: Plasticity,
    options: &SolverOptions,
) -> Result<Solution> {
    super::check_load(problem, force, plasticity)?;
    let mut iterations = 0;
    let mut solve = |delta: f64, warm: Option<&[f64]>| -> Result<Solution> {
        let s = solve_displacement(problem, delta, plasticity, warm, options)?;
        iterations += s.iterations;
        Ok(s)
    };
    let lo_delta = problem.min_separation();
    let mut step = problem.separation_range() * 1e-3;
    let (mut lo, mut f_lo) = (lo_delta, -force);
    let mut hi = solve(lo_delta + step, None)?;
    while hi.force < force {
        (lo, f_lo) = (hi.approach, hi.force - force);
        step *= 2.0;
        if step > 1e3 * problem.separation_range() {
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
