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

/// Approach δ = a²/R (m) at force `force_n`.
pub fn approach(force_n: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    contact_radius(force_n, radius_m, e_star_pa).powi(2) / radius_m
}

/// Force N = (4/3)E*R^½δ^{3/2} at approach `delta_m`.
pub fn force_at_approach(delta_m: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    4.0 / 3.0 * e_star_pa * radius_m.sqrt() * delta_m.powf(1.5)
}

/// Peak pressure p₀ = 3N/(2πa²).
pub fn peak_pressure(force_n: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    let a = contact_radius(force_n, radius_m, e_star_pa);
    3.0 * force_n / (2.0 * std::f64::consts::PI * a * a)
}

/// Pressure p₀√(1 − r²/a²) at distance `r_m` from the centre (0 outside the contact).
pub fn pressure_at(r_m: f64, force_n: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    let a = contact_radius(force_n, radius_m, e_star_pa);
    peak_pressure(force_n, radius_m, e_star_pa) * (1.0 - (r_m / a).powi(2)).max(0.0).sqrt()
}

/// Elastic energy (8/15)E*R^½δ^{5/2} at approach `delta_m`.
pub fn elastic_energy(delta_m: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    8.0 / 15.0 * e_star_pa * radius_m.sqrt() * delta_m.powf(2.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_scale() {
        // docs/validation.md B20: R = 290 µm, E* = 3.7 GPa: a = 6.172 µm at 4 mN, 28.649 µm at 400 mN.
        assert!((contact_radius(4e-3, 290e-6, 3.7e9) * 1e6 - 6.172).abs() < 5e-4);
        assert!((contact_radius(0.4, 290e-6, 3.7e9) * 1e6 - 28.649).abs() < 5e-4);
        let a = contact_radius(0.01, 290e-6, 3.7e9);
        assert!((contact_area(0.01, 290e-6, 3.7e9) - std::f64::consts::PI * a * a).abs() < 1e-24);
    }

    #[test]
    fn reference_values() {
        // docs/validation.md B3 (CM `test_Hertz_refVals`): E* = 5, R = 4, F = 7.
        let rel = |a: f64, b: f64| (a - b).abs() / b;
        assert!(rel(approach(7.0, 4.0, 5.0), 0.6507879989531481) < 1e-7);
        assert!(rel(contact_radius(7.0, 4.0, 5.0), 1.6134286460245437) < 1e-7);
        assert!(rel(peak_pressure(7.0, 4.0, 5.0), 1.2839257217043503) < 1e-7);
        // B3 displacement control δ = 0.1, R = 20, E* = 102.
        assert!(rel(force_at_approach(0.1, 20.0, 102.0), 19.233304) < 1e-7);
        assert!(rel(elastic_energy(0.1, 20.0, 102.0), 0.769332) < 1e-6);
        assert!(rel(approach(15.0, 20.0, 102.0), 0.0847276) < 1e-6);
    }
}
