//! What the QC page and the series table flag: the things that make a series' numbers doubtful,
//! found late if at all when an archive is read one series at a time (`docs/outputs.md` lists
//! each flag with its rule).

use serde::Serialize;

use super::record::{Record, Status};

/// R² of the log–log power law below which a fit is weak.
pub const WEAK_FIT_R2: f64 = 0.95;
/// Fewest points of a power law that is not weak.
pub const WEAK_FIT_POINTS: usize = 3;
/// Robust z-score (|t − median| / (1.4826 · MAD)) beyond which a series' threshold is far from
/// the archive's others.
pub const THRESHOLD_Z: f64 = 3.5;
/// Fewest comparable series (same sample type, one global Otsu threshold each) before
/// thresholds are compared.
pub const THRESHOLD_MIN_SERIES: usize = 5;
/// Relative difference between a given pixel size and the file's own beyond which it is flagged.
pub const PIXEL_SIZE_TOLERANCE: f64 = 0.01;

/// One flag: a short code (for filtering) and what it means for this series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Flag {
    /// `failed`, `edge_contact`, `weak_fit`, `threshold_outlier`, `pixel_size_default`,
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
    "pixel_size_default",
    "pixel_size_vs_metadata",
    "no_pixel_size",
    "no_forces",
    "physics",
    "warnings",
    "fit_warnings",
];

/// The flags of each series (in the order of `records`).
pub fn flags(records: &[&Record]) -> Vec<Vec<Flag>> {
    let thresholds = ThresholdStats::of(records);
    records
        .iter()
        .map(|r| series_flags(r, &thresholds))
        .collect()
}

fn series_flags(record: &Record, thresholds: &ThresholdStats) -> Vec<Flag> {
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
    if let (Some(t), Some(z)) = (result.threshold, thresholds.z(record)) {
        if z.abs() > THRESHOLD_Z {
            flag(
                "threshold_outlier",
                format!(
                    "threshold {t} is far from the archive's median {} (robust z = {z:.1})",
                    thresholds.median_of(record).unwrap_or(f64::NAN)
                ),
            );
        }
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

/// The archive's thresholds per kind of series (sample type; one global Otsu threshold each).
struct ThresholdStats {
    groups: Vec<(String, f64, f64)>,
}

impl ThresholdStats {
    fn key(record: &Record) -> Option<(String, f64)> {
        let r = record.result.as_ref()?;
        (r.threshold_method == "otsu-global")
            .then_some(())
            .and(r.threshold)
            .map(|t| (r.sample_type.clone(), t))
    }

    fn of(records: &[&Record]) -> Self {
        let mut by_type: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
        for (kind, t) in records.iter().filter_map(|r| ThresholdStats::key(r)) {
            by_type.entry(kind).or_default().push(t);
        }
        let groups = by_type
            .into_iter()
            .filter(|(_, v)| v.len() >= THRESHOLD_MIN_SERIES)
            .map(|(kind, v)| {
                let median = median(v.clone());
                let mad = median_abs_dev(&v, median);
                // A floor on the spread: 1 % of the median, and one grey level.
                let scale = (1.4826 * mad).max(0.01 * median.abs()).max(1.0);
                (kind, median, scale)
            })
            .collect();
        ThresholdStats { groups }
    }

    fn group(&self, record: &Record) -> Option<(f64, f64, f64)> {
        let (kind, t) = ThresholdStats::key(record)?;
        self.groups
            .iter()
            .find(|(k, _, _)| *k == kind)
            .map(|(_, m, s)| (t, *m, *s))
    }

    fn z(&self, record: &Record) -> Option<f64> {
        self.group(record).map(|(t, m, s)| (t - m) / s)
    }

    fn median_of(&self, record: &Record) -> Option<f64> {
        self.group(record).map(|(_, m, _)| m)
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn median_abs_dev(v: &[f64], m: f64) -> f64 {
    median(v.iter().map(|x| (x - m).abs()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians_and_spreads() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert_eq!(median_abs_dev(&[1.0, 2.0, 3.0, 4.0, 100.0], 3.0), 1.0);
    }
}
