//! `simulate` and `fit-hardening` on vendor height maps through the built binary (issue 14,
//! item 2): `--channel NAME` picks a channel, and a map with invalid points is refused unless
//! `--fill-invalid mean|nearest` (crates/algorithms/src/surface/fill.rs). Real files from
//! `../shared/data/real-formats` (skipped with a message when absent).

use std::path::Path;

use crate::common::{run, run_ok, shared_data, stderr};
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// `simulate` (elastic, two tiny loads: the map is what is tested) into `out`; summary.json.
fn simulate(out: &Path, topography: &Path, extra: &[&str]) -> Value {
    let mut args = vec![
        "simulate",
        "-q",
        "--topography",
        s(topography),
        "--modulus",
        "3GPa",
        "--model",
        "elastic",
        "--forces",
        "0.1mN,0.2mN",
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    run_ok(&args);
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

fn one_line_error(args: &[&str]) -> String {
    let o = run(args);
    assert!(!o.status.success(), "{args:?} should fail");
    let e = stderr(&o);
    assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
    e
}

#[test]
fn invalid_points_are_refused_unless_filled() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let frt = dir.join("frt/frt-2.frt");
    let tmp = tempfile::tempdir().unwrap();
    // The map as stored: its invalid points and the rms of its valid heights.
    let o = run_ok(&["topography", s(&frt), "--json"]);
    let t: Value = serde_json::from_slice(&o.stdout).unwrap();
    let total = t["nx"].as_u64().unwrap() * t["ny"].as_u64().unwrap();
    let valid = t["valid_points"].as_u64().unwrap();
    let invalid = total - valid;
    assert!(invalid > 0, "the sample has invalid points");
    let e = one_line_error(&[
        "simulate",
        "--topography",
        s(&frt),
        "--modulus",
        "3GPa",
        "--model",
        "elastic",
        "--forces",
        "0.1mN",
        "--out",
        s(&tmp.path().join("refused")),
    ]);
    assert!(
        e.contains(&format!("{invalid} of {total} points")) && e.contains("--fill-invalid"),
        "{e}"
    );
    assert!(!tmp.path().join("refused").exists(), "nothing written");
    // Mean fill without detrending: the filled points sit at the mean, so the rms over every
    // point is the valid points' rms × √(valid/total).
    let mean = simulate(
        &tmp.path().join("mean"),
        &frt,
        &["--fill-invalid", "mean", "--detrend", "none"],
    );
    let h_valid_nm = t["h_rms_as_stored_um"].as_f64().unwrap() * 1e3;
    let expected = h_valid_nm * (valid as f64 / total as f64).sqrt();
    let got = mean["topography"]["h_rms_nm"].as_f64().unwrap();
    assert!((got / expected - 1.0).abs() < 1e-9, "{got} vs {expected}");
    assert_eq!(mean["topography"]["fill_invalid"], "mean");
    let warnings = mean["warnings"].to_string();
    assert!(
        warnings.contains(&format!("{invalid} invalid point(s) filled")),
        "{warnings}"
    );
    // Nearest fill gives another map (a larger rms here: edges are extended, not flattened).
    let nearest = simulate(
        &tmp.path().join("nearest"),
        &frt,
        &["--fill-invalid", "nearest", "--detrend", "none"],
    );
    let h_nearest = nearest["topography"]["h_rms_nm"].as_f64().unwrap();
    assert!((h_nearest / got - 1.0).abs() > 1e-3, "{h_nearest} vs {got}");
}

#[test]
fn channel_by_name_for_simulate_and_fit_hardening() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let ibw = dir.join("ibw/spot_1-1000nm.ibw");
    let tmp = tempfile::tempdir().unwrap();
    let default = simulate(&tmp.path().join("d"), &ibw, &[]);
    let retrace = simulate(&tmp.path().join("r"), &ibw, &["--channel", "HeightRetrace"]);
    assert_eq!(retrace["topography"]["channel"], "HeightRetrace");
    let (hd, hr) = (
        default["topography"]["h_rms_nm"].as_f64().unwrap(),
        retrace["topography"]["h_rms_nm"].as_f64().unwrap(),
    );
    assert!(hd > 0.0 && hr > 0.0 && hd != hr, "{hd} vs {hr}");
    // The same channel through `topography` gives the same rms of the plane-detrended map.
    let o = run_ok(&[
        "topography",
        s(&ibw),
        "--channel",
        "HeightRetrace",
        "--json",
    ]);
    let t: Value = serde_json::from_slice(&o.stdout).unwrap();
    let h_t = t["detrended"]["h_rms_nm"].as_f64().unwrap();
    assert!((h_t / hr - 1.0).abs() < 1e-12, "{h_t} vs {hr}");
    // Unknown channel: the error lists them; a single-map format refuses --channel.
    let out = tmp.path().join("x");
    let base = |topo: &'static str| vec!["--modulus", "3GPa", "--out", s(&out), "--channel", topo];
    let mut args = vec![
        "simulate",
        "--model",
        "elastic",
        "--forces",
        "1mN",
        "--topography",
        s(&ibw),
    ];
    args.extend(base("Nope"));
    let e = one_line_error(&args);
    assert!(
        e.contains("no channel 'Nope'") && e.contains("HeightRetrace"),
        "{e}"
    );
    let npy = tmp.path().join("flat.npy");
    run_ok(&[
        "surface",
        "--size",
        "16",
        "--pixel-size",
        "1um",
        "--hurst",
        "0.8",
        "--rms-slope",
        "0.1",
        "--seed",
        "1",
        "--out",
        s(&npy),
    ]);
    let mut args = vec![
        "simulate",
        "--model",
        "elastic",
        "--forces",
        "1mN",
        "--pixel-size",
        "1um",
        "--topography",
        s(&npy),
    ];
    args.extend(base("Phase"));
    let e = one_line_error(&args);
    assert!(
        e.contains("no channel 'Phase'") && e.contains("holds one height map"),
        "{e}"
    );
    // fit-hardening takes the same flags (the channel is read before any fitting).
    let areas = tmp.path().join("areas.csv");
    std::fs::write(&areas, "force_mN,area_um2\n1,10\n2,16\n4,25\n").unwrap();
    let mut args = vec![
        "fit-hardening",
        "--areas",
        s(&areas),
        "--radius",
        "290um",
        "--topography",
        s(&ibw),
    ];
    args.extend(base("Nope"));
    let e = one_line_error(&args);
    assert!(e.contains("no channel 'Nope'"), "{e}");
}

/// Gwyddion's `test.gwy` has no units: its 1 m pixels are outside the plausible range. The
/// summary as stored is still printed (the issue's "every file gives its statistics"), with
/// the reason as a note; `simulate` refuses it with one line, and `--pixel-size` is the way out.
#[test]
fn implausible_pixel_size_is_summarised_and_refused_for_contact() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let gwy = dir.join("gwy/test.gwy");
    let o = run_ok(&["topography", s(&gwy), "--json"]);
    let t: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((t["nx"].as_u64(), t["ny"].as_u64()), (Some(128), Some(128)));
    assert_eq!(t["pixel_size_um"]["x"].as_f64(), Some(1e6));
    let note = t["note"].as_str().unwrap_or_default();
    assert!(note.contains("pixel size"), "{t}");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("sim");
    let e = one_line_error(&[
        "simulate",
        "--topography",
        s(&gwy),
        "--modulus",
        "3GPa",
        "--model",
        "elastic",
        "--forces",
        "0.1mN",
        "--out",
        s(&out),
    ]);
    assert!(e.contains("test.gwy") && e.contains("pixel size"), "{e}");
    assert!(!out.exists());
    // With a pixel size given, the map is usable.
    let o = run_ok(&["topography", s(&gwy), "--pixel-size", "100nm", "--json"]);
    let t: Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(t["note"].is_null(), "{t}");
}

/// A map too small for the slope and curvature (2 × 2, 2 × 5) is summarised with what can be
/// computed (grid, pixel size, heights as stored), the slope and curvature null and a note why;
/// 3 × 3 gets them all.
#[test]
fn tiny_maps_print_what_they_can() {
    let tmp = tempfile::tempdir().unwrap();
    for (nx, ny) in [(2usize, 2usize), (5, 2), (3, 3)] {
        let heights: Vec<f32> = (0..nx * ny).map(|i| (i * i) as f32 * 1e-9).collect();
        let mut bytes = format!(
            "Gwyddion Simple Field 1.0\nXRes = {nx}\nYRes = {ny}\nXReal = {}e-6\nYReal = {}e-6\n\
             XYUnits = m\nZUnits = m\n",
            nx, ny
        )
        .into_bytes();
        let pad = 4 - bytes.len() % 4;
        bytes.extend(std::iter::repeat_n(0u8, pad));
        for h in &heights {
            bytes.extend_from_slice(&h.to_le_bytes());
        }
        let path = tmp.path().join(format!("t{nx}x{ny}.gsf"));
        std::fs::write(&path, bytes).unwrap();
        let o = run_ok(&["topography", s(&path), "--json"]);
        let t: Value = serde_json::from_slice(&o.stdout).unwrap();
        let max_um = heights.iter().fold(0f32, |a, &b| a.max(b)) as f64 * 1e6;
        assert!(
            (t["height_max_um"].as_f64().unwrap() - max_um).abs() < 1e-12,
            "{t}"
        );
        assert!(t["h_rms_as_stored_um"].as_f64().unwrap() > 0.0, "{t}");
        let small = nx < 3 || ny < 3;
        assert_eq!(t["h_prime_rms_as_stored"].is_null(), small, "{t}");
        assert_eq!(t["detrended"].is_null(), small, "{t}");
        let note = t["note"].as_str().unwrap_or_default();
        assert_eq!(
            note.contains("needs at least 3 × 3 pixels (map is"),
            small,
            "{t}"
        );
        // The text summary too, with exit status 0.
        let o = run_ok(&["topography", s(&path)]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("heights:"), "{text}");
    }
}
