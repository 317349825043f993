//! The `threshold` job: the global Otsu threshold (Otsu 1979) of every image of a series,
//! without measuring: the same threshold `analyze` applies. Files or planes in memory
//! ([`Micrographs`]); the outcome is what `threshold --json` prints and what Python's
//! `otsu_threshold` returns.

use serde::Serialize;

use contactscope::analysis::global_threshold;

use crate::error::Result;
use crate::series::Micrographs;

/// Which images.
#[derive(Debug, Clone)]
pub struct ThresholdRequest {
    /// Files (folders, manifest, planes along a load axis) or planes in memory.
    pub micrographs: Micrographs,
}

/// The threshold and what it was computed from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThresholdOutcome {
    /// One exact Otsu threshold over the pooled histogram; contact is value > t.
    pub threshold: f64,
    /// The rule's name.
    pub method: &'static str,
    /// Which side of the threshold is contact.
    pub contact_rule: &'static str,
    /// Pixels in the pooled histogram.
    pub pixels: u64,
    /// Images in the series.
    pub images: usize,
    /// Distinct files (0 for planes in memory).
    pub files: usize,
    /// Notes for the user (non-finite pixels).
    pub warnings: Vec<String>,
}

/// Read every image (every image counts once) and pick the series threshold; nothing is
/// written.
pub fn run(request: &ThresholdRequest) -> Result<ThresholdOutcome> {
    request.micrographs.check()?;
    let open = request.micrographs.open()?;
    let (threshold, pixels, warnings) = global_threshold(&open.default_planes(), &|_, _, _| {})?;
    Ok(ThresholdOutcome {
        threshold: threshold.value,
        method: "otsu-global",
        contact_rule: "value > threshold",
        pixels,
        images: open.series.images.len(),
        files: open.series.files.len(),
        warnings,
    })
}
