//! The `newton` job: read the two images, analyse, write `newton.json`, `newton_rings.csv`,
//! `newton_profiles.csv` and `newton_gap.png` through [`Staging`] (nothing appears on error).

use std::path::PathBuf;

use serde_json::{json, Value};

use crate::error::{Error, Result};
use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::staging::Staging;
use contactscope::numerics::stats::MeanSd;
use contactscope::optics::newton::{analyse, hertz_gap, ring_gap, NewtonAnalysis, NewtonOptions};
use contactscope_formats::microscopy::select::{read_one_image, Selection};

/// What `contactscope newton` asks for.
#[derive(Debug, Clone)]
pub struct NewtonRequest {
    /// Reflection image (Newton rings), single page.
    pub reflection: PathBuf,
    /// Fluorescence image of the contact, single page, same field.
    pub fluorescence: PathBuf,
    /// `--pixel-size` override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// The plane of each file (the same selection for both, except the channel below).
    pub selection: Selection,
    /// Channel of the fluorescence image when it differs from the reflection's (both images
    /// as two channels of one file).
    pub contact_channel: Option<usize>,
    /// Analysis choices.
    pub options: NewtonOptions,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the JSON.
    pub command_line: Vec<String>,
}

/// What `newton` produced.
#[derive(Debug, Clone)]
pub struct NewtonOutcome {
    /// The measurement.
    pub analysis: NewtonAnalysis,
    /// Files written.
    pub written: Vec<PathBuf>,
}

/// Read, analyse and write the outputs.
pub fn run_newton(request: &NewtonRequest) -> Result<NewtonOutcome> {
    let (sel, px) = (&request.selection, request.pixel_size_m);
    let reflection = read_one_image(&request.reflection, sel, px)?;
    let contact = Selection {
        channel: request.contact_channel.or(sel.channel),
        ..sel.clone()
    };
    let fluorescence = read_one_image(&request.fluorescence, &contact, px)?;
    let analysis = analyse(&reflection, &fluorescence, &request.options)?;
    let inputs = [request.reflection.clone(), request.fluorescence.clone()];
    let staging = Staging::new(&request.out_dir, &inputs)?;
    let text = serde_json::to_string_pretty(&summary_json(request, &analysis))
        .expect("JSON values serialise");
    staging.write("newton.json", text.as_bytes())?;
    staging.write("newton_rings.csv", &rings_csv(&analysis)?)?;
    staging.write("newton_profiles.csv", &profiles_csv(&analysis)?)?;
    staging.write("newton_gap.png", &gap_chart(&analysis).to_png()?)?;
    let written = staging.commit()?;
    Ok(NewtonOutcome { analysis, written })
}

fn nm(v: Option<f64>) -> Option<f64> {
    v.map(|x| x * 1e9)
}

fn um(v: Option<f64>) -> Option<f64> {
    v.map(|x| x * 1e6)
}

fn spread_json(s: &MeanSd, scale: f64) -> (f64, Option<f64>) {
    (s.mean * scale, s.sd.map(|sd| sd * scale))
}

fn summary_json(request: &NewtonRequest, a: &NewtonAnalysis) -> Value {
    let o = &request.options;
    let (gap_mean, gap_sd) = spread_json(&a.detection_gap_m, 1e9);
    let (edge_mean, edge_sd) = spread_json(&a.edge_radius_m, 1e6);
    let (a_mean, a_sd) = spread_json(&a.contact_radius_m, 1e6);
    let (r_mean, r_sd) = spread_json(&a.sphere_radius_m, 1e3);
    let (cx, cy) = a.contact.centre_px;
    let orders = (0..6).map(|m| m + o.phase.first_order());
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "inputs": {
            "reflection": request.reflection.display().to_string(),
            "fluorescence": request.fluorescence.display().to_string(),
            "pixel_size_x_um": a.pixel_m.0 * 1e6,
            "pixel_size_y_um": a.pixel_m.1 * 1e6,
        },
        "detection_gap_nm_mean": gap_mean,
        "detection_gap_nm_sd": gap_sd,
        "edge_radius_um": edge_mean,
        "edge_radius_um_sd": edge_sd,
        "contact_radius_a_um_mean": a_mean,
        "contact_radius_a_um_sd": a_sd,
        "sphere_radius_R_mm_mean": r_mean,
        "sphere_radius_R_mm_sd": r_sd,
        "profiles_used": a.used().count(),
        "profiles_total": a.profiles.len(),
        "profiles_needed": o.min_profiles.min(o.profiles),
        "centre_x_px": cx,
        "centre_y_px": cy,
        "centre_x_um": cx * a.pixel_m.0 * 1e6,
        "centre_y_um": cy * a.pixel_m.1 * 1e6,
        "fluorescence_threshold": a.contact.threshold,
        "fluorescence_contact_pixels": a.contact.pixels,
        "wavelength_nm": o.wavelength_m * 1e9,
        "medium_index": o.medium_index,
        "phase": o.phase.name(),
        "ring_gaps_nm": orders.map(|m| json!({
            "order": m,
            "gap_nm": ring_gap(m, o.wavelength_m, o.medium_index, o.phase) * 1e9,
        })).collect::<Vec<_>>(),
        "method": {
            "centre": "centroid of the largest 8-connected region above the exact Otsu threshold of the fluorescence image",
            "line_width_px": o.line_width_px,
            "smoothing_sigma_px": o.smoothing_px,
            "edge": "half-way between the inside and outside plateaus (medians beyond the margin), linearly interpolated",
            "edge_margin_um": o.edge_margin_m * 1e6,
            "ring_orders": format!("innermost ring outside the fluorescent edge is m = {}; further orders where r² extrapolated from the last two rings puts them", o.phase.first_order()),
            "gap_model": "Hertz exterior gap (Johnson 1985), a and R free, a ≤ edge radius",
            "max_rms_residual_nm": o.max_rms_residual_m * 1e9,
        },
        "profiles": a.profiles.iter().map(|p| json!({
            "profile": p.index,
            "angle_deg": p.angle_deg,
            "rings": p.rings.len(),
            "edge_radius_um": um(p.edge_radius_m()),
            "half_lines_used": p.sides_used().iter().filter(|&&u| u).count(),
            "a_um": um(p.fit.map(|f| f.contact_radius_m)),
            "R_mm": p.fit.map(|f| f.sphere_radius_m * 1e3),
            "rms_residual_nm": nm(p.fit.map(|f| f.rms_residual_m)),
            "shifted_rms_residual_nm": nm(p.shifted_fit.map(|f| f.rms_residual_m)),
            "shifted_residual_ratio": p.shifted_residual_ratio(),
            "detection_gap_nm": nm(p.detection_gap_m),
            "used": p.skipped.is_none(),
            "skipped_reason": p.skipped,
        })).collect::<Vec<_>>(),
        "skipped_profiles": a.profiles.iter().filter_map(|p| p.skipped.as_ref().map(|why| json!({
            "profile": p.index,
            "angle_deg": p.angle_deg,
            "reason": why,
        }))).collect::<Vec<_>>(),
    })
}

fn csv_error(e: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("CSV: {e}"))
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| x.to_string())
}

fn rings_csv(a: &NewtonAnalysis) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "profile",
        "angle_deg",
        "side",
        "order",
        "r_um",
        "gap_nm",
        "fit_gap_nm",
        "used",
    ])
    .map_err(csv_error)?;
    for p in &a.profiles {
        for ring in &p.rings {
            let fitted = p.fit.map(|f| f.gap_at(ring.radius_m) * 1e9);
            w.write_record([
                p.index.to_string(),
                p.angle_deg.to_string(),
                if ring.side > 0 { "+" } else { "-" }.to_string(),
                ring.order.to_string(),
                (ring.radius_m * 1e6).to_string(),
                (ring.gap_m * 1e9).to_string(),
                opt(fitted),
                p.skipped.is_none().to_string(),
            ])
            .map_err(csv_error)?;
        }
    }
    w.into_inner().map_err(csv_error)
}

fn profiles_csv(a: &NewtonAnalysis) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "profile",
        "angle_deg",
        "rings",
        "edge_radius_um",
        "a_um",
        "R_mm",
        "rms_residual_nm",
        "shifted_residual_ratio",
        "detection_gap_nm",
        "used",
        "skipped_reason",
    ])
    .map_err(csv_error)?;
    for p in &a.profiles {
        w.write_record([
            p.index.to_string(),
            p.angle_deg.to_string(),
            p.rings.len().to_string(),
            opt(um(p.edge_radius_m())),
            opt(um(p.fit.map(|f| f.contact_radius_m))),
            opt(p.fit.map(|f| f.sphere_radius_m * 1e3)),
            opt(nm(p.fit.map(|f| f.rms_residual_m))),
            opt(p.shifted_residual_ratio()),
            opt(nm(p.detection_gap_m)),
            p.skipped.is_none().to_string(),
            p.skipped.clone().unwrap_or_default(),
        ])
        .map_err(csv_error)?;
    }
    w.into_inner().map_err(csv_error)
}

/// Gap versus radius: every ring point of the used profiles, the Hertz gap with the mean a and
/// R, and the mean edge radius as a vertical line.
fn gap_chart(a: &NewtonAnalysis) -> Chart {
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
    }
}
