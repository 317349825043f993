//! Hertz reference formulas for a sphere on a flat (K. L. Johnson, *Contact Mechanics*, 1985,
//! §4.2; Weber et al. 2018, Eq. 3). SI units throughout.

/// Contact radius a = (3PR / 4E*)^(1/3) in metres, for force `force_n` (N), sphere radius
/// `radius_m` (m) and contact modulus `e_star_pa` (Pa).
pub fn contact_radius(force_n: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    (3.0 * force_n * radius_m / (4.0 * e_star_pa)).cbrt()
}

/// Contact area πa² in m².
pub fn contact_area(force_n: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    std::f64::consts::PI * contact_radius(force_n, radius_m, e_star_pa).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_scale() {
        // validation.md B20: R = 290 µm, E* = 3.7 GPa: a = 6.172 µm at 4 mN, 28.649 µm at 400 mN.
        assert!((contact_radius(4e-3, 290e-6, 3.7e9) * 1e6 - 6.172).abs() < 5e-4);
        assert!((contact_radius(0.4, 290e-6, 3.7e9) * 1e6 - 28.649).abs() < 5e-4);
        let a = contact_radius(0.01, 290e-6, 3.7e9);
        assert!((contact_area(0.01, 290e-6, 3.7e9) - std::f64::consts::PI * a * a).abs() < 1e-24);
    }
}
