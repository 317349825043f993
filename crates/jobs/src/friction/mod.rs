//! The `friction` job: rheometer trace CSVs (and optionally `analyze`'s `areas.csv`) in; slip, μ
//! and the τ of F_s = τ·A per [`contactscope::mechanics::friction`] out. Every front-end builds a
//! [`FrictionRequest`] (the command line from its arguments, Python from its keywords),
//! [`FrictionRequest::check`] applies the same range checks to both, and [`run`] returns a
//! [`FrictionOutcome`], whose serialisation is `summary.json` (lab units) and the Python result
//! (SI units, [`crate::lab`]). [`files`] writes `friction.csv`, `summary.json` and the plots.

pub mod files;

use std::path::{Path, PathBuf};

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use contactscope::mechanics::friction::{
    detect_slip, fit_shear_strength, mu_trend, MuTrend, ShearFit, Slip, SlipCriterion, SlipOptions,
    XAxis,
};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::{Error, Location, Result};
use crate::lab::{self, OptQ, Unit, Q};
use crate::mechanics_csv::read_trace;
use crate::results::read_areas_csv;

/// Everything `friction` needs. SI units.
#[derive(Debug, Clone)]
pub struct FrictionRequest {
    /// Trace CSV files (format in [`crate::mechanics_csv`]).
    pub traces: Vec<PathBuf>,
    /// N for traces without a normal-force column, N.
    pub normal_force_n: Option<f64>,
    /// Rotation radius of the sphere for torque traces, m.
    pub rotation_radius_m: Option<f64>,
    /// `analyze` output `areas.csv` (`force_mN`, `area_um2`), for F = τ·A.
    pub areas: Option<PathBuf>,
    /// Largest relative difference between a trace's N and an area row's force, in [0, 1).
    pub force_tolerance: f64,
    /// Slip detection settings.
    pub slip: SlipOptions,
}

impl FrictionRequest {
    /// Default largest relative difference between a trace's N and an area row's force (2 %).
    pub const FORCE_TOLERANCE: f64 = 0.02;

    /// A request with the defaults: N from the traces' columns, no torque, no areas, 2 %
    /// force tolerance, the default slip detection.
    pub fn new(traces: Vec<PathBuf>) -> Self {
        FrictionRequest {
            traces,
            normal_force_n: None,
            rotation_radius_m: None,
            areas: None,
            force_tolerance: Self::FORCE_TOLERANCE,
            slip: SlipOptions::default(),
        }
    }

    /// Every range check, the same for every front-end; each refusal names the parameter.
    pub fn check(&self) -> Result<()> {
        if self.traces.is_empty() {
            return Err(Error::InvalidArgument("no friction traces given".into()));
        }
        if let Some(n) = self.normal_force_n {
            Quantity::Force.check(n, Param::NormalForce)?;
        }
        if let Some(r) = self.rotation_radius_m {
            Quantity::Length.check(r, Param::RotationRadius)?;
        }
        if !(0.0..1.0).contains(&self.force_tolerance) {
            return Err(Error::InvalidArgument(format!(
                "{}: {} is not a fraction in [0, 1) such as 0.01",
                Param::ForceTolerance,
                self.force_tolerance
            )));
        }
        Ok(())
    }
}

/// Result for one trace (`summary.json` `traces`, one row of `friction.csv`).
#[derive(Debug, Clone, PartialEq)]
pub struct TraceResult {
    /// The trace file.
    pub file: PathBuf,
    /// Its x axis.
    pub x_axis: XAxis,
    /// Normal force N, N.
    pub normal_force_n: f64,
    /// The slip event.
    pub slip: Slip,
    /// Matched real contact area, m² (with areas).
    pub area_m2: Option<f64>,
}

impl TraceResult {
    /// μ_s = F_s / N.
    pub fn mu_static(&self) -> f64 {
        self.slip.static_friction_n / self.normal_force_n
    }

    /// μ_k = F_k / N.
    pub fn mu_kinetic(&self) -> f64 {
        self.slip.kinetic_friction_n / self.normal_force_n
    }

    /// The slip position and its unit: in the trace's column unit (`um`, `rad`, `s`), or in SI
    /// units (`m`, `rad`, `s`) inside [`lab::in_si`].
    fn slip_at(&self) -> (f64, &'static str) {
        if lab::si() {
            let unit = match self.x_axis {
                XAxis::Displacement => "m",
                XAxis::Angle => "rad",
                XAxis::Time => "s",
            };
            (self.slip.x, unit)
        } else {
            (
                self.x_axis.to_column_unit(self.slip.x),
                self.x_axis.slip_column().trim_start_matches("slip_at_"),
            )
        }
    }
}

impl Serialize for TraceResult {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let (slip_at, slip_unit) = self.slip_at();
        let mut m = s.serialize_map(Some(13))?;
        m.serialize_entry("file", &self.file.display().to_string())?;
        m.serialize_entry("normal_force_mN", &Q(self.normal_force_n, Unit::NAsMn))?;
        m.serialize_entry(
            "static_friction_mN",
            &Q(self.slip.static_friction_n, Unit::NAsMn),
        )?;
        m.serialize_entry(
            "kinetic_friction_mN",
            &Q(self.slip.kinetic_friction_n, Unit::NAsMn),
        )?;
        m.serialize_entry("slip_at", &slip_at)?;
        m.serialize_entry("slip_at_unit", slip_unit)?;
        m.serialize_entry("slip_sample", &self.slip.index)?;
        m.serialize_entry("slip_criterion", self.slip.criterion.name())?;
        m.serialize_entry("mu_static", &self.mu_static())?;
        m.serialize_entry("mu_kinetic", &self.mu_kinetic())?;
        m.serialize_entry("noise_mN", &Q(self.slip.noise_n, Unit::NAsMn))?;
        m.serialize_entry(
            "drop_threshold_mN",
            &Q(self.slip.drop_threshold_n, Unit::NAsMn),
        )?;
        m.serialize_entry("area_um2", &OptQ(self.area_m2, Unit::M2AsUm2))?;
        m.end()
    }
}

/// What `friction` found: `summary.json` without the version and the command line.
#[derive(Debug, Clone)]
pub struct FrictionOutcome {
    /// The request it answers (its inputs and slip settings are recorded).
    pub request: FrictionRequest,
    /// One result per trace, in input order.
    pub traces: Vec<TraceResult>,
    /// F_s = τ·A (with areas).
    pub shear: Option<ShearFit>,
    /// F_k = τ_k·A (with areas).
    pub kinetic_shear: Option<ShearFit>,
    /// μ_s versus N (two or more distinct loads).
    pub mu_trend: Option<MuTrend>,
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// A shear-strength fit as `summary.json` records it.
struct ShearJson<'a>(&'a ShearFit);

impl Serialize for ShearJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let f = self.0;
        let mut m = s.serialize_map(Some(4))?;
        m.serialize_entry("tau_MPa", &Q(f.tau_pa, Unit::PaAsMpa))?;
        m.serialize_entry("tau_se_MPa", &OptQ(f.tau_se_pa, Unit::PaAsMpa))?;
        m.serialize_entry("r2", &f.r_squared)?;
        m.serialize_entry("points", &f.points)?;
        m.end()
    }
}

/// The trend of μ_s with N as `summary.json` records it.
struct TrendJson<'a>(&'a MuTrend);

impl Serialize for TrendJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let t = self.0;
        let mut m = s.serialize_map(Some(4))?;
        m.serialize_entry("exponent", &t.exponent)?;
        m.serialize_entry("exponent_se", &t.exponent_se)?;
        m.serialize_entry("relative_spread", &t.relative_spread)?;
        m.serialize_entry("varies", &t.varies)?;
        m.end()
    }
}

/// The request's inputs as `summary.json` records them (`inputs`).
struct InputsJson<'a>(&'a FrictionRequest);

impl Serialize for InputsJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let r = self.0;
        let mut m = s.serialize_map(Some(5))?;
        let traces: Vec<String> = r.traces.iter().map(|p| p.display().to_string()).collect();
        m.serialize_entry("traces", &traces)?;
        m.serialize_entry("areas", &r.areas.as_ref().map(|p| p.display().to_string()))?;
        m.serialize_entry("normal_force_mN", &OptQ(r.normal_force_n, Unit::NAsMn))?;
        m.serialize_entry(
            "rotation_radius_mm",
            &OptQ(r.rotation_radius_m, Unit::MAsMm),
        )?;
        m.serialize_entry(
            "force_tolerance_pct",
            &Q(r.force_tolerance, Unit::FractionAsPct),
        )?;
        m.end()
    }
}

/// How the numbers were found (`method`), with the slip detection settings.
struct MethodJson<'a>(&'a SlipOptions);

impl Serialize for MethodJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let o = self.0;
        let mut m = s.serialize_map(Some(10))?;
        m.serialize_entry("static_friction", "denoised force at the onset of slip: the first running maximum of the running-median force after which its median over 4h+1 samples stays more than max(k*noise, f*range) lower; onset = last raw sample before the steep part of the drop; line fit through the raw samples up to the onset, evaluated there; without a drop, where the centred slope over +-5h samples stays below 0.1 of the loading slope (criterion plateau, F_s = F_k)")?;
        m.serialize_entry(
            "kinetic_friction",
            "median raw force from the first minimum after the slip drop to the end of the trace",
        )?;
        m.serialize_entry("noise", "1.4826*MAD of second differences / sqrt(6)")?;
        m.serialize_entry("smoothing_half_width", &o.smoothing_half_width)?;
        m.serialize_entry("drop_noise_levels", &o.drop_noise_levels)?;
        m.serialize_entry("min_drop_fraction", &o.min_drop_fraction)?;
        m.serialize_entry("torque_to_force", "F = T / rotation radius")?;
        m.serialize_entry("shear_strength", "F_s = tau*A, least squares in F through the origin; se = sqrt(SS_res/(n-1)/sum A^2); r2 about the mean")?;
        m.serialize_entry(
            "mu_trend",
            "mu_static = c*N^m by log-log least squares; m = 0 is Amontons' law; varies when |m| > 2 se",
        )?;
        m.end()
    }
}

impl Serialize for FrictionOutcome {
    /// `summary.json` (lab units), or the Python result inside [`lab::in_si`].
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let shear = self.shear;
        let mut m = s.serialize_map(Some(10))?;
        m.serialize_entry("inputs", &InputsJson(&self.request))?;
        m.serialize_entry("method", &MethodJson(&self.request.slip))?;
        m.serialize_entry("tau_MPa", &OptQ(shear.map(|f| f.tau_pa), Unit::PaAsMpa))?;
        m.serialize_entry(
            "tau_se_MPa",
            &OptQ(shear.and_then(|f| f.tau_se_pa), Unit::PaAsMpa),
        )?;
        m.serialize_entry("r2", &shear.and_then(|f| f.r_squared))?;
        m.serialize_entry("static_shear_fit", &self.shear.as_ref().map(ShearJson))?;
        m.serialize_entry(
            "kinetic_shear_fit",
            &self.kinetic_shear.as_ref().map(ShearJson),
        )?;
        m.serialize_entry("mu_static_vs_load", &self.mu_trend.as_ref().map(TrendJson))?;
        m.serialize_entry("traces", &self.traces)?;
        m.serialize_entry("warnings", &self.warnings)?;
        m.end()
    }
}

/// Run `friction` in memory: check the request, analyse every trace, match areas, fit τ.
/// Nothing is written.
pub fn run(request: &FrictionRequest) -> Result<FrictionOutcome> {
    request.check()?;
    let mut warnings = Vec::new();
    let mut traces = request
        .traces
        .iter()
        .map(|path| analyse_trace(path, request, &mut warnings))
        .collect::<Result<Vec<_>>>()?;
    // Physics checks (`crate::physics`): μ outside any dry contact's range names the likely unit.
    for t in &traces {
        for (kind, mu) in [("static", t.mu_static()), ("kinetic", t.mu_kinetic())] {
            if let Some(w) = crate::physics::check(crate::physics::Checked::FrictionCoefficient, mu)
            {
                warnings.push(format!("{}: {kind} {w}", t.file.display()));
            }
        }
    }
    if let Some(path) = &request.areas {
        let areas = read_areas_csv(path)?;
        match_areas(&mut traces, &areas, request.force_tolerance, path)?;
    }
    let fit = |f: fn(&TraceResult) -> f64| {
        let a: Vec<f64> = traces.iter().filter_map(|t| t.area_m2).collect();
        let y: Vec<f64> = traces
            .iter()
            .filter(|t| t.area_m2.is_some())
            .map(f)
            .collect();
        fit_shear_strength(&a, &y)
    };
    let shear = fit(|t| t.slip.static_friction_n);
    let kinetic_shear = fit(|t| t.slip.kinetic_friction_n);
    let normals: Vec<f64> = traces.iter().map(|t| t.normal_force_n).collect();
    let mus: Vec<f64> = traces.iter().map(TraceResult::mu_static).collect();
    let trend = mu_trend(&normals, &mus);
    Ok(FrictionOutcome {
        request: request.clone(),
        traces,
        shear,
        kinetic_shear,
        mu_trend: trend,
        warnings,
    })
}

fn analyse_trace(
    path: &Path,
    request: &FrictionRequest,
    warnings: &mut Vec<String>,
) -> Result<TraceResult> {
    let trace = read_trace(path, request.rotation_radius_m)?;
    let at = || Location::file(path);
    let normal_force_n = match (trace.normal_force_n, request.normal_force_n) {
        (Some(column), given) => {
            if let Some(given) =
                given.filter(|f| (column / f - 1.0).abs() > request.force_tolerance)
            {
                warnings.push(format!(
                    "{}: the normal-force column ({:.4} mN) differs from {} ({:.4} mN); using the column",
                    path.display(),
                    column * 1e3,
                    Param::NormalForce,
                    given * 1e3
                ));
            }
            column
        }
        (None, Some(given)) => given,
        (None, None) => {
            return Err(Error::bad_input(
                at(),
                format!(
                    "no normal_force_mN or normal_force_N column; give {} (e.g. 40mN)",
                    Param::NormalForce
                ),
            ))
        }
    };
    if normal_force_n <= 0.0 || !normal_force_n.is_finite() {
        return Err(Error::bad_input(
            at(),
            format!(
                "normal force {:.4} mN must be positive",
                normal_force_n * 1e3
            ),
        ));
    }
    let slip = detect_slip(&trace.x, &trace.friction_n, &request.slip).ok_or_else(|| {
        Error::bad_input(
            at(),
            "no slip found: the friction force never drops clearly below a preceding maximum (or the trace ends during the drop)",
        )
    })?;
    if slip.criterion == SlipCriterion::Plateau {
        warnings.push(format!(
            "{}: no drop after the peak; slip taken where the loading slope collapses (plateau), so static = kinetic friction",
            path.display()
        ));
    }
    Ok(TraceResult {
        file: path.to_path_buf(),
        x_axis: trace.x_axis,
        normal_force_n,
        slip,
        area_m2: None,
    })
}

/// Give each trace the area of the row with the nearest force, within `tolerance` (relative).
fn match_areas(
    traces: &mut [TraceResult],
    areas: &[(f64, f64)],
    tolerance: f64,
    path: &Path,
) -> Result<()> {
    for t in traces.iter_mut() {
        let n = t.normal_force_n;
        let nearest = areas
            .iter()
            .min_by(|a, b| (a.0 - n).abs().total_cmp(&(b.0 - n).abs()))
            .filter(|a| (a.0 / n - 1.0).abs() <= tolerance);
        t.area_m2 = nearest.map(|a| a.1);
    }
    if traces.iter().all(|t| t.area_m2.is_some()) {
        return Ok(());
    }
    let list = |v: Vec<f64>| {
        v.iter()
            .map(|f| format!("{:.4}", f * 1e3))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let unmatched: Vec<String> = traces
        .iter()
        .filter(|t| t.area_m2.is_none())
        .map(|t| t.file.display().to_string())
        .collect();
    Err(Error::bad_input(
        Location::file(path),
        format!(
            "mismatched forces: no area row within {:.2} % for {}; trace forces {} mN, areas.csv forces {} mN",
            tolerance * 100.0,
            unmatched.join(", "),
            list(traces.iter().map(|t| t.normal_force_n).collect()),
            list(areas.iter().map(|a| a.0).collect()),
        ),
    ))
}
