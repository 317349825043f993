//! The standard solver against the reference (the previous, unaccelerated solver: PK restarting
//! on every engagement, a root-find on the approach over displacement-controlled solves for the
//! bounded models) on a 256² load ramp of the paper's kind, for every model and plastic path.
//! Issue 10: contact and plastic maps equal at every load to ≤ 0.05 % of the contact pixels at
//! the same tolerance.

use contactscope::solver::cg::{Method, SolverOptions};
use contactscope::solver::halfspace::Boundary;
use contactscope::solver::simulate::{sweep, LoadStep, Model, Setup};
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::Topography;

/// A rough sphere (R = 290 µm) on a 256² map of 128 nm (32.8 µm): H = 0.8, rms slope 0.1,
/// roll-off 4 µm, cutoff 512 nm.
fn rough_sphere() -> Topography {
    sphere(256, 4e-6, 512e-9, 11)
}

/// A rough sphere (R = 290 µm) on an `n`² map of 128 nm: H = 0.8, rms slope 0.1.
fn sphere(n: usize, rolloff_m: f64, cutoff_m: f64, seed: u64) -> Topography {
    let mut t = self_affine(&SelfAffineParams {
        nx: n,
        ny: n,
        dx_m: 128e-9,
        hurst: 0.8,
        rolloff_wavelength_m: Some(rolloff_m),
        short_cutoff_wavelength_m: Some(cutoff_m),
        target: RmsTarget::Slope(0.1),
        seed,
    })
    .unwrap();
    t.add_sphere(290e-6).unwrap();
    t
}

fn ramp(topo: &Topography, model: Model, method: Method) -> Vec<LoadStep> {
    // 1, 5 and 25 mN: the contact grows from a few patches to a disc of 40 % of the map.
    ramp_at(topo, model, method, &[1e-3, 5e-3, 25e-3])
}

fn ramp_at(topo: &Topography, model: Model, method: Method, loads_n: &[f64]) -> Vec<LoadStep> {
    let setup = Setup {
        topography: topo,
        e_star_pa: 3.7e9,
        boundary: Boundary::Free,
        model,
        options: SolverOptions {
            max_iterations: 20_000,
            tolerance: 1e-8,
            method,
            ..SolverOptions::default()
        },
    };
    sweep(&setup, loads_n, &|_, _| {}).unwrap()
}

fn compare(name: &str, model: Model) {
    let topo = rough_sphere();
    let fast = ramp(&topo, model, Method::Standard);
    let slow = ramp(&topo, model, Method::Reference);
    same_maps(name, &fast, &slow, 1e-12);
}

/// Contact and plastic maps, approach and force balance (the standard solver's to `balance`).
fn same_maps(name: &str, fast: &[LoadStep], slow: &[LoadStep], balance: f64) {
    for (a, b) in fast.iter().zip(slow) {
        let load = a.force_n * 1e3;
        assert!(
            !a.edge_contact,
            "{name} {load} mN: the contact stays inside the map"
        );
        let contact = a.solution.contact_pixels();
        assert!(contact > 100, "{name} {load} mN: {contact} contact pixels");
        let differ = |x: &[f64], y: &[f64]| {
            x.iter()
                .zip(y)
                .filter(|(p, q)| (**p > 0.0) != (**q > 0.0))
                .count()
        };
        let contact_differ = differ(&a.solution.pressure, &b.solution.pressure);
        let plastic_differ = differ(&a.plastic_m, &b.plastic_m);
        let allowed = contact as f64 * 5e-4;
        assert!(
            contact_differ as f64 <= allowed && plastic_differ as f64 <= allowed,
            "{name} {load} mN: {contact_differ} contact and {plastic_differ} plastic pixels differ of {contact}"
        );
        let peak = b.plastic_m.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = a
            .plastic_m
            .iter()
            .zip(&b.plastic_m)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        assert!(
            worst <= 1e-6 * peak.max(1e-30),
            "{name} {load} mN: plastic displacement differs by {worst:e} m of {peak:e}"
        );
        let relative = (a.solution.approach - b.solution.approach).abs() / b.solution.approach;
        assert!(
            relative < 1e-6,
            "{name} {load} mN: approach differs by {relative:e}"
        );
        // The reference's root-find on δ stops at |F − W| ≤ tolerance·W; the standard solver
        // balances the load to round-off (unless it handed the load to the reference).
        assert!((a.solution.force / a.force_n - 1.0).abs() <= balance);
        assert!((b.solution.force / b.force_n - 1.0).abs() <= 1e-8);
    }
}

#[test]
fn elastic_ramp_equals_the_reference() {
    compare("elastic", Model::Elastic);
}

#[test]
fn hardness_ramp_equals_the_reference() {
    compare(
        "hardness",
        Model::Hardness {
            hardness_pa: 370e6,
            volume_conserving: None,
        },
    );
}

#[test]
fn volume_conserving_hardness_ramp_equals_the_reference() {
    compare(
        "hardness, Eq. 5",
        Model::Hardness {
            hardness_pa: 370e6,
            volume_conserving: Some(1.0),
        },
    );
}

#[test]
fn hardening_ramp_equals_the_reference() {
    compare(
        "hardening",
        Model::Hardening {
            modulus_pa_per_m: 4e15,
            initial_pa: 0.0,
        },
    );
}

/// A low hardness (20 MPa) on the paper's 512² map: after 7.7 mN nearly every loaded pixel is
/// at the cap, and at 14.9 mN the standard iteration cycles (the active set swaps ~14,000 pixels
/// back and forth); the stall guard hands the load to the reference algorithm. The ramp must
/// converge and give the reference's maps.
#[test]
fn a_stalled_low_hardness_ramp_gives_the_reference_maps() {
    let topo = sphere(512, 8e-6, 256e-9, 2018);
    let model = Model::Hardness {
        hardness_pa: 20e6,
        volume_conserving: None,
    };
    let loads = [4e-3, 7.72e-3, 14.9e-3];
    let fast = ramp_at(&topo, model, Method::Standard, &loads);
    let slow = ramp_at(&topo, model, Method::Reference, &loads);
    // The stalled load was finished by the reference: its balance is the reference's.
    same_maps("hardness 20 MPa", &fast, &slow, 1e-8);
}
