//! The paper's regime (Weber et al. 2018; issue 10): a rough sphere of R = 290 µm, E* = 3.7 GPa
//! pressed through the load ramp 4 / 40 / 400 mN on a 65.5 µm map with free boundaries, for the
//! elastic, penetration-hardness (p_Y = 370 MPa) and hardening (k = 4 MPa/nm) models, at
//! 1024² / 64 nm and 2048² / 32 nm (and 512² / 128 nm for quick runs). `harness = false`.
//!
//! Surface: [`self_affine`], H = 0.8, rms slope 0.1 (finite differences), roll-off wavelength
//! 16.4 µm (a quarter of the map), short cutoff 128 nm, seed 2018, plus the sphere. The same
//! physical surface at every grid would need one spectrum sampled three ways; here each grid
//! draws its own surface with these parameters (the cutoff is resolved by 4, 2 and 1 pixels at
//! 32, 64 and 128 nm).
//!
//! Per model and load it prints the CG iterations, wall and CPU seconds, ms per iteration, the
//! FFT share (2·apply·iterations / wall, each iteration applies G twice), the contact fraction,
//! the plastic volume, and at the end the peak RSS of the process. With `--method both` each ramp
//! is solved by the standard solver and by the reference (the previous solver: PK restarting on
//! every engagement, a root-find on δ for the bounded models) side by side, and the contact and
//! plastic maps are compared pixel by pixel.
//!
//! ```sh
//! cargo bench --bench paper                                          # 1024², all models
//! cargo bench --bench paper -- --grid 2048 --models hardening        # the 90 s target
//! cargo bench --bench paper -- --grid 512 --method both              # before/after, maps
//! ```
//!
//! `--device cpu|cuda|both` solves on the CPU, on the first CUDA GPU (feature `cuda`), or on
//! both side by side with the maps compared (`cargo bench --features cuda --bench paper --
//! --device both`); with the GPU it prints the peak device memory in use during a solve.
//!
//! Options: `--grid 512|1024|2048`, `--models elastic,hardness,hardening`, `--forces 4,40,400`
//! (mN), `--method standard|reference|both`, `--tolerance 1e-8`, `--restart 0.01|every`,
//! `--applies N` (timings of one operator application, default 10). Unknown arguments (cargo's
//! `--bench`) are ignored.
//!
//! `--whole all,contact,none` also runs, per model, the whole `simulate` job as the command line
//! does (`contactscope_jobs::simulate::files::run_to_folder`: statistics, sphere, solve, the maps
//! `--maps` chooses written as TIFFs, `areas.csv`, `summary.json`, the plot, the folder
//! committed) into a temporary folder, once per choice, and prints its wall time beside the
//! solve's. Not timed there: starting the process and reading the height map (the command line
//! reads a 2048² `.npy` in about 0.06 s).
//!
//! ```sh
//! cargo bench --bench paper -- --grid 2048 --models hardening --rolloff 8 --applies 0 --whole all,contact,none
//! ```

use std::time::Instant;

use contactscope::solver::cg::{Method, Restart, SolverOptions};
use contactscope::solver::gpu::Gpu;
use contactscope::solver::halfspace::{Boundary, ElasticOperator};
use contactscope::solver::simulate::{sweep, LoadStep, Model, Setup};
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::{Detrend, Topography};
use contactscope_jobs::heights::HeightInput;
use contactscope_jobs::simulate::files::run_to_folder;
use contactscope_jobs::simulate::{MapChoice, ModelChoice, SimulateRequest};

const BOX_M: f64 = 65.536e-6;
const E_STAR_PA: f64 = 3.7e9;
const RADIUS_M: f64 = 290e-6;
const HARDNESS_PA: f64 = 370e6;
const K_PA_PER_M: f64 = 4e15;

struct Args {
    grid: usize,
    models: Vec<String>,
    loads_mn: Vec<f64>,
    methods: Vec<Method>,
    tolerance: f64,
    restart: Restart,
    applies: usize,
    rolloff_m: f64,
    hardness_pa: f64,
    /// Solve on the CPU (false) and/or the GPU (true).
    devices: Vec<bool>,
    /// `--maps` choices of the whole-job runs (`--whole`); empty: none.
    whole: Vec<MapChoice>,
}

fn parse_args() -> Args {
    let mut args = Args {
        grid: 1024,
        models: vec!["elastic".into(), "hardness".into(), "hardening".into()],
        loads_mn: vec![4.0, 40.0, 400.0],
        methods: vec![Method::Standard],
        tolerance: 1e-8,
        restart: Restart::default(),
        applies: 10,
        rolloff_m: 4e-6,
        hardness_pa: HARDNESS_PA,
        devices: vec![false],
        whole: Vec::new(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().unwrap_or_else(|| panic!("{name} needs a value"));
        match a.as_str() {
            "--grid" => args.grid = value("--grid").parse().expect("--grid 512|1024|2048"),
            "--models" => {
                args.models = value("--models").split(',').map(String::from).collect();
            }
            "--forces" => {
                args.loads_mn = value("--forces")
                    .split(',')
                    .map(|v| v.parse().expect("--forces in mN"))
                    .collect();
            }
            "--method" => {
                args.methods = match value("--method").as_str() {
                    "standard" => vec![Method::Standard],
                    "reference" => vec![Method::Reference],
                    "both" => vec![Method::Reference, Method::Standard],
                    other => panic!("--method standard|reference|both, not {other}"),
                }
            }
            "--device" => {
                args.devices = match value("--device").as_str() {
                    "cpu" => vec![false],
                    "cuda" => vec![true],
                    "both" => vec![false, true],
                    other => panic!("--device cpu|cuda|both, not {other}"),
                }
            }
            "--tolerance" => args.tolerance = value("--tolerance").parse().expect("--tolerance"),
            "--restart" => {
                let v = value("--restart");
                args.restart = if v == "every" {
                    Restart::EveryChange
                } else {
                    Restart::Adaptive {
                        fraction: v.parse().expect("--restart fraction|every"),
                    }
                };
            }
            "--applies" => args.applies = value("--applies").parse().expect("--applies"),
            "--rolloff" => {
                args.rolloff_m = value("--rolloff").parse::<f64>().expect("--rolloff in µm") * 1e-6;
            }
            "--hardness" => {
                args.hardness_pa = value("--hardness")
                    .parse::<f64>()
                    .expect("--hardness in MPa")
                    * 1e6;
            }
            "--whole" => {
                args.whole = value("--whole")
                    .split(',')
                    .map(|m| m.parse().expect("--whole all,contact,none"))
                    .collect();
            }
            _ => {}
        }
    }
    args
}

/// The rough sphere, the rms height of its roughness and the roughness alone.
fn body(grid: usize, rolloff_m: f64) -> (Topography, f64, Topography) {
    let dx = BOX_M / grid as f64;
    let mut t = self_affine(&SelfAffineParams {
        nx: grid,
        ny: grid,
        dx_m: dx,
        hurst: 0.8,
        rolloff_wavelength_m: Some(rolloff_m),
        short_cutoff_wavelength_m: Some(128e-9_f64.max(2.0 * dx)),
        target: RmsTarget::Slope(0.1),
        seed: 2018,
    })
    .expect("surface parameters");
    println!(
        "surface: {grid}² of {:.0} nm, h_rms {:.1} nm, box {:.1} µm",
        dx * 1e9,
        t.rms_height() * 1e9,
        BOX_M * 1e6
    );
    let roughness_rms_m = t.rms_height();
    let roughness = t.clone();
    t.add_sphere(RADIUS_M).expect("radius");
    (t, roughness_rms_m, roughness)
}

/// The whole `simulate` job of one model into a temporary folder, once per `--maps` choice:
/// wall seconds and the files written.
fn whole_job(roughness: &Topography, model: Model, args: &Args, solve_s: f64) {
    for &maps in &args.whole {
        let mut request = SimulateRequest::new(
            HeightInput::Memory {
                topography: roughness.clone(),
                // As generated: the job adds the same sphere the solve above was given.
                detrend: Detrend::None,
                label: "paper surface".into(),
            },
            E_STAR_PA,
            ModelChoice::HalfSpace(model),
            args.loads_mn.iter().map(|f| f * 1e-3).collect(),
        );
        request.radius_m = Some(RADIUS_M);
        request.tolerance = args.tolerance;
        request.max_iterations = 20_000;
        request.maps = maps;
        let dir = tempfile::tempdir().expect("temporary folder");
        let out = dir.path().join("sim");
        let start = (Instant::now(), cpu_seconds());
        let (outcome, written) =
            run_to_folder(&request, &out, &[], &|_, _| {}, None, &[]).expect("simulate job");
        let (wall, cpu) = (start.0.elapsed().as_secs_f64(), cpu_seconds() - start.1);
        let bytes: u64 = written
            .iter()
            .filter_map(|p| std::fs::metadata(p).ok())
            .map(|m| m.len())
            .sum();
        let iterations: Vec<usize> = outcome.loads.iter().map(|l| l.iterations).collect();
        println!(
            "  whole simulate job, --maps {:<7}: {wall:.2} s wall ({cpu:.2} s CPU), {:.2}× the solve above; iterations {iterations:?}; {} files, {:.1} MB",
            maps.name(),
            wall / solve_s,
            written.len(),
            bytes as f64 / 1e6
        );
    }
}

fn model(name: &str, hardness_pa: f64) -> Model {
    match name {
        "elastic" => Model::Elastic,
        "hardness" => Model::Hardness {
            hardness_pa,
            volume_conserving: None,
        },
        "hardening" => Model::Hardening {
            modulus_pa_per_m: K_PA_PER_M,
            initial_pa: 0.0,
        },
        other => panic!("unknown model {other}"),
    }
}

/// CPU seconds of this process (user + system), from /proc/self/stat (clock ticks of 1/100 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit_once(')')
        .map(|(_, rest)| rest.split_whitespace().collect())
        .unwrap_or_default();
    let tick = |k: usize| {
        fields
            .get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (tick(11) + tick(12)) / 100.0
}

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn apply_ms(topo: &Topography, applies: usize) -> f64 {
    if applies == 0 {
        return f64::NAN;
    }
    let (ny, nx) = (topo.ny(), topo.nx());
    let op = ElasticOperator::new(ny, nx, topo.dx_m, topo.dy_m, E_STAR_PA, Boundary::Free);
    let p: Vec<f64> = (0..nx * ny).map(|i| (i % 7) as f64).collect();
    let mut u = vec![0.0; nx * ny];
    let mut work = op.workspace();
    op.apply(&p, &mut u, &mut work);
    let mut times: Vec<f64> = (0..applies)
        .map(|_| {
            let start = Instant::now();
            op.apply(&p, &mut u, &mut work);
            start.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() {
    let args = parse_args();
    let gpu = args.devices.contains(&true).then(|| {
        let gpu = Gpu::open(0).unwrap_or_else(|e| panic!("{e}"));
        println!("GPU: {}", gpu.name());
        gpu
    });
    let (topo, roughness_rms_m, roughness) = body(args.grid, args.rolloff_m);
    let apply = apply_ms(&topo, args.applies);
    println!(
        "one operator application (median of {}): {apply:.1} ms",
        args.applies
    );
    let loads: Vec<f64> = args.loads_mn.iter().map(|f| f * 1e-3).collect();
    println!(
        "{:<10} {:<9} {:>8} {:>6} {:>8} {:>8} {:>8} {:>6} {:>9} {:>11}",
        "model",
        "method",
        "load_mN",
        "iters",
        "wall_s",
        "cpu_s",
        "ms/iter",
        "fft%",
        "contact%",
        "V_pl_um3"
    );
    for name in &args.models {
        let mut ramps: Vec<(Method, Vec<LoadStep>)> = Vec::new();
        let mut solve_s = f64::NAN;
        let runs = args
            .methods
            .iter()
            .flat_map(|m| args.devices.iter().map(move |d| (*m, *d)));
        for (method, on_gpu) in runs {
            let label = format!(
                "{}{}",
                format!("{method:?}").to_lowercase(),
                if on_gpu { "-cuda" } else { "" }
            );
            let start = (Instant::now(), cpu_seconds());
            let last = std::cell::Cell::new(start);
            let setup = Setup {
                topography: &topo,
                e_star_pa: E_STAR_PA,
                boundary: Boundary::Free,
                model: model(name, args.hardness_pa),
                options: SolverOptions {
                    max_iterations: 20_000,
                    tolerance: args.tolerance,
                    monitor: None,
                    method,
                    restart: args.restart,
                    // As `simulate`: gap residuals relative to the roughness.
                    gap_scale_m: Some(roughness_rms_m),
                    gpu: if on_gpu { gpu.as_ref() } else { None },
                },
            };
            let steps = sweep(&setup, &loads, &|_, step| {
                let (t0, c0) = last.get();
                let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
                let it = step.solution.iterations;
                println!(
                    "{:<10} {:<9} {:>8.1} {:>6} {:>8.2} {:>8.2} {:>8.1} {:>6.0} {:>9.3} {:>11.4}",
                    name,
                    label,
                    step.force_n * 1e3,
                    it,
                    wall,
                    cpu,
                    wall * 1e3 / it.max(1) as f64,
                    200.0 * apply * 1e-3 * it as f64 / wall,
                    step.contact_fraction * 100.0,
                    step.plastic_m.iter().sum::<f64>() * topo.dx_m * topo.dy_m * 1e18,
                );
                last.set((Instant::now(), cpu_seconds()));
            })
            .expect("sweep");
            let (t0, c0) = start;
            solve_s = t0.elapsed().as_secs_f64();
            let total: usize = steps.iter().map(|s| s.solution.iterations).sum();
            println!(
                "{:<10} {:<9} {:>8} {:>6} {:>8.2} {:>8.2}  (whole ramp){}",
                name,
                label,
                "ramp",
                total,
                t0.elapsed().as_secs_f64(),
                cpu_seconds() - c0,
                if steps.iter().any(|s| s.edge_contact) {
                    "  EDGE CONTACT"
                } else {
                    ""
                }
            );
            ramps.push((method, steps));
        }

        if let [(_, a), (_, b)] = ramps.as_slice() {
            for (x, y) in a.iter().zip(b) {
                let contact = x
                    .solution
                    .pressure
                    .iter()
                    .zip(&y.solution.pressure)
                    .filter(|(p, q)| (**p > 0.0) != (**q > 0.0))
                    .count();
                let plastic = x
                    .plastic_m
                    .iter()
                    .zip(&y.plastic_m)
                    .filter(|(p, q)| (**p > 0.0) != (**q > 0.0))
                    .count();
                let scale = x.plastic_m.iter().fold(0.0f64, |m, v| m.max(*v));
                let worst = x
                    .plastic_m
                    .iter()
                    .zip(&y.plastic_m)
                    .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
                let pixels = x.solution.contact_pixels().max(1);
                println!(
                    "  {name} {:.1} mN: contact pixels differing {contact} of {pixels} ({:.4} %), plastic pixels differing {plastic}, max |Δh_pl| {:.2e} of max h_pl {:.2e} m",
                    x.force_n * 1e3,
                    100.0 * contact as f64 / pixels as f64,
                    worst,
                    scale
                );
            }
        }
        if !args.whole.is_empty() {
            // The solve's fields go first: the job holds its own.
            drop(ramps);
            whole_job(&roughness, model(name, args.hardness_pa), &args, solve_s);
        }
    }
    println!("peak RSS {:.0} MiB", peak_rss_mib());
    if let Some(gpu) = &gpu {
        println!(
            "peak GPU memory in use during a solve {:.0} MiB",
            gpu.peak_memory_used() as f64 / (1 << 20) as f64
        );
    }
}
