//! The `friction` job: trace CSVs (and optionally `analyze`'s `areas.csv`) in; slip, μ and the
//! τ of F_s = τ·A per [`contactscope::mechanics::friction`]; `friction.csv`, `summary.json` and plots
//! out.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use crate::error::{Error, Location, Result};
use crate::mechanics_csv::read_trace;
use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::results::read_areas_csv;
use crate::staging::Staging;
use contactscope::mechanics::friction::{
    detect_slip, fit_shear_strength, mu_trend, MuTrend, ShearFit, Slip, SlipCriterion, SlipOptions,
    XAxis,
};

/// Everything `friction` needs, already parsed.
#[derive(Debug, Clone)]
pub struct FrictionRequest {
    /// Trace CSV files.
    pub traces: Vec<PathBuf>,
    /// N for traces without a normal-force column, N.
    pub normal_force_n: Option<f64>,
    /// Rotation radius of the sphere for torque traces, m.
    pub rotation_radius_m: Option<f64>,
    /// `analyze` output `areas.csv` (`force_mN`, `area_um2`), for F = τ·A.
    pub areas: Option<PathBuf>,
    /// Largest relative difference between a trace's N and an area row's force.
    pub force_tolerance: f64,
    /// Slip detection settings.
    pub slip: SlipOptions,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the JSON.
    pub command_line: Vec<String>,
}

/// Result for one trace.
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
    /// Matched real contact area, m² (with `--areas`).
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
}

/// What `friction` computed and wrote.
#[derive(Debug, Clone)]
pub struct FrictionOutcome {
    /// One result per trace, in input order.
    pub traces: Vec<TraceResult>,
    /// F_s = τ·A (with areas).
    pub shear: Option<ShearFit>,
    /// F_k = τ_k·A (with areas).
    pub kinetic_shear: Option<ShearFit>,
    /// μ_s versus N (two or more distinct loads).
    pub mu_trend: Option<MuTrend>,
    /// Files written.
    pub written: Vec<PathBuf>,
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// Run `friction`: analyse every trace, match areas, fit τ, and write `friction.csv`,
/// `summary.json`, `friction_vs_load.png`, `mu_vs_load.png` and (with areas)
/// `friction_vs_area.png` into the output folder, all or nothing.
pub fn run_friction(request: &FrictionRequest) -> Result<FrictionOutcome> {
    if request.traces.is_empty() {
        return Err(Error::InvalidArgument("no friction traces given".into()));
    }
    let mut warnings = Vec::new();
    let mut traces = request
        .traces
        .iter()
        .map(|path| analyse_trace(path, request, &mut warnings))
        .collect::<Result<Vec<_>>>()?;
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
    let mut outcome = FrictionOutcome {
        traces,
        shear,
        kinetic_shear,
        mu_trend: trend,
        written: Vec::new(),
        warnings,
    };
    outcome.written = write_outputs(request, &outcome)?;
    Ok(outcome)
}

fn analyse_trace(
    path: &Path,
    request: &FrictionRequest,
    warnings: &mut Vec<String>,
) -> Result<TraceResult> {
    let trace = read_trace(path, request.rotation_radius_m)?;
    let at = || Location::file(path);
    let normal_force_n = match (trace.normal_force_n, request.normal_force_n) {
        (Some(column), flag) => {
            if let Some(flag) = flag.filter(|f| (column / f - 1.0).abs() > request.force_tolerance)
            {
                warnings.push(format!(
                    "{}: the normal-force column ({:.4} mN) differs from --normal-force ({:.4} mN); using the column",
                    path.display(),
                    column * 1e3,
                    flag * 1e3
                ));
            }
            column
        }
        (None, Some(flag)) => flag,
        (None, None) => {
            return Err(Error::bad_input(
                at(),
                "no normal_force_mN or normal_force_N column; give --normal-force (e.g. 40mN)",
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

fn write_outputs(request: &FrictionRequest, outcome: &FrictionOutcome) -> Result<Vec<PathBuf>> {
    let mut inputs = request.traces.clone();
    inputs.extend(request.areas.iter().cloned());
    let staging = Staging::new(&request.out_dir, &inputs)?;
    staging.write("friction.csv", results_csv(&outcome.traces)?.as_bytes())?;
    let text = serde_json::to_string_pretty(&summary_json(request, outcome))
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    staging.write("summary.json", text.as_bytes())?;
    staging.write(
        "friction_vs_load.png",
        &load_chart(&outcome.traces, outcome.shear.as_ref()).to_png()?,
    )?;
    staging.write("mu_vs_load.png", &mu_chart(&outcome.traces).to_png()?)?;
    if let Some(fit) = &outcome.shear {
        staging.write(
            "friction_vs_area.png",
            &area_chart(&outcome.traces, fit).to_png()?,
        )?;
    }
    staging.commit()
}

/// `friction.csv`: one row per trace; every number's unit is in its column name. Slip positions
/// go in the column of the trace's own x unit (`slip_at_um`, `slip_at_rad`, `slip_at_s`).
pub fn results_csv(traces: &[TraceResult]) -> Result<String> {
    let axes: Vec<XAxis> = XAxis::ALL
        .into_iter()
        .filter(|a| traces.iter().any(|t| t.x_axis == *a))
        .collect();
    let with_area = traces.iter().any(|t| t.area_m2.is_some());
    let mut header = vec![
        "file".to_string(),
        "normal_force_mN".into(),
        "static_friction_mN".into(),
        "kinetic_friction_mN".into(),
    ];
    header.extend(axes.iter().map(|a| a.slip_column().to_string()));
    header.extend([
        "mu_static".into(),
        "mu_kinetic".into(),
        "noise_mN".into(),
        "slip_criterion".into(),
    ]);
    if with_area {
        header.extend(["area_um2".into(), "shear_stress_MPa".into()]);
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    w.write_record(&header).map_err(csv_err)?;
    for t in traces {
        w.write_record(result_row(t, &axes, with_area))
            .map_err(csv_err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

fn result_row(t: &TraceResult, axes: &[XAxis], with_area: bool) -> Vec<String> {
    let mut row = vec![
        t.file.display().to_string(),
        format!("{:.6}", t.normal_force_n * 1e3),
        format!("{:.6}", t.slip.static_friction_n * 1e3),
        format!("{:.6}", t.slip.kinetic_friction_n * 1e3),
    ];
    row.extend(axes.iter().map(|a| {
        if *a == t.x_axis {
            format!("{:.6}", a.to_column_unit(t.slip.x))
        } else {
            String::new()
        }
    }));
    row.extend([
        format!("{:.6}", t.mu_static()),
        format!("{:.6}", t.mu_kinetic()),
        format!("{:.6}", t.slip.noise_n * 1e3),
        t.slip.criterion.name().to_string(),
    ]);
    if with_area {
        match t.area_m2 {
            Some(a) => row.extend([
                format!("{:.6}", a * 1e12),
                format!("{:.6}", t.slip.static_friction_n / a * 1e-6),
            ]),
            None => row.extend([String::new(), String::new()]),
        }
    }
    row
}

fn shear_json(fit: &Option<ShearFit>) -> Value {
    match fit {
        Some(f) => json!({
            "tau_MPa": f.tau_pa * 1e-6,
            "tau_se_MPa": f.tau_se_pa.map(|s| s * 1e-6),
            "r2": f.r_squared,
            "points": f.points,
        }),
        None => Value::Null,
    }
}

fn summary_json(request: &FrictionRequest, outcome: &FrictionOutcome) -> Value {
    let traces: Vec<Value> = outcome
        .traces
        .iter()
        .map(|t| {
            json!({
                "file": t.file.display().to_string(),
                "normal_force_mN": t.normal_force_n * 1e3,
                "static_friction_mN": t.slip.static_friction_n * 1e3,
                "kinetic_friction_mN": t.slip.kinetic_friction_n * 1e3,
                "slip_at": t.x_axis.to_column_unit(t.slip.x),
                "slip_at_unit": t.x_axis.slip_column().trim_start_matches("slip_at_"),
                "slip_sample": t.slip.index,
                "slip_criterion": t.slip.criterion.name(),
                "mu_static": t.mu_static(),
                "mu_kinetic": t.mu_kinetic(),
                "noise_mN": t.slip.noise_n * 1e3,
                "drop_threshold_mN": t.slip.drop_threshold_n * 1e3,
                "area_um2": t.area_m2.map(|a| a * 1e12),
            })
        })
        .collect();
    let shear = outcome.shear;
    let trend = outcome.mu_trend.map(|m| {
        json!({
            "exponent": m.exponent,
            "exponent_se": m.exponent_se,
            "relative_spread": m.relative_spread,
            "varies": m.varies,
        })
    });
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "inputs": {
            "traces": request.traces.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "areas": request.areas.as_ref().map(|p| p.display().to_string()),
            "normal_force_mN": request.normal_force_n.map(|n| n * 1e3),
            "rotation_radius_mm": request.rotation_radius_m.map(|r| r * 1e3),
            "force_tolerance_pct": request.force_tolerance * 100.0,
        },
        "method": {
            "static_friction": "denoised force at the onset of slip: the first running maximum of the running-median force after which its median over 4h+1 samples stays more than max(k*noise, f*range) lower; onset = last raw sample before the steep part of the drop; line fit through the raw samples up to the onset, evaluated there; without a drop, where the centred slope over +-5h samples stays below 0.1 of the loading slope (criterion plateau, F_s = F_k)",
            "kinetic_friction": "median raw force from the first minimum after the slip drop to the end of the trace",
            "noise": "1.4826*MAD of second differences / sqrt(6)",
            "smoothing_half_width": request.slip.smoothing_half_width,
            "drop_noise_levels": request.slip.drop_noise_levels,
            "min_drop_fraction": request.slip.min_drop_fraction,
            "torque_to_force": "F = T / rotation radius",
            "shear_strength": "F_s = tau*A, least squares in F through the origin; se = sqrt(SS_res/(n-1)/sum A^2); r2 about the mean",
            "mu_trend": "mu_static = c*N^m by log-log least squares; m = 0 is Amontons' law; varies when |m| > 2 se",
        },
        "tau_MPa": shear.map(|f| f.tau_pa * 1e-6),
        "tau_se_MPa": shear.and_then(|f| f.tau_se_pa).map(|s| s * 1e-6),
        "r2": shear.and_then(|f| f.r_squared),
        "static_shear_fit": shear_json(&outcome.shear),
        "kinetic_shear_fit": shear_json(&outcome.kinetic_shear),
        "mu_static_vs_load": trend,
        "traces": traces,
        "warnings": outcome.warnings,
    })
}

/// Friction against normal force (Fig. 3b of the paper), with τ·A at each load's measured area
/// when τ was fitted.
fn load_chart(traces: &[TraceResult], shear: Option<&ShearFit>) -> Chart {
    let pts = |f: fn(&Slip) -> f64| {
        traces
            .iter()
            .map(|t| (t.normal_force_n * 1e3, f(&t.slip) * 1e3))
            .collect()
    };
    Chart {
        title: "Friction versus normal force".into(),
        x_label: "normal force N (mN)".into(),
        y_label: "friction force F (mN)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperLeft,
        points: vec![
            PointSet {
                label: "static F_s".into(),
                xy: pts(|s| s.static_friction_n),
            },
            PointSet {
                label: "kinetic F_k".into(),
                xy: pts(|s| s.kinetic_friction_n),
            },
        ],
        curves: shear
            .map(|fit| tau_area_curve(traces, fit))
            .into_iter()
            .collect(),
    }
}

/// τ·A at the traces' areas, in order of normal force.
fn tau_area_curve(traces: &[TraceResult], fit: &ShearFit) -> Curve {
    let mut xy: Vec<(f64, f64)> = traces
        .iter()
        .filter_map(|t| {
            t.area_m2
                .map(|a| (t.normal_force_n * 1e3, fit.tau_pa * a * 1e3))
        })
        .collect();
    xy.sort_by(|a, b| a.0.total_cmp(&b.0));
    Curve {
        label: format!("τ·A, τ = {:.1} MPa", fit.tau_pa * 1e-6),
        xy,
    }
}

fn mu_chart(traces: &[TraceResult]) -> Chart {
    let pts = |f: fn(&TraceResult) -> f64| {
        traces
            .iter()
            .map(|t| (t.normal_force_n * 1e3, f(t)))
            .collect()
    };
    Chart {
        title: "Friction coefficient versus normal force".into(),
        x_label: "normal force N (mN)".into(),
        y_label: "friction coefficient μ = F/N".into(),
        axes: Axes::Linear,
        legend: Legend::UpperRight,
        points: vec![
            PointSet {
                label: "μ static".into(),
                xy: pts(TraceResult::mu_static),
            },
            PointSet {
                label: "μ kinetic".into(),
                xy: pts(TraceResult::mu_kinetic),
            },
        ],
        curves: Vec::new(),
    }
}

fn area_chart(traces: &[TraceResult], fit: &ShearFit) -> Chart {
    let xy: Vec<(f64, f64)> = traces
        .iter()
        .filter_map(|t| {
            t.area_m2
                .map(|a| (a * 1e12, t.slip.static_friction_n * 1e3))
        })
        .collect();
    let a_max = xy.iter().map(|p| p.0).fold(0.0, f64::max) * 1.05;
    // τ [MPa] · A [µm²] = τ·A [µN] = 1e-3 · τ·A [mN].
    let tau_mpa = fit.tau_pa * 1e-6;
    Chart {
        title: "Static friction versus real contact area".into(),
        x_label: "real contact area A (µm²)".into(),
        y_label: "static friction F_s (mN)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperLeft,
        points: vec![PointSet {
            label: "measured".into(),
            xy,
        }],
        curves: vec![Curve {
            label: format!("F = τ·A, τ = {tau_mpa:.1} MPa"),
            xy: vec![(0.0, 0.0), (a_max, tau_mpa * a_max * 1e-3)],
        }],
    }
}
