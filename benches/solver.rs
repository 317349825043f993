//! Contact-solver benchmark (`harness = false`): Polonsky–Keer load control
//! ([`solve_load`], elastic) on
//!
//! | name           | surface                                   | grid  | FFT size        |
//! |----------------|-------------------------------------------|-------|-----------------|
//! | `sphere512`    | rough sphere, free boundaries, 0.27 mN    | 512²  | 1024² (padded)  |
//! | `sphere1024`   | rough sphere, free boundaries, 2.1 mN     | 1024² | 2048² (padded)  |
//! | `periodic2048` | self-affine, periodic, p̄ = 0.03·E*·h'_rms | 2048² | 2048²           |
//!
//! Surfaces: 32 nm pixels, [`self_affine`] with H = 0.8, roll-off wavelength 1/4 of the map,
//! short cutoff 4 px, finite-difference rms slope 0.1 ([`RmsTarget::Slope`]), seed 2018; the
//! spheres add a paraboloid of R = 290 µm ([`Topography::add_sphere`]). E* = 3.7 GPa. The sphere
//! loads give a Hertz radius a = 2.5 µm (512²) and 5 µm (1024²), N = 4E*a³/(3R).
//!
//! Per problem it prints: surface and operator set-up times; the median of `--applies` timings
//! of one [`ElasticOperator::apply`] (half before, half after the solves); `--repeats` full
//! solves (iterations, median solve time, time per iteration); the FFT share
//! `2·apply / (time per iteration)` (each Polonsky–Keer iteration applies G twice: u = G∗p and
//! r = G∗t); the contact fraction, whether the contact touches the border of a free map, and a
//! digest of the pressure bits (equal digests: bit-identical results, to compare builds).
//! `tolcheck` solves `sphere512` at `--tolerance` and at 1e-10 and compares the contact sets.
//!
//! ```sh
//! cargo bench --bench solver                                   # everything
//! cargo bench --bench solver -- --only sphere1024 --repeats 1  # one problem
//! cargo bench --bench solver -- --only periodic2048 --repeats 0 --applies 40   # apply only
//! # peak RSS: run the executable that `cargo bench --bench solver --no-run` names
//! /usr/bin/time -v target/release/deps/solver-HASH --only sphere1024 --repeats 1
//! ```
//!
//! Options: `--only NAME` (repeatable), `--repeats N` (default 3; 0: time `apply` only),
//! `--applies N` (default 20), `--tolerance T` (default 1e-8). Unknown arguments (cargo's
//! `--bench`) are ignored.

use std::hint::black_box;
use std::time::Instant;

use contactscope::solver::cg::{solve_load, Problem, Solution, SolverOptions};
use contactscope::solver::halfspace::{Boundary, ElasticOperator};
use contactscope::solver::simulate::separation;
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::Topography;

const PIXEL_M: f64 = 32e-9;
const E_STAR_PA: f64 = 3.7e9;
const RADIUS_M: f64 = 290e-6;
const HURST: f64 = 0.8;
const RMS_SLOPE: f64 = 0.1;
const SEED: u64 = 2018;

struct Args {
    only: Vec<String>,
    repeats: usize,
    applies: usize,
    tolerance: f64,
}

fn parse_args() -> Args {
    let mut args = Args {
        only: Vec::new(),
        repeats: 3,
        applies: 20,
        tolerance: 1e-8,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().unwrap_or_else(|| panic!("{name} needs a value"));
        match a.as_str() {
            "--only" => args.only.push(value("--only")),
            "--repeats" => args.repeats = value("--repeats").parse().expect("--repeats"),
            "--applies" => args.applies = value("--applies").parse().expect("--applies"),
            "--tolerance" => args.tolerance = value("--tolerance").parse().expect("--tolerance"),
            _ => {}
        }
    }
    args
}

/// One benchmark problem.
struct Case {
    name: &'static str,
    n: usize,
    boundary: Boundary,
    topography: Topography,
    force_n: f64,
    /// rms height of the roughness alone (before the sphere), m.
    roughness_rms_m: f64,
}

fn surface(n: usize) -> Topography {
    self_affine(&SelfAffineParams {
        nx: n,
        ny: n,
        dx_m: PIXEL_M,
        hurst: HURST,
        rolloff_wavelength_m: Some(n as f64 * PIXEL_M / 4.0),
        short_cutoff_wavelength_m: Some(4.0 * PIXEL_M),
        target: RmsTarget::Slope(RMS_SLOPE),
        seed: SEED,
    })
    .expect("surface parameters")
}

fn build(name: &str) -> Case {
    match name {
        "sphere512" | "sphere1024" => {
            let (n, hertz_radius_m): (usize, f64) = if name == "sphere512" {
                (512, 2.5e-6)
            } else {
                (1024, 5e-6)
            };
            let mut topography = surface(n);
            let roughness_rms_m = topography.rms_height();
            topography.add_sphere(RADIUS_M).expect("radius");
            Case {
                name: if n == 512 { "sphere512" } else { "sphere1024" },
                n,
                boundary: Boundary::Free,
                topography,
                force_n: 4.0 * E_STAR_PA * hertz_radius_m.powi(3) / (3.0 * RADIUS_M),
                roughness_rms_m,
            }
        }
        "periodic2048" => {
            let n = 2048;
            let topography = surface(n);
            let mean_pressure = 0.03 * E_STAR_PA * RMS_SLOPE;
            Case {
                name: "periodic2048",
                n,
                boundary: Boundary::Periodic,
                force_n: mean_pressure * topography.area_m2(),
                roughness_rms_m: topography.rms_height(),
                topography,
            }
        }
        other => panic!("unknown problem {other}"),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

fn edge_contact(pressure: &[f64], n: usize) -> bool {
    (0..n * n).any(|i| {
        let (x, y) = (i % n, i / n);
        pressure[i] > 0.0 && (x == 0 || y == 0 || x == n - 1 || y == n - 1)
    })
}

/// FNV-1a over the bits of a field: equal digests mean bit-identical results (to compare builds).
fn digest(values: &[f64]) -> u64 {
    values.iter().fold(0xcbf2_9ce4_8422_2325, |h, v| {
        (h ^ v.to_bits()).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Largest distance of a contact pixel from the map centre, m.
fn contact_extent(pressure: &[f64], n: usize, dx: f64) -> f64 {
    let c = (n as f64 - 1.0) / 2.0;
    (0..n * n)
        .filter(|&i| pressure[i] > 0.0)
        .map(|i| ((i % n) as f64 - c).hypot((i / n) as f64 - c) * dx)
        .fold(0.0, f64::max)
}

fn solve(problem: &Problem, force: f64, tolerance: f64) -> (Solution, f64) {
    let options = SolverOptions {
        tolerance,
        ..SolverOptions::default()
    };
    let start = Instant::now();
    let solution = solve_load(problem, force, &options).expect("solver converges");
    (solution, start.elapsed().as_secs_f64())
}

fn run(case: &Case, setup_s: f64, args: &Args) {
    let n = case.n;
    let topo = &case.topography;
    let start = Instant::now();
    let operator = ElasticOperator::new(n, n, topo.dx_m, topo.dy_m, E_STAR_PA, case.boundary);
    let operator_s = start.elapsed().as_secs_f64();
    let fft = match case.boundary {
        Boundary::Free => 2 * n,
        Boundary::Periodic => n,
    };
    let s = separation(topo);
    let problem = Problem {
        operator: &operator,
        separation: &s,
        pixel_area: topo.dx_m * topo.dy_m,
    };

    // One operator application on a uniform pressure (the cost does not depend on the values),
    // timed before and after the solves (half of `--applies` each) so that a load change on the
    // machine shows up in both.
    let time_applies = |count: usize| -> Vec<f64> {
        let p = vec![case.force_n / topo.area_m2(); n * n];
        let mut u = vec![0.0; n * n];
        let mut work = operator.workspace();
        operator.apply(&p, &mut u, &mut work);
        (0..count)
            .map(|_| {
                let t = Instant::now();
                operator.apply(black_box(&p), &mut u, &mut work);
                black_box(&u);
                t.elapsed().as_secs_f64()
            })
            .collect()
    };
    let mut apply = time_applies(args.applies.div_ceil(2));
    if args.repeats == 0 {
        apply.extend(time_applies(args.applies / 2));
        println!(
            "{}: apply median {:.2} ms of {} (min {:.2})",
            case.name,
            median(apply.clone()) * 1e3,
            apply.len(),
            apply.iter().copied().fold(f64::INFINITY, f64::min) * 1e3
        );
        return;
    }

    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..args.repeats {
        let (solution, t) = solve(&problem, case.force_n, args.tolerance);
        times.push(t);
        last = Some(solution);
    }
    let solution = last.expect("one solve");
    apply.extend(time_applies(args.applies / 2));
    let apply_s = median(apply.clone());
    let solve_s = median(times.clone());
    let per_iteration = solve_s / solution.iterations as f64;
    let contact = solution.contact_pixels();
    println!(
        "{name}: grid {n}² FFT {fft}² {boundary:?}, load {force:.4e} N, tolerance {tol:e}",
        name = case.name,
        boundary = case.boundary,
        force = case.force_n,
        tol = args.tolerance,
    );
    println!(
        "  surface {setup_s:.3} s (roughness h_rms {:.1} nm), operator set-up {operator_s:.3} s",
        case.roughness_rms_m * 1e9
    );
    println!(
        "  apply: median {:.2} ms of {} (min {:.2}, max {:.2})",
        apply_s * 1e3,
        apply.len(),
        apply.iter().copied().fold(f64::INFINITY, f64::min) * 1e3,
        apply.iter().copied().fold(0.0, f64::max) * 1e3,
    );
    println!(
        "  solve: {} iterations, median {:.3} s of {:?} s -> {:.1} ms/iteration",
        solution.iterations,
        solve_s,
        times
            .iter()
            .map(|t| (t * 1e3).round() / 1e3)
            .collect::<Vec<_>>(),
        per_iteration * 1e3
    );
    if case.boundary == Boundary::Free {
        println!(
            "  contact extent: farthest contact pixel {:.2} µm from the centre (map half-width \
             {:.2} µm)",
            contact_extent(&solution.pressure, n, topo.dx_m) * 1e6,
            n as f64 * topo.dx_m / 2.0 * 1e6
        );
    }
    println!(
        "  FFT share 2·apply/iteration = {:.1} %, non-FFT {:.1} ms/iteration",
        200.0 * apply_s / per_iteration,
        (per_iteration - 2.0 * apply_s) * 1e3
    );
    println!(
        "  contact {contact} px = {:.4} %, edge contact {}, gap residual {:.2e}, pressure change {:.2e}, force {:.6e} N, pressure digest {:016x}",
        100.0 * contact as f64 / (n * n) as f64,
        case.boundary == Boundary::Free && edge_contact(&solution.pressure, n),
        solution.gap_residual,
        solution.pressure_change,
        solution.force,
        digest(&solution.pressure),
    );
}

/// The contact set at `--tolerance` against 1e-10 on `sphere512`.
fn tolerance_check(args: &Args) {
    let case = build("sphere512");
    let topo = &case.topography;
    let n = case.n;
    let operator = ElasticOperator::new(n, n, topo.dx_m, topo.dy_m, E_STAR_PA, case.boundary);
    let s = separation(topo);
    let problem = Problem {
        operator: &operator,
        separation: &s,
        pixel_area: topo.dx_m * topo.dy_m,
    };
    let (coarse, _) = solve(&problem, case.force_n, args.tolerance);
    let (fine, _) = solve(&problem, case.force_n, 1e-10);
    let differ = coarse
        .pressure
        .iter()
        .zip(&fine.pressure)
        .filter(|(a, b)| (**a > 0.0) != (**b > 0.0))
        .count();
    let scale = fine.pressure.iter().copied().fold(0.0, f64::max);
    let worst = coarse
        .pressure
        .iter()
        .zip(&fine.pressure)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    println!(
        "tolcheck sphere512: {:e}: {} px in contact, {} iterations; 1e-10: {} px, {} iterations; \
         pixels whose contact state differs: {differ}; max |Δp| / max p = {:.2e}",
        args.tolerance,
        coarse.contact_pixels(),
        coarse.iterations,
        fine.contact_pixels(),
        fine.iterations,
        worst / scale
    );
}

fn main() {
    let args = parse_args();
    let all = ["sphere512", "sphere1024", "periodic2048", "tolcheck"];
    let wanted: Vec<&str> = if args.only.is_empty() {
        all.to_vec()
    } else {
        args.only.iter().map(String::as_str).collect()
    };
    println!(
        "rayon threads {}, repeats {}, applies {}",
        rayon::current_num_threads(),
        args.repeats,
        args.applies
    );
    for name in wanted {
        if name == "tolcheck" {
            tolerance_check(&args);
            continue;
        }
        let start = Instant::now();
        let case = build(name);
        run(&case, start.elapsed().as_secs_f64(), &args);
    }
}
