//! The `hertz` job: a squeeze-test CSV in; E* from [`contactscope::mechanics::squeeze`] and predicted
//! Hertz contact radii; `hertz.json`, `hertz_fit.csv` and `squeeze_fit.png` out.

use std::path::PathBuf;

use serde_json::{json, Value};

use crate::error::{Error, Result};
use crate::mechanics_csv::read_squeeze;
use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::staging::Staging;
use contactscope::mechanics::hertz;
use contactscope::mechanics::squeeze::{
    check_radius, fit_hertz, fit_hertz_with_offset, HertzFit, SqueezePoint,
};

/// Everything `hertz` needs, already parsed.
#[derive(Debug, Clone)]
pub struct HertzRequest {
    /// The squeeze CSV.
    pub input: PathBuf,
    /// Sphere radius R, m.
    pub radius_m: f64,
    /// Loads at which to predict the contact radius, N; the measured forces when `None`.
    pub loads_n: Option<Vec<f64>>,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the JSON.
    pub command_line: Vec<String>,
}

/// What `hertz` computed and wrote.
#[derive(Debug, Clone)]
pub struct HertzOutcome {
    /// Points used (P > 0).
    pub points: Vec<SqueezePoint>,
    /// Fit through the origin (the main result).
    pub fit: HertzFit,
    /// Fit with a free contact offset, when there are enough points.
    pub offset_fit: Option<HertzFit>,
    /// (load N, Hertz contact radius m) pairs.
    pub predicted: Vec<(f64, f64)>,
    /// Files written.
    pub written: Vec<PathBuf>,
}

/// Run `hertz`: read, fit, predict a = (3PR/4E*)^(1/3) (paper Eq. 3) and write `hertz.json`,
/// `hertz_fit.csv` and `squeeze_fit.png` (all or nothing).
pub fn run_hertz(request: &HertzRequest) -> Result<HertzOutcome> {
    check_radius(request.radius_m)?;
    let points = read_squeeze(&request.input)?;
    let fit = fit_hertz(&points, request.radius_m)?;
    let offset_fit = fit_hertz_with_offset(&points, request.radius_m).ok();
    let loads = match &request.loads_n {
        Some(l) => l.clone(),
        None => points.iter().map(|p| p.force_n).collect(),
    };
    if let Some(bad) = loads.iter().find(|l| !(**l > 0.0 && l.is_finite())) {
        return Err(Error::InvalidArgument(format!(
            "load {bad:e} N must be positive"
        )));
    }
    let predicted = loads
        .iter()
        .map(|&p| (p, hertz::contact_radius(p, request.radius_m, fit.e_star_pa)))
        .collect();
    let mut outcome = HertzOutcome {
        points,
        fit,
        offset_fit,
        predicted,
        written: Vec::new(),
    };
    outcome.written = write_outputs(request, &outcome)?;
    Ok(outcome)
}

fn write_outputs(request: &HertzRequest, outcome: &HertzOutcome) -> Result<Vec<PathBuf>> {
    let staging = Staging::new(&request.out_dir, std::slice::from_ref(&request.input))?;
    let text = serde_json::to_string_pretty(&summary_json(request, outcome))
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    staging.write("hertz.json", text.as_bytes())?;
    staging.write(
        "hertz_fit.csv",
        fit_csv(&outcome.points, &outcome.fit)?.as_bytes(),
    )?;
    staging.write(
        "squeeze_fit.png",
        &fit_chart(&outcome.points, &outcome.fit, request.radius_m).to_png()?,
    )?;
    staging.commit()
}

/// `hertz_fit.csv`: force_mN, displacement_um, delta_um, fitted_force_mN, residual_mN.
pub fn fit_csv(points: &[SqueezePoint], fit: &HertzFit) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    w.write_record([
        "force_mN",
        "displacement_um",
        "delta_um",
        "fitted_force_mN",
        "residual_mN",
    ])
    .map_err(csv_err)?;
    for ((p, f), r) in points.iter().zip(&fit.fitted_n).zip(fit.residuals(points)) {
        w.write_record([
            format!("{:.9}", p.force_n * 1e3),
            format!("{:.9}", p.displacement_m * 1e6),
            format!("{:.9}", p.delta_m() * 1e6),
            format!("{:.9}", f * 1e3),
            format!("{:.9}", r * 1e3),
        ])
        .map_err(csv_err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

fn fit_json(fit: &HertzFit) -> Value {
    json!({
        "contact_modulus_GPa": fit.e_star_pa * 1e-9,
        "contact_modulus_se_GPa": fit.e_star_se_pa * 1e-9,
        "r2": fit.r_squared,
        "contact_offset_displacement_um": 2.0 * fit.offset_m * 1e6,
    })
}

fn summary_json(request: &HertzRequest, outcome: &HertzOutcome) -> Value {
    let fit = &outcome.fit;
    let predicted: Vec<Value> = outcome
        .predicted
        .iter()
        .map(|&(p, a)| {
            json!({
                "force_mN": p * 1e3,
                "contact_radius_um": a * 1e6,
                "contact_area_um2": std::f64::consts::PI * a * a * 1e12,
            })
        })
        .collect();
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "input": request.input.display().to_string(),
        "radius_um": request.radius_m * 1e6,
        "method": {
            "law": "P = (4/3) E* R^(1/2) delta^(3/2), delta = displacement/2 (two contacts in series); Johnson 1985 eq. 4.23. The paper's printed Eq. 2 lacks the square on E* and is not dimensionally consistent.",
            "fit": "least squares in P of P on delta^(3/2) through the origin (unweighted); se from sqrt(SS_res/(n-1)/sum x^2); r2 about the mean",
            "offset_fit": "same, with P = (4/3) E* R^(1/2) (delta - delta0)^(3/2) and delta0 minimising the residual (reported separately)",
            "contact_radius": "a = (3PR/4E*)^(1/3) (paper Eq. 3)",
        },
        "points_used": outcome.points.len(),
        "contact_modulus_GPa": fit.e_star_pa * 1e-9,
        "contact_modulus_se_GPa": fit.e_star_se_pa * 1e-9,
        "r2": fit.r_squared,
        "max_abs_residual_mN": fit.residuals(&outcome.points).iter().fold(0.0f64, |m, r| m.max(r.abs())) * 1e3,
        "offset_fit": outcome.offset_fit.as_ref().map(fit_json),
        "predicted": predicted,
    })
}

fn fit_chart(points: &[SqueezePoint], fit: &HertzFit, radius_m: f64) -> Chart {
    let max_disp = points.iter().map(|p| p.displacement_m).fold(0.0, f64::max);
    let curve: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let disp = max_disp * 1.05 * i as f64 / 100.0;
            let p = hertz::force_at_approach(0.5 * disp, radius_m, fit.e_star_pa);
            (disp * 1e6, p * 1e3)
        })
        .collect();
    Chart {
        title: "Squeeze test: Hertz fit".into(),
        x_label: "plate displacement 2δ (µm)".into(),
        y_label: "force P (mN)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperLeft,
        points: vec![PointSet {
            label: "measured".into(),
            xy: points
                .iter()
                .map(|p| (p.displacement_m * 1e6, p.force_n * 1e3))
                .collect(),
        }],
        curves: vec![Curve {
            label: format!(
                "Hertz, E* = {:.3} ± {:.3} GPa",
                fit.e_star_pa * 1e-9,
                fit.e_star_se_pa * 1e-9
            ),
            xy: curve,
        }],
    }
}
