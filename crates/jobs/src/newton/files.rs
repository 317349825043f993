//! The outputs of `newton` as the command line writes them, through a staging folder (nothing
//! appears unless everything succeeded): `newton.json` (the outcome without `rings`),
//! `newton_rings.csv` (the outcome's `rings`), `newton_profiles.csv` (its `profiles`, less two
//! columns) and `newton_gap.png` (feature `plots`).

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::{run, NewtonOutcome, NewtonRequest};
use crate::error::{Error, Result};
use crate::images::input_files;
use crate::staging::Staging;
use crate::summary::summary_json_without;
use crate::table::rows_csv;

/// Run `newton` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &NewtonRequest,
    out_dir: &Path,
    command_line: &[String],
) -> Result<(NewtonOutcome, Vec<PathBuf>)> {
    let outcome = run(request)?;
    let inputs = input_files([&request.reflection, &request.fluorescence]);
    let staging = Staging::new(out_dir, &inputs)?;
    staging.write(
        "newton.json",
        &summary_json_without(command_line, &outcome, &["rings"])?,
    )?;
    staging.write("newton_rings.csv", &rings_csv(&outcome)?)?;
    staging.write("newton_profiles.csv", &profiles_csv(&outcome)?)?;
    #[cfg(feature = "plots")]
    staging.write("newton_gap.png", &gap_chart(&outcome).to_png()?)?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// `newton_rings.csv`: one row per ring maximum.
pub fn rings_csv(outcome: &NewtonOutcome) -> Result<Vec<u8>> {
    if outcome.rings.is_empty() {
        return Ok(b"profile,angle_deg,side,order,r_um,gap_nm,fit_gap_nm,used\n".to_vec());
    }
    rows_csv(&outcome.rings, &[])
}

/// Columns of `profiles` that `newton_profiles.csv` leaves out.
const NOT_IN_PROFILES_CSV: [&str; 2] = ["half_lines_used", "shifted_rms_residual_nm"];

/// `newton_profiles.csv`: one row per profile, the columns of `profiles` in `newton.json` but
/// the half-lines used and the shifted fit's residual.
pub fn profiles_csv(outcome: &NewtonOutcome) -> Result<Vec<u8>> {
    let rows = outcome
        .profiles
        .iter()
        .map(|p| {
            let mut row =
                serde_json::to_value(p).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
            if let Value::Object(fields) = &mut row {
                for key in NOT_IN_PROFILES_CSV {
                    fields.shift_remove(key);
                }
            }
            Ok(row)
        })
        .collect::<Result<Vec<Value>>>()?;
    rows_csv(&rows, &[])
}

/// Gap versus radius: every ring point of the used profiles, the Hertz gap with the mean a and
/// R, and the mean edge radius as a vertical line.
#[cfg(feature = "plots")]
fn gap_chart(outcome: &NewtonOutcome) -> crate::plot::Chart {
    use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
    use contactscope::optics::newton::hertz_gap;
    let a = &outcome.analysis;
    let points: Vec<(f64, f64)> = a
        .used()
        .flat_map(|p| p.rings.iter().map(|r| (r.radius_m * 1e6, r.gap_m * 1e9)))
        .collect();
    let r_max = points.iter().map(|p| p.0).fold(0.0, f64::max) * 1e-6;
    let (ca, cr) = (a.contact_radius_m.mean, a.sphere_radius_m.mean);
    let start = ca.min(a.edge_radius_m.mean);
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|i| start + (r_max - start) * i as f64 / 200.0)
        .map(|r| (r * 1e6, hertz_gap(r, ca, cr) * 1e9))
        .collect();
    let top = points.iter().map(|p| p.1).fold(0.0, f64::max);
    let edge_um = a.edge_radius_m.mean * 1e6;
    Chart {
        title: format!(
            "Newton rings: detection gap {:.1} nm at r = {:.2} µm",
            a.detection_gap_m.mean * 1e9,
            edge_um
        ),
        x_label: "distance from the contact centre r (µm)".into(),
        y_label: "gap (nm)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperLeft,
        points: vec![PointSet {
            label: format!("ring maxima, {} profiles", a.used().count()),
            xy: points,
            hollow: false,
        }],
        curves: vec![
            Curve {
                label: format!("Hertz gap, a = {:.2} µm, R = {:.1} µm", ca * 1e6, cr * 1e6),
                xy: curve,
            },
            Curve {
                label: "fluorescent edge".into(),
                xy: vec![(edge_um, 0.0), (edge_um, top)],
            },
        ],
        ..Chart::default()
    }
}
