//! Incremental re-runs: an unchanged archive is re-used without reading image data (shown by
//! new bytes behind an unchanged size and time going unnoticed, by design), a touched file is
//! hashed and found unchanged, one changed file re-analyses one series, a changed option or a
//! new row re-analyses its series only, a removed output folder is made again, `--rerun all`
//! redoes everything; the tables are rewritten whole each time and come out the same.

use std::time::{Duration, SystemTime};

use serde_json::Value;

use super::{batch_ok, counts, synth};

fn set_time(path: &std::path::Path, time: SystemTime) {
    std::fs::File::options()
        .write(true)
        .open(path)
        .unwrap()
        .set_modified(time)
        .unwrap();
}

fn hashed(dir: &std::path::Path) -> u64 {
    let record: Value =
        serde_json::from_slice(&std::fs::read(dir.join("results/batch.json")).unwrap()).unwrap();
    record["bytes_hashed"].as_u64().unwrap()
}

#[test]
fn reruns_redo_only_what_changed() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    for i in 1..=3 {
        synth(dir, &format!("s{i}"), i, &[]);
    }
    let sheet = "id,input,sample\ns1,s1,a\ns2,s2,b\ns3,s3,c\n";
    std::fs::write(dir.join("sheet.csv"), sheet).unwrap();
    let args = ["--samplesheet", "sheet.csv", "--out", "results"];
    assert_eq!(counts(&batch_ok(dir, &args)), (3, 0));
    let tables = |dir: &std::path::Path| {
        [
            "images.parquet",
            "series.parquet",
            "images.csv",
            "series.csv",
        ]
        .map(|n| std::fs::read(dir.join("results").join(n)).unwrap())
    };
    let first = tables(dir);
    let first_hashed = hashed(dir);
    assert!(first_hashed > 3 * 100_000, "{first_hashed}");

    // Unchanged: nothing analysed, nothing hashed, the same tables.
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 3));
    assert_eq!(hashed(dir), 0);
    assert_eq!(tables(dir), first);

    // New bytes behind the same size and time are not seen: no image data is read.
    let tif = dir.join("s2/series.tif");
    let time = std::fs::metadata(&tif).unwrap().modified().unwrap();
    let original = std::fs::read(&tif).unwrap();
    let mut altered = original.clone();
    let n = altered.len();
    altered[n - 2] ^= 0xff;
    std::fs::write(&tif, &altered).unwrap();
    set_time(&tif, time);
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 3));
    assert_eq!(tables(dir), first);

    // Touched (a new time, the original bytes): hashed, found unchanged, not analysed.
    std::fs::write(&tif, &original).unwrap();
    set_time(&tif, time + Duration::from_secs(10));
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 3));
    assert_eq!(hashed(dir), original.len() as u64);
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 3));
    assert_eq!(hashed(dir), 0, "the record took the new time");

    // One changed file: one series analysed.
    synth(dir, "s2-new", 7, &[]);
    std::fs::copy(dir.join("s2-new/series.tif"), &tif).unwrap();
    let stdout = batch_ok(dir, &args);
    assert_eq!(counts(&stdout), (1, 2), "{stdout}");
    let record: Value =
        serde_json::from_slice(&std::fs::read(dir.join("results/batch.json")).unwrap()).unwrap();
    assert_eq!(record["series"][1]["decision"], "analysed");
    assert_eq!(
        record["series"][1]["reason"],
        "s2/series.tif changed (content)"
    );
    assert_ne!(tables(dir), first);

    // A metadata change re-writes the tables and analyses nothing.
    std::fs::write(dir.join("sheet.csv"), sheet.replace(",c\n", ",steel\n")).unwrap();
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 3));
    let series = super::csv(&dir.join("results/series.csv"));
    assert_eq!(super::cells(&series, "sample")[2], "steel");

    // An option changed in one row, a new row: those two.
    std::fs::write(
        dir.join("sheet.csv"),
        "id,input,sample,threshold\ns1,s1,a,\ns2,s2,b,per-image\ns3,s3,steel,\ns4,s2-new,d,\n",
    )
    .unwrap();
    let stdout = batch_ok(dir, &args);
    assert_eq!(counts(&stdout), (2, 2), "{stdout}");
    // The same option in other words is the same option.
    std::fs::write(
        dir.join("sheet.csv"),
        "id,input,sample,threshold\ns1,s1,a,otsu\ns2,s2,b,per-image-otsu\ns3,s3,steel,\ns4,s2-new,d,\n",
    )
    .unwrap();
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 4));

    // A removed folder is made again; --rerun all redoes everything.
    std::fs::remove_dir_all(dir.join("results/series/s3")).unwrap();
    assert_eq!(counts(&batch_ok(dir, &args)), (1, 3));
    let mut all = args.to_vec();
    all.extend(["--rerun", "all"]);
    assert_eq!(counts(&batch_ok(dir, &all)), (4, 0));

    // A series dropped from the samplesheet leaves the tables, with a note.
    std::fs::write(dir.join("sheet.csv"), "id,input\ns1,s1\n").unwrap();
    let o = super::batch(dir, &args);
    assert!(o.status.success());
    let err = crate::common::stderr(&o);
    assert!(
        err.contains("3 series") && err.contains("s2, s3, s4"),
        "{err}"
    );
    assert_eq!(super::csv(&dir.join("results/series.csv")).1.len(), 1);
}

#[test]
fn a_changed_psf_file_redoes_its_series() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    synth(dir, "s1", 1, &[]);
    synth(dir, "s2", 2, &[]);
    std::fs::write(dir.join("psf.json"), r#"{"fwhm_nm_mean": 450}"#).unwrap();
    std::fs::write(
        dir.join("sheet.csv"),
        "id,input,psf\ns1,s1,psf.json\ns2,s2,\n",
    )
    .unwrap();
    let args = ["--samplesheet", "sheet.csv", "--out", "results"];
    assert_eq!(counts(&batch_ok(dir, &args)), (2, 0));
    let fwhm = |dir: &std::path::Path| -> Value {
        let s = std::fs::read(dir.join("results/series/s1/summary.json")).unwrap();
        serde_json::from_slice::<Value>(&s).unwrap()["area_interval"]["psf_fwhm_um"].clone()
    };
    assert_eq!(fwhm(dir), 0.45);
    assert_eq!(counts(&batch_ok(dir, &args)), (0, 2));
    // The same file with another PSF: the series that uses it is analysed again.
    std::fs::write(dir.join("psf.json"), r#"{"fwhm_nm_mean": 600}"#).unwrap();
    assert_eq!(counts(&batch_ok(dir, &args)), (1, 1));
    assert_eq!(fwhm(dir), 0.6);
}
