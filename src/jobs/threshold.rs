//! The `threshold` job: the global Otsu threshold of all pages of all inputs, without measuring.

use std::path::PathBuf;

use crate::analysis::global_threshold;
use crate::error::Result;
use crate::io::series;
use crate::threshold::Threshold;

/// Which files, already validated.
#[derive(Debug, Clone)]
pub struct ThresholdRequest {
    /// TIFF files or directories.
    pub inputs: Vec<PathBuf>,
    /// Channel of multi-channel files.
    pub channel: Option<usize>,
}

/// The threshold and what it was computed from.
#[derive(Debug, Clone)]
pub struct ThresholdOutcome {
    /// One exact Otsu threshold over the pooled histogram; contact is value > t.
    pub threshold: Threshold,
    /// Pixels in the pooled histogram.
    pub pixels: u64,
    /// Images in the series.
    pub images: usize,
    /// Distinct files.
    pub files: usize,
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// Read every page (every image counts once) and pick the series threshold; nothing is written.
pub fn run_threshold(request: &ThresholdRequest) -> Result<ThresholdOutcome> {
    let series = series::from_files(&request.inputs, request.channel)?;
    let (threshold, pixels, warnings) = global_threshold(&series.planes(0), &|_, _, _| {})?;
    Ok(ThresholdOutcome {
        threshold,
        pixels,
        images: series.images.len(),
        files: series.files.len(),
        warnings,
    })
}
