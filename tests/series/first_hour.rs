//! The commands a newcomer tries first, on the bundled series: `analyze` without forces, on a
//! folder holding `manifest.csv`, with a threshold that finds no contact, with force ranges and
//! a 0 mN reference frame; reruns into the same output folder.

use std::fs;
use std::path::Path;

use crate::common::{column, fixture_series, read_csv, run, run_ok, stderr};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn names(dir: &Path) -> Vec<String> {
    let mut n: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    n.sort();
    n
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn analyze_without_forces_measures_every_image_and_says_why_there_is_no_fit() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("first-look");
    let tif = fixture_series().join("series.tif");
    let o = run_ok(&["analyze", s(&tif), "--out", s(&out), "-q"]);
    let err = stderr(&o);
    assert!(
        err.contains("no forces") && err.contains("--forces"),
        "{err}"
    );
    assert!(
        !out.join("area_vs_load.png").exists(),
        "no log plot without forces"
    );
    let (header, rows) = read_csv(&out.join("areas.csv"));
    assert_eq!(rows.len(), 8);
    let areas = column(&header, &rows, "area_um2");
    assert!(areas.windows(2).all(|w| w[1] > w[0]), "{areas:?}");
    let k = header.iter().position(|h| h == "force_mN").unwrap();
    assert!(rows.iter().all(|r| r[k].is_empty()), "forces left empty");
    let fits = &summary(&out)["fits"];
    assert!(fits["power_law"].is_null() && fits["proportional"].is_null());
}

#[test]
fn a_folder_holding_manifest_csv_is_that_manifest_everywhere() {
    let tmp = tempfile::tempdir().unwrap();
    let folder = fixture_series();
    let by_folder = tmp.path().join("folder");
    let by_flag = tmp.path().join("flag");
    let by_csv = tmp.path().join("csv");
    run_ok(&["analyze", s(&folder), "--out", s(&by_folder), "-q"]);
    run_ok(&[
        "analyze",
        "--manifest",
        s(&folder),
        "--out",
        s(&by_flag),
        "-q",
    ]);
    let manifest = folder.join("manifest.csv");
    run_ok(&["analyze", s(&manifest), "--out", s(&by_csv), "-q"]);
    let areas = |d: &Path| {
        let (h, r) = read_csv(&d.join("areas.csv"));
        (column(&h, &r, "force_mN"), column(&h, &r, "area_um2"))
    };
    let reference = areas(&by_flag);
    assert_eq!(reference.0.len(), 8);
    assert_eq!(areas(&by_folder), reference);
    assert_eq!(areas(&by_csv), reference);
    assert!(by_folder.join("area_vs_load.png").exists());
}

#[test]
fn a_threshold_that_finds_no_contact_gives_its_table_and_a_warning() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let tif = fixture_series().join("series.tif");
    // The table is written; no load is valid, which is exit status 4 (docs/errors.md).
    let o = crate::common::run(&[
        "analyze",
        s(&tif),
        "--forces",
        "4,6,10,16,25,40,63,100mN",
        "--threshold",
        "60000",
        "--out",
        s(&out),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("no image has contact pixels"),
        "{}",
        stderr(&o)
    );
    let (h, r) = read_csv(&out.join("areas.csv"));
    assert!(column(&h, &r, "area_um2").iter().all(|&a| a == 0.0));
    assert!(!out.join("area_vs_load.png").exists());
}

#[test]
fn force_ranges_and_a_zero_reference_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let tif = fixture_series().join("series.tif");
    let ranged = tmp.path().join("ranged");
    run_ok(&[
        "analyze",
        s(&tif),
        "--forces",
        "1mN..128mN:8",
        "--out",
        s(&ranged),
        "-q",
    ]);
    let (h, r) = read_csv(&ranged.join("areas.csv"));
    let forces = column(&h, &r, "force_mN");
    for (i, f) in forces.iter().enumerate() {
        assert!((f - 2f64.powi(i as i32)).abs() < 1e-9, "{forces:?}");
    }
    // The first image as a 0 mN reference frame: measured, left out of the fits and the plot.
    let zero = tmp.path().join("zero");
    run_ok(&[
        "analyze",
        s(&tif),
        "--forces",
        "0,6,10,16,25,40,63,100mN",
        "--out",
        s(&zero),
        "-q",
    ]);
    let (h, r) = read_csv(&zero.join("areas.csv"));
    assert_eq!(column(&h, &r, "force_mN")[0], 0.0);
    assert!(column(&h, &r, "area_um2")[0] > 0.0, "the frame is measured");
    let fits = &summary(&zero)["fits"];
    assert_eq!(fits["power_law"]["points"], 7);
    assert_eq!(fits["proportional"]["points"], 7);
    assert!(zero.join("area_vs_load.png").exists());
    // The same series as a manifest in newtons.
    let manifest = tmp.path().join("newtons.csv");
    let mut text = String::from("file,page,force_N\n");
    for (page, f) in [0.0, 6.0, 10.0, 16.0, 25.0, 40.0, 63.0, 100.0]
        .iter()
        .enumerate()
    {
        text += &format!("{},{page},{}\n", s(&tif), f * 1e-3);
    }
    fs::write(&manifest, text).unwrap();
    let newtons = tmp.path().join("newtons");
    run_ok(&[
        "analyze",
        "--manifest",
        s(&manifest),
        "--out",
        s(&newtons),
        "-q",
    ]);
    let (h2, r2) = read_csv(&newtons.join("areas.csv"));
    assert_eq!(
        column(&h2, &r2, "area_um2"),
        column(&h, &r, "area_um2"),
        "force_N and force_mN manifests agree"
    );
    // The same as a spreadsheet saves it where the decimal mark is a comma: semicolons between
    // fields, decimal commas, a byte-order mark.
    let semicolons = tmp.path().join("semicolons.csv");
    let mut text = String::from("\u{feff}file;page;force_N\n");
    for (page, f) in [0.0, 6.0, 10.0, 16.0, 25.0, 40.0, 63.0, 100.0]
        .iter()
        .enumerate()
    {
        let newtons = format!("{}", f * 1e-3).replace('.', ",");
        text += &format!("{};{page};{newtons}\n", s(&tif));
    }
    fs::write(&semicolons, text).unwrap();
    let out3 = tmp.path().join("semicolons");
    run_ok(&["analyze", s(&semicolons), "--out", s(&out3), "-q"]);
    let (h3, r3) = read_csv(&out3.join("areas.csv"));
    assert_eq!(column(&h3, &r3, "force_mN"), column(&h2, &r2, "force_mN"));
    assert_eq!(column(&h3, &r3, "area_um2"), column(&h, &r, "area_um2"));
}

#[test]
fn a_rerun_replaces_its_folder_and_a_foreign_folder_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let folder = fixture_series();
    run_ok(&["analyze", s(&folder), "--overlays", "--out", s(&out), "-q"]);
    assert_eq!(
        names(&out)
            .iter()
            .filter(|n| n.starts_with("overlay_"))
            .count(),
        8
    );
    // Fewer images the second time: no overlay of the first run survives.
    let tif = folder.join("series.tif");
    let manifest = tmp.path().join("three.csv");
    fs::write(
        &manifest,
        format!("file,page,force_mN\n{0},0,4\n{0},1,6\n{0},2,10\n", s(&tif)),
    )
    .unwrap();
    run_ok(&[
        "analyze",
        s(&manifest),
        "--overlays",
        "--out",
        s(&out),
        "-q",
    ]);
    let overlays: Vec<String> = names(&out)
        .into_iter()
        .filter(|n| n.starts_with("overlay_"))
        .collect();
    assert_eq!(overlays.len(), 3, "{overlays:?}");
    // A folder of someone's own files is never replaced.
    let mine = tmp.path().join("mine");
    fs::create_dir_all(&mine).unwrap();
    fs::write(mine.join("notes.txt"), "keep").unwrap();
    let o = run(&["analyze", s(&folder), "--out", s(&mine), "-q"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("not written by contactscope") && err.contains("--out"),
        "{err}"
    );
    assert_eq!(names(&mine), ["notes.txt"]);
    assert_eq!(
        fs::read_dir(tmp.path()).unwrap().count(),
        3,
        "nothing left beside"
    );
}

#[test]
fn a_manifest_beside_forces_or_other_inputs_is_refused_in_one_line() {
    // The folder's manifest lists its images and their forces: a second source of forces, or
    // images read beside it, is refused before anything is written (it was once ignored).
    let tmp = tempfile::tempdir().unwrap();
    let folder = fixture_series();
    let out = tmp.path().join("out");
    let tif = folder.join("series.tif");
    let manifest = folder.join("manifest.csv");
    let cases: [(&[&str], &str, &str); 3] = [
        (
            &[s(&folder), "--forces", "1mN..8mN:8"],
            s(&folder),
            "--forces would give",
        ),
        (&[s(&folder), s(&tif)], s(&folder), "other inputs beside it"),
        (
            &[s(&manifest), "--forces", "1,2mN"],
            s(&manifest),
            "--forces would give",
        ),
    ];
    for (inputs, named, says) in cases {
        let mut args = vec!["analyze"];
        args.extend_from_slice(inputs);
        args.extend(["--out", s(&out)]);
        let o = run(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(named) && err.contains(says), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!out.exists(), "{args:?}: wrote {}", out.display());
    }
    // Alone, the folder is its manifest.
    run_ok(&["analyze", s(&folder), "--out", s(&out), "-q"]);
    assert!(out.join("areas.csv").exists());
}
