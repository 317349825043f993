//! A samplesheet of three kinds of input (a manifest folder, a folder of TIFFs, a multi-page
//! TIFF) with options and metadata: every series' folder is the one its recorded `analyze`
//! command writes, byte for byte; the tables hold the same numbers as the folders' `areas.csv`,
//! in Parquet and CSV alike; `batch.json` names every input file with its size and SHA-256.

use std::path::Path;

use parquet::record::Field;
use serde_json::Value;

use super::{batch_ok, cells, counts, csv, field_text, files, parquet, synth};
use crate::common::{run_in, stderr};

/// The archive of the tests: three series of different input kinds under `dir/archive`, and a
/// samplesheet `dir/sheet.csv` naming them.
pub fn archive(dir: &Path) {
    let archive = dir.join("archive");
    synth(&archive, "manifest-a", 1, &[]);
    let b = synth(&archive, "tiffs-b", 2, &["--layout", "files"]);
    let c = synth(&archive, "c", 3, &[]);
    for folder in [&b, &c] {
        std::fs::remove_file(folder.join("manifest.csv")).unwrap();
        std::fs::remove_file(folder.join("truth.csv")).unwrap();
    }
    std::fs::write(
        dir.join("sheet.csv"),
        "id,input,forces_mN,pixel_size_nm,psf_fwhm_nm,sample,load_cell_N,date\n\
         a,archive/manifest-a,,,,glass,1.5,2026-11-02\n\
         b,archive/tiffs-b,\"1,2,4,8\",,,glass,2,2026-11-03\n\
         c,archive/c/series.tif,\"1,2,4,8\",250,450,steel,2.5,2026-11-04\n",
    )
    .unwrap();
}

#[test]
fn a_samplesheet_gives_analyze_folders_one_table_and_provenance() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    archive(dir);
    let stdout = batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "results"]);
    assert_eq!(counts(&stdout), (3, 0), "{stdout}");
    let results = dir.join("results");

    // Each folder is what its recorded analyze command writes, byte for byte.
    for id in ["a", "b", "c"] {
        let folder = results.join("series").join(id);
        let before = files(&folder);
        assert!(before.contains_key("areas.csv") && before.contains_key("area_vs_load.png"));
        let summary: Value = serde_json::from_slice(&before["summary.json"]).expect("summary.json");
        let line: Vec<String> = summary["command_line"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        assert_eq!(line[1], "analyze", "{line:?}");
        assert_eq!(
            line[line.len() - 1],
            format!("results/series/{id}"),
            "{line:?}"
        );
        let args: Vec<&str> = line[1..].iter().map(String::as_str).collect();
        let o = run_in(dir, &args);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(files(&folder), before, "series {id}: {line:?}");
    }
    let summary_c: Value =
        serde_json::from_slice(&std::fs::read(results.join("series/c/summary.json")).unwrap())
            .unwrap();
    assert_eq!(
        summary_c["command_line"].as_array().unwrap()[2..9],
        [
            "archive/c/series.tif",
            "--forces",
            "1,2,4,8mN",
            "--pixel-size",
            "250nm",
            "--psf-fwhm",
            "450nm"
        ]
    );
    // The row's PSF reached the area intervals.
    assert_eq!(summary_c["area_interval"]["psf_fwhm_um"], 0.45);

    // The image table: the folders' numbers, with the metadata on every row.
    let images = csv(&results.join("images.csv"));
    assert_eq!(images.1.len(), 12);
    assert_eq!(
        images.0[..7],
        [
            "series_id",
            "sample",
            "load_cell_N",
            "date",
            "image_index",
            "image",
            "page"
        ]
    );
    for id in ["a", "b", "c"] {
        let areas = csv(&results.join("series").join(id).join("areas.csv"));
        let rows: Vec<usize> = (0..images.1.len())
            .filter(|&r| images.1[r][0] == id)
            .collect();
        assert_eq!(rows.len(), areas.1.len(), "{id}");
        for name in [
            "force_mN",
            "threshold",
            "contact_pixels",
            "area_um2",
            "mean_intensity",
            "integrated_intensity",
            "background_mean",
            "patches",
            "largest_patch_um2",
            "mean_pressure_MPa",
            "equivalent_radius_um",
        ] {
            let ours = cells(&images, name);
            let theirs = cells(&areas, name);
            for (k, &r) in rows.iter().enumerate() {
                let (a, b): (f64, f64) = (ours[r].parse().unwrap(), theirs[k].parse().unwrap());
                assert_eq!(a, b, "{id} row {k} {name}");
            }
        }
    }
    let names = cells(&images, "image");
    assert_eq!(names[0], "series.tif", "relative to the manifest's folder");
    assert_eq!(names[4], "load_1.tif".replace("load_1", "load_01"));
    assert_eq!(cells(&images, "sample")[11], "steel");

    // The series table: status, threshold, pixel size and its source, flags.
    let series = csv(&results.join("series.csv"));
    assert_eq!(cells(&series, "series_id"), ["a", "b", "c"]);
    assert_eq!(cells(&series, "status"), ["ok", "ok", "ok"]);
    let sources = cells(&series, "pixel_size_source");
    assert_eq!(sources[0], "ImageJ unit + X/YResolution");
    assert_eq!(sources[2], "samplesheet (pixel_size)");
    assert_eq!(cells(&series, "pixel_size_x_um")[2], "0.25");
    // Converted to µm without binary noise (metres × 1e6 would give 0.19999999999999998).
    assert_eq!(cells(&series, "pixel_size_x_um")[0], "0.2");
    assert_eq!(cells(&images, "pixel_size_uncertainty_pct")[0], "0");
    let flags = cells(&series, "flags");
    assert_eq!(flags[..2], ["", ""]);
    assert_eq!(flags[2], "pixel_size_vs_metadata");
    let exponents = cells(&series, "power_law_exponent");
    let summary_a: Value =
        serde_json::from_slice(&std::fs::read(results.join("series/a/summary.json")).unwrap())
            .unwrap();
    assert_eq!(
        exponents[0].parse::<f64>().unwrap(),
        summary_a["fits"]["power_law"]["exponent"].as_f64().unwrap()
    );

    // Parquet: the same names, types and values as the CSV.
    for name in ["images", "series"] {
        let text = csv(&results.join(format!("{name}.csv")));
        let (columns, rows) = parquet(&results.join(format!("{name}.parquet")));
        assert_eq!(columns, text.0, "{name}");
        assert_eq!(rows.len(), text.1.len(), "{name}");
        for (r, row) in rows.iter().enumerate() {
            let as_text: Vec<String> = row.iter().map(field_text).collect();
            assert_eq!(as_text, text.1[r], "{name} row {r}");
        }
    }
    let (columns, rows) = parquet(&results.join("images.parquet"));
    let at = |n: &str| columns.iter().position(|c| c == n).unwrap();
    assert!(matches!(rows[0][at("sample")], Field::Str(_)));
    assert!(matches!(rows[0][at("load_cell_N")], Field::Double(_)));
    assert!(matches!(rows[0][at("date")], Field::Str(_)));
    assert!(matches!(rows[0][at("contact_pixels")], Field::Long(_)));
    assert!(matches!(rows[0][at("edge_contact")], Field::Bool(false)));

    // Provenance: every input file with its size and SHA-256, the options after defaults.
    let record: Value =
        serde_json::from_slice(&std::fs::read(results.join("batch.json")).unwrap()).unwrap();
    assert_eq!(record["counts"]["series"], 3);
    let sheet_sha = contactscope_jobs::provenance::sha256_file(&dir.join("sheet.csv")).unwrap();
    assert_eq!(record["samplesheet"]["sha256"], sheet_sha.0);
    let mut hashed = 0;
    for s in record["series"].as_array().unwrap() {
        for f in s["files"].as_array().unwrap() {
            let path = dir.join(f["path"].as_str().unwrap());
            let (sha, size) = contactscope_jobs::provenance::sha256_file(&path).unwrap();
            assert_eq!(f["sha256"], sha, "{path:?}");
            assert_eq!(f["size_bytes"], size, "{path:?}");
            hashed += 1;
        }
        assert_eq!(s["decision"], "analysed");
    }
    // a: its TIFF and manifest; b: four TIFFs; c: one TIFF.
    assert_eq!(hashed, 2 + 4 + 1);
    assert_eq!(record["series"][2]["options"]["pixel_size"], "250nm");
    assert_eq!(record["series"][2]["options_si"]["pixel_size"][0], 2.5e-7);

    // The QC page references only files that exist.
    let html = std::fs::read_to_string(results.join("index.html")).unwrap();
    let sources: Vec<&str> = html
        .split("src=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap())
        .collect();
    assert_eq!(
        sources.len(),
        4,
        "three thumbnails and the combined plot: {sources:?}"
    );
    for s in sources {
        assert!(results.join(s).is_file(), "{s}");
    }
}

#[test]
fn a_bad_samplesheet_is_refused_whole_with_its_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    archive(dir);
    let sheet = std::fs::read_to_string(dir.join("sheet.csv")).unwrap();
    std::fs::write(dir.join("bad.csv"), sheet.replace(",250,", ",250parsecs,")).unwrap();
    let o = super::batch(dir, &["--samplesheet", "bad.csv", "--out", "results"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("bad.csv: line 4, column pixel_size_nm") && err.contains("parsecs"),
        "{err}"
    );
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!dir.join("results").exists(), "nothing written");
    // Forces for a manifest, which gives its own: one of the two would be ignored.
    std::fs::write(
        dir.join("both.csv"),
        sheet.replace("a,archive/manifest-a,,", "a,archive/manifest-a,\"1,2\","),
    )
    .unwrap();
    let o = super::batch(dir, &["--samplesheet", "both.csv", "--out", "results"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("line 2, column forces_mN: the input archive/manifest-a is a manifest"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.join("results").exists(), "nothing written");
    // A folder of one's own is never taken.
    std::fs::create_dir(dir.join("mine")).unwrap();
    std::fs::write(dir.join("mine/notes.txt"), "mine").unwrap();
    let o = super::batch(dir, &["--samplesheet", "sheet.csv", "--out", "mine"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("not a batch's folder"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read_dir(dir.join("mine")).unwrap().count(), 1);
}
