//! The `threshold` job: the global Otsu threshold of all pages of all inputs, without measuring.

use std::path::PathBuf;

use crate::error::Result;
use crate::series;
use contactscope::analysis::global_threshold;
use contactscope::threshold::Threshold;
use contactscope_formats::microscopy::select::{LoadAxis, Selection};

/// Which files, already validated.
#[derive(Debug, Clone)]
pub struct ThresholdRequest {
    /// TIFF, CZI, ND2 or LIF files, or directories of them.
    pub inputs: Vec<PathBuf>,
    /// Which planes of confocal files (and the channel of TIFFs).
    pub selection: Selection,
    /// Axis of a CZI, ND2 or LIF file whose planes are the series' images.
    pub load_axis: Option<LoadAxis>,
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
    let series =
        series::from_files_selected(&request.inputs, &request.selection, request.load_axis)?;
    let (threshold, pixels, warnings) = global_threshold(&series.planes(0), &|_, _, _| {})?;
    Ok(ThresholdOutcome {
        threshold,
        pixels,
        images: series.images.len(),
        files: series.files.len(),
        warnings,
    })
}
