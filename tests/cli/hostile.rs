//! Regression inputs of the reliability work (issue 12): the files of `tests/hostile/` and
//! hostile arguments built here. Each must give one clean error line that names its source,
//! exit non-zero, write nothing and change no input.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::{fixture_series, run_in, stderr};

fn hostile(name: &str) -> PathBuf {
    crate::common::root().join("tests/hostile").join(name)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Run in `dir`, expect exit `code`, one `contactscope: error:` line holding every needle, and no
/// `out` folder.
fn refused_in(dir: &Path, args: &[&str], code: i32, needles: &[&str]) -> String {
    let o = run_in(dir, args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.starts_with("contactscope: error: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' not in {err}");
    }
    assert!(!dir.join("out").exists(), "{args:?} left out/");
    err
}

#[test]
fn corpus_files_give_one_clean_error_each() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cases: &[(&str, &[&str], &[&str])] = &[
        (
            "nanoscope-samps-2e58.di",
            &["topography"],
            &["288230376151711744", "limit"],
        ),
        (
            "nanoscope-samps-2e63.di",
            &["topography"],
            &["9223372036854775808", "limit"],
        ),
        (
            "gsf-huge-xres.gsf",
            &["topography"],
            &["288230376151711744", "limit"],
        ),
        (
            "npy-fortran-overflow.npy",
            &["topography", "--pixel-size", "100nm"],
            &["limit"],
        ),
        (
            "npy-fortran-zero-rows.npy",
            &["topography", "--pixel-size", "100nm"],
            &["no pixels"],
        ),
        (
            "npy-height-1e200.npy",
            &["topography", "--pixel-size", "100nm"],
            &["1e200 m", "--height-unit"],
        ),
    ];
    for (file, args, needles) in cases {
        let path = hostile(file);
        let mut full: Vec<&str> = args.to_vec();
        full.insert(1, s(&path));
        let mut needles = needles.to_vec();
        needles.push(file);
        refused_in(d, &full, 1, &needles);
    }
}

#[test]
fn absurd_psf_json_and_zero_areas_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let series = fixture_series().join("series.tif");
    crate::common::rough_surface(&d.join("t.npy"), 32, "200nm", 3, &[]);
    crate::common::run_ok(&[
        "simulate",
        "--topography",
        s(&d.join("t.npy")),
        "--pixel-size",
        "200nm",
        "--radius",
        "20um",
        "--modulus",
        "3.7GPa",
        "--model",
        "elastic",
        "--forces",
        "4,6,9,13,20,30,45,68mN",
        "--out",
        s(&d.join("sim")),
        "-q",
    ]);
    for json in ["psf-fwhm-1e13nm.json", "psf-fwhm-1e308nm.json"] {
        refused_in(
            d,
            &[
                "compare",
                "--micrographs",
                s(&series),
                "--forces",
                "4,6,9,13,20,30,45,68mN",
                "--simulation",
                "sim",
                "--psf",
                s(&hostile(json)),
                "--out",
                "out",
            ],
            1,
            &[json, "PSF FWHM", "plausible range"],
        );
    }
    refused_in(
        d,
        &[
            "fit-hardening",
            "--areas",
            s(&hostile("areas-zero-area.csv")),
            "--topography",
            "t.npy",
            "--pixel-size",
            "200nm",
            "--radius",
            "20um",
            "--modulus",
            "3.7GPa",
            "--out",
            "out",
        ],
        1,
        &["areas-zero-area.csv:3", "area_um2 = 0"],
    );
}

#[test]
fn absurd_sizes_on_the_command_line_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    refused_in(
        d,
        &[
            "surface",
            "--size",
            "9223372036854775808",
            "--pixel-size",
            "1nm",
            "--rms-height",
            "1nm",
            "--out",
            "out",
        ],
        1,
        &["limit of 65536 pixels"],
    );
    refused_in(
        d,
        &[
            "surface",
            "--size",
            "64",
            "--pixel-size",
            "10nm",
            "--rms-height",
            "1e308nm",
            "--out",
            "out",
        ],
        1,
        &["--rms-height", "plausible range"],
    );
    refused_in(
        d,
        &[
            "synth-series",
            "--size",
            "288230376151711744",
            "--out",
            "out",
        ],
        1,
        &["2^26"],
    );
}

/// Fuzz seed 7 (30 000 cases): `--upsample 4294967296` asked for 51 GB, `18446744073709551615`
/// overflowed a capacity; a squeeze row of 1e308 mN printed E* = inf.
#[test]
fn registration_upsampling_and_squeeze_numbers_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for n in ["0", "101", "4294967296", "18446744073709551615"] {
        refused_in(
            d,
            &[
                "compare",
                "--micrographs",
                "exp.tif",
                "--forces",
                "1mN",
                "--simulation",
                "sim",
                "--psf-fwhm",
                "450nm",
                "--upsample",
                n,
                "--out",
                "out",
            ],
            1,
            &["--upsample", "1 to 100"],
        );
    }
    // R = 290 µm, E* = 3.7 MPa: 2δ from F, then one absurd force or vanishing displacements.
    let rows = |f: &dyn Fn(usize) -> (String, String)| {
        let mut text = String::from("force_mN,displacement_um\n");
        for i in 1..=8 {
            let (force, disp) = f(i);
            text.push_str(&format!("{force},{disp}\n"));
        }
        text
    };
    let hertz = |force: f64| 2.0 * (9.0 * force * force / (16.0 * 290e-6 * 3.7e6 * 3.7e6)).cbrt();
    let absurd = rows(&|i| {
        let f = 0.5e-3 * i as f64;
        let force = if i == 8 {
            "1e308".to_string()
        } else {
            (f * 1e3).to_string()
        };
        (force, (hertz(f) * 1e6).to_string())
    });
    fs::write(d.join("absurd.csv"), absurd).unwrap();
    let args = ["hertz", "absurd.csv", "--radius", "290um", "--out", "out"];
    refused_in(d, &args, 1, &["absurd.csv", "line 9", "force_mN"]);
    let tiny = rows(&|i| ((0.5 * i as f64).to_string(), format!("{i}e-290")));
    fs::write(d.join("tiny.csv"), tiny).unwrap();
    let args = ["hertz", "tiny.csv", "--radius", "290um", "--out", "out"];
    refused_in(d, &args, 1, &["no finite Hertz fit"]);
}

#[test]
fn usage_errors_are_one_line_and_negative_values_reach_the_range_check() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let manifest = fixture_series().join("manifest.csv");
    // Before: clap took `-1um` for an unknown flag and printed seven lines of usage.
    refused_in(
        d,
        &[
            "analyze",
            "--manifest",
            s(&manifest),
            "--radius",
            "-1um",
            "--modulus",
            "3.7GPa",
            "--out",
            "out",
        ],
        1,
        &["--radius", "-1um", "positive"],
    );
    refused_in(d, &["analyze", "--bogus"], 2, &["--bogus", "see --help"]);
    refused_in(
        d,
        &["simulate", "--model", "elastic"],
        2,
        &["required", "--topography"],
    );
}

#[test]
fn files_named_inside_inputs_are_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let series = fixture_series().join("series.tif");
    crate::common::rough_surface(&d.join("t.npy"), 32, "200nm", 3, &[]);
    crate::common::run_ok(&[
        "simulate",
        "--topography",
        s(&d.join("t.npy")),
        "--pixel-size",
        "200nm",
        "--radius",
        "20um",
        "--modulus",
        "3.7GPa",
        "--model",
        "elastic",
        "--forces",
        "4,6,9,13,20,30,45,68mN",
        "--out",
        s(&d.join("sim")),
        "-q",
    ]);
    // A PSF JSON inside the output folder, under the name compare writes.
    fs::create_dir_all(d.join("res")).unwrap();
    let psf = d.join("res/compare.json");
    fs::write(&psf, "{\"fwhm_nm_mean\": 450}\n").unwrap();
    let o = run_in(
        d,
        &[
            "compare",
            "--micrographs",
            s(&series),
            "--forces",
            "4,6,9,13,20,30,45,68mN",
            "--simulation",
            "sim",
            "--psf",
            "res/compare.json",
            "--out",
            "res",
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("input file of this run"), "{err}");
    assert_eq!(
        fs::read_to_string(&psf).unwrap(),
        "{\"fwhm_nm_mean\": 450}\n"
    );
    assert!(!d.join("res/compare.csv").exists(), "nothing committed");
}

/// A Greenwood–Tripp load whose bearing area covers no pixel has no mean pressure: before, the
/// CSV held `NaN` and the table printed it. Now: an empty cell, a warning, nothing non-finite.
#[test]
fn zero_area_load_writes_no_nan() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let ok = |args: &[&str]| {
        let o = run_in(d, args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        (String::from_utf8_lossy(&o.stdout).into_owned(), stderr(&o))
    };
    ok(&[
        "surface",
        "--size",
        "32",
        "--pixel-size",
        "200nm",
        "--rms-height",
        "20nm",
        "--out",
        "t.npy",
    ]);
    let (stdout, err) = ok(&[
        "simulate",
        "--topography",
        "t.npy",
        "--pixel-size",
        "200nm",
        "--radius",
        "20um",
        "--modulus",
        "3.7GPa",
        "--model",
        "gt",
        "--forces",
        "1e-6mN,0.1mN",
        "--out",
        "gt",
    ]);
    assert!(err.contains("no pixel in contact"), "{err}");
    let csv = fs::read_to_string(d.join("gt/areas.csv")).unwrap();
    let summary = fs::read_to_string(d.join("gt/summary.json")).unwrap();
    for text in [&stdout, &csv, &summary] {
        let non_finite = text
            .split(|c: char| !c.is_ascii_alphanumeric())
            .any(|w| matches!(w.to_ascii_lowercase().as_str(), "nan" | "inf" | "infinity"));
        assert!(!non_finite, "{text}");
    }
    let first = csv.lines().nth(1).unwrap();
    assert_eq!(first.split(',').nth(3), Some(""), "{first}");
}
