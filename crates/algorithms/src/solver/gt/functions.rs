//! The special functions of the Greenwood–Tripp model: the integrals F_n of the Gaussian summit
//! heights, the complete elliptic integrals and the ring-load kernel built from them.

use std::f64::consts::{FRAC_2_PI, PI, SQRT_2};

/// 1/√(2π), the peak of the standard normal density.
pub(super) const FRAC_1_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

pub(super) fn normal_pdf(z: f64) -> f64 {
    FRAC_1_SQRT_2PI * (-0.5 * z * z).exp()
}

/// Complementary error function: `libm::erfc` (the FreeBSD/musl implementation). Against
/// 50-digit mpmath values at 22 points in [−3, 27] its worst relative error is 1.5e-16, ours
/// (a series below 1.5 and Laplace's continued fraction above) was 3.3e-15, and it is 8× faster
/// (33 ns against 263 ns per call); `docs/performance.md`, "Numerics from crates".
pub(super) fn erfc(x: f64) -> f64 {
    libm::erfc(x)
}

/// The Greenwood–Tripp integral F_n(t) = ∫_t^∞ (z − t)^n φ(z) dz, φ the standard normal density.
///
/// Implemented for the orders the model needs, n = 0, ½, 1 and 3/2 (F₀ is the fraction of
/// summits in contact, F₁ their area, F_{3/2} their load; F_{1/2} = −(2/3)·dF_{3/2}/dt enters the
/// Newton Jacobian); any other `n` returns NaN. Relative accuracy is about 1e-13 or better
/// wherever the value is a normal floating-point number (`docs/validation.md` B11 asks for 1e-7):
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

pub(super) fn f_zero(t: f64) -> f64 {
    0.5 * erfc(t / SQRT_2)
}

/// F₁ = φ(t) − t·F₀(t). For large t the two terms agree to about 1/t², so the result keeps
/// about 1e-16·t² relative accuracy (1e-13 at t = 30, beyond which φ underflows anyway).
pub(super) fn f_one(t: f64) -> f64 {
    normal_pdf(t) - t * f_zero(t)
}

/// Trapezoidal nodes over the window. The hardest case is t ≈ −10, where the window starts at
/// s = 0 but the peak at s = √10 is narrow: 32 nodes leave 6e-10 there, 40 or more reach the
/// rounding floor (≈ 1e-13) for all t.
pub(super) const HALF_ORDER_NODES: usize = 48;

/// (F_{1/2}(t), F_{3/2}(t)) from one pass over shared nodes.
pub(super) fn f_half_orders(t: f64) -> (f64, f64) {
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
pub(super) fn f_moment_expansion(n: f64, big_t: f64) -> f64 {
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
///
/// Kept rather than taken from the `ellip` crate, for speed (`docs/performance.md`, "Numerics
/// from crates"). The crate's accurate route is Bulirsch's cel1(k′), cel2(k′, 1, k′²) with the
/// complementary modulus k′ (its parameter form ellipk(m = k²) loses up to 2.7e-11 near k = 1);
/// against 50-digit mpmath values up to k = 1 − 2⁻⁴⁵ it matches ours for K (1.7e-16) and is
/// better for E (3.8e-16 against 3.8e-15), far below anything the GT model needs (1e-7,
/// `docs/validation.md` B11). But one pass of this mean gives both integrals, where the crate needs
/// two evaluations: 47 against 31 ns per pair, and the GT kernel build (256 points) takes 9.0 ms
/// instead of 7.0 ms.
pub(super) fn elliptic_pair(k: f64) -> (f64, f64) {
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
/// **modulus** k (scipy's `ellipk` takes m = k²).
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

/// Complete elliptic integral of the second kind E(k) = ∫_0^{π/2} √(1 − k² sin²θ) dθ, modulus k.
/// E(±1) = 1; |k| > 1 or NaN gives NaN.
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
/// (`docs/methods.md` §4.2): the deflection at radius r per unit pressure on the ring at radius rξ.
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

pub(super) fn ring_kernel_series(xi: f64) -> f64 {
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
