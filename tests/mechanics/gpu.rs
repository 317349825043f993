//! The GPU solver (feature `cuda`) against the CPU solver: the same operator to round-off and
//! the same contact and plastic maps, pixel for pixel, on the solver's test problems and on the
//! paper's rough sphere. Where no GPU is usable (no feature, no driver, no device) each test says
//! why and passes: the CPU tests are the same either way.

use contactscope::solver::cg::{solve_load_with, Plasticity, Problem, SolverOptions};
use contactscope::solver::gpu::{DeviceChoice, Gpu};
use contactscope::solver::halfspace::{Boundary, ElasticOperator};
use contactscope::solver::simulate::{sweep, LoadStep, Model, Setup};
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::Topography;
use rand::{Rng, SeedableRng};

fn gpu() -> Option<Gpu> {
    match Gpu::open(0) {
        Ok(gpu) => Some(gpu),
        Err(e) => {
            eprintln!("skipped: no usable GPU ({e})");
            None
        }
    }
}

#[test]
fn a_gpu_that_cannot_be_used_is_refused_in_one_line() {
    // The message names the flag as the command line writes it (in a process of its own, as
    // cargo-nextest runs each test, no other test has set that).
    crate::common::cli_names();
    let Err(e) = DeviceChoice::Cuda.open() else {
        eprintln!("skipped: a GPU is usable here");
        return;
    };
    let message = e.to_string();
    assert!(!message.contains('\n'), "{message}");
    assert!(message.contains("--device cuda"), "{message}");
    // `auto` falls back to the CPU instead.
    assert!(DeviceChoice::Auto.open().unwrap().is_none());
    assert!(DeviceChoice::Cpu.open().unwrap().is_none());
}

#[test]
fn gpu_operator_equals_the_host_operator() {
    let Some(gpu) = gpu() else { return };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    for (ny, nx, boundary) in [
        (40, 36, Boundary::Free),
        (64, 64, Boundary::Free),
        (32, 24, Boundary::Periodic),
    ] {
        let op = ElasticOperator::new(ny, nx, 0.7, 0.9, 2.5, boundary);
        let windows: &[(usize, usize)] = match boundary {
            Boundary::Free => &[(ny, nx), (9, 14), (17, 33)],
            Boundary::Periodic => &[(ny, nx)],
        };
        for &(h, w) in windows {
            let p: Vec<f64> = (0..h * w).map(|_| rng.random_range(0.0..1.0)).collect();
            let host_op = op.window(h, w);
            let mut host = vec![0.0; h * w];
            host_op.apply_window(&p, h, w, &mut host, &mut host_op.window_workspace(h));
            let device = gpu.displacement(&op, &p, h, w).unwrap();
            let scale = host.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = host
                .iter()
                .zip(&device)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                worst <= 1e-12 * scale,
                "{boundary:?} {ny}×{nx}, window {h}×{w}: max |Δu| {worst:.2e} of {scale:.2e}"
            );
        }
    }
}

/// Pixels where exactly one of the two is positive.
fn differing(a: &[f64], b: &[f64]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| (**x > 0.0) != (**y > 0.0))
        .count()
}

fn max_abs(a: &[f64]) -> f64 {
    a.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The same solve on both: 0 differing contact pixels, approach and pressure to `rel`.
#[test]
fn gpu_solves_the_sphere_as_the_host_for_every_bound() {
    let Some(gpu) = gpu() else { return };
    // Hertz geometry of the solver tests: R = 20, E* = 102, 128² over 5 length units.
    let (n, side, radius, e_star) = (128usize, 5.0, 20.0, 102.0);
    let dx = side / n as f64;
    let c = n as f64 / 2.0;
    let separation: Vec<f64> = (0..n * n)
        .map(|i| {
            let (x, y) = (
                ((i % n) as f64 + 0.5 - c) * dx,
                ((i / n) as f64 + 0.5 - c) * dx,
            );
            (x * x + y * y) / (2.0 * radius)
        })
        .collect();
    for boundary in [Boundary::Free, Boundary::Periodic] {
        let op = ElasticOperator::new(n, n, dx, dx, e_star, boundary);
        let problem = Problem {
            operator: &op,
            separation: &separation,
            pixel_area: dx * dx,
        };
        let cap = vec![9.0; n * n];
        let yield_pressure = vec![6.0; n * n];
        for (name, plasticity) in [
            ("elastic", Plasticity::Elastic),
            ("hardness", Plasticity::Cap(&cap)),
            (
                "hardening",
                Plasticity::Hardening {
                    yield_pressure: &yield_pressure,
                    compliance: 0.01,
                },
            ),
        ] {
            let cpu_options = SolverOptions {
                tolerance: 1e-10,
                ..SolverOptions::default()
            };
            let gpu_options = SolverOptions {
                gpu: Some(&gpu),
                ..cpu_options
            };
            let force = 15.0;
            let host = solve_load_with(&problem, force, plasticity, None, &cpu_options).unwrap();
            let device = solve_load_with(&problem, force, plasticity, None, &gpu_options).unwrap();
            let contact = differing(&host.pressure, &device.pressure);
            let dp = max_diff(&host.pressure, &device.pressure) / max_abs(&host.pressure);
            let da = (host.approach - device.approach).abs() / host.approach.abs();
            eprintln!(
                "{boundary:?} {name}: iterations cpu {} gpu {}, contact pixels {} differing {contact}, \
                 max |Δp|/max p {dp:.1e}, |Δδ|/δ {da:.1e}",
                host.iterations,
                device.iterations,
                host.contact_pixels()
            );
            assert_eq!(contact, 0, "{boundary:?} {name}: contact maps differ");
            assert!(
                dp < 1e-6,
                "{boundary:?} {name}: pressure differs by {dp:.2e}"
            );
            assert!(
                da < 1e-8,
                "{boundary:?} {name}: approach differs by {da:.2e}"
            );
            assert!((device.force / force - 1.0).abs() < 1e-9);
        }
    }
}

/// The paper's rough sphere (R = 290 µm, E* = 3.7 GPa, 65.5 µm box, H = 0.8, rms slope 0.1,
/// roll-off 4 µm) at `grid`², free boundaries.
fn paper_surface(grid: usize) -> (Topography, f64) {
    let dx = 65.536e-6 / grid as f64;
    let mut t = self_affine(&SelfAffineParams {
        nx: grid,
        ny: grid,
        dx_m: dx,
        hurst: 0.8,
        rolloff_wavelength_m: Some(4e-6),
        short_cutoff_wavelength_m: Some(128e-9_f64.max(2.0 * dx)),
        target: RmsTarget::Slope(0.1),
        seed: 2018,
    })
    .unwrap();
    let rms = t.rms_height();
    t.add_sphere(290e-6).unwrap();
    (t, rms)
}

fn ramp(topo: &Topography, rms: f64, model: Model, gpu: Option<&Gpu>) -> Vec<LoadStep> {
    let setup = Setup {
        topography: topo,
        e_star_pa: 3.7e9,
        boundary: Boundary::Free,
        model,
        options: SolverOptions {
            max_iterations: 20_000,
            tolerance: 1e-8,
            gap_scale_m: Some(rms),
            gpu,
            ..SolverOptions::default()
        },
    };
    sweep(&setup, &[4e-3, 40e-3, 400e-3], &|_, _| {}).unwrap()
}

#[test]
fn gpu_ramps_give_the_host_maps_on_the_paper_surface() {
    let Some(gpu) = gpu() else { return };
    let (topo, rms) = paper_surface(512);
    let models = [
        ("elastic", Model::Elastic),
        (
            "hardness",
            Model::Hardness {
                hardness_pa: 370e6,
                volume_conserving: None,
            },
        ),
        (
            "hardening",
            Model::Hardening {
                modulus_pa_per_m: 4e15,
                initial_pa: 0.0,
            },
        ),
    ];
    for (name, model) in models {
        let host = ramp(&topo, rms, model, None);
        let device = ramp(&topo, rms, model, Some(&gpu));
        for (a, b) in host.iter().zip(&device) {
            let contact = differing(&a.solution.pressure, &b.solution.pressure);
            let plastic = differing(&a.plastic_m, &b.plastic_m);
            let scale = max_abs(&a.plastic_m);
            let dh = max_diff(&a.plastic_m, &b.plastic_m);
            eprintln!(
                "512² {name} {:.0} mN: iterations cpu {} gpu {}, contact pixels {} differing \
                 {contact}, plastic pixels differing {plastic}, max |Δh_pl| {dh:.2e} of {scale:.2e} m",
                a.force_n * 1e3,
                a.solution.iterations,
                b.solution.iterations,
                a.solution.contact_pixels(),
            );
            assert_eq!(contact, 0, "{name} {} N: contact maps differ", a.force_n);
            assert_eq!(plastic, 0, "{name} {} N: plastic maps differ", a.force_n);
            assert!(dh <= 1e-6 * scale.max(1e-30), "{name}: plastic depth");
            let da = (a.solution.approach - b.solution.approach).abs();
            assert!(da <= 1e-6 * a.solution.approach.abs(), "{name}: approach");
        }
    }
}

#[test]
fn gpu_gives_the_volume_conserving_and_periodic_maps_of_the_host() {
    let Some(gpu) = gpu() else { return };
    let (topo, _) = paper_surface(256);
    let conserving = Model::Hardness {
        hardness_pa: 370e6,
        volume_conserving: Some(0.5),
    };
    let host = ramp(&topo, topo.rms_height(), conserving, None);
    let device = ramp(&topo, topo.rms_height(), conserving, Some(&gpu));
    for (a, b) in host.iter().zip(&device) {
        let contact = differing(&a.solution.pressure, &b.solution.pressure);
        let plastic = differing(&a.plastic_m, &b.plastic_m);
        eprintln!(
            "256² volume-conserving {:.0} mN: contact {} differing {contact}, plastic differing {plastic}",
            a.force_n * 1e3,
            a.solution.contact_pixels()
        );
        assert_eq!((contact, plastic), (0, 0));
    }
    // A periodic rough surface (no sphere) pressed to a few per cent of contact.
    let periodic = self_affine(&SelfAffineParams {
        nx: 256,
        ny: 256,
        dx_m: 100e-9,
        hurst: 0.8,
        rolloff_wavelength_m: Some(6.4e-6),
        short_cutoff_wavelength_m: Some(400e-9),
        target: RmsTarget::Slope(0.1),
        seed: 7,
    })
    .unwrap();
    for model in [
        Model::Elastic,
        Model::Hardness {
            hardness_pa: 370e6,
            volume_conserving: None,
        },
    ] {
        let run = |gpu: Option<&Gpu>| {
            let setup = Setup {
                topography: &periodic,
                e_star_pa: 3.7e9,
                boundary: Boundary::Periodic,
                model,
                options: SolverOptions {
                    max_iterations: 20_000,
                    tolerance: 1e-8,
                    gap_scale_m: Some(periodic.rms_height()),
                    gpu,
                    ..SolverOptions::default()
                },
            };
            sweep(&setup, &[20e-3, 200e-3], &|_, _| {}).unwrap()
        };
        for (a, b) in run(None).iter().zip(&run(Some(&gpu))) {
            let contact = differing(&a.solution.pressure, &b.solution.pressure);
            eprintln!(
                "256² periodic {} {:.0} mN: contact {} differing {contact}",
                model.name(),
                a.force_n * 1e3,
                a.solution.contact_pixels()
            );
            assert_eq!(contact, 0);
        }
    }
}

/// `--device`: `cuda` where no GPU is usable is one line naming the flag, with nothing
/// written; `auto` falls back to the CPU and says so in summary.json. With a usable GPU, `cuda`
/// runs there and says which.
#[test]
fn simulate_says_which_device_ran() {
    use crate::common::{rough_surface, run, stderr};
    let dir = tempfile::tempdir().unwrap();
    let surface = dir.path().join("rough.npy");
    rough_surface(
        &surface,
        64,
        "32nm",
        3,
        &["--rolloff", "1um", "--cutoff", "128nm"],
    );
    let simulate = |device: &str, out: &std::path::Path| {
        run(&[
            "simulate",
            "--topography",
            surface.to_str().unwrap(),
            "--pixel-size",
            "32nm",
            "--radius",
            "20um",
            "--modulus",
            "3.7GPa",
            "--model",
            "hardness",
            "--hardness",
            "370MPa",
            "--forces",
            "0.05,0.1mN",
            "--device",
            device,
            "--out",
            out.to_str().unwrap(),
            "-q",
        ])
    };
    let device_of = |out: &std::path::Path| {
        let text = std::fs::read_to_string(out.join("summary.json")).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        v["solver"]["device"].as_str().unwrap().to_string()
    };
    let usable = gpu().is_some();
    let auto = dir.path().join("auto");
    let o = simulate("auto", &auto);
    assert!(o.status.success(), "{}", stderr(&o));
    let ran = device_of(&auto);
    assert_eq!(ran.starts_with("cuda: "), usable, "{ran}");
    assert!(usable || ran == "cpu", "{ran}");
    let cuda = dir.path().join("cuda");
    let o = simulate("cuda", &cuda);
    if usable {
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(device_of(&cuda).starts_with("cuda: "));
    } else {
        let message = stderr(&o);
        assert!(!o.status.success());
        assert_eq!(message.trim().lines().count(), 1, "{message}");
        assert!(message.contains("--device cuda"), "{message}");
        assert!(!cuda.exists(), "nothing is written");
    }
}
