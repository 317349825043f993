//! The `topography` job: read a height map, summarise it as stored (issue 14 item 3: size, pixel
//! size, valid points, height range, h_rms, rms slope and curvature over the valid points), and
//! detrend it and compute its roughness statistics (finite-difference estimators,
//! `docs/conventions.md`, "Roughness statistics").

use crate::error::{Error, Location, Result};
use crate::io::topography::summary::{summarise, summarise_heights, TopographySummary};
use crate::io::topography::{detect_file, extension_format, read, TopographySource};
use crate::surface::stats::SurfaceStats;
use crate::surface::{Detrend, Topography};

/// The height map to describe, already validated.
#[derive(Debug, Clone)]
pub struct TopographyRequest {
    /// The file, pixel size and height unit overrides, and the detrending.
    pub source: TopographySource,
    /// Channel of a multi-channel vendor file (by name); the file's height channel by default.
    pub channel: Option<String>,
}

/// The map as stored and, when every point is valid, detrended with its statistics.
#[derive(Debug, Clone)]
pub struct TopographyOutcome {
    /// Statistics of the stored heights over the valid points (no detrending).
    pub summary: TopographySummary,
    /// The detrended map and h_rms, h'_rms, h''_rms by finite differences; `None` when the map
    /// has invalid points (`note` says so).
    pub detrended: Option<(Topography, SurfaceStats)>,
    /// Why `detrended` is missing.
    pub note: Option<String>,
}

/// Read, summarise, detrend, describe; nothing is written.
pub fn run_topography(request: &TopographyRequest) -> Result<TopographyOutcome> {
    let source = &request.source;
    let path = &source.path;
    let file = path.display().to_string();
    let (summary, topography) = if matches!(detect_file(path), Ok(Some(_))) {
        if source.height_unit_m.is_some() {
            return Err(Error::bad_input(
                Location::file(path),
                "this format states its height unit; do not give another one",
            ));
        }
        let map = read(path, request.channel.as_deref())?;
        let summary = summarise(&file, &map);
        (summary, map.into_topography(path, source.pixel_size_m))
    } else {
        if let Some(channel) = &request.channel {
            return Err(Error::bad_input(
                Location::file(path),
                format!("channel '{channel}' asked for, but this format holds one height map"),
            ));
        }
        let raw = TopographySource {
            detrend: Detrend::None,
            ..source.clone()
        }
        .read()?;
        let summary = summarise_heights(
            &file,
            extension_format(path).unwrap_or("unknown"),
            "height",
            &raw.heights,
            (raw.dx_m, raw.dy_m),
        );
        (summary, Ok(raw))
    };
    summary.check_finite(path)?;
    match topography {
        Ok(mut topography) => {
            topography.detrend(source.detrend);
            let stats = SurfaceStats::finite_differences(&topography)?;
            Ok(TopographyOutcome {
                summary,
                detrended: Some((topography, stats)),
                note: None,
            })
        }
        // Only a vendor map gets here with an error (invalid points, or a pixel size or heights
        // outside the plausible ranges): its summary as stored still stands, with the reason
        // it cannot be used for a contact calculation.
        Err(e) => Ok(TopographyOutcome {
            summary,
            detrended: None,
            note: Some(e.to_string()),
        }),
    }
}
