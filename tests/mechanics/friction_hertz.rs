//! `contactscope friction` and `contactscope hertz`: known τ and E* recovered from seeded
//! synthetic data, slip detection that a later spike cannot fool, bad input, all-or-nothing
//! outputs.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::{column, read_csv, run, stderr, stdout};
use contactscope::mechanics::friction::{detect_slip, SlipCriterion, SlipOptions, XAxis};
use contactscope::mechanics::hertz;
use contactscope::mechanics::squeeze::fit_hertz;
use contactscope::synth::traces::{
    synthetic_trace, trace_csv, CsvLayout, SyntheticTrace, TraceParams,
};
use contactscope_formats::param::Param;
use contactscope_jobs::friction::{files::run_to_folder, FrictionOutcome, FrictionRequest};
use contactscope_jobs::hertz::{files::run_to_folder as hertz_to_folder, HertzRequest};
use contactscope_jobs::mechanics_csv::{read_squeeze, read_trace};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

const TAU_PA: f64 = 50e6;
const LOADS_MN: [f64; 4] = [4.0, 10.0, 20.0, 40.0];

/// Sublinear areas as in Fig. 3a: 40 µm² at 4 mN, A ∝ N^0.8. Returns m².
fn area_m2(load_mn: f64) -> f64 {
    40e-12 * (load_mn / 4.0).powf(0.8)
}

/// A realistic trace for F_s = τ·A: 400 loading samples, creep over the last 10 %, kinetic level
/// 80 % of F_s with 1 % stick-slip wiggles, noise 0.3 % of F_s.
fn params(static_n: f64, seed: u64) -> TraceParams {
    TraceParams {
        static_friction_n: static_n,
        kinetic_friction_n: 0.8 * static_n,
        stiffness_n_per_m: static_n / 20e-6,
        noise_n: 0.003 * static_n,
        wiggle_n: 0.01 * static_n,
        seed,
        ..TraceParams::default()
    }
}

fn layout(x_axis: XAxis, normal_mn: Option<f64>) -> CsvLayout {
    CsvLayout {
        x_axis,
        torque: false,
        rotation_radius_m: 5e-3,
        normal_force_n: normal_mn.map(|n| n * 1e-3),
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    fs::write(&path, text).unwrap();
    path
}

/// One trace per load (normal force in a column) and a matching areas.csv.
fn load_series(dir: &Path) -> (Vec<PathBuf>, PathBuf) {
    let traces = LOADS_MN
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            let t = synthetic_trace(&params(TAU_PA * area_m2(n), 11 + i as u64));
            let text = trace_csv(&t, &layout(XAxis::Displacement, Some(n)));
            write(dir, &format!("trace_{n}mN.csv"), &text)
        })
        .collect();
    let mut areas = String::from("image,force_mN,area_um2,patches\n");
    for &n in &LOADS_MN {
        // The area table's forces differ from the traces' by 0.5 %, inside the 2 % tolerance.
        areas.push_str(&format!("x.tif,{},{},3\n", n * 1.005, area_m2(n) * 1e12));
    }
    (traces, write(dir, "areas.csv", &areas))
}

/// A friction request with the folder the command line would write.
struct Req {
    job: FrictionRequest,
    out: PathBuf,
}

impl std::ops::Deref for Req {
    type Target = FrictionRequest;
    fn deref(&self) -> &FrictionRequest {
        &self.job
    }
}

impl std::ops::DerefMut for Req {
    fn deref_mut(&mut self) -> &mut FrictionRequest {
        &mut self.job
    }
}

fn request(traces: Vec<PathBuf>, areas: Option<PathBuf>, out: PathBuf) -> Req {
    Req {
        job: FrictionRequest {
            traces,
            normal_force_n: None,
            rotation_radius_m: None,
            areas,
            force_tolerance: 0.02,
            slip: SlipOptions::default(),
        },
        out,
    }
}

/// The job run as the command line runs it: its folder written all or nothing.
fn run_friction(req: &Req) -> contactscope_jobs::Result<FrictionOutcome> {
    Ok(run_to_folder(&req.job, &req.out, &["test".into()])?.0)
}

/// Known τ = 50 MPa from four noisy traces with creep and stick-slip; tolerance 2 % (measured
/// error printed). μ falls with N as N^(0.8 − 1).
#[test]
fn recovers_the_shear_strength() {
    let dir = tempfile::tempdir().unwrap();
    let (traces, areas) = load_series(dir.path());
    let outcome = run_friction(&request(traces, Some(areas), dir.path().join("out"))).unwrap();
    let fit = outcome.shear.unwrap();
    let err = fit.tau_pa / TAU_PA - 1.0;
    eprintln!(
        "τ = {:.4} MPa (error {:.3} %), se {:.4} MPa",
        fit.tau_pa * 1e-6,
        err * 100.0,
        fit.tau_se_pa.unwrap() * 1e-6
    );
    assert!(err.abs() < 0.02, "τ error {err}");
    assert!(fit.r_squared.unwrap() > 0.999);
    for t in &outcome.traces {
        let truth = TAU_PA * t.area_m2.unwrap();
        assert!((t.slip.static_friction_n / truth - 1.0).abs() < 0.02);
        assert!((t.slip.kinetic_friction_n / (0.8 * truth) - 1.0).abs() < 0.01);
    }
    let trend = outcome.mu_trend.unwrap();
    assert!(
        (trend.exponent + 0.2).abs() < 0.02,
        "m = {}",
        trend.exponent
    );
    assert_eq!(trend.varies, Some(true));
    let kinetic = outcome.kinetic_shear.unwrap();
    assert!((kinetic.tau_pa / (0.8 * TAU_PA) - 1.0).abs() < 0.02);
}

/// The slip is found where it happens, on the ramp's peak (20 seeds: within 2 samples, F_s
/// within 1 %), and read back in x units.
#[test]
fn slip_position_is_the_true_onset() {
    for seed in 0..20 {
        let t = synthetic_trace(&params(10e-3, seed));
        let slip = detect_slip(&t.displacement_m, &t.friction_n, &SlipOptions::default()).unwrap();
        assert!(
            slip.index.abs_diff(t.slip_index) <= 2,
            "seed {seed}: {} vs {}",
            slip.index,
            t.slip_index
        );
        assert!(
            (slip.static_friction_n / 10e-3 - 1.0).abs() < 0.01,
            "seed {seed}"
        );
    }
    let t = synthetic_trace(&params(10e-3, 5));
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "t.csv",
        &trace_csv(&t, &layout(XAxis::Displacement, Some(40.0))),
    );
    let trace = read_trace(&path, None).unwrap();
    assert_eq!(trace.x_axis, XAxis::Displacement);
    assert!((trace.x[t.slip_index] - t.displacement_m[t.slip_index]).abs() < 1e-12);
    assert_eq!(trace.normal_force_n, Some(40e-3));
}

fn with_spike(t: &mut SyntheticTrace, at: usize, width: usize, value: f64) {
    for f in &mut t.friction_n[at..at + width] {
        *f = value;
    }
}

/// A later, larger spike (the global maximum) is not the slip; neither is a one-sample dropout
/// on the loading ramp (10 seeds).
#[test]
fn later_spike_and_dropout_do_not_fool_the_detector() {
    for seed in 0..10 {
        let mut t = synthetic_trace(&params(10e-3, seed));
        let later = t.slip_index + 150;
        with_spike(&mut t, later, 3, 15e-3);
        let halfway = t.slip_index / 2;
        with_spike(&mut t, halfway, 1, 0.0);
        let global_max = (0..t.friction_n.len())
            .max_by(|&a, &b| t.friction_n[a].total_cmp(&t.friction_n[b]))
            .unwrap();
        assert!(global_max >= later, "the spike is the global maximum");
        let slip = detect_slip(&t.displacement_m, &t.friction_n, &SlipOptions::default()).unwrap();
        assert!(
            slip.index.abs_diff(t.slip_index) <= 2,
            "seed {seed}: slip at {}",
            slip.index
        );
        assert!((slip.static_friction_n / 10e-3 - 1.0).abs() < 0.02);
    }
}

/// Without a drop (F_k = F_s, no stick-slip, as the paper reports at 1 µm/s) the slip is where
/// the loading slope collapses: F_s within 1 %, onset within 10 samples, over 10 seeds.
#[test]
fn a_plateau_without_drop_slips_where_the_slope_collapses() {
    for seed in 0..10 {
        let p = TraceParams {
            kinetic_friction_n: 10e-3,
            wiggle_n: 0.0,
            slip_samples: 1,
            ..params(10e-3, seed)
        };
        let t = synthetic_trace(&p);
        let slip = detect_slip(&t.displacement_m, &t.friction_n, &SlipOptions::default()).unwrap();
        assert_eq!(slip.criterion, SlipCriterion::Plateau);
        assert!(
            slip.index.abs_diff(t.slip_index) <= 10,
            "seed {seed}: {} vs {}",
            slip.index,
            t.slip_index
        );
        assert!(
            (slip.static_friction_n / 10e-3 - 1.0).abs() < 0.01,
            "seed {seed}"
        );
        assert!(
            (slip.kinetic_friction_n / 10e-3 - 1.0).abs() < 0.01,
            "seed {seed}"
        );
    }
}

/// A torque trace on a time axis gives the same friction as the force trace it came from.
#[test]
fn torque_traces_use_the_rotation_radius() {
    let dir = tempfile::tempdir().unwrap();
    let t = synthetic_trace(&params(10e-3, 3));
    let torque = CsvLayout {
        torque: true,
        ..layout(XAxis::Time, None)
    };
    let path = write(dir.path(), "torque.csv", &trace_csv(&t, &torque));
    let trace = read_trace(&path, Some(5e-3)).unwrap();
    assert_eq!(trace.x_axis, XAxis::Time);
    for (a, b) in trace.friction_n.iter().zip(&t.friction_n) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
    let mut req = request(vec![path.clone()], None, dir.path().join("out"));
    req.normal_force_n = Some(40e-3);
    let err = run_friction(&req).unwrap_err().to_string();
    assert!(
        err.contains("torque.csv") && err.contains("rotation radius"),
        "{err}"
    );
    req.rotation_radius_m = Some(5e-3);
    let outcome = run_friction(&req).unwrap();
    assert!((outcome.traces[0].slip.static_friction_n / 10e-3 - 1.0).abs() < 0.02);
    assert!((outcome.traces[0].mu_static() - 0.25).abs() < 0.005);
}

#[test]
fn a_trace_without_slip_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut text = String::from("time_s,friction_mN\n");
    for i in 0..500 {
        let e: f64 = StandardNormal.sample(&mut rng);
        text.push_str(&format!(
            "{},{}\n",
            i as f64 * 0.05,
            0.02 * i as f64 + 0.03 * e
        ));
    }
    let path = write(dir.path(), "ramp.csv", &text);
    let mut req = request(vec![path], None, dir.path().join("out"));
    req.normal_force_n = Some(40e-3);
    let err = run_friction(&req).unwrap_err().to_string();
    assert!(
        err.contains("ramp.csv") && err.contains("no slip found"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn bad_columns_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let missing = write(dir.path(), "force.csv", "time_s,force_mN\n0,1\n");
    let err = read_trace(&missing, None).unwrap_err().to_string();
    assert!(
        err.contains("force.csv") && err.contains("columns found: time_s, force_mN"),
        "{err}"
    );
    let no_x = write(dir.path(), "nox.csv", "t,friction_mN\n0,1\n");
    let err = read_trace(&no_x, None).unwrap_err().to_string();
    assert!(
        err.contains("no x column") && err.contains("t, friction_mN"),
        "{err}"
    );
    let unit = write(dir.path(), "lbf.csv", "time_s,friction_lbf\n0,1\n");
    let err = read_trace(&unit, None).unwrap_err().to_string();
    assert!(err.contains("friction_lbf"), "{err}");
    let both = write(
        dir.path(),
        "both.csv",
        "time_s,friction_mN,friction_N\n0,1,1\n",
    );
    assert!(read_trace(&both, None).is_err());
    let backwards = (0..20)
        .map(|i| format!("{},{}\n", if i == 7 { 0.0 } else { i as f64 }, i))
        .collect::<String>();
    let back = write(
        dir.path(),
        "back.csv",
        &format!("time_s,friction_mN\n{backwards}"),
    );
    let err = read_trace(&back, None).unwrap_err().to_string();
    assert!(
        err.contains("line 9") && err.contains("does not increase"),
        "{err}"
    );
}

#[test]
fn normal_force_is_required() {
    let dir = tempfile::tempdir().unwrap();
    let t = synthetic_trace(&params(10e-3, 3));
    let path = write(
        dir.path(),
        "t.csv",
        &trace_csv(&t, &layout(XAxis::Time, None)),
    );
    let err = run_friction(&request(vec![path], None, dir.path().join("out")))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("t.csv") && err.contains(&Param::NormalForce.to_string()),
        "{err}"
    );
}

#[test]
fn mismatched_forces_list_both_sides() {
    crate::common::cli_names();
    let dir = tempfile::tempdir().unwrap();
    let (traces, _) = load_series(dir.path());
    let areas = write(dir.path(), "few.csv", "force_mN,area_um2\n4,40\n10,83\n");
    let err = run_friction(&request(traces, Some(areas), dir.path().join("out")))
        .unwrap_err()
        .to_string();
    assert!(err.contains("mismatched forces"), "{err}");
    assert!(err.contains("40.0000") && err.contains("10.0000"), "{err}");
    assert!(!dir.path().join("out").exists());
    let pixels = write(dir.path(), "px.csv", "force_mN,area_px\n4,40\n");
    let (traces, _) = load_series(dir.path());
    let err = run_friction(&request(traces, Some(pixels), dir.path().join("out")))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("area_um2") && err.contains("--pixel-size"),
        "{err}"
    );
}

#[test]
fn friction_command_writes_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let (traces, areas) = load_series(dir.path());
    // One trace without a normal-force column takes --forces.
    let t = synthetic_trace(&params(TAU_PA * area_m2(40.0), 99));
    let bare = write(
        dir.path(),
        "bare.csv",
        &trace_csv(&t, &layout(XAxis::Time, None)),
    );
    let out = dir.path().join("fr");
    let mut args = vec!["friction"];
    args.extend(traces.iter().map(|p| s(p)));
    args.extend([
        s(&bare),
        "--forces",
        "40mN",
        "--areas",
        s(&areas),
        "--out",
        s(&out),
    ]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("τ = "), "{}", stdout(&o));
    let (header, rows) = read_csv(&out.join("friction.csv"));
    for name in [
        "file",
        "normal_force_mN",
        "static_friction_mN",
        "kinetic_friction_mN",
        "slip_at_um",
        "slip_at_s",
        "mu_static",
        "mu_kinetic",
        "area_um2",
        "shear_stress_MPa",
    ] {
        assert!(header.iter().any(|h| h == name), "{name} in {header:?}");
    }
    assert_eq!(rows.len(), 5);
    let n = column(&header, &rows, "normal_force_mN");
    assert!((n[4] - 40.0).abs() < 1e-9);
    let stress = column(&header, &rows, "shear_stress_MPa");
    assert!(
        stress.iter().all(|t| (t / 50.0 - 1.0).abs() < 0.02),
        "{stress:?}"
    );
    let summary = json(&out.join("summary.json"));
    let tau = summary["tau_MPa"].as_f64().unwrap();
    assert!((tau / 50.0 - 1.0).abs() < 0.02, "τ = {tau}");
    assert!(summary["tau_se_MPa"].as_f64().unwrap() > 0.0);
    assert!(summary["r2"].as_f64().unwrap() > 0.99);
    assert_eq!(summary["traces"].as_array().unwrap().len(), 5);
    assert_eq!(summary["contactscope_version"], env!("CARGO_PKG_VERSION"));
    for png in [
        "friction_vs_load.png",
        "mu_vs_load.png",
        "friction_vs_area.png",
    ] {
        let bytes = fs::read(out.join(png)).unwrap();
        assert_eq!(&bytes[1..4], b"PNG", "{png}");
    }
}

#[test]
fn failed_friction_command_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (traces, _) = load_series(dir.path());
    let torque_t = synthetic_trace(&params(10e-3, 3));
    let torque = write(
        dir.path(),
        "torque.csv",
        &trace_csv(
            &torque_t,
            &CsvLayout {
                torque: true,
                ..layout(XAxis::Angle, Some(40.0))
            },
        ),
    );
    let out = dir.path().join("fr");
    let o = run(&["friction", s(&traces[0]), s(&torque), "--out", s(&out)]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("rotation radius"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = run(&[
        "friction",
        s(&traces[0]),
        "--rotation-radius",
        "5",
        "--out",
        s(&out),
    ]);
    assert!(!o.status.success() && stderr(&o).contains("--rotation-radius"));
    assert!(!out.exists());
    let o = run(&[
        "friction",
        s(&traces[0]),
        s(&torque),
        "--rotation-radius",
        "5mm",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, _) = read_csv(&out.join("friction.csv"));
    assert!(header.iter().any(|h| h == "slip_at_rad"));
}

// ---- hertz ----

const E_STAR: f64 = 3.7e9;
const RADIUS: f64 = 290e-6;

/// Squeeze data for loads 2..50 mN: 2δ from Hertz, with Gaussian noise of `noise_m` on the
/// displacement, written as force_mN, displacement_um after two pre-contact rows.
fn squeeze_csv(dir: &Path, name: &str, noise_m: f64, seed: u64) -> PathBuf {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut text = String::from("force_mN,displacement_um\n-0.001,0\n0,0\n");
    for i in 1..=25 {
        let p = 2e-3 * i as f64;
        let e: f64 = StandardNormal.sample(&mut rng);
        let disp = 2.0 * hertz::approach(p, RADIUS, E_STAR) + noise_m * e;
        text.push_str(&format!("{:.12},{:.12}\n", p * 1e3, disp * 1e6));
    }
    write(dir, name, &text)
}

/// Exact data give E* to 1e-9; 5 nm displacement noise gives E* within 1 % (error printed).
#[test]
fn recovers_the_contact_modulus() {
    let dir = tempfile::tempdir().unwrap();
    let exact = read_squeeze(&squeeze_csv(dir.path(), "exact.csv", 0.0, 1)).unwrap();
    assert_eq!(exact.len(), 25, "pre-contact rows are not fitted");
    let fit = fit_hertz(&exact, RADIUS).unwrap();
    assert!(
        (fit.e_star_pa / E_STAR - 1.0).abs() < 1e-9,
        "{}",
        fit.e_star_pa
    );
    let noisy = read_squeeze(&squeeze_csv(dir.path(), "noisy.csv", 5e-9, 2)).unwrap();
    let fit = fit_hertz(&noisy, RADIUS).unwrap();
    let err = fit.e_star_pa / E_STAR - 1.0;
    eprintln!(
        "E* = {:.5} GPa (error {:.3} %), se {:.5} GPa",
        fit.e_star_pa * 1e-9,
        err * 100.0,
        fit.e_star_se_pa * 1e-9
    );
    assert!(err.abs() < 0.01, "E* error {err}");
    assert!(fit.e_star_se_pa > 0.0 && fit.e_star_se_pa < 0.01 * E_STAR);
    assert!(fit.r_squared > 0.999);
}

#[test]
fn bad_squeeze_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let cols = write(dir.path(), "cols.csv", "load_mN,displacement_um\n1,0.1\n");
    let err = read_squeeze(&cols).unwrap_err().to_string();
    assert!(err.contains("cols.csv") && err.contains("columns found: load_mN, displacement_um"));
    let few = write(
        dir.path(),
        "few.csv",
        "force_mN,displacement_um\n0,0\n1,0.1\n2,0.15\n",
    );
    let err = read_squeeze(&few).unwrap_err().to_string();
    assert!(err.contains("2 points with positive force"), "{err}");
    let back = write(
        dir.path(),
        "back.csv",
        "force_mN,displacement_um\n1,0.1\n2,0.15\n3,0.2\n2.5,0.18\n",
    );
    let err = read_squeeze(&back).unwrap_err().to_string();
    assert!(
        err.contains("line 5") && err.contains("not monotonic"),
        "{err}"
    );
    let not_number = write(dir.path(), "nan.csv", "force_N,displacement_um\n1,abc\n");
    let err = read_squeeze(&not_number).unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("abc"), "{err}");
    let good = squeeze_csv(dir.path(), "good.csv", 0.0, 1);
    let out = dir.path().join("out");
    let req = |radius_m: f64| HertzRequest::new(good.clone(), radius_m);
    assert!(hertz_to_folder(&req(0.0), &out, &[]).is_err());
    assert!(hertz_to_folder(&req(-290e-6), &out, &[]).is_err());
    assert!(!dir.path().join("out").exists());
}

#[test]
fn hertz_command_writes_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let input = squeeze_csv(dir.path(), "squeeze.csv", 0.0, 1);
    let out = dir.path().join("hz");
    let o = run(&[
        "hertz",
        s(&input),
        "--radius",
        "290um",
        "--forces",
        "4mN,40mN",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = json(&out.join("hertz.json"));
    let e = summary["contact_modulus_GPa"].as_f64().unwrap();
    assert!((e / 3.7 - 1.0).abs() < 1e-9, "{e}");
    assert_eq!(summary["points_used"], 25);
    assert_eq!(summary["radius_um"].as_f64().unwrap(), 290.0);
    let predicted = summary["predicted"].as_array().unwrap();
    assert_eq!(predicted.len(), 2);
    // docs/validation.md B20: a = 6.172 µm at 4 mN, R = 290 µm, E* = 3.7 GPa.
    let a4 = predicted[0]["contact_radius_um"].as_f64().unwrap();
    assert!((a4 - 6.172).abs() < 5e-4, "{a4}");
    let (header, rows) = read_csv(&out.join("hertz_fit.csv"));
    assert_eq!(
        header,
        [
            "force_mN",
            "displacement_um",
            "delta_um",
            "fitted_force_mN",
            "residual_mN"
        ]
    );
    assert_eq!(rows.len(), 25);
    let d = column(&header, &rows, "displacement_um");
    let delta = column(&header, &rows, "delta_um");
    assert!(d
        .iter()
        .zip(&delta)
        .all(|(a, b)| (a - 2.0 * b).abs() < 1e-8));
    assert!(column(&header, &rows, "residual_mN")
        .iter()
        .all(|r| r.abs() < 1e-6));
    assert_eq!(
        &fs::read(out.join("squeeze_fit.png")).unwrap()[1..4],
        b"PNG"
    );
}

#[test]
fn failed_hertz_command_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = squeeze_csv(dir.path(), "squeeze.csv", 0.0, 1);
    let out = dir.path().join("hz");
    for radius in ["0um", "-290um", "290"] {
        let o = run(&["hertz", s(&input), "--radius", radius, "--out", s(&out)]);
        assert!(!o.status.success(), "{radius}");
        assert!(stderr(&o).contains("--radius"), "{}", stderr(&o));
    }
    let bad = write(dir.path(), "bad.csv", "force_mN,displacement_um\n1,0.1\n");
    let o = run(&["hertz", s(&bad), "--radius", "290um", "--out", s(&out)]);
    assert!(!o.status.success());
    assert!(!out.exists());
}
