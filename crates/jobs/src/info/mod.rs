//! The `info` job: what a micrograph file holds (TIFF, Zeiss CZI, Nikon ND2, Leica LIF): series,
//! axes, sample type, voxel size and where it came from and, on request, every plane's
//! statistics ([`contactscope_formats::microscopy::summary`]). Every front-end builds an
//! [`InfoRequest`] and [`run`] returns an [`InfoOutcome`], whose serialisation is `info --json`
//! (voxel sizes in µm) and the Python result (SI units, [`crate::lab`]). [`tiff_details`] gives
//! the header facts of a TIFF that `info` prints without `--json`.

use std::path::PathBuf;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use contactscope_formats::microscopy::select::Selection;
use contactscope_formats::microscopy::summary::{
    info_summary_selected, ChannelSummary, InfoSummary, SeriesSummary,
};
use contactscope_formats::tiff::{TiffInfo, TiffReader};

use crate::error::Result;
use crate::lab::{OptQ, Unit};

/// Which file to describe, and how much.
#[derive(Debug, Clone, PartialEq)]
pub struct InfoRequest {
    /// A TIFF, CZI, ND2 or LIF file.
    pub file: PathBuf,
    /// Decode every (selected) plane and add its min, max, mean and sum.
    pub stats: bool,
    /// Restrict the listing: `series` keeps one series, `channel`, `z`, `t` (and extra axes) the
    /// planes of the statistics.
    pub selection: Selection,
}

impl InfoRequest {
    /// A request with the defaults: every series, no statistics.
    pub fn new(file: PathBuf) -> Self {
        InfoRequest {
            file,
            stats: false,
            selection: Selection::default(),
        }
    }

    /// Every check of the request itself (none: the selection is checked against the file's
    /// axes when it is read).
    pub fn check(&self) -> Result<()> {
        Ok(())
    }
}

/// What `info` found: `info --json`.
#[derive(Debug, Clone)]
pub struct InfoOutcome {
    /// The file's summary.
    pub summary: InfoSummary,
}

/// One series with its voxel size in the output's units.
struct SeriesJson<'a>(&'a SeriesSummary);

/// The voxel size: µm (`pixel_size_um`), or m inside [`crate::lab::in_si`].
struct VoxelJson<'a>(&'a SeriesSummary);

impl Serialize for VoxelJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let v = &self.0.pixel_size_m;
        let mut m = s.serialize_map(Some(3))?;
        m.serialize_entry("x", &OptQ(v.x_m, Unit::MAsUm))?;
        m.serialize_entry("y", &OptQ(v.y_m, Unit::MAsUm))?;
        m.serialize_entry("z", &OptQ(v.z_m, Unit::MAsUm))?;
        m.end()
    }
}

/// One channel: its name (what `--channel NAME` matches) and wavelengths in nm (SI: m).
struct ChannelJson<'a>(&'a ChannelSummary);

impl Serialize for ChannelJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let c = self.0;
        let mut m = s.serialize_map(Some(3))?;
        m.serialize_entry("name", &c.name)?;
        m.serialize_entry("emission_nm", &OptQ(c.emission_m, Unit::MAsNm))?;
        m.serialize_entry("excitation_nm", &OptQ(c.excitation_m, Unit::MAsNm))?;
        m.end()
    }
}

impl Serialize for SeriesJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let series = self.0;
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("index", &series.index)?;
        m.serialize_entry("name", &series.name)?;
        m.serialize_entry("axes", &series.axes)?;
        m.serialize_entry("dtype", &series.dtype)?;
        let channels: Vec<ChannelJson<'_>> = series.channels.iter().map(ChannelJson).collect();
        m.serialize_entry("channels", &channels)?;
        m.serialize_entry("pixel_size_um", &VoxelJson(series))?;
        m.serialize_entry("pixel_size_source", &series.pixel_size_source)?;
        if let Some(from) = &series.axes_from {
            m.serialize_entry("axes_from", from)?;
        }
        if !series.rows.is_y() {
            m.serialize_entry("rows", &series.rows)?;
        }
        if let Some(planes) = &series.planes {
            m.serialize_entry("planes", planes)?;
        }
        m.end()
    }
}

impl Serialize for InfoOutcome {
    /// `info --json`, or the Python result inside [`crate::lab::in_si`].
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let summary = &self.summary;
        let series: Vec<SeriesJson<'_>> = summary.series.iter().map(SeriesJson).collect();
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("file", &summary.file)?;
        m.serialize_entry("format", &summary.format)?;
        m.serialize_entry("series", &series)?;
        if let Some(file) = &summary.metadata_file {
            m.serialize_entry("metadata_file", file)?;
        }
        m.end()
    }
}

/// Run `info`: read the file's metadata (and, with `stats`, decode its planes); nothing is
/// written.
pub fn run(request: &InfoRequest) -> Result<InfoOutcome> {
    request.check()?;
    Ok(InfoOutcome {
        summary: info_summary_selected(&request.file, request.stats, &request.selection)?,
    })
}

/// The header facts of one TIFF file (pages, shape, sample type, compression, channels, pixel
/// size and where it came from), as `info` prints them for a TIFF without `--json`.
pub fn tiff_details(file: &std::path::Path) -> Result<TiffInfo> {
    Ok(TiffReader::open(file)?.info().clone())
}
