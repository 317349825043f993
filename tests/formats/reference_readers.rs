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
//! * JPK HDF5 export `.h5-jpk`: `sample_0.h5-jpk` of `AFM-SPM/AFMReader`
//!   (`CONTACTSCOPE_AFMREADER_DIR`); reference `tests/data/h5jpk_reference.csv`
//!   (`h5jpk_reference.py`, AFMReader 0.0.7). CI reads `fixtures/jpk/tiny.h5-jpk`
//!   (`h5jpk_fixture.py`, h5py) against its formula.
//! * Createc `.dat`: the eleven `[Paramco32]` images of
//!   `SPMQT-Lab/Createc-to-Nanonis-file-conversion` (`CONTACTSCOPE_CREATEC_DIR`); reference
//!   `tests/data/createc_reference.csv` (`createc_reference.py`, ProbeFlow's decoder). Its
//!   smallest image is committed (`fixtures/createc`, MIT) and compared always. The same folder's
//!   Nanonis scan `sxm_moire_10nm.sxm` against nanonispy 1.1.0
//!   (`tests/data/nanonis_sxm_probeflow_reference.csv`, `nanonis_sxm_reference.py`).
//!
//! * Keyence `.zon`: `tests/test_files/test_1.zon` of `fredericjs/surfalize@f558db5` (a VR-6100
//!   scan, GPL-3.0: not committed; `CONTACTSCOPE_ZON_DIR`), and always the two small files of
//!   `fixtures/zon` (`zon_fixture.py`); reference `tests/data/zon_reference.csv`
//!   (`zon_reference.py`, SurfaceTopography 1.27.1's `ZONReader`).
//!
//! And, always (the files are our own, written by the reference package itself): surfalize
//! `.sflz`, the three files of `fixtures/sflz` (`sflz_fixture.py`: zlib, LZMA and no
//! compression; uint32, float64 and int16 heights; um, nm and mm); reference
//! `tests/data/sflz_reference.csv` (`sflz_reference.py`, surfalize 0.19.2); and two files of
//! the earlier layout (`sflz_earlier_fixture.py`, surfalize 0.17.1), reference
//! `tests/data/sflz_earlier_reference.csv` (the same script run with surfalize 0.17.1).

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
    compare_files(dir, table, |_| true)
}

/// Compare the rows of `table` whose file `keep` accepts; the number of rows compared.
fn compare_files(dir: &Path, table: &str, keep: impl Fn(&str) -> bool) -> usize {
    let table = crate::common::root().join("tests/data").join(table);
    let mut reader = csv::Reader::from_path(table).unwrap();
    let rows: Vec<HashMap<String, String>> = reader
        .deserialize()
        .map(Result::unwrap)
        .filter(|row: &HashMap<String, String>| keep(row.get("file").map_or("", String::as_str)))
        .collect();
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

#[test]
fn sflz_files_read_as_surfalize_reads_them() {
    let dir = crate::common::root().join("fixtures/sflz");
    assert_eq!(compare(&dir, "sflz_reference.csv"), 3);
    // The earlier layout (surfalize 0.17.1), as that version reads it.
    assert_eq!(compare(&dir, "sflz_earlier_reference.csv"), 2);
    let map = read_height_map(&dir.join("earlier_zlib_u4.sflz"), &ReadOptions::default()).unwrap();
    assert_eq!(map.channels, ["topography", "Camera"]);
    // The camera image beside the heights is listed, not read as heights.
    let map = read_height_map(&dir.join("lzma_f8.sflz"), &ReadOptions::default()).unwrap();
    assert_eq!(map.channels, ["topography", "Camera"]);
    assert_eq!(map.invalid_points, 5);
    let options = ReadOptions {
        channel: Some("camera".into()),
        ..ReadOptions::default()
    };
    let err = read_height_map(&dir.join("lzma_f8.sflz"), &options)
        .unwrap_err()
        .to_string();
    assert!(err.contains("'Camera' is a camera image"), "{err}");
}

#[test]
fn the_committed_createc_image_reads_as_probeflow_reads_it() {
    let dir = crate::common::root().join("fixtures/createc");
    let compared = compare_files(&dir, "createc_reference.csv", |f| f == "A250407.141806.dat");
    assert_eq!(compared, 2);
    // Without a channel: Z forward; the current is listed and refused as heights.
    let path = dir.join("A250407.141806.dat");
    let map = read_height_map(&path, &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "Z (forward)");
    assert_eq!(
        map.channels,
        [
            "Z (forward)",
            "Current (forward)",
            "Z (backward)",
            "Current (backward)"
        ]
    );
    let options = ReadOptions {
        channel: Some("current (backward)".into()),
        ..ReadOptions::default()
    };
    let err = read_height_map(&path, &options).unwrap_err().to_string();
    assert!(err.contains("'A', not a length"), "{err}");
}

#[test]
fn createc_images_read_as_probeflow_reads_them() {
    let Some(dir) = folder(
        "CONTACTSCOPE_CREATEC_DIR",
        "the Createc .dat images of SPMQT-Lab/Createc-to-Nanonis-file-conversion's test_data",
    ) else {
        return;
    };
    assert_eq!(compare(&dir, "createc_reference.csv"), 25);
    // A Nanonis scan of a fifth project, as nanonispy reads it.
    assert_eq!(compare(&dir, "nanonis_sxm_probeflow_reference.csv"), 2);
    // A qPlus scan's planes named by the channels it selected (Channelselectval=899).
    let map = read_height_map(
        &dir.join("createc_scan_qplus_10ch_afm.dat"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(map.channels.len(), 10);
    assert_eq!(map.channels[2], "Aux6 (forward)");
}

#[test]
fn jpk_hdf5_exports_read_as_afmreader_reads_them() {
    let Some(dir) = folder(
        "CONTACTSCOPE_AFMREADER_DIR",
        "AFMReader's tests/resources/sample_0.h5-jpk",
    ) else {
        return;
    };
    assert_eq!(compare(&dir, "h5jpk_reference.csv"), 8);
    // Without a channel: the first height frame; the phase (degrees) is refused.
    let path = dir.join("sample_0.h5-jpk");
    let map = read_height_map(&path, &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "height (trace, frame 1)");
    assert_eq!(map.channels.len(), 36, "{:?}", map.channels);
    let options = ReadOptions {
        channel: Some("phase (retrace, frame 2)".into()),
        ..ReadOptions::default()
    };
    let err = read_height_map(&path, &options).unwrap_err().to_string();
    assert!(err.contains("'deg', not a length"), "{err}");
}

#[test]
fn the_committed_jpk_hdf5_export_reads_its_counts_in_metres() {
    let path = crate::common::root().join("fixtures/jpk/tiny.h5-jpk");
    let read = |channel: &str| {
        let options = ReadOptions {
            channel: Some(channel.into()),
            ..ReadOptions::default()
        };
        read_height_map(&path, &options).unwrap()
    };
    let map = read_height_map(&path, &ReadOptions::default()).unwrap();
    assert_eq!(
        map.channels,
        [
            "height (trace, frame 1)",
            "height (trace, frame 2)",
            "height (retrace, frame 1)",
            "height (retrace, frame 2)",
            "phase (trace, frame 1)",
            "phase (trace, frame 2)"
        ]
    );
    assert_eq!(
        (map.channel.as_str(), map.nx(), map.ny()),
        ("height (trace, frame 1)", 5, 4)
    );
    assert!(rel(map.dx_m, 4e-9) < 1e-12 && rel(map.dy_m, 3e-9) < 1e-12);
    // Counts 1000·line + 10·column + 100000·frame (+ 7 retrace), lines stored bottom first.
    for (channel, frame, extra) in [
        ("height (trace, frame 1)", 0.0, 0.0),
        ("height (retrace, frame 2)", 1.0, 7.0),
    ] {
        let m = read(channel);
        for row in 0..4 {
            for column in 0..5 {
                let line = (3 - row) as f64;
                let raw = 1000.0 * line + 10.0 * column as f64 + 100000.0 * frame + extra;
                let want = raw * -2e-15 + 3e-7;
                let got = m.heights[[row, column]];
                assert!(
                    rel(got, want) < 1e-12,
                    "{channel} {row} {column}: {got:e} vs {want:e}"
                );
            }
        }
    }
    let options = ReadOptions {
        channel: Some("phase".into()),
        ..ReadOptions::default()
    };
    let err = read_height_map(&path, &options).unwrap_err().to_string();
    assert!(err.contains("'deg', not a length"), "{err}");
    // Its unit is stated, as a TopoStats file's is: a second one is refused, not applied.
    for file in [
        "fixtures/jpk/tiny.h5-jpk",
        "fixtures/topostats/tiny.topostats",
    ] {
        let options = ReadOptions {
            height_unit_m: Some(1e-9),
            ..ReadOptions::default()
        };
        let err = read_height_map(&crate::common::root().join(file), &options)
            .unwrap_err()
            .to_string();
        assert!(err.contains("states its height unit"), "{file}: {err}");
    }
}

#[test]
fn zon_files_read_as_surface_topography_reads_them() {
    let dir = crate::common::root().join("fixtures/zon");
    assert_eq!(
        compare_files(&dir, "zon_reference.csv", |f| f.starts_with("tiny")),
        2
    );
    // Row 0 is the first row stored, each row's padding skipped (the fixture's counts are
    // trunc(300·(x − 9.5)² − 150·(y − 6.5)² + 4000·[x > 12] − 7), 10 nm each), and a pixel
    // whose validity byte is 4 is measured while 1, 2 and 3 are not.
    let map = read_height_map(&dir.join("tiny.zon"), &ReadOptions::default()).unwrap();
    assert_eq!(map.heights[(0, 5)], -269.0 * 1e-8);
    assert_eq!(map.heights[(13, 15)], 6730.0 * 1e-8);
    assert!(map.heights[(5, 7)].is_nan() && map.heights[(9, 3)].is_nan());
    assert!(map.heights[(3, 10)].is_finite());
    if let Some(dir) = folder(
        "CONTACTSCOPE_ZON_DIR",
        "test_1.zon of fredericjs/surfalize@f558db5 (tests/test_files)",
    ) {
        assert_eq!(
            compare_files(&dir, "zon_reference.csv", |f| f == "test_1.zon"),
            1
        );
    }
}
