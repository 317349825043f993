//! Golden-section search for the minimum of a unimodal function on an interval: one evaluation
//! per step, the bracket shrinking by 1/φ ≈ 0.618, until it is narrower than an **absolute**
//! width (Kiefer 1953; Press et al., *Numerical Recipes*, 3rd ed., §10.2).
//!
//! Kept rather than taken from `argmin` (`GoldenSectionSearch`), whose stopping rule is relative
//! to the position, tolerance·(|x₁| + |x₂|) ≥ |x₃ − x₀| (argmin 0.11). Measured with the same
//! bracket and target width (`docs/performance.md`, "Numerics from crates"):
//! * `fit-hardening` searches ln(parameter), so a relative rule makes the work depend on the
//!   unit the parameter is expressed in: 14 evaluations in ln(Pa/m) but 21 in ln(MPa/nm) for
//!   the same 1 % in k, each evaluation a full contact simulation of every load;
//! * the squeeze fit's contact offset has its optimum near 0 m, where a relative rule is never
//!   met: argmin ran 803 iterations, until the bracket underflowed, unless capped.
//!
//! Both uses want a width in the variable itself, which is what this search stops on.

/// The minimiser's estimate (the better of the two interior points) and the final bracket.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoldenMinimum {
    /// Best point found.
    pub x: f64,
    /// Its function value.
    pub value: f64,
    /// Final bracket (lo, hi), narrower than the requested width.
    pub bracket: (f64, f64),
    /// Function evaluations made.
    pub evaluations: usize,
}

/// Minimum of `f` on [`lo`, `hi`] (f unimodal there) to a bracket narrower than `width`.
/// Errors of `f` are passed on; a value that compares false (NaN) counts as the larger one.
pub fn golden_section<E>(
    lo: f64,
    hi: f64,
    width: f64,
    f: &mut dyn FnMut(f64) -> Result<f64, E>,
) -> Result<GoldenMinimum, E> {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c)?, f(d)?);
    let mut evaluations = 2;
    while b - a > width {
        if fc <= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = f(c)?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = f(d)?;
        }
        evaluations += 1;
    }
    let (x, value) = if fc <= fd { (c, fc) } else { (d, fd) };
    Ok(GoldenMinimum {
        x,
        value,
        bracket: (a, b),
        evaluations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_parabola_minimum_with_one_evaluation_per_step() {
        let mut calls = 0;
        let m = golden_section(-3.0, 5.0, 1e-6, &mut |x| {
            calls += 1;
            Ok::<f64, ()>((x - 1.234).powi(2))
        })
        .unwrap();
        assert!((m.x - 1.234).abs() < 1e-6, "{}", m.x);
        assert_eq!(m.evaluations, calls);
        // 8 → 1e-6 takes ceil(ln(8e6)/ln φ) = 34 steps, plus the two first points.
        assert_eq!(calls, 36);
        assert!(m.bracket.1 - m.bracket.0 <= 1e-6 && m.bracket.0 <= 1.234 && 1.234 <= m.bracket.1);
    }

    #[test]
    fn an_optimum_at_zero_stops_on_width() {
        let m = golden_section(-2e-6, 1e-7, 1e-18, &mut |x| Ok::<f64, ()>(x * x)).unwrap();
        assert!(m.x.abs() < 1e-18, "{}", m.x);
        // 2.1e-6 → 1e-18: ceil(ln(2.1e12)/ln φ) = 59 steps, plus the two first points.
        assert_eq!(m.evaluations, 61);
    }

    #[test]
    fn errors_are_passed_on() {
        let r = golden_section(0.0, 1.0, 1e-3, &mut |x| {
            if x > 0.5 {
                Err("bad")
            } else {
                Ok(x)
            }
        });
        assert_eq!(r.unwrap_err(), "bad");
    }
}
