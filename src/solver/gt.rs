//! Greenwood–Tripp model of a rough elastic sphere on a flat, and the "GT bearing-area" contact
//! map of Weber et al. 2018, Fig. 2b.
//!
//! # Model
//!
//! J. A. Greenwood and J. H. Tripp, "The elastic contact of rough spheres", J. Appl. Mech. 34,
//! 153–159 (1967). Summits with Gaussian heights (standard deviation σ), areal density η and
//! radius β each make a Hertz contact; their averaged pressure deforms the sphere (radius R) as
//! an elastic half-space of contact modulus E*. The equations are those restated in
//! `methods.md` §4.2:
//!
//! * F_n(t) = ∫_t^∞ (z − t)^n φ(z) dz, φ the standard normal density ([`gt_f`]);
//! * mean-plane separation u(r) = d + r²/(2R) + w(r) − w(0), d the central separation;
//! * asperity pressure p(r) = (4/3)·η·E*·β^{1/2}·σ^{3/2}·F_{3/2}(u(r)/σ);
//! * bulk deflection under ring loads w(r) = (4r/(πE*)) ∫_0^∞ p(rξ) Λ(ξ) dξ with
//!   Λ(ξ) = ξK(ξ) for ξ < 1 and K(1/ξ) for ξ > 1 (K: complete elliptic integral of the first
//!   kind, modulus k), integrated against the antiderivative S of (2/π)Λ
//!   ([`ring_kernel_antiderivative`]);
//! * load N = 2π ∫ p r dr; GT real-area density π·η·β·σ·F₁(u/σ).
//!
//! # Notation and choices (`methods.md` §4.1, §10 item 7)
//!
//! Greenwood & Tripp call the sphere radius B and the summit radius β; Weber et al. swap the
//! letters. Here **R is the sphere radius and β the summit radius**, with β = 1/h''_rms and
//! η·h_rms·β = 0.05 (Weber et al.). The summit-height deviation σ is taken as **σ = h_rms**, the
//! same h_rms as in the density relation; the paper does not say which σ it used.
//!
//! # Scaled form
//!
//! With ρ = r/√(2Rσ), p̃ = p/(E*√(σ/(8R))), w̃ = w/σ, d* = d/σ and μ = (8/3)·η·σ·√(2Rβ):
//! p̃ = μ·F_{3/2}(d* + ρ² + w̃(ρ) − w̃(0)), w̃(ρ) = ρ ∫ p̃(ρξ)(2/π)Λ(ξ) dξ, P̃ = 2π ∫ p̃ ρ dρ and
//! N = P̃·E*·σ^{3/2}·√(R/2). This is the parametrisation of ContactMechanics'
//! `GreenwoodTripp` reference function, whose numbers `validation.md` B12 records. At the
//! solution p̃(0) = μ·F_{3/2}(d*), because u(0) = d.
//!
//! # Discretisation and solvers
//!
//! p̃ is piecewise linear on a radial grid ([`RadialKernel`]); w̃ is its exact integral against
//! the kernel (integration by parts onto S, whose interval means come from Gauss–Legendre
//! quadrature, graded towards the logarithmic point ξ = 1). The discrete equations are solved
//! either by the damped fixed point of `methods.md` §4.3 (ContactMechanics' scheme) or by
//! Newton's method on the same equations; [`gt_profile`] uses Newton, because the mixing that
//! keeps the fixed point stable shrinks as μ·F_{1/2}(u/σ)·ρ_max grows, i.e. towards the Hertz
//! limit, where it would need many thousands of iterations.
//!
//! # Bearing area (`methods.md` §4.4)
//!
//! [`gt_bearing_area`] overlays a measured roughness map on the GT separation profile: contact
//! wherever z_rough ≥ u(r). This geometric overlap is what the paper's Fig. 2b shows; it is not
//! GT's own area integral (reported beside it as `gt_area_m2`).

use std::f64::consts::{FRAC_2_PI, FRAC_2_SQRT_PI, PI, SQRT_2};

use ndarray::Array2;

use crate::error::{Error, Result};
use crate::surface::Topography;

/// 1/√(2π), the peak of the standard normal density.
const FRAC_1_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

// ---------------------------------------------------------------------------------------------
// Special functions
// ---------------------------------------------------------------------------------------------

fn normal_pdf(z: f64) -> f64 {
    FRAC_1_SQRT_2PI * (-0.5 * z * z).exp()
}

/// Complementary error function to about 1e-15 relative: a positive-term series for erf below
/// 1.5, Laplace's continued fraction above (where 1 − erf would lose digits: 4e-14 at 1.9).
fn erfc(x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    if x < 0.0 {
        return 2.0 - erfc(-x);
    }
    if x < 1.5 {
        return 1.0 - erf_series(x);
    }
    if x > 27.3 {
        // e^{−x²} underflows; erfc(27.3) < 1e-325.
        return 0.0;
    }
    erfc_continued_fraction(x)
}

/// erf(x) = (2/√π)·e^{−x²}·Σ_k x·(2x²)^k / (1·3·…·(2k+1)). Every term is positive, so nothing
/// cancels; for x < 1.5 about 30 terms reach full precision.
fn erf_series(x: f64) -> f64 {
    let two_x2 = 2.0 * x * x;
    let (mut term, mut sum, mut k) = (x, x, 0.0);
    while term > 1e-17 * sum {
        k += 1.0;
        term *= two_x2 / (2.0 * k + 1.0);
        sum += term;
    }
    FRAC_2_SQRT_PI * (-x * x).exp() * sum
}

/// erfc(x) = e^{−x²}/√π · 1/(x + (1/2)/(x + 1/(x + (3/2)/(x + …)))), evaluated forwards by the
/// modified Lentz method; for x ≥ 1.5 it converges in under 100 terms.
fn erfc_continued_fraction(x: f64) -> f64 {
    let (mut f, mut c, mut d) = (x, x, 0.0);
    for k in 1..300 {
        let a = 0.5 * k as f64;
        d = 1.0 / (x + a * d);
        c = x + a / c;
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    (-x * x).exp() / (PI.sqrt() * f)
}

/// The Greenwood–Tripp integral F_n(t) = ∫_t^∞ (z − t)^n φ(z) dz, φ the standard normal density.
///
/// Implemented for the orders the model needs, n = 0, ½, 1 and 3/2 (F₀ is the fraction of
/// summits in contact, F₁ their area, F_{3/2} their load; F_{1/2} = −(2/3)·dF_{3/2}/dt enters the
/// Newton Jacobian); any other `n` returns NaN. Relative accuracy is about 1e-13 or better
/// wherever the value is a normal floating-point number (`validation.md` B11 asks for 1e-7):
///
/// * F₀(t) = ½·erfc(t/√2) and F₁(t) = φ(t) − t·F₀(t) in closed form;
/// * F_{1/2}, F_{3/2}: with z = t + s², F_n(t) = ∫_0^∞ 2s^{2n+1} φ(s² + t) ds, whose integrand is
///   even and entire in s for half-integer n, so the trapezoidal rule converges geometrically; it
///   runs over the window where φ(s² + t) is within e^{−50} of its peak. Below t = −30 the
///   moment expansion F_n(−T) = T^n Σ_k C(n, 2k)(2k − 1)!! T^{−2k} is used instead.
///
/// ```
/// use contactscope::solver::gt::gt_f;
/// assert!((gt_f(1.5, 0.0) - 0.4300200).abs() < 1e-7);
/// ```
pub fn gt_f(n: f64, t: f64) -> f64 {
    if n == 0.0 {
        f_zero(t)
    } else if n == 1.0 {
        f_one(t)
    } else if n == 0.5 {
        f_half_orders(t).0
    } else if n == 1.5 {
        f_half_orders(t).1
    } else {
        f64::NAN
    }
}

fn f_zero(t: f64) -> f64 {
    0.5 * erfc(t / SQRT_2)
}

/// F₁ = φ(t) − t·F₀(t). For large t the two terms agree to about 1/t², so the result keeps
/// about 1e-16·t² relative accuracy (1e-13 at t = 30, beyond which φ underflows anyway).
fn f_one(t: f64) -> f64 {
    normal_pdf(t) - t * f_zero(t)
}

/// Trapezoidal nodes over the window. The hardest case is t ≈ −10, where the window starts at
/// s = 0 but the peak at s = √10 is narrow: 32 nodes leave 6e-10 there, 40 or more reach the
/// rounding floor (≈ 1e-13) for all t.
const HALF_ORDER_NODES: usize = 48;

/// (F_{1/2}(t), F_{3/2}(t)) from one pass over shared nodes.
fn f_half_orders(t: f64) -> (f64, f64) {
    if t.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    if t < -30.0 {
        return (f_moment_expansion(0.5, -t), f_moment_expansion(1.5, -t));
    }
    if t > 40.0 {
        // φ(40) ≈ 1e-348: below the smallest subnormal.
        return (0.0, 0.0);
    }
    // Window where (s² + t)² − min over s of (s² + t)² ≤ 100, i.e. φ within e^{−50} of its peak.
    let (lo, hi) = if t >= 0.0 {
        (0.0, (100.0 / ((t * t + 100.0).sqrt() + t)).sqrt())
    } else {
        ((-t - 10.0).max(0.0).sqrt(), (10.0 - t).sqrt())
    };
    let h = (hi - lo) / HALF_ORDER_NODES as f64;
    let (mut half, mut three_halves) = (0.0, 0.0);
    for i in 0..=HALF_ORDER_NODES {
        let s = lo + h * i as f64;
        let edge = if i == 0 || i == HALF_ORDER_NODES {
            0.5
        } else {
            1.0
        };
        let s2 = s * s;
        let g = edge * 2.0 * s2 * normal_pdf(s2 + t);
        half += g;
        three_halves += g * s2;
    }
    (half * h, three_halves * h)
}

/// F_n(−T) = E[(T + Z)^n; Z > −T] for T > 30: the tail P(Z < −T) < 1e-197 is dropped, and the
/// binomial expansion of (T + Z)^n with the Gaussian moments E[Z^{2k}] = (2k − 1)!! converges
/// to full precision within a few terms.
fn f_moment_expansion(n: f64, big_t: f64) -> f64 {
    let inv_t2 = 1.0 / (big_t * big_t);
    let (mut term, mut sum) = (1.0, 1.0);
    for k in 1..=16 {
        let two_k = 2.0 * k as f64;
        term *= (n - two_k + 2.0) * (n - two_k + 1.0) / two_k * inv_t2;
        sum += term;
        if term.abs() < 1e-17 * sum {
            break;
        }
    }
    big_t.powf(n) * sum
}

/// K(k) and E(k) for 0 ≤ k < 1 by the arithmetic–geometric mean: with a₀ = 1, b₀ = √(1 − k²),
/// c₀ = k, K = π/(2a_∞) and E = K·(1 − Σ_j 2^{j−1} c_j²) (Abramowitz & Stegun 17.6).
fn elliptic_pair(k: f64) -> (f64, f64) {
    let (mut a, mut b) = (1.0, ((1.0 - k) * (1.0 + k)).sqrt());
    let (mut sum, mut weight) = (0.5 * k * k, 0.5);
    for _ in 0..64 {
        let c = 0.5 * (a - b);
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
        weight *= 2.0;
        sum += weight * c * c;
        if c.abs() <= 4.0 * f64::EPSILON * a {
            break;
        }
    }
    let big_k = PI / (2.0 * a);
    (big_k, big_k * (1.0 - sum))
}

/// Complete elliptic integral of the first kind K(k) = ∫_0^{π/2} dθ/√(1 − k² sin²θ), with
/// **modulus** k (scipy's `ellipk` takes m = k²), by the arithmetic–geometric mean.
/// K(±1) = ∞; |k| > 1 or NaN gives NaN.
pub fn elliptic_k(k: f64) -> f64 {
    let k = k.abs();
    if k < 1.0 {
        elliptic_pair(k).0
    } else if k == 1.0 {
        f64::INFINITY
    } else {
        f64::NAN
    }
}

/// Complete elliptic integral of the second kind E(k) = ∫_0^{π/2} √(1 − k² sin²θ) dθ, modulus k,
/// by the arithmetic–geometric mean. E(±1) = 1; |k| > 1 or NaN gives NaN.
pub fn elliptic_e(k: f64) -> f64 {
    let k = k.abs();
    if k < 1.0 {
        elliptic_pair(k).1
    } else if k == 1.0 {
        1.0
    } else {
        f64::NAN
    }
}

/// The ring-load kernel (2/π)·Λ(ξ), Λ(ξ) = ξ·K(ξ) for ξ < 1 and K(1/ξ) for ξ > 1
/// (`methods.md` §4.2): the deflection at radius r per unit pressure on the ring at radius rξ.
/// It tends to 1 as ξ → ∞, vanishes like ξ at 0 and has an integrable logarithmic singularity at
/// ξ = 1 (returned as ∞). Negative or NaN ξ gives NaN.
pub fn ring_kernel(xi: f64) -> f64 {
    if xi.is_nan() || xi < 0.0 {
        f64::NAN
    } else if xi < 1.0 {
        FRAC_2_PI * xi * elliptic_k(xi)
    } else if xi > 1.0 {
        FRAC_2_PI * elliptic_k(1.0 / xi)
    } else {
        f64::INFINITY
    }
}

/// The antiderivative S(ξ) = ∫_0^ξ (2/π)Λ(t) dt of [`ring_kernel`], in closed form:
/// S = (2/π)·[E(ξ) − (1 − ξ²)·K(ξ)] for ξ ≤ 1 and S = (2/π)·ξ·E(1/ξ) for ξ ≥ 1 (from
/// d/dk[E − (1 − k²)K] = kK and d/dk[−E/k] = K/k²), continuous with S(1) = 2/π.
/// Below ξ = 1/4, where E and (1 − ξ²)K cancel, the power series
/// S = Σ_m [(2m − 1)!!/(2m)!!]² ξ^{2m+2}/(2m + 2) is summed instead.
/// Limits: S ≈ ξ²/2 as ξ → 0 and S ≈ ξ as ξ → ∞. Negative or NaN ξ gives NaN.
pub fn ring_kernel_antiderivative(xi: f64) -> f64 {
    if xi.is_nan() || xi < 0.0 {
        f64::NAN
    } else if xi < 0.25 {
        ring_kernel_series(xi)
    } else if xi < 1.0 {
        let (k, e) = elliptic_pair(xi);
        FRAC_2_PI * (e - (1.0 - xi) * (1.0 + xi) * k)
    } else if xi == 1.0 {
        FRAC_2_PI
    } else if xi.is_infinite() {
        f64::INFINITY
    } else {
        FRAC_2_PI * xi * elliptic_pair(1.0 / xi).1
    }
}

fn ring_kernel_series(xi: f64) -> f64 {
    let x2 = xi * xi;
    let (mut coefficient, mut power, mut sum) = (1.0, x2, 0.5 * x2);
    for m in 1..60 {
        let m = m as f64;
        coefficient *= (2.0 * m - 1.0) / (2.0 * m);
        power *= x2;
        let term = coefficient * coefficient * power / (2.0 * m + 2.0);
        sum += term;
        if term <= 1e-17 * sum {
            break;
        }
    }
    sum
}

// ---------------------------------------------------------------------------------------------
// Radial discretisation
// ---------------------------------------------------------------------------------------------

/// Four-point Gauss–Legendre rule on [a, b] (signed).
fn gauss4(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
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
const GRADING_LEVELS: usize = 30;

/// ∫_a^b S(ξ) dξ for 0 ≤ a < b. S is smooth except for a (ξ − 1)·ln|ξ − 1| term at ξ = 1, so an
/// interval ending at 1 is cut into pieces that halve towards it, each integrated by Gauss–Legendre.
fn s_integral(a: f64, b: f64) -> f64 {
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
                return Err(Error::InvalidArgument(format!(
                    "initial pressure has {} values for a grid of {n}",
                    p.len()
                )))
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

    /// Damped fixed point p̃ ← (1 − m)·p̃ + m·μ·F_{3/2}(…) (`methods.md` §4.3): the undamped map
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

fn check_grid(rho: &[f64]) -> Result<()> {
    if rho.len() < 3 {
        return Err(Error::InvalidArgument(format!(
            "radial grid needs at least 3 points (got {})",
            rho.len()
        )));
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

fn check_scaled(mu: f64, d_star: f64, options: &ScaledOptions) -> Result<()> {
    if !(mu.is_finite() && mu > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "μ must be positive (got {mu})"
        )));
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
            return Err(Error::InvalidArgument(format!(
                "mixing must lie in (0, 1] (got {mixing})"
            )));
        }
    }
    Ok(())
}

fn not_converged(method: &str, options: &ScaledOptions, change: f64) -> Error {
    Error::InvalidArgument(format!(
        "Greenwood–Tripp {method} did not converge in {} iterations \
         (last max |Δp̃| = {change:.3e}, tolerance {:.1e})",
        options.max_iter, options.tol
    ))
}

/// Row i ≥ 1 of the absolute displacement map (see [`RadialKernel`]).
fn ring_row(rho: &[f64], i: usize) -> Vec<f64> {
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

fn trapezoid_weights(x: &[f64]) -> Vec<f64> {
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
fn load_weights(rho: &[f64]) -> Vec<f64> {
    let mut w = vec![0.0; rho.len()];
    for (j, pair) in rho.windows(2).enumerate() {
        let (a, b) = (pair[0], pair[1]);
        let sixth = 2.0 * PI * (b - a) / 6.0;
        w[j] += sixth * (2.0 * a + b);
        w[j + 1] += sixth * (a + 2.0 * b);
    }
    w
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Solves A·x = b (A row-major n × n) by Gaussian elimination with partial pivoting; `None` if
/// A is singular or not finite.
fn solve_dense(mut a: Vec<f64>, mut b: Vec<f64>) -> Option<Vec<f64>> {
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

// ---------------------------------------------------------------------------------------------
// Scaled solver: options and result
// ---------------------------------------------------------------------------------------------

/// How [`RadialKernel::solve`] iterates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScaledMethod {
    /// Damped fixed point p̃ ← (1 − m)·p̃ + m·μ·F_{3/2}(…) with mixing m in (0, 1]
    /// (ContactMechanics' scheme, `methods.md` §4.3). Converges only while m·μ·(3/2)·F_{1/2}
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

// ---------------------------------------------------------------------------------------------
// Dimensional API
// ---------------------------------------------------------------------------------------------

/// Material and roughness parameters of the GT model, SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GtParams {
    /// Sphere radius R, m.
    pub sphere_radius_m: f64,
    /// Contact modulus E* (`methods.md` §0), Pa.
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
            ("sphere radius", self.sphere_radius_m, "m"),
            ("contact modulus E*", self.e_star_pa, "Pa"),
            ("h_rms", self.h_rms_m, "m"),
            ("h''_rms", self.h_double_prime_rms_per_m, "1/m"),
            ("η·h_rms·β", self.eta_h_beta, ""),
        ];
        for (name, value, unit) in named {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "Greenwood–Tripp: {name} must be positive and finite (got {value} {unit})"
                )));
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

    fn check(&self) -> Result<()> {
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
/// monotonically with d (`methods.md` §4.3 item 3); every solve at fixed d uses Newton's method,
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
        return Err(Error::InvalidArgument(format!(
            "Greenwood–Tripp: force must be positive and finite (got {force_n} N)"
        )));
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

fn check_numerics(numerics: &GtNumerics) -> Result<()> {
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
fn hertz_rho(scaled_load: f64) -> f64 {
    (3.0 * scaled_load / 16.0).cbrt()
}

fn dimensional(params: &GtParams, s: &ScaledSolution, iterations: usize) -> GtProfile {
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
struct LoadSearch<'a> {
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
        Err(Error::InvalidArgument(
            "Greenwood–Tripp: load search did not converge in 200 steps".into(),
        ))
    }
}

// ---------------------------------------------------------------------------------------------
// Bearing-area map
// ---------------------------------------------------------------------------------------------

/// The GT bearing-area contact map (Weber et al. 2018, Fig. 2b; `methods.md` §4.4).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactMap {
    /// Contact pixels, shape `(ny, nx)` like the roughness map.
    pub mask: Array2<bool>,
    /// Number of contact pixels.
    pub contact_pixels: usize,
    /// Contact pixels over all pixels.
    pub contact_fraction: f64,
    /// Contact pixels × pixel area, m² (the geometric overlap area).
    pub area_m2: f64,
    /// GT's own real-area integral 2π ∫ π·η·β·σ·F₁(u/σ) r dr of the profile, m², for
    /// comparison: it is not the overlap area (per asperity the overlap is twice the Hertz area,
    /// and the overlap fraction at separation u is about F₀(u/σ)).
    pub gt_area_m2: f64,
    /// Centre of the sphere used, (x, y) in m from the outer corner of pixel (0, 0).
    pub centre_m: (f64, f64),
}

/// Overlays a roughness map on the GT separation profile: a pixel is in contact where
/// z_rough(x, y) ≥ u_GT(r(x, y)) (`methods.md` §4.4).
///
/// `roughness` is the measured **roughness** z_rough, not the sphere: heights in m with the mean
/// plane removed, positive towards the flat (the [`Topography`] convention); the caller removes
/// the sphere and the mean plane, because u_GT already contains the sphere's r²/(2R). Pixel
/// (iy, ix) sits at its centre ((ix + ½)·dx, (iy + ½)·dy); r is measured from `centre` ((x, y)
/// in m from the outer corner of pixel (0, 0); default: the middle of the map). Beyond the
/// profile's last radius u_GT continues as in [`GtProfile::separation_at`]. No elastic
/// interaction between the overlapping asperities is modelled.
pub fn gt_bearing_area(
    roughness: &Topography,
    profile: &GtProfile,
    centre: Option<(f64, f64)>,
) -> Result<ContactMap> {
    profile.check()?;
    let (dx, dy) = (roughness.dx_m, roughness.dy_m);
    let (width, height) = roughness.size_m();
    let (x0, y0) = centre.unwrap_or((0.5 * width, 0.5 * height));
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "bearing-area centre must be finite (got ({x0}, {y0}) m)"
        )));
    }
    let mask = Array2::from_shape_fn(roughness.heights.dim(), |(iy, ix)| {
        let x = (ix as f64 + 0.5) * dx - x0;
        let y = (iy as f64 + 0.5) * dy - y0;
        roughness.heights[[iy, ix]] >= profile.separation_at(x.hypot(y))
    });
    let contact_pixels = mask.iter().filter(|&&c| c).count();
    Ok(ContactMap {
        contact_fraction: contact_pixels as f64 / mask.len() as f64,
        area_m2: contact_pixels as f64 * dx * dy,
        mask,
        contact_pixels,
        gt_area_m2: profile.gt_area_m2,
        centre_m: (x0, y0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a / b - 1.0).abs()
    }

    /// Tanh–sinh quadrature on [a, b]; tolerates integrable endpoint singularities because the
    /// nodes never reach the endpoints.
    fn tanh_sinh(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
        let (h, half) = (1.0 / 64.0, 0.5 * (b - a));
        let mut sum = 0.0;
        for k in -192..=192 {
            let t = k as f64 * h;
            let u = 0.5 * PI * t.sinh();
            // Distance of the node from the nearer endpoint, in units of the half-width,
            // formed without cancellation: 1 − tanh|u| = 2/(1 + e^{2|u|}).
            let gap = 2.0 / (1.0 + (2.0 * u.abs()).exp());
            let x = if t < 0.0 {
                a + half * gap
            } else {
                b - half * gap
            };
            if x <= a || x >= b {
                continue; // rounded onto an endpoint; its weight is below 1e-13
            }
            let weight = 0.5 * PI * t.cosh() / u.cosh().powi(2);
            sum += weight * f(x);
        }
        sum * h * half
    }

    #[test]
    fn b11_special_values() {
        // validation.md B11, quoted to 7 decimals.
        assert!((gt_f(0.0, 1.0) - 0.1586553).abs() < 5e-8);
        assert!((gt_f(1.0, 0.0) - 0.3989423).abs() < 5e-8);
        assert!((gt_f(1.5, 0.0) - 0.4300200).abs() < 5e-8);
        assert!(rel(gt_f(1.0, 0.0), FRAC_1_SQRT_2PI) < 1e-15);
        // High-precision values (mpmath, 25 digits) across the range.
        let table = [
            (0.0, -3.0, 0.998_650_101_968_369_9),
            (0.0, 6.0, 9.865_876_450_376_98e-10),
            (0.0, 20.0, 2.753_624_118_606_233_7e-89),
            (0.5, -50.0, 7.070_714_125_752_899),
            (0.5, -3.0, 1.704_132_001_920_450_6),
            (0.5, 0.5, 0.225_335_581_697_311_6),
            (0.5, 10.0, 2.117_479_299_141_611e-24),
            (1.0, -3.0, 3.000_382_154_317_047_7),
            (1.0, 1.0, 0.083_315_470_587_686_3),
            (1.0, 10.0, 7.474_560_254_589_328e-25),
            (1.5, -1000.0, 31_622.788_460_227_242),
            (1.5, -50.0, 353.606_427_581_661_5),
            (1.5, -10.0, 31.741_587_709_726_317),
            (1.5, -1.0, 1.404_597_470_473_952_4),
            (1.5, 1.0, 0.075_668_177_390_975_07),
            (1.5, 6.0, 8.203_580_589_815_165e-11),
            (1.5, 20.0, 4.058_555_079_262_784e-91),
        ];
        for (n, t, want) in table {
            let got = gt_f(n, t);
            assert!(rel(got, want) < 1e-12, "F_{n}({t}) = {got}, want {want}");
        }
        assert!(gt_f(2.0, 0.0).is_nan());
        assert!(gt_f(1.5, f64::NAN).is_nan());
        // Both sides of the series/continued-fraction switch of erfc at 1.5, and the reflection.
        for (x, want) in [
            (0.5, 0.479_500_122_186_953_5),
            (1.4, 0.047_714_880_237_351_2),
            (1.9, 0.007_209_570_764_742_533),
            (2.0, 0.004_677_734_981_047_266),
            (5.0, 1.537_459_794_428_035e-12),
            (-1.0, 1.842_700_792_949_715),
        ] {
            assert!(rel(erfc(x), want) < 1e-14, "erfc({x})");
        }
    }

    #[test]
    fn half_orders_are_continuous_across_method_switches() {
        // t = −30 (moment expansion) and t = 0 (window shape) switch methods.
        for t in [-30.0, 0.0] {
            for n in [0.5, 1.5] {
                let (below, above) = (gt_f(n, t - 1e-9), gt_f(n, t + 1e-9));
                assert!(rel(below, above) < 1e-8, "F_{n} jumps at {t}");
            }
        }
        // dF_{3/2}/dt = −(3/2)·F_{1/2}.
        for t in [-5.0, -0.3, 0.7, 3.0] {
            let h = 1e-5;
            let slope = (gt_f(1.5, t + h) - gt_f(1.5, t - h)) / (2.0 * h);
            assert!(rel(-slope, 1.5 * gt_f(0.5, t)) < 1e-8);
        }
    }

    #[test]
    fn elliptic_integrals() {
        assert!(rel(elliptic_k(0.0), 0.5 * PI) < 1e-15);
        assert!(rel(elliptic_e(0.0), 0.5 * PI) < 1e-15);
        // Near k = 1 the rounding of k itself (dK/dk ≈ 1/(1 − k²)) limits the comparison.
        for (k, big_k, big_e, tol) in [
            (0.5, 1.685_750_354_812_596, 1.467_462_209_339_427_2, 1e-14),
            (0.9, 2.280_549_138_422_770_3, 1.171_697_052_781_614_1, 1e-14),
            (
                0.999_999,
                7.947_479_773_542_437,
                1.000_007_447_477_724_5,
                1e-10,
            ),
        ] {
            assert!(rel(elliptic_k(k), big_k) < tol, "K({k})");
            assert!(rel(elliptic_e(k), big_e) < tol, "E({k})");
        }
        assert!(elliptic_k(1.0).is_infinite());
        assert!(elliptic_k(1.5).is_nan());
    }

    #[test]
    fn gauss4_is_exact_to_degree_seven() {
        let got = gauss4(|x| x.powi(7) + x.powi(6), 0.0, 2.0);
        assert!(rel(got, 256.0 / 8.0 + 128.0 / 7.0) < 1e-14);
    }

    #[test]
    fn b11_kernel_antiderivative() {
        // Limits: S ≈ ξ²/2 (ξ → 0) and S ≈ ξ (ξ → ∞).
        assert!(rel(ring_kernel_antiderivative(1e-4), 0.5e-8) < 1e-7);
        assert!(rel(ring_kernel_antiderivative(1e6), 1e6) < 1e-7);
        assert!(rel(ring_kernel_antiderivative(1.0), 2.0 / PI) < 1e-15);
        // Against direct quadrature of (2/π)Λ, split at the log singularity ξ = 1 (CM test_s).
        for xi in [
            0.01, 0.2, 0.25, 0.5, 0.9, 0.999, 1.001, 1.5, 3.0, 10.0, 1000.0,
        ] {
            let direct = if xi <= 1.0 {
                tanh_sinh(ring_kernel, 0.0, xi)
            } else {
                tanh_sinh(ring_kernel, 0.0, 1.0) + tanh_sinh(ring_kernel, 1.0, xi)
            };
            let closed = ring_kernel_antiderivative(xi);
            assert!(
                rel(closed, direct) < 1e-7,
                "S({xi}) = {closed}, quadrature {direct}"
            );
        }
        // Series and closed form agree where they meet.
        let (series, closed) = (ring_kernel_series(0.25), ring_kernel_antiderivative(0.25));
        assert!(rel(series, closed) < 1e-14);
    }

    #[test]
    fn kernel_reproduces_hertz_displacement() {
        // Hertz pressure p̃ = (8/π)·√(a² − ρ²) displaces w̃(ρ) − w̃(0) = −ρ² inside the contact and
        // w̃(0) = 2a² (δ = a²/R); P̃ = (16/3)a³.
        let a = 2.0;
        let kernel = RadialKernel::uniform(4.0, 401).unwrap();
        let p: Vec<f64> = kernel
            .rho()
            .iter()
            .map(|r| 8.0 / PI * (a * a - r * r).max(0.0).sqrt())
            .collect();
        let w = kernel.displacement(&p);
        assert!(rel(w[0], 2.0 * a * a) < 1e-3, "w(0) = {}", w[0]);
        for (r, wi) in kernel.rho().iter().zip(&w).filter(|(r, _)| **r < 0.9 * a) {
            assert!((wi - w[0] + r * r).abs() < 2e-3 * a * a, "ρ = {r}");
        }
        assert!(rel(kernel.load(&p), 16.0 / 3.0 * a.powi(3)) < 1e-3);
    }

    const B12_MU: f64 = 24.042_558_684_1;

    fn b12(d_star: f64, method: ScaledMethod) -> ScaledSolution {
        let kernel = RadialKernel::uniform(5.0, 100).unwrap();
        let options = ScaledOptions {
            method,
            ..ScaledOptions::default()
        };
        kernel.solve(B12_MU, d_star, None, &options).unwrap()
    }

    /// First ρ where p̃ falls below p̃(0)/100, linearly interpolated.
    fn one_percent_radius(s: &ScaledSolution) -> f64 {
        let level = 0.01 * s.pressure[0];
        let j = s.pressure.iter().position(|p| *p < level).unwrap();
        let t = (s.pressure[j - 1] - level) / (s.pressure[j - 1] - s.pressure[j]);
        s.rho[j - 1] + t * (s.rho[j] - s.rho[j - 1])
    }

    #[test]
    fn b12_contact_mechanics_reference() {
        // validation.md B12: μ = 24.0425586841, 100 points on [0, 5], mixing 0.1, tol 1e-6.
        let fixed = ScaledMethod::FixedPoint { mixing: 0.1 };
        for (d_star, p0, load, rho1) in
            [(0.5, 4.69319, 44.1697, 2.58), (1.0, 1.81926, 5.35602, 1.67)]
        {
            let s = b12(d_star, fixed);
            assert!(rel(s.pressure[0], p0) < 0.01);
            assert!(rel(s.load, load) < 0.01);
            assert!(rel(one_percent_radius(&s), rho1) < 0.01);
            assert!(
                s.pressure.windows(2).all(|w| w[1] < w[0]),
                "not strictly decreasing"
            );
            assert!(s.final_change < 1e-6);
        }
    }

    #[test]
    fn newton_reaches_the_fixed_point_solution() {
        let fixed = b12(0.5, ScaledMethod::FixedPoint { mixing: 0.1 });
        let newton = b12(0.5, ScaledMethod::Newton);
        assert!(newton.iterations < 20);
        // The fixed point stops at a change of 1e-6 per iteration with mixing 0.1.
        for (a, b) in fixed.pressure.iter().zip(&newton.pressure) {
            assert!((a - b).abs() < 1e-4, "{a} vs {b}");
        }
    }

    #[test]
    fn scaled_load_decreases_with_central_separation() {
        let kernel = RadialKernel::uniform(8.0, 120).unwrap();
        let options = ScaledOptions {
            method: ScaledMethod::Newton,
            tol: 1e-10,
            max_iter: 100,
        };
        let mut previous = f64::INFINITY;
        for d_star in [-6.0, -3.0, -1.0, 0.0, 0.5, 1.0, 2.0, 4.0] {
            let s = kernel.solve(3.0, d_star, None, &options).unwrap();
            assert!(s.load < previous, "N(d*) not decreasing at d* = {d_star}");
            assert!(rel(s.pressure[0], 3.0 * gt_f(1.5, d_star)) < 1e-9);
            previous = s.load;
        }
    }

    #[test]
    fn non_convergence_is_an_error() {
        let kernel = RadialKernel::uniform(5.0, 50).unwrap();
        let options = ScaledOptions {
            max_iter: 3,
            ..ScaledOptions::default()
        };
        let err = kernel.solve(B12_MU, 0.5, None, &options).unwrap_err();
        assert!(matches!(err, Error::InvalidArgument(ref m) if m.contains("did not converge")));
    }

    fn ps_sphere(h_rms_m: f64) -> GtParams {
        // Weber et al.: PS sphere R = 290 µm, E* = 3.7 GPa; summit radius 1 µm.
        GtParams::new(290e-6, 3.7e9, h_rms_m, 1e6)
    }

    #[test]
    fn hertz_limit() {
        // σ = 1e-4·δ_Hertz: the asperity layer is a stiff penalty, GT must give Hertz.
        let (force, radius, e_star) = (0.01, 290e-6, 3.7e9);
        let a = crate::mechanics::hertz::contact_radius(force, radius, e_star);
        let delta = a * a / radius;
        let params = ps_sphere(1e-4 * delta);
        let profile = gt_profile(&params, force).unwrap();
        assert!(rel(profile.load_n, force) < 1e-8);
        // Load at the same central compression δ = w(0) − d (measured: 0.13 %).
        let hertz_load = 4.0 / 3.0 * e_star * radius.sqrt() * profile.approach_m.powf(1.5);
        assert!(
            rel(hertz_load, force) < 0.02,
            "Hertz load at GT approach {hertz_load}"
        );
        // Pressure against p₀·√(1 − r²/a²) (measured: centre 0.1 %, rms 0.16 % and worst 2.2 %
        // of p₀, the worst at the edge, where GT rounds the square-root profile off).
        let p0 = 2.0 * e_star * a / (PI * radius);
        assert!(rel(profile.pressure_pa[0], p0) < 0.005);
        let deviations: Vec<f64> = profile
            .r_m
            .iter()
            .zip(&profile.pressure_pa)
            .map(|(r, p)| (p - p0 * (1.0 - (r / a).powi(2)).max(0.0).sqrt()) / p0)
            .collect();
        let rms = (dot(&deviations, &deviations) / deviations.len() as f64).sqrt();
        assert!(
            max_abs(&deviations) < 0.05 && rms < 0.005,
            "max {}, rms {rms}",
            max_abs(&deviations)
        );
        // The mean planes meet at the Hertz radius (u_GT ≈ 0 up to the penetration ~ 20σ).
        let edge = profile.separation_at(a);
        assert!(edge.abs() < 50.0 * params.sigma_m(), "u_GT(a) = {edge}");
    }

    #[test]
    fn profiles_over_the_paper_range() {
        // Roughness from 1 nm to 1 µm, loads 0.1 mN to 400 mN: the load search converges, the
        // pressure falls and the separation rises with r, and the tail check holds.
        let numerics = GtNumerics {
            points: 128,
            ..GtNumerics::default()
        };
        for h_rms in [1e-9, 1e-8, 1e-7, 1e-6] {
            for h2 in [1e5, 1e7] {
                for force in [1e-4, 4e-3, 0.4] {
                    let params = GtParams::new(290e-6, 3.7e9, h_rms, h2);
                    let what = format!("h_rms {h_rms}, h'' {h2}, N {force}");
                    let profile = gt_profile_with(&params, force, &numerics).expect(&what);
                    assert!(rel(profile.load_n, force) < 1e-8, "{what}");
                    let p = &profile.pressure_pa;
                    assert!(p.windows(2).all(|w| w[1] <= w[0] * (1.0 + 1e-9)), "{what}");
                    assert!(p[p.len() - 1] < 1e-6 * p[0], "{what}");
                    let u = &profile.separation_m;
                    assert!(u.windows(2).all(|w| w[1] > w[0]), "{what}");
                    // Roughness spreads the load: the centre never exceeds Hertz's p₀.
                    let a = crate::mechanics::hertz::contact_radius(force, 290e-6, 3.7e9);
                    assert!(p[0] < 1.001 * 2.0 * 3.7e9 * a / (PI * 290e-6), "{what}");
                    assert!(profile.gt_area_m2 > 0.0 && profile.gt_area_m2.is_finite());
                }
            }
        }
    }

    #[test]
    fn derived_parameters() {
        let p = GtParams::new(290e-6, 3.7e9, 50e-9, 2e6);
        assert_eq!(p.eta_h_beta, 0.05);
        assert!(rel(p.asperity_radius_m(), 0.5e-6) < 1e-15);
        assert!(rel(p.summit_density_per_m2(), 0.05 / (50e-9 * 0.5e-6)) < 1e-15);
        // With η = 0.05/(σβ), μ = (0.4/3)·√(2R/β) does not depend on σ.
        assert!(rel(p.mu(), 0.4 / 3.0 * (2.0 * 290e-6 / 0.5e-6_f64).sqrt()) < 1e-14);
        // N = P̃·E*σ^{3/2}√(R/2) = p̃·E*√(σ/8R) integrated over (√(2Rσ))² of area.
        let consistent = p.pressure_scale_pa() * p.length_scale_m().powi(2);
        assert!(rel(p.load_scale_n(), consistent) < 1e-14);
    }

    fn rough_profile() -> (GtParams, GtProfile) {
        let params = ps_sphere(50e-9);
        let profile = gt_profile(&params, 4e-3).unwrap();
        (params, profile)
    }

    #[test]
    fn bearing_area_of_a_constant_roughness_is_a_disc() {
        let (_, profile) = rough_profile();
        let (nx, ny, dx, dy) = (201, 151, 0.2e-6, 0.25e-6);
        let radius = 10e-6;
        let c = profile.separation_at(radius);
        let topo = Topography::new(Array2::from_elem((ny, nx), c), dx, dy).unwrap();
        for centre in [None, Some((15e-6, 20e-6))] {
            let map = gt_bearing_area(&topo, &profile, centre).unwrap();
            let (x0, y0) = centre.unwrap_or((0.5 * nx as f64 * dx, 0.5 * ny as f64 * dy));
            assert_eq!(map.centre_m, (x0, y0));
            // Contact exactly where u_GT(r) ≤ c.
            for ((iy, ix), &contact) in map.mask.indexed_iter() {
                let r = ((ix as f64 + 0.5) * dx - x0).hypot((iy as f64 + 0.5) * dy - y0);
                assert_eq!(contact, profile.separation_at(r) <= c, "pixel ({iy}, {ix})");
            }
            // u_GT rises with r, so that set is the disc of radius 10 µm.
            assert!(
                rel(map.area_m2, PI * radius * radius) < 0.01,
                "area {}",
                map.area_m2
            );
            assert_eq!(map.area_m2, map.contact_pixels as f64 * dx * dy);
            assert_eq!(
                map.contact_fraction,
                map.contact_pixels as f64 / (nx * ny) as f64
            );
            assert_eq!(map.gt_area_m2, profile.gt_area_m2);
        }
    }

    #[test]
    fn bearing_area_beyond_the_profile_follows_the_sphere() {
        let (_, profile) = rough_profile();
        let r_max = profile.r_m[profile.r_m.len() - 1];
        let u_max = profile.separation_m[profile.separation_m.len() - 1];
        assert_eq!(profile.separation_at(r_max), u_max);
        // Contact radius 1.5·r_max on 1 µm pixels.
        let radius = 1.5 * r_max;
        let c = u_max + (radius * radius - r_max * r_max) / (2.0 * profile.sphere_radius_m);
        let n = (2.0 * radius / 1e-6) as usize + 20;
        let topo = Topography::new(Array2::from_elem((n, n), c), 1e-6, 1e-6).unwrap();
        let map = gt_bearing_area(&topo, &profile, None).unwrap();
        assert!(
            rel(map.area_m2, PI * radius * radius) < 0.01,
            "area {}",
            map.area_m2
        );
    }

    #[test]
    fn bearing_fraction_of_gaussian_roughness_is_f0() {
        // i.i.d. Gaussian heights of deviation σ: a pixel at separation u is in contact with
        // probability F₀(u/σ) (methods.md §4.4), so the count matches Σ F₀ within noise.
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let (params, profile) = rough_profile();
        let sigma = params.sigma_m();
        let (n, dx) = (256, 0.1e-6);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2018);
        let normal = Normal::new(0.0, sigma).unwrap();
        let heights = Array2::from_shape_simple_fn((n, n), || normal.sample(&mut rng));
        let topo = Topography::new(heights, dx, dx).unwrap();
        let map = gt_bearing_area(&topo, &profile, None).unwrap();
        let (mut mean, mut variance) = (0.0, 0.0);
        for iy in 0..n {
            for ix in 0..n {
                let r = ((ix as f64 + 0.5 - 0.5 * n as f64) * dx)
                    .hypot((iy as f64 + 0.5 - 0.5 * n as f64) * dx);
                let q = gt_f(0.0, profile.separation_at(r) / sigma);
                mean += q;
                variance += q * (1.0 - q);
            }
        }
        let observed = map.contact_pixels as f64;
        assert!(
            mean > 100.0,
            "too few expected contacts ({mean}) for a useful test"
        );
        assert!(
            (observed - mean).abs() < 5.0 * variance.sqrt(),
            "{observed} vs {mean}"
        );
        // The overlap differs from GT's own area (methods.md §4.4); both are reported.
        assert!(map.gt_area_m2 > 0.0 && map.gt_area_m2 != map.area_m2);
    }

    #[test]
    fn invalid_input_is_an_error() {
        let good = ps_sphere(50e-9);
        let bad = [
            GtParams {
                sphere_radius_m: -290e-6,
                ..good
            },
            GtParams {
                e_star_pa: 0.0,
                ..good
            },
            GtParams {
                h_rms_m: f64::NAN,
                ..good
            },
            GtParams {
                h_double_prime_rms_per_m: 0.0,
                ..good
            },
            GtParams {
                eta_h_beta: -0.05,
                ..good
            },
            GtParams {
                sphere_radius_m: f64::INFINITY,
                ..good
            },
        ];
        for params in bad {
            assert!(matches!(
                gt_profile(&params, 4e-3),
                Err(Error::InvalidArgument(_))
            ));
        }
        for force in [0.0, -1e-3, f64::NAN, f64::INFINITY, 1e-300] {
            assert!(gt_profile(&good, force).is_err(), "force {force}");
        }
        let numerics = GtNumerics {
            points: 2,
            ..GtNumerics::default()
        };
        assert!(gt_profile_with(&good, 4e-3, &numerics).is_err());

        assert!(RadialKernel::new(vec![0.0, 1.0]).is_err());
        assert!(RadialKernel::new(vec![0.1, 1.0, 2.0]).is_err());
        assert!(RadialKernel::new(vec![0.0, 1.0, 1.0]).is_err());
        assert!(RadialKernel::new(vec![0.0, 1.0, f64::NAN]).is_err());
        assert!(RadialKernel::uniform(-1.0, 10).is_err());
        let kernel = RadialKernel::uniform(5.0, 20).unwrap();
        let newton = ScaledOptions {
            method: ScaledMethod::Newton,
            tol: 1e-8,
            max_iter: 50,
        };
        assert!(kernel.solve(0.0, 0.5, None, &newton).is_err());
        assert!(kernel.solve(1.0, f64::NAN, None, &newton).is_err());
        assert!(kernel.solve(1.0, 0.5, Some(&[0.0; 3]), &newton).is_err());
        for mixing in [0.0, 1.5, f64::NAN] {
            let options = ScaledOptions {
                method: ScaledMethod::FixedPoint { mixing },
                ..ScaledOptions::default()
            };
            assert!(kernel.solve(1.0, 0.5, None, &options).is_err());
        }
        assert!(kernel
            .solve(1.0, 0.5, None, &ScaledOptions { tol: 0.0, ..newton })
            .is_err());

        let (_, profile) = rough_profile();
        let topo = Topography::new(Array2::zeros((4, 4)), 1e-6, 1e-6).unwrap();
        assert!(gt_bearing_area(&topo, &profile, Some((f64::NAN, 0.0))).is_err());
        let empty = GtProfile {
            r_m: vec![],
            separation_m: vec![],
            ..profile
        };
        assert!(gt_bearing_area(&topo, &empty, None).is_err());
    }
}
