//! contact.engineering surface containers: read (index.json or meta.yml, ZIP or folder) with
//! the container's size, unit, height scale, filling and detrending applied; written by
//! `surface --out x.zip` and read back; the download layout of `simulate --export
//! contact-engineering` against the run's own tables; refusals that name what is wrong.
//!
//! The folder containers here are written from the container schema by hand (JSON, YAML,
//! `.npy` data), not by the code under test; SurfaceTopography's own containers and
//! ContactMechanics' results are compared in `python/tests/test_contact_engineering.py`.

use std::io::Read;
use std::path::Path;

use serde_json::{json, Value};

use crate::common::{read_csv, run, run_ok, stderr, stdout};
use contactscope_formats::topography::encode_npy;

const NY: usize = 24;
const NX: usize = 32;

/// A tilted plane plus a bump, in nm, rows = y.
fn heights_nm() -> ndarray::Array2<f64> {
    ndarray::Array2::from_shape_fn((NY, NX), |(i, j)| {
        let (x, y) = (j as f64 - 15.5, i as f64 - 11.5);
        40.0 + 0.5 * j as f64 - 0.25 * i as f64 + 6.0 * (-(x * x + y * y) / 30.0).exp()
    })
}

fn write(path: &Path, bytes: &[u8]) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, bytes).unwrap();
}

fn topography_json(args: &[&str]) -> Value {
    let out = run_ok(args);
    serde_json::from_slice(&out.stdout).expect("topography --json")
}

/// rms about the mean of `h` with the least-squares plane removed (the `height` mode).
fn rms_after_plane(h: &ndarray::Array2<f64>) -> f64 {
    // Normal equations of a + b·x + c·y over the grid; x and y are centred, so a is the mean
    // and b, c decouple.
    let n = h.len() as f64;
    let mean = h.sum() / n;
    let (mut sxx, mut syy, mut sxh, mut syh) = (0.0, 0.0, 0.0, 0.0);
    for ((i, j), v) in h.indexed_iter() {
        let (x, y) = (
            j as f64 - (NX as f64 - 1.0) / 2.0,
            i as f64 - (NY as f64 - 1.0) / 2.0,
        );
        sxx += x * x;
        syy += y * y;
        sxh += x * v;
        syh += y * v;
    }
    let (b, c) = (sxh / sxx, syh / syy);
    let ss: f64 = h
        .indexed_iter()
        .map(|((i, j), v)| {
            let (x, y) = (
                j as f64 - (NX as f64 - 1.0) / 2.0,
                i as f64 - (NY as f64 - 1.0) / 2.0,
            );
            (v - mean - b * x - c * y).powi(2)
        })
        .sum();
    (ss / n).sqrt()
}

#[test]
fn a_container_applies_its_size_unit_scale_and_detrending() {
    let dir = tempfile::tempdir().unwrap();
    let c = dir.path().join("lab");
    let h = heights_nm();
    write(&c.join("raw/scan.npy"), &encode_npy(&h));
    let measurement = |name: &str, extra: Value| {
        let mut m = json!({
            "name": name,
            "datafile": {"original": "raw/scan.npy"},
            "size": [6.4, 4.8],
            "unit": "nm",
            "is_periodic": false,
        });
        m.as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        m
    };
    let meta = json!({"versions": {}, "surfaces": [{"name": "s", "topographies": [
        measurement("plain", json!({"detrend_mode": "center"})),
        measurement("levelled", json!({"detrend_mode": "height", "height_scale": 2.0})),
    ]}]});
    write(&c.join("index.json"), &serde_json::to_vec(&meta).unwrap());
    let c_arg = c.to_str().unwrap();
    // 6.4 nm over 32 columns, 4.8 nm over 24 rows: 0.2 nm pixels; heights in nm.
    let plain = topography_json(&[
        "topography",
        c_arg,
        "--measurement",
        "plain",
        "--detrend",
        "none",
        "--json",
    ]);
    assert_eq!(
        (plain["nx"].as_u64(), plain["ny"].as_u64()),
        (Some(32), Some(24))
    );
    let px = plain["pixel_size_um"]["x"].as_f64().unwrap();
    assert!((px - 2e-4).abs() < 1e-15, "{px}");
    let n = h.len() as f64;
    let mean = h.sum() / n;
    let rms = (h.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    // center: the mean is taken off, the rms stays.
    assert!(plain["height_mean_um"].as_f64().unwrap().abs() < 1e-15);
    let got = plain["h_rms_as_stored_um"].as_f64().unwrap() * 1e3;
    assert!((got - rms).abs() < 1e-9 * rms, "{got} vs {rms} nm");
    // height: the plane is taken off after the heights are doubled.
    let levelled = topography_json(&[
        "topography",
        c_arg,
        "--measurement",
        "s/levelled",
        "--detrend",
        "none",
        "--json",
    ]);
    let want = 2.0 * rms_after_plane(&h);
    let got = levelled["h_rms_as_stored_um"].as_f64().unwrap() * 1e3;
    assert!((got - want).abs() < 1e-9 * want, "{got} vs {want} nm");
    // The whole container: one row per measurement and the pooled statistics.
    let whole = topography_json(&["topography", c_arg, "--detrend", "none", "--json"]);
    let rows = whole["measurements"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[1]["name"], "levelled");
    let pooled = whole["combined"]["h_rms_nm"].as_f64().unwrap();
    let expect = ((rms * rms + want * want) / 2.0).sqrt();
    assert!(
        (pooled - expect).abs() < 1e-9 * expect,
        "{pooled} vs {expect}"
    );
    let text = stdout(&run_ok(&["topography", c_arg]));
    assert!(
        text.contains("s/levelled") && text.contains("pooled (2 measurements"),
        "{text}"
    );

    // meta.yml only: a measurement without detrend_mode is not detrended (as SurfaceTopography
    // reads YAML metadata).
    let y = dir.path().join("yml");
    write(&y.join("a.npy"), &encode_npy(&h));
    write(
        &y.join("meta.yml"),
        b"surfaces:\n- name: s\n  topographies:\n  - name: raw\n    datafile:\n      original: a.npy\n    size: [6.4, 4.8]\n    unit: nm\n",
    );
    let raw = topography_json(&[
        "topography",
        y.to_str().unwrap(),
        "--measurement",
        "raw",
        "--detrend",
        "none",
        "--json",
    ]);
    let got = raw["height_mean_um"].as_f64().unwrap() * 1e3;
    assert!((got - mean).abs() < 1e-9 * mean, "{got} vs {mean}");
}

#[test]
fn containers_refuse_what_they_cannot_do_with_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let c = dir.path().join("c");
    write(&c.join("a.npy"), &encode_npy(&heights_nm()));
    write(&c.join("m.npy"), &encode_npy(&(heights_nm() * 1e-9)));
    let topo = |name: &str, file: &str, mode: &str| {
        json!({"name": name, "datafile": {"original": file}, "size": [6.4, 4.8], "unit": "nm",
               "detrend_mode": mode})
    };
    let meta = json!({"surfaces": [{"name": "s", "topographies": [
        topo("ok", "a.npy", "center"),
        topo("escape", "../a.npy", "center"),
        topo("robust", "a.npy", "mad-tilt"),
        json!({"name": "unitless", "datafile": {"original": "m.npy"}, "size": [6.4, 4.8]}),
        json!({"name": "second", "datafile": {"original": "a.npy"}, "size": [6.4, 4.8],
               "unit": "nm", "data_source": 1}),
    ]}]});
    write(&c.join("index.json"), &serde_json::to_vec(&meta).unwrap());
    let c_arg = c.to_str().unwrap();
    let fails = |args: &[&str], needle: &str| {
        let out = run(args);
        let err = stderr(&out);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: one line: {err}");
    };
    fails(
        &[
            "simulate",
            "--topography",
            c_arg,
            "--modulus",
            "1GPa",
            "--model",
            "elastic",
            "--forces",
            "1mN",
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ],
        "5 measurements; choose one with --measurement",
    );
    fails(
        &["topography", c_arg, "--measurement", "escape"],
        "points outside the container",
    );
    fails(
        &["topography", c_arg, "--measurement", "robust"],
        "detrend mode 'mad-tilt'",
    );
    fails(
        &["topography", c_arg, "--measurement", "9"],
        "no measurement 9",
    );
    fails(
        &["topography", c_arg, "--measurement", "unitless"],
        "the container's size has no unit",
    );
    fails(
        &["topography", c_arg, "--measurement", "second"],
        "measurement s/second: data_source 1 is a channel index in SurfaceTopography's order, \
         which is not known for npy files",
    );
    fails(
        &[
            "topography",
            c_arg,
            "--measurement",
            "ok",
            "--pixel-size",
            "1nm",
        ],
        "states each measurement's size",
    );
    let npy = c.join("a.npy");
    fails(
        &[
            "topography",
            npy.to_str().unwrap(),
            "--measurement",
            "0",
            "--pixel-size",
            "1nm",
        ],
        "not a contact.engineering surface container",
    );
    // The whole container still lists what it can, and says which it cannot.
    let whole = run(&["topography", c_arg]);
    assert!(
        !whole.status.success(),
        "a measurement that cannot be read fails the listing"
    );
}

/// A 2 × 2 Nanoscope file of three channels, as the Nanoscope manual lays it out (a text header,
/// then int16 data at each channel's `Data offset`): `Height` first (the default channel) with
/// its data beyond the end of the file, then `Phase` (degrees), then `ZSensor` with the raw
/// values `zsensor` (0.002 nm per count: 6.5536 V / 65536 × 20 nm/V).
fn nanoscope_with_a_broken_height(zsensor: [i16; 4]) -> Vec<u8> {
    let mut text = String::from(
        "\\*File list\r\n\\Data length: 1024\r\n\\*Ciao scan list\r\n\
         \\@Sens. Zsens: V 20 nm/V\r\n\\@Sens. Phase: V 1 deg/V\r\n",
    );
    for (name, quantity, offset) in [
        ("Height", "Zsens", 4096),
        ("Phase", "Phase", 1024),
        ("ZSensor", "Zsens", 1032),
    ] {
        text.push_str(&format!(
            "\\*Ciao image list\r\n\\Data offset: {offset}\r\n\\Bytes/pixel: 2\r\n\
             \\Samps/line: 2\r\n\\Number of lines: 2\r\n\\Scan Size: 4 2 ~m\r\n\
             \\@2:Image Data: S [{name}] \"{name}\"\r\n\
             \\@2:Z scale: V [Sens. {quantity}] (0.0001 V/LSB) 6.5536 V\r\n"
        ));
    }
    text.push_str("\\*File list end\r\n");
    let mut out = text.into_bytes();
    assert!(out.len() <= 1024, "header of {} bytes", out.len());
    out.resize(1024, 0);
    out.extend([1i16, 2, 3, 4].iter().flat_map(|v| v.to_le_bytes()));
    out.extend(zsensor.iter().flat_map(|v| v.to_le_bytes()));
    out
}

#[test]
fn a_data_source_is_read_whatever_the_file_s_default_channel_holds() {
    // SurfaceTopography's channel k of a Nanoscope file is its k-th channel in file order; the
    // channel is read by its place, so a default channel (here the first height channel, whose
    // data lie beyond the file) that cannot be read does not stop another from being read.
    let dir = tempfile::tempdir().unwrap();
    let c = dir.path().join("c");
    write(
        &c.join("scan.di"),
        &nanoscope_with_a_broken_height([500, 1500, 2500, 3500]),
    );
    let topo = |name: &str, k: usize| {
        json!({"name": name, "datafile": {"original": "scan.di"}, "size": [4.0, 2.0],
               "unit": "um", "data_source": k, "detrend_mode": "center"})
    };
    let meta = json!({"surfaces": [{"name": "s", "topographies": [
        topo("default", 0), topo("phase", 1), topo("zsensor", 2), topo("beyond", 3)]}]});
    write(&c.join("index.json"), &serde_json::to_vec(&meta).unwrap());
    let c_arg = c.to_str().unwrap();
    let z = topography_json(&[
        "topography",
        c_arg,
        "--measurement",
        "zsensor",
        "--detrend",
        "none",
        "--json",
    ]);
    assert_eq!(z["channel"], "ZSensor", "{z}");
    // Raw 500…3500 at 0.002 nm per count: 1, 3, 5, 7 nm (centred by the container's mode).
    let um = |key: &str| z[key].as_f64().unwrap();
    let range_nm = (um("height_max_um") - um("height_min_um")) * 1e3;
    assert!((range_nm - 6.0).abs() < 1e-9, "{range_nm}");
    assert!(um("height_mean_um").abs() < 1e-12, "{z}");
    assert_eq!(z["nx"], 2, "{z}");
    let refused = |measurement: &str, needles: &[&str]| {
        let out = run(&["topography", c_arg, "--measurement", measurement]);
        let err = stderr(&out);
        assert!(!out.status.success(), "{measurement} was read");
        assert_eq!(err.trim().lines().count(), 1, "one line: {err}");
        for needle in needles {
            assert!(err.contains(needle), "{measurement}: {err}");
        }
    };
    // The default channel's own error; the phase refused as not a height; beyond the list.
    refused("default", &["scan.di", "Height"]);
    refused(
        "phase",
        &["measurement s/phase: data_source 1:", "'Phase'", "height"],
    );
    refused(
        "beyond",
        &[
            "data_source 3:",
            "no channel 3 (channels count from 0)",
            "3 channel(s)",
        ],
    );
}

fn zip_entry(path: &Path, name: &str) -> Vec<u8> {
    let mut z = zip::ZipArchive::new(std::fs::File::open(path).unwrap()).unwrap();
    let mut e = z.by_name(name).unwrap();
    let mut v = Vec::new();
    e.read_to_end(&mut v).unwrap();
    v
}

#[test]
fn surface_writes_a_container_and_simulate_exports_the_download_layout() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for out in ["g.zip", "g.npy"] {
        run_ok(&[
            "surface",
            "--size",
            "64",
            "--pixel-size",
            "100nm",
            "--rms-height",
            "40nm",
            "--seed",
            "2",
            "--out",
            &p(out),
        ]);
    }
    let from_zip = topography_json(&[
        "topography",
        &p("g.zip"),
        "--measurement",
        "0",
        "--detrend",
        "none",
        "--json",
    ]);
    let from_npy = topography_json(&[
        "topography",
        &p("g.npy"),
        "--pixel-size",
        "100nm",
        "--detrend",
        "none",
        "--json",
    ]);
    for key in ["height_min_um", "height_max_um", "h_rms_as_stored_um"] {
        assert_eq!(from_zip[key], from_npy[key], "{key}");
    }
    // A micrograph command given a container says what it is and which command reads it.
    for command in ["info", "analyze"] {
        let out = run(&[command, &p("g.zip")]);
        let err = stderr(&out);
        assert!(!out.status.success(), "{command}");
        assert!(
            err.contains("contact.engineering surface container") && err.contains("topography"),
            "{command}: {err}"
        );
    }
    // The generated container is periodic: simulate takes periodic boundaries from it.
    let out = run_ok(&[
        "simulate",
        "--topography",
        &p("g.zip"),
        "--modulus",
        "1GPa",
        "--model",
        "elastic",
        "--forces",
        "0.1mN,0.4mN",
        "--maps",
        "none",
        "--export",
        "contact-engineering",
        "--out",
        &p("sim"),
    ]);
    assert!(
        stderr(&out).contains("marks the measurement periodic"),
        "{}",
        stderr(&out)
    );
    let summary: Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("sim/summary.json")).unwrap())
            .unwrap();
    assert!(summary["boundary"]
        .as_str()
        .unwrap()
        .starts_with("periodic"));
    let zip = dir.path().join("sim/contact_mechanics.zip");
    let names: Vec<String> = {
        let z = zip::ZipArchive::new(std::fs::File::open(&zip).unwrap()).unwrap();
        z.file_names().map(String::from).collect()
    };
    for n in [
        "README.txt",
        "g/plot.csv",
        "g/info.txt",
        "g/result-step-0.nc",
        "g/result-step-1.nc",
    ] {
        assert!(names.iter().any(|m| m == n), "{n} in {names:?}");
    }
    let plot = String::from_utf8(zip_entry(&zip, "g/plot.csv")).unwrap();
    let mut lines = plot.lines();
    assert_eq!(
        lines.next(),
        Some(",Normalized pressure p/E*,Fractional contact area A/A0,Normalized mean gap u/h_rms,converged,filename")
    );
    let (header, rows) = read_csv(&dir.path().join("sim/areas.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let a0 = (64.0 * 100e-9f64).powi(2);
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells[0], k.to_string());
        assert_eq!(
            cells[5],
            format!("result-step-{k}.nc"),
            "loads in increasing force"
        );
        let force_n: f64 = rows[k][col("force_mN")].parse::<f64>().unwrap() * 1e-3;
        let p: f64 = cells[1].parse().unwrap();
        assert!((p - force_n / (a0 * 1e9)).abs() < 1e-9 * p, "{p}");
        let fraction: f64 = cells[2].parse().unwrap();
        let ours: f64 = rows[k][col("contact_fraction")].parse().unwrap();
        assert!((fraction - ours).abs() < 1e-9, "{fraction} vs {ours}");
        assert_eq!(cells[4], "True");
    }
    let info = String::from_utf8(zip_entry(&zip, "g/info.txt")).unwrap();
    assert!(info.lines().all(|l| l.starts_with("# ")), "{info}");
    assert!(info.contains("Input SHA-256: ") && info.contains("10.1016/S0043-1648(99)00113-1"));
    // What cannot be exported is refused before anything is solved.
    let gt = run(&[
        "simulate",
        "--topography",
        &p("g.zip"),
        "--modulus",
        "1GPa",
        "--model",
        "gt",
        "--radius",
        "290um",
        "--forces",
        "1mN",
        "--export",
        "contact-engineering",
        "--out",
        &p("gt"),
    ]);
    assert!(
        !gt.status.success() && stderr(&gt).contains("Greenwood–Tripp"),
        "{}",
        stderr(&gt)
    );
    let elastic = run(&[
        "simulate",
        "--topography",
        &p("g.zip"),
        "--modulus",
        "1GPa",
        "--model",
        "elastic",
        "--forces",
        "1mN",
        "--export",
        "surface-container",
        "--out",
        &p("el"),
    ]);
    assert!(!elastic.status.success() && stderr(&elastic).contains("leaves none"));
    assert!(!dir.path().join("gt").exists() && !dir.path().join("el").exists());
}
