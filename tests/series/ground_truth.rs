//! Measurements against the synthetic generator's ground truth.

use contactscope::image::Plane;
use contactscope::measure::measure;
use contactscope::synth::{self, SynthParams};
use contactscope::threshold::{Binning, Histogram, Threshold};
use contactscope_jobs::analyze::AnalyzeRequest;
use contactscope_jobs::series::{Micrographs, SeriesSpec};
use contactscope_jobs::synth_series::{read_truth, write_series, Layout};

#[test]
fn bundled_fixture_is_what_the_generator_makes() {
    let dir = tempfile::tempdir().unwrap();
    write_series(&SynthParams::default(), dir.path(), Layout::MultiPage).unwrap();
    for name in ["series.tif", "manifest.csv", "truth.csv"] {
        let bundled = std::fs::read(crate::common::fixture_series().join(name)).unwrap();
        let fresh = std::fs::read(dir.path().join(name)).unwrap();
        assert!(
            bundled == fresh,
            "{name} differs from a fresh generation: regenerate (fixtures/README.md)"
        );
    }
}

#[test]
fn bundled_series_areas_match_the_truth() {
    let manifest = crate::common::fixture_series().join("manifest.csv");
    let request = AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
        manifest: Some(manifest),
        ..SeriesSpec::default()
    }));
    let outcome =
        contactscope_jobs::analyze::run(&request, &|_, _, _| {}, &|_, _, _| Ok(())).unwrap();
    let (analysis, report) = (&outcome.analysis, &outcome.rows);
    let truth = read_truth(&crate::common::fixture_series().join("truth.csv")).unwrap();
    assert_eq!(report.rows.len(), truth.len());
    for (row, true_area) in report.rows.iter().zip(&truth) {
        let error = row.area / true_area - 1.0;
        // PSF blur (FWHM 2.25 px) erodes the smallest patches: at most 8 % at 40 µm², at most
        // 2 % once the true contact exceeds 100 µm².
        let tolerance = if *true_area > 100.0 { 0.02 } else { 0.08 };
        assert!(
            error.abs() <= tolerance,
            "{} mN: {} vs {true_area}",
            row.force_mn.unwrap(),
            row.area
        );
    }
    let fit = outcome.fits.power_law.unwrap();
    assert!((fit.exponent - 0.85).abs() < 0.03, "β = {}", fit.exponent);
    let t = analysis.series_threshold.unwrap().value;
    assert!(
        t > 400.0 && t < 2000.0,
        "threshold between background and contact: {t}"
    );
    let first = &analysis.images[0].measurement;
    let last = &analysis.images[7].measurement;
    assert!(
        last.mean_intensity.unwrap() > first.mean_intensity.unwrap(),
        "signal rises with load"
    );
    for r in &analysis.images {
        let bg = r.measurement.background_mean.unwrap();
        // 300 counts plus the PSF tails of contact just below the threshold.
        assert!((bg - 300.0).abs() < 30.0, "background {bg}");
    }
}

#[test]
fn contact_masks_overlap_the_true_contact() {
    let p = SynthParams {
        width: 128,
        height: 128,
        forces_n: vec![10e-3, 40e-3],
        ..SynthParams::default()
    };
    let images = synth::generate(&p).unwrap();
    let planes: Vec<Plane> = images
        .iter()
        .map(|im| Plane::from_u16(p.width, p.height, im.codes.clone()))
        .collect();
    let mut pooled = Histogram::new(Binning::Integer { offset: 0 });
    for plane in &planes {
        pooled.add_plane(plane).unwrap();
    }
    let t = Threshold::otsu(&pooled, "series").unwrap();
    for (plane, im) in planes.iter().zip(&images) {
        let (_, mask) = measure(plane, &t).unwrap();
        let both = mask
            .data
            .iter()
            .zip(&im.truth)
            .filter(|(m, t)| **m == 1 && **t)
            .count();
        let either = mask
            .data
            .iter()
            .zip(&im.truth)
            .filter(|(m, t)| **m == 1 || **t)
            .count();
        let jaccard = both as f64 / either as f64;
        assert!(jaccard > 0.75, "Jaccard {jaccard}");
    }
}
