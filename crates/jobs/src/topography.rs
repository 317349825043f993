//! The `topography` job: read a height map, summarise it as stored (issue 14 item 3: size, pixel
//! size, valid points, height range, h_rms, rms slope and curvature over the valid points), and
//! detrend it and compute its roughness statistics (finite-difference estimators,
//! `docs/conventions.md`, "Roughness statistics").

use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Location, Result};
use crate::heights::{usable, TopographySource};
use contactscope::surface::masked::masked_stats;
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::{Detrend, HeightMap, Topography};
use contactscope_formats::topography::{read_height_map, ReadOptions};

/// `topography --json` for one file.
#[derive(Debug, Clone, Serialize)]
pub struct TopographySummary {
    /// The file as named.
    pub file: String,
    /// Format name (`ibw`, `park-tiff`, …).
    pub format: String,
    /// Channel read.
    pub channel: String,
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Pixel size in µm.
    pub pixel_size_um: PixelSizeXy,
    /// Points with a height.
    pub valid_points: usize,
    /// Lowest valid height, µm.
    pub height_min_um: f64,
    /// Highest valid height, µm.
    pub height_max_um: f64,
    /// Mean valid height, µm.
    pub height_mean_um: f64,
    /// rms height about the mean, µm.
    pub h_rms_um: f64,
    /// rms slope (central differences), dimensionless; `null` without an interior point.
    pub slope_rms: Option<f64>,
    /// rms full Laplacian (5-point), 1/m; `null` without an interior point.
    pub curvature_rms: Option<f64>,
}

/// Lateral pixel size in µm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PixelSizeXy {
    /// Along x.
    pub x: f64,
    /// Along y.
    pub y: f64,
}

impl TopographySummary {
    /// The summary of a map as stored (statistics over its valid points,
    /// [`contactscope::surface::masked`]), in the units the keys name.
    pub fn of(file: &str, map: &HeightMap) -> Self {
        let s = masked_stats(&map.heights, (map.dx_m, map.dy_m));
        TopographySummary {
            file: file.to_string(),
            format: map.format.name().to_string(),
            channel: map.channel.clone(),
            nx: map.nx(),
            ny: map.ny(),
            pixel_size_um: PixelSizeXy {
                x: map.dx_m * 1e6,
                y: map.dy_m * 1e6,
            },
            valid_points: s.valid_points,
            height_min_um: s.min_m * 1e6,
            height_max_um: s.max_m * 1e6,
            height_mean_um: s.mean_m * 1e6,
            h_rms_um: s.rms_m * 1e6,
            slope_rms: s.slope_rms,
            curvature_rms: s.curvature_rms_per_m,
        }
    }

    /// An error naming `path` when a statistic is not finite (no valid point, or heights or
    /// pixel sizes so extreme that sums of squares overflow): nothing non-finite is printed.
    pub fn check_finite(&self, path: &Path) -> Result<()> {
        let values = [
            ("pixel size x", Some(self.pixel_size_um.x)),
            ("pixel size y", Some(self.pixel_size_um.y)),
            ("minimum height", Some(self.height_min_um)),
            ("maximum height", Some(self.height_max_um)),
            ("mean height", Some(self.height_mean_um)),
            ("rms height", Some(self.h_rms_um)),
            ("rms slope", self.slope_rms),
            ("rms curvature", self.curvature_rms),
        ];
        match values
            .iter()
            .find(|(_, v)| v.is_some_and(|v| !v.is_finite()))
        {
            None => Ok(()),
            Some((what, v)) => Err(Error::bad_input(
                Location::file(path),
                format!(
                    "the {what} of the stored heights is {} ({} valid of {} points; heights up \
                     to {:e} µm): not a usable height map",
                    v.unwrap_or(f64::NAN),
                    self.valid_points,
                    self.nx * self.ny,
                    self.height_min_um.abs().max(self.height_max_um.abs())
                ),
            )),
        }
    }
}

/// Read a file and summarise it as stored.
pub fn topography_summary(path: &Path, channel: Option<&str>) -> Result<TopographySummary> {
    let map = read_height_map(
        path,
        &ReadOptions {
            channel: channel.map(str::to_string),
            ..ReadOptions::default()
        },
    )?;
    Ok(TopographySummary::of(&path.display().to_string(), &map))
}

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
    let source = TopographySource {
        channel: request.channel.clone(),
        detrend: Detrend::None,
        ..request.source.clone()
    };
    let path = &source.path;
    let map = source.read_raw()?;
    let summary = TopographySummary::of(&path.display().to_string(), &map);
    let topography = usable(path, map);
    summary.check_finite(path)?;
    match topography {
        Ok(mut topography) => {
            topography.detrend(request.source.detrend);
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
