//! What the QC page and the series table flag: the things that make a series' numbers doubtful,
//! found late if at all when an archive is read one series at a time (`docs/outputs.md` lists
//! each flag with its rule).

use serde::Serialize;

use super::outliers;
use super::record::{Record, Status};

/// R² of the log–log power law below which a fit is weak.
pub const WEAK_FIT_R2: f64 = 0.95;
/// Fewest points of a power law that is not weak.
pub const WEAK_FIT_POINTS: usize = 3;
/// Relative difference between a given pixel size and the file's own beyond which it is flagged.
pub const PIXEL_SIZE_TOLERANCE: f64 = 0.01;

/// One flag: a short code (for filtering) and what it means for this series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Flag {
    /// `failed`, `edge_contact`, `weak_fit`, `threshold_outlier`, `archive_outlier`,
    /// `pixel_size_default`,
    /// `pixel_size_vs_metadata`, `no_pixel_size`, `no_forces`, `physics`, `warnings`,
    /// `fit_warnings`.
    pub code: &'static str,
    /// In words, with this series' numbers.
    pub text: String,
}

/// Every code, in the order they are listed.
pub const CODES: &[&str] = &[
    "failed",
    "edge_contact",
    "weak_fit",
    "threshold_outlier",
    "archive_outlier",
    "pixel_size_default",
    "pixel_size_vs_metadata",
    "no_pixel_size",
    "no_forces",
    "physics",
    "warnings",
    "fit_warnings",
];

/// The flags of each series (in the order of `records`); `groups` names each series' sample
/// for the archive-wide comparison ([`outliers`]; empty: the whole archive).
pub fn flags(records: &[&Record], groups: &[String]) -> Vec<Vec<Flag>> {
    let far = outliers::find(records, groups);
    records
        .iter()
        .zip(far)
        .map(|(r, far)| series_flags(r, &far))
        .collect()
}

fn series_flags(record: &Record, far: &[outliers::Finding]) -> Vec<Flag> {
    let mut out = Vec::new();
    let mut flag = |code: &'static str, text: String| out.push(Flag { code, text });
    if record.status == Status::Failed {
        flag(
            "failed",
            format!(
                "{} failed: {}",
                record.failed_stage.as_deref().unwrap_or("a stage"),
                record.error.as_deref().unwrap_or("")
            ),
        );
    }
    let Some(result) = &record.result else {
        return out;
    };
    let loaded: Vec<_> = result
        .images
        .iter()
        .filter(|i| i.force_mn.is_some_and(|f| f > 0.0))
        .collect();
    if let Some(edge) = loaded
        .iter()
        .filter(|i| i.edge_contact)
        .map(|i| i.force_mn)
        .next()
    {
        let at = loaded.iter().filter(|i| i.edge_contact).count();
        flag(
            "edge_contact",
            format!(
                "contact is cut off by the image border in {at} of {} loaded images (from {} mN): \
                 those images are left out of the fits",
                loaded.len(),
                edge.unwrap_or(f64::NAN)
            ),
        );
    }
    let with_contact = loaded.iter().filter(|i| i.contact_pixels > 0).count();
    match &result.power_law {
        Some(p) if p.points < WEAK_FIT_POINTS => flag(
            "weak_fit",
            format!("the power law rests on {} points", p.points),
        ),
        Some(p) if p.r_squared.is_some_and(|r| r < WEAK_FIT_R2) => flag(
            "weak_fit",
            format!(
                "the power law has R² = {:.3} (< {WEAK_FIT_R2})",
                p.r_squared.unwrap_or(f64::NAN)
            ),
        ),
        None if !loaded.is_empty() => flag(
            "weak_fit",
            format!("no power law: {with_contact} loaded image(s) with contact"),
        ),
        _ => {}
    }
    let (thresholds, others): (Vec<_>, Vec<_>) = far
        .iter()
        .partition(|(q, _)| *q == outliers::Quantity::Threshold);
    if !thresholds.is_empty() {
        flag("threshold_outlier", thresholds[0].1.clone());
    }
    if !others.is_empty() {
        let words: Vec<&str> = others.iter().map(|(_, w)| w.as_str()).collect();
        flag("archive_outlier", words.join("; "));
    }
    if result.pixel_size_from_default {
        flag(
            "pixel_size_default",
            "the files state no pixel size: the batch's default (--pixel-size) is used".into(),
        );
    }
    if let (true, Some((x, y)), Some((mx, my))) = (
        result.pixel_size_given,
        result.pixel_size_um,
        result.metadata_pixel_size_um,
    ) {
        if (x / mx - 1.0).abs() > PIXEL_SIZE_TOLERANCE
            || (y / my - 1.0).abs() > PIXEL_SIZE_TOLERANCE
        {
            flag(
                "pixel_size_vs_metadata",
                format!(
                    "the pixel size given ({x} × {y} µm) differs from the file's ({mx} × {my} µm)"
                ),
            );
        }
    }
    if result.pixel_size_um.is_none() {
        flag("no_pixel_size", "no pixel size: areas are in pixels".into());
    }
    if result.images.iter().all(|i| i.force_mn.is_none()) {
        flag("no_forces", "no forces: areas per image, no fits".into());
    }
    // Physics checks (`crate::physics`): an area that falls as the load rises, pressures beyond
    // any contact.
    let physics: Vec<String> = result
        .power_law
        .as_ref()
        .and_then(|p| {
            let significant = p.exponent_se.is_some_and(|se| p.exponent + 2.0 * se < 0.0);
            crate::physics::falling_area(p.exponent, significant)
        })
        .into_iter()
        .chain(result.mean_pressure_range_mpa.iter().flat_map(|&(lo, hi)| {
            [lo, hi].into_iter().filter_map(|p| {
                crate::physics::check(crate::physics::Checked::MeanPressure, p * 1e6)
            })
        }))
        .collect();
    if !physics.is_empty() {
        flag("physics", physics.join("; "));
    }
    if !result.warnings.is_empty() {
        flag(
            "warnings",
            format!("{} warning(s) from analyze", result.warnings.len()),
        );
    }
    if let Some(fit) = record.fit.as_ref().filter(|f| !f.warnings.is_empty()) {
        flag(
            "fit_warnings",
            format!("{} warning(s) from fit-hardening", fit.warnings.len()),
        );
    }
    out
}
