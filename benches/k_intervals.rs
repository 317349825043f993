//! Coverage of the hardening coefficient's 95 % interval on synthetic truth (`docs/validation.md`,
//! B25, "k intervals"). `harness = false`.
//!
//! Each synthetic experiment is the reduced demo's (`contactscope demo --small`): a seeded rough
//! R = 50 µm sphere (96² px of 80 nm) pressed through four loads 0.05–0.35 mN with linear
//! hardening at the true k = 4 MPa/nm, each load's contact map rendered as a 12-bit micrograph
//! (48² px of 200 nm, the PSF and shot noise of the row), analysed as `analyze` does (one
//! global Otsu threshold, each area with its interval), and k fitted as `fit-hardening` fits it
//! on the demo (areas counted as imaged, a log grid of 5 then Brent to 2 % in ln k). Printed per
//! noise level and PSF: experiments, the fraction whose 95 % interval
//! ([`contactscope::model_fit::interval`]) holds the true k, its median relative width, the same
//! for k̂ ± 1.96·SE (the Gauss–Newton standard error alone), for the bootstrap over the loads
//! alone (no area intervals), the median relative error of k̂, and the same for the interval
//! drawn from each area's whole band (as for raw areas).
//!
//! ```sh
//! cargo bench --bench k_intervals                  # 100 seeds × 5 rows (about 12 min, 2 cores)
//! cargo bench --bench k_intervals -- --seeds 20 --first-seed 0     # the calibration seeds
//! ```
//!
//! Noise levels are detector counts per photon (4 is the demo's); PSF widths FWHM in nm (450 is
//! the demo's).

#[path = "support.rs"]
mod support;
use std::time::Instant;
use support::{arg, median};

use contactscope::model_fit::interval::parameter_interval;
use contactscope::model_fit::{fit_parameter, Family, Measured};
use contactscope_jobs::analyze::{run as analyze, AnalyzeRequest};
use contactscope_jobs::demo::{fit_search, imaging, model_body, synthetic_experiment, DemoParams};
use contactscope_jobs::series::{Micrographs, SeriesSpec};

/// One experiment's intervals on k, Pa/m: (with the area intervals, k̂ ± 1.96 SE, loads alone),
/// and k̂.
struct Outcome {
    full: Option<(f64, f64)>,
    se: Option<(f64, f64)>,
    loads_only: Option<(f64, f64)>,
    band: Option<(f64, f64)>,
    k: f64,
    /// Seconds of the fit (its interval included), and of one more interval's bootstrap.
    fit_s: f64,
    interval_s: f64,
}

fn experiment(p: &DemoParams, dir: &std::path::Path) -> Result<Outcome, String> {
    let e = |e: &dyn std::fmt::Display| e.to_string();
    let experiment = synthetic_experiment(p, dir, &|_| {}).map_err(|x| e(&x))?;
    let request = AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
        manifest: Some(experiment.manifest.clone()),
        ..SeriesSpec::default()
    }));
    let outcome = analyze(&request, &|_, _, _| {}, &|_, _, _| Ok(())).map_err(|x| e(&x))?;
    let measured = outcome.measured_curve().ok_or("no measured curve")?;
    let mut body = model_body(p, &experiment).map_err(|x| e(&x))?;
    body.imaging = Some(imaging(p));
    let search = fit_search(p, Family::Hardening);
    let started = Instant::now();
    let fit = fit_parameter(&body, Family::Hardening, &measured, search).map_err(|x| e(&x))?;
    let fit_s = started.elapsed().as_secs_f64();
    let k = fit.best.parameter.ok_or("no k")?;
    let loads_only = fit.sensitivities.as_ref().and_then(|j| {
        let points = Measured {
            intervals_m2: None,
            ..measured.clone()
        };
        parameter_interval(k.ln(), j, &fit.best.areas_m2, &points, true)
    });
    let started = Instant::now();
    let band = fit
        .sensitivities
        .as_ref()
        .and_then(|j| parameter_interval(k.ln(), j, &fit.best.areas_m2, &measured, false));
    let interval_s = started.elapsed().as_secs_f64();
    Ok(Outcome {
        full: fit.parameter_ci95,
        se: fit.parameter_se.map(|s| (k - 1.96 * s, k + 1.96 * s)),
        loads_only,
        band,
        k,
        fit_s,
        interval_s,
    })
}

fn main() {
    let seeds: u64 = arg("--seeds", 100);
    let first_seed: u64 = arg("--first-seed", 1000);
    let rows: [(f64, f64); 5] = [
        (1.0, 450.0),
        (4.0, 450.0),
        (16.0, 450.0),
        (4.0, 350.0),
        (4.0, 600.0),
    ];
    println!(
        "k intervals on synthetic truth (reduced demo, true k = 4 MPa/nm): {seeds} seeds per row from {first_seed}"
    );
    println!(
        "{:>13} {:>8} {:>5} {:>9} {:>8} {:>12} {:>9} {:>12} {:>9} {:>10} {:>12} {:>9}",
        "counts/photon",
        "PSF (nm)",
        "runs",
        "coverage",
        "width",
        "SE coverage",
        "SE width",
        "loads alone",
        "width",
        "median err",
        "whole band",
        "width"
    );
    let started = Instant::now();
    let (mut fit_s, mut interval_s) = (0.0, 0.0);
    let scratch = std::env::temp_dir().join(format!("k_intervals_{}", std::process::id()));
    for (counts, psf_nm) in rows {
        let (mut runs, mut errors) = (0usize, Vec::new());
        let mut hits = [0usize; 4];
        let mut widths: [Vec<f64>; 4] = Default::default();
        for seed in first_seed..first_seed + seeds {
            let p = DemoParams {
                seed,
                counts_per_photon: counts,
                psf_fwhm_m: psf_nm * 1e-9,
                ..DemoParams::reduced()
            };
            let truth = p.k_pa_per_m;
            let dir = scratch.join(format!("{seed}"));
            let outcome = match experiment(&p, &dir) {
                Ok(o) => o,
                Err(e) => {
                    eprintln!("seed {seed}: {e}");
                    continue;
                }
            };
            let _ = std::fs::remove_dir_all(&dir);
            runs += 1;
            fit_s += outcome.fit_s;
            interval_s += outcome.interval_s;
            errors.push((outcome.k / truth - 1.0).abs());
            for (i, interval) in [outcome.full, outcome.se, outcome.loads_only, outcome.band]
                .into_iter()
                .enumerate()
            {
                if let Some((lo, hi)) = interval {
                    hits[i] += usize::from(lo <= truth && truth <= hi);
                    widths[i].push((hi - lo) / truth);
                }
            }
        }
        let pct = |h: usize| 100.0 * h as f64 / runs.max(1) as f64;
        let [w0, w1, w2, w3] = widths;
        println!(
            "{counts:>13} {psf_nm:>8} {runs:>5} {:>8.1}% {:>7.1}% {:>11.1}% {:>8.1}% {:>11.1}% {:>8.1}% {:>9.1}% {:>11.1}% {:>8.1}%",
            pct(hits[0]),
            100.0 * median(w0),
            pct(hits[1]),
            100.0 * median(w1),
            pct(hits[2]),
            100.0 * median(w2),
            100.0 * median(errors),
            pct(hits[3]),
            100.0 * median(w3)
        );
    }
    let _ = std::fs::remove_dir_all(&scratch);
    println!(
        "{:.0} s; the fits took {:.1} s in all, the bootstrap of one interval {:.2} ms per fit",
        started.elapsed().as_secs_f64(),
        fit_s,
        1e3 * interval_s / rows.len() as f64 / seeds as f64
    );
}
