//! A height map as `simulate`, `fit-hardening` and `topography` take it: a file read by
//! `contactscope_formats::topography`, its invalid points filled on request
//! (`contactscope::surface::fill`) and the map detrended (`contactscope::surface`), with notes
//! for the user. Every front-end reads height maps through [`TopographySource`], so the defaults
//! and refusals are the same everywhere.

use std::path::PathBuf;

use contactscope::surface::fill::{fill_harmonic, fill_invalid, FillInvalid};
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::trend::ContainerDetrend;
use contactscope::surface::{Detrend, Topography};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;
use contactscope_formats::topography::container::{self, Container};
use contactscope_formats::topography::{read_height_map, HeightMap, ReadOptions};
use serde::Serialize;

use crate::error::{Error, Location, Result};

/// A height map as a request carries it: a file to read (the command line; Python given a
/// path), or heights already in memory (Python given an array). Either way it is detrended by
/// the request's rule, so that both give the same numbers on the same heights.
#[derive(Debug, Clone, PartialEq)]
pub enum HeightInput {
    /// A file, with how to read and level it.
    File(TopographySource),
    /// Heights in memory (m, rows = y) with their pixel size.
    Memory {
        /// The heights and pixel size.
        topography: Topography,
        /// Detrending applied before use.
        detrend: Detrend,
        /// What to call them in outputs and messages.
        label: String,
    },
}

impl HeightInput {
    /// Heights in memory with the default detrending ([`Detrend::Plane`], as for a file).
    pub fn memory(topography: Topography, label: impl Into<String>) -> Self {
        HeightInput::Memory {
            topography,
            detrend: Detrend::Plane,
            label: label.into(),
        }
    }

    /// The file, or the label of the heights in memory.
    pub fn label(&self) -> String {
        match self {
            HeightInput::File(s) => s.path.display().to_string(),
            HeightInput::Memory { label, .. } => label.clone(),
        }
    }

    /// The detrending.
    pub fn detrend(&self) -> Detrend {
        match self {
            HeightInput::File(s) => s.detrend,
            HeightInput::Memory { detrend, .. } => *detrend,
        }
    }

    /// Range checks of what the caller gave: pixel sizes and the height unit.
    pub fn check(&self) -> Result<()> {
        match self {
            HeightInput::File(s) => s.check(),
            HeightInput::Memory { topography, .. } => {
                check_pixel_size((topography.dx_m, topography.dy_m))?;
                check_memory_heights(&topography.heights)
            }
        }
    }

    /// The heights, filled and detrended, with notes for the user.
    pub fn read_with_notes(&self) -> Result<(Topography, Vec<String>)> {
        match self {
            HeightInput::File(s) => s.read_with_notes(),
            HeightInput::Memory {
                topography,
                detrend,
                ..
            } => {
                let mut t = topography.clone();
                t.detrend(*detrend);
                Ok((t, Vec::new()))
            }
        }
    }

    /// The container measurement the heights come from (`surface/name`), `None` for other
    /// inputs.
    pub fn measurement_label(&self) -> Result<Option<String>> {
        match self {
            HeightInput::File(s) if s.is_container() => {
                let c = Container::open(&s.path)?;
                Ok(Some(c.find(s.measurement.as_deref())?.label()))
            }
            _ => Ok(None),
        }
    }

    /// Whether the heights are marked periodic (a container's measurement,
    /// [`TopographySource::stated_periodic`]).
    pub fn stated_periodic(&self) -> Result<bool> {
        match self {
            HeightInput::File(s) => s.stated_periodic(),
            HeightInput::Memory { .. } => Ok(false),
        }
    }

    /// What the outputs record of the input.
    pub fn facts(&self) -> (Option<String>, Option<FillInvalid>) {
        match self {
            HeightInput::File(s) => (s.channel.clone(), s.fill_invalid),
            HeightInput::Memory { .. } => (None, None),
        }
    }
}

/// What a summary records of the height map a simulation ran on (`summary.json` of
/// `simulate`: `topography`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeightFacts {
    /// The file (or the label of heights given in memory).
    pub path: String,
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Pixel size along x, m.
    #[serde(rename = "pixel_size_x_nm", serialize_with = "crate::lab::m_as_nm")]
    pub pixel_size_x_m: f64,
    /// Pixel size along y, m.
    #[serde(rename = "pixel_size_y_nm", serialize_with = "crate::lab::m_as_nm")]
    pub pixel_size_y_m: f64,
    /// Detrending applied.
    pub detrend: &'static str,
    /// Channel read (vendor files).
    pub channel: Option<String>,
    /// How invalid points were filled.
    pub fill_invalid: Option<FillInvalid>,
    /// The container measurement read (`surface/name`); `null` for other files.
    pub measurement: Option<String>,
    /// Roughness after detrending (written as `h_rms_nm`, `h_prime_rms`,
    /// `h_double_prime_rms_per_um`).
    #[serde(flatten)]
    pub roughness: Roughness,
    /// Sphere radius added, m.
    #[serde(
        rename = "sphere_radius_um",
        serialize_with = "crate::lab::opt_m_as_um"
    )]
    pub sphere_radius_m: Option<f64>,
}

/// The roughness statistics a summary records of a height map (`docs/conventions.md`,
/// "Roughness statistics"): one shape for `surface`, `topography`, `simulate` and
/// `fit-hardening`, written in nm and 1/µm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Roughness {
    /// rms height about the mean, m.
    #[serde(rename = "h_rms_nm", serialize_with = "crate::lab::m_as_nm")]
    pub h_rms_m: f64,
    /// rms slope (central differences).
    pub h_prime_rms: f64,
    /// rms full Laplacian (5-point), 1/m.
    #[serde(
        rename = "h_double_prime_rms_per_um",
        serialize_with = "crate::lab::per_m_as_per_um"
    )]
    pub h_double_prime_rms_per_m: f64,
}

impl From<&SurfaceStats> for Roughness {
    fn from(stats: &SurfaceStats) -> Self {
        Roughness {
            h_rms_m: stats.h_rms_m,
            h_prime_rms: stats.h_prime_rms,
            h_double_prime_rms_per_m: stats.h_double_prime_rms_per_m,
        }
    }
}

/// A height-map file with how to read and level it.
#[derive(Debug, Clone, PartialEq)]
pub struct TopographySource {
    /// The file.
    pub path: PathBuf,
    /// Pixel size override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// Height unit override, m per stored unit.
    pub height_unit_m: Option<f64>,
    /// Detrending applied after reading.
    pub detrend: Detrend,
    /// Channel of a multi-channel vendor file, by name (default: its height channel).
    pub channel: Option<String>,
    /// Fill a vendor map's invalid points this way (default: refuse such a map).
    pub fill_invalid: Option<FillInvalid>,
    /// The measurement of a contact.engineering surface container, by index or name
    /// (`surface/name`); default: its only one.
    pub measurement: Option<String>,
}

impl TopographySource {
    /// A file with the default channel, no filling and no detrending.
    pub fn new(path: PathBuf) -> Self {
        TopographySource {
            path,
            pixel_size_m: None,
            height_unit_m: None,
            detrend: Detrend::None,
            channel: None,
            fill_invalid: None,
            measurement: None,
        }
    }

    /// Whether the file is a contact.engineering surface container (ZIP or folder).
    pub fn is_container(&self) -> bool {
        container::is_container(&self.path)
    }

    /// Whether the height map is marked periodic: a container's measurement with
    /// `is_periodic` (other files state no periodicity).
    pub fn stated_periodic(&self) -> Result<bool> {
        if !self.is_container() {
            return Ok(false);
        }
        let c = Container::open(&self.path)?;
        Ok(c.find(self.measurement.as_deref())?.periodic)
    }

    /// Range checks of the overrides: the pixel size and the height unit.
    pub fn check(&self) -> Result<()> {
        if let Some(u) = self.height_unit_m {
            Quantity::Height.check(u, Param::HeightUnit)?;
        }
        match self.pixel_size_m {
            Some(p) => check_pixel_size(p),
            None => Ok(()),
        }
    }

    /// The map as stored (no filling, no detrending), with every override applied; a
    /// container's measurement with the container's own processing applied
    /// ([`read_measurement`]).
    pub fn read_raw(&self) -> Result<HeightMap> {
        Ok(self.read_raw_with_notes()?.0)
    }

    /// [`Self::read_raw`] with notes for the user (a container's size that differs from its
    /// data file's).
    pub fn read_raw_with_notes(&self) -> Result<(HeightMap, Vec<String>)> {
        if self.is_container() {
            if self.pixel_size_m.is_some() || self.height_unit_m.is_some() {
                return Err(Error::bad_input(
                    Location::file(&self.path),
                    format!(
                        "a surface container states each measurement's size and unit; do not give {} or {}",
                        Param::PixelSize,
                        Param::HeightUnit
                    ),
                ));
            }
            let c = Container::open(&self.path)?;
            let m = c.find(self.measurement.as_deref())?;
            return read_measurement(&c, m, self.channel.as_deref());
        }
        if let Some(m) = &self.measurement {
            return Err(Error::bad_input(
                Location::file(&self.path),
                format!(
                    "measurement '{m}' asked for, but the file is not a contact.engineering surface container (a ZIP archive or folder with index.json or meta.yml)"
                ),
            ));
        }
        let map = read_height_map(
            &self.path,
            &ReadOptions {
                pixel_size_m: self.pixel_size_m,
                height_unit_m: self.height_unit_m,
                channel: self.channel.clone(),
            },
        )?;
        Ok((map, Vec::new()))
    }

    /// Read the file, fill and detrend it.
    pub fn read(&self) -> Result<Topography> {
        Ok(self.read_with_notes()?.0)
    }

    /// [`Self::read`], with notes for the user (a pixel size that replaced the file's own, how
    /// many invalid points were filled).
    pub fn read_with_notes(&self) -> Result<(Topography, Vec<String>)> {
        let (mut map, mut notes) = self.read_raw_with_notes()?;
        notes.extend(replaced_pixel_size_note(&map));
        match self.fill_invalid {
            Some(_) => notes.extend(self.fill(&mut map)),
            None if map.invalid_points > 0 && map.valid_points() > 0 => {
                return Err(Error::bad_input(
                    Location::file(&self.path),
                    format!(
                        "{} of {} points of channel '{}' are invalid (not measured); a contact \
                         calculation needs every height: give {} mean|nearest to fill them",
                        map.invalid_points,
                        map.heights.len(),
                        map.channel,
                        Param::FillInvalid
                    ),
                ));
            }
            None => {}
        }
        let mut topography = usable(&self.path, map)?;
        topography.detrend(self.detrend);
        Ok((topography, notes))
    }
}

impl TopographySource {
    /// Fill the map's invalid points as asked ([`Self::fill_invalid`]); the note for the user
    /// when any were filled.
    pub fn fill(&self, map: &mut HeightMap) -> Option<String> {
        let how = self.fill_invalid?;
        let filled = fill_invalid(map, how);
        (filled > 0).then(|| {
            format!(
                "{}: {filled} invalid point(s) filled with the {} valid height",
                self.path.display(),
                how.name()
            )
        })
    }
}

/// A container's measurement as SurfaceTopography reads it (`read_container`): the data file
/// with the container's size, unit, channel and height scale, its undefined points filled by
/// the measurement's `fill_undefined_data_mode` and its heights detrended by its `detrend_mode`
/// (neither for a squeezed NetCDF file, which holds them applied); notes for the user.
pub fn read_measurement(
    c: &Container,
    m: &container::Measurement,
    channel: Option<&str>,
) -> Result<(HeightMap, Vec<String>)> {
    let read = c.read(m, channel)?;
    let at = || Location::file(format!("{}:{}", c.path.display(), m.datafile));
    let (fill, detrend) = (
        read.fill_mode().map(str::to_string),
        read.detrend_mode().map(str::to_string),
    );
    let mut map = read.map;
    match fill.as_deref() {
        None => {}
        Some("harmonic") => {
            fill_harmonic(&mut map.heights, m.periodic);
            map.invalid_points = map.heights.iter().filter(|h| !h.is_finite()).count();
        }
        Some(other) => {
            return Err(Error::bad_input(
                at(),
                format!(
                    "measurement {}: fill_undefined_data_mode '{other}' is not applied by contactscope (do-not-fill and harmonic are)",
                    m.label()
                ),
            ))
        }
    }
    if let Some(mode) = detrend.as_deref() {
        ContainerDetrend::from_mode(mode)
            .and_then(|d| d.apply(&mut map.heights, m.periodic))
            .map_err(|e| Error::bad_input(at(), format!("measurement {}: {e}", m.label())))?;
    }
    Ok((map, read.notes))
}

/// Heights given in memory (a Python array) are held to the bound of heights read from a file,
/// ±[`MAX_FILE_HEIGHT_M`](contactscope_formats::topography::MAX_FILE_HEIGHT_M): beyond it they
/// were almost always given in another unit than metres (a scan in nanometres gave 1-pixel
/// contacts at 650 GPa without a word).
fn check_memory_heights(heights: &ndarray::Array2<f64>) -> Result<()> {
    let max = contactscope_formats::topography::MAX_FILE_HEIGHT_M;
    match heights.iter().position(|h| h.is_nan() || h.abs() > max) {
        None => Ok(()),
        Some(k) => {
            let nx = heights.ncols().max(1);
            let h = heights.iter().nth(k).copied().unwrap_or(f64::NAN);
            Err(Error::InvalidArgument(format!(
                "{}: the height at row {}, column {} is {h:.3e} m, beyond ±{max} m: heights are \
                 in metres (from nanometres, multiply by 1e-9)",
                Param::Topography,
                k / nx,
                k % nx
            )))
        }
    }
}

/// A pixel size (x, y), m, within the plausible range.
fn check_pixel_size((x, y): (f64, f64)) -> Result<()> {
    Quantity::PixelSize.check(x, Param::PixelSize)?;
    Quantity::PixelSize.check(y, Param::PixelSize)?;
    Ok(())
}

/// The note that the pixel size given replaced the one the file states (both named).
pub fn replaced_pixel_size_note(map: &HeightMap) -> Option<String> {
    use contactscope_formats::units::format_length;
    let (x, y) = map.replaced_pixel_size_m?;
    Some(format!(
        "{} {} × {} replaces the pixel size the file states, {} × {}",
        Param::PixelSize,
        format_length(map.dx_m),
        format_length(map.dy_m),
        format_length(x),
        format_length(y)
    ))
}

/// The map as a [`Topography`] for a contact calculation, or an error naming the file (invalid
/// points, an implausible pixel size or height).
pub fn usable(path: &std::path::Path, map: HeightMap) -> Result<Topography> {
    map.check_usable(path)?;
    Topography::from_height_map(map).map_err(|e| match e {
        contactscope::Error::InvalidArgument(reason) => {
            Error::bad_input(Location::file(path), reason)
        }
        other => other.into(),
    })
}

/// A height map of any format as a [`Topography`], as stored (no channel choice, no filling, no
/// detrending): `pixel_size_m` (x, y) overrides the file's, `height_unit_m` gives metres per
/// stored unit for formats without a unit. A map with invalid points is refused.
pub fn read_topography(
    path: &std::path::Path,
    pixel_size_m: Option<(f64, f64)>,
    height_unit_m: Option<f64>,
) -> Result<Topography> {
    TopographySource {
        pixel_size_m,
        height_unit_m,
        ..TopographySource::new(path.to_path_buf())
    }
    .read()
}

/// Write the heights (m) as a `.npy` file, atomically (the pixel size is not stored).
pub fn write_npy(path: &std::path::Path, topography: &Topography) -> Result<()> {
    crate::staging::write_atomic(
        path,
        &contactscope_formats::topography::encode_npy(&topography.heights),
    )
}

/// Write the heights and pixel size (m) as a `.gsf` file (float32), atomically.
pub fn write_gsf(path: &std::path::Path, topography: &Topography) -> Result<()> {
    crate::staging::write_atomic(
        path,
        &contactscope_formats::topography::encode_gsf(
            &topography.heights,
            (topography.dx_m, topography.dy_m),
        ),
    )
}
