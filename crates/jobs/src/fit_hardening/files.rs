//! The outputs of `fit-hardening` as the command line writes them, through a staging folder
//! (all or nothing): `fit.json` (the outcome), `fit_areas.csv`, `sweep.csv` with a sweep, and
//! (feature `plots`) `fit_area_vs_load.png` (Fig. 3a), `misfit.png` and
//! `sweep_area_vs_load.png`.

use std::path::{Path, PathBuf};

use contactscope::model_fit::{Family, Measured, ModelFit, ProgressHook};

use super::{display, run, FitOutcome, FitRequest, MeasuredInput, SweepRow};
use crate::error::Result;
use crate::heights::HeightInput;
#[cfg(feature = "plots")]
use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::staging::Staging;
use crate::summary::summary_json;
use crate::table::csv_text;

/// Run `fit-hardening` and write its folder: the outcome and the files written.
pub fn run_to_folder(
    request: &FitRequest,
    out_dir: &Path,
    command_line: &[String],
    progress: Option<ProgressHook>,
) -> Result<(FitOutcome, Vec<PathBuf>)> {
    let outcome = run(request, progress)?;
    let mut inputs = Vec::new();
    if let MeasuredInput::File(path) = &request.measured {
        inputs.push(path.clone());
    }
    if let HeightInput::File(source) = &request.body.heights {
        inputs.push(source.path.clone());
    }
    let staging = Staging::new(out_dir, &inputs)?;
    let measured = outcome.measured.0.clone();
    let fits: Vec<ModelFit> = outcome.fits().cloned().collect();
    staging.write("fit_areas.csv", fit_csv(&measured, &fits)?.as_bytes())?;
    #[cfg(feature = "plots")]
    {
        staging.write(
            "fit_area_vs_load.png",
            &fit_chart(&measured, &fits).to_png()?,
        )?;
        if let Some(chart) = misfit_chart(&fits) {
            staging.write("misfit.png", &chart.to_png()?)?;
        }
    }
    if let Some(family) = outcome.sweep_family {
        staging.write("sweep.csv", sweep_csv(family, &outcome.sweep)?.as_bytes())?;
        #[cfg(feature = "plots")]
        staging.write(
            "sweep_area_vs_load.png",
            &sweep_chart(family, &measured, &outcome.sweep).to_png()?,
        )?;
    }
    staging.write("fit.json", &summary_json(command_line, &outcome)?)?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

fn unit(family: Family) -> &'static str {
    match family {
        Family::Hardness => "MPa",
        _ => "MPa_per_nm",
    }
}

#[cfg(feature = "plots")]
fn model_label(fit: &ModelFit) -> String {
    let name = match fit.family {
        Family::Elastic => "elastic".to_string(),
        Family::GreenwoodTripp => "Greenwood–Tripp".to_string(),
        Family::Hardness => format!(
            "hardness {:.0} MPa",
            display(Family::Hardness, fit.best.parameter.unwrap_or(f64::NAN))
        ),
        Family::Hardening => format!(
            "hardening k = {:.2} MPa/nm",
            display(Family::Hardening, fit.best.parameter.unwrap_or(f64::NAN))
        ),
    };
    let interval = match (fit.family, fit.parameter_ci95) {
        (Family::Hardening, Some((lo, hi))) => format!(
            ", 95 % {:.2}…{:.2}",
            display(fit.family, lo),
            display(fit.family, hi)
        ),
        (Family::Hardness, Some((lo, hi))) => format!(
            ", 95 % {:.0}…{:.0}",
            display(fit.family, lo),
            display(fit.family, hi)
        ),
        _ => String::new(),
    };
    format!("{name}{interval} (misfit {:.3})", fit.best.misfit)
}

fn fit_csv(measured: &Measured, fits: &[ModelFit]) -> Result<String> {
    csv_text(|w| {
        let mut header = vec!["force_mN".to_string(), "measured_area_um2".to_string()];
        header.extend(fits.iter().map(|f| format!("{}_area_um2", f.family.name())));
        w.write_record(&header)?;
        for (i, (&f, &a)) in measured.forces_n.iter().zip(&measured.areas_m2).enumerate() {
            let mut row = vec![format!("{:.6}", f * 1e3), format!("{:.6}", a * 1e12)];
            row.extend(
                fits.iter()
                    .map(|fit| format!("{:.6}", fit.best.areas_m2[i] * 1e12)),
            );
            w.write_record(&row)?;
        }
        Ok(())
    })
}

fn sweep_csv(family: Family, rows: &[SweepRow]) -> Result<String> {
    csv_text(|w| {
        w.write_record([
            format!(
                "{}_{}",
                if family == Family::Hardness {
                    "hardness"
                } else {
                    "k"
                },
                unit(family)
            ),
            "force_mN".into(),
            "measured_area_um2".into(),
            "simulated_area_um2".into(),
            "dice".into(),
        ])?;
        for r in rows {
            w.write_record([
                format!("{:.6}", display(family, r.parameter)),
                format!("{:.6}", r.force_n * 1e3),
                format!("{:.6}", r.measured_area_m2 * 1e12),
                format!("{:.6}", r.simulated_area_m2 * 1e12),
                r.dice.map_or(String::new(), |d| format!("{d:.5}")),
            ])?;
        }
        Ok(())
    })
}

#[cfg(feature = "plots")]
fn measured_points(measured: &Measured) -> PointSet {
    PointSet {
        label: "measured".into(),
        xy: measured
            .forces_n
            .iter()
            .zip(&measured.areas_m2)
            .map(|(f, a)| (f * 1e3, a * 1e12))
            .collect(),
        hollow: false,
    }
}

#[cfg(feature = "plots")]
/// Fig. 3a: measured areas and every model's best curve, log-log.
pub fn fit_chart(measured: &Measured, fits: &[ModelFit]) -> Chart {
    let mut curves: Vec<Curve> = fits
        .iter()
        .map(|fit| Curve {
            label: model_label(fit),
            xy: measured
                .forces_n
                .iter()
                .zip(&fit.best.areas_m2)
                .map(|(f, a)| (f * 1e3, a * 1e12))
                .collect(),
        })
        .collect();
    // Each measured area's 95 % interval (calibration included) as a vertical bar; a
    // non-finite vertex breaks the line between bars.
    if let Some(intervals) = measured.reported_intervals_m2() {
        let bars: Vec<(f64, f64)> = measured
            .forces_n
            .iter()
            .zip(intervals)
            .filter(|(_, (lo, hi))| *lo > 0.0 && hi > lo)
            .flat_map(|(f, (lo, hi))| {
                [
                    (f * 1e3, lo * 1e12),
                    (f * 1e3, hi * 1e12),
                    (f * 1e3, f64::NAN),
                ]
            })
            .collect();
        if !bars.is_empty() {
            curves.insert(
                0,
                Curve {
                    label: "95 % interval of the measured area".into(),
                    xy: bars,
                },
            );
        }
    }
    Chart {
        title: "Contact area vs load: experiment and models".into(),
        x_label: "normal force N (mN)".into(),
        y_label: "contact area A (µm²)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points: vec![measured_points(measured)],
        curves,
        ..Chart::default()
    }
}

#[cfg(feature = "plots")]
fn misfit_chart(fits: &[ModelFit]) -> Option<Chart> {
    let fit = fits
        .iter()
        .find(|f| f.family == Family::Hardening && !f.trace.is_empty())?;
    let mut trace = fit.trace.clone();
    trace.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(Chart {
        title: "Hardening fit: misfit vs k".into(),
        x_label: "hardening coefficient k (MPa/nm)".into(),
        y_label: "misfit: RMS of ln(simulated / measured area)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperRight,
        points: vec![PointSet {
            label: "evaluated".into(),
            xy: trace
                .iter()
                .map(|&(k, m)| (display(Family::Hardening, k), m))
                .collect(),
            hollow: false,
        }],
        curves: Vec::new(),
        ..Chart::default()
    })
}

#[cfg(feature = "plots")]
fn sweep_chart(family: Family, measured: &Measured, rows: &[SweepRow]) -> Chart {
    let mut values: Vec<f64> = rows.iter().map(|r| r.parameter).collect();
    values.dedup();
    let curves = values
        .iter()
        .map(|&v| Curve {
            label: format!(
                "{} = {:.3} {}",
                if family == Family::Hardness {
                    "hardness"
                } else {
                    "k"
                },
                display(family, v),
                unit(family).replace("_per_", "/")
            ),
            xy: rows
                .iter()
                .filter(|r| r.parameter == v)
                .map(|r| (r.force_n * 1e3, r.simulated_area_m2 * 1e12))
                .collect(),
        })
        .collect();
    Chart {
        title: format!("Parameter sweep ({} model)", family.name()),
        x_label: "normal force N (mN)".into(),
        y_label: "contact area A (µm²)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points: vec![measured_points(measured)],
        curves,
        ..Chart::default()
    }
}
