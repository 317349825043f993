//! Archive-wide plausibility on repeats of one experiment: ten seeds of the same synthetic
//! contact series (one sample) flag nothing; the same archive with one file whose own
//! calibration says 2 µm pixels (0.2 µm in truth) flags that series alone, naming the pixel
//! size, the factor and the direction, and the pressure and area that follow from it.

use super::{batch_ok, cells, csv, synth};

#[test]
fn repeats_are_not_flagged_and_a_wrong_calibration_is() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let mut sheet = String::from("id,input,sample\n");
    for i in 1..=10u64 {
        synth(dir, &format!("s{i}"), 100 + i, &[]);
        sheet.push_str(&format!("s{i},s{i},glass\n"));
    }
    std::fs::write(dir.join("sheet.csv"), &sheet).unwrap();
    batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "healthy"]);
    let series = csv(&dir.join("healthy/series.csv"));
    for (id, flags) in cells(&series, "series_id")
        .iter()
        .zip(cells(&series, "flags"))
    {
        assert!(
            !flags.contains("outlier"),
            "healthy repeat {id} flagged: {flags}"
        );
    }

    // s7's file says 2 µm pixels (its planes written again with that calibration).
    let planes: Vec<_> = (0..4)
        .map(|z| {
            (
                0,
                contactscope_formats::microscopy::PlaneIndex::tzc(0, z, 0),
            )
        })
        .collect();
    let tif = dir.join("s7/series.tif");
    let wrong = dir.join("s7/wrong.tif");
    crate::common::export_tiff(&tif, &planes, Some((2e-6, 2e-6)), &wrong);
    std::fs::rename(&wrong, &tif).unwrap();
    batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "healthy"]);
    let series = csv(&dir.join("healthy/series.csv"));
    let flags = cells(&series, "flags");
    for (k, f) in flags.iter().enumerate() {
        assert_eq!(f.contains("archive_outlier"), k == 6, "s{}: {f}", k + 1);
        assert!(!f.contains("threshold_outlier"), "s{}: {f}", k + 1);
    }
    let why = &cells(&series, "flag_notes")[6];
    assert!(
        why.contains("pixel size 2 µm is 10× the median 0.2 µm of the 10 series of sample 'glass'")
            && why.contains("calibration wrong in the file"),
        "{why}"
    );
    // The pressure and area follow (about 1/100 and 100× with the pixel 10× too large).
    let after = |what: &str| why.split(what).nth(1).unwrap_or_default().to_string();
    assert!(after("mean pressure").contains(" is 1/9"), "{why}");
    assert!(after("contact area").contains("× the median"), "{why}");
}
