//! The outputs of `hertz` as the command line writes them, through a staging folder (nothing
//! appears unless everything succeeded): `hertz.json` (the [`HertzOutcome`] without `points`),
//! `hertz_fit.csv` (the points) and, with feature `plots`, `squeeze_fit.png`.

use std::path::{Path, PathBuf};

use super::{run, FitPoint, HertzOutcome, HertzRequest};
use crate::error::Result;
use crate::staging::Staging;
use crate::summary::summary_json_without;
use crate::table::csv_text;

/// Run `hertz` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &HertzRequest,
    out_dir: &Path,
    command_line: &[String],
) -> Result<(HertzOutcome, Vec<PathBuf>)> {
    let outcome = run(request)?;
    let staging = Staging::new(out_dir, std::slice::from_ref(&request.input))?;
    staging.write(
        "hertz.json",
        &summary_json_without(command_line, &outcome, &["points"])?,
    )?;
    staging.write("hertz_fit.csv", fit_csv(&outcome.fit_points())?.as_bytes())?;
    #[cfg(feature = "plots")]
    staging.write("squeeze_fit.png", &fit_chart(&outcome).to_png()?)?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// `hertz_fit.csv`: force_mN, displacement_um, delta_um, fitted_force_mN, residual_mN, nine
/// decimals each.
pub fn fit_csv(points: &[FitPoint]) -> Result<String> {
    csv_text(|w| {
        w.write_record([
            "force_mN",
            "displacement_um",
            "delta_um",
            "fitted_force_mN",
            "residual_mN",
        ])?;
        for p in points {
            w.write_record([
                format!("{:.9}", p.force_n * 1e3),
                format!("{:.9}", p.displacement_m * 1e6),
                format!("{:.9}", p.delta_m * 1e6),
                format!("{:.9}", p.fitted_force_n * 1e3),
                format!("{:.9}", p.residual_n * 1e3),
            ])?;
        }
        Ok(())
    })
}

/// The measured points and the Hertz curve of the fit through the origin.
#[cfg(feature = "plots")]
fn fit_chart(outcome: &HertzOutcome) -> crate::plot::Chart {
    use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
    use contactscope::mechanics::hertz;
    let (points, fit) = (&outcome.points, &outcome.fit);
    let max_disp = points.iter().map(|p| p.displacement_m).fold(0.0, f64::max);
    let curve: Vec<(f64, f64)> = (0..=100)
        .map(|i| {
            let disp = max_disp * 1.05 * i as f64 / 100.0;
            let p = hertz::force_at_approach(0.5 * disp, outcome.radius_m, fit.e_star_pa);
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
            hollow: false,
        }],
        curves: vec![Curve {
            label: format!(
                "Hertz, E* = {} GPa",
                crate::table::value_pm(fit.e_star_pa * 1e-9, fit.e_star_se_pa * 1e-9)
            ),
            xy: curve,
        }],
        ..Chart::default()
    }
}
