//! Least squares for the bead fits (3 or 6 parameters, a few hundred residuals): the
//! `levenberg-marquardt` crate (a port of MINPACK's `lmder`: trust region, pivoted QR of the
//! Jacobian, Moré's diagonal scaling) behind the small [`Problem`] interface the fits implement.
//!
//! It replaced a hand-written Levenberg–Marquardt on the normal equations. Measured on the PSF
//! tests and the demo's bead stack: the fitted σ agree to 1e-9 relative, and QR never squares
//! the Jacobian's condition number as the normal equations do (`docs/performance.md`).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::storage::Owned;
use nalgebra::{DMatrix, DVector, Dyn};

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
    /// Residual evaluations.
    pub iterations: usize,
    /// Whether a convergence criterion was met before the iteration limit.
    pub converged: bool,
}

/// Adapts a [`Problem`] to the crate: residuals and Jacobian are evaluated together when the
/// parameters are set.
struct Adapter<'a, P> {
    problem: &'a P,
    params: DVector<f64>,
    residuals: Vec<f64>,
    jacobian: Vec<f64>,
}

impl<P: Problem> Adapter<'_, P> {
    fn finite(&self) -> bool {
        self.residuals
            .iter()
            .chain(&self.jacobian)
            .all(|v| v.is_finite())
    }
}

impl<P: Problem> LeastSquaresProblem<f64, Dyn, Dyn> for Adapter<'_, P> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, p: &DVector<f64>) {
        self.params.copy_from(p);
        self.problem
            .evaluate(p.as_slice(), &mut self.residuals, &mut self.jacobian);
    }

    fn params(&self) -> DVector<f64> {
        self.params.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.finite()
            .then(|| DVector::from_column_slice(&self.residuals))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let (m, n) = (self.residuals.len(), self.params.len());
        self.finite()
            .then(|| DMatrix::from_row_slice(m, n, &self.jacobian))
    }
}

fn converged(reason: &TerminationReason) -> bool {
    reason.was_successful() || matches!(reason, TerminationReason::NoImprovementPossible(_))
}

/// Minimise Σ r_i(p)² from `start` with at most `max_iterations`·(n + 1) residual evaluations
/// (the crate's "patience"). Converged means one of MINPACK's criteria on the relative
/// reduction, the step or the gradient (each 30 ε) was met, or no step can improve the fit at
/// machine precision (noise-free data end there).
pub(crate) fn minimise(problem: &impl Problem, start: &[f64], max_iterations: usize) -> LmOutcome {
    let (m, n) = (problem.residual_count(), start.len());
    let mut adapter = Adapter {
        problem,
        params: DVector::from_column_slice(start),
        residuals: vec![0.0; m],
        jacobian: vec![0.0; m * n],
    };
    adapter.set_params(&DVector::from_column_slice(start));
    let (adapter, report) = LevenbergMarquardt::new()
        .with_patience(max_iterations.max(1))
        .minimize(adapter);
    let cost = adapter.residuals.iter().map(|v| v * v).sum();
    LmOutcome {
        params: adapter.params.as_slice().to_vec(),
        cost,
        iterations: report.number_of_evaluations,
        converged: converged(&report.termination) && adapter.finite(),
    }
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
}
