//! TIFF described as a [`MicroscopyFile`](super::MicroscopyFile) series, through the existing
//! [`crate::tiff`] reader: one series, `C` = channels (samples per pixel or ImageJ
//! hyperstack channels), `Z` = full-resolution pages per channel (ImageJ slices and frames are
//! not told apart: pages of one channel are counted along `Z`), `T` = 1.

use std::collections::BTreeMap;
use std::path::Path;

use super::{Axes, ChannelInfo, PlaneIndex, SeriesInfo, VoxelSize};
use crate::error::Result;
use crate::image::Plane;
use crate::tiff::TiffReader;

/// An open TIFF.
pub(crate) struct TiffBackend {
    reader: TiffReader,
}

impl TiffBackend {
    pub(crate) fn open(path: &Path) -> Result<Self> {
        Ok(TiffBackend {
            reader: TiffReader::open(path)?,
        })
    }

    pub(crate) fn series(&self) -> Vec<SeriesInfo> {
        let info = self.reader.info();
        let z = info.pages_of_channel(0).len();
        let pixel_size = match info.pixel_size {
            Some(p) => VoxelSize {
                x_m: Some(p.x_m),
                y_m: Some(p.y_m),
                z_m: None,
                source: Some(p.source.describe().to_string()),
            },
            None => VoxelSize::default(),
        };
        vec![SeriesInfo {
            index: 0,
            name: String::new(),
            axes: Axes {
                t: 1,
                z,
                c: info.channels,
                y: info.height,
                x: info.width,
                extra: BTreeMap::new(),
            },
            dtype: info.sample_type,
            pixel_size,
            channels: vec![ChannelInfo::default(); info.channels],
            rows: super::Rows::Y,
        }]
    }

    pub(crate) fn read_plane(&mut self, _info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let page = self.reader.info().pages_of_channel(index.c)[index.z];
        self.reader.read_page(page, index.c)
    }
}
