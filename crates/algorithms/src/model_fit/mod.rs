//! Fitting contact models to a measured area–load curve (Weber et al. 2018, Fig. 3a and
//! Supplementary Fig. 8: only linear hardening with k ≈ 4 MPa/nm reproduces the sublinear measured
//! curve; the elastic, penetration-hardness and Greenwood–Tripp models do not).
//!
//! Misfit: the RMS over the measured loads of ln(A_sim/A_exp) (least squares in log area, so every
//! load counts alike whatever its area). One-parameter models (hardening k with p_Y0 = 0, as the
//! paper; penetration hardness p_Y) are fitted by a log-spaced grid evaluated in parallel, then
//! Brent's method (`argmin`) on ln(parameter) around the best grid point. The standard error comes from
//! the Gauss–Newton approximation at the optimum: var(ln p) = s²/ΣJ², with J = ∂ ln A_sim/∂ ln p by
//! central differences and s² = Σr²/(n − 1); the 95 % interval by a bootstrap on the same
//! linearisation ([`interval`]). The parameter-free models (elastic, GT) are evaluated
//! once. Hardening and hardness runs load in increasing force order, carrying the plastic
//! deformation from load to load, as an experiment's load ramp does.

pub mod interval;

use std::sync::{Arc, Mutex};

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::brent::BrentOpt;

use rayon::prelude::*;

use crate::analysis::bootstrap::calibration_bounds;
use crate::error::{Error, Result};
use crate::optics::blur::{microscope_image, Grid};
use crate::solver::cg::SolverOptions;
use crate::solver::gt::{gt_bearing_area, gt_profile, GtParams};
use crate::solver::halfspace::Boundary;
use crate::solver::simulate::{sweep_each, Model, Setup};
use crate::surface::stats::SurfaceStats;
use crate::surface::Topography;
use crate::threshold::otsu_of_values;

/// A model family as fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// Linear elastic half-space, hard wall.
    Elastic,
    /// Greenwood–Tripp bearing area.
    GreenwoodTripp,
    /// Penetration hardness p_Y (fitted).
    Hardness,
    /// Linear hardening p_Y = k·h_pl (k fitted).
    Hardening,
}

impl Family {
    /// All four, in the order of the paper's Fig. 3a legend.
    pub const ALL: [Family; 4] = [
        Family::GreenwoodTripp,
        Family::Elastic,
        Family::Hardness,
        Family::Hardening,
    ];

    /// Name used in outputs and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Family::Elastic => "elastic",
            Family::GreenwoodTripp => "gt",
            Family::Hardness => "hardness",
            Family::Hardening => "hardening",
        }
    }

    /// Parse a name as [`Family::name`] gives it.
    pub fn parse(text: &str) -> Result<Self> {
        Family::ALL
            .into_iter()
            .find(|f| f.name() == text.trim())
            .ok_or_else(|| Error::UnknownName {
                what: "model",
                name: text.to_string(),
                choices: "elastic, gt, hardness or hardening",
            })
    }

    /// Whether the family has a fitted parameter.
    pub fn has_parameter(self) -> bool {
        matches!(self, Family::Hardness | Family::Hardening)
    }
}

/// One evaluated model at the measured loads.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Parameter (Pa for hardness, Pa/m for hardening), `None` for parameter-free models.
    pub parameter: Option<f64>,
    /// Simulated contact areas, m², in the order of the measured loads.
    pub areas_m2: Vec<f64>,
    /// RMS of ln(A_sim/A_exp).
    pub misfit: f64,
    /// Contact maps (1 = contact), row-major as the topography, when kept.
    pub maps: Option<Vec<Vec<f64>>>,
    /// Some load's contact reaches the border of a free map (the result is then not valid).
    pub edge_contact: bool,
}

/// Simulated areas at the measured loads, the contact maps when kept, and whether any contact
/// reached the map's border.
pub type ModelAreas = (Vec<f64>, Option<Vec<Vec<f64>>>, bool);

/// A fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelFit {
    /// The family.
    pub family: Family,
    /// The best evaluation.
    pub best: Evaluation,
    /// Standard error of the parameter (same unit), when it can be estimated.
    pub parameter_se: Option<f64>,
    /// 95 % interval of the parameter (same unit) from the measured areas' intervals and the
    /// scatter about the fit ([`interval::parameter_interval`]), when it can be estimated.
    pub parameter_ci95: Option<(f64, f64)>,
    /// J_i = ∂ ln A_sim,i/∂ ln p at the optimum per measured load (central differences 5 %
    /// either side), when they could be computed: what the standard error and the interval
    /// are made from.
    pub sensitivities: Option<Vec<f64>>,
    /// Every (parameter, misfit) evaluated, in order of evaluation.
    pub trace: Vec<(f64, f64)>,
    /// The optimum lies at an end of the search range.
    pub at_range_edge: bool,
    /// The simulated areas do not change when the parameter moves 5 % either way from its best
    /// value (no pixel is near the yield condition, say): the misfit is flat there, the value is
    /// not determined by the data and has no standard error.
    pub undetermined: bool,
}

/// What [`ModelBody`] reports after each load of a ramp it runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RampEvent {
    /// The model.
    pub family: Family,
    /// Its parameter (SI: Pa for hardness, Pa/m for k), if it has one.
    pub parameter: Option<f64>,
    /// Loads solved so far in this ramp.
    pub load: usize,
    /// Loads in the ramp.
    pub loads: usize,
}

/// A callback hearing of every solved load ([`ModelBody::progress`]). Evaluations run in
/// parallel, so it must be `Send + Sync`; events of different ramps interleave.
#[derive(Clone)]
pub struct ProgressHook(pub Arc<dyn Fn(&RampEvent) + Send + Sync>);

impl std::fmt::Debug for ProgressHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgressHook")
    }
}

/// The rough sphere and material the models are run on.
#[derive(Debug, Clone)]
pub struct ModelBody {
    /// Roughness after detrending (for GT and its statistics).
    pub roughness: Topography,
    /// The rigid body for the half-space models (roughness plus sphere, or as given).
    pub body: Topography,
    /// Roughness statistics (GT inputs).
    pub stats: SurfaceStats,
    /// Sphere radius, m (needed for GT).
    pub radius_m: Option<f64>,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// Periodic boundaries (free otherwise).
    pub periodic: bool,
    /// CG limits.
    pub options: SolverOptions<'static>,
    /// Count simulated areas as the microscope would see them (blur, resample, threshold), so
    /// they compare like with like with areas measured on micrographs; raw g = 0 areas otherwise.
    pub imaging: Option<Imaging>,
    /// Told of every load solved (progress bars).
    pub progress: Option<ProgressHook>,
}

/// How simulated maps are imaged before their area is counted (docs/methods.md §7.1: apply the same
/// blur-and-threshold procedure to simulated maps as to micrographs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Imaging {
    /// PSF FWHM, m.
    pub fwhm_m: f64,
    /// Micrograph pixel size (x, y), m.
    pub pixel_m: (f64, f64),
}

impl Imaging {
    /// Areas of the maps of one load series as imaged: each map blurred and integrated onto
    /// micrograph pixels, one Otsu threshold over the whole series (as for micrographs), then
    /// pixels above it × pixel area.
    pub fn areas(&self, maps: &[Vec<f64>], body: &Topography) -> Result<Vec<f64>> {
        let images: Vec<Grid> = maps
            .iter()
            .map(|m| {
                let grid = Grid::new(m.clone(), body.nx(), body.ny(), body.dx_m, body.dy_m)?;
                microscope_image(&grid, self.fwhm_m, self.pixel_m)
            })
            .collect::<Result<_>>()?;
        let values: Vec<&[f64]> = images.iter().map(|g| g.values.as_slice()).collect();
        let Ok(t) = otsu_of_values(&values, "the imaged simulated maps") else {
            // Every imaged map is uniform (no contact anywhere): no area.
            return Ok(vec![0.0; maps.len()]);
        };
        let pixel_area = self.pixel_m.0 * self.pixel_m.1;
        Ok(images
            .iter()
            .map(|g| g.values.iter().filter(|&&v| v > t).count() as f64 * pixel_area)
            .collect())
    }
}

/// Measured area–load points, SI units, sorted by force.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Normal forces, N (increasing).
    pub forces_n: Vec<f64>,
    /// Contact areas, m².
    pub areas_m2: Vec<f64>,
    /// Each area's interval (lo, hi), m², without the pixel size's calibration (`analyze`'s
    /// edge band); `None` when the measured curve carries none.
    pub intervals_m2: Option<Vec<(f64, f64)>>,
    /// Relative uncertainty (bounds) of the micrographs' pixel size, shared by every area.
    pub pixel_size_uncertainty: f64,
}

impl Measured {
    /// Points sorted by force; errors for fewer than 2 points or non-positive values.
    pub fn new(mut points: Vec<(f64, f64)>) -> Result<Self> {
        if points.len() < 2 {
            return Err(Error::TooFew {
                what: "a fit",
                needed: 2,
                got: points.len(),
            });
        }
        if let Some((f, a)) = points
            .iter()
            .find(|(f, a)| !(*f > 0.0 && *a > 0.0 && f.is_finite() && a.is_finite()))
        {
            return Err(Error::InvalidArgument(format!(
                "measured point ({f} N, {a} m²) is not positive"
            )));
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(Measured {
            forces_n: points.iter().map(|p| p.0).collect(),
            areas_m2: points.iter().map(|p| p.1).collect(),
            intervals_m2: None,
            pixel_size_uncertainty: 0.0,
        })
    }

    /// Points (force N, area m², lo m², hi m²) with each area's interval, sorted by force, and
    /// the pixel size's relative uncertainty; errors as [`Measured::new`], for an interval
    /// that does not hold its area, or for an uncertainty outside [0, 0.5).
    pub fn with_intervals(
        mut points: Vec<(f64, f64, f64, f64)>,
        pixel_size_uncertainty: f64,
    ) -> Result<Self> {
        if let Some(&(f, a, lo, hi)) = points
            .iter()
            .find(|(_, a, lo, hi)| !(*lo >= 0.0 && lo <= a && a <= hi && hi.is_finite()))
        {
            return Err(Error::InvalidArgument(format!(
                "the interval {lo:e}..{hi:e} m² of the area {a:e} m² at {f} N does not hold it"
            )));
        }
        if !(0.0..0.5).contains(&pixel_size_uncertainty) {
            return Err(Error::InvalidArgument(format!(
                "the pixel size's relative uncertainty {pixel_size_uncertainty} must lie in \
                 [0, 0.5)"
            )));
        }
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut measured = Measured::new(points.iter().map(|p| (p.0, p.1)).collect())?;
        measured.intervals_m2 = Some(points.iter().map(|p| (p.2, p.3)).collect());
        measured.pixel_size_uncertainty = pixel_size_uncertainty;
        Ok(measured)
    }

    /// Each area's interval with the pixel size's calibration, m² (what `areas.csv` reports):
    /// the ends of [`Measured::intervals_m2`] times [`calibration_bounds`].
    pub fn reported_intervals_m2(&self) -> Option<Vec<(f64, f64)>> {
        let (lo, hi) = calibration_bounds(self.pixel_size_uncertainty);
        self.intervals_m2
            .as_ref()
            .map(|v| v.iter().map(|&(l, h)| (l * lo, h * hi)).collect())
    }

    /// RMS of ln(A_sim/A_exp); a load without simulated contact counts as a hundredth of the
    /// measured area (a large but finite misfit, so searches stay well defined).
    pub fn misfit(&self, simulated_m2: &[f64]) -> f64 {
        let residuals = self.log_residuals(simulated_m2);
        (residuals.iter().map(|r| r * r).sum::<f64>() / residuals.len() as f64).sqrt()
    }

    fn log_residuals(&self, simulated_m2: &[f64]) -> Vec<f64> {
        simulated_m2
            .iter()
            .zip(&self.areas_m2)
            .map(|(&s, &e)| (s.max(0.01 * e) / e).ln())
            .collect()
    }
}

impl ModelBody {
    /// A free-boundary body from detrended roughness: the sphere (if any) is added for the
    /// half-space models, the statistics feed GT; raw g = 0 areas (set `imaging` to change).
    pub fn new(
        roughness: Topography,
        radius_m: Option<f64>,
        e_star_pa: f64,
        options: SolverOptions<'static>,
    ) -> Result<Self> {
        let stats = SurfaceStats::finite_differences(&roughness)?;
        let mut body = roughness.clone();
        if let Some(r) = radius_m {
            body.add_sphere(r)?;
        }
        // Gap residuals relative to the roughness (SolverOptions::gap_scale_m).
        let options = SolverOptions {
            gap_scale_m: options.gap_scale_m.or(Some(stats.h_rms_m)),
            ..options
        };
        Ok(ModelBody {
            roughness,
            body,
            stats,
            radius_m,
            e_star_pa,
            periodic: false,
            options,
            imaging: None,
            progress: None,
        })
    }

    /// Contact areas (and maps when `keep_maps`) at `loads_n` (increasing) for one model.
    pub fn evaluate(
        &self,
        family: Family,
        parameter: Option<f64>,
        loads_n: &[f64],
        keep_maps: bool,
    ) -> Result<ModelAreas> {
        let model = match (family, parameter) {
            (Family::GreenwoodTripp, _) => return self.evaluate_gt(loads_n, keep_maps),
            (Family::Elastic, _) => Model::Elastic,
            (Family::Hardness, Some(p)) => Model::Hardness {
                hardness_pa: p,
                volume_conserving: None,
            },
            (Family::Hardening, Some(k)) => Model::Hardening {
                modulus_pa_per_m: k,
                initial_pa: 0.0,
            },
            (f, None) => {
                return Err(Error::InvalidArgument(format!(
                    "the {} model needs its parameter",
                    f.name()
                )))
            }
        };
        let setup = Setup {
            topography: &self.body,
            e_star_pa: self.e_star_pa,
            boundary: if self.periodic {
                Boundary::Periodic
            } else {
                Boundary::Free
            },
            model,
            options: self.options,
        };
        // Only the contact map and area of each load are kept, not its fields.
        let (mut maps, mut raw_areas, mut edge) = (Vec::new(), Vec::new(), false);
        sweep_each(&setup, loads_n, &mut |i, step| {
            edge |= step.edge_contact;
            raw_areas.push(step.area_m2);
            maps.push(
                step.solution
                    .pressure
                    .iter()
                    .map(|&p| f64::from(u8::from(p > 0.0)))
                    .collect::<Vec<f64>>(),
            );
            self.report(family, parameter, i + 1, loads_n.len());
            Ok(())
        })?;
        let areas = match &self.imaging {
            Some(imaging) => imaging.areas(&maps, &self.body)?,
            None => raw_areas,
        };
        Ok((areas, keep_maps.then_some(maps), edge))
    }

    fn report(&self, family: Family, parameter: Option<f64>, load: usize, loads: usize) {
        if let Some(hook) = &self.progress {
            (hook.0)(&RampEvent {
                family,
                parameter,
                load,
                loads,
            });
        }
    }

    fn evaluate_gt(&self, loads_n: &[f64], keep_maps: bool) -> Result<ModelAreas> {
        let radius = self.radius_m.ok_or_else(|| {
            Error::InvalidArgument("the Greenwood–Tripp model needs the sphere radius".into())
        })?;
        let params = GtParams::new(
            radius,
            self.e_star_pa,
            self.stats.h_rms_m,
            self.stats.h_double_prime_rms_per_m,
        );
        params.validate()?;
        let mut areas = Vec::new();
        let mut maps = Vec::new();
        for &force in loads_n {
            let profile = gt_profile(&params, force)?;
            let map = gt_bearing_area(&self.roughness, &profile, None)?;
            areas.push(map.area_m2);
            maps.push(map.mask.iter().map(|&m| f64::from(u8::from(m))).collect());
            self.report(Family::GreenwoodTripp, None, maps.len(), loads_n.len());
        }
        if let Some(imaging) = &self.imaging {
            areas = imaging.areas(&maps, &self.roughness)?;
        }
        Ok((areas, keep_maps.then_some(maps), false))
    }

    /// Evaluate a model at the measured loads and score it.
    pub fn score(
        &self,
        family: Family,
        parameter: Option<f64>,
        measured: &Measured,
        keep_maps: bool,
    ) -> Result<Evaluation> {
        let (areas_m2, maps, edge_contact) =
            self.evaluate(family, parameter, &measured.forces_n, keep_maps)?;
        Ok(Evaluation {
            parameter,
            misfit: measured.misfit(&areas_m2),
            areas_m2,
            maps,
            edge_contact,
        })
    }
}

/// How a one-parameter search runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Search {
    /// Parameter range (lo, hi), > 0.
    pub range: (f64, f64),
    /// Log-spaced grid points evaluated in parallel first (≥ 3).
    pub grid: usize,
    /// Golden-section stop: bracket width in ln(parameter).
    pub ln_tolerance: f64,
}

impl Search {
    /// Defaults for a family: k in 0.1–100 MPa/nm, p_Y in 10 MPa–10 GPa; 7 grid points;
    /// 1 % in the parameter.
    pub fn default_for(family: Family) -> Self {
        let range = match family {
            Family::Hardness => (1e7, 1e10),
            _ => (1e14, 1e17),
        };
        Search {
            range,
            grid: 7,
            ln_tolerance: 0.01,
        }
    }

    /// About how many ramps [`fit_parameter`] runs, at most: the grid, the golden-section steps
    /// from a bracket of two grid spacings down to `ln_tolerance` (Brent's parabolic steps
    /// usually need fewer), the final evaluation and the two of the standard error. For progress
    /// estimates only.
    pub fn expected_ramps(&self) -> usize {
        let (lo, hi) = self.range;
        let spacing = (hi / lo).ln().abs() / (self.grid.max(2) - 1) as f64;
        let ratio = 2.0 * spacing / self.ln_tolerance.max(1e-6);
        let golden = if ratio > 1.0 {
            (ratio.ln() / 1.618_033_988_749_895_f64.ln()).ceil() as usize + 1
        } else {
            0
        };
        self.grid + golden + 3
    }
}

/// Fit a one-parameter family (hardness or hardening) to the measured curve.
pub fn fit_parameter(
    body: &ModelBody,
    family: Family,
    measured: &Measured,
    search: Search,
) -> Result<ModelFit> {
    let (lo, hi) = search.range;
    if !(lo > 0.0 && hi > lo && hi.is_finite() && search.grid >= 3) {
        return Err(Error::InvalidArgument(format!(
            "search range {lo:e}..{hi:e} with {} grid points is not usable",
            search.grid
        )));
    }
    // A parameter the map cannot carry (e.g. a hardness too low for the load on the whole map)
    // is infeasible, not fatal: it scores +∞ and the search moves on.
    let misfit_at = |ln_p: f64| -> std::result::Result<f64, Error> {
        body.score(family, Some(ln_p.exp()), measured, false)
            .map(|e| e.misfit)
    };
    let (a, b) = (lo.ln(), hi.ln());
    let grid: Vec<f64> = (0..search.grid)
        .map(|i| a + (b - a) * i as f64 / (search.grid - 1) as f64)
        .collect();
    let outcomes: Vec<Result<f64>> = grid.par_iter().map(|&x| misfit_at(x)).collect();
    let values: Vec<f64> = outcomes
        .iter()
        .map(|r| *r.as_ref().unwrap_or(&f64::INFINITY))
        .collect();
    if values.iter().all(|v| v.is_infinite()) {
        let first = outcomes.into_iter().find_map(Result::err);
        return Err(first.unwrap_or_else(|| Error::InvalidArgument("no feasible value".into())));
    }
    let trace: Mutex<Vec<(f64, f64)>> = Mutex::new(
        grid.iter()
            .map(|x| x.exp())
            .zip(values.iter().copied())
            .filter(|(_, m)| m.is_finite())
            .collect(),
    );
    let best = (0..values.len())
        .min_by(|&i, &j| values[i].total_cmp(&values[j]))
        .expect("grid is not empty");
    let at_range_edge = best == 0 || best == values.len() - 1;
    let (x0, x1) = (
        grid[best.saturating_sub(1)],
        grid[(best + 1).min(grid.len() - 1)],
    );
    let ln_best = brent_minimum(x0, x1, search.ln_tolerance, &|x| {
        let m = misfit_at(x).unwrap_or(f64::INFINITY);
        if m.is_finite() {
            trace.lock().expect("trace").push((x.exp(), m));
        }
        m
    })?;
    let trace = trace.into_inner().expect("trace");
    let best_eval = body.score(family, Some(ln_best.exp()), measured, false)?;
    let jacobian = sensitivity(body, family, measured, ln_best)?;
    let undetermined = jacobian
        .as_ref()
        .is_some_and(|j| j.iter().all(|&v| v == 0.0));
    let (parameter_se, parameter_ci95) = match (&jacobian, undetermined) {
        (Some(j), false) => (
            standard_error(measured, ln_best, j, &best_eval),
            interval::parameter_interval(
                ln_best,
                j,
                &best_eval.areas_m2,
                measured,
                body.imaging.is_some(),
            ),
        ),
        _ => (None, None),
    };
    Ok(ModelFit {
        family,
        best: best_eval,
        parameter_se,
        parameter_ci95,
        sensitivities: jacobian,
        trace,
        at_range_edge,
        undetermined,
    })
}

/// The minimum of `f` on [`lo`, `hi`] to within about `width` in x, by Brent's method (golden
/// section with parabolic steps; Brent, *Algorithms for Minimization without Derivatives*,
/// 1973, ch. 5) from `argmin`. The tolerance is absolute in x (its relative part is set to
/// nothing): x is ln(parameter), and a relative rule would make the work depend on the unit.
/// A misfit of +∞ (an infeasible parameter) is passed on as a large finite value, so that the
/// parabolic steps stay defined. On the demo's fits (grid of 5, width 0.02): 10 evaluations
/// instead of the golden section's 13 for k, 9 instead of 10 for the hardness.
fn brent_minimum(lo: f64, hi: f64, width: f64, f: &(dyn Fn(f64) -> f64 + Sync)) -> Result<f64> {
    struct Cost<'a>(&'a (dyn Fn(f64) -> f64 + Sync));
    impl CostFunction for Cost<'_> {
        type Param = f64;
        type Output = f64;
        fn cost(&self, x: &f64) -> std::result::Result<f64, argmin::core::Error> {
            let m = (self.0)(*x);
            Ok(if m.is_finite() { m } else { INFEASIBLE_MISFIT })
        }
    }
    // Brent stops when the bracket is within about 4·tol of its best point.
    let solver = BrentOpt::new(lo, hi).set_tolerance(1e-12, width / 4.0);
    let result = Executor::new(Cost(f), solver)
        .configure(|state| state.max_iters(200))
        .run()
        .map_err(|e| Error::InvalidArgument(format!("parameter search: {e}")))?;
    result
        .state()
        .get_best_param()
        .copied()
        .ok_or_else(|| Error::InvalidArgument("parameter search found no point".into()))
}

/// The misfit that stands for an infeasible parameter in [`brent_minimum`] (misfits are RMS
/// log ratios, of order 1).
const INFEASIBLE_MISFIT: f64 = 1e6;

/// J = ∂ ln A_sim/∂ ln p at `ln_best` for each measured load, by central differences 5 % either
/// side (see the module docs); all zero when the response is flat there (the parameter is
/// undetermined). `None` with a single load or next to an infeasible region (no two-sided
/// derivative).
fn sensitivity(
    body: &ModelBody,
    family: Family,
    measured: &Measured,
    ln_best: f64,
) -> Result<Option<Vec<f64>>> {
    if measured.areas_m2.len() < 2 {
        return Ok(None);
    }
    let h = 0.05;
    let sides: Result<Vec<Vec<f64>>> = [ln_best - h, ln_best + h]
        .par_iter()
        .map(|&x| Ok(body.score(family, Some(x.exp()), measured, false)?.areas_m2))
        .collect();
    let Ok(sides) = sides else {
        return Ok(None);
    };
    Ok(Some(
        sides[0]
            .iter()
            .zip(&sides[1])
            .map(|(lo, hi)| (hi.max(1e-300).ln() - lo.max(1e-300).ln()) / (2.0 * h))
            .collect(),
    ))
}

/// Gauss–Newton standard error of the parameter at `ln_best` from the sensitivities `jacobian`
/// (see the module docs); `None` when they are all zero.
fn standard_error(
    measured: &Measured,
    ln_best: f64,
    jacobian: &[f64],
    best: &Evaluation,
) -> Option<f64> {
    let n = measured.areas_m2.len();
    let jtj: f64 = jacobian.iter().map(|j| j * j).sum();
    if jtj <= 0.0 || n < 2 {
        return None;
    }
    let residuals = measured.log_residuals(&best.areas_m2);
    let s2 = residuals.iter().map(|r| r * r).sum::<f64>() / (n - 1) as f64;
    Some(ln_best.exp() * (s2 / jtj).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misfit_is_rms_log_ratio() {
        let m = Measured::new(vec![(2.0, 4.0), (1.0, 1.0)]).unwrap();
        assert_eq!(m.forces_n, vec![1.0, 2.0]);
        let misfit = m.misfit(&[std::f64::consts::E, 4.0]);
        assert!((misfit - (0.5f64).sqrt()).abs() < 1e-12);
        assert!(m.misfit(&[0.0, 4.0]).is_finite());
        assert!(Measured::new(vec![(1.0, 1.0)]).is_err());
        assert!(Measured::new(vec![(1.0, 1.0), (2.0, -1.0)]).is_err());
        assert_eq!(Family::parse("hardening").unwrap(), Family::Hardening);
        assert!(Family::parse("plastic").is_err());
    }
}
