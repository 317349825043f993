//! Elastic half-space surface response to normal pressure.
//!
//! * Free boundaries: the displacement under uniform unit pressure on one rectangular pixel
//!   (Love 1929; K. L. Johnson, *Contact Mechanics*, 1985, §3.2, Eq. 3.25), written with `asinh`
//!   so that the far field does not cancel catastrophically (docs/methods.md §1.2):
//!   G(x, y) = [f(x+a, y+b) − f(x+a, y−b) − f(x−a, y+b) + f(x−a, y−b)] / (π E*),
//!   f(X, Y) = X·asinh(Y/|X|) + Y·asinh(X/|Y|), a = Δx/2, b = Δy/2.
//! * Periodic boundaries: the continuum multiplier û(q) = 2 p̂(q) / (E* |q|) (Johnson, Greenwood &
//!   Higginson 1985, App. 1; docs/methods.md §1.4), with the q = 0 mode set to zero: a mean pressure
//!   produces no mean displacement, and under load control the approach δ is the Lagrange
//!   multiplier of the load.

/// `X·asinh(Y/|X|) + Y·asinh(X/|Y|)`, each term 0 when its prefactor is 0.
fn corner(x: f64, y: f64) -> f64 {
    let term = |p: f64, q: f64| {
        if p == 0.0 {
            0.0
        } else {
            p * (q / p.abs()).asinh()
        }
    };
    term(x, y) + term(y, x)
}

/// Surface displacement at offset (x, y) from the centre of a `dx × dy` pixel under unit pressure,
/// for contact modulus `e_star` (same length unit for all lengths; result in length/pressure).
pub fn love_pixel(x: f64, y: f64, dx: f64, dy: f64, e_star: f64) -> f64 {
    let (a, b) = (dx / 2.0, dy / 2.0);
    (corner(x + a, y + b) - corner(x + a, y - b) - corner(x - a, y + b) + corner(x - a, y - b))
        / (std::f64::consts::PI * e_star)
}

/// Periodic compliance 2/(E*|q|) at wavevector magnitude `q` (rad per length); 0 at q = 0.
pub fn periodic_compliance(q: f64, e_star: f64) -> f64 {
    if q == 0.0 {
        0.0
    } else {
        2.0 / (e_star * q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn self_coefficient_and_far_field() {
        // docs/validation.md B1: G(0,0) = (4/π) ln(1+√2) Δ/E* = 1.1221997 Δ/E*.
        let g0 = love_pixel(0.0, 0.0, 1.0, 1.0, 1.0);
        let exact = 4.0 / std::f64::consts::PI * (1.0 + 2f64.sqrt()).ln();
        assert!((g0 - exact).abs() < 1e-12 * exact);
        assert!((g0 - 1.1221997).abs() < 1e-7);
        // Far field → Boussinesq 1/(π E* r) per unit force (force = Δ²).
        for (r, reference) in [(20.0, 1.000104), (50.0, 1.000017)] {
            let ratio = love_pixel(r, 0.0, 1.0, 1.0, 1.0) * std::f64::consts::PI * r;
            assert!((ratio - reference).abs() < 2e-6, "r = {r}: {ratio}");
        }
        let g = |x: f64, y: f64| love_pixel(x, y, 1.0, 1.0, 3.0);
        for (x, y) in [(2.0, 5.0), (7.0, 1.0), (0.0, 3.0)] {
            assert!((g(x, y) - g(-x, y)).abs() < 1e-15);
            assert!((g(x, y) - g(x, -y)).abs() < 1e-15);
            assert!((g(x, y) - g(y, x)).abs() < 1e-15);
        }
        // Scaling: Δ and E* enter as Δ/E*.
        assert!((love_pixel(0.0, 0.0, 2.0, 2.0, 4.0) - exact / 2.0).abs() < 1e-12);
    }
}
