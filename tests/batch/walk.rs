//! The folder walk: manifest folders (nested) and files matching a pattern become series with
//! the batch's defaults; the walk writes the samplesheet it used, which repeats the run exactly
//! (every series re-used), and a hand-edited samplesheet is never overwritten by a new walk.

use super::{batch, batch_ok, cells, counts, csv, synth};
use crate::common::stderr;

#[test]
fn a_walk_writes_the_samplesheet_it_used() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let archive = dir.join("archive");
    synth(&archive.join("glass"), "run2", 1, &[]);
    synth(&archive.join("glass"), "run10", 2, &[]);
    let loose = synth(&archive, "loose", 3, &[]);
    std::fs::remove_file(loose.join("manifest.csv")).unwrap();
    // The loose file states no pixel size (its planes written again without one).
    let planes: Vec<_> = (0..4)
        .map(|z| {
            (
                0,
                contactscope_formats::microscopy::PlaneIndex::tzc(0, z, 0),
            )
        })
        .collect();
    crate::common::export_tiff(
        &loose.join("series.tif"),
        &planes,
        None,
        &archive.join("steel-ramp.tif"),
    );
    std::fs::remove_dir_all(&loose).unwrap();
    // The output folder inside the archive is not walked into.
    let args = [
        "archive",
        "--pattern",
        "*.tif",
        "--forces",
        "1,2,4,8mN",
        "--pixel-size",
        "200nm",
        "--out",
        "archive/results",
    ];
    let stdout = batch_ok(dir, &args);
    assert_eq!(counts(&stdout), (3, 0), "{stdout}");
    let sheet = std::fs::read_to_string(archive.join("results/samplesheet.csv")).unwrap();
    assert_eq!(
        sheet,
        "id,input,forces,pixel_size_default\n\
         glass-run2,../glass/run2,,200nm\n\
         glass-run10,../glass/run10,,200nm\n\
         steel-ramp,../steel-ramp.tif,\"1,2,4,8mN\",200nm\n"
    );
    let series = csv(&archive.join("results/series.csv"));
    assert_eq!(
        cells(&series, "series_id"),
        ["glass-run2", "glass-run10", "steel-ramp"]
    );
    // The manifests give their own forces; the default applies to the loose file only.
    let images = csv(&archive.join("results/images.csv"));
    assert_eq!(images.1.len(), 12);
    // The batch's pixel size fills only the file that states none (flagged); the others keep
    // their own.
    let flags = cells(&series, "flags");
    assert!(!flags[0].contains("pixel_size") && !flags[1].contains("pixel_size"));
    assert!(flags[2].contains("pixel_size_default"), "{flags:?}");
    let sources = cells(&series, "pixel_size_source");
    assert_eq!(sources[0], "ImageJ unit + X/YResolution");
    assert_eq!(sources[2], "batch default for files without one");

    // The samplesheet repeats the run: everything re-used, the same tables.
    let before = std::fs::read(archive.join("results/series.parquet")).unwrap();
    let stdout = batch_ok(
        dir,
        &[
            "--samplesheet",
            "archive/results/samplesheet.csv",
            "--out",
            "archive/results",
        ],
    );
    assert_eq!(counts(&stdout), (0, 3), "{stdout}");
    let after = std::fs::read(archive.join("results/series.parquet")).unwrap();
    assert_eq!(
        super::parquet(&archive.join("results/series.parquet"))
            .1
            .len(),
        3
    );
    // The input column says how the series were named (the walk's paths, then the sheet's).
    assert_ne!(before, after);

    // Edited by hand, the samplesheet is not overwritten by another walk.
    std::fs::write(
        archive.join("results/samplesheet.csv"),
        sheet
            .replace(
                "id,input,forces,pixel_size",
                "id,input,forces,pixel_size,sample",
            )
            .replace("200nm\n", "200nm,x\n"),
    )
    .unwrap();
    let o = batch(dir, &args);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("edited since the last walk"),
        "{}",
        stderr(&o)
    );
}

/// A folder of micrographs the walk does not take (no manifest, no matching pattern) is named
/// with the options that would take it, on the terminal and in batch.json; never skipped in
/// silence.
#[test]
fn folders_of_tiffs_the_walk_does_not_take_are_listed_with_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let archive = dir.join("archive");
    synth(&archive.join("glass"), "run1", 1, &[]);
    let plain = synth(&archive, "plain", 2, &[]);
    std::fs::remove_file(plain.join("manifest.csv")).unwrap();
    let args = ["archive", "--pixel-size", "200nm", "--out", "results"];
    let o = batch(dir, &args);
    assert!(o.status.success(), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(counts(&stdout), (1, 0), "{stdout}");
    let err = stderr(&o);
    assert!(
        err.contains("not a series")
            && err.contains("plain")
            && err.contains("--tiff-folders")
            && err.contains("--pattern"),
        "{err}"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("results/batch.json")).unwrap()).unwrap();
    assert!(json["warnings"].to_string().contains("plain"), "{json}");
    // Taken when asked: the folder is a series of its own.
    let args = [
        "archive",
        "--tiff-folders",
        "--forces",
        "1,2,4,8mN",
        "--pixel-size",
        "200nm",
        "--out",
        "results2",
    ];
    let o = batch(dir, &args);
    assert!(!stderr(&o).contains("not a series"), "{}", stderr(&o));
    assert_eq!(counts(&String::from_utf8_lossy(&o.stdout)).0, 2);
}
