//! The radial GT solve in scaled units: the discretised deflection of a piecewise-linear pressure
//! ([`RadialKernel`]) and the fixed-point and Newton iterations on it.

use std::f64::consts::PI;

use super::functions::*;
use crate::error::{Error, Result};

/// Four-point Gauss–Legendre rule on [a, b] (signed).
pub(super) fn gauss4(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    const X: [f64; 2] = [0.339_981_043_584_856_3, 0.861_136_311_594_052_6];
    const W: [f64; 2] = [0.652_145_154_862_546_1, 0.347_854_845_137_453_9];
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    half * X
        .iter()
        .zip(&W)
        .map(|(x, w)| w * (f(mid - half * x) + f(mid + half * x)))
        .sum::<f64>()
}

/// Geometric halvings towards ξ = 1 for intervals that end there.
pub(super) const GRADING_LEVELS: usize = 30;

/// ∫_a^b S(ξ) dξ for 0 ≤ a < b. S is smooth except for a (ξ − 1)·ln|ξ − 1| term at ξ = 1, so an
/// interval ending at 1 is cut into pieces that halve towards it, each integrated by Gauss–Legendre.
pub(super) fn s_integral(a: f64, b: f64) -> f64 {
    let s = ring_kernel_antiderivative;
    if a < 1.0 && b > 1.0 {
        return s_integral(a, 1.0) + s_integral(1.0, b);
    }
    if a != 1.0 && b != 1.0 {
        return gauss4(s, a, b);
    }
    let far = if a == 1.0 { b } else { a };
    let (mut total, mut outer) = (0.0, far);
    for _ in 0..GRADING_LEVELS {
        let inner = 1.0 + 0.5 * (outer - 1.0);
        total += gauss4(s, inner.min(outer), inner.max(outer));
        outer = inner;
    }
    total + gauss4(s, outer.min(1.0), outer.max(1.0))
}

/// A radial grid ρ₀ = 0 < ρ₁ < … < ρ_max (scaled units) with the precomputed linear maps of the
/// scaled GT equations for a piecewise-linear pressure p̃ (zero beyond ρ_max):
///
/// * w̃(ρ_i) = ρ_i ∫ p̃(ρ_iξ) dS(ξ) = ρ_i·[p̃_last·S(ξ_last) − Σ_j (p̃_{j+1} − p̃_j)·S̄_j] with
///   ξ_j = ρ_j/ρ_i and S̄_j the mean of S over [ξ_j, ξ_{j+1}] (integration by parts: exact for
///   piecewise-linear p̃ up to the Gauss–Legendre quadrature of S̄_j);
/// * w̃(0) = ∫ p̃ dρ (the ρ → 0 limit, since S ≈ ξ for large ξ);
/// * P̃ = 2π ∫ p̃ ρ dρ, exact for piecewise-linear p̃.
///
/// Building costs O(n²) kernel evaluations; reuse one kernel for many solves on the same grid.
#[derive(Debug, Clone)]
pub struct RadialKernel {
    rho: Vec<f64>,
    /// Row-major n × n: contribution of p̃_j to w̃(ρ_i) − w̃(0).
    relative: Vec<f64>,
    /// Weights of w̃(0).
    centre: Vec<f64>,
    /// Weights of P̃.
    load: Vec<f64>,
}

impl RadialKernel {
    /// A kernel on the given grid: at least 3 finite points, starting at exactly 0, strictly
    /// increasing.
    pub fn new(rho: Vec<f64>) -> Result<Self> {
        check_grid(&rho)?;
        let n = rho.len();
        let centre = trapezoid_weights(&rho);
        let mut relative = vec![0.0; n * n];
        for (i, row) in relative.chunks_exact_mut(n).enumerate().skip(1) {
            for ((out, w), c) in row.iter_mut().zip(ring_row(&rho, i)).zip(&centre) {
                *out = w - c;
            }
        }
        let load = load_weights(&rho);
        Ok(RadialKernel {
            rho,
            relative,
            centre,
            load,
        })
    }

    /// A uniform grid of `n` points on [0, `rho_max`], as ContactMechanics uses
    /// (`np.linspace(0, rhomax, n)`).
    pub fn uniform(rho_max: f64, n: usize) -> Result<Self> {
        if !(rho_max.is_finite() && rho_max > 0.0) || n < 3 {
            return Err(Error::InvalidArgument(format!(
                "radial grid needs ρ_max > 0 and at least 3 points (got ρ_max = {rho_max}, n = {n})"
            )));
        }
        let step = rho_max / (n - 1) as f64;
        let mut rho: Vec<f64> = (0..n).map(|j| step * j as f64).collect();
        rho[n - 1] = rho_max;
        Self::new(rho)
    }

    /// The grid ρ (scaled radius).
    pub fn rho(&self) -> &[f64] {
        &self.rho
    }

    /// Scaled displacement w̃(ρ_i) of a piecewise-linear pressure p̃ given at the grid points
    /// (one value per point).
    pub fn displacement(&self, pressure: &[f64]) -> Vec<f64> {
        debug_assert_eq!(pressure.len(), self.rho.len());
        let w0 = dot(&self.centre, pressure);
        self.relative_displacement(pressure)
            .into_iter()
            .map(|w| w + w0)
            .collect()
    }

    /// Scaled load P̃ = 2π ∫ p̃ ρ dρ of a piecewise-linear pressure (one value per point).
    pub fn load(&self, pressure: &[f64]) -> f64 {
        debug_assert_eq!(pressure.len(), self.rho.len());
        dot(&self.load, pressure)
    }

    fn relative_displacement(&self, pressure: &[f64]) -> Vec<f64> {
        self.relative
            .chunks_exact(self.rho.len())
            .map(|row| dot(row, pressure))
            .collect()
    }

    /// u/σ = d* + ρ² + w̃(ρ) − w̃(0).
    fn separation(&self, d_star: f64, pressure: &[f64]) -> Vec<f64> {
        self.relative_displacement(pressure)
            .into_iter()
            .zip(&self.rho)
            .map(|(w, r)| d_star + r * r + w)
            .collect()
    }

    /// Solves the scaled GT equations p̃ = μ·F_{3/2}(d* + ρ² + w̃ − w̃(0)) at fixed d* on this
    /// grid, starting from `initial` (default: p̃ = 0, as ContactMechanics). Errors: invalid
    /// arguments, and [`Error::InvalidArgument`] naming the last change when the iteration does
    /// not converge within `options.max_iter` (or Newton's line search stalls).
    pub fn solve(
        &self,
        mu: f64,
        d_star: f64,
        initial: Option<&[f64]>,
        options: &ScaledOptions,
    ) -> Result<ScaledSolution> {
        check_scaled(mu, d_star, options)?;
        let n = self.rho.len();
        let start = match initial {
            Some(p) if p.len() != n => {
                return Err(Error::SizeMismatch {
                    what: "initial pressure values",
                    expected: n,
                    got: p.len(),
                })
            }
            Some(p) => p.to_vec(),
            None => vec![0.0; n],
        };
        let (pressure, iterations, final_change) = match options.method {
            ScaledMethod::FixedPoint { mixing } => {
                self.fixed_point(mu, d_star, start, mixing, options)?
            }
            ScaledMethod::Newton => self.newton(mu, d_star, start, options)?,
        };
        Ok(self.solution(d_star, pressure, iterations, final_change))
    }

    fn solution(
        &self,
        d_star: f64,
        pressure: Vec<f64>,
        iterations: usize,
        final_change: f64,
    ) -> ScaledSolution {
        ScaledSolution {
            rho: self.rho.clone(),
            displacement: self.displacement(&pressure),
            separation: self.separation(d_star, &pressure),
            load: self.load(&pressure),
            pressure,
            d_star,
            iterations,
            final_change,
        }
    }

    /// Damped fixed point p̃ ← (1 − m)·p̃ + m·μ·F_{3/2}(…) (`docs/methods.md` §4.3): the undamped map
    /// overshoots because a higher pressure raises the separation that lowers it.
    fn fixed_point(
        &self,
        mu: f64,
        d_star: f64,
        mut p: Vec<f64>,
        mixing: f64,
        options: &ScaledOptions,
    ) -> Result<(Vec<f64>, usize, f64)> {
        let mut change = f64::INFINITY;
        for iteration in 1..=options.max_iter {
            let separation = self.separation(d_star, &p);
            change = 0.0;
            for (pi, u) in p.iter_mut().zip(&separation) {
                let next = (1.0 - mixing) * *pi + mixing * mu * f_half_orders(*u).1;
                change = change.max((next - *pi).abs());
                *pi = next;
            }
            if change < options.tol {
                return Ok((p, iteration, change));
            }
            if !change.is_finite() {
                break;
            }
        }
        Err(not_converged("damped fixed point", options, change))
    }

    /// r(p̃) = p̃ − μ·F_{3/2}(u(p̃)), with the separations u.
    fn residual(&self, mu: f64, d_star: f64, p: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let separation = self.separation(d_star, p);
        let r = p
            .iter()
            .zip(&separation)
            .map(|(pi, u)| pi - mu * f_half_orders(*u).1)
            .collect();
        (r, separation)
    }

    /// J = I + diag(μ·(3/2)·F_{1/2}(u))·K, using dF_{3/2}/dt = −(3/2)·F_{1/2}.
    fn jacobian(&self, mu: f64, separation: &[f64]) -> Vec<f64> {
        let n = self.rho.len();
        let mut jac = Vec::with_capacity(n * n);
        for (i, (row, u)) in self.relative.chunks_exact(n).zip(separation).enumerate() {
            let slope = 1.5 * mu * f_half_orders(*u).0;
            jac.extend(row.iter().map(|k| slope * k));
            jac[i * n + i] += 1.0;
        }
        jac
    }

    /// Newton's method with a backtracking (Armijo) line search on |r|². Converged when the
    /// accepted step changes p̃ by less than the tolerance and was a full step (or the residual
    /// itself is below the tolerance), so a stalled line search is never mistaken for
    /// convergence.
    fn newton(
        &self,
        mu: f64,
        d_star: f64,
        mut p: Vec<f64>,
        options: &ScaledOptions,
    ) -> Result<(Vec<f64>, usize, f64)> {
        let (mut r, mut separation) = self.residual(mu, d_star, &p);
        let mut change = f64::INFINITY;
        for iteration in 1..=options.max_iter {
            let rhs: Vec<f64> = r.iter().map(|x| -x).collect();
            let step = solve_dense(self.jacobian(mu, &separation), rhs).ok_or_else(|| {
                Error::InvalidArgument("Greenwood–Tripp Newton: singular Jacobian".into())
            })?;
            let merit = dot(&r, &r);
            let mut lambda = 1.0;
            loop {
                let trial: Vec<f64> = p.iter().zip(&step).map(|(a, b)| a + lambda * b).collect();
                let (r_trial, s_trial) = self.residual(mu, d_star, &trial);
                if dot(&r_trial, &r_trial) <= (1.0 - 1e-4 * lambda) * merit {
                    (p, r, separation) = (trial, r_trial, s_trial);
                    break;
                }
                lambda *= 0.5;
                if lambda < 1e-12 {
                    return Err(Error::InvalidArgument(format!(
                        "Greenwood–Tripp Newton: line search stalled at iteration {iteration} \
                         (residual max |r| = {:.3e})",
                        max_abs(&r)
                    )));
                }
            }
            change = lambda * max_abs(&step);
            if change < options.tol && (lambda == 1.0 || max_abs(&r) < options.tol) {
                return Ok((p, iteration, change));
            }
        }
        Err(not_converged("Newton", options, change))
    }
}

pub(super) fn check_grid(rho: &[f64]) -> Result<()> {
    if rho.len() < 3 {
        return Err(Error::TooFew {
            what: "a radial grid",
            needed: 3,
            got: rho.len(),
        });
    }
    if rho[0] != 0.0 {
        return Err(Error::InvalidArgument(format!(
            "radial grid must start at ρ = 0 (got {})",
            rho[0]
        )));
    }
    if rho.iter().any(|r| !r.is_finite()) || rho.windows(2).any(|w| w[1] <= w[0]) {
        return Err(Error::InvalidArgument(
            "radial grid must be finite and strictly increasing".into(),
        ));
    }
    Ok(())
}

pub(super) fn check_scaled(mu: f64, d_star: f64, options: &ScaledOptions) -> Result<()> {
    if !(mu.is_finite() && mu > 0.0) {
        return Err(Error::not_positive("μ", mu, ""));
    }
    if !d_star.is_finite() {
        return Err(Error::InvalidArgument(format!(
            "d* must be finite (got {d_star})"
        )));
    }
    if options.tol.is_nan() || options.tol <= 0.0 || options.max_iter == 0 {
        return Err(Error::InvalidArgument(format!(
            "tolerance must be positive and max_iter at least 1 (got {}, {})",
            options.tol, options.max_iter
        )));
    }
    if let ScaledMethod::FixedPoint { mixing } = options.method {
        if !(mixing > 0.0 && mixing <= 1.0) {
            return Err(Error::Value {
                what: "mixing",
                value: mixing,
                unit: "",
                requirement: "must lie in (0, 1]",
            });
        }
    }
    Ok(())
}

pub(super) fn not_converged(method: &str, options: &ScaledOptions, change: f64) -> Error {
    Error::NotConverged {
        what: format!("Greenwood–Tripp {method} (last max |Δp̃|)"),
        iterations: options.max_iter,
        residual: change,
        tolerance: options.tol,
    }
}

/// Row i ≥ 1 of the absolute displacement map (see [`RadialKernel`]).
pub(super) fn ring_row(rho: &[f64], i: usize) -> Vec<f64> {
    let scale = rho[i];
    let xi: Vec<f64> = rho.iter().map(|r| r / scale).collect();
    let means: Vec<f64> = xi
        .windows(2)
        .map(|w| s_integral(w[0], w[1]) / (w[1] - w[0]))
        .collect();
    let last = ring_kernel_antiderivative(xi[xi.len() - 1]);
    (0..xi.len())
        .map(|j| {
            let upper = means.get(j).copied().unwrap_or(last);
            let lower = if j > 0 { means[j - 1] } else { 0.0 };
            scale * (upper - lower)
        })
        .collect()
}

pub(super) fn trapezoid_weights(x: &[f64]) -> Vec<f64> {
    let mut w = vec![0.0; x.len()];
    for (j, pair) in x.windows(2).enumerate() {
        let half = 0.5 * (pair[1] - pair[0]);
        w[j] += half;
        w[j + 1] += half;
    }
    w
}

/// Weights of 2π ∫ p ρ dρ for piecewise-linear p: on [a, b],
/// ∫ p ρ dρ = (b − a)/6 · [p_a(2a + b) + p_b(a + 2b)].
pub(super) fn load_weights(rho: &[f64]) -> Vec<f64> {
    let mut w = vec![0.0; rho.len()];
    for (j, pair) in rho.windows(2).enumerate() {
        let (a, b) = (pair[0], pair[1]);
        let sixth = 2.0 * PI * (b - a) / 6.0;
        w[j] += sixth * (2.0 * a + b);
        w[j + 1] += sixth * (a + 2.0 * b);
    }
    w
}

pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub(super) fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Solves A·x = b (A row-major n × n) by Gaussian elimination with partial pivoting; `None` if
/// A is singular or not finite.
///
/// Kept rather than `nalgebra`'s LU, for speed (`docs/performance.md`, "Numerics from crates"):
/// on random 256 × 256 systems both reach the same residual (1e-15) in about the same time
/// (2.2 against 2.6 ms), but on the Newton systems of [`super::gt_profile`] (Weber et al.'s
/// sphere at 4 mN) the whole profile took 36.5 ms with this elimination and 53.1 ms with the LU (the same elliptic
/// integrals in both builds).
pub(super) fn solve_dense(mut a: Vec<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for col in 0..n {
        let pivot =
            (col..n).max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))?;
        let pv = a[pivot * n + col];
        if !(pv.abs() > 0.0 && pv.is_finite()) {
            return None;
        }
        if pivot != col {
            for k in 0..n {
                a.swap(pivot * n + k, col * n + k);
            }
            b.swap(pivot, col);
        }
        let (head, tail) = a.split_at_mut((col + 1) * n);
        let pivot_row = &head[col * n + col..];
        let b_col = b[col];
        for (r, row) in tail.chunks_exact_mut(n).enumerate() {
            let f = row[col] / pv;
            if f != 0.0 {
                for (x, y) in row[col..].iter_mut().zip(pivot_row) {
                    *x -= f * y;
                }
                b[col + 1 + r] -= f * b_col;
            }
        }
    }
    for col in (0..n).rev() {
        let row = &a[col * n..(col + 1) * n];
        let s = dot(&row[col + 1..], &b[col + 1..]);
        b[col] = (b[col] - s) / row[col];
    }
    b.iter().all(|x| x.is_finite()).then_some(b)
}

/// How [`RadialKernel::solve`] iterates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScaledMethod {
    /// Damped fixed point p̃ ← (1 − m)·p̃ + m·μ·F_{3/2}(…) with mixing m in (0, 1]
    /// (ContactMechanics' scheme, `docs/methods.md` §4.3). Converges only while m·μ·(3/2)·F_{1/2}
    /// times the kernel norm stays below about 2, i.e. away from the Hertz limit.
    FixedPoint {
        /// Mixing m; ContactMechanics' default is 0.1.
        mixing: f64,
    },
    /// Newton's method on the same discrete equations (dense Jacobian, line search); a few
    /// iterations at any μ and d*.
    Newton,
}

/// Options of [`RadialKernel::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaledOptions {
    /// Iteration scheme.
    pub method: ScaledMethod,
    /// Stop when max |Δp̃| over one iteration is below this (p̃ units).
    pub tol: f64,
    /// Iterations before giving up with an error.
    pub max_iter: usize,
}

impl Default for ScaledOptions {
    /// ContactMechanics' defaults: fixed point, mixing 0.1, tolerance 1e-6, with 10 000
    /// iterations allowed (its own limit is 1000).
    fn default() -> Self {
        ScaledOptions {
            method: ScaledMethod::FixedPoint { mixing: 0.1 },
            tol: 1e-6,
            max_iter: 10_000,
        }
    }
}

/// The scaled GT solution on a radial grid (units in the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ScaledSolution {
    /// Grid ρ = r/√(2Rσ).
    pub rho: Vec<f64>,
    /// Pressure p̃ = p/(E*√(σ/(8R))) at the grid points (the last iterate).
    pub pressure: Vec<f64>,
    /// Bulk displacement w̃(ρ) = w/σ (w̃(0) = ∫ p̃ dρ).
    pub displacement: Vec<f64>,
    /// Mean-plane separation u/σ = d* + ρ² + w̃(ρ) − w̃(0).
    pub separation: Vec<f64>,
    /// Central separation d* = d/σ.
    pub d_star: f64,
    /// Load P̃ = 2π ∫ p̃ ρ dρ = N/(E*·σ^{3/2}·√(R/2)).
    pub load: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// max |Δp̃| of the last iteration.
    pub final_change: f64,
}
