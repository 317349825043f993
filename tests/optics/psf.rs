//! PSF from beads: validation B15 (Gaussian-fit sanity), synthetic beads with known σ, the
//! `psf` command and the real pycudadecon bead stack.

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Poisson};
use serde_json::Value;

use contactscope::image::Image;
use contactscope::image::{PixelSize, PixelSizeSource};
use contactscope::optics::psf::{
    fit_spot, measure_psf, PlaneView, PsfOptions, PsfReport, SkipReason, SpotOptions,
    FWHM_PER_SIGMA,
};
use contactscope::synth::beads::{synth_beads, BeadKind, BeadParams, Sampling, SyntheticBeads};
use contactscope_formats::tiff::encode_u16_stack;

const SIZE: usize = 41;
const CENTRE: (f64, f64) = (20.37, 19.81);

/// B15's spot: point-sampled Gaussian, σ = 2 px, background 10, peak 1000.
fn b15_spot() -> Vec<f64> {
    (0..SIZE * SIZE)
        .map(|i| {
            let (x, y) = ((i % SIZE) as f64 - CENTRE.0, (i / SIZE) as f64 - CENTRE.1);
            10.0 + 1000.0 * (-(x * x + y * y) / 8.0).exp()
        })
        .collect()
}

fn fit_b15(values: &[f64]) -> contactscope::optics::psf::SpotFit {
    let grid = PlaneView {
        values,
        width: SIZE,
        height: SIZE,
    };
    fit_spot(grid, 20, 20, &SpotOptions::default()).expect("spot fits")
}

#[test]
fn b15_fwhm_per_sigma() {
    assert!((FWHM_PER_SIGMA - 2.354820).abs() < 1e-6);
    assert!((FWHM_PER_SIGMA - 2.0 * (2.0 * 2f64.ln()).sqrt()).abs() < 1e-15);
}

#[test]
fn b15_noise_free_spot_gives_sigma_and_centre_to_1e3_px() {
    let fit = fit_b15(&b15_spot());
    let g = &fit.gauss2d;
    println!(
        "noise-free: radial σ − 2 = {:.2e}, 2-D σx − 2 = {:.2e}, centre error {:.2e} px",
        fit.radial.sigma_px - 2.0,
        g.sigma_x_px - 2.0,
        (g.x_px - CENTRE.0).hypot(g.y_px - CENTRE.1)
    );
    assert!(
        (fit.radial.sigma_px - 2.0).abs() < 1e-3,
        "radial σ {}",
        fit.radial.sigma_px
    );
    assert!(
        (g.sigma_x_px - 2.0).abs() < 1e-3 && (g.sigma_y_px - 2.0).abs() < 1e-3,
        "{g:?}"
    );
    // The reported centre is the 2-D fit's.
    assert!(
        (g.x_px - CENTRE.0).abs() < 1e-3 && (g.y_px - CENTRE.1).abs() < 1e-3,
        "{g:?}"
    );
    // The centre of intensity that the radial profile uses is close too.
    let (cx, cy) = fit.centroid_px;
    assert!(
        (cx - CENTRE.0).hypot(cy - CENTRE.1) < 0.05,
        "{:?}",
        fit.centroid_px
    );
}

#[test]
fn b15_poisson_noise_at_peak_1000_gives_sigma_within_2_percent() {
    for seed in 0..5 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noisy: Vec<f64> = b15_spot()
            .iter()
            .map(|&v| Poisson::new(v).unwrap().sample(&mut rng))
            .collect();
        let fit = fit_b15(&noisy);
        let radial = fit.radial.sigma_px;
        let (sx, sy) = (fit.gauss2d.sigma_x_px, fit.gauss2d.sigma_y_px);
        println!("Poisson seed {seed}: radial σ {radial:.4}, 2-D σx {sx:.4}, σy {sy:.4} px");
        assert!(
            (radial / 2.0 - 1.0).abs() < 0.02,
            "seed {seed}: radial σ {radial}"
        );
        assert!(
            (sx / 2.0 - 1.0).abs() < 0.02 && (sy / 2.0 - 1.0).abs() < 0.02,
            "seed {seed}: {sx} {sy}"
        );
    }
}

fn images_of(s: &SyntheticBeads, pixel_m: f64) -> Vec<Image> {
    s.planes
        .iter()
        .enumerate()
        .map(|(page, codes)| Image {
            values: codes.iter().map(|&c| f64::from(c)).collect(),
            width: s.width,
            height: s.height,
            pixel_size: Some(PixelSize {
                x_m: pixel_m,
                y_m: pixel_m,
                source: PixelSizeSource::CommandLine,
            }),
            path: PathBuf::from("synthetic.tif"),
            page,
        })
        .collect()
}

/// 191 nm σ at 100 nm pixels (Weber et al.'s FWHM 450 nm), with a crowded pair and a saturated bead.
fn paper_like(planes: usize, seed: u64) -> BeadParams {
    BeadParams {
        width: 160,
        height: 160,
        planes,
        beads: 8,
        sigma_px: 1.91,
        min_separation_px: 24.0,
        crowded_pair: true,
        saturated_bead: true,
        seed,
        ..BeadParams::default()
    }
}

fn measure(s: &SyntheticBeads, bead_diameter_m: Option<f64>) -> PsfReport {
    let options = PsfOptions {
        saturation_level: Some(4095.0),
        bead_diameter_m,
        ..PsfOptions::default()
    };
    measure_psf(&images_of(s, 100e-9), &options).expect("PSF measured")
}

/// Every truth bead is found, isolated ones used at their focus plane, the others skipped
/// with their reason; the mean σ is within 1 % of 191 nm.
fn check_recovery(s: &SyntheticBeads, report: &PsfReport) {
    for t in &s.truth {
        let b = report
            .beads
            .iter()
            .find(|b| (b.candidate.x as f64 - t.x_px).hypot(b.candidate.y as f64 - t.y_px) < 1.5)
            .unwrap_or_else(|| panic!("bead at {t:?} not found"));
        match t.kind {
            BeadKind::Isolated => {
                assert!(b.skip.is_none(), "{t:?}: {:?}", b.skip);
                assert_eq!(b.candidate.plane, t.focus_plane, "{t:?}");
                let g = &b.fit.as_ref().unwrap().gauss2d;
                assert!(
                    (g.x_px - t.x_px).hypot(g.y_px - t.y_px) < 0.1,
                    "{t:?} {g:?}"
                );
            }
            BeadKind::Crowded => {
                assert!(
                    matches!(b.skip, Some(SkipReason::Crowded { .. })),
                    "{:?}",
                    b.skip
                )
            }
            BeadKind::Saturated => {
                assert!(
                    matches!(b.skip, Some(SkipReason::Saturated { .. })),
                    "{:?}",
                    b.skip
                )
            }
        }
    }
    let isolated = s
        .truth
        .iter()
        .filter(|t| t.kind == BeadKind::Isolated)
        .count();
    assert_eq!(report.summary.beads_used, isolated);
    let sigma_nm = report.summary.sigma_m.mean * 1e9;
    println!(
        "{} plane(s): mean σ {sigma_nm:.3} nm ({:+.3} % vs 191 nm), sd {:.3} nm, {} used",
        report.planes,
        100.0 * (sigma_nm / 191.0 - 1.0),
        report.summary.sigma_m.sd.unwrap_or(f64::NAN) * 1e9,
        report.summary.beads_used
    );
    assert!(
        (sigma_nm / 191.0 - 1.0).abs() < 0.01,
        "mean σ {sigma_nm} nm"
    );
}

#[test]
fn synthetic_stack_recovers_sigma_focus_and_skips() {
    for seed in [1, 2] {
        let s = synth_beads(&paper_like(11, seed)).unwrap();
        let report = measure(&s, None);
        check_recovery(&s, &report);
        assert_eq!(report.planes, 11);
    }
}

#[test]
fn synthetic_image_recovers_sigma_and_skips() {
    let s = synth_beads(&paper_like(1, 3)).unwrap();
    check_recovery(&s, &measure(&s, None));
}

#[test]
fn bead_correction_subtracts_a_squared_over_5() {
    let s = synth_beads(&paper_like(1, 3)).unwrap();
    let report = measure(&s, Some(100e-9));
    for b in report.beads.iter().filter(|b| b.skip.is_none()) {
        let (raw, corr) = (b.sigma_raw_m.unwrap(), b.sigma_m.unwrap());
        assert!((raw * raw - corr * corr - (50e-9f64).powi(2) / 5.0).abs() < 1e-20);
    }
    assert!(report.summary.sigma_m.mean < report.summary.sigma_raw_m.mean);
}

#[test]
fn pixel_integration_widens_sigma_squared_by_a_twelfth() {
    let p = BeadParams {
        beads: 3,
        sigma_px: 1.5,
        noise: false,
        sampling: Sampling::Integrated,
        peak: 3000.0,
        ..BeadParams::default()
    };
    let s = synth_beads(&p).unwrap();
    let report = measure(&s, None);
    let sigma_px = report.summary.sigma_raw_m.mean / 100e-9;
    // 8 × 8 midpoint sub-samples give (1 − 1/64)/12 rather than 1/12; rounding to integers adds a little.
    let expected = (1.5f64 * 1.5 + (1.0 - 1.0 / 64.0) / 12.0).sqrt();
    assert!(
        (sigma_px - expected).abs() < 2e-3,
        "{sigma_px} vs {expected}"
    );
    assert!(sigma_px - 1.5 > 0.02);
}

// ---- command line ----

fn write_tiff(dir: &Path, name: &str, s: &SyntheticBeads, pixel_m: Option<f64>) -> PathBuf {
    let path = dir.join(name);
    let pages: Vec<&[u16]> = s.planes.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(&pages, s.width, s.height, pixel_m.map(|p| (p, p)), "").unwrap();
    std::fs::write(&path, tiff).unwrap();
    path
}

fn json_of(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn cli_psf_on_a_synthetic_stack_writes_the_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let s = synth_beads(&paper_like(9, 4)).unwrap();
    let input = write_tiff(dir.path(), "beads.tif", &s, Some(100e-9));
    let out = dir.path().join("psf-out");
    let run = crate::common::run(&[
        "psf",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", crate::common::stderr(&run));
    assert!(
        crate::common::stdout(&run).contains("FWHM"),
        "{}",
        crate::common::stdout(&run)
    );
    let json = json_of(&out.join("psf.json"));
    let fwhm = json["fwhm_nm_mean"].as_f64().unwrap();
    assert!(
        (fwhm / (191.0 * FWHM_PER_SIGMA) - 1.0).abs() < 0.01,
        "{fwhm}"
    );
    assert!(json["fwhm_nm_sd"].as_f64().unwrap() < 0.05 * fwhm);
    assert!((json["sigma_nm_mean"].as_f64().unwrap() - fwhm / FWHM_PER_SIGMA).abs() < 1e-9);
    assert_eq!(json["beads_used"], 8);
    assert_eq!(json["beads_found"], 11);
    assert_eq!(json["pixel_size_nm"].as_f64().unwrap().round(), 100.0);
    assert_eq!(json["bead_correction_applied"], false);
    assert_eq!(json["saturation_level"], 4095.0);
    let reasons: Vec<&str> = json["skipped"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["reason"].as_str().unwrap())
        .collect();
    assert_eq!(
        reasons.iter().filter(|r| **r == "crowded").count(),
        2,
        "{reasons:?}"
    );
    assert_eq!(
        reasons.iter().filter(|r| **r == "saturated").count(),
        1,
        "{reasons:?}"
    );
    let (header, rows) = crate::common::read_csv(&out.join("beads.csv"));
    assert_eq!(rows.len(), 11);
    let used: Vec<&Vec<String>> = rows
        .iter()
        .filter(|r| r[header.iter().position(|h| h == "used").unwrap()] == "true")
        .collect();
    assert_eq!(used.len(), 8);
    let fwhm_col = header.iter().position(|h| h == "fwhm_nm").unwrap();
    assert!(used
        .iter()
        .all(|r| (r[fwhm_col].parse::<f64>().unwrap() / 449.8 - 1.0).abs() < 0.05));
    let png = std::fs::read(out.join("psf_profiles.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn cli_bead_diameter_turns_the_correction_on() {
    let dir = tempfile::tempdir().unwrap();
    let s = synth_beads(&paper_like(1, 5)).unwrap();
    let input = write_tiff(dir.path(), "beads.tif", &s, Some(100e-9));
    let out = dir.path().join("o");
    let run = crate::common::run(&[
        "psf",
        input.to_str().unwrap(),
        "--bead-diameter",
        "100nm",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", crate::common::stderr(&run));
    let json = json_of(&out.join("psf.json"));
    assert_eq!(json["bead_correction_applied"], true);
    assert_eq!(json["bead_diameter_nm"].as_f64().unwrap().round(), 100.0);
    assert!(json["sigma_nm_mean"].as_f64().unwrap() < json["sigma_raw_nm_mean"].as_f64().unwrap());
}

/// A failing run names the file, exits non-zero and leaves no output folder (nor its parent).
fn assert_refused(args: &[&str], out: &Path, file: &str, message: &str) {
    let run = crate::common::run(args);
    let err = crate::common::stderr(&run);
    assert!(!run.status.success(), "{args:?} succeeded");
    assert!(err.contains(file) && err.contains(message), "{err}");
    assert!(
        !out.exists() && !out.parent().unwrap().exists(),
        "{} exists",
        out.display()
    );
}

#[test]
fn cli_bad_inputs_are_refused_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results/psf");
    let out_s = out.to_str().unwrap();
    let blank = SyntheticBeads {
        planes: vec![vec![100; 64 * 64]],
        width: 64,
        height: 64,
        truth: vec![],
    };
    let blank_path = write_tiff(dir.path(), "blank.tif", &blank, Some(100e-9));
    assert_refused(
        &["psf", blank_path.to_str().unwrap(), "--out", out_s],
        &out,
        "blank.tif",
        "no beads",
    );

    // A 20 px tall strip; a σ = 2.5 px bead needs a 25 px window.
    let one = BeadParams {
        width: 100,
        height: 20,
        beads: 1,
        sigma_px: 2.5,
        margin_px: 9.0,
        ..BeadParams::default()
    };
    let tiny = write_tiff(
        dir.path(),
        "tiny.tif",
        &synth_beads(&one).unwrap(),
        Some(100e-9),
    );
    assert_refused(
        &["psf", tiny.to_str().unwrap(), "--out", out_s],
        &out,
        "tiny.tif",
        "wider than the image",
    );

    let s = synth_beads(&paper_like(1, 6)).unwrap();
    let bare = write_tiff(dir.path(), "bare.tif", &s, None);
    assert_refused(
        &["psf", bare.to_str().unwrap(), "--out", out_s],
        &out,
        "bare.tif",
        "--pixel-size",
    );
    assert_refused(
        &[
            "psf",
            bare.to_str().unwrap(),
            "--pixel-size",
            "100",
            "--out",
            out_s,
        ],
        &out,
        "",
        "unit",
    );
}

#[test]
fn cli_all_beads_skipped_lists_the_reasons() {
    let dir = tempfile::tempdir().unwrap();
    let p = BeadParams {
        beads: 0,
        crowded_pair: true,
        ..BeadParams::default()
    };
    let input = write_tiff(
        dir.path(),
        "pair.tif",
        &synth_beads(&p).unwrap(),
        Some(100e-9),
    );
    let out = dir.path().join("x/psf");
    assert_refused(
        &[
            "psf",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &out,
        "pair.tif",
        "all 2 bead candidates were skipped",
    );
    let err = crate::common::stderr(&crate::common::run(&[
        "psf",
        input.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(err.contains("crowded"), "{err}");
}

// ---- real data ----

#[test]
fn real_pycudadecon_bead_stack() {
    let Some(input) = crate::common::shared_data("real-tiff/pycudadecon/psf.tif") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("psf");
    let run = crate::common::run(&[
        "psf",
        input.to_str().unwrap(),
        "--pixel-size",
        "101.08nm",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(run.status.success(), "{}", crate::common::stderr(&run));
    println!("{}", crate::common::stdout(&run));
    let json = json_of(&out.join("psf.json"));
    assert!(json["beads_used"].as_u64().unwrap() >= 1, "{json}");
    let fwhm = json["fwhm_nm_mean"].as_f64().unwrap();
    // Physically sensible: above the ~150 nm a visible-light objective can reach, below a micron.
    assert!((150.0..1000.0).contains(&fwhm), "FWHM {fwhm} nm");
    assert_eq!(json["planes"], 61);
    let (header, rows) = crate::common::read_csv(&out.join("beads.csv"));
    let used = header.iter().position(|h| h == "used").unwrap();
    let planes = crate::common::column(&header, &rows, "plane");
    for (row, plane) in rows.iter().zip(planes) {
        if row[used] == "true" {
            assert!(plane > 0.0 && plane < 60.0, "focus plane {plane}");
        }
    }
}
