//! The corrected areas' intervals of `analyze` against the generator's truth, through the
//! command line and the library: a smaller version of `cargo bench --bench intervals`
//! (`docs/validation.md` B25).

use crate::common::{column, read_csv, run_ok};

/// Three synthetic series through the command line: every interval holds its corrected area, at
/// least 90 % hold the truth, the pressures' interval is the force over the areas' ends, and
/// the exponent's interval holds the true areas' exponent in at least two of three.
#[test]
fn area_intervals_hold_the_true_area_of_synthetic_series() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut covered, mut total, mut beta_covered) = (0usize, 0usize, 0usize);
    let mut widths = Vec::new();
    for seed in ["3", "5", "8"] {
        let series = tmp.path().join(format!("s{seed}"));
        let out = tmp.path().join(format!("a{seed}"));
        let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
        run_ok(&["synth-series", "--seed", seed, "--out", &s(&series)]);
        run_ok(&[
            "analyze",
            &s(&series),
            "--out",
            &s(&out),
            "--psf-fwhm",
            "450nm",
            "-q",
        ]);
        let (h, r) = read_csv(&out.join("areas.csv"));
        let (corrected, lo, hi) = (
            column(&h, &r, "area_corrected_um2"),
            column(&h, &r, "area_um2_lo"),
            column(&h, &r, "area_um2_hi"),
        );
        let (th, tr) = read_csv(&series.join("truth.csv"));
        let truth = column(&th, &tr, "true_area_um2");
        assert_eq!(truth.len(), corrected.len());
        for i in 0..corrected.len() {
            assert!(
                lo[i] <= corrected[i] && corrected[i] <= hi[i],
                "the interval holds the corrected area"
            );
            total += 1;
            // The truth file rounds to 1e-6 µm².
            if lo[i] <= truth[i] + 1e-6 && truth[i] - 1e-6 <= hi[i] {
                covered += 1;
            }
            widths.push((hi[i] - lo[i]) / truth[i]);
        }
        // The pressures' interval is the force over the areas' ends.
        let (f, p_lo, p_hi) = (
            column(&h, &r, "force_mN"),
            column(&h, &r, "mean_pressure_MPa_lo"),
            column(&h, &r, "mean_pressure_MPa_hi"),
        );
        for i in 0..f.len() {
            assert!((p_lo[i] - f[i] / hi[i] * 1e3).abs() < 1e-9 * p_lo[i]);
            assert!((p_hi[i] - f[i] / lo[i] * 1e3).abs() < 1e-9 * p_hi[i]);
        }
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["area_interval"]["level_pct"], 95.0);
        assert_eq!(summary["area_interval"]["model"], "light_budget");
        assert_eq!(summary["area_interval"]["psf_source"], "given");
        assert!((summary["area_interval"]["psf_fwhm_um"].as_f64().unwrap() - 0.45).abs() < 1e-9);
        // The exponent's bootstrap interval against the exponent of the true areas; it holds
        // the corrected areas' exponent.
        let law = &summary["fits"]["power_law"];
        let ci: Vec<f64> = law["exponent_ci95"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(ci[0] < ci[1] && ci[1] - ci[0] < 0.1, "{ci:?}");
        let estimate = law["exponent_corrected"].as_f64().unwrap();
        assert!(ci[0] <= estimate && estimate <= ci[1], "{estimate} {ci:?}");
        // So do the prefactor's and the pressure's: each estimate from the corrected areas.
        for (estimate, interval) in [
            (
                &law["prefactor_corrected_um2_per_mN_pow_exponent"],
                &law["prefactor_um2_per_mN_pow_exponent_ci95"],
            ),
            (
                &summary["fits"]["proportional"]["pressure_corrected_MPa"],
                &summary["fits"]["proportional"]["pressure_MPa_ci95"],
            ),
        ] {
            let (e, lo, hi) = (
                estimate.as_f64().unwrap(),
                interval[0].as_f64().unwrap(),
                interval[1].as_f64().unwrap(),
            );
            assert!(lo <= e && e <= hi, "{e} outside {lo}…{hi}");
        }
        let (n, a): (Vec<f64>, Vec<f64>) = column(&th, &tr, "force_mN")
            .into_iter()
            .zip(truth.iter().copied())
            .map(|(f, a)| (f.ln(), a.ln()))
            .unzip();
        let (mn, ma) = (n.iter().sum::<f64>() / 8.0, a.iter().sum::<f64>() / 8.0);
        let true_beta = n
            .iter()
            .zip(&a)
            .map(|(x, y)| (x - mn) * (y - ma))
            .sum::<f64>()
            / n.iter().map(|x| (x - mn).powi(2)).sum::<f64>();
        if ci[0] <= true_beta && true_beta <= ci[1] {
            beta_covered += 1;
        }
        let p = &summary["fits"]["proportional"]["pressure_MPa_ci95"];
        assert!(p[0].as_f64().unwrap() < p[1].as_f64().unwrap());
    }
    widths.sort_by(f64::total_cmp);
    let median_width = widths[widths.len() / 2];
    assert_eq!(total, 24);
    assert!(
        covered * 10 >= total * 9,
        "{covered} of {total} intervals hold the truth"
    );
    assert!(median_width <= 0.20, "median relative width {median_width}");
    assert!(
        beta_covered >= 2,
        "the true exponent in {beta_covered} of 3 intervals"
    );
}

/// One series analysed as `analyze` does with light budgets (the PSF and pixel size given),
/// scored against its truth: per load rank (the two lightest loads, the middle four, the two
/// heaviest) the intervals holding the true area and the images, and the contact-pixel count's
/// relative errors at the lightest two. Asserts that every interval holds its corrected area.
struct RankTally {
    covered: [usize; 3],
    images: [usize; 3],
    pixel_err_lightest: Vec<f64>,
    corrected_err: [Vec<f64>; 3],
}

impl RankTally {
    fn new() -> Self {
        RankTally {
            covered: [0; 3],
            images: [0; 3],
            pixel_err_lightest: Vec::new(),
            corrected_err: Default::default(),
        }
    }

    fn add(
        &mut self,
        codes: &[Vec<u16>],
        side: usize,
        forces_n: &[f64],
        truth_px: &[f64],
        psf_fwhm_m: f64,
        pixel_m: f64,
    ) {
        use contactscope::analysis::corrected::{correct_series, Assumptions};
        use contactscope::analysis::{analyze, AnalysisOptions};
        use contactscope::image::{PixelSize, PixelSizeSource, Plane};
        let planes: Vec<Plane> = codes
            .iter()
            .map(|c| Plane::from_u16(side, side, c.clone()))
            .collect();
        let options = AnalysisOptions {
            psf_sigma_px: Some(psf_fwhm_m / contactscope::optics::blur::FWHM_PER_SIGMA / pixel_m),
            pixel_size: Some(PixelSize {
                x_m: pixel_m,
                y_m: pixel_m,
                source: PixelSizeSource::CommandLine,
            }),
            light_budgets: true,
            ..AnalysisOptions::default()
        };
        let analysis = analyze(
            planes.as_slice(),
            &options,
            &|_, _, _| {},
            &|_, _, _| Ok(()),
        )
        .unwrap();
        let forces: Vec<Option<f64>> = forces_n.iter().map(|&f| Some(f)).collect();
        let correction = correct_series(&analysis, &forces, Assumptions::default());
        let n = codes.len();
        for (k, &truth) in truth_px.iter().enumerate() {
            let rank = if k < 2 {
                0
            } else if k + 2 >= n {
                2
            } else {
                1
            };
            let c = correction.areas[k].expect("contact light");
            self.images[rank] += 1;
            self.covered[rank] += usize::from(c.lo_px <= truth && truth <= c.hi_px);
            assert!(c.lo_px <= c.area_px && c.area_px <= c.hi_px);
            self.corrected_err[rank].push(c.area_px / truth - 1.0);
            if rank == 0 {
                let pixels = analysis.images[k].measurement.contact_pixels as f64;
                self.pixel_err_lightest.push(pixels / truth - 1.0);
            }
        }
    }

    /// At least 90 % of each rank's intervals hold the truth.
    fn assert_coverage(&self, what: &str) {
        for r in 0..3 {
            assert!(
                self.covered[r] * 10 >= self.images[r] * 9,
                "{what}, rank {r}: {} of {} intervals hold the truth",
                self.covered[r],
                self.images[r]
            );
        }
    }

    /// The corrected areas' median relative error is within `bound` at each rank.
    fn assert_estimate(&self, what: &str, bound: f64) {
        for (r, errors) in self.corrected_err.iter().enumerate() {
            let mut e = errors.clone();
            e.sort_by(f64::total_cmp);
            let median = e[e.len() / 2];
            eprintln!("{what}, rank {r}: median error of the corrected area {median:+.4}");
            assert!(
                median.abs() <= bound,
                "{what}, rank {r}: median error of the corrected area {median:+.3}"
            );
        }
    }

    /// The mean relative error of the pixel count at the lightest loads.
    fn lightest_pixel_bias(&self) -> f64 {
        self.pixel_err_lightest.iter().sum::<f64>() / self.pixel_err_lightest.len() as f64
    }
}

/// The light budget's corrected areas (`contactscope::analysis::corrected`; a smaller version
/// of `cargo bench --bench light_intervals`): patches below the PSF and coarse ones, under the
/// widest PSF of the bench, at 20 and 500 photons: per load rank at least 90 % of the intervals
/// hold the true area, where the contact-pixel count misses it by more than its own noise at
/// the lightest loads below the PSF.
#[test]
fn corrected_areas_hold_the_truth_where_the_psf_biases_the_pixel_count() {
    use contactscope::synth::{generate, SynthParams};
    for scale in [0.25, 2.0] {
        let mut tally = RankTally::new();
        for seed in 0..6u64 {
            let photons = if seed % 2 == 0 { 20.0 } else { 500.0 };
            let params = SynthParams {
                seed: 7000 + seed,
                counts_per_photon: 1800.0 / photons,
                psf_fwhm_m: 750e-9,
                patch_scale: scale,
                read_noise_counts: 3.0,
                ..SynthParams::default()
            };
            let series = generate(&params).unwrap();
            assert_eq!(params.width, params.height);
            tally.add(
                &series.iter().map(|i| i.codes.clone()).collect::<Vec<_>>(),
                params.width,
                &series.iter().map(|i| i.force_n).collect::<Vec<_>>(),
                &series
                    .iter()
                    .map(|i| i.true_contact_pixels as f64)
                    .collect::<Vec<_>>(),
                750e-9,
                params.pixel_size_m,
            );
        }
        tally.assert_coverage(&format!("scale {scale}"));
        tally.assert_estimate(&format!("scale {scale}"), 0.08);
        if scale < 1.0 {
            // What the correction is for: the count is biased below the PSF.
            let mean = tally.lightest_pixel_bias();
            assert!(
                mean.abs() > 0.05,
                "pixel-count error at the lightest loads {mean}"
            );
        }
    }
}

/// The same on the second generator, `contactscope::synth::solved`: six ramps of the paper
/// preset's sub-PSF patches (two per contact model; seeds 0, 3 and 6 are elastic, whose
/// heaviest interiors are porous below the PSF and read 20–30 % under the signal) imaged at the
/// widest PSF, 750 nm, on 200 nm pixels at 20 and 500 photons: per load rank at least 90 % of
/// the intervals hold the true area. About a minute of solving on 2 cores.
#[test]
fn corrected_areas_hold_the_truth_of_solved_rough_contacts() {
    use contactscope::synth::solved::{image_ramp, solve_ramp, Camera, PatchScale, RampSpec};
    use rayon::prelude::*;
    let ramps: Vec<_> = [0u64, 1, 2, 3, 5, 6]
        .par_iter()
        .map(|&seed| solve_ramp(&RampSpec::paper(PatchScale::SubPsf, seed)).unwrap())
        .collect();
    let mut tally = RankTally::new();
    for ramp in &ramps {
        for photons in [20.0, 500.0] {
            let camera = Camera::new(200e-9, 750e-9, photons, 7 + ramp.spec.seed);
            let images = image_ramp(ramp, &camera).unwrap();
            assert_eq!(images[0].width, images[0].height);
            tally.add(
                &images.iter().map(|i| i.codes.clone()).collect::<Vec<_>>(),
                images[0].width,
                &images.iter().map(|i| i.force_n).collect::<Vec<_>>(),
                &images.iter().map(|i| i.true_area_px).collect::<Vec<_>>(),
                750e-9,
                200e-9,
            );
        }
    }
    tally.assert_coverage("solved sub-PSF ramps");
    tally.assert_estimate("solved sub-PSF ramps", 0.08);
}

/// A smaller version of `cargo bench --bench k_intervals`: the reduced demo's synthetic
/// experiment (true k = 4 MPa/nm) on 5 seeds, analysed and fitted as the demo does; the 95 %
/// interval of k holds the truth in at least 4 of 5 and is under 60 % wide (median).
#[test]
fn k_intervals_hold_the_true_k_of_synthetic_experiments() {
    use contactscope::model_fit::{fit_parameter, Family};
    use contactscope_jobs::analyze::{run, AnalyzeRequest};
    use contactscope_jobs::demo::{
        fit_search, imaging, model_body, synthetic_experiment, DemoParams,
    };
    use contactscope_jobs::series::{Micrographs, SeriesSpec};
    let tmp = tempfile::tempdir().unwrap();
    let (mut covered, mut widths) = (0, Vec::new());
    for seed in 3000..3005 {
        let p = DemoParams {
            seed,
            ..DemoParams::reduced()
        };
        let experiment = synthetic_experiment(&p, &tmp.path().join(seed.to_string()), &|_| {})
            .expect("the synthetic experiment");
        let analysis = run(
            &AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
                manifest: Some(experiment.manifest.clone()),
                ..SeriesSpec::default()
            })),
            &|_, _, _| {},
            &|_, _, _| Ok(()),
        )
        .unwrap();
        let measured = analysis.measured_curve().expect("a measured curve");
        let mut body = model_body(&p, &experiment).unwrap();
        body.imaging = Some(imaging(&p));
        let search = fit_search(&p, Family::Hardening);
        let fit = fit_parameter(&body, Family::Hardening, &measured, search).unwrap();
        let (lo, hi) = fit.parameter_ci95.expect("an interval");
        let k = fit.best.parameter.unwrap();
        assert!(lo < k && k < hi, "{lo} {k} {hi}");
        covered += usize::from(lo <= p.k_pa_per_m && p.k_pa_per_m <= hi);
        widths.push((hi - lo) / p.k_pa_per_m);
    }
    widths.sort_by(f64::total_cmp);
    assert!(covered >= 4, "the true k in {covered} of 5 intervals");
    assert!(widths[2] < 0.6, "median relative width {}", widths[2]);
}

/// The pixel size's uncertainty from `analyze` reaches `fit-hardening` through `areas.csv`: the
/// fit records it, and its k interval widens; an interval whose ends are out of order is
/// refused naming the file and line.
#[test]
fn a_pixel_size_uncertainty_travels_from_analyze_to_the_k_interval() {
    let tmp = tempfile::tempdir().unwrap();
    let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
    let demo = tmp.path().join("demo");
    run_ok(&["demo", "--small", "--out", &s(&demo), "-q"]);
    let manifest = demo.join("data/micrographs/manifest.csv");
    let fit = |name: &str, extra: &[&str]| -> serde_json::Value {
        let analysis = tmp.path().join(format!("a_{name}"));
        let mut args = vec!["analyze", "--manifest"];
        let (m, a) = (s(&manifest), s(&analysis));
        args.extend([m.as_str(), "--out", a.as_str(), "-q"]);
        args.extend(extra);
        run_ok(&args);
        let out = tmp.path().join(format!("f_{name}"));
        let (areas, topo, o) = (
            s(&analysis.join("areas.csv")),
            s(&demo.join("data/topography.npy")),
            s(&out),
        );
        run_ok(&[
            "fit-hardening",
            "--areas",
            &areas,
            "--topography",
            &topo,
            "--pixel-size",
            "80nm",
            "--detrend",
            "none",
            "--radius",
            "50um",
            "--modulus",
            "3.7GPa",
            "--models",
            "hardening",
            "--psf-fwhm",
            "450nm",
            "--micrograph-pixel-size",
            "200nm",
            "--imaged-areas",
            "--out",
            &o,
            "-q",
        ]);
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap()
    };
    let exact = fit("exact", &[]);
    let calibrated = fit("calibrated", &["--pixel-size", "200nm±3%"]);
    assert_eq!(exact["measured"]["pixel_size_uncertainty_pct"], 0.0);
    assert_eq!(calibrated["measured"]["pixel_size_uncertainty_pct"], 3.0);
    let width = |v: &serde_json::Value| {
        let ci = &v["models"][0]["k_MPa_per_nm_ci95"];
        ci[1].as_f64().unwrap() - ci[0].as_f64().unwrap()
    };
    assert!(
        width(&calibrated) > width(&exact),
        "{} {}",
        width(&calibrated),
        width(&exact)
    );
    // The same k: the calibration widens the interval, it does not move the fit.
    assert_eq!(
        exact["models"][0]["k_MPa_per_nm"],
        calibrated["models"][0]["k_MPa_per_nm"]
    );
    // An areas.csv whose interval misses its area: one line naming the file and the line.
    let table = tmp.path().join("a_exact/areas.csv");
    let text = std::fs::read_to_string(&table).unwrap();
    let (header, rest) = text.split_once('\n').unwrap();
    let cols: Vec<&str> = header.split(',').collect();
    let at = cols.iter().position(|c| *c == "area_um2_lo").unwrap();
    let mut lines: Vec<String> = rest.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[1].split(',').map(String::from).collect();
    cells[at] = "1e6".into();
    lines[1] = cells.join(",");
    let broken = tmp.path().join("broken.csv");
    std::fs::write(&broken, format!("{header}\n{}\n", lines.join("\n"))).unwrap();
    let out = crate::common::run(&[
        "fit-hardening",
        "--areas",
        &s(&broken),
        "--topography",
        &s(&demo.join("data/topography.npy")),
        "--pixel-size",
        "80nm",
        "--modulus",
        "3.7GPa",
        "--radius",
        "50um",
        "--out",
        &s(&tmp.path().join("never")),
    ]);
    assert!(!out.status.success());
    let err = crate::common::stderr(&out);
    assert!(
        err.contains("broken.csv:3") && err.contains("is not an interval"),
        "{err}"
    );
    assert!(!tmp.path().join("never").exists());
}

/// A pixel-size uncertainty out of range, or given twice, is refused in one line naming the flag
/// that gave it; nothing is written.
#[test]
fn a_wrong_pixel_size_uncertainty_is_refused_naming_its_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("a");
    let series = crate::common::fixture_series();
    let (series, out_s) = (series.to_str().unwrap(), out.to_str().unwrap());
    for (args, expected) in [
        (vec!["--pixel-size", "200nm±25%"], "--pixel-size: "),
        (
            vec!["--pixel-size-uncertainty", "30%"],
            "--pixel-size-uncertainty: ",
        ),
        (
            vec!["--pixel-size", "200nm±1%", "--pixel-size-uncertainty", "1%"],
            "given twice",
        ),
        (vec!["--pixel-size", "200nm±abc"], "--pixel-size"),
    ] {
        let mut all = vec!["analyze", series, "--out", out_s, "-q"];
        all.extend(args);
        let o = crate::common::run(&all);
        assert_eq!(o.status.code(), Some(1), "{all:?}");
        let err = crate::common::stderr(&o);
        assert!(err.contains(expected), "{all:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!out.exists());
    }
}
