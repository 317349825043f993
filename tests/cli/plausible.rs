//! Nothing silently wrong: every number a command gives is plausible, consistent with its inputs,
//! or comes with a warning — fits that say what they rest on, maps that say what they hold, pixel
//! sizes checked against the files' own, results outside physical ranges warned of.

use std::path::{Path, PathBuf};

use crate::common::{fixture_series, run, run_ok, stderr, stdout};

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A 64² map of 100 nm pixels, 20 nm rms: contacts reach its border from about 1 mN.
fn small_map(dir: &Path) -> PathBuf {
    let map = dir.join("rough.gsf");
    run_ok(&[
        "surface",
        "--size",
        "64",
        "--pixel-size",
        "100nm",
        "--rms-height",
        "20nm",
        "--out",
        s(&map),
    ]);
    map
}

/// A synthetic series of two 64² micrographs (1 and 2 mN) with its manifest, in `dir/synth`.
fn small_micrographs(dir: &Path) -> PathBuf {
    let synth = dir.join("synth");
    run_ok(&[
        "synth-series",
        "--out",
        s(&synth),
        "--size",
        "64",
        "--forces",
        "1mN,2mN",
    ]);
    synth
}

fn simulate(map: &Path, forces: &str, out: &Path, maps: &str) -> std::process::Output {
    run(&[
        "simulate",
        "--topography",
        s(map),
        "--model",
        "elastic",
        "--radius",
        "290um",
        "--modulus",
        "3.7GPa",
        "--forces",
        forces,
        "--maps",
        maps,
        "--out",
        s(out),
    ])
}

#[test]
fn simulated_loads_at_the_border_leave_the_fit_and_all_invalid_exits_4() {
    let dir = tempfile::tempdir().unwrap();
    let map = small_map(dir.path());
    let out = dir.path().join("sim");
    let o = simulate(&map, "0.0001mN,0.001mN,0.01mN,1mN,10mN", &out, "none");
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(
        err.contains(
            "2 of 5 loads left out of the area–load fits and marked on the plot, 1 mN, 10 mN"
        ),
        "{err}"
    );
    assert!(stdout(&o).contains("(edge contact: left out of the fit)"));
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["power_law"]["points"], 3, "{summary}");
    let edges: Vec<bool> = summary["loads"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["edge_contact"].as_bool().unwrap())
        .collect();
    assert_eq!(edges, [false, false, false, true, true]);

    // Every load at the border: outputs written, a warning, exit status 4.
    let all = dir.path().join("all");
    let o = simulate(&map, "5mN,10mN", &all, "none");
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(stderr(&o).contains("no load is valid"), "{}", stderr(&o));
    assert!(all.join("areas.csv").is_file());
    assert!(json(&all.join("summary.json"))["power_law"].is_null());
}

#[test]
fn an_analysis_says_what_its_fit_rests_on() {
    let dir = tempfile::tempdir().unwrap();
    let series = fixture_series().join("series.tif");
    // Page 0 twice (a manifest naming one page for two loads).
    let manifest = dir.path().join("twice.csv");
    std::fs::write(
        &manifest,
        format!("file,page,force_mN\n{0},0,4\n{0},0,8\n", s(&series)),
    )
    .unwrap();
    let out = dir.path().join("twice");
    let o = run_ok(&["analyze", s(&manifest), "--out", s(&out)]);
    let err = stderr(&o);
    for needle in [
        "is given twice (images 1 and 2)",
        "every load gives the same area",
        "rests on 2 point(s) at 2 distinct force(s)",
    ] {
        assert!(err.contains(needle), "'{needle}' not in {err}");
    }
    assert!(
        stdout(&o).contains("R² = — (fewer than 3 distinct forces)"),
        "{}",
        stdout(&o)
    );
    let law = &json(&out.join("summary.json"))["fits"]["power_law"];
    assert!(
        law["r_squared"].is_null() && law["exponent_se"].is_null(),
        "{law}"
    );
    assert_eq!(law["distinct_forces"], 2);

    // A frame without contact (a threshold above every pixel) is named, not dropped silently.
    let none = dir.path().join("none");
    let o = run(&[
        "analyze",
        s(&series),
        "--forces",
        "4,6,10,16,25,40,63,100mN",
        "--threshold",
        "65535",
        "--out",
        s(&none),
    ]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("8 of 8 loads left out of the area–load fits"),
        "{}",
        stderr(&o)
    );
    assert!(none.join("areas.csv").is_file());
}

#[test]
fn every_map_a_command_writes_says_what_it_holds_and_is_read_as_that() {
    let dir = tempfile::tempdir().unwrap();
    let map = small_map(dir.path());
    let sim = dir.path().join("sim");
    let o = simulate(&map, "0.001mN,0.01mN", &sim, "all");
    assert!(o.status.success(), "{}", stderr(&o));
    let masks = dir.path().join("masks");
    run_ok(&[
        "analyze",
        s(&fixture_series().join("series.tif")),
        "--forces",
        "4,6,10,16,25,40,63,100mN",
        "--save-masks",
        "--out",
        s(&masks),
    ]);
    let synth = small_micrographs(dir.path());

    let mut tiffs: Vec<PathBuf> = [&sim, &masks, &synth]
        .iter()
        .flat_map(|d| std::fs::read_dir(d).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "tif"))
        .collect();
    tiffs.sort();
    assert_eq!(tiffs.len(), 5 * 2 + 8 + 1, "{tiffs:?}");
    for tiff in &tiffs {
        let name = tiff.file_name().unwrap().to_str().unwrap();
        let (quantity, unit) = match name {
            n if n.ends_with("_contact.tif") => ("contact", None),
            n if n.ends_with("_pressure_MPa.tif") => ("pressure", Some("MPa")),
            n if n.ends_with("_gap_um.tif") => ("gap", Some("um")),
            n if n.ends_with("_plastic_um.tif") => ("plastic displacement", Some("um")),
            n if n.ends_with("_deformed_um.tif") => ("height", Some("um")),
            n if n.starts_with("mask_") => ("contact mask", None),
            _ => ("intensity", None),
        };
        let info = stdout(&run_ok(&["info", s(tiff)]));
        let said = match unit {
            Some(u) => format!("values:       {quantity} in {u}\n"),
            None => format!("values:       {quantity}\n"),
        };
        assert!(info.contains(&said), "{name}: {info}");

        let topo = run(&["topography", s(tiff), "--json", "--detrend", "none"]);
        if quantity == "height" {
            // Read in its own unit: the heights in metres are the stored µm × 1e-6.
            assert!(topo.status.success(), "{name}: {}", stderr(&topo));
            let facts: serde_json::Value = serde_json::from_slice(&topo.stdout).unwrap();
            let stored = contactscope_formats::tiff::read_image(tiff, None, None).unwrap();
            let max_um = stored.values.iter().copied().fold(f64::MIN, f64::max);
            let read = facts["height_max_um"].as_f64().unwrap();
            assert!(
                (read - max_um).abs() <= 1e-9 * max_um.abs().max(1.0),
                "{read} vs {max_um}"
            );
            // A height unit beside the file's own is refused.
            let both = run(&["topography", s(tiff), "--height-unit", "1nm"]);
            assert!(
                stderr(&both).contains("states its height unit (um)"),
                "{}",
                stderr(&both)
            );
        } else {
            let err = stderr(&topo);
            assert!(!topo.status.success(), "{name} read as heights");
            assert!(err.contains(&format!("holds {quantity}")), "{name}: {err}");
            assert!(err.contains(name), "{name}: {err}");
        }

        let analyse = run(&["analyze", s(tiff), "--out", s(&dir.path().join("a"))]);
        if quantity == "intensity" {
            assert!(analyse.status.success(), "{name}: {}", stderr(&analyse));
            std::fs::remove_dir_all(dir.path().join("a")).unwrap();
        } else {
            let err = stderr(&analyse);
            assert!(
                err.contains("not a micrograph's intensities"),
                "{name}: {err}"
            );
        }
    }

    // compare takes only contact maps: a pressure map in a contact map's place is refused.
    std::fs::copy(
        sim.join("load_001_pressure_MPa.tif"),
        sim.join("load_001_contact.tif"),
    )
    .unwrap();
    let o = run(&[
        "compare",
        "--simulation",
        s(&sim),
        "--micrographs",
        s(&synth),
        "--psf-fwhm",
        "450nm",
        "--out",
        s(&dir.path().join("c")),
    ]);
    assert!(
        stderr(&o).contains("holds pressure in MPa, not a contact map"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_pixel_size_far_from_the_files_own_is_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let series = fixture_series().join("series.tif");
    let forces = "4,6,10,16,25,40,63,100mN";
    let analyse = |pixel: &str| {
        let out = dir.path().join(pixel);
        run_ok(&[
            "analyze",
            s(&series),
            "--forces",
            forces,
            "--pixel-size",
            pixel,
            "--out",
            s(&out),
        ])
    };
    // 1000× the metadata's 0.2 µm: both named, and the absurd pressures that follow.
    let err = stderr(&analyse("200um"));
    assert!(
        err.contains("--pixel-size 200 µm is 1000× larger than the 200 nm of"),
        "{err}"
    );
    assert!(err.contains("ImageJ"), "{err}");
    assert!(err.contains("below any contact that bears a load"), "{err}");
    // Below a light microscope's resolution.
    let err = stderr(&analyse("0.5nm"));
    assert!(
        err.contains("far below what a light microscope resolves"),
        "{err}"
    );
    assert!(err.contains("is 400× smaller than the 200 nm"), "{err}");
    // Within 1.5× of the metadata: no word.
    let err = stderr(&analyse("250nm"));
    assert!(!err.contains("metadata"), "{err}");
}

/// The fuzz campaign's one abort: micrographs whose pixel size makes the simulated region tens of
/// thousands of pixels wide were rendered (gigabytes) before being refused. Under a 2 GiB address
/// space limit the refusal must come first, as one line.
#[test]
fn compare_refuses_an_oversized_rendering_before_allocating_it() {
    let dir = tempfile::tempdir().unwrap();
    let map = small_map(dir.path());
    let sim = dir.path().join("sim");
    // Loads that match the micrographs' (on this small map they reach its border: status 4).
    let o = simulate(&map, "1mN,2mN", &sim, "contact");
    assert!(sim.join("load_002_contact.tif").is_file(), "{}", stderr(&o));
    let synth = small_micrographs(dir.path());
    let o = run_limited(&[
        "compare",
        "--simulation",
        s(&sim),
        "--micrographs",
        s(&synth),
        "--psf-fwhm",
        "450nm",
        "--pixel-size",
        "0.2nm",
        "--out",
        s(&dir.path().join("c")),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("larger than the micrograph"), "{err}");
    assert!(err.contains("check the micrographs' pixel size"), "{err}");
    assert!(!dir.path().join("c").exists());
}

/// Run `args` under a 2 GiB address-space limit: a size that passed the checks and then
/// allocated would abort instead of failing in one line.
fn run_limited(args: &[&str]) -> std::process::Output {
    let quoted: Vec<String> = args.iter().map(|a| format!("'{a}'")).collect();
    let line = format!(
        "ulimit -v 2097152; exec '{}' {}",
        env!("CARGO_BIN_EXE_contactscope"),
        quoted.join(" ")
    );
    std::process::Command::new("sh")
        .args(["-c", &line])
        .output()
        .unwrap()
}

#[test]
fn sizes_are_checked_before_the_grids_are_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s");
    // 100 images of 8192² kept in memory (19 GiB).
    let o = run_limited(&[
        "synth-series",
        "--size",
        "8192",
        "--forces",
        "4mN..4.4mN:100",
        "--out",
        s(&out),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("100 images of 8192×8192 px would hold 18.8 GiB"),
        "{err}"
    );
    assert!(!out.exists());
    // A simulated contact map imaged on 0.2 nm pixels: 32,000² per load from the 6.4 µm map
    // (each side within the limit, the plane 7.6 GiB), refused before the first load is solved.
    let map = small_map(dir.path());
    let measured = dir.path().join("areas.csv");
    std::fs::write(&measured, "force_mN,area_um2\n1,2\n2,3\n3,4\n").unwrap();
    let o = run_limited(&[
        "fit-hardening",
        "--areas",
        s(&measured),
        "--topography",
        s(&map),
        "--modulus",
        "3.7GPa",
        "--imaged-areas",
        "--psf-fwhm",
        "450nm",
        "--micrograph-pixel-size",
        "0.2nm",
        "--out",
        s(&dir.path().join("fit")),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("resampling"), "{err}");
}

#[test]
fn messages_keep_clap_suggestions_and_point_to_the_right_command() {
    let one_line = |args: &[&str]| {
        let o = run(args);
        assert!(!o.status.success(), "{args:?}");
        let err = stderr(&o);
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        err
    };
    let err = one_line(&["analyse", "x"]);
    assert!(err.contains("'analyze'"), "{err}");
    let err = one_line(&["analyze", "x.tif", "--force", "4mN"]);
    assert!(err.contains("'--forces'"), "{err}");
    // A height map where a micrograph is expected.
    let dir = tempfile::tempdir().unwrap();
    let gwy = dir.path().join("scan.gwy");
    std::fs::write(&gwy, b"GWYP\0\0\0\0GwyContainer\0rest of a file").unwrap();
    for command in ["info", "threshold"] {
        let err = one_line(&[command, s(&gwy)]);
        assert!(
            err.contains("a gwy height map") && err.contains("topography"),
            "{err}"
        );
    }
    // A reference frame before a range of loads.
    let out = dir.path().join("ranged");
    let o = run_ok(&[
        "analyze",
        s(&fixture_series().join("series.tif")),
        "--forces",
        "0,1mN..100mN:7",
        "--out",
        s(&out),
    ]);
    assert!(stdout(&o).contains("     0.000 "), "{}", stdout(&o));
    // A confocal file given as a height map says what it is; an unknown extension lists the
    // formats read by content too.
    let czi = crate::common::czi::czi(&[]);
    let path = dir.path().join("scan.czi");
    std::fs::write(&path, czi).unwrap();
    let err = stderr(&run(&["topography", s(&path)]));
    assert!(err.contains("a CZI micrograph, not a height map"), "{err}");
    // The article as the name is spoken ("an ND2").
    let path = dir.path().join("scan.nd2");
    let mut nd2 = vec![0xda, 0xce, 0xbe, 0x0a];
    nd2.resize(4096, 0);
    std::fs::write(&path, nd2).unwrap();
    let err = stderr(&run(&["topography", s(&path)]));
    assert!(err.contains("an ND2 micrograph, not a height map"), "{err}");
    let path = dir.path().join("scan.xyz");
    std::fs::write(&path, b"\x01\x02\x00\x03binary").unwrap();
    let err = stderr(&run(&["topography", s(&path)]));
    assert!(
        err.contains("recognises from its content (named .xyz)") && err.contains("Igor .ibw"),
        "{err}"
    );
}

/// Another program's ImageJ TIFF: a length `vunit` is honoured as the heights' unit; a unit that
/// is not a length ("Gray Value") says nothing about heights and leaves `--height-unit` to decide.
#[test]
fn a_foreign_value_unit_is_honoured_only_when_it_is_a_length() {
    let dir = tempfile::tempdir().unwrap();
    let heights: Vec<f32> = (0..64).map(|i| (i % 8) as f32 * 10.0).collect();
    let write = |name: &str, extra: &str| {
        let path = dir.path().join(name);
        let bytes = contactscope_formats::tiff::encode_f32_stack(
            &[&heights],
            8,
            8,
            Some((1e-7, 1e-7)),
            extra,
        )
        .unwrap();
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let max_um = |args: &[&str]| {
        let o = run_ok(args);
        let facts: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        facts["height_max_um"].as_f64().unwrap()
    };
    let nm = write("nm.tif", "vunit=nm\n");
    let read = max_um(&["topography", s(&nm), "--json", "--detrend", "none"]);
    assert!((read - 0.07).abs() < 1e-9, "{read}");
    let grey = write("grey.tif", "vunit=Gray Value\n");
    let read = max_um(&[
        "topography",
        s(&grey),
        "--height-unit",
        "1nm",
        "--json",
        "--detrend",
        "none",
    ]);
    assert!((read - 0.07).abs() < 1e-9, "{read}");
}

#[test]
fn a_flat_map_for_the_greenwood_tripp_model_names_the_file() {
    // Found by the fuzz campaign (seed 13): the error named no file.
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("flat.txt");
    let row = vec!["0"; 32].join(" ");
    std::fs::write(&map, vec![row; 32].join("\n")).unwrap();
    let out = dir.path().join("o");
    let o = run(&[
        "simulate",
        "--topography",
        s(&map),
        "--pixel-size",
        "200nm",
        "--radius",
        "20um",
        "--modulus",
        "3.7GPa",
        "--model",
        "gt",
        "--forces",
        "1mN",
        "--out",
        s(&out),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("flat.txt: Greenwood–Tripp: h_rms 0 m"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn a_solver_that_does_not_converge_names_the_map() {
    // Found by a fuzz campaign (seed 19, a map with its lines flipped): the non-convergence
    // error named no file. An iteration limit of 2 reproduces it on any map.
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("rough.npy");
    crate::common::rough_surface(&map, 64, "200nm", 3, &[]);
    let out = dir.path().join("o");
    let o = run(&[
        "simulate",
        "--topography",
        s(&map),
        "--pixel-size",
        "200nm",
        "--radius",
        "20um",
        "--modulus",
        "3.7GPa",
        "--model",
        "elastic",
        "--forces",
        "0.1mN",
        "--max-iterations",
        "2",
        "--out",
        s(&out),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("rough.npy: ")
            && err.contains("did not converge")
            && err.contains("--max-iterations"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
}

/// Physics checks on every result (`docs/conventions.md`, "Plausible results"): a number no
/// contact can give is kept, with a warning naming the likely cause.
#[test]
fn impossible_results_are_warned_of_with_their_likely_cause() {
    let dir = tempfile::tempdir().unwrap();
    // Forces listed from the largest load: the area falls as the load rises.
    let series = fixture_series().join("series.tif");
    let out = dir.path().join("reversed");
    let o = run_ok(&[
        "analyze",
        s(&series),
        "--forces",
        "100,63,40,25,16,10,6,4mN",
        "--out",
        s(&out),
    ]);
    let err = stderr(&o);
    assert!(
        err.contains("area falls as the load rises") && err.contains("wrong order"),
        "{err}"
    );
    let warnings = json(&out.join("summary.json"))["warnings"].to_string();
    assert!(warnings.contains("wrong order"), "{warnings}");
    // In load order: no such warning.
    let o = run_ok(&[
        "analyze",
        s(&series),
        "--forces",
        "4,6,10,16,25,40,63,100mN",
        "--out",
        s(&dir.path().join("ordered")),
    ]);
    assert!(!stderr(&o).contains("wrong order"), "{}", stderr(&o));

    // A squeeze test in mN under a header that says N: E* a thousand times too stiff.
    let mut csv = String::from("force_N,displacement_um\n");
    let (r, e_star) = (290e-6_f64, 3.7e9_f64);
    for i in 1..=20 {
        let p = 2e-3 * f64::from(i);
        let delta = (3.0 * p / (4.0 * e_star * r.sqrt())).powf(2.0 / 3.0);
        csv.push_str(&format!("{},{}\n", p * 1e3, 2.0 * delta * 1e6));
    }
    let squeeze = dir.path().join("squeeze.csv");
    std::fs::write(&squeeze, csv).unwrap();
    let out = dir.path().join("hertz");
    let o = run_ok(&["hertz", s(&squeeze), "--radius", "290um", "--out", s(&out)]);
    let err = stderr(&o);
    assert!(
        err.contains("contact modulus E*") && err.contains("_N") && err.contains("squeeze.csv"),
        "{err}"
    );
    let hertz = json(&out.join("hertz.json"));
    assert!(hertz["warnings"][0].as_str().unwrap().contains("diamond"));

    // A friction trace whose friction_N column holds mN: μ in the hundreds.
    let mut trace = String::from("time_s,friction_N,normal_force_mN\n");
    for i in 0..=200 {
        let t = f64::from(i) * 0.5;
        let f = if t <= 50.0 { 0.4 * t } else { 14.0 };
        let wiggle = 0.01 * ((i * 37) % 7) as f64;
        trace.push_str(&format!("{t},{},40\n", f + wiggle));
    }
    let trace_path = dir.path().join("trace.csv");
    std::fs::write(&trace_path, trace).unwrap();
    let o = run_ok(&[
        "friction",
        s(&trace_path),
        "--out",
        s(&dir.path().join("friction")),
    ]);
    let err = stderr(&o);
    assert!(
        err.contains("static friction coefficient μ") && err.contains("trace.csv"),
        "{err}"
    );
}

/// Heights stored in µm but read as metres: an rms height of metres and slopes in the
/// thousands are named, with the option that fixes them.
#[test]
fn heights_in_the_wrong_unit_are_warned_of() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::new();
    for y in 0..32 {
        let row: Vec<String> = (0..32)
            .map(|x| format!("{:.4}", 0.1 * ((x * 7 + y * 13) % 11) as f64 - 0.5))
            .collect();
        text.push_str(&row.join(" "));
        text.push('\n');
    }
    let map = dir.path().join("heights_um.txt");
    std::fs::write(&map, text).unwrap();
    let o = run_ok(&["topography", s(&map), "--pixel-size", "100nm"]);
    let err = stderr(&o);
    assert!(
        err.contains("rms height") && err.contains("--height-unit"),
        "{err}"
    );
    assert!(err.contains("rms slope"), "{err}");
    // Told the unit: no warning.
    let o = run_ok(&[
        "topography",
        s(&map),
        "--pixel-size",
        "100nm",
        "--height-unit",
        "1um",
    ]);
    assert!(!stderr(&o).contains("rms height"), "{}", stderr(&o));
}
