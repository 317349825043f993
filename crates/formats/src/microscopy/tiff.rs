//! TIFF described as a [`MicroscopyFile`](super::MicroscopyFile) series, through the existing
//! [`crate::tiff`] reader: one series whose `T`, `Z` and `C` are the axes the file's OME-XML or
//! ImageJ description states ([`crate::tiff::axes`]), one series per image of an OME-TIFF
//! whose XML describes several (OME `Image` elements: stage positions, scenes); pages without
//! axis metadata are time points (`T`), and serve as the load axis whichever one is asked for
//! ([`super::select::Selection::tiff_planes`]).

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

use super::select::{LoadAxis, SelectedPlane, Selection};
use super::{Axes, ChannelInfo, PlaneIndex, SeriesInfo, VoxelSize};
use crate::binary::bad;
use crate::error::Result;
use crate::image::{PixelSize, Plane, SampleType};
use crate::param::Param;
use crate::tiff::{AxesSource, Place, TiffAxes, TiffInfo, TiffReader};

/// An open TIFF.
pub(crate) struct TiffBackend {
    reader: TiffReader,
    /// The other file of its OME set last read from.
    member: Option<TiffReader>,
}

/// Where a selected plane of a TIFF is read: the file (the TIFF itself, or another file of its
/// OME set) and the page's IFD and sample there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TiffPage {
    /// The file holding the page.
    pub path: PathBuf,
    /// Its IFD in that file.
    pub ifd: usize,
    /// The sample of a pixel (a channel stored as samples).
    pub sample: usize,
}

/// The path of the file `name` of `info`'s OME set (one of [`TiffInfo::set_files`]): a
/// multi-file OME set names its files by `UUID FileName`, relative to the folder of the file
/// whose OME-XML names them (OME-TIFF specification, "multi-file datasets"). A name that is
/// absolute or leaves the folder (`..`) is refused, as is one no file answers to.
pub fn set_member(info: &TiffInfo, name: &str) -> Result<PathBuf> {
    let relative = Path::new(name);
    let plain = relative
        .components()
        .all(|c| matches!(c, Component::Normal(_) | Component::CurDir));
    if name.is_empty() || !plain {
        return Err(bad(
            &info.path,
            format!(
                "its OME-XML names the file {name:?} of its set by a path that leaves the \
                 file's folder; a set's files are named relative to it"
            ),
        ));
    }
    let folder = info.path.parent().unwrap_or(Path::new(""));
    let path = folder.join(relative);
    if !path.is_file() {
        return Err(bad(
            &info.path,
            format!(
                "planes of this OME-TIFF set are stored in {name}, which is not in {}; copy \
                 the set's files together",
                if folder.as_os_str().is_empty() {
                    "this folder".to_string()
                } else {
                    folder.display().to_string()
                }
            ),
        ));
    }
    Ok(path)
}

/// Read the page `at` names, from the TIFF `own` or from another file of its OME set (`member`
/// keeps the one last opened). A page read from another file must hold a plane of the
/// series' size and sample type (`expect`: width, height, type); its first page need not (it
/// may belong to another image of the set).
pub(crate) fn read_set_page(
    own: &mut TiffReader,
    member: &mut Option<TiffReader>,
    at: &TiffPage,
    expect: (usize, usize, SampleType),
) -> Result<Plane> {
    if at.path == own.info().path {
        return own.read_page(at.ifd, at.sample);
    }
    if member.as_ref().is_none_or(|m| m.info().path != at.path) {
        *member = Some(TiffReader::open(&at.path)?);
    }
    let plane = member
        .as_mut()
        .expect("just opened")
        .read_page(at.ifd, at.sample)?;
    if (plane.width, plane.height, plane.sample_type) != expect {
        return Err(bad(
            &at.path,
            format!(
                "page {} of this file of the OME-TIFF set of {} holds a {}×{} {} plane, the \
                 series {}×{} {}",
                at.ifd,
                own.info().path.display(),
                plane.width,
                plane.height,
                plane.sample_type.name(),
                expect.0,
                expect.1,
                expect.2.name()
            ),
        ));
    }
    Ok(plane)
}

/// Where plane (t, z, c) of series `series` of a TIFF is read (module docs); an error when no
/// page holds it.
pub fn page_at(info: &TiffInfo, series: usize, t: usize, z: usize, c: usize) -> Result<TiffPage> {
    let axes = info
        .axes_of(series)
        .ok_or_else(|| bad(&info.path, format!("the file holds no series {series}")))?;
    let (place, sample) = axes.place_of(t, z, c).ok_or_else(|| {
        bad(
            &info.path,
            format!("no page holds plane t {t}, z {z}, c {c}"),
        )
    })?;
    Ok(match place {
        Place::Here(ifd) => TiffPage {
            path: info.path.clone(),
            ifd,
            sample,
        },
        Place::There { file, ifd } => TiffPage {
            path: set_member(info, &axes.other_files[file])?,
            ifd,
            sample,
        },
    })
}

/// The series of a TIFF: one, with the axes its metadata states, or one per OME image, each
/// with its own plane size and pixel size ([`TiffInfo::image`]).
pub fn tiff_series(info: &TiffInfo) -> Vec<SeriesInfo> {
    if info.images.is_empty() {
        return vec![series_of_tiff(info)];
    }
    info.images
        .iter()
        .enumerate()
        .map(|(k, image)| {
            let pixel_size = info.image_pixel_size(image);
            SeriesInfo {
                index: k,
                name: image.name.clone().unwrap_or_default(),
                ..series_of(&image.axes, image.width, image.height, info, pixel_size)
            }
        })
        .collect()
}

/// The series a TIFF shows alone (its first image's), with the axes its metadata states.
pub fn series_of_tiff(info: &TiffInfo) -> SeriesInfo {
    series_of(&info.axes, info.width, info.height, info, info.pixel_size)
}

fn series_of(
    axes: &TiffAxes,
    width: usize,
    height: usize,
    info: &TiffInfo,
    pixel_size: Option<PixelSize>,
) -> SeriesInfo {
    let pixel_size = match pixel_size {
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
            y: height,
            x: width,
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
            member: None,
        })
    }

    pub(crate) fn info(&self) -> &TiffInfo {
        self.reader.info()
    }

    pub(crate) fn series(&self) -> Vec<SeriesInfo> {
        tiff_series(self.reader.info())
    }

    pub(crate) fn read_plane(&mut self, series: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let info = self.reader.info();
        // Pages without axis metadata stand for whichever load axis was asked for (one of t
        // and z is then 0).
        let (t, z) = match info.axes.source {
            AxesSource::Pages => (index.t + index.z, 0),
            _ => (index.t, index.z),
        };
        let at = page_at(info, series.index, t, z, index.c)?;
        let expect = (series.axes.x, series.axes.y, series.dtype);
        read_set_page(&mut self.reader, &mut self.member, &at, expect)
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
    /// The planes of a TIFF this selection names, each with the file, IFD and sample it is read
    /// from (another file of a multi-file OME set, [`set_member`], for a plane stored there), in
    /// load order: along `along`, or the axis [`LoadDefault`] gives when none is named. Pages
    /// without axis metadata are the load axis whichever is named. Also the file as the chosen
    /// image shows it ([`TiffInfo::image`]: plane size, pixel size); along the images of a
    /// multi-image OME-TIFF (`--load-axis series`) they must all have one plane size and pixel
    /// size.
    pub fn tiff_planes(
        &self,
        info: &TiffInfo,
        along: Option<LoadAxis>,
        default: LoadDefault,
    ) -> Result<(TiffInfo, Vec<(SelectedPlane, TiffPage)>)> {
        let path = &info.path;
        let view = match along {
            Some(LoadAxis::Series) => None,
            _ => info.image(self.series.unwrap_or(0)),
        };
        let shown = view.as_ref().unwrap_or(info);
        let along = match along {
            Some(a) => Some(a),
            None => self.tiff_default(shown, default)?,
        };
        let mut series = tiff_series(info);
        if info.axes.source == AxesSource::Pages && along == Some(LoadAxis::Z) {
            (series[0].axes.z, series[0].axes.t) = (series[0].axes.t, 1);
        }
        let planes = self.planes_in(path, &series, along)?;
        if along == Some(LoadAxis::Series) {
            same_images(info, &series, &planes)?;
        }
        let planes = planes
            .into_iter()
            .map(|p| {
                let (t, z, c) = (p.index.t, p.index.z, p.index.c);
                let (t, z) = match info.axes.source {
                    AxesSource::Pages => (t + z, 0),
                    _ => (t, z),
                };
                let at = page_at(info, p.series, t, z, c)?;
                Ok((p, at))
            })
            .collect::<Result<Vec<_>>>()?;
        // Along the images, they share one plane and pixel size (checked above): image 0's.
        let shown = view
            .or_else(|| info.image(0))
            .unwrap_or_else(|| info.clone());
        Ok((shown, planes))
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

/// Images of a multi-image OME-TIFF read as one load series: one plane size and one pixel size
/// (to 0.1 nm, as the file states it: an override by `--pixel-size` does not make two stated
/// sizes agree, as for a CZI's scenes), or an error naming the first image that differs.
fn same_images(info: &TiffInfo, series: &[SeriesInfo], planes: &[SelectedPlane]) -> Result<()> {
    let describe = |s: &SeriesInfo| {
        let size = match (s.pixel_size.x_m, s.pixel_size.y_m) {
            (Some(x), Some(y)) => format!("{:.4} × {:.4} µm pixels", x * 1e6, y * 1e6),
            _ => "no pixel size".to_string(),
        };
        format!("{}×{} px, {}", s.axes.x, s.axes.y, size)
    };
    let Some(first) = planes.first().map(|p| &series[p.series]) else {
        return Ok(());
    };
    for p in planes {
        let other = &series[p.series];
        if describe(other) != describe(first) {
            return Err(bad(
                &info.path,
                format!(
                    "its images are read as one load series (--load-axis series), but image {} \
                     is {} and image {} {}",
                    other.index,
                    describe(other),
                    first.index,
                    describe(first)
                ),
            ));
        }
    }
    Ok(())
}
