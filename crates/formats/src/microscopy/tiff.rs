//! TIFF described as a [`MicroscopyFile`](super::MicroscopyFile) series, through the existing
//! [`crate::tiff`] reader: one series whose `T`, `Z` and `C` are the axes the file's OME-XML or
//! ImageJ description states ([`crate::tiff::axes`]); pages without axis metadata are time
//! points (`T`), and serve as the load axis whichever one is asked for
//! ([`super::select::Selection::tiff_planes`]).

use std::collections::BTreeMap;
use std::path::Path;

use super::select::{LoadAxis, SelectedPlane, Selection};
use super::{Axes, ChannelInfo, PlaneIndex, SeriesInfo, VoxelSize};
use crate::binary::bad;
use crate::error::Result;
use crate::image::Plane;
use crate::param::Param;
use crate::tiff::{AxesSource, TiffAxes, TiffInfo, TiffReader};

/// An open TIFF.
pub(crate) struct TiffBackend {
    reader: TiffReader,
}

/// The one series of a TIFF, with the axes its metadata states.
pub fn series_of_tiff(info: &TiffInfo) -> SeriesInfo {
    let axes = &info.axes;
    let pixel_size = match info.pixel_size {
        Some(p) => VoxelSize {
            x_m: Some(p.x_m),
            y_m: Some(p.y_m),
            z_m: axes.z_step_m,
            source: Some(p.source.describe().to_string()),
        },
        None => VoxelSize {
            z_m: axes.z_step_m,
            ..VoxelSize::default()
        },
    };
    SeriesInfo {
        index: 0,
        name: String::new(),
        axes: Axes {
            t: axes.t,
            z: axes.z,
            c: axes.c,
            y: info.height,
            x: info.width,
            extra: BTreeMap::new(),
        },
        dtype: info.sample_type,
        pixel_size,
        channels: axes
            .channel_names
            .iter()
            .map(|name| ChannelInfo {
                name: name.clone(),
                ..ChannelInfo::default()
            })
            .collect(),
        rows: super::Rows::Y,
        tiff_axes: Some(axes.source),
    }
}

impl TiffBackend {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        Ok(TiffBackend {
            reader: TiffReader::open(path)?,
        })
    }

    pub(crate) fn info(&self) -> &TiffInfo {
        self.reader.info()
    }

    pub(crate) fn series(&self) -> Vec<SeriesInfo> {
        vec![series_of_tiff(self.reader.info())]
    }

    pub(crate) fn read_plane(&mut self, _info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let info = self.reader.info();
        // Pages without axis metadata stand for whichever load axis was asked for (one of t
        // and z is then 0).
        let (t, z) = match info.axes.source {
            AxesSource::Pages => (index.t + index.z, 0),
            _ => (index.t, index.z),
        };
        let (page, sample) = info
            .axes
            .page_of(t, z, index.c)
            .ok_or_else(|| bad(&info.path, elsewhere(&info.axes, t, z, index.c)))?;
        self.reader.read_page(page, sample)
    }
}

/// How a TIFF's load axis is chosen when none is named.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoadDefault {
    /// No load axis: the selection names one plane.
    None,
    /// A load series: the time points, else the focal planes; a z stack (a z step and no time
    /// points) is refused, since its planes are focal planes, not loads.
    Series,
    /// As [`LoadDefault::Series`], a z stack accepted (a manifest names its pages one by one;
    /// the optics commands read z stacks).
    AnyStack,
}

impl Selection {
    /// The planes of a TIFF this selection names, each with its IFD and sample, in load order:
    /// along `along`, or the axis [`LoadDefault`] gives when none is named. Pages without axis
    /// metadata are the load axis whichever is named.
    pub fn tiff_planes(
        &self,
        info: &TiffInfo,
        along: Option<LoadAxis>,
        default: LoadDefault,
    ) -> Result<Vec<(SelectedPlane, (usize, usize))>> {
        let (path, axes) = (&info.path, &info.axes);
        let along = match along {
            Some(a) => Some(a),
            None => self.tiff_default(info, default)?,
        };
        let mut series = series_of_tiff(info);
        if axes.source == AxesSource::Pages && along == Some(LoadAxis::Z) {
            (series.axes.z, series.axes.t) = (series.axes.t, 1);
        }
        let planes = self.planes_in(path, &[series], along)?;
        planes
            .into_iter()
            .map(|p| {
                let (t, z, c) = (p.index.t, p.index.z, p.index.c);
                let (t, z) = match axes.source {
                    AxesSource::Pages => (t + z, 0),
                    _ => (t, z),
                };
                let at = axes
                    .page_of(t, z, c)
                    .ok_or_else(|| bad(path, elsewhere(axes, t, z, c)))?;
                Ok((p, at))
            })
            .collect()
    }

    /// The load axis of a TIFF when none is named (see [`LoadDefault`]).
    fn tiff_default(&self, info: &TiffInfo, default: LoadDefault) -> Result<Option<LoadAxis>> {
        let a = &info.axes;
        if default == LoadDefault::None {
            return Ok(None);
        }
        if a.t > 1 && self.t.is_none() {
            return Ok(Some(LoadAxis::T));
        }
        if a.z > 1 && self.z.is_none() {
            if a.is_z_stack() && default == LoadDefault::Series {
                let step = a.z_step_m.map_or(String::new(), |s| {
                    format!(" {} µm apart", (s * 1e10).round() / 1e4)
                });
                let channels = match self.channel {
                    None if a.c > 1 => format!(
                        "; it has {} channels too: choose one with {}",
                        a.c,
                        Param::Channel.with_value(format!("0..{}", a.c - 1))
                    ),
                    _ => String::new(),
                };
                return Err(bad(
                    &info.path,
                    format!(
                        "a z stack ({} focal planes{step}, no time points, says its {}): its \
                         planes are focal planes, not loads; give {} if each plane is one load, \
                         or {} for one plane{channels}",
                        a.z,
                        a.source.describe(),
                        Param::LoadAxis.with_value("z"),
                        Param::Z.with_value(format!("0..{}", a.z - 1))
                    ),
                ));
            }
            return Ok(Some(LoadAxis::Z));
        }
        Ok(None)
    }
}

/// Why plane (t, z, c) has no page: an OME set keeps it in another file.
pub(crate) fn elsewhere(axes: &TiffAxes, t: usize, z: usize, c: usize) -> String {
    if axes.other_files.is_empty() {
        format!("no page holds plane t {t}, z {z}, c {c}")
    } else {
        format!(
            "plane t {t}, z {z}, c {c} is stored in another file of this OME-TIFF set ({}); \
             select planes of this file, or open the file that holds them",
            axes.other_files.join(", ")
        )
    }
}
