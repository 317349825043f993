//! Coverage of the corrected areas' 95 % intervals and of the exponent's interval on two
//! generators of truth (`docs/validation.md`, B25 "Area intervals"). `harness = false`.
//!
//! * **series**: `contactscope::synth::generate` (eight loads 4–100 mN, 256² px of 200 nm or
//!   512² px of 100 nm, the true contact map known), its patches scaled by 0.25 (below the PSF),
//!   0.6 (the PSF's size) and 2.0 (coarse), with 3 counts of read noise.
//! * **solved**: `contactscope::synth::solved` (written apart from the intervals): contacts the
//!   solver makes of a rough sphere at the paper's pressures (elastic, hardness, hardening by the
//!   seed), the mask on a 50 nm grid blurred there and area-averaged to the camera's pixels,
//!   Poisson and read noise, 12-bit codes; patch scales sub-PSF, PSF-sized and coarse, and the
//!   `cloud` stress case (sub-PSF patches at every load, outside the paper's regime). Solved ramps
//!   are cached in `--cache` (default `target/solved-ramps`): the first run solves them.
//!
//! Every series is analysed as `analyze` does it when every image has a light budget (the edge
//! band's coverage is `benches/intervals.rs`) — one global Otsu threshold, each image measured
//! with its light budget, the series' corrected areas drawn jointly ([`correct_series`]), the
//! exponent's interval by the bootstrap over those draws
//! ([`joint_fit_intervals`]) — with the PSF given. Printed per generator, scale and cell (PSF FWHM,
//! pixel, photons at contact): series, and per load rank (the two lightest loads, the middle
//! four, the two heaviest) the share of intervals holding the true area and their median
//! relative width, the median error of the pixel count and of the corrected area; then the share
//! of exponent intervals holding the true areas' exponent, their median width, and how many
//! series have the corrected exponent (the estimate) and the pixel count's exponent outside the
//! interval; last, the range over the series of the reference interior's top reading over its
//! mean (how flat the interior that sets the signal reads: a glow of sub-PSF patches follows the
//! pressure; `docs/validation.md` B25, "A glow instead of an interior").
//!
//! ```sh
//! cargo bench --bench light_intervals                    # 20 series per cell, both generators
//! cargo bench --bench light_intervals -- --seeds 40 --only series
//! cargo bench --bench light_intervals -- --only solved --seeds 20
//! # a part of the table: scales by name (series: sub-PSF, PSF-sized, coarse; solved: sub_psf,
//! # psf_sized, coarse, cloud), PSF FWHMs in nm, and seeds from 20 on (held out)
//! cargo bench --bench light_intervals -- --only solved --scales sub_psf --psfs 600,750 --first-seed 20
//! # one cell, every image whose interval misses its truth printed
//! cargo bench --bench light_intervals -- --only solved --scales sub_psf --psfs 600 --pixels 100 --photons 20 --misses
//! ```

#[path = "support.rs"]
mod support;
use std::path::{Path, PathBuf};

use contactscope::analysis::bootstrap::joint_fit_intervals;
use contactscope::analysis::corrected::{correct_series, Assumptions, SignalSource};
use contactscope::analysis::fit::fit_power_law;
use contactscope::analysis::{analyze, AnalysisOptions};
use contactscope::image::{PixelSize, PixelSizeSource, Plane};
use contactscope::optics::blur::FWHM_PER_SIGMA;
use contactscope::synth::solved::{
    image_ramp, solve_ramp, Camera, ContactRamp, PatchScale, RampSpec,
};
use contactscope::synth::{generate, SynthParams};
use rayon::prelude::*;
use support::{arg, median};

const PSFS_NM: [f64; 4] = [300.0, 450.0, 600.0, 750.0];
const PIXELS_NM: [f64; 2] = [100.0, 200.0];
const PHOTONS: [f64; 3] = [20.0, 100.0, 500.0];
const RANKS: [&str; 3] = ["lightest 2", "middle", "heaviest 2"];

/// One series: its images (codes, forces, true areas in pixels).
struct Series {
    width: usize,
    height: usize,
    codes: Vec<Vec<u16>>,
    forces_n: Vec<f64>,
    truth_px: Vec<f64>,
}

/// What one series gave.
#[derive(Default, Clone)]
struct Tally {
    series: usize,
    images: [usize; 3],
    covered: [usize; 3],
    widths: [Vec<f64>; 3],
    pixel_err: [Vec<f64>; 3],
    corrected_err: [Vec<f64>; 3],
    beta_series: usize,
    beta_covered: usize,
    beta_widths: Vec<f64>,
    estimate_outside: usize,
    pixel_beta_outside: usize,
    /// Images whose signal rests on the bounds alone (no interior in the series), and how many
    /// of their intervals held the truth.
    bounds_images: usize,
    bounds_covered: usize,
    /// Series with corrected areas but without any interior.
    bounds_series: usize,
    /// Per series with a reading: its reference interior's top reading over its mean.
    top_over_mean: Vec<f64>,
}

impl Tally {
    fn add(&mut self, other: Tally) {
        self.series += other.series;
        for r in 0..3 {
            self.images[r] += other.images[r];
            self.covered[r] += other.covered[r];
            self.widths[r].extend(&other.widths[r]);
            self.pixel_err[r].extend(&other.pixel_err[r]);
            self.corrected_err[r].extend(&other.corrected_err[r]);
        }
        self.beta_series += other.beta_series;
        self.beta_covered += other.beta_covered;
        self.beta_widths.extend(other.beta_widths);
        self.estimate_outside += other.estimate_outside;
        self.pixel_beta_outside += other.pixel_beta_outside;
        self.bounds_images += other.bounds_images;
        self.bounds_covered += other.bounds_covered;
        self.bounds_series += other.bounds_series;
        self.top_over_mean.extend(other.top_over_mean);
    }

    fn coverage(&self, r: usize) -> f64 {
        100.0 * self.covered[r] as f64 / self.images[r].max(1) as f64
    }
}

fn rank(k: usize, n: usize) -> usize {
    if k < 2 {
        0
    } else if k + 2 >= n {
        2
    } else {
        1
    }
}

/// Analyse one series as `analyze` does and score it against its truth.
fn score(s: &Series, sigma_px: f64, pixel_m: f64, label: &str) -> Tally {
    let planes: Vec<Plane> = s
        .codes
        .iter()
        .map(|c| Plane::from_u16(s.width, s.height, c.clone()))
        .collect();
    let options = AnalysisOptions {
        psf_sigma_px: Some(sigma_px),
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
    .expect("the analysis");
    let forces: Vec<Option<f64>> = s.forces_n.iter().map(|&f| Some(f)).collect();
    let correction = correct_series(&analysis, &forces, Assumptions::default());
    let n = s.codes.len();
    let mut t = Tally {
        series: 1,
        ..Tally::default()
    };
    for k in 0..n {
        let truth = s.truth_px[k];
        if truth <= 0.0 {
            continue;
        }
        let r = rank(k, n);
        t.images[r] += 1;
        let pixels = analysis.images[k].measurement.contact_pixels as f64;
        t.pixel_err[r].push(pixels / truth - 1.0);
        match correction.areas[k] {
            Some(c) => {
                let held = c.lo_px <= truth && truth <= c.hi_px;
                if !held && show_misses() {
                    eprintln!(
                        "miss {label} image {k}: truth {truth:.0} px, interval [{:.0}, {:.0}], corrected {:.0} ({:?}, signal {:.0}), pixel count {pixels:.0}",
                        c.lo_px, c.hi_px, c.area_px, c.source, c.signal
                    );
                }
                t.covered[r] += usize::from(held);
                if c.source == SignalSource::Bounds {
                    t.bounds_images += 1;
                    t.bounds_covered += usize::from(held);
                }
                t.widths[r].push((c.hi_px - c.lo_px) / truth);
                t.corrected_err[r].push(c.area_px / truth - 1.0);
            }
            None => t.widths[r].push(f64::INFINITY),
        }
    }
    if let Some(r) = correction.model.reference_interior() {
        t.top_over_mean.push(r.top_over_mean);
    }
    let read: Vec<_> = correction.areas.iter().flatten().collect();
    t.bounds_series =
        usize::from(!read.is_empty() && read.iter().all(|c| c.source == SignalSource::Bounds));
    let true_beta = fit_power_law(&s.forces_n, &s.truth_px).map(|f| f.exponent);
    if let (Some(true_beta), Some(i)) = (
        true_beta,
        joint_fit_intervals(&s.forces_n, &correction.draws, 0.0),
    ) {
        let (lo, hi) = i.exponent;
        t.beta_series = 1;
        t.beta_covered = usize::from(lo <= true_beta && true_beta <= hi);
        t.beta_widths.push(hi - lo);
        let corrected: Vec<f64> = correction
            .areas
            .iter()
            .map(|c| c.map_or(f64::NAN, |c| c.area_px))
            .collect();
        let outside = |b: Option<f64>| b.is_none_or(|b| b < lo || b > hi);
        t.estimate_outside = usize::from(outside(
            fit_power_law(&s.forces_n, &corrected).map(|f| f.exponent),
        ));
        let pixels: Vec<f64> = analysis
            .images
            .iter()
            .map(|r| r.measurement.contact_pixels as f64)
            .collect();
        t.pixel_beta_outside = usize::from(outside(
            fit_power_law(&s.forces_n, &pixels).map(|f| f.exponent),
        ));
    }
    t
}

fn row(cell: &str, t: &Tally) -> String {
    let pct = |v: &Vec<f64>| 100.0 * median(v.clone());
    let mut line = format!("| {cell} | {} |", t.series);
    for r in 0..3 {
        line += &format!(" {:.1} |", t.coverage(r));
    }
    for r in 0..3 {
        line += &format!(" {:.1} |", pct(&t.widths[r]));
    }
    for r in 0..3 {
        line += &format!(
            " {:+.1} / {:+.1} |",
            pct(&t.pixel_err[r]),
            pct(&t.corrected_err[r])
        );
    }
    line += &format!(
        " {:.1} | {:.3} | {} | {} |",
        100.0 * t.beta_covered as f64 / t.beta_series.max(1) as f64,
        median(t.beta_widths.clone()),
        t.estimate_outside,
        t.pixel_beta_outside
    );
    let lowest = t
        .top_over_mean
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let highest = t
        .top_over_mean
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    if t.top_over_mean.is_empty() {
        line += " — |";
    } else {
        line += &format!(" {lowest:.3}…{highest:.3} |");
    }
    line
}

fn header(title: &str) {
    println!("\n### {title}\n");
    println!(
        "| PSF nm, px nm, photons | series | cover {} % | cover {} % | cover {} % | width {} % | width {} % | width {} % | err px / corr {} % | err px / corr {} % | err px / corr {} % | β cover % | β width | β̂ out | β_px out | reference top/mean |",
        RANKS[0], RANKS[1], RANKS[2], RANKS[0], RANKS[1], RANKS[2], RANKS[0], RANKS[1], RANKS[2]
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
}

/// Score every cell of one scale; `make(psf, px, photons, seed)` gives a series.
fn table(
    title: &str,
    seeds: std::ops::Range<u64>,
    make: &(dyn Fn(f64, f64, f64, u64) -> Series + Sync),
) -> Vec<(String, Tally)> {
    header(title);
    let mut all = Vec::new();
    let mut pooled = Tally::default();
    let psfs = list("--psfs", &PSFS_NM);
    for psf in psfs {
        for px in list("--pixels", &PIXELS_NM) {
            for photons in list("--photons", &PHOTONS) {
                let tallies: Vec<Tally> = seeds
                    .clone()
                    .into_par_iter()
                    .map(|seed| {
                        let s = make(psf, px, photons, seed);
                        let label =
                            format!("{title} ({psf:.0}, {px:.0}, {photons:.0}) seed {seed}");
                        score(&s, psf / FWHM_PER_SIGMA / px, px * 1e-9, &label)
                    })
                    .collect();
                let mut t = Tally::default();
                for x in tallies {
                    t.add(x);
                }
                let cell = format!("{psf:.0}, {px:.0}, {photons:.0}");
                println!("{}", row(&cell, &t));
                pooled.add(t.clone());
                all.push((format!("{title}: {cell}"), t));
            }
        }
    }
    println!("{}", row("**all cells**", &pooled));
    println!(
        "\nSeries with corrected areas but no contact interior (the signal bounded only): {} of {}; their \
         images' intervals held the truth in {} of {} ({:.1} %); the other images: {:.1} %",
        pooled.bounds_series,
        pooled.series,
        pooled.bounds_covered,
        pooled.bounds_images,
        100.0 * pooled.bounds_covered as f64 / pooled.bounds_images.max(1) as f64,
        {
            let images: usize = pooled.images.iter().sum::<usize>() - pooled.bounds_images;
            let covered: usize = pooled.covered.iter().sum::<usize>() - pooled.bounds_covered;
            100.0 * covered as f64 / images.max(1) as f64
        }
    );
    all
}

fn series_generator(scale: f64, psf: f64, px: f64, photons: f64, seed: u64) -> Series {
    let size = if px < 150.0 { 512 } else { 256 };
    let params = SynthParams {
        width: size,
        height: size,
        pixel_size_m: px * 1e-9,
        seed: 5000 + seed,
        counts_per_photon: 1800.0 / photons,
        psf_fwhm_m: psf * 1e-9,
        patch_scale: scale,
        read_noise_counts: 3.0,
        ..SynthParams::default()
    };
    let images = generate(&params).expect("a synthetic series");
    Series {
        width: size,
        height: size,
        codes: images.iter().map(|i| i.codes.clone()).collect(),
        forces_n: images.iter().map(|i| i.force_n).collect(),
        truth_px: images
            .iter()
            .map(|i| i.true_contact_pixels as f64)
            .collect(),
    }
}

fn ramp(cache: &Path, scale: Option<PatchScale>, seed: u64) -> ContactRamp {
    let path = cache.join(format!(
        "{}-{seed}.bin",
        scale.map_or("cloud", |s| s.name())
    ));
    if let Ok(bytes) = std::fs::read(&path) {
        if let Ok(r) = ContactRamp::decode(&bytes) {
            return r;
        }
    }
    let spec = match scale {
        Some(s) => RampSpec::paper(s, seed),
        None => RampSpec::cloud(seed),
    };
    let r = solve_ramp(&spec).expect("a solved ramp");
    std::fs::create_dir_all(cache).expect("the cache folder");
    std::fs::write(&path, r.encode()).expect("the cached ramp");
    r
}

fn solved_generator(r: &ContactRamp, psf: f64, px: f64, photons: f64) -> Series {
    let camera = Camera::new(px * 1e-9, psf * 1e-9, photons, 7 + r.spec.seed);
    let images = image_ramp(r, &camera).expect("the imaged ramp");
    Series {
        width: images[0].width,
        height: images[0].height,
        codes: images.iter().map(|i| i.codes.clone()).collect(),
        forces_n: images.iter().map(|i| i.force_n).collect(),
        truth_px: images.iter().map(|i| i.true_area_px).collect(),
    }
}

/// The numbers after `name` (`--psfs 600,750`), else `all`.
fn list(name: &str, all: &[f64]) -> Vec<f64> {
    let given: String = arg(name, String::new());
    let v: Vec<f64> = given
        .split(',')
        .filter_map(|x| x.trim().parse().ok())
        .collect();
    if v.is_empty() {
        all.to_vec()
    } else {
        v
    }
}

/// Whether `--misses` was given: every image whose interval misses its truth is printed.
fn show_misses() -> bool {
    std::env::args().any(|a| a == "--misses")
}

/// Whether the scale named `name` was asked for (`--scales sub_psf,coarse`; all by default).
fn wanted(name: &str) -> bool {
    let given: String = arg("--scales", String::new());
    given.is_empty() || given.split(',').any(|x| x.trim() == name)
}

fn main() {
    let count: u64 = arg("--seeds", 20);
    let first: u64 = arg("--first-seed", 0);
    let seeds = first..first + count;
    let only: String = arg("--only", String::from("both"));
    let cache: PathBuf = arg("--cache", PathBuf::from("target/solved-ramps"));
    let started = std::time::Instant::now();
    println!(
        "area and exponent intervals on two generators: seeds {seeds:?} per cell, assumptions {:?}",
        Assumptions::default()
    );
    let mut cells = Vec::new();
    if only != "solved" {
        for (scale, name) in [(0.25, "sub-PSF"), (0.6, "PSF-sized"), (2.0, "coarse")] {
            if !wanted(name) {
                continue;
            }
            let title = format!("series generator, {name} patches (scale {scale})");
            cells.extend(table(&title, seeds.clone(), &|psf, px, ph, seed| {
                series_generator(scale, psf, px, ph, seed)
            }));
        }
    }
    if only != "series" {
        for scale in [
            Some(PatchScale::SubPsf),
            Some(PatchScale::PsfSized),
            Some(PatchScale::Coarse),
            None,
        ] {
            if !wanted(scale.map_or("cloud", |s| s.name())) {
                continue;
            }
            let ramps: Vec<ContactRamp> = seeds
                .clone()
                .into_par_iter()
                .map(|seed| ramp(&cache, scale, seed))
                .collect();
            let title = match scale {
                Some(s) => format!("solved generator, paper preset, {} patches", s.name()),
                None => "solved generator, cloud preset (stress case, not carried)".to_string(),
            };
            let found = table(&title, seeds.clone(), &|psf, px, ph, seed| {
                solved_generator(&ramps[(seed - first) as usize], psf, px, ph)
            });
            if scale.is_some() {
                cells.extend(found);
            }
        }
    }
    println!("\n### Cells outside 90–99 % (any load rank), β below 90 %\n");
    let mut flagged = 0;
    for (cell, t) in &cells {
        let ranks: Vec<String> = (0..3)
            .filter(|&r| t.images[r] > 0 && !(90.0..=99.0).contains(&t.coverage(r)))
            .map(|r| format!("{} {:.1} %", RANKS[r], t.coverage(r)))
            .collect();
        let beta = 100.0 * t.beta_covered as f64 / t.beta_series.max(1) as f64;
        if !ranks.is_empty() || beta < 90.0 {
            flagged += 1;
            println!("- {cell}: {} β {beta:.1} %", ranks.join(", "));
        }
    }
    println!(
        "\n{flagged} of {} cells flagged; {:.0} s",
        cells.len(),
        started.elapsed().as_secs_f64()
    );
}
