//! The `topography` job: read a height map, summarise it as stored (size, pixel
//! size, valid points, height range, h_rms, rms slope and curvature over the valid points), and
//! detrend it and compute its roughness statistics (finite-difference estimators,
//! `docs/conventions.md`, "Roughness statistics"). Every front-end builds a
//! [`TopographyRequest`] (the command line from its flags, Python's `read_topography` from its
//! keywords), [`TopographyRequest::check`] applies the same range checks, and [`run`] returns a
//! [`TopographyOutcome`]: its `summary` is `topography --json` (lab units; in SI units for
//! Python, [`crate::lab`]) and its heights are what Python's `read_topography` returns.

use std::path::Path;

use serde::Serialize;

use crate::error::{Error, Location, Result};
use crate::heights::{usable, Roughness, TopographySource};
use crate::lab;
use contactscope::surface::masked::masked_stats;
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::{HeightMap, Topography};
use contactscope_formats::param::Param;
use contactscope_formats::topography::{read_height_map, ReadOptions};

/// `topography --json` for one file: the map as stored.
#[derive(Debug, Clone, Serialize)]
pub struct TopographySummary {
    /// The file as named.
    pub file: String,
    /// Format name (`ibw`, `park-tiff`, …).
    pub format: String,
    /// Channel read (by `--channel`, else the file's height channel).
    pub channel: String,
    /// Every channel of the file, as `--channel` names them.
    pub channels: Vec<String>,
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Pixel size, m.
    #[serde(rename = "pixel_size_um")]
    pub pixel_size: PixelSizeXy,
    /// Points with a height.
    pub valid_points: usize,
    /// Lowest valid height, m.
    #[serde(rename = "height_min_um", serialize_with = "lab::m_as_um")]
    pub height_min_m: f64,
    /// Highest valid height, m.
    #[serde(rename = "height_max_um", serialize_with = "lab::m_as_um")]
    pub height_max_m: f64,
    /// Mean valid height, m.
    #[serde(rename = "height_mean_um", serialize_with = "lab::m_as_um")]
    pub height_mean_m: f64,
    /// rms height about the mean of the heights as stored (before detrending: the roughness a
    /// simulation uses is `detrended.h_rms_nm`), m.
    #[serde(rename = "h_rms_as_stored_um", serialize_with = "lab::m_as_um")]
    pub h_rms_m: f64,
    /// rms slope h' of the heights as stored (central differences), dimensionless; `null`
    /// without an interior point.
    #[serde(rename = "h_prime_rms_as_stored")]
    pub h_prime_rms: Option<f64>,
    /// rms curvature h'' of the heights as stored (5-point Laplacian), 1/m (written per µm);
    /// `null` without an interior point.
    #[serde(
        rename = "h_double_prime_rms_as_stored_per_um",
        serialize_with = "lab::opt_per_m_as_per_um"
    )]
    pub h_double_prime_rms_per_m: Option<f64>,
}

/// Lateral pixel size, m (written in µm under `pixel_size_um`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PixelSizeXy {
    /// Along x, m.
    #[serde(rename = "x", serialize_with = "lab::m_as_um")]
    pub x_m: f64,
    /// Along y, m.
    #[serde(rename = "y", serialize_with = "lab::m_as_um")]
    pub y_m: f64,
}

impl TopographySummary {
    /// The summary of a map as stored (statistics over its valid points,
    /// [`contactscope::surface::masked`]).
    pub fn of(file: &str, map: &HeightMap) -> Self {
        let s = masked_stats(&map.heights, (map.dx_m, map.dy_m));
        TopographySummary {
            file: file.to_string(),
            format: map.format.name().to_string(),
            channel: map.channel.clone(),
            channels: map.channels.clone(),
            nx: map.nx(),
            ny: map.ny(),
            pixel_size: PixelSizeXy {
                x_m: map.dx_m,
                y_m: map.dy_m,
            },
            valid_points: s.valid_points,
            height_min_m: s.min_m,
            height_max_m: s.max_m,
            height_mean_m: s.mean_m,
            h_rms_m: s.rms_m,
            h_prime_rms: s.slope_rms,
            h_double_prime_rms_per_m: s.curvature_rms_per_m,
        }
    }

    /// An error naming `path` when a statistic is not finite (no valid point, or heights or
    /// pixel sizes so extreme that sums of squares overflow): nothing non-finite is printed.
    pub fn check_finite(&self, path: &Path) -> Result<()> {
        let values = [
            ("pixel size x", Some(self.pixel_size.x_m * 1e6)),
            ("pixel size y", Some(self.pixel_size.y_m * 1e6)),
            ("minimum height", Some(self.height_min_m * 1e6)),
            ("maximum height", Some(self.height_max_m * 1e6)),
            ("mean height", Some(self.height_mean_m * 1e6)),
            ("rms height", Some(self.h_rms_m * 1e6)),
            ("rms slope", self.h_prime_rms),
            ("rms curvature", self.h_double_prime_rms_per_m),
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
                    (self.height_min_m * 1e6)
                        .abs()
                        .max((self.height_max_m * 1e6).abs())
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

/// The statistics of the map after detrending (`detrended` of `topography --json`).
#[derive(Debug, Clone, Serialize)]
pub struct DetrendedFacts {
    /// Detrending applied.
    pub detrend: &'static str,
    /// Pixel size along x, m.
    #[serde(rename = "pixel_size_x_nm", serialize_with = "lab::m_as_nm")]
    pub pixel_size_x_m: f64,
    /// Pixel size along y, m.
    #[serde(rename = "pixel_size_y_nm", serialize_with = "lab::m_as_nm")]
    pub pixel_size_y_m: f64,
    /// Roughness (written as `h_rms_nm`, `h_prime_rms`, `h_double_prime_rms_per_um`).
    #[serde(flatten)]
    pub roughness: Roughness,
}

/// `topography --json`: the map as stored and, when every point is valid, its statistics after
/// detrending.
#[derive(Debug, Clone, Serialize)]
pub struct TopographyDescription {
    /// Statistics of the stored heights over the valid points (no detrending).
    #[serde(flatten)]
    pub stored: TopographySummary,
    /// After detrending; `null` when the map cannot be used (`note` says why).
    pub detrended: Option<DetrendedFacts>,
    /// Why `detrended` is missing (absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The height map to read and describe.
#[derive(Debug, Clone, PartialEq)]
pub struct TopographyRequest {
    /// The file, its overrides (pixel size, height unit), channel, filling and detrending.
    pub source: TopographySource,
}

impl TopographyRequest {
    /// A request with the defaults: the file's own pixel size and height unit, its height
    /// channel, no filling, plane detrending (as every command that takes a height map).
    pub fn new(path: std::path::PathBuf) -> Self {
        TopographyRequest {
            source: TopographySource {
                detrend: contactscope::surface::Detrend::Plane,
                ..TopographySource::new(path)
            },
        }
    }

    /// Every range check, the same for every front-end: the pixel size and the height unit.
    pub fn check(&self) -> Result<()> {
        self.source.check()
    }
}

/// What `topography` found: the description (`topography --json`) and the heights, filled as
/// asked and detrended, when the map is usable.
#[derive(Debug, Clone, Serialize)]
pub struct TopographyOutcome {
    /// `topography --json`.
    pub summary: TopographyDescription,
    /// Notes for the user (how many invalid points were filled).
    pub notes: Vec<String>,
    /// The heights (m, rows = y, filled and detrended) with their pixel size; `None` when the
    /// map cannot be used (`summary.note` says why).
    #[serde(skip)]
    pub heights: Option<Topography>,
}

impl TopographyOutcome {
    /// The heights, or an error saying why the map cannot be used (for a map with invalid
    /// points: how to fill them).
    pub fn usable_heights(&self) -> Result<&Topography> {
        if let Some(t) = &self.heights {
            return Ok(t);
        }
        let s = &self.summary;
        let note = s.note.as_deref().unwrap_or("not a usable height map");
        Err(Error::InvalidArgument(
            if s.stored.valid_points < s.stored.nx * s.stored.ny {
                format!(
                    "{note}: give {} mean|nearest to fill them",
                    Param::FillInvalid
                )
            } else {
                note.to_string()
            },
        ))
    }
}

/// Read, summarise, fill (as asked), detrend, describe; nothing is written.
pub fn run(request: &TopographyRequest) -> Result<TopographyOutcome> {
    request.check()?;
    let source = &request.source;
    let path = &source.path;
    let (mut map, read_notes) = source.read_raw_with_notes()?;
    let stored = TopographySummary::of(&path.display().to_string(), &map);
    stored.check_finite(path)?;
    let notes: Vec<String> = read_notes
        .into_iter()
        .chain(crate::heights::replaced_pixel_size_note(&map))
        .chain(source.fill(&mut map))
        .collect();
    let detrend = source.detrend;
    let mut notes = notes;
    match usable(path, map) {
        Ok(mut topography) => {
            topography.detrend(detrend);
            let stats = match SurfaceStats::finite_differences(&topography) {
                Ok(stats) => stats,
                // Too small for the finite-difference slope and curvature (fewer than 3 × 3
                // points): the heights' own statistics (as stored) are what can be said, the
                // others are null and the note says why; the heights are levelled as asked.
                Err(e) => {
                    notes.extend(physics_notes(path, stored.h_rms_m, None));
                    return Ok(TopographyOutcome {
                        summary: TopographyDescription {
                            note: Some(format!(
                                "{}: {e}; its heights are summarised as stored",
                                path.display()
                            )),
                            stored,
                            detrended: None,
                        },
                        notes,
                        heights: Some(topography),
                    });
                }
            };
            notes.extend(physics_notes(path, stats.h_rms_m, Some(stats.h_prime_rms)));
            Ok(TopographyOutcome {
                summary: TopographyDescription {
                    stored,
                    detrended: Some(DetrendedFacts {
                        detrend: detrend.name(),
                        pixel_size_x_m: topography.dx_m,
                        pixel_size_y_m: topography.dy_m,
                        roughness: Roughness::from(&stats),
                    }),
                    note: None,
                },
                notes,
                heights: Some(topography),
            })
        }
        // Only a vendor map gets here with an error (invalid points, or a pixel size or heights
        // outside the plausible ranges): its summary as stored still stands, with the reason
        // it cannot be used for a contact calculation.
        Err(e) => Ok(TopographyOutcome {
            notes: {
                notes.extend(physics_notes(path, stored.h_rms_m, None));
                notes
            },
            summary: TopographyDescription {
                stored,
                detrended: None,
                note: Some(e.to_string()),
            },
            heights: None,
        }),
    }
}

/// The physics checks of a height map ([`crate::physics`]): an rms height over 1 mm or an rms
/// slope over 10 names the likely unit.
fn physics_notes(path: &std::path::Path, h_rms_m: f64, slope_rms: Option<f64>) -> Vec<String> {
    use crate::physics::{check, Checked};
    check(Checked::HeightRms, h_rms_m)
        .into_iter()
        .chain(slope_rms.and_then(|s| check(Checked::SlopeRms, s)))
        .map(|w| format!("{}: {w}", path.display()))
        .collect()
}

/// One measurement of a surface container in `topography --json` of the container.
#[derive(Debug, Clone, Serialize)]
pub struct MeasurementDescription {
    /// Index over the container (`--measurement` takes it).
    pub index: usize,
    /// The surface it belongs to.
    pub surface: String,
    /// Its name.
    pub name: String,
    /// Marked periodic by the container.
    pub periodic: bool,
    /// The same description as for a single map.
    #[serde(flatten)]
    pub description: TopographyDescription,
}

/// The roughness of all measurements together: the rms of each statistic over every
/// measurement's points, each point weighted alike (sums of squares pooled).
#[derive(Debug, Clone, Serialize)]
pub struct CombinedFacts {
    /// Measurements pooled (those with statistics).
    pub measurements: usize,
    /// Points pooled.
    pub points: usize,
    /// Detrending applied to each before pooling.
    pub detrend: &'static str,
    /// Pooled roughness (written as `h_rms_nm`, `h_prime_rms`, `h_double_prime_rms_per_um`).
    #[serde(flatten)]
    pub roughness: Roughness,
}

/// `topography --json` of a surface container read whole: each measurement, then the pooled
/// statistics.
#[derive(Debug, Clone, Serialize)]
pub struct ContainerDescription {
    /// The container file or folder.
    pub container: String,
    /// Every measurement, in the container's order.
    pub measurements: Vec<MeasurementDescription>,
    /// All measurements together; `null` when none has statistics.
    pub combined: Option<CombinedFacts>,
}

/// Describe every measurement of a container (`request.source` names it, without a
/// measurement) with the request's filling and detrending, and pool their statistics.
pub fn run_container(request: &TopographyRequest) -> Result<(ContainerDescription, Vec<String>)> {
    use contactscope_formats::topography::container::Container;
    request.check()?;
    let path = &request.source.path;
    let c = Container::open(path)?;
    let mut measurements = Vec::new();
    let mut notes = Vec::new();
    let (mut n, mut h2, mut s2, mut c2) = (0usize, 0.0, 0.0, 0.0);
    for m in &c.measurements {
        let one = TopographyRequest {
            source: TopographySource {
                measurement: Some(m.index.to_string()),
                ..request.source.clone()
            },
        };
        let outcome = run(&one)?;
        notes.extend(
            outcome
                .notes
                .iter()
                .map(|note| format!("{}: {note}", m.label())),
        );
        if let (Some(stats), Some(t)) = (&outcome.summary.detrended, &outcome.heights) {
            let points = t.heights.len();
            n += points;
            h2 += points as f64 * stats.roughness.h_rms_m.powi(2);
            s2 += points as f64 * stats.roughness.h_prime_rms.powi(2);
            c2 += points as f64 * stats.roughness.h_double_prime_rms_per_m.powi(2);
        }
        measurements.push(MeasurementDescription {
            index: m.index,
            surface: m.surface.clone(),
            name: m.name.clone(),
            periodic: m.periodic,
            description: outcome.summary,
        });
    }
    let pooled = measurements
        .iter()
        .filter(|m| m.description.detrended.is_some())
        .count();
    let combined = (n > 0).then(|| CombinedFacts {
        measurements: pooled,
        points: n,
        detrend: request.source.detrend.name(),
        roughness: Roughness {
            h_rms_m: (h2 / n as f64).sqrt(),
            h_prime_rms: (s2 / n as f64).sqrt(),
            h_double_prime_rms_per_m: (c2 / n as f64).sqrt(),
        },
    });
    Ok((
        ContainerDescription {
            container: path.display().to_string(),
            measurements,
            combined,
        },
        notes,
    ))
}
