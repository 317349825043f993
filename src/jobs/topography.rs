//! The `topography` job: read a height map, detrend it and compute its roughness statistics
//! (finite-difference estimators, `docs/conventions.md`, "Roughness statistics").

use crate::error::Result;
use crate::io::topography::TopographySource;
use crate::surface::stats::SurfaceStats;
use crate::surface::Topography;

/// The height map to describe, already validated.
#[derive(Debug, Clone)]
pub struct TopographyRequest {
    /// The file, pixel size and height unit overrides, and the detrending.
    pub source: TopographySource,
}

/// The map as read and detrended, and its statistics.
#[derive(Debug, Clone)]
pub struct TopographyOutcome {
    /// The detrended map.
    pub topography: Topography,
    /// h_rms, h'_rms and h''_rms by finite differences.
    pub stats: SurfaceStats,
}

/// Read, detrend, describe; nothing is written.
pub fn run_topography(request: &TopographyRequest) -> Result<TopographyOutcome> {
    let topography = request.source.read()?;
    let stats = SurfaceStats::finite_differences(&topography)?;
    Ok(TopographyOutcome { topography, stats })
}
