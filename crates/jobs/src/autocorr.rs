//! The `autocorr` job: radially averaged intensity autocorrelations of several images (an
//! experiment and a simulation, say) as one CSV, one JSON of correlation lengths and one linear
//! plot with a curve per image, so they can be compared as in Weber et al. 2018 (patch scale
//! ≈ 5 µm). The estimator and its choices are in [`contactscope::spectral::autocorrelation`].

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use crate::error::{Error, Location, Result};
use crate::plot::{Axes, Chart, Curve, Legend};
use crate::staging::Staging;
use contactscope::image::Image;
use contactscope_formats::microscopy::select::{read_images, Selection};

use contactscope::spectral::autocorrelation::AcfCurve;

/// Everything `autocorr` needs, already parsed.
#[derive(Debug, Clone)]
pub struct AutocorrRequest {
    /// Image files; every page of a multi-page file is one image.
    pub inputs: Vec<PathBuf>,
    /// Which plane of confocal files (and the channel of TIFFs).
    pub selection: Selection,
    /// Pixel size override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// Largest lag, m; by default half the smaller side of each image.
    pub max_lag_m: Option<f64>,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the JSON.
    pub command_line: Vec<String>,
}

/// What `autocorr` computed and wrote.
#[derive(Debug, Clone)]
pub struct AutocorrOutcome {
    /// One curve per image, in input order.
    pub curves: Vec<AcfCurve>,
    /// Files written.
    pub written: Vec<PathBuf>,
    /// Notes for the user (lags clamped, …).
    pub warnings: Vec<String>,
}

/// Run `autocorr`: read every image, compute its curve, write `autocorr.csv`, `autocorr.json`
/// and `autocorr.png` into the output folder (all or nothing).
pub fn run_autocorr(request: &AutocorrRequest) -> Result<AutocorrOutcome> {
    if request.inputs.is_empty() {
        return Err(Error::InvalidArgument("no input images given".into()));
    }
    let mut images = Vec::new();
    for path in &request.inputs {
        let pages = read_images(path, &request.selection, None, request.pixel_size_m)?;
        let multi = pages.len() > 1;
        images.extend(pages.into_iter().map(|im| (label_of(&im, multi), im)));
    }
    let mut warnings = Vec::new();
    let mut curves = Vec::new();
    let mut facts = Vec::new();
    for (label, image) in &images {
        let (curve, fact) = image_curve(label, image, request.max_lag_m, &mut warnings)?;
        curves.push(curve);
        facts.push(fact);
    }
    let staging = Staging::new(&request.out_dir, &request.inputs)?;
    staging.write("autocorr.csv", curves_csv(&curves)?.as_bytes())?;
    let summary = summary_json(request, &curves, &facts, &warnings);
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    staging.write("autocorr.json", text.as_bytes())?;
    staging.write(
        "autocorr.png",
        &acf_chart(&curves, "Radially averaged intensity autocorrelation").to_png()?,
    )?;
    Ok(AutocorrOutcome {
        curves,
        written: staging.commit()?,
        warnings,
    })
}

fn label_of(image: &Image, multi_page: bool) -> String {
    let name = image.path.file_name().map_or_else(
        || image.path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    if multi_page {
        format!("{name}:page {}", image.page)
    } else {
        name
    }
}

/// Per-image facts for the JSON beside the curve.
struct ImageFacts {
    path: PathBuf,
    page: usize,
    size: (usize, usize),
    pixel_m: (f64, f64),
    max_lag_m: f64,
}

fn image_curve(
    label: &str,
    image: &Image,
    max_lag_m: Option<f64>,
    warnings: &mut Vec<String>,
) -> Result<(AcfCurve, ImageFacts)> {
    let px = image.require_pixel_size()?;
    let half_side = 0.5 * (image.width as f64 * px.x_m).min(image.height as f64 * px.y_m);
    let lag = match max_lag_m {
        Some(l) if l > half_side => {
            warnings.push(format!(
                "{label}: --max-lag {:.3} µm exceeds half the image ({:.3} µm), where the estimate \
                 rests on few pixel pairs; using {:.3} µm",
                l * 1e6,
                half_side * 1e6,
                half_side * 1e6
            ));
            half_side
        }
        Some(l) => l,
        None => half_side,
    };
    let at = Location::page(&image.path, image.page);
    let curve = AcfCurve::of_grid(
        label,
        &image.values,
        (image.width, image.height),
        (px.x_m, px.y_m),
        lag,
    )
    .map_err(|e| Error::bad_input(at, e.to_string()))?;
    if curve.xi_1e_m.is_none() {
        warnings.push(format!(
            "{label}: C(r) stays above 1/e up to {:.3} µm; no correlation length within the lags",
            lag * 1e6
        ));
    }
    let facts = ImageFacts {
        path: image.path.clone(),
        page: image.page,
        size: (image.width, image.height),
        pixel_m: (px.x_m, px.y_m),
        max_lag_m: lag,
    };
    Ok((curve, facts))
}

/// Long-format table: `image, lag_um, acf`.
pub fn curves_csv(curves: &[AcfCurve]) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    w.write_record(["image", "lag_um", "acf"])
        .map_err(csv_err)?;
    for curve in curves {
        for &(r, c) in &curve.profile {
            w.write_record([
                curve.label.clone(),
                format!("{:.6}", r * 1e6),
                format!("{c:.8}"),
            ])
            .map_err(csv_err)?;
        }
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

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
    }
}

fn summary_json(
    request: &AutocorrRequest,
    curves: &[AcfCurve],
    facts: &[ImageFacts],
    warnings: &[String],
) -> Value {
    let um = |m: Option<f64>| m.map(|v| v * 1e6);
    let images: Vec<Value> = curves
        .iter()
        .zip(facts)
        .map(|(c, f)| {
            json!({
                "image": c.label,
                "file": path_text(&f.path),
                "page": f.page,
                "width_px": f.size.0,
                "height_px": f.size.1,
                "pixel_size_x_nm": f.pixel_m.0 * 1e9,
                "pixel_size_y_nm": f.pixel_m.1 * 1e9,
                "max_lag_um": f.max_lag_m * 1e6,
                "correlation_length_um_1e": um(c.xi_1e_m),
                "first_zero_um": um(c.first_zero_m),
            })
        })
        .collect();
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "method": {
            "estimator": "mean-subtracted intensity, zero-padded FFT (no wrap-around), unbiased: divided by the pair count per lag, C(0) = 1",
            "radial_average": "rings one pixel wide, weighted by pair counts; lags with under a quarter of the zero-lag pairs dropped",
            "correlation_length_um_1e": "first lag with C <= 1/e, linear interpolation",
            "first_zero_um": "first lag with C <= 0, linear interpolation; null if C stays positive",
        },
        "images": images,
        "warnings": warnings,
    })
}

fn path_text(path: &Path) -> String {
    path.display().to_string()
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
