//! The `fit-hardening` job: contact models fitted to a measured area–load curve on a rough
//! sphere (Weber et al. 2018, Fig. 3a; `docs/fitting.md`). Every front-end builds a
//! [`FitRequest`]: the measured curve (an `areas.csv` or numbers in memory), the body
//! ([`BodyRequest`]: heights, sphere, E*, solver limits, imaging), the families and their
//! searches, an optional sweep (Supplementary Fig. 8) scored against micrographs.
//! [`FitRequest::check`] applies the same range checks everywhere; [`run`] returns a
//! [`FitOutcome`], which is `fit.json` (lab units) and the Python result (SI units). One load
//! ramp on its own ([`ramp`]) is the unit of a distributed fit.

pub mod files;
mod sweep;

use std::path::PathBuf;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use contactscope::model_fit::{
    fit_parameter, Family, Imaging, Measured, ModelBody, ModelFit, ProgressHook, Search,
};
use contactscope::solver::cg::SolverOptions;
use contactscope::surface::fill::FillInvalid;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::{short, Quantity};

pub use sweep::{Sweep, SweepMicrographs, SweepRow};

use crate::error::{Error, Result};
use crate::heights::{HeightInput, Roughness};
use crate::lab::{self, Interval, OptQ, Qs, Unit, Q};
use crate::results::read_measured;
use crate::simulate::{check_loads, check_solver, DeviceChoice, SimulateRequest};

/// The rough sphere of a fit or a ramp: heights, sphere, material, solver limits, imaging.
#[derive(Debug, Clone)]
pub struct BodyRequest {
    /// The roughness (a sphere of `radius_m` is added when given).
    pub heights: HeightInput,
    /// Sphere radius, m.
    pub radius_m: Option<f64>,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// Periodic boundaries (free otherwise).
    pub periodic: bool,
    /// Relative CG tolerance.
    pub tolerance: f64,
    /// Most CG iterations per load.
    pub max_iterations: usize,
    /// Count simulated areas as imaged (blur, resample, Otsu) instead of raw g = 0 pixels.
    pub imaging: Option<Imaging>,
    /// Where the ramps are solved (CPU, CUDA GPU, or a GPU when one is usable).
    pub device: DeviceChoice,
}

impl BodyRequest {
    /// A body with the defaults: no sphere, free boundaries, the solver's default limits, raw
    /// areas.
    pub fn new(heights: HeightInput, e_star_pa: f64) -> Self {
        BodyRequest {
            heights,
            radius_m: None,
            e_star_pa,
            periodic: false,
            tolerance: SimulateRequest::TOLERANCE,
            max_iterations: SimulateRequest::MAX_ITERATIONS,
            imaging: None,
            device: DeviceChoice::Cpu,
        }
    }

    /// Every range check of the body.
    pub fn check(&self) -> Result<()> {
        self.heights.check()?;
        if let Some(r) = self.radius_m {
            Quantity::Radius.check(r, Param::Radius)?;
        }
        Quantity::Modulus.check(self.e_star_pa, Param::Modulus)?;
        check_solver(self.tolerance, self.max_iterations)?;
        if let Some(i) = self.imaging {
            Quantity::Fwhm.check(i.fwhm_m, Param::PsfFwhm)?;
            Quantity::PixelSize.check(i.pixel_m.0, Param::PixelSize)?;
            Quantity::PixelSize.check(i.pixel_m.1, Param::PixelSize)?;
        }
        Ok(())
    }

    /// The model body, with notes on the heights.
    pub fn build(&self, progress: Option<ProgressHook>) -> Result<(ModelBody, Vec<String>)> {
        let (topography, mut notes) = self.heights.read_with_notes()?;
        // A container's measurement marked periodic is solved with periodic boundaries, as by
        // `simulate`.
        let periodic = self.periodic || self.heights.stated_periodic()?;
        if periodic && !self.periodic {
            notes.push(format!(
                "{}: the container marks the measurement periodic: periodic boundaries",
                self.heights.label()
            ));
        }
        if let Some(i) = self.imaging {
            // The micrograph each simulated map becomes, checked before any load is solved.
            contactscope::optics::blur::check_resample(
                (topography.nx(), topography.ny()),
                (topography.dx_m, topography.dy_m),
                i.pixel_m,
            )?;
        }
        let options = SolverOptions {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            monitor: None,
            gpu: self.device.open()?,
            ..SolverOptions::default()
        };
        let mut body = ModelBody::new(topography, self.radius_m, self.e_star_pa, options)?;
        body.periodic = periodic;
        body.imaging = self.imaging;
        body.progress = progress;
        Ok((body, notes))
    }
}

/// The measured area–load curve: `areas.csv` of `analyze`, or (force N, area m²) pairs.
#[derive(Debug, Clone)]
pub enum MeasuredInput {
    /// A table with `force_mN` and `area_um2` columns.
    File(PathBuf),
    /// (force N, area m²) per load.
    Memory(Vec<(f64, f64)>),
    /// (force N, area m², lo m², hi m²) per load: each area with its interval (without the
    /// pixel size's calibration).
    Intervals(Vec<(f64, f64, f64, f64)>),
}

impl MeasuredInput {
    fn label(&self) -> String {
        match self {
            MeasuredInput::File(p) => p.display().to_string(),
            MeasuredInput::Memory(_) => "forces and areas (arrays)".into(),
            MeasuredInput::Intervals(_) => "forces, areas and their intervals (arrays)".into(),
        }
    }

    /// The measured curve, checked: forces within their range, at least two loads.
    pub fn read(&self) -> Result<Measured> {
        match self {
            MeasuredInput::File(path) => read_measured(path),
            MeasuredInput::Memory(points) => {
                let forces: Vec<f64> = points.iter().map(|p| p.0).collect();
                check_loads(&forces, Param::Forces)?;
                Ok(Measured::new(points.clone())?)
            }
            MeasuredInput::Intervals(points) => {
                let forces: Vec<f64> = points.iter().map(|p| p.0).collect();
                check_loads(&forces, Param::Forces)?;
                // `analyze`'s intervals are on the true area and need not hold the contact-pixel
                // area: widened to hold it, as from areas.csv (`results::read_measured`); an
                // interval out of order is refused.
                let mut widened = Vec::with_capacity(points.len());
                for &(f, a, lo, hi) in points {
                    if lo > hi {
                        return Err(crate::error::Error::InvalidArgument(format!(
                            "area_intervals: the interval {lo:e}..{hi:e} m² at {f} N is out of \
                             order"
                        )));
                    }
                    let (lo, hi) = crate::results::interval_holding(a, lo, hi);
                    widened.push((f, a, lo, hi));
                }
                Ok(Measured::with_intervals(widened, 0.0)?)
            }
        }
    }
}

/// Everything `fit-hardening` needs. SI units.
#[derive(Debug, Clone)]
pub struct FitRequest {
    /// The measured curve.
    pub measured: MeasuredInput,
    /// The rough sphere.
    pub body: BodyRequest,
    /// Models to fit, in order.
    pub families: Vec<Family>,
    /// Search settings per fitted family (defaults from [`Search::default_for`]).
    pub searches: Vec<(Family, Search)>,
    /// A parameter sweep.
    pub sweep: Option<Sweep>,
    /// Micrographs to score the sweep against (Dice per load).
    pub micrographs: Option<SweepMicrographs>,
}

impl FitRequest {
    /// Every model, the default searches, no sweep.
    pub fn new(measured: MeasuredInput, body: BodyRequest) -> Self {
        FitRequest {
            measured,
            body,
            families: Family::ALL.to_vec(),
            searches: Vec::new(),
            sweep: None,
            micrographs: None,
        }
    }

    /// The search of a family (the request's, else the default).
    pub fn search(&self, family: Family) -> Search {
        self.searches
            .iter()
            .find(|(f, _)| *f == family)
            .map_or_else(|| Search::default_for(family), |(_, s)| *s)
    }

    /// Every range check, the same for every front-end.
    pub fn check(&self) -> Result<()> {
        self.body.check()?;
        if self.families.is_empty() {
            return Err(Error::InvalidArgument("no model to fit".into()));
        }
        for &family in self.families.iter().filter(|f| f.has_parameter()) {
            let search = self.search(family);
            let (quantity, param) = parameter_quantity(family);
            let (lo, hi) = search.range;
            quantity.check(lo, param)?;
            quantity.check(hi, param)?;
            if lo >= hi {
                return Err(Error::InvalidArgument(format!(
                    "{param}: the search range {lo:e}..{hi:e} must be increasing"
                )));
            }
            if search.grid < 3 || !(search.ln_tolerance > 0.0 && search.ln_tolerance < 1.0) {
                return Err(Error::InvalidArgument(format!(
                    "a search needs a grid of at least 3 points and a tolerance in ln(parameter) \
                     in (0, 1); got {} and {}",
                    search.grid, search.ln_tolerance
                )));
            }
        }
        if let Some(s) = &self.sweep {
            let (quantity, param) = parameter_quantity(s.family);
            for &v in &s.values {
                quantity.check(v, param)?;
            }
        }
        if let Some(m) = &self.micrographs {
            if self.sweep.is_none() {
                return Err(Error::InvalidArgument(
                    "micrographs score a sweep; give one".into(),
                ));
            }
            m.check()?;
        }
        Ok(())
    }

    /// About how many load ramps the fit will run: for progress bars and their time
    /// estimates; the true count differs by a few.
    pub fn expected_ramps(&self) -> usize {
        self.families
            .iter()
            .map(|&family| match family.has_parameter() {
                true => self.search(family).expected_ramps(),
                false => 1,
            })
            .sum::<usize>()
            + self.sweep.as_ref().map_or(0, |s| s.values.len())
    }
}

/// The search range of k (Pa/m) from the text of `--k-range`: `0.1..100MPa/nm`.
pub fn parse_k_range(text: &str) -> std::result::Result<(f64, f64), String> {
    use contactscope_formats::units::{self, Dimension};
    units::parse_range(text, &|t| {
        units::parse_ratio(t, Dimension::Pressure, Dimension::Length)
    })
    .map_err(|e| e.to_string())
}

/// The search range of the hardness p_Y (Pa) from the text of `--hardness-range`:
/// `10MPa..10GPa`.
pub fn parse_hardness_range(text: &str) -> std::result::Result<(f64, f64), String> {
    use contactscope_formats::units::{self, Dimension};
    units::parse_range(text, &|t| units::parse_positive(t, Dimension::Pressure))
        .map_err(|e| e.to_string())
}

/// The searches of a fit over the ranges of k (Pa/m) and p_Y (Pa), the other settings the
/// families' defaults.
pub fn searches(k_range: (f64, f64), hardness_range: (f64, f64)) -> Vec<(Family, Search)> {
    [
        (Family::Hardening, k_range),
        (Family::Hardness, hardness_range),
    ]
    .into_iter()
    .map(|(family, range)| {
        (
            family,
            Search {
                range,
                ..Search::default_for(family)
            },
        )
    })
    .collect()
}

/// The families of `--models` (`gt,elastic,hardness,hardening`), in order.
pub fn families_from_text(text: &str) -> std::result::Result<Vec<Family>, String> {
    text.split(',')
        .map(|t| Family::parse(t).map_err(|e| e.to_string()))
        .collect()
}

/// The range and the parameter name of a family's parameter.
fn parameter_quantity(family: Family) -> (Quantity, Param) {
    match family {
        Family::Hardness => (Quantity::Hardness, Param::Hardness),
        _ => (Quantity::Hardening, Param::Hardening),
    }
}

/// The measured curve as a summary records it: forces and areas, and, where the curve carries
/// them, each area's interval as `areas.csv` gives it (calibration included) and the pixel
/// size's uncertainty.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredFacts(pub Measured);

impl Serialize for MeasuredFacts {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let m = &self.0;
        let mut map = s.serialize_map(None)?;
        map.serialize_entry("force_mN", &Qs(&m.forces_n, Unit::NAsMn))?;
        map.serialize_entry("area_um2", &Qs(&m.areas_m2, Unit::M2AsUm2))?;
        if let Some(intervals) = m.reported_intervals_m2() {
            let u = m.pixel_size_uncertainty;
            let lo: Vec<f64> = intervals.iter().map(|i| i.0).collect();
            let hi: Vec<f64> = intervals.iter().map(|i| i.1).collect();
            map.serialize_entry("area_um2_lo", &Qs(&lo, Unit::M2AsUm2))?;
            map.serialize_entry("area_um2_hi", &Qs(&hi, Unit::M2AsUm2))?;
            map.serialize_entry("pixel_size_uncertainty_pct", &Q(u, Unit::FractionAsPct))?;
        }
        map.end()
    }
}

/// How the simulated areas were counted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Counting(pub Option<Imaging>);

impl Serialize for Counting {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(None)?;
        match self.0 {
            Some(i) => {
                m.serialize_entry(
                    "counted",
                    "as imaged: blurred by the PSF, integrated onto micrograph pixels, one Otsu threshold per simulated series",
                )?;
                m.serialize_entry("psf_fwhm_nm", &Q(i.fwhm_m, Unit::MAsNm))?;
                m.serialize_entry(
                    "pixel_size_nm",
                    &Qs(&[i.pixel_m.0, i.pixel_m.1], Unit::MAsNm),
                )?;
            }
            None => m.serialize_entry("counted", "raw: simulation pixels with g = 0 (p > 0)")?,
        }
        m.end()
    }
}

/// One fitted model as `fit.json` lists it.
#[derive(Debug, Clone)]
pub struct FittedModel(pub ModelFit);

impl Serialize for FittedModel {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let fit = &self.0;
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("model", fit.family.name())?;
        m.serialize_entry("misfit_rms_ln_area", &fit.best.misfit)?;
        m.serialize_entry("areas_um2", &Qs(&fit.best.areas_m2, Unit::M2AsUm2))?;
        m.serialize_entry("evaluations", &fit.trace.len())?;
        m.serialize_entry("at_range_edge", &fit.at_range_edge)?;
        if let Some(p) = fit.best.parameter {
            let (key, unit) = match fit.family {
                Family::Hardness => ("hardness_MPa", Unit::PaAsMpa),
                _ => ("k_MPa_per_nm", Unit::PaPerMAsMpaPerNm),
            };
            m.serialize_entry(key, &Q(p, unit))?;
            m.serialize_entry(&format!("{key}_se"), &OptQ(fit.parameter_se, unit))?;
            m.serialize_entry(
                &format!("{key}_ci95"),
                &fit.parameter_ci95.map(|(lo, hi)| Interval(lo, hi, unit)),
            )?;
            m.serialize_entry("undetermined", &fit.undetermined)?;
        }
        m.end()
    }
}

/// What `fit-hardening` found: `fit.json` without the command line.
#[derive(Debug, Clone, Serialize)]
pub struct FitOutcome {
    /// The measured table (or the label of numbers in memory).
    pub experiment: String,
    /// The height map (or the label of heights in memory).
    pub topography: String,
    /// Channel of a vendor height map.
    pub topography_channel: Option<String>,
    /// How invalid points were filled.
    pub fill_invalid: Option<FillInvalid>,
    /// Sphere radius, m.
    #[serde(rename = "radius_um", serialize_with = "lab::opt_m_as_um")]
    pub radius_m: Option<f64>,
    /// Contact modulus E*, Pa.
    #[serde(rename = "contact_modulus_GPa", serialize_with = "lab::pa_as_gpa")]
    pub contact_modulus_pa: f64,
    /// Roughness statistics.
    pub roughness: Roughness,
    /// The measured curve.
    pub measured: MeasuredFacts,
    /// How simulated areas were counted.
    pub simulated_areas: Counting,
    /// The fitting method, in words.
    pub method: &'static str,
    /// Where the ramps were solved: "cpu", or "cuda: " and the GPU's name.
    pub device: String,
    /// One fit per family, in request order.
    pub models: Vec<FittedModel>,
    /// The family with the lowest misfit.
    pub best_model: Option<&'static str>,
    /// Rows of `sweep.csv`.
    pub sweep_rows: usize,
    /// Notes.
    pub warnings: Vec<String>,
    /// The sweep (empty without one).
    #[serde(skip)]
    pub sweep: Vec<SweepRow>,
    /// The swept family.
    #[serde(skip)]
    pub sweep_family: Option<Family>,
}

impl FitOutcome {
    /// The fits, in request order.
    pub fn fits(&self) -> impl Iterator<Item = &ModelFit> {
        self.models.iter().map(|m| &m.0)
    }
}

const METHOD: &str = "least squares in log area: misfit = RMS of ln(A_sim/A_exp) over the measured loads; one-parameter models by a parallel log grid then Brent's method on ln(parameter); SE by Gauss-Newton at the optimum; hardening has p_Y0 = 0 as in the paper";

/// Run `fit-hardening` in memory. `progress` is told of every load of every ramp.
pub fn run(request: &FitRequest, progress: Option<ProgressHook>) -> Result<FitOutcome> {
    request.check()?;
    let measured = request.measured.read()?;
    let (body, notes) = request.body.build(progress)?;
    let map_area = body.body.nx() as f64 * body.body.dx_m * body.body.ny() as f64 * body.body.dy_m;
    if let Some((i, &a)) = measured
        .areas_m2
        .iter()
        .enumerate()
        .find(|(_, a)| **a > map_area)
    {
        return Err(Error::InvalidArgument(format!(
            "{}: measured area {:.4e} µm² at {:.4} mN is larger than the whole height map \
             ({:.1} µm², {}): areas in another unit (1 µm² is 1e-12 m²), or the map's {}?",
            request.measured.label(),
            a * 1e12,
            measured.forces_n[i] * 1e3,
            map_area * 1e12,
            request.body.heights.label(),
            Param::PixelSize
        )));
    }
    let micrographs = request
        .micrographs
        .as_ref()
        .map(|m| crate::compare::load_micrographs(&m.micrographs, m.pixel_size_m).map(|(_, m)| m))
        .transpose()?;
    let mut warnings = notes;
    let mut fits = Vec::new();
    for &family in &request.families {
        let fit = fit_family(request, &body, family, &measured)?;
        if fit.best.edge_contact {
            warnings.push(format!(
                "{}: the contact reaches the border of the map; the free-boundary areas are not valid (use a larger map or smaller loads)",
                family.name()
            ));
        }
        if let (true, Some(p)) = (fit.undetermined, fit.best.parameter) {
            let value = match family {
                Family::Hardness => format!("p_Y = {} MPa", short(p * 1e-6)),
                _ => format!("k = {} MPa/nm", short(p * 1e-15)),
            };
            warnings.push(format!(
                "{}: {value} is not determined by the areas: they do not change when it moves 5 % \
                 either way (misfit {:.4}, flat); the value is one of many that fit as well",
                family.name(),
                fit.best.misfit
            ));
        }
        if fit.at_range_edge {
            warnings.push(format!(
                "{}: the best value lies at the end of the search range; widen it",
                family.name()
            ));
        }
        fits.push(FittedModel(fit));
    }
    let sweep = match &request.sweep {
        Some(s) => sweep::run_sweep(request, &body, s, &measured, micrographs.as_ref())?,
        None => Vec::new(),
    };
    let best_model = fits
        .iter()
        .min_by(|a, b| a.0.best.misfit.total_cmp(&b.0.best.misfit))
        .map(|f| f.0.family.name());
    let (channel, fill_invalid) = request.body.heights.facts();
    Ok(FitOutcome {
        experiment: request.measured.label(),
        topography: request.body.heights.label(),
        topography_channel: channel,
        fill_invalid,
        radius_m: request.body.radius_m,
        contact_modulus_pa: request.body.e_star_pa,
        roughness: Roughness::from(&body.stats),
        measured: MeasuredFacts(measured.clone()),
        simulated_areas: Counting(request.body.imaging),
        method: METHOD,
        device: contactscope::solver::gpu::describe(body.options.gpu),
        models: fits,
        best_model,
        sweep_rows: sweep.len(),
        warnings,
        sweep,
        sweep_family: request.sweep.as_ref().map(|s| s.family),
    })
}

fn fit_family(
    request: &FitRequest,
    body: &ModelBody,
    family: Family,
    measured: &Measured,
) -> Result<ModelFit> {
    if !family.has_parameter() {
        let best = body.score(family, None, measured, false)?;
        return Ok(ModelFit {
            family,
            trace: Vec::new(),
            best,
            parameter_se: None,
            parameter_ci95: None,
            sensitivities: None,
            at_range_edge: false,
            undetermined: false,
        });
    }
    Ok(fit_parameter(
        body,
        family,
        measured,
        request.search(family),
    )?)
}

/// One load ramp of a family at a parameter: the unit of a distributed fit or sweep.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RampOutcome {
    /// Contact areas, m², per load.
    #[serde(rename = "areas_um2", serialize_with = "lab::each_m2_as_um2")]
    pub areas_m2: Vec<f64>,
    /// The contact reaches the border of a free map at some load.
    pub edge_contact: bool,
}

/// Solve one ramp (`loads_n` increasing) of `family` at `parameter` on the body, counting areas
/// as [`run`] does.
pub fn ramp(
    body: &BodyRequest,
    family: Family,
    parameter: Option<f64>,
    loads_n: &[f64],
) -> Result<RampOutcome> {
    body.check()?;
    check_loads(loads_n, Param::Loads)?;
    if let (true, Some(p)) = (family.has_parameter(), parameter) {
        let (quantity, param) = parameter_quantity(family);
        quantity.check(p, param)?;
    }
    let (model, _) = body.build(None)?;
    let (areas_m2, _, edge_contact) = model.evaluate(family, parameter, loads_n, false)?;
    Ok(RampOutcome {
        areas_m2,
        edge_contact,
    })
}

/// A family's parameter in the unit tables and charts show: MPa for hardness, MPa/nm for k.
pub fn display(family: Family, value: f64) -> f64 {
    match family {
        Family::Hardness => value * 1e-6,
        _ => value * 1e-15,
    }
}
