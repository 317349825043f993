//! Header facts of one file of a load series, whatever its format: a TIFF (its pages) or a
//! CZI, ND2 or LIF file (the planes a [`Selection`] names, along an optional [`LoadAxis`]).

use std::path::{Path, PathBuf};

use crate::error::{Error, Location, Result};
use contactscope::image::{PixelSize, SampleType};
use contactscope_formats::microscopy::select::{
    series_pixel_size, LoadAxis, SelectedPlane, Selection,
};
use contactscope_formats::microscopy::TiffPage;
use contactscope_formats::microscopy::{MicroscopyFile, MicroscopyFormat, SeriesInfo};
use contactscope_formats::tiff::TiffInfo;

/// Header facts of one file of a series, whatever its format.
#[derive(Debug, Clone)]
pub struct SeriesFile {
    /// The file.
    pub path: PathBuf,
    /// Its format (by content).
    pub format: MicroscopyFormat,
    /// Plane width in pixels.
    pub width: usize,
    /// Plane height in pixels.
    pub height: usize,
    /// Sample type of a plane.
    pub sample_type: SampleType,
    /// Compression of the first page (TIFF); for CZI, ND2 and LIF "compressed" when any
    /// plane is (CZI zstd, ND2 lossless), else "none".
    pub compression: String,
    /// Channels (of the selected series for CZI, ND2 and LIF).
    pub channels: usize,
    /// Pixel size from the file's metadata, if any.
    pub pixel_size: Option<PixelSize>,
    /// Notes about ignored or doubtful metadata.
    pub notes: Vec<String>,
    /// The TIFF header facts (TIFF files only).
    pub tiff: Option<TiffInfo>,
    /// The selected planes, in load order.
    pub planes: Vec<SelectedPlane>,
    /// The file and IFD of each selected plane (TIFF files only; another file of a multi-file
    /// OME set for a plane stored there).
    pub tiff_pages: Vec<TiffPage>,
}

impl SeriesFile {
    pub(super) fn from_tiff(info: TiffInfo, planes: Vec<(SelectedPlane, TiffPage)>) -> Self {
        let (planes, tiff_pages) = planes.into_iter().unzip();
        SeriesFile {
            path: info.path.clone(),
            format: MicroscopyFormat::Tiff,
            width: info.width,
            height: info.height,
            sample_type: info.sample_type,
            compression: info.compression.clone(),
            channels: info.channels,
            pixel_size: info.pixel_size,
            notes: info.notes.clone(),
            tiff: Some(info),
            planes,
            tiff_pages,
        }
    }

    /// Open a CZI, ND2 or LIF file and resolve the selection: every selected series must have
    /// one plane size, sample type and pixel size.
    pub(super) fn from_vendor(
        path: &Path,
        selection: &Selection,
        along: Option<LoadAxis>,
    ) -> Result<Self> {
        let file = MicroscopyFile::open(path)?;
        let planes = selection.planes(&file, along)?;
        let first = &file.series[planes[0].series];
        let describe = |s: &SeriesInfo| format!("{}×{} {}", s.axes.x, s.axes.y, s.dtype.name());
        let pixel_size = series_pixel_size(file.format, first);
        for p in &planes[1..] {
            let other = &file.series[p.series];
            if describe(other) != describe(first) {
                return Err(Error::SeriesMismatch {
                    at: Location::file(path),
                    reason: format!("series {} is {}", other.index, describe(other)),
                    expected: describe(first),
                });
            }
            let same = match (pixel_size, series_pixel_size(file.format, other)) {
                (Some(a), Some(b)) => a.same_size(&b),
                (a, b) => a.is_none() && b.is_none(),
            };
            if !same {
                return Err(Error::SeriesMismatch {
                    at: Location::file(path),
                    reason: format!("series {} has another pixel size", other.index),
                    expected: format!("the pixel size of series {}", first.index),
                });
            }
        }
        Ok(SeriesFile {
            path: path.to_path_buf(),
            format: file.format,
            width: first.axes.x,
            height: first.axes.y,
            sample_type: first.dtype,
            compression: if file.compressed() {
                "compressed".into()
            } else {
                "none".into()
            },
            channels: first.axes.c,
            pixel_size,
            notes: Vec::new(),
            tiff: None,
            planes,
            tiff_pages: Vec::new(),
        })
    }

    pub(super) fn describe(&self) -> String {
        format!(
            "{}×{} {} with {} channel(s)",
            self.width,
            self.height,
            self.sample_type.name(),
            self.channels
        )
    }

    /// (file, page, plane) of every image this file gives to a series built from files: the
    /// file and IFD of each selected plane of a TIFF (another file of its OME set for a plane
    /// stored there), this file and the selected planes otherwise.
    pub(super) fn images(&self) -> Vec<(PathBuf, usize, Option<SelectedPlane>)> {
        match &self.tiff {
            Some(_) => self
                .tiff_pages
                .iter()
                .map(|p| (p.path.clone(), p.ifd, None))
                .collect(),
            None => self
                .planes
                .iter()
                .map(|p| (self.path.clone(), p.load_index, Some(p.clone())))
                .collect(),
        }
    }

    /// The other files of a multi-file OME set this file reads planes from.
    pub(super) fn set_members(&self) -> Vec<&Path> {
        let mut members: Vec<&Path> = Vec::new();
        for p in &self.tiff_pages {
            if p.path != self.path && !members.contains(&p.path.as_path()) {
                members.push(&p.path);
            }
        }
        members
    }
}
