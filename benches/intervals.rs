//! Coverage of the per-image area intervals on synthetic truth (`docs/validation.md`, "Area
//! intervals"). `harness = false`.
//!
//! For every seed, noise level and PSF width, a synthetic load series
//! (`contactscope::synth::generate`: eight loads 4…100 mN on 256² px of 200 nm, the true
//! contact map known) is analysed as `analyze` analyses it — one global Otsu threshold, each
//! image measured — and each image's interval ([`area_band`], band half-width
//! [`EDGE_BAND_HALF_WIDTH`]) is checked against the true contact area. Printed per noise level
//! and PSF: images, the fraction of intervals holding the truth, the median relative width
//! (hi − lo)/truth, the median relative error of the measured area, and the fraction of
//! measured areas within their interval's half-width of the truth.
//!
//! ```sh
//! cargo bench --bench intervals                        # 100 seeds × 3 noise levels × 3 PSFs
//! cargo bench --bench intervals -- --seeds 20          # quicker
//! cargo bench --bench intervals -- --half-width 0.2    # another band
//! ```
//!
//! Noise levels are detector counts per photon (4 is the demo's: photon shot noise of about
//! 2·√I counts; 16 quadruples the variance); PSF widths are FWHM in nm (450 nm is the demo's).

#[path = "support.rs"]
mod support;
use contactscope::analysis::bootstrap::fit_intervals;
use contactscope::analysis::fit::fit_power_law;
use contactscope::analysis::interval::{area_band, EDGE_BAND_HALF_WIDTH, NOISE_WIDENING};
use contactscope::analysis::{analyze, AnalysisOptions};
use contactscope::image::Plane;
use contactscope::measure::Mask;
use contactscope::synth::{generate, SynthParams};
use std::sync::Mutex;
use support::{arg, median};

fn main() {
    let seeds: u64 = arg("--seeds", 100);
    let w: f64 = arg("--half-width", EDGE_BAND_HALF_WIDTH);
    let z: f64 = arg("--noise", NOISE_WIDENING);
    let first_seed: u64 = arg("--first-seed", 1000);
    println!("area intervals on synthetic truth: {seeds} seeds per row, band half-width {w}, noise widening {z}, seeds from {first_seed}");
    println!(
        "{:>12} {:>9} {:>7} {:>9} {:>13} {:>14} {:>11} {:>12}",
        "counts/photon",
        "PSF (nm)",
        "images",
        "coverage",
        "median width",
        "median |err|",
        "β coverage",
        "β width"
    );
    let started = std::time::Instant::now();
    // Time of the analyses (each computes the bands) and of the bands computed again alone.
    let (mut analysing, mut banding) = (0.0f64, 0.0f64);
    for counts_per_photon in [4.0, 16.0, 64.0] {
        for psf_nm in [300.0, 450.0, 600.0] {
            let mut covered = 0usize;
            let mut total = 0usize;
            let mut widths = Vec::new();
            let mut errors = Vec::new();
            let (mut beta_covered, mut beta_widths) = (0usize, Vec::new());
            for seed in 0..seeds {
                let params = SynthParams {
                    seed: first_seed + seed,
                    counts_per_photon,
                    psf_fwhm_m: psf_nm * 1e-9,
                    ..SynthParams::default()
                };
                let images = generate(&params).expect("synthetic series");
                let planes: Vec<Plane> = images
                    .iter()
                    .map(|i| Plane::from_u16(params.width, params.height, i.codes.clone()))
                    .collect();
                let masks: Mutex<Vec<Option<Mask>>> = Mutex::new(vec![None; planes.len()]);
                let t0 = std::time::Instant::now();
                let analysis = analyze(
                    planes.as_slice(),
                    &AnalysisOptions::default(),
                    &|_, _, _| {},
                    &|i, _, mask| {
                        masks.lock().unwrap()[i] = Some(mask.clone());
                        Ok(())
                    },
                )
                .expect("analysis");
                analysing += t0.elapsed().as_secs_f64();
                let masks = masks.into_inner().unwrap();
                let (mut lo, mut hi, mut truths) = (Vec::new(), Vec::new(), Vec::new());
                for ((plane, image), (mask, result)) in planes
                    .iter()
                    .zip(&images)
                    .zip(masks.iter().zip(&analysis.images))
                {
                    let t0 = std::time::Instant::now();
                    let band = area_band(plane, mask.as_ref().unwrap(), w, z);
                    banding += t0.elapsed().as_secs_f64();
                    let truth = image.true_contact_pixels as f64;
                    let measured = result.measurement.contact_pixels as f64;
                    total += 1;
                    if (band.lo_pixels as f64) <= truth && truth <= band.hi_pixels as f64 {
                        covered += 1;
                    }
                    widths.push((band.hi_pixels - band.lo_pixels) as f64 / truth);
                    errors.push((measured - truth).abs() / truth);
                    lo.push(band.lo_pixels as f64);
                    hi.push(band.hi_pixels as f64);
                    truths.push(truth);
                }
                // The exponent of the true areas against its bootstrap interval.
                let forces: Vec<f64> = images.iter().map(|i| i.force_n * 1e3).collect();
                let true_beta = fit_power_law(&forces, &truths).expect("law").exponent;
                if let Some(f) = fit_intervals(&forces, &lo, &hi, 0.0) {
                    if f.exponent.0 <= true_beta && true_beta <= f.exponent.1 {
                        beta_covered += 1;
                    }
                    beta_widths.push(f.exponent.1 - f.exponent.0);
                }
            }
            println!(
                "{:>12} {:>9} {:>7} {:>8.1}% {:>12.1}% {:>13.2}% {:>10.1}% {:>12.4}",
                counts_per_photon,
                psf_nm,
                total,
                100.0 * covered as f64 / total as f64,
                100.0 * median(widths),
                100.0 * median(errors),
                100.0 * beta_covered as f64 / seeds as f64,
                median(beta_widths)
            );
        }
    }
    println!(
        "{:.1} s; analyses {analysing:.2} s (bands included), the bands alone {banding:.2} s \
         (one thread)",
        started.elapsed().as_secs_f64()
    );
}
