//! The outputs of `friction` as the command line writes them, through a staging folder (nothing
//! appears unless everything succeeded): `friction.csv` (one row per trace), `summary.json` (the
//! [`FrictionOutcome`]) and, with feature `plots`, `friction_vs_load.png`, `mu_vs_load.png` and
//! (with areas) `friction_vs_area.png`.

use std::path::{Path, PathBuf};

use contactscope::mechanics::friction::XAxis;

use super::{run, FrictionOutcome, FrictionRequest, TraceResult};
use crate::error::Result;
use crate::staging::Staging;
use crate::summary::summary_json;
use crate::table::csv_text;

/// Run `friction` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &FrictionRequest,
    out_dir: &Path,
    command_line: &[String],
) -> Result<(FrictionOutcome, Vec<PathBuf>)> {
    let outcome = run(request)?;
    let mut inputs = request.traces.clone();
    inputs.extend(request.areas.iter().cloned());
    let staging = Staging::new(out_dir, &inputs)?;
    staging.write("friction.csv", results_csv(&outcome.traces)?.as_bytes())?;
    staging.write("summary.json", &summary_json(command_line, &outcome)?)?;
    #[cfg(feature = "plots")]
    {
        staging.write(
            "friction_vs_load.png",
            &plots::load_chart(&outcome.traces, outcome.shear.as_ref()).to_png()?,
        )?;
        staging.write(
            "mu_vs_load.png",
            &plots::mu_chart(&outcome.traces).to_png()?,
        )?;
        if let Some(fit) = &outcome.shear {
            staging.write(
                "friction_vs_area.png",
                &plots::area_chart(&outcome.traces, fit).to_png()?,
            )?;
        }
    }
    let written = staging.commit()?;
    Ok((outcome, written))
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
    csv_text(|w| {
        w.write_record(&header)?;
        for t in traces {
            w.write_record(result_row(t, &axes, with_area))?;
        }
        Ok(())
    })
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

#[cfg(feature = "plots")]
mod plots {
    use contactscope::mechanics::friction::{ShearFit, Slip};

    use super::TraceResult;
    use crate::plot::{Axes, Chart, Curve, Legend, PointSet};

    /// Friction against normal force (Fig. 3b of the paper), with τ·A at each load's measured
    /// area when τ was fitted.
    pub(super) fn load_chart(traces: &[TraceResult], shear: Option<&ShearFit>) -> Chart {
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
                    hollow: false,
                },
                PointSet {
                    label: "kinetic F_k".into(),
                    xy: pts(|s| s.kinetic_friction_n),
                    hollow: false,
                },
            ],
            curves: shear
                .map(|fit| tau_area_curve(traces, fit))
                .into_iter()
                .collect(),
            ..Chart::default()
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

    pub(super) fn mu_chart(traces: &[TraceResult]) -> Chart {
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
                    hollow: false,
                },
                PointSet {
                    label: "μ kinetic".into(),
                    xy: pts(TraceResult::mu_kinetic),
                    hollow: false,
                },
            ],
            curves: Vec::new(),
            ..Chart::default()
        }
    }

    pub(super) fn area_chart(traces: &[TraceResult], fit: &ShearFit) -> Chart {
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
                hollow: false,
            }],
            curves: vec![Curve {
                label: format!("F = τ·A, τ = {tau_mpa:.1} MPa"),
                xy: vec![(0.0, 0.0), (a_max, tau_mpa * a_max * 1e-3)],
            }],
            ..Chart::default()
        }
    }
}
