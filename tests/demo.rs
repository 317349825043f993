//! `contactscope demo`: the whole method on a generated experiment; every recovered number must
//! match the generator's truth, and the report must be complete.

use std::fs;
use std::path::Path;

use crate::common::{run, stderr};
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Tolerances: PSF from 6 noisy beads (B15-like, 2 %); Newton: the documented +0.7 nm bias of the
/// blurred-ring fit plus noise (2 nm); E* from 25 noisy squeeze points (1 %); τ from 4 traces
/// (2 %); k from 4 imaged loads at the reduced size (10 %).
#[test]
fn reduced_demo_recovers_the_truth_and_writes_a_complete_report() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let o = run(&["demo", "--small", "--quiet", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let demo: Value =
        serde_json::from_str(&fs::read_to_string(out.join("demo.json")).unwrap()).unwrap();
    let recovered = demo["recovered"].as_array().unwrap();
    let check = |by: &str, tolerance: &dyn Fn(f64, f64) -> bool| {
        let r = recovered
            .iter()
            .find(|r| r["by"] == by)
            .unwrap_or_else(|| panic!("{by} missing"));
        let (truth, got) = (
            r["truth"].as_f64().unwrap(),
            r["recovered"].as_f64().unwrap(),
        );
        assert!(
            tolerance(truth, got),
            "{by}: truth {truth}, recovered {got}"
        );
    };
    let relative = |tol: f64| move |t: f64, g: f64| (g / t - 1.0).abs() <= tol;
    check("psf", &relative(0.02));
    check("newton", &|t, g| (g - t).abs() <= 2.0);
    check("hertz", &relative(0.01));
    check("friction", &relative(0.02));
    check("fit-hardening", &relative(0.10));

    // The hardening model matches the micrographs best (Fig. 2), the elastic one worst.
    let models = demo["models"].as_array().unwrap();
    let mean_dice = |name: &str| {
        let m = models.iter().find(|m| m["model"] == name).unwrap();
        let d: Vec<f64> = m["dice"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        d.iter().sum::<f64>() / d.len() as f64
    };
    let hardening = mean_dice("linear hardening");
    for other in ["elastic", "Greenwood–Tripp"] {
        assert!(
            hardening > mean_dice(other),
            "hardening {hardening} vs {other} {}",
            mean_dice(other)
        );
    }
    assert!(hardening > 0.85, "{hardening}");
    // Every model's map is registered where the micrographs were rendered, at every load.
    let truth = (
        demo["true_shift_x_px"].as_f64().unwrap(),
        demo["true_shift_y_px"].as_f64().unwrap(),
    );
    for m in models {
        let values = |key: &str| -> Vec<f64> {
            m[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        };
        let (xs, ys) = (values("shift_x_px"), values("shift_y_px"));
        assert_eq!(xs.len(), 4);
        for (x, y) in xs.iter().zip(&ys) {
            assert!(
                (x - truth.0).hypot(y - truth.1) <= 2.0,
                "{}: shift ({x}, {y}), truth {truth:?}",
                m["model"]
            );
        }
    }

    // Every local link and image of the page exists.
    let html = fs::read_to_string(out.join("index.html")).unwrap();
    let mut links = 0;
    for attr in ["href=\"", "src=\""] {
        for part in html.split(attr).skip(1) {
            let target = &part[..part.find('"').unwrap()];
            if target.starts_with("https://") {
                // The one outside link is the paper's DOI.
                assert_eq!(target, "https://doi.org/10.1038/s41467-018-02981-y");
                continue;
            }
            assert!(out.join(target).exists(), "broken link {target}");
            links += 1;
        }
    }
    assert!(links > 20, "{links} links");
    for text in [
        "Inputs (generator truth)",
        "Recovered",
        "Fig. 2",
        "Fig. 3a",
        "Fig. 3b",
        "MPa/nm",
    ] {
        assert!(html.contains(text), "page lacks {text}");
    }
    assert!(out.join("data/micrographs/series.tif").is_file());

    // A second run replaces the earlier report; a foreign non-empty folder is refused.
    let o = run(&["demo", "--small", "--quiet", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let foreign = dir.path().join("foreign");
    fs::create_dir_all(&foreign).unwrap();
    fs::write(foreign.join("notes.txt"), "keep me").unwrap();
    let o = run(&["demo", "--small", "--quiet", "--out", s(&foreign)]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("foreign"), "{}", stderr(&o));
    assert_eq!(
        fs::read_to_string(foreign.join("notes.txt")).unwrap(),
        "keep me"
    );
}

/// The standard demo's series with the penetration-hardness model at the hardness its fit finds
/// (102 MPa). The model's contact at the two highest loads is much wider than the measured one,
/// so those loads' own phase correlations peak far away (133 and 190 px off when each load was
/// registered alone); the series registration must place every load within 2 px of the offset
/// the micrographs were rendered with.
#[test]
fn hardness_model_registers_in_place_at_every_load_of_the_standard_demo() {
    use contactscope::model_fit::Family;
    use contactscope::spectral::register::Refinement;
    use contactscope_jobs::demo::{
        compare_model, model_body, synthetic_experiment, DemoParams, MICROGRAPH_OFFSET_PX,
    };
    let p = DemoParams::standard();
    let dir = tempfile::tempdir().unwrap();
    let experiment = synthetic_experiment(&p, dir.path(), &|_| {}).unwrap();
    let body = model_body(&p, &experiment).unwrap();
    let model = ("penetration hardness", Family::Hardness, Some(102e6));
    let c = compare_model(&p, &experiment, &body, model).unwrap();
    assert_eq!(c.loads.len(), p.loads_n.len());
    let (tx, ty) = (MICROGRAPH_OFFSET_PX.0 as f64, MICROGRAPH_OFFSET_PX.1 as f64);
    let off = |(x, y): (f64, f64)| (x - tx).hypot(y - ty);
    assert!(off(c.registration.shift_px) <= 0.5, "{:?}", c.registration);
    for l in &c.loads {
        assert!(
            off(l.shift_px) <= 2.0,
            "{:.3} mN: shift {:?}, {} px off",
            l.force_n * 1e3,
            l.shift_px,
            off(l.shift_px)
        );
        assert_ne!(l.refinement, Refinement::WindowEdge, "{l:?}");
    }
    // In place, the model's maps overlap the micrographs at every load (before: 0.35 and 0.45
    // at the two highest loads).
    let dice: Vec<f64> = c.loads.iter().map(|l| l.dice).collect();
    assert!(dice.iter().all(|&d| d > 0.7), "{dice:?}");
    assert!(
        !c.warnings.iter().any(|w| w.contains("weak registration")),
        "{:?}",
        c.warnings
    );
}
