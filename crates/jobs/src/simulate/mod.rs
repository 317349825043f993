//! The `simulate` job: a load ramp with one contact model on a rough body, in memory. Every
//! front-end builds a [`SimulateRequest`] (the command line from its flags, Python from its
//! keywords), [`SimulateRequest::check`] applies the same range checks to both, [`run`] solves
//! and returns a [`SimulateOutcome`], whose serialisation is `summary.json` (lab units) and the
//! Python result (SI units, [`crate::lab`]). Per-load maps reach the caller's [`LoadObserver`]
//! as they come (the command line writes them as TIFFs, [`files`]; Python keeps them as arrays).

pub mod export_ce;
pub mod files;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use contactscope::analysis::fit::fit_power_law;
use contactscope::measure::patches::count_patches;
use contactscope::solver::cg::{Monitor, SolverOptions};
pub use contactscope::solver::gpu::DeviceChoice;
use contactscope::solver::gpu::{describe, Gpu};
use contactscope::solver::gt::{gt_bearing_area, gt_profile, GtParams};
use contactscope::solver::halfspace::Boundary;
use contactscope::solver::simulate::{separation, sweep_each, LoadStep, Model, Setup};
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::Topography;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::{short, Quantity};

use crate::error::{Error, Result};
use crate::fits::{self, LoadPoint, Source};
use crate::heights::{HeightFacts, HeightInput, Roughness};
use crate::lab::{self, Unit, Q};

/// Which model to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelChoice {
    /// One of the half-space models.
    HalfSpace(Model),
    /// Greenwood–Tripp with the bearing-area map (needs the sphere radius).
    GreenwoodTripp,
}

impl ModelChoice {
    /// Name used in outputs.
    pub fn name(&self) -> &'static str {
        match self {
            ModelChoice::HalfSpace(m) => m.name(),
            ModelChoice::GreenwoodTripp => "gt",
        }
    }
}

/// The model as `summary.json` records it (`model`).
impl Serialize for ModelChoice {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("name", self.name())?;
        match *self {
            ModelChoice::GreenwoodTripp => {
                m.serialize_entry("eta_h_rms_beta", &GtParams::DEFAULT_ETA_H_BETA)?;
                m.serialize_entry("sigma", "h_rms")?;
            }
            ModelChoice::HalfSpace(Model::Elastic) => {}
            ModelChoice::HalfSpace(Model::Hardness {
                hardness_pa,
                volume_conserving,
            }) => {
                m.serialize_entry("hardness_MPa", &Q(hardness_pa, Unit::PaAsMpa))?;
                m.serialize_entry(
                    "plastic_increment",
                    if volume_conserving.is_some() {
                        "volume-conserving (Eq. 5)"
                    } else {
                        "local (Eq. 4)"
                    },
                )?;
                m.serialize_entry("relaxation_alpha", &volume_conserving)?;
            }
            ModelChoice::HalfSpace(Model::Hardening {
                modulus_pa_per_m,
                initial_pa,
            }) => {
                m.serialize_entry(
                    "hardening_MPa_per_nm",
                    &Q(modulus_pa_per_m, Unit::PaPerMAsMpaPerNm),
                )?;
                m.serialize_entry("initial_hardness_MPa", &Q(initial_pa, Unit::PaAsMpa))?;
                m.serialize_entry(
                    "solve",
                    "implicit series compliance per load step (docs/methods.md §3.4)",
                )?;
            }
        }
        m.end()
    }
}

/// Which per-load maps a run writes (the command line's TIFFs) or keeps (Python's arrays).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MapChoice {
    /// No maps: the tables, `summary.json` and the plot only.
    None,
    /// The contact map of each load only.
    Contact,
    /// Every map of each load: contact, pressure, gap, plastic displacement, deformed surface
    /// (Greenwood–Tripp: the contact).
    #[default]
    All,
}

impl MapChoice {
    /// Every choice, in the order help texts list them.
    pub const ALL: [MapChoice; 3] = [MapChoice::None, MapChoice::Contact, MapChoice::All];

    /// The choice's name, as `summary.json` records it and the front-ends take it.
    pub fn name(self) -> &'static str {
        match self {
            MapChoice::None => "none",
            MapChoice::Contact => "contact",
            MapChoice::All => "all",
        }
    }

    /// Whether the maps other than the contact are wanted.
    pub fn all(self) -> bool {
        self == MapChoice::All
    }
}

impl std::str::FromStr for MapChoice {
    type Err = String;

    /// `none`, `contact` or `all`; the refusal lists them (the front-end adds its own name).
    fn from_str(text: &str) -> std::result::Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == text.trim())
            .ok_or_else(|| format!("{text:?} is not one of none, contact, all"))
    }
}

/// `summary.json` records the choice by its name (`"maps": "contact"`).
impl Serialize for MapChoice {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// Everything `simulate` needs. SI units.
#[derive(Debug, Clone)]
pub struct SimulateRequest {
    /// The rough body's heights.
    pub heights: HeightInput,
    /// Sphere radius to add to a flattened map (and the GT sphere), m.
    pub radius_m: Option<f64>,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// The model.
    pub model: ModelChoice,
    /// Periodic boundaries (free otherwise).
    pub periodic: bool,
    /// Normal forces, N, in order (the plastic state carries from load to load).
    pub loads_n: Vec<f64>,
    /// Relative CG tolerance.
    pub tolerance: f64,
    /// Most CG iterations per load.
    pub max_iterations: usize,
    /// Where the half-space solver runs (CPU, CUDA GPU, or a GPU when one is usable).
    pub device: DeviceChoice,
    /// Which per-load maps reach the caller (the observer hears of every load either way).
    pub maps: MapChoice,
}

impl SimulateRequest {
    /// Default relative CG tolerance.
    pub const TOLERANCE: f64 = 1e-8;
    /// Default iteration limit per load.
    pub const MAX_ITERATIONS: usize = 5000;

    /// A request with the defaults: no sphere, free boundaries, the default solver limits.
    pub fn new(
        heights: HeightInput,
        e_star_pa: f64,
        model: ModelChoice,
        loads_n: Vec<f64>,
    ) -> Self {
        SimulateRequest {
            heights,
            radius_m: None,
            e_star_pa,
            model,
            periodic: false,
            loads_n,
            tolerance: Self::TOLERANCE,
            max_iterations: Self::MAX_ITERATIONS,
            device: DeviceChoice::Cpu,
            maps: MapChoice::All,
        }
    }

    /// Every range check, the same for every front-end; each refusal names the parameter.
    pub fn check(&self) -> Result<()> {
        self.heights.check()?;
        if let Some(r) = self.radius_m {
            Quantity::Radius.check(r, Param::Radius)?;
        }
        Quantity::Modulus.check(self.e_star_pa, Param::Modulus)?;
        check_loads(&self.loads_n, Param::Loads)?;
        check_model(&self.model)?;
        check_solver(self.tolerance, self.max_iterations)?;
        if self.model == ModelChoice::GreenwoodTripp && self.radius_m.is_none() {
            return Err(Error::InvalidArgument(format!(
                "the Greenwood–Tripp model needs the sphere radius ({})",
                Param::Radius
            )));
        }
        Ok(())
    }

    fn solver_options(&self) -> SolverOptions<'static> {
        SolverOptions {
            tolerance: self.tolerance,
            max_iterations: self.max_iterations,
            monitor: None,
            ..SolverOptions::default()
        }
    }
}

/// Loads (or forces) of a ramp: at least one, each within the force range.
pub fn check_loads(loads_n: &[f64], param: Param) -> Result<()> {
    if loads_n.is_empty() {
        return Err(Error::InvalidArgument(format!("{param}: no loads given")));
    }
    for &f in loads_n {
        Quantity::Force.check(f, param)?;
    }
    Ok(())
}

/// The model's own parameters within their ranges.
pub fn check_model(model: &ModelChoice) -> Result<()> {
    match *model {
        ModelChoice::HalfSpace(Model::Hardness {
            hardness_pa,
            volume_conserving,
        }) => {
            Quantity::Hardness.check(hardness_pa, Param::Hardness)?;
            if let Some(alpha) = volume_conserving {
                if !(alpha > 0.0 && alpha <= 1.0) {
                    return Err(Error::InvalidArgument(format!(
                        "{}: the relaxation α = {alpha} must lie in (0, 1]",
                        Param::VolumeConserving
                    )));
                }
            }
        }
        ModelChoice::HalfSpace(Model::Hardening {
            modulus_pa_per_m,
            initial_pa,
        }) => {
            Quantity::Hardening.check(modulus_pa_per_m, Param::Hardening)?;
            if initial_pa != 0.0 {
                Quantity::Hardness.check(initial_pa, Param::InitialHardness)?;
            }
        }
        ModelChoice::HalfSpace(Model::Elastic) | ModelChoice::GreenwoodTripp => {}
    }
    Ok(())
}

/// The solver's stopping rule: a tolerance in (0, 0.1] and at least one iteration.
pub fn check_solver(tolerance: f64, max_iterations: usize) -> Result<()> {
    if !(tolerance > 0.0 && tolerance <= 0.1) {
        return Err(Error::InvalidArgument(format!(
            "{}: the relative tolerance {tolerance:e} must lie in (0, 0.1]",
            Param::Tolerance
        )));
    }
    if max_iterations == 0 {
        return Err(Error::InvalidArgument(format!(
            "{}: at least one iteration",
            Param::MaxIterations
        )));
    }
    Ok(())
}

/// One row of the simulated area–load table (`areas.csv`, `summary.json` `loads`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimulatedLoad {
    /// Normal force, N.
    #[serde(rename = "force_mN", serialize_with = "lab::n_as_mn")]
    pub force_n: f64,
    /// Contact area, m².
    #[serde(rename = "area_um2", serialize_with = "lab::m2_as_um2")]
    pub area_m2: f64,
    /// Contact fraction of the map.
    pub contact_fraction: f64,
    /// Force / area, Pa; NaN where the area is zero (a Greenwood–Tripp load whose bearing
    /// area covers no pixel): an empty cell in `areas.csv`, `null` in `summary.json`.
    #[serde(rename = "mean_pressure_MPa", serialize_with = "lab::pa_as_mpa")]
    pub mean_pressure_pa: f64,
    /// Largest pressure, Pa.
    #[serde(rename = "max_pressure_MPa", serialize_with = "lab::pa_as_mpa")]
    pub max_pressure_pa: f64,
    /// Rigid approach, m.
    #[serde(rename = "approach_um", serialize_with = "lab::m_as_um")]
    pub approach_m: f64,
    /// 8-connected contact patches.
    pub patches: u64,
    /// Solver iterations.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Plastic volume, m³.
    #[serde(rename = "plastic_volume_um3", serialize_with = "lab::m3_as_um3")]
    pub plastic_volume_m3: f64,
    /// Contact reaches the border of a free map.
    pub edge_contact: bool,
}

impl SimulatedLoad {
    /// The load as a point of the fit: left out with edge contact or without a contact pixel.
    pub fn load_point(&self) -> LoadPoint {
        LoadPoint {
            force_mn: self.force_n * 1e3,
            area: self.area_m2 * 1e12,
            excluded: if self.area_m2 <= 0.0 {
                Some(fits::Exclusion::NoContact)
            } else if self.edge_contact {
                Some(fits::Exclusion::EdgeContact)
            } else {
                None
            },
        }
    }
}

/// A warning for each load whose mean pressure is implausible (`fits::implausible_pressure`).
fn implausible_pressures(loads: &[SimulatedLoad]) -> Vec<String> {
    loads
        .iter()
        .filter_map(|l| {
            fits::implausible_pressure(l.mean_pressure_pa).map(|why| {
                format!(
                    "{} mN: mean pressure {} MPa is {why}; are the forces ({}), the modulus ({}) \
                     or the heights' unit right?",
                    short(l.force_n * 1e3),
                    short(l.mean_pressure_pa * 1e-6),
                    Param::Forces,
                    Param::Modulus
                )
            })
        })
        .collect()
}

/// The solver settings a summary records.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SolverFacts {
    /// The algorithm.
    pub method: &'static str,
    /// Relative tolerance.
    pub tolerance: f64,
    /// Iteration limit per load.
    pub max_iterations: usize,
    /// Where the loads were solved: "cpu", or "cuda: " and the GPU's name.
    pub device: String,
}

/// The power law A = c·N^β through the simulated areas (N in mN, A in µm²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerLaw {
    /// β.
    pub exponent: f64,
    /// Standard error of β.
    pub exponent_se: Option<f64>,
    /// c in µm²·mN^(−β).
    pub prefactor_um2: f64,
    /// R² of the log–log regression (none from fewer than three distinct forces).
    pub r_squared: Option<f64>,
    /// Loads fitted (those without edge contact and with a contact pixel).
    pub points: usize,
}

impl Serialize for PowerLaw {
    /// In SI units ([`lab::in_si`]) the prefactor is c in m²·N^(−β).
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(4))?;
        m.serialize_entry("exponent", &self.exponent)?;
        m.serialize_entry("exponent_se", &self.exponent_se)?;
        let prefactor = if lab::si() {
            self.prefactor_um2 * 1e-12 * 1e3f64.powf(self.exponent)
        } else {
            self.prefactor_um2
        };
        m.serialize_entry("prefactor_um2_per_mN_pow_exponent", &prefactor)?;
        m.serialize_entry("r_squared", &self.r_squared)?;
        m.serialize_entry("points", &self.points)?;
        m.end()
    }
}

/// What `simulate` found: `summary.json` without the command line.
#[derive(Debug, Clone, Serialize)]
pub struct SimulateOutcome {
    /// The height map and its roughness.
    pub topography: HeightFacts,
    /// Contact modulus E*, Pa.
    #[serde(rename = "contact_modulus_GPa", serialize_with = "lab::pa_as_gpa")]
    pub contact_modulus_pa: f64,
    /// The model.
    pub model: ModelChoice,
    /// The boundary conditions, in words.
    pub boundary: &'static str,
    /// The solver's settings.
    pub solver: SolverFacts,
    /// One row per load.
    pub loads: Vec<SimulatedLoad>,
    /// A = c·N^β through the loads with contact.
    pub power_law: Option<PowerLaw>,
    /// Which per-load maps were written (kept, in Python): `none`, `contact` or `all`.
    pub maps: MapChoice,
    /// Warnings (notes on the input, edge contact, empty contacts).
    pub warnings: Vec<String>,
    /// Statistics of the roughness (after detrending, before adding a sphere).
    #[serde(skip)]
    pub stats: SurfaceStats,
}

/// The maps of one solved load, as they come.
pub enum LoadMaps<'a> {
    /// A half-space model: the body (sphere included), its undeformed separation, the solution.
    HalfSpace {
        /// The rough body, sphere included.
        body: &'a Topography,
        /// Undeformed separation max(h) − h, m.
        base: &'a [f64],
        /// The load's solution: pressure, gap, plastic displacement.
        step: LoadStep,
    },
    /// Greenwood–Tripp: the bearing-area contact mask only.
    BearingArea {
        /// The roughness (no sphere).
        roughness: &'a Topography,
        /// 1 = contact, row-major.
        mask: Vec<u8>,
    },
}

impl SimulateOutcome {
    /// Whether every load is invalid (edge contact or no contact pixel): the command line exits
    /// with status 4 after writing its outputs.
    pub fn nothing_valid(&self) -> bool {
        let points: Vec<_> = self.loads.iter().map(SimulatedLoad::load_point).collect();
        fits::nothing_valid(&points)
    }
}

/// What a caller hears of each load while `simulate` runs.
pub trait LoadObserver {
    /// Load `index` (of `total`) is solved; its maps are the caller's to keep or drop (they are
    /// dropped before the next load is solved unless kept).
    fn load(&mut self, _index: usize, _total: usize, _maps: LoadMaps<'_>) -> Result<()> {
        Ok(())
    }
}

/// An observer that keeps nothing.
pub struct NoMaps;
impl LoadObserver for NoMaps {}

/// Run `simulate` in memory: check the request, read and prepare the heights, solve every load.
/// `observer` receives each load's maps, `monitor` every CG iteration (for progress displays).
pub fn run(
    request: &SimulateRequest,
    observer: &mut dyn LoadObserver,
    monitor: Option<Monitor>,
) -> Result<SimulateOutcome> {
    request.check()?;
    let (roughness, mut notes) = request.heights.read_with_notes()?;
    // A container's measurement marked periodic is solved with periodic boundaries.
    let periodic_request;
    let request = if !request.periodic && request.heights.stated_periodic()? {
        notes.push(format!(
            "{}: the container marks the measurement periodic: periodic boundaries",
            request.heights.label()
        ));
        periodic_request = SimulateRequest {
            periodic: true,
            ..request.clone()
        };
        &periodic_request
    } else {
        request
    };
    let stats = SurfaceStats::finite_differences(&roughness).map_err(|e| {
        crate::error::Error::bad_input(
            crate::error::Location::file(request.heights.label()),
            e.to_string(),
        )
    })?;
    let mut gpu = None;
    let loads = match request.model {
        ModelChoice::GreenwoodTripp => run_gt(request, &roughness, &stats, observer)?,
        ModelChoice::HalfSpace(model) => {
            let mut body = roughness.clone();
            if let Some(r) = request.radius_m {
                body.add_sphere(r)?;
            }
            gpu = request.device.open()?;
            run_halfspace(request, model, &body, stats.h_rms_m, gpu, observer, monitor)?
        }
    };
    let mut warnings = notes;
    let points: Vec<LoadPoint> = loads.iter().map(SimulatedLoad::load_point).collect();
    warnings.extend(fits::exclusion_warnings(&points, Source::Simulation));
    let (f, a) = fits::fit_points(&points);
    let power_law = fit_power_law(&f, &a);
    warnings.extend(fits::power_law_warnings(power_law.as_ref(), &points));
    if fits::nothing_valid(&points) {
        warnings.push(
            "no load is valid (see above): the loads' numbers are given, but no area–load fit \
             rests on them"
                .into(),
        );
    }
    warnings.extend(implausible_pressures(&loads));
    let (channel, fill_invalid) = request.heights.facts();
    Ok(SimulateOutcome {
        topography: HeightFacts {
            path: request.heights.label(),
            nx: roughness.nx(),
            ny: roughness.ny(),
            pixel_size_x_m: roughness.dx_m,
            pixel_size_y_m: roughness.dy_m,
            detrend: request.heights.detrend().name(),
            channel,
            fill_invalid,
            measurement: request.heights.measurement_label()?,
            roughness: Roughness::from(&stats),
            sphere_radius_m: request.radius_m,
        },
        contact_modulus_pa: request.e_star_pa,
        model: request.model,
        boundary: if request.periodic {
            "periodic (q = 0 mode zero: mean pressure imposed, approach is the multiplier)"
        } else {
            "free (2N zero padding, Love pixel kernel)"
        },
        solver: SolverFacts {
            method: "Polonsky–Keer constrained conjugate gradients, f64",
            tolerance: request.tolerance,
            max_iterations: request.max_iterations,
            device: describe(gpu),
        },
        power_law: power_law.map(|fit| PowerLaw {
            exponent: fit.exponent,
            exponent_se: fit.exponent_se,
            prefactor_um2: fit.prefactor,
            r_squared: fit.r_squared,
            points: fit.points,
        }),
        loads,
        maps: request.maps,
        warnings,
        stats,
    })
}

type Rows = Vec<SimulatedLoad>;

fn run_halfspace(
    request: &SimulateRequest,
    model: Model,
    body: &Topography,
    h_rms_m: f64,
    gpu: Option<&'static Gpu>,
    observer: &mut dyn LoadObserver,
    monitor: Option<Monitor>,
) -> Result<Rows> {
    let options = SolverOptions {
        monitor,
        gpu,
        // Gap residuals relative to the roughness (SolverOptions::gap_scale_m).
        gap_scale_m: Some(h_rms_m),
        ..request.solver_options()
    };
    let setup = Setup {
        topography: body,
        e_star_pa: request.e_star_pa,
        boundary: if request.periodic {
            Boundary::Periodic
        } else {
            Boundary::Free
        },
        model,
        options,
    };
    let base = separation(body);
    let total = request.loads_n.len();
    let mut rows = Vec::with_capacity(total);
    // Each load's maps go to the observer and its fields are dropped before the next load is
    // solved (unless the observer keeps them).
    sweep_each(&setup, &request.loads_n, &mut |i, step| {
        rows.push(row_of(body, &step));
        let maps = LoadMaps::HalfSpace {
            body,
            base: &base,
            step,
        };
        Ok(observer.load(i, total, maps)?)
    })
    .map_err(|e| match e {
        // A solver that cannot converge on this map: the message names the map.
        e @ contactscope::Error::NotConverged { .. } => crate::error::Error::bad_input(
            crate::error::Location::file(request.heights.label()),
            format!(
                "{e} on this map ({} too low, heights in another unit, or a map with steps?)",
                Param::MaxIterations
            ),
        ),
        other => other.into(),
    })?;
    Ok(rows)
}

fn row_of(body: &Topography, s: &LoadStep) -> SimulatedLoad {
    SimulatedLoad {
        force_n: s.force_n,
        area_m2: s.area_m2,
        contact_fraction: s.contact_fraction,
        mean_pressure_pa: s.mean_pressure_pa,
        max_pressure_pa: s.max_pressure_pa,
        approach_m: s.solution.approach,
        patches: s.patches,
        iterations: s.solution.iterations,
        residual: s.solution.gap_residual.max(s.solution.pressure_change),
        plastic_volume_m3: s.plastic_m.iter().sum::<f64>() * body.dx_m * body.dy_m,
        edge_contact: s.edge_contact,
    }
}

fn run_gt(
    request: &SimulateRequest,
    roughness: &Topography,
    stats: &SurfaceStats,
    observer: &mut dyn LoadObserver,
) -> Result<Rows> {
    let radius = request.radius_m.ok_or_else(|| {
        Error::InvalidArgument(format!(
            "the Greenwood–Tripp model needs the sphere radius ({})",
            Param::Radius
        ))
    })?;
    let params = GtParams::new(
        radius,
        request.e_star_pa,
        stats.h_rms_m,
        stats.h_double_prime_rms_per_m,
    );
    // A flat map (h_rms 0) has no roughness for the model: the error names the map.
    params.validate().map_err(|e| {
        crate::error::Error::bad_input(
            crate::error::Location::file(request.heights.label()),
            format!("{e} (the map is flat after detrending: no roughness for the model)"),
        )
    })?;
    let total = request.loads_n.len();
    let mut rows = Vec::new();
    for (i, &force) in request.loads_n.iter().enumerate() {
        let profile = gt_profile(&params, force)?;
        let map = gt_bearing_area(roughness, &profile, None)?;
        let mask: Vec<u8> = map.mask.iter().map(|m| u8::from(*m)).collect();
        rows.push(SimulatedLoad {
            force_n: force,
            area_m2: map.area_m2,
            contact_fraction: map.contact_fraction,
            mean_pressure_pa: if map.area_m2 > 0.0 {
                force / map.area_m2
            } else {
                f64::NAN
            },
            max_pressure_pa: profile.pressure_pa.first().copied().unwrap_or(f64::NAN),
            approach_m: profile.approach_m,
            patches: count_patches(&mask, roughness.nx()).0,
            iterations: profile.iterations,
            residual: (profile.load_n - force).abs() / force,
            plastic_volume_m3: 0.0,
            edge_contact: false,
        });
        observer.load(i, total, LoadMaps::BearingArea { roughness, mask })?;
    }
    Ok(rows)
}
