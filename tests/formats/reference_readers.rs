//! Formats read as their own reference readers read them, on public sample files whose licence
//! keeps them out of this repository: grid, pixel size, valid points and the values of each
//! channel (min, max, rms about the mean, to 1e-9), and what `topography` picks without
//! `--channel`. Each test runs when its environment variable names a folder holding the
//! samples (`fixtures/README.md`, "Files used by opt-in tests"), and is skipped with a message
//! otherwise; CI tests the same readers on files written by the unit tests, committed small
//! fixtures and the fuzz templates.
//!
//! * Nanonis `.sxm`: the four scans of `alexriss/SpmImages.jl` (`CONTACTSCOPE_SXM_DIR`);
//!   reference `tests/data/nanonis_sxm_reference.csv` (`nanonis_sxm_reference.py`, nanonispy
//!   1.1.0).
//! * TopoStats `.topostats`: the two files of `AFM-SPM/AFMReader` (`CONTACTSCOPE_AFMREADER_DIR`);
//!   reference `tests/data/topostats_reference.csv` (`topostats_reference.py`, AFMReader 0.0.7).
//! * JPK TIFF `.jpk`, `.jpk-qi-image`: the two files of `AFM-SPM/AFMReader`
//!   (`CONTACTSCOPE_AFMREADER_DIR`); reference `tests/data/jpk_reference.csv`
//!   (`jpk_reference.py`, AFMReader 0.0.7).

use std::collections::HashMap;
use std::path::Path;

use contactscope_formats::topography::{read_height_map, HeightMap, ReadOptions};

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs().max(1e-300)
    }
}

/// Compare every row of `table` (under `tests/data`) with the files in `dir`; the number of
/// rows compared.
fn compare(dir: &Path, table: &str) -> usize {
    let table = crate::common::root().join("tests/data").join(table);
    let mut reader = csv::Reader::from_path(table).unwrap();
    let rows: Vec<HashMap<String, String>> = reader.deserialize().map(Result::unwrap).collect();
    for row in &rows {
        let get = |k: &str| row.get(k).map_or("", String::as_str);
        let num = |k: &str| get(k).parse::<f64>().unwrap();
        let options = ReadOptions {
            channel: Some(get("channel").to_string()),
            ..ReadOptions::default()
        };
        let map = read_height_map(&dir.join(get("file")), &options).unwrap();
        let what = format!("{} {}", get("file"), get("channel"));
        assert_eq!(map.channel, get("channel"), "{what}");
        let grid = (map.nx(), map.ny(), map.valid_points());
        let want = (num("nx"), num("ny"), num("valid_points"));
        assert_eq!(
            grid,
            (want.0 as usize, want.1 as usize, want.2 as usize),
            "{what}"
        );
        let (min, max, mean, rms) = stats(&map);
        let dy = if row.contains_key("dy_m") {
            num("dy_m")
        } else {
            num("dx_m")
        };
        for (name, got, want) in [
            ("dx", map.dx_m, num("dx_m")),
            ("dy", map.dy_m, dy),
            ("min", min, num("min_m")),
            ("max", max, num("max_m")),
        ] {
            assert!(rel(got, want) < 1e-9, "{what} {name}: {got:e} vs {want:e}");
        }
        // A constant channel has an rms of rounding size about its mean.
        let want_rms = num("rms_m");
        assert!(
            rel(rms, want_rms) < 1e-9 || (want_rms == 0.0 && rms < 1e-12 * mean.abs()),
            "{what} rms: {rms:e} vs {want_rms:e}"
        );
    }
    rows.len()
}

/// min, max, mean and rms about the mean of the valid heights.
fn stats(map: &HeightMap) -> (f64, f64, f64, f64) {
    let values: Vec<f64> = map
        .heights
        .iter()
        .copied()
        .filter(|h| h.is_finite())
        .collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let rms = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (min, max, mean, rms)
}

fn folder(variable: &str, what: &str) -> Option<std::path::PathBuf> {
    match std::env::var(variable) {
        Ok(dir) => Some(dir.into()),
        Err(_) => {
            eprintln!("SKIPPED: set {variable} to a folder with {what}");
            None
        }
    }
}

#[test]
fn nanonis_scans_read_as_nanonispy_reads_them() {
    let Some(dir) = folder("CONTACTSCOPE_SXM_DIR", "SpmImages.jl's test/*.sxm") else {
        return;
    };
    assert_eq!(compare(&dir, "nanonis_sxm_reference.csv"), 16);
    // Without a channel: the height Z, forward, whatever else the file holds (the oscillation
    // amplitude is in metres too, but named as another signal).
    let map = read_height_map(&dir.join("01581.sxm"), &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "Z (forward)");
    assert_eq!(map.channels.len(), 18, "{:?}", map.channels);
}

#[test]
fn topostats_files_read_as_afmreader_reads_them() {
    let Some(dir) = folder(
        "CONTACTSCOPE_AFMREADER_DIR",
        "AFMReader's tests/resources/*.topostats",
    ) else {
        return;
    };
    assert_eq!(compare(&dir, "topostats_reference.csv"), 3);
    // Without a channel: TopoStats' levelled image.
    let map = read_height_map(&dir.join("sample_0_2.topostats"), &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "image");
}

#[test]
fn jpk_tiffs_read_as_afmreader_reads_them() {
    let Some(dir) = folder(
        "CONTACTSCOPE_AFMREADER_DIR",
        "AFMReader's tests/resources/sample_0.jpk and sample_0.jpk-qi-image",
    ) else {
        return;
    };
    assert_eq!(compare(&dir, "jpk_reference.csv"), 6);
    // Without a channel: the first height page (a retrace in this file), never the deflection
    // or adhesion of a QI map (in newtons).
    let map = read_height_map(&dir.join("sample_0.jpk"), &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "height (retrace)");
    let qi = dir.join("sample_0.jpk-qi-image");
    let map = read_height_map(&qi, &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "measuredHeight (trace)");
    let options = ReadOptions {
        channel: Some("adhesion".into()),
        ..ReadOptions::default()
    };
    let err = read_height_map(&qi, &options).unwrap_err().to_string();
    assert!(err.contains("'N', not a length"), "{err}");
}
