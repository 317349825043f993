//! The outputs of `psf` as the command line writes them, through a staging folder (nothing
//! appears unless everything succeeded): `beads.csv` (the outcome's `beads`), `psf.json` (the
//! rest of the outcome) and `psf_profiles.png` (feature `plots`).

use std::path::{Path, PathBuf};

use serde_json::Value;

use super::{run, PsfOutcome, PsfRequest};
use crate::error::Result;
use crate::images::input_files;
use crate::staging::Staging;
use crate::summary::summary_json_without;
use crate::table::{rows_csv, CellFormat};

/// Run `psf` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &PsfRequest,
    out_dir: &Path,
    command_line: &[String],
) -> Result<(PsfOutcome, Vec<PathBuf>)> {
    let outcome = run(request)?;
    let staging = Staging::new(out_dir, &input_files([&request.beads]))?;
    staging.write("beads.csv", &beads_csv(&outcome)?)?;
    #[cfg(feature = "plots")]
    staging.write("psf_profiles.png", &profiles_chart(&outcome).to_png()?)?;
    staging.write(
        "psf.json",
        &summary_json_without(command_line, &outcome, &["beads"])?,
    )?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// A number with `D` decimals (an empty cell for `null`).
fn fixed<const D: usize>(v: &Value) -> String {
    v.as_f64().map_or_else(String::new, |x| format!("{x:.D$}"))
}

/// `beads.csv`: one row per candidate, positions and widths with fixed decimals.
pub fn beads_csv(outcome: &PsfOutcome) -> Result<Vec<u8>> {
    let formats: [(&str, CellFormat); 14] = [
        ("x_px", fixed::<4>),
        ("y_px", fixed::<4>),
        ("x_um", fixed::<5>),
        ("y_um", fixed::<5>),
        ("background", fixed::<2>),
        ("centroid_x_px", fixed::<4>),
        ("centroid_y_px", fixed::<4>),
        ("sigma_nm", fixed::<3>),
        ("fwhm_nm", fixed::<3>),
        ("sigma_raw_nm", fixed::<3>),
        ("sigma_x_nm", fixed::<3>),
        ("sigma_y_nm", fixed::<3>),
        ("ellipticity", fixed::<4>),
        ("fit_rms_rel", fixed::<5>),
    ];
    rows_csv(&outcome.beads, &formats)
}

/// Beads drawn in `psf_profiles.png` at most (the legend stays readable).
#[cfg(feature = "plots")]
const MAX_PLOTTED_BEADS: usize = 8;

/// The radial profiles of the first used beads, normalised, with their Gaussian fits.
#[cfg(feature = "plots")]
fn profiles_chart(outcome: &PsfOutcome) -> crate::plot::Chart {
    use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
    let report = &outcome.report;
    let used: Vec<_> = report
        .beads
        .iter()
        .enumerate()
        .filter(|(_, b)| b.skip.is_none())
        .collect();
    let shown = used.len().min(MAX_PLOTTED_BEADS);
    let px_nm = report.pixel_size.x_m * 1e9;
    let mut chart = Chart {
        title: if used.len() > shown {
            format!(
                "PSF from beads: radial profiles (first {shown} of {} used beads)",
                used.len()
            )
        } else {
            format!(
                "PSF from beads: radial profiles ({shown} bead{})",
                if shown == 1 { "" } else { "s" }
            )
        },
        x_label: "radius r (nm)".into(),
        y_label: "normalised intensity (I − c)/I0".into(),
        axes: Axes::Linear,
        legend: Legend::UpperRight,
        ..Chart::default()
    };
    for (k, &(i, b)) in used.iter().take(shown).enumerate() {
        let Some(fit) = b.fit.as_ref() else { continue };
        let r = &fit.radial;
        chart.points.push(PointSet {
            label: format!("bead {i} (plane {})", b.candidate.plane),
            xy: r
                .profile
                .iter()
                .map(|&(rr, v)| (rr * px_nm, (v - r.offset) / r.amplitude))
                .collect(),
            hollow: false,
        });
        let r_max = r.profile.last().map_or(0.0, |p| p.0);
        chart.curves.push(Curve {
            label: if k == 0 {
                "Gaussian fits".into()
            } else {
                String::new()
            },
            xy: (0..=100)
                .map(|i| {
                    let rr = r_max * i as f64 / 100.0;
                    (
                        rr * px_nm,
                        (-rr * rr / (2.0 * r.sigma_px * r.sigma_px)).exp(),
                    )
                })
                .collect(),
        });
    }
    chart
}
