//! A small dense Levenberg–Marquardt least-squares solver for the bead fits (3 or 6 parameters,
//! a few hundred residuals), with Marquardt's diagonal scaling.

/// Residuals and Jacobian of a model at a parameter vector: fills `residuals` (length m) and
/// `jacobian` (row-major m × n, ∂r_i/∂p_j).
pub(crate) trait Problem {
    /// Number of residuals m.
    fn residual_count(&self) -> usize;
    /// Evaluate residuals and Jacobian at `p`.
    fn evaluate(&self, p: &[f64], residuals: &mut [f64], jacobian: &mut [f64]);
}

/// Outcome of [`minimise`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LmOutcome {
    /// Best parameters found.
    pub params: Vec<f64>,
    /// Sum of squared residuals at `params`.
    pub cost: f64,
    /// Accepted steps.
    pub iterations: usize,
    /// Whether a convergence criterion was met before the iteration limit.
    pub converged: bool,
}

/// Relative cost decrease (or parameter step) below which the fit has converged.
const TOLERANCE: f64 = 1e-13;
/// Damping beyond which no step lowers the cost any more: the gradient is numerically zero.
const MAX_DAMPING: f64 = 1e12;

/// Minimise Σ r_i(p)² from `start`, at most `max_iterations` accepted steps.
pub(crate) fn minimise(problem: &impl Problem, start: &[f64], max_iterations: usize) -> LmOutcome {
    let (m, n) = (problem.residual_count(), start.len());
    let mut p = start.to_vec();
    let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
    problem.evaluate(&p, &mut r, &mut jac);
    let mut cost = sum_sq(&r);
    let (mut trial_r, mut trial_jac) = (vec![0.0; m], vec![0.0; m * n]);
    let mut damping = 1e-3;
    let mut iterations = 0;
    if !cost.is_finite() {
        return outcome(p, cost, 0, false);
    }
    while iterations < max_iterations {
        let (a, g) = normal_equations(&jac, &r, m, n);
        let Some(step) = damped_step(&a, &g, n, damping) else {
            damping *= 4.0;
            if damping > MAX_DAMPING {
                return outcome(p, cost, iterations, false);
            }
            continue;
        };
        let trial: Vec<f64> = p.iter().zip(&step).map(|(x, d)| x + d).collect();
        problem.evaluate(&trial, &mut trial_r, &mut trial_jac);
        let trial_cost = sum_sq(&trial_r);
        if trial_cost.is_finite() && trial_cost <= cost {
            iterations += 1;
            let small_step = step
                .iter()
                .zip(&p)
                .all(|(d, x)| d.abs() <= TOLERANCE * (x.abs() + TOLERANCE));
            let small_gain = cost - trial_cost <= TOLERANCE * cost;
            p = trial;
            cost = trial_cost;
            std::mem::swap(&mut r, &mut trial_r);
            std::mem::swap(&mut jac, &mut trial_jac);
            if small_step || small_gain {
                return outcome(p, cost, iterations, true);
            }
            damping = (damping / 3.0).max(1e-12);
        } else {
            damping *= 4.0;
            if damping > MAX_DAMPING {
                // No damped step lowers the cost: we sit at a minimum to rounding precision.
                return outcome(p, cost, iterations, true);
            }
        }
    }
    outcome(p, cost, iterations, false)
}

fn outcome(params: Vec<f64>, cost: f64, iterations: usize, converged: bool) -> LmOutcome {
    LmOutcome {
        params,
        cost,
        iterations,
        converged,
    }
}

fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// JᵀJ (n × n) and Jᵀr.
fn normal_equations(jac: &[f64], r: &[f64], m: usize, n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = vec![0.0; n * n];
    let mut g = vec![0.0; n];
    for i in 0..m {
        let row = &jac[i * n..(i + 1) * n];
        for j in 0..n {
            g[j] += row[j] * r[i];
            for k in 0..n {
                a[j * n + k] += row[j] * row[k];
            }
        }
    }
    (a, g)
}

/// Solve (JᵀJ + λ·diag(JᵀJ)) δ = −Jᵀr; `None` if singular or not finite.
fn damped_step(a: &[f64], g: &[f64], n: usize, damping: f64) -> Option<Vec<f64>> {
    let mut lhs = a.to_vec();
    let scale = (0..n).map(|j| a[j * n + j]).fold(0.0, f64::max);
    for j in 0..n {
        // The floor keeps a parameter with a vanishing column (e.g. a flat background) solvable.
        lhs[j * n + j] += damping * a[j * n + j].max(1e-15 * scale);
    }
    let rhs: Vec<f64> = g.iter().map(|v| -v).collect();
    solve(lhs, rhs, n).filter(|d| d.iter().all(|v| v.is_finite()))
}

/// Gaussian elimination with partial pivoting on a small dense system.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Option<Vec<f64>> {
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        if a[pivot * n + col].abs() < 1e-300 {
            return None;
        }
        if pivot != col {
            for k in 0..n {
                a.swap(pivot * n + k, col * n + k);
            }
            b.swap(pivot, col);
        }
        for row in col + 1..n {
            let f = a[row * n + col] / a[col * n + col];
            for k in col..n {
                a[row * n + k] -= f * a[col * n + k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = vec![0.0; n];
    for row in (0..n).rev() {
        let tail: f64 = (row + 1..n).map(|k| a[row * n + k] * x[k]).sum();
        x[row] = (b[row] - tail) / a[row * n + row];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = a·exp(b·t) sampled without noise: the fit recovers (a, b) from a poor start.
    struct Exponential {
        t: Vec<f64>,
        y: Vec<f64>,
    }

    impl Problem for Exponential {
        fn residual_count(&self) -> usize {
            self.t.len()
        }
        fn evaluate(&self, p: &[f64], r: &mut [f64], j: &mut [f64]) {
            for (i, (&t, &y)) in self.t.iter().zip(&self.y).enumerate() {
                let e = (p[1] * t).exp();
                r[i] = p[0] * e - y;
                j[2 * i] = e;
                j[2 * i + 1] = p[0] * t * e;
            }
        }
    }

    #[test]
    fn recovers_an_exponential() {
        let t: Vec<f64> = (0..20).map(|i| i as f64 * 0.1).collect();
        let y = t.iter().map(|t| 3.0 * (-1.3 * t).exp()).collect();
        let out = minimise(&Exponential { t, y }, &[1.0, 0.0], 200);
        assert!(out.converged);
        assert!((out.params[0] - 3.0).abs() < 1e-9, "{:?}", out.params);
        assert!((out.params[1] + 1.3).abs() < 1e-9, "{:?}", out.params);
    }

    #[test]
    fn solves_a_pivoting_system() {
        let x = solve(vec![0.0, 1.0, 2.0, 1.0], vec![3.0, 4.0], 2).unwrap();
        assert!((x[0] - 0.5).abs() < 1e-12 && (x[1] - 3.0).abs() < 1e-12);
        assert!(solve(vec![1.0, 2.0, 2.0, 4.0], vec![1.0, 2.0], 2).is_none());
    }
}
