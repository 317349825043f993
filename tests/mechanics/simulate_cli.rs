//! `surface`, `topography` and `simulate` from the command line: outputs, units and bad input.

use std::fs;
use std::path::Path;

use crate::common::{column, read_csv, rough_surface, run, stderr, stdout};
use contactscope_formats::tiff::TiffReader;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn make_surface(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("rough.npy");
    rough_surface(
        &path,
        128,
        "32nm",
        3,
        &["--rolloff", "1um", "--cutoff", "128nm"],
    );
    path
}

#[test]
fn surface_topography_and_elastic_simulation() {
    let dir = tempfile::tempdir().unwrap();
    let surface = make_surface(dir.path());
    let o = run(&[
        "topography",
        s(&surface),
        "--pixel-size",
        "32nm",
        "--detrend",
        "none",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["nx"], 128);
    assert_eq!(v["format"], "npy");
    assert_eq!(v["valid_points"], 128 * 128);
    let d = &v["detrended"];
    assert!(
        (d["h_prime_rms"].as_f64().unwrap() - 0.1).abs() < 1e-9,
        "generator's slope target"
    );
    assert!((d["pixel_size_x_nm"].as_f64().unwrap() - 32.0).abs() < 1e-9);
    assert!((v["pixel_size_um"]["x"].as_f64().unwrap() - 0.032).abs() < 1e-12);
    // Without detrending, the stored map's summary and the roughness statistics agree.
    let slope = v["h_prime_rms_as_stored"].as_f64().unwrap();
    assert!((slope / d["h_prime_rms"].as_f64().unwrap() - 1.0).abs() < 1e-9);
    let curvature = v["h_double_prime_rms_as_stored_per_um"].as_f64().unwrap();
    let detrended = d["h_double_prime_rms_per_um"].as_f64().unwrap();
    assert!((curvature / detrended - 1.0).abs() < 1e-9);
    let h_rms_um = v["h_rms_as_stored_um"].as_f64().unwrap();
    assert!((h_rms_um * 1e3 / d["h_rms_nm"].as_f64().unwrap() - 1.0).abs() < 1e-6);

    let out = dir.path().join("sim");
    let o = run(&[
        "simulate",
        "--topography",
        s(&surface),
        "--pixel-size",
        "32nm",
        "--radius",
        "290um",
        "--modulus",
        "3.7GPa",
        "--model",
        "elastic",
        "--forces",
        "0.002mN..0.01mN:3",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("wrote"));
    let (h, r) = read_csv(&out.join("areas.csv"));
    for col in [
        "force_mN",
        "area_um2",
        "contact_fraction",
        "mean_pressure_MPa",
        "max_pressure_MPa",
        "approach_um",
        "patches",
        "iterations",
        "residual",
    ] {
        assert!(h.contains(&col.to_string()), "{col}");
    }
    let areas = column(&h, &r, "area_um2");
    assert!(
        areas.windows(2).all(|w| w[1] > w[0]),
        "area grows with load: {areas:?}"
    );
    let pressure = column(&h, &r, "mean_pressure_MPa");
    let forces = column(&h, &r, "force_mN");
    for ((p, f), a) in pressure.iter().zip(&forces).zip(&areas) {
        assert!((p - f / a * 1e3).abs() < 1e-6 * p);
    }
    for name in [
        "contact",
        "pressure_MPa",
        "gap_um",
        "plastic_um",
        "deformed_um",
    ] {
        let path = out.join(format!("load_003_{name}.tif"));
        let info = TiffReader::open(&path).unwrap().info().clone();
        let size = info.pixel_size.unwrap();
        assert!((size.x_m - 32e-9).abs() < 1e-15, "{name}: pixel size kept");
        assert_eq!((info.width, info.height), (128, 128));
    }
    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["model"]["name"], "elastic");
    assert_eq!(summary["loads"].as_array().unwrap().len(), 3);
    assert!(summary["topography"]["h_rms_nm"].as_f64().unwrap() > 0.0);
    assert!(out.join("area_vs_load.png").exists());
}

/// `simulate` of the 128² test surface on a 290 µm sphere at 2 and 5 µN, into `out`, with
/// `extra` arguments (the model, `--maps`).
fn simulate_sphere(surface: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "simulate",
        "--topography",
        s(surface),
        "--pixel-size",
        "32nm",
        "--radius",
        "290um",
        "--modulus",
        "3.7GPa",
        "--forces",
        "0.002mN,0.005mN",
        "--out",
        s(out),
        "-q",
    ];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn plastic_models_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let surface = make_surface(dir.path());
    let sim = |extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        let o = simulate_sphere(&surface, &out, extra);
        // Written; on this small map every load reaches its border (exit status 4).
        assert!(
            o.status.success() || o.status.code() == Some(4),
            "{name}: {}",
            stderr(&o)
        );
        let (h, r) = read_csv(&out.join("areas.csv"));
        (
            column(&h, &r, "area_um2"),
            column(&h, &r, "max_pressure_MPa"),
            column(&h, &r, "plastic_volume_um3"),
        )
    };
    let (elastic, _, _) = sim(&["--model", "elastic"], "elastic");
    let (hard, p_max, volume) = sim(&["--model", "hardness", "--hardness", "100MPa"], "hardness");
    assert!(p_max.iter().all(|p| *p <= 100.0 + 1e-9));
    assert!(
        volume[1] > volume[0] && volume[0] > 0.0,
        "plastic state grows: {volume:?}"
    );
    assert!(
        hard[0] > elastic[0],
        "a softer surface carries the load on more area"
    );
    let (_, _, conserved) = sim(
        &[
            "--model",
            "hardness",
            "--hardness",
            "100MPa",
            "--volume-conserving",
            "0.5",
        ],
        "eq5",
    );
    assert!(
        conserved.iter().all(|v| v.abs() < 1e-9),
        "Eq. 5 conserves volume: {conserved:?}"
    );
    let (hardening, _, _) = sim(
        &["--model", "hardening", "--hardening", "4MPa/nm"],
        "hardening",
    );
    assert!(hardening[1] > hardening[0]);
    let (gt, _, _) = sim(&["--model", "gt"], "gt");
    assert!(gt[1] > gt[0] && gt[0] > 0.0);
}

#[test]
fn bad_simulation_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let surface = make_surface(dir.path());
    let out = dir.path().join("never");
    let fail = |args: &[&str], needle: &str| {
        let mut all = vec!["simulate", "--out", s(&out)];
        all.extend_from_slice(args);
        let o = run(&all);
        assert!(!o.status.success(), "should fail: {args:?}");
        assert!(stderr(&o).contains(needle), "'{needle}' in {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"));
        assert!(!out.exists(), "no output on failure");
    };
    let base = ["--modulus", "3.7GPa", "--forces", "0.002mN"];
    let with = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = vec![
            "--topography".into(),
            s(&surface).into(),
            "--pixel-size".into(),
            "32nm".into(),
        ];
        v.extend(base.iter().map(|a| a.to_string()));
        v.extend(extra.iter().map(|a| a.to_string()));
        v
    };
    let call = |extra: &[&str], needle: &str| {
        let v = with(extra);
        let refs: Vec<&str> = v.iter().map(String::as_str).collect();
        fail(&refs, needle);
    };
    call(&["--model", "hardness"], "--hardness");
    call(
        &["--model", "hardness", "--hardness", "1kPa"],
        "exceeds what the hardness can carry",
    );
    call(&["--model", "gt"], "--radius");
    fail(
        &[
            "--topography",
            s(&surface),
            "--pixel-size",
            "0nm",
            "--model",
            "elastic",
            "--modulus",
            "3.7GPa",
            "--forces",
            "1mN",
        ],
        "positive",
    );
    call(
        &["--model", "elastic", "--hardening", "4MPa/nm"],
        "applies to --model hardening only",
    );
    call(&["--model", "hardening", "--hardening", "4MPa"], "per");
    // NaN heights in a text matrix.
    let nan = dir.path().join("nan.txt");
    fs::write(&nan, "1 2 3\n4 nan 6\n7 8 9\n").unwrap();
    fail(
        &[
            "--topography",
            s(&nan),
            "--pixel-size",
            "32nm",
            "--model",
            "elastic",
            "--modulus",
            "3.7GPa",
            "--forces",
            "1mN",
        ],
        "nan.txt",
    );
    // Missing pixel size for a format without one.
    fail(
        &[
            "--topography",
            s(&surface),
            "--model",
            "elastic",
            "--modulus",
            "3.7GPa",
            "--forces",
            "1mN",
        ],
        "rough.npy",
    );
    // Unknown model: a usage error from the argument parser.
    let o = run(&[
        "simulate",
        "--topography",
        s(&surface),
        "--model",
        "plastic",
        "--modulus",
        "3.7GPa",
        "--forces",
        "1mN",
    ]);
    assert_eq!(o.status.code(), Some(2));
    // Unknown topography format.
    let odd = dir.path().join("map.xyz");
    fs::write(&odd, "x").unwrap();
    fail(
        &[
            "--topography",
            s(&odd),
            "--model",
            "elastic",
            "--modulus",
            "3.7GPa",
            "--forces",
            "1mN",
        ],
        "map.xyz",
    );
}

/// The files of a run's folder, sorted (the run record included).
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn float_page(path: &Path) -> Vec<u32> {
    let mut reader = TiffReader::open(path).unwrap();
    match reader.read_page(0, 0).unwrap().samples {
        contactscope_formats::image::Samples::Float(v) => v.iter().map(|x| x.to_bits()).collect(),
        _ => panic!("{}: float32 expected", path.display()),
    }
}

#[test]
fn maps_choice_writes_exactly_the_maps_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let surface = make_surface(dir.path());
    let sim = |model: &[&str], maps: Option<&str>, name: &str| {
        let out = dir.path().join(name);
        let mut extra = model.to_vec();
        if let Some(m) = maps {
            extra.extend(["--maps", m]);
        }
        let o = simulate_sphere(&surface, &out, &extra);
        // Written; on this small map every load reaches its border (exit status 4).
        assert!(
            o.status.success() || o.status.code() == Some(4),
            "{name}: {}",
            stderr(&o)
        );
        let summary: serde_json::Value =
            serde_json::from_str(&fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
        (out, summary)
    };
    let hardening = ["--model", "hardening", "--hardening", "4MPa/nm"];
    let tables = [
        ".contactscope-run.json",
        "area_vs_load.png",
        "areas.csv",
        "summary.json",
    ];
    let with_tables = |maps: &[&str]| {
        let mut v: Vec<String> = tables.iter().chain(maps).map(|n| n.to_string()).collect();
        v.sort();
        v
    };

    let (all, summary) = sim(&hardening, None, "all");
    assert_eq!(summary["maps"], "all", "the default");
    let every: Vec<String> = (1..=2)
        .flat_map(|i| {
            [
                "contact",
                "deformed_um",
                "gap_um",
                "plastic_um",
                "pressure_MPa",
            ]
            .map(|m| format!("load_{i:03}_{m}.tif"))
        })
        .collect();
    let every: Vec<&str> = every.iter().map(String::as_str).collect();
    assert_eq!(listing(&all), with_tables(&every));

    let (contact, summary) = sim(&hardening, Some("contact"), "contact");
    assert_eq!(summary["maps"], "contact");
    assert_eq!(
        listing(&contact),
        with_tables(&["load_001_contact.tif", "load_002_contact.tif"])
    );
    // The same solution: the same table and, bit for bit, the same contact maps.
    assert_eq!(
        fs::read_to_string(contact.join("areas.csv")).unwrap(),
        fs::read_to_string(all.join("areas.csv")).unwrap()
    );
    for i in 1..=2 {
        let name = format!("load_{i:03}_contact.tif");
        let page = float_page(&contact.join(&name));
        assert_eq!(page, float_page(&all.join(&name)), "{name}");
        assert!(
            page.iter().any(|b| f32::from_bits(*b) == 1.0),
            "{name}: contact"
        );
    }
    // The run record lists exactly the files written.
    let record: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(contact.join(".contactscope-run.json")).unwrap())
            .unwrap();
    assert_eq!(record["files"].as_array().unwrap().len(), 5);

    let (none, summary) = sim(&hardening, Some("none"), "none");
    assert_eq!(summary["maps"], "none");
    assert_eq!(listing(&none), with_tables(&[]));
    assert_eq!(summary["loads"].as_array().unwrap().len(), 2);

    // A rerun with fewer maps replaces the folder as a whole: no map of the earlier run stays.
    let (again, _) = sim(&hardening, Some("none"), "all");
    assert_eq!(listing(&again), with_tables(&[]));

    // Greenwood–Tripp has a contact map only, written under `contact` and `all`, not `none`.
    let (gt, summary) = sim(&["--model", "gt"], Some("contact"), "gt");
    assert_eq!(summary["maps"], "contact");
    assert_eq!(
        listing(&gt),
        with_tables(&["load_001_contact.tif", "load_002_contact.tif"])
    );
    let (gt_none, _) = sim(&["--model", "gt"], Some("none"), "gt-none");
    assert_eq!(listing(&gt_none), with_tables(&[]));

    // A choice that does not exist: one line naming the flag, nothing written.
    let out = dir.path().join("never");
    let o = run(&[
        "simulate",
        "--topography",
        s(&surface),
        "--pixel-size",
        "32nm",
        "--modulus",
        "3.7GPa",
        "--model",
        "elastic",
        "--forces",
        "1mN",
        "--maps",
        "pressure",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("--maps") && err.contains("contact"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!out.exists());
}
