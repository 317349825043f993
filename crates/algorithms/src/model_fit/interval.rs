//! The 95 % interval of a fitted model parameter (k of linear hardening, the penetration
//! hardness p_Y; `docs/methods.md`, "Fit intervals"): a bootstrap over the measured loads and
//! over each measured area's interval, each resample refitted on the linearisation of the model
//! at the optimum instead of by new simulations.
//!
//! Near the optimum p̂ the simulated areas follow ln A_sim,i(p) ≈ ln A_sim,i(p̂) + J_i·ln(p/p̂),
//! with J_i = ∂ ln A_sim,i/∂ ln p the sensitivities the standard error already needs (central
//! differences 5 % either side of p̂, two load ramps). The least-squares refit of a resample of
//! measured areas A*_i is then one Gauss–Newton step:
//! ln p* = ln p̂ + Σ J_i·ln(A*_i/A_sim,i(p̂)) / Σ J_i², the sums over the resampled loads.
//! Each resample draws the loads with replacement (the scatter of the points about the model,
//! which also carries what the model and the solver's discretisation get wrong) and gives each
//! drawn load an area lo + u·(hi − lo), u uniform on [0, 1] and independent per load (the
//! measured area's own uncertainty); with a pixel size known to within ±u, one factor
//! (1 + u·t)² shared by all loads ([`calibration_factor`]). The interval is the 2.5th and 97.5th
//! percentiles of p*.
//!
//! Which [lo, hi]: when the simulated areas are raw contact (g = 0), the measured area's whole
//! interval on the true area (`analyze`'s edge band and pixel noise). When they are counted as
//! imaged (blurred, resampled, thresholded like the micrographs), the model itself loses the
//! small patches the blur hides — the lower part of the band, up to a third of the area of a
//! small contact — so that part is not an uncertainty of the comparison; what is left is the
//! measured area's own scatter, taken as symmetric about it with the band's upper half-width
//! (the upper edge band and the pixel noise): [2A − hi, hi]. On synthetic truth (four loads,
//! seeds 0–19) the whole band covered the true k in 85–100 % of experiments with median widths
//! of 75–94 %, this symmetric one in 85–100 % with widths of 19–48 %; the held-out coverage is in
//! `docs/validation.md`, B25.
//!
//! Cost: no simulation beyond the fit's own, as a bootstrap with refits would need (a full
//! refit is a grid and a Brent search: about 15 load ramps, so 2000 resamples would take 30,000
//! ramps); the linearisation holds while ln A_sim is close to straight in ln p over the interval,
//! which the coverage on synthetic truth measures (`docs/validation.md`, B25).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::Measured;
use crate::analysis::bootstrap::{calibration_factor, percentiles, RESAMPLES};

/// Seed of the bootstrap's generator (the same inputs give the same interval).
const SEED: u64 = 2019;

/// The 95 % interval of a parameter fitted at `ln_best` (ln of its SI value), from the
/// sensitivities `jacobian` (J_i = ∂ ln A_sim,i/∂ ln p per measured load), the simulated areas
/// at the optimum `simulated_m2`, and the measured curve with its intervals (when it has them)
/// and its pixel size's uncertainty; `imaged`: the simulated areas are counted as imaged (the
/// intervals are then made symmetric with their upper half-width, module docs). `None` with
/// fewer than two loads, sizes that do not match, or sensitivities that are all zero.
pub fn parameter_interval(
    ln_best: f64,
    jacobian: &[f64],
    simulated_m2: &[f64],
    measured: &Measured,
    imaged: bool,
) -> Option<(f64, f64)> {
    let n = measured.areas_m2.len();
    if n < 2 || jacobian.len() != n || simulated_m2.len() != n {
        return None;
    }
    if jacobian.iter().all(|&j| j == 0.0) || jacobian.iter().any(|j| !j.is_finite()) {
        return None;
    }
    // A load without simulated contact counts as a hundredth of its measured area, as in the
    // misfit ([`Measured::misfit`]).
    let simulated: Vec<f64> = simulated_m2
        .iter()
        .zip(&measured.areas_m2)
        .map(|(&s, &a)| s.max(0.01 * a))
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let mut refits = Vec::with_capacity(RESAMPLES);
    for _ in 0..RESAMPLES {
        let scale = calibration_factor(&mut rng, measured.pixel_size_uncertainty);
        let (mut jr, mut jj) = (0.0, 0.0);
        for _ in 0..n {
            let i = rng.random_range(0..n);
            let u: f64 = rng.random();
            let area = match &measured.intervals_m2 {
                Some(intervals) => {
                    let (lo, hi) = intervals[i];
                    let lo = match imaged {
                        true => (2.0 * measured.areas_m2[i] - hi).max(0.0),
                        false => lo,
                    };
                    lo + u * (hi - lo)
                }
                None => measured.areas_m2[i],
            };
            // An interval reaching 0 at a load: the drawn area is floored as the misfit floors
            // a simulated one.
            let area = (scale * area).max(0.01 * measured.areas_m2[i]);
            jr += jacobian[i] * (area / simulated[i]).ln();
            jj += jacobian[i] * jacobian[i];
        }
        if jj > 0.0 {
            refits.push((ln_best + jr / jj).exp());
        }
    }
    if refits.len() < RESAMPLES / 2 {
        return None;
    }
    percentiles(&mut refits)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A model whose areas fall as p^(−1/2) (more hardening, less area), at 6 loads.
    fn model(p: f64, forces: &[f64]) -> Vec<f64> {
        forces
            .iter()
            .map(|f| 1e-10 * f.powf(0.8) * p.powf(-0.5))
            .collect()
    }

    #[test]
    fn exact_areas_with_point_intervals_give_the_parameter_itself() {
        let forces = [1e-3, 2e-3, 4e-3, 8e-3, 16e-3, 32e-3];
        let areas = model(4.0, &forces);
        let measured = Measured::with_intervals(
            forces
                .iter()
                .zip(&areas)
                .map(|(&f, &a)| (f, a, a, a))
                .collect(),
            0.0,
        )
        .unwrap();
        let (lo, hi) = parameter_interval(4f64.ln(), &[-0.5; 6], &areas, &measured, false).unwrap();
        assert!(
            (lo - 4.0).abs() < 1e-9 && (hi - 4.0).abs() < 1e-9,
            "{lo} {hi}"
        );
    }

    #[test]
    fn intervals_holding_the_truth_give_a_parameter_interval_holding_it() {
        // 200 synthetic experiments: each measured area off the truth by up to ±6 % (uniform),
        // its interval ±8 % about the measured value (so it holds the truth); the parameter
        // fitted by least squares in log area (exact for this model: the mean log ratio / J).
        let forces = [1e-3, 2e-3, 4e-3, 8e-3, 16e-3, 32e-3];
        let truth = 4.0;
        let exact = model(truth, &forces);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let (mut covered, mut widths) = (0, Vec::new());
        for _ in 0..200 {
            let measured_areas: Vec<f64> = exact
                .iter()
                .map(|a| a * (1.0 + rng.random_range(-0.06..0.06)))
                .collect();
            let mean_log: f64 = measured_areas
                .iter()
                .zip(&exact)
                .map(|(m, e)| (m / e).ln())
                .sum::<f64>()
                / 6.0;
            let ln_best = truth.ln() + mean_log / -0.5;
            let simulated = model(ln_best.exp(), &forces);
            let measured = Measured::with_intervals(
                forces
                    .iter()
                    .zip(&measured_areas)
                    .map(|(&f, &a)| (f, a, a * 0.92, a * 1.08))
                    .collect(),
                0.0,
            )
            .unwrap();
            let (lo, hi) =
                parameter_interval(ln_best, &[-0.5; 6], &simulated, &measured, false).unwrap();
            assert!(lo < ln_best.exp() && ln_best.exp() < hi);
            covered += usize::from(lo <= truth && truth <= hi);
            widths.push((hi - lo) / truth);
        }
        assert!(covered >= 180, "{covered} of 200");
        widths.sort_by(f64::total_cmp);
        // ±8 % intervals on areas falling as p^−½ are about ±16 % on p at one load; six loads
        // and independent draws narrow it.
        assert!(widths[100] > 0.05 && widths[100] < 0.4, "{}", widths[100]);
    }

    #[test]
    fn a_shared_calibration_widens_the_interval() {
        let forces = [1e-3, 2e-3, 4e-3, 8e-3];
        let areas = model(4.0, &forces);
        let points = |_: ()| -> Vec<(f64, f64, f64, f64)> {
            forces
                .iter()
                .zip(&areas)
                .map(|(&f, &a)| (f, a, 0.97 * a, 1.03 * a))
                .collect()
        };
        let j = [-0.5; 4];
        let exact = Measured::with_intervals(points(()), 0.0).unwrap();
        let calibrated = Measured::with_intervals(points(()), 0.02).unwrap();
        let a = parameter_interval(4f64.ln(), &j, &areas, &exact, false).unwrap();
        let b = parameter_interval(4f64.ln(), &j, &areas, &calibrated, false).unwrap();
        assert!(b.1 - b.0 > 1.5 * (a.1 - a.0), "{a:?} {b:?}");
        // Counted as imaged, the interval's lower part (here 3 %, as the upper) is kept as is;
        // an interval reaching far below the area is cut to the upper half-width.
        assert_eq!(
            parameter_interval(4f64.ln(), &j, &areas, &exact, true),
            Some(a)
        );
        let lopsided = Measured::with_intervals(
            forces
                .iter()
                .zip(&areas)
                .map(|(&f, &a)| (f, a, 0.6 * a, 1.03 * a))
                .collect(),
            0.0,
        )
        .unwrap();
        assert_eq!(
            parameter_interval(4f64.ln(), &j, &areas, &lopsided, true),
            Some(a)
        );
        let raw = parameter_interval(4f64.ln(), &j, &areas, &lopsided, false).unwrap();
        assert!(raw.1 > 2.0 * a.1 - 4.0, "{raw:?} {a:?}");
        // Flat sensitivities, or too few loads: no interval.
        assert_eq!(
            parameter_interval(0.0, &[0.0; 4], &areas, &exact, false),
            None
        );
        assert_eq!(
            parameter_interval(0.0, &j[..3], &areas, &exact, false),
            None
        );
        // An interval that does not hold its area, a calibration of 50 % or more: refused.
        assert!(
            Measured::with_intervals(vec![(1.0, 2.0, 2.5, 3.0), (2.0, 3.0, 3.0, 3.0)], 0.0)
                .is_err()
        );
        assert!(Measured::with_intervals(points(()), 0.5).is_err());
    }
}
