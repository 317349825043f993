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

use crate::error::{Error, Result};

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
}
