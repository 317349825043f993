//! Contact at an imposed approach δ (docs/methods.md §2.2), with the pressure bounded as a
//! [`Plasticity`] says (§2.3, §3.4): CG over a working set of free pixels plus the pixels that
//! violate complementarity, restarting when the set changes or a step is clipped.

use crate::error::{Error, Result};

use super::{finish, Plasticity, Problem, Solution, SolverOptions};

/// Contact at imposed approach δ (docs/methods.md §2.2), with the pressure bounded as `plasticity`
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
    let scale = problem.gap_scale(options);
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
            return Ok(finish(
                problem, previous, delta, plasticity, iteration, residual,
            ));
        }
        if p.iter().all(|v| *v == 0.0) && previous.iter().all(|v| *v == 0.0) {
            return Ok(finish(problem, p, delta, plasticity, iteration, (0.0, 0.0)));
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
