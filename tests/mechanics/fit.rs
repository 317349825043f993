//! `contactscope fit-hardening`: recover a known hardening coefficient from a simulated
//! area–load curve, sweep k against micrographs (Dice), and reject bad input.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::{column, read_csv, rough_surface, run, stderr};
use contactscope::optics::blur::Grid;
use contactscope::synth::{render_micrograph, MicrographParams};
use contactscope_formats::tiff::read_image;
use contactscope_formats::tiff::write::encode_u16_stack;
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const LOADS: &str = "0.05mN..0.4mN:4";

/// An 80² rough map at 100 nm on a 50 µm sphere (contact well inside the map), and the
/// "experiment": a hardening simulation at k = 4 MPa/nm.
fn truth(dir: &Path) -> (PathBuf, PathBuf) {
    let topo = dir.join("rough.npy");
    rough_surface(
        &topo,
        80,
        "100nm",
        5,
        &["--rolloff", "2um", "--cutoff", "300nm"],
    );
    let sim = dir.join("truth");
    let o = run(&[
        "simulate",
        "--topography",
        s(&topo),
        "--pixel-size",
        "100nm",
        "--radius",
        "50um",
        "--modulus",
        "3.7GPa",
        "--forces",
        LOADS,
        "--model",
        "hardening",
        "--hardening",
        "4MPa/nm",
        "--quiet",
        "--out",
        s(&sim),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("border"), "{}", stderr(&o));
    (topo, sim)
}

fn fit(topo: &Path, experiment: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "fit-hardening",
        "--areas",
        s(experiment),
        "--topography",
        s(topo),
        "--pixel-size",
        "100nm",
        "--radius",
        "50um",
        "--modulus",
        "3.7GPa",
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn recovers_a_known_hardening_coefficient() {
    let dir = tempfile::tempdir().unwrap();
    let (topo, sim) = truth(dir.path());
    let out = dir.path().join("fit");
    let o = fit(
        &topo,
        &sim.join("areas.csv"),
        &out,
        &["--models", "hardening,elastic,hardness"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = json(&out.join("fit.json"));
    assert_eq!(summary["best_model"], "hardening");
    let models = summary["models"].as_array().unwrap();
    let hardening = models.iter().find(|m| m["model"] == "hardening").unwrap();
    let k = hardening["k_MPa_per_nm"].as_f64().unwrap();
    // The golden-section search stops at 1 % of k; the data are the model itself.
    assert!((k / 4.0 - 1.0).abs() < 0.01, "k = {k}");
    let se = hardening["k_MPa_per_nm_se"].as_f64().unwrap();
    assert!(se > 0.0 && se < 0.1, "se = {se}");
    assert!(hardening["misfit_rms_ln_area"].as_f64().unwrap() < 0.01);
    let elastic = models.iter().find(|m| m["model"] == "elastic").unwrap();
    assert!(
        elastic["misfit_rms_ln_area"].as_f64().unwrap() > 0.3,
        "elastic should not fit"
    );
    let (header, rows) = read_csv(&out.join("fit_areas.csv"));
    let measured = column(&header, &rows, "measured_area_um2");
    let fitted = column(&header, &rows, "hardening_area_um2");
    for (m, f) in measured.iter().zip(&fitted) {
        assert!((f / m - 1.0).abs() < 0.02, "{f} vs {m}");
    }
    assert!(out.join("fit_area_vs_load.png").is_file() && out.join("misfit.png").is_file());
}

/// Micrographs rendered from the k = 4 MPa/nm maps: the sweep's Dice is best at k = 4.
#[test]
fn sweep_scores_dice_against_micrographs() {
    let dir = tempfile::tempdir().unwrap();
    let (topo, sim) = truth(dir.path());
    let exp = dir.path().join("micrographs");
    fs::create_dir_all(&exp).unwrap();
    let (header, rows) = read_csv(&sim.join("areas.csv"));
    let forces = column(&header, &rows, "force_mN");
    let mut pages = Vec::new();
    for i in 0..forces.len() {
        let map = read_image(
            &sim.join(format!("load_{:03}_contact.tif", i + 1)),
            None,
            None,
        )
        .unwrap();
        let grid = Grid::new(map.values, map.width, map.height, 100e-9, 100e-9).unwrap();
        let params = MicrographParams {
            fwhm_m: 450e-9,
            pixel_m: 200e-9,
            width: 56,
            height: 56,
            corner_px: (10, 6),
            background: 300.0,
            contact_level: 2500.0,
            counts_per_photon: 4.0,
            seed: i as u64,
        };
        pages.push(render_micrograph(&grid, &params).unwrap());
    }
    let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
    fs::write(
        exp.join("series.tif"),
        encode_u16_stack(&refs, 56, 56, Some((200e-9, 200e-9)), "").unwrap(),
    )
    .unwrap();
    let manifest: String = std::iter::once("file,page,force_mN\n".to_string())
        .chain(
            forces
                .iter()
                .enumerate()
                .map(|(i, f)| format!("series.tif,{i},{f}\n")),
        )
        .collect();
    fs::write(exp.join("manifest.csv"), manifest).unwrap();

    let out = dir.path().join("sweep");
    let o = fit(
        &topo,
        &sim.join("areas.csv"),
        &out,
        &[
            "--models",
            "hardening",
            "--sweep",
            "k=1,4,16MPa/nm",
            "--micrographs",
            s(&exp),
            "--psf-fwhm",
            "450nm",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&out.join("sweep.csv"));
    assert_eq!(rows.len(), 3 * forces.len());
    let k = column(&header, &rows, "k_MPa_per_nm");
    let dice = column(&header, &rows, "dice");
    let mean_dice = |value: f64| {
        let d: Vec<f64> = k
            .iter()
            .zip(&dice)
            .filter(|(kk, _)| (**kk - value).abs() < 1e-9)
            .map(|(_, d)| *d)
            .collect();
        d.iter().sum::<f64>() / d.len() as f64
    };
    let (low, right, high) = (mean_dice(1.0), mean_dice(4.0), mean_dice(16.0));
    assert!(right > 0.85, "Dice at the true k: {right}");
    assert!(right > low && right > high, "Dice {low} / {right} / {high}");
    let area = column(&header, &rows, "simulated_area_um2");
    let measured = column(&header, &rows, "measured_area_um2");
    for ((kk, a), m) in k.iter().zip(&area).zip(&measured) {
        if (kk - 4.0).abs() < 1e-9 {
            assert!((a / m - 1.0).abs() < 1e-3);
        }
    }
    assert!(out.join("sweep_area_vs_load.png").is_file());
}

#[test]
fn bad_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let topo = dir.path().join("rough.npy");
    rough_surface(&topo, 32, "100nm", 1, &[]);
    let out = dir.path().join("fit");
    let bad = dir.path().join("bad.csv");
    fs::write(&bad, "force_mN,area\n1,2\n2,3\n").unwrap();
    let o = fit(&topo, &bad, &out, &[]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("bad.csv") && stderr(&o).contains("area_um2"),
        "{}",
        stderr(&o)
    );

    let good = dir.path().join("areas.csv");
    fs::write(&good, "force_mN,area_um2\n0.01,0.5\n0.02,0.8\n").unwrap();
    let o = fit(&topo, &good, &out, &["--models", "plastic"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("plastic"));
    let o = fit(&topo, &good, &out, &["--micrographs", s(dir.path())]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--sweep"));
    let o = fit(&topo, &good, &out, &["--sweep", "k=3..1MPa/nm:3"]);
    assert!(!o.status.success());
    assert!(!out.exists());
}
