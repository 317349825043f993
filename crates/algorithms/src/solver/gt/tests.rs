//! Tests of the Greenwood–Tripp model (docs/validation.md B11, B12) against references.

use std::f64::consts::PI;

use ndarray::Array2;

use super::functions::*;
use super::kernel::*;
use super::profile::*;
use super::*;
use crate::error::Error;
use crate::surface::Topography;

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
    // docs/validation.md B11, quoted to 7 decimals.
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
    // docs/validation.md B12: μ = 24.0425586841, 100 points on [0, 5], mixing 0.1, tol 1e-6.
    let fixed = ScaledMethod::FixedPoint { mixing: 0.1 };
    for (d_star, p0, load, rho1) in [(0.5, 4.69319, 44.1697, 2.58), (1.0, 1.81926, 5.35602, 1.67)] {
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
    assert!(
        matches!(err, Error::NotConverged { iterations: 3, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("did not converge"), "{err}");
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
    // probability F₀(u/σ) (docs/methods.md §4.4), so the count matches Σ F₀ within noise.
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
    // The overlap differs from GT's own area (docs/methods.md §4.4); both are reported.
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
            Err(Error::Value { .. })
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
