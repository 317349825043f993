//! Nanonis `.sxm` scans read as nanonispy reads them: grid, pixel size, valid points and the
//! values of every channel in a length unit (min, max, rms about the mean, to 1e-9), both
//! directions, and what `topography` picks without `--channel`.
//!
//! Reference: `tests/data/nanonis_sxm_reference.csv`, written by
//! `tests/data/nanonis_sxm_reference.py` with nanonispy 1.1.0. Files: the four `.sxm` scans of
//! `alexriss/SpmImages.jl` at commit d189646 (`test/`; GPL-3.0, so not committed here): run with
//! `CONTACTSCOPE_SXM_DIR` naming a folder that holds them (`fixtures/README.md`). Without it the
//! comparison is skipped with a message; the format itself is tested in CI on files written
//! by the reader's unit tests and the fuzz templates.

use std::collections::HashMap;
use std::path::Path;

use contactscope_formats::topography::{read_height_map, ReadOptions};

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs().max(1e-300)
    }
}

#[test]
fn nanonis_scans_read_as_nanonispy_reads_them() {
    let Ok(dir) = std::env::var("CONTACTSCOPE_SXM_DIR") else {
        eprintln!("SKIPPED: set CONTACTSCOPE_SXM_DIR to a folder with SpmImages.jl's test/*.sxm");
        return;
    };
    let table = crate::common::root().join("tests/data/nanonis_sxm_reference.csv");
    let mut reader = csv::Reader::from_path(table).unwrap();
    let rows: Vec<HashMap<String, String>> = reader.deserialize().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 16);
    for row in &rows {
        let get = |k: &str| row[k].as_str();
        let num = |k: &str| get(k).parse::<f64>().unwrap();
        let path = Path::new(&dir).join(get("file"));
        let options = ReadOptions {
            channel: Some(get("channel").to_string()),
            ..ReadOptions::default()
        };
        let map = read_height_map(&path, &options).unwrap();
        let what = format!("{} {}", get("file"), get("channel"));
        assert_eq!(map.channel, get("channel"), "{what}");
        assert_eq!(
            (map.nx(), map.ny(), map.valid_points()),
            (
                num("nx") as usize,
                num("ny") as usize,
                num("valid_points") as usize
            ),
            "{what}"
        );
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
        for (name, got, want) in [
            ("dx", map.dx_m, num("dx_m")),
            ("dy", map.dy_m, num("dy_m")),
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
    // Without a channel: the height Z, forward, whatever else the file holds (the oscillation
    // amplitude is in metres too, but named as another signal).
    let map = read_height_map(&Path::new(&dir).join("01581.sxm"), &ReadOptions::default()).unwrap();
    assert_eq!(map.channel, "Z (forward)");
    assert_eq!(map.channels.len(), 18, "{:?}", map.channels);
}
