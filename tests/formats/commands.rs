//! `info --json [--stats]` and `topography --json [--channel]` on the real vendor files of
//! `../shared/data/real-formats` (skipped with a message when absent): the printed JSON carries
//! the trusted readers' numbers (the same references as `tests/formats/real.rs`: plane statistics
//! in `tests/data/real_formats_planes.csv` from the `nd2` Python package, heights from
//! SurfaceTopography), and broken files give one clean error line naming the file.

use std::collections::HashMap;

use crate::common::{read_csv, root, run, shared_data, stderr};
use serde_json::Value;

fn json(args: &[&str]) -> Value {
    let o = run(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

#[test]
fn info_json_stats_gives_the_trusted_readers_planes() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let file = dir.join("nd2/cluster.nd2");
    let v = json(&["info", file.to_str().unwrap(), "--json", "--stats"]);
    assert_eq!(v["format"], "nd2");
    let series = &v["series"][0];
    for (axis, n) in [("T", 3), ("Z", 10), ("C", 2), ("Y", 31), ("X", 38)] {
        assert_eq!(series["axes"][axis], n, "axis {axis}");
    }
    assert_eq!(series["dtype"], "uint16");
    let px = series["pixel_size_um"]["x"].as_f64().unwrap();
    assert!((px / 0.167_808_983_232_682_45 - 1.0).abs() < 1e-12, "{px}");
    assert_eq!(series["pixel_size_um"]["z"].as_f64(), Some(0.5));
    // Every plane's min, max and sum as the trusted reader gives them (exact: integer image).
    let (_, rows) = read_csv(&root().join("tests/data/real_formats_planes.csv"));
    let trusted: HashMap<String, (f64, f64, f64)> = rows
        .iter()
        .filter(|r| r[0] == "nd2/cluster.nd2" && r[1] == "0")
        .map(|r| {
            let n = |i: usize| r[i].parse::<f64>().unwrap();
            (r[2].clone(), (n(3), n(4), n(5)))
        })
        .collect();
    let planes = series["planes"].as_array().unwrap();
    assert_eq!(planes.len(), 3 * 10 * 2);
    assert_eq!(trusted.len(), planes.len(), "a reference for every plane");
    for p in planes {
        let key = format!("t={};z={};c={}", p["t"], p["z"], p["c"]);
        let (min, max, sum) = trusted[&key];
        assert_eq!(p["min"].as_f64(), Some(min), "{key}");
        assert_eq!(p["max"].as_f64(), Some(max), "{key}");
        assert_eq!(p["sum"].as_f64(), Some(sum), "{key}");
    }
    // Without --stats no planes are decoded or printed.
    let v = json(&["info", file.to_str().unwrap(), "--json"]);
    assert!(v["series"][0].get("planes").is_none());
}

#[test]
fn topography_json_gives_surface_topographys_numbers() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let file = dir.join("ibw/spot_1-1000nm.ibw");
    let path = file.to_str().unwrap();
    let v = json(&["topography", path, "--json"]);
    assert_eq!(v["format"], "ibw");
    assert_eq!(v["channel"], "HeightTrace");
    assert_eq!((v["nx"].as_u64(), v["ny"].as_u64()), (Some(256), Some(256)));
    assert_eq!(v["valid_points"], 65536);
    // SurfaceTopography 1.x on the same file (tests/formats/real.rs, HEIGHTS), in µm.
    let close = |key: &str, trusted: f64| {
        let got = v[key].as_f64().unwrap();
        assert!(
            (got / trusted - 1.0).abs() < 1e-6,
            "{key}: {got} vs {trusted}"
        );
    };
    close("height_min_um", -0.704_623_857_927_799_7);
    close("height_max_um", -0.331_233_451_333_901_03);
    close("height_mean_um", -0.538_691_195_036_984);
    close("h_rms_as_stored_um", 0.089_454_814_912_564_12);
    assert!((v["pixel_size_um"]["x"].as_f64().unwrap() / (20.0 / 255.0) - 1.0).abs() < 1e-12);
    assert!(v["detrended"]["h_rms_nm"].as_f64().unwrap() > 0.0);

    // Another channel by name, and a missing one listed in the error.
    let v = json(&["topography", path, "--json", "--channel", "HeightRetrace"]);
    assert_eq!(v["channel"], "HeightRetrace");
    let o = run(&["topography", path, "--channel", "NoSuchChannel"]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("spot_1-1000nm.ibw") && err.contains("HeightTrace"),
        "{err}"
    );
}

#[test]
fn truncated_vendor_files_give_one_error_line_through_the_cli() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    for (command, sample) in [
        ("info", "nd2/cluster.nd2"),
        ("info", "czi/CellDivision_T3_Z5_CH2_X240_Y170.czi"),
        ("topography", "ibw/spot_1-1000nm.ibw"),
        ("topography", "x3p/x3p-2.x3p"),
    ] {
        let bytes = std::fs::read(dir.join(sample)).unwrap();
        let name = sample.rsplit('/').next().unwrap();
        let cut = tmp.path().join(format!("cut_{name}"));
        std::fs::write(&cut, &bytes[..bytes.len() / 3]).unwrap();
        // --stats decodes every plane: the metadata of a cut file may survive, its planes not.
        let o = match command {
            "info" => run(&[command, cut.to_str().unwrap(), "--json", "--stats"]),
            _ => run(&[command, cut.to_str().unwrap(), "--json"]),
        };
        assert!(
            !o.status.success(),
            "{command} {sample}: a third of the file is refused"
        );
        let err = stderr(&o);
        assert_eq!(
            err.trim_end().lines().count(),
            1,
            "{command} {sample}: {err}"
        );
        assert!(
            err.contains(&format!("cut_{name}")),
            "{command} {sample}: {err}"
        );
        assert!(o.stdout.is_empty(), "{command} {sample}: nothing printed");
    }
}
