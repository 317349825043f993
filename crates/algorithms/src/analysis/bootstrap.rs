//! Intervals on the area–load fits (`docs/methods.md`, "Fit intervals"): a bootstrap over the
//! images and over each image's area interval ([`super::interval`]).
//!
//! Each resample draws the images with replacement (Efron's nonparametric bootstrap: the scatter
//! of the points about the law) and gives each drawn image an area from its interval, lo +
//! u·(hi − lo) with u uniform on [0, 1] and drawn for each image on its own: the true area may lie
//! anywhere in the interval, and where it lies differs from image to image (the edge bias falls
//! with load as patches merge, so a shift shared by all images would miss the trend it gives β;
//! a shared and a per-image draw averaged half and half covered the true β in 75–97 % of
//! synthetic series, independent draws in 100 % of the calibration seeds). The power law and the
//! proportional law are refitted to each resample; the interval is the 2.5th and 97.5th
//! percentiles of the refitted values. The generator is seeded: the same inputs give the same
//! interval.
//!
//! The pixel size's calibration (a relative uncertainty u, taken as bounds: the true pixel size
//! lies within ±u of the stated one) is shared by every image of a series: each resample draws
//! one factor (1 + u·t)², t uniform on [−1, 1], and multiplies every area by it. It moves the
//! prefactor and the mean pressure; it cannot move the exponent.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::fit::{fit_power_law, fit_proportional};

/// Resamples of the bootstrap.
pub const RESAMPLES: usize = 2000;

/// Seed of the bootstrap's generator.
const SEED: u64 = 2018;

/// 95 % intervals on the fits' parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct FitIntervals {
    /// Exponent β of A = c·N^β.
    pub exponent: (f64, f64),
    /// Prefactor c, in the units of the areas and forces given.
    pub prefactor: (f64, f64),
    /// Slope s of A = s·N (the mean pressure is its inverse); `None` when no resample had one.
    pub proportional_slope: Option<(f64, f64)>,
    /// Resamples whose power law could be fitted.
    pub resamples: usize,
    /// Each such resample's (c, β), for the prefactor in other units ([`Self::prefactor_in`]).
    laws: Vec<(f64, f64)>,
}

impl FitIntervals {
    /// The prefactor's interval after `convert(c, β)` (e.g. from µm² per mN^β to m² per N^β:
    /// c·10⁻¹²·10^(3β), which depends on each resample's β).
    pub fn prefactor_in(&self, convert: impl Fn(f64, f64) -> f64) -> Option<(f64, f64)> {
        let mut v: Vec<f64> = self.laws.iter().map(|&(c, b)| convert(c, b)).collect();
        percentiles(&mut v)
    }
}

/// The intervals from `forces` and each image's area interval [`lo`, `hi`] (same units as the
/// fits; without the calibration), over the images given (the caller leaves out those the fits
/// leave out), and the pixel size's relative uncertainty `calibration` (0 for none). `None`
/// with fewer than three images or two distinct forces, or when too few resamples can be fitted.
pub fn fit_intervals(
    forces: &[f64],
    lo: &[f64],
    hi: &[f64],
    calibration: f64,
) -> Option<FitIntervals> {
    if lo.len() != forces.len() || hi.len() != forces.len() {
        return None;
    }
    resample(forces, calibration, |rng, _, i| {
        let u: f64 = rng.random();
        lo[i] + u * (hi[i] - lo[i])
    })
}

/// The intervals from `forces` and joint draws of the images' true areas (`draws[r][i]`: draw
/// r of image i, in the units of the fits, without the calibration; [`super::corrected`]):
/// resample r takes draw r mod the draws given, so that an error the draws share between loads
/// (the contact signal and its trend with load) moves the exponent as it moves the areas, and
/// draws the images with replacement. `None` as [`fit_intervals`], or for rows of another length.
pub fn joint_fit_intervals(
    forces: &[f64],
    draws: &[Vec<f64>],
    calibration: f64,
) -> Option<FitIntervals> {
    if draws.is_empty() || draws.iter().any(|d| d.len() != forces.len()) {
        return None;
    }
    resample(forces, calibration, |_, r, i| draws[r % draws.len()][i])
}

/// Resamples drawn, then refitted in parallel, at a time.
const CHUNK: usize = 250;

/// The bootstrap both intervals share: [`RESAMPLES`] resamples of the images with replacement,
/// image i of resample r given the area `area(rng, r, i)` times the resample's calibration
/// factor, each resample refitted.
fn resample(
    forces: &[f64],
    calibration: f64,
    mut area: impl FnMut(&mut ChaCha8Rng, usize, usize) -> f64,
) -> Option<FitIntervals> {
    let n = forces.len();
    if n < 3 {
        return None;
    }
    let mut distinct: Vec<f64> = forces.to_vec();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    if distinct.len() < 2 {
        return None;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    // The calibration's factors from a generator of their own: a pixel size's uncertainty
    // scales the same resamples instead of drawing others.
    let mut calibration_rng = ChaCha8Rng::seed_from_u64(SEED);
    calibration_rng.set_stream(1);
    let (mut exponents, mut prefactors, mut slopes) = (Vec::new(), Vec::new(), Vec::new());
    let mut laws = Vec::new();
    // The resamples are drawn in order from one generator (the same numbers on any number of
    // threads) and refitted in parallel, a chunk at a time.
    let (mut x, mut y) = (vec![0.0; n * CHUNK], vec![0.0; n * CHUNK]);
    for first in (0..RESAMPLES).step_by(CHUNK) {
        let count = CHUNK.min(RESAMPLES - first);
        for (j, (xs, ys)) in x
            .chunks_exact_mut(n)
            .zip(y.chunks_exact_mut(n))
            .take(count)
            .enumerate()
        {
            let scale = calibration_factor(&mut calibration_rng, calibration);
            for k in 0..n {
                let i = rng.random_range(0..n);
                xs[k] = forces[i];
                ys[k] = scale * area(&mut rng, first + j, i);
            }
        }
        let fits: Vec<_> = x
            .par_chunks_exact(n)
            .zip(y.par_chunks_exact(n))
            .take(count)
            .map(|(xs, ys)| (fit_power_law(xs, ys), fit_proportional(xs, ys)))
            .collect();
        for (law, proportional) in fits {
            if let Some(f) = law {
                exponents.push(f.exponent);
                prefactors.push(f.prefactor);
                laws.push((f.prefactor, f.exponent));
            }
            if let Some((s, _)) = proportional {
                slopes.push(s);
            }
        }
    }
    if exponents.len() < RESAMPLES / 2 {
        return None;
    }
    Some(FitIntervals {
        exponent: percentiles(&mut exponents)?,
        prefactor: percentiles(&mut prefactors)?,
        proportional_slope: percentiles(&mut slopes),
        resamples: laws.len(),
        laws,
    })
}

/// The factors on an area interval's ends from a pixel size known to within ±`u` (relative,
/// bounds): ((1 − u)², (1 + u)²). An interval on the true area is the band's ends times these.
pub fn calibration_bounds(u: f64) -> (f64, f64) {
    ((1.0 - u).powi(2), (1.0 + u).powi(2))
}

/// The factor on every area of one resample from a pixel size known to within ±`u` (relative):
/// (1 + u·t)², t uniform on [−1, 1]; exactly 1 when `u` is 0 (and no number is drawn).
pub fn calibration_factor(rng: &mut impl Rng, u: f64) -> f64 {
    if u > 0.0 {
        let t: f64 = rng.random_range(-1.0..=1.0);
        (1.0 + u * t).powi(2)
    } else {
        1.0
    }
}

/// The 2.5th and 97.5th percentiles (nearest rank).
pub fn percentiles(v: &mut [f64]) -> Option<(f64, f64)> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)];
    Some((at(0.025), at(0.975)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_points_with_point_intervals_give_the_exponent_itself() {
        let forces = [1.0, 2.0, 4.0, 8.0, 16.0];
        let areas: Vec<f64> = forces.iter().map(|f: &f64| 3.0 * f.powf(0.8)).collect();
        let i = fit_intervals(&forces, &areas, &areas, 0.0).unwrap();
        assert!((i.exponent.0 - 0.8).abs() < 1e-12 && (i.exponent.1 - 0.8).abs() < 1e-12);
        assert!((i.prefactor.0 - 3.0).abs() < 1e-9, "{i:?}");
    }

    #[test]
    fn area_intervals_widen_the_exponent_interval_around_the_truth() {
        // ±5 % intervals around a law with β = 0.8 (areas measured 2 % low at every load).
        let forces = [4.0, 6.0, 10.0, 16.0, 25.0, 40.0, 63.0, 100.0];
        let truth: Vec<f64> = forces.iter().map(|f: &f64| 10.0 * f.powf(0.8)).collect();
        let lo: Vec<f64> = truth.iter().map(|a| a * 0.93).collect();
        let hi: Vec<f64> = truth.iter().map(|a| a * 1.03).collect();
        let i = fit_intervals(&forces, &lo, &hi, 0.0).unwrap();
        assert!(i.exponent.0 < 0.8 && 0.8 < i.exponent.1, "{i:?}");
        assert!(i.exponent.1 - i.exponent.0 < 0.05, "{i:?}");
        assert!(i.prefactor.0 < 10.0 && 10.0 < i.prefactor.1, "{i:?}");
        let (s_lo, s_hi) = i.proportional_slope.unwrap();
        assert!(s_lo < s_hi);
        // In other units, converted resample by resample: the identity gives the same interval.
        assert_eq!(i.prefactor_in(|c, _| c), Some(i.prefactor));
        // Deterministic: the same inputs give the same interval.
        assert_eq!(fit_intervals(&forces, &lo, &hi, 0.0), Some(i));
    }

    #[test]
    fn too_few_images_give_no_interval() {
        assert_eq!(
            fit_intervals(&[1.0, 2.0], &[1.0, 2.0], &[1.0, 2.0], 0.0),
            None
        );
        assert_eq!(
            fit_intervals(&[2.0, 2.0, 2.0], &[1.0, 1.0, 1.0], &[2.0, 2.0, 2.0], 0.0),
            None
        );
    }

    #[test]
    fn a_shared_calibration_widens_the_prefactor_not_the_exponent() {
        let forces = [4.0, 6.0, 10.0, 16.0, 25.0, 40.0, 63.0, 100.0];
        let lo: Vec<f64> = forces.iter().map(|f: &f64| 9.5 * f.powf(0.8)).collect();
        let hi: Vec<f64> = forces.iter().map(|f: &f64| 10.5 * f.powf(0.8)).collect();
        let exact = fit_intervals(&forces, &lo, &hi, 0.0).unwrap();
        let calibrated = fit_intervals(&forces, &lo, &hi, 0.05).unwrap();
        let width = |(a, b): (f64, f64)| b - a;
        // ±5 % in the pixel size is about ±10 % in every area at once.
        assert!(
            width(calibrated.prefactor) > 1.5 * width(exact.prefactor),
            "{exact:?} {calibrated:?}"
        );
        assert!(calibrated.prefactor.0 < 9.5 && calibrated.prefactor.1 > 10.5);
        // A factor shared by all areas leaves the exponent where it was: the same resamples
        // (the factors come from a generator of their own), each scaled as a whole.
        assert!((calibrated.exponent.0 - exact.exponent.0).abs() < 1e-9);
        assert!((calibrated.exponent.1 - exact.exponent.1).abs() < 1e-9);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert_eq!(calibration_factor(&mut rng, 0.0), 1.0);
        for _ in 0..100 {
            let f = calibration_factor(&mut rng, 0.01);
            assert!((0.99f64.powi(2)..=1.01f64.powi(2)).contains(&f));
        }
    }

    #[test]
    fn joint_draws_trending_with_load_move_the_exponent() {
        // Each draw tilts the law by t ∈ [−0.05, 0.05] (a signal that trends with load): the
        // exponent's interval spans the tilts.
        let forces = [4.0, 6.0, 10.0, 16.0, 25.0, 40.0, 63.0, 100.0];
        let truth: Vec<f64> = forces.iter().map(|f: &f64| 10.0 * f.powf(0.8)).collect();
        let tilted: Vec<Vec<f64>> = (0..=200)
            .map(|k| {
                let t = -0.05 + 0.1 * k as f64 / 200.0;
                forces
                    .iter()
                    .zip(&truth)
                    .map(|(f, a)| a * (f / 20.0).powf(t))
                    .collect()
            })
            .collect();
        let i = joint_fit_intervals(&forces, &tilted, 0.0).unwrap();
        assert!(
            i.exponent.0 < 0.76 && i.exponent.1 > 0.84,
            "{:?}",
            i.exponent
        );
        assert!(
            i.exponent.0 > 0.74 && i.exponent.1 < 0.86,
            "{:?}",
            i.exponent
        );
        // One exact row: the bootstrap over the images alone gives the exponent itself.
        let exact = joint_fit_intervals(&forces, std::slice::from_ref(&truth), 0.0).unwrap();
        assert!((exact.exponent.0 - 0.8).abs() < 1e-12 && (exact.exponent.1 - 0.8).abs() < 1e-12);
        assert_eq!(joint_fit_intervals(&forces, &[vec![1.0, 2.0]], 0.0), None);
        assert_eq!(joint_fit_intervals(&forces, &[], 0.0), None);
    }
}
