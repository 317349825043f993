//! The outputs of `autocorr` as the command line writes them, through a staging folder
//! (nothing appears unless everything succeeded): `autocorr.csv` (the curves, long format),
//! `autocorr.json` (the outcome) and `autocorr.png` (feature `plots`).

use std::path::{Path, PathBuf};

use contactscope::spectral::autocorrelation::AcfCurve;

use super::{run, AutocorrOutcome, AutocorrRequest};
use crate::error::Result;
use crate::images::input_files;
#[cfg(feature = "plots")]
use crate::plot::{Axes, Chart, Curve, Legend};
use crate::staging::Staging;
use crate::summary::summary_json;
use crate::table::csv_text;

/// Run `autocorr` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &AutocorrRequest,
    out_dir: &Path,
    command_line: &[String],
) -> Result<(AutocorrOutcome, Vec<PathBuf>)> {
    let outcome = run(request)?;
    let staging = Staging::new(out_dir, &input_files(&request.inputs))?;
    staging.write("autocorr.csv", curves_csv(&outcome.curves)?.as_bytes())?;
    staging.write("autocorr.json", &summary_json(command_line, &outcome)?)?;
    #[cfg(feature = "plots")]
    staging.write(
        "autocorr.png",
        &acf_chart(
            &outcome.curves,
            "Radially averaged intensity autocorrelation",
        )
        .to_png()?,
    )?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// Long-format table: `image, lag_um, acf`.
pub fn curves_csv(curves: &[AcfCurve]) -> Result<String> {
    csv_text(|w| {
        w.write_record(["image", "lag_um", "acf"])?;
        for curve in curves {
            for &(r, c) in &curve.profile {
                w.write_record([
                    curve.label.clone(),
                    format!("{:.6}", r * 1e6),
                    format!("{c:.8}"),
                ])?;
            }
        }
        Ok(())
    })
}

#[cfg(feature = "plots")]
/// All curves on one linear chart against lag in µm, with the 1/e level as a guide.
pub fn acf_chart(curves: &[AcfCurve], title: &str) -> Chart {
    let max_lag_um = curves
        .iter()
        .filter_map(|c| c.profile.last())
        .map(|&(r, _)| r * 1e6)
        .fold(0.0, f64::max);
    let mut lines: Vec<Curve> = curves
        .iter()
        .map(|c| Curve {
            label: match c.xi_1e_m {
                Some(xi) => format!("{} (ξ₁/ₑ = {:.2} µm)", c.label, xi * 1e6),
                None => c.label.clone(),
            },
            xy: c.profile.iter().map(|&(r, v)| (r * 1e6, v)).collect(),
        })
        .collect();
    lines.push(Curve {
        label: "1/e".into(),
        xy: vec![(0.0, (-1.0f64).exp()), (max_lag_um, (-1.0f64).exp())],
    });
    Chart {
        title: title.to_string(),
        x_label: "lag r (µm)".into(),
        y_label: "autocorrelation C(r)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperRight,
        points: Vec::new(),
        curves: lines,
        ..Chart::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(points: &[(f64, f64)]) -> AcfCurve {
        AcfCurve {
            label: "c".into(),
            profile: points.to_vec(),
            xi_1e_m: None,
            first_zero_m: None,
        }
    }

    #[test]
    fn interpolation_and_distance() {
        let a = curve(&[(0.0, 1.0), (1.0, 0.5), (2.0, 0.0)]);
        assert_eq!(a.at(0.5), Some(0.75));
        assert_eq!(a.at(3.0), None);
        assert_eq!(a.rms_distance(&a), Some(0.0));
        let b = curve(&[(0.0, 0.9), (4.0, 0.9)]);
        // Differences 0.1, −0.4, −0.9 at lags 0, 1, 2.
        let expected = ((0.01 + 0.16 + 0.81) / 3.0f64).sqrt();
        assert!((a.rms_distance(&b).unwrap() - expected).abs() < 1e-12);
        assert_eq!(a.rms_distance(&curve(&[(5.0, 1.0), (6.0, 1.0)])), None);
    }

    #[test]
    fn csv_is_long_format_with_units() {
        let text = curves_csv(&[curve(&[(0.0, 1.0), (2e-7, 0.5)])]).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "image,lag_um,acf");
        assert_eq!(lines[2], "c,0.200000,0.50000000");
    }
}
