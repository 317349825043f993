//! The images of a TIFF as series: one for most files, one per OME `Image` element of a
//! multi-image OME-TIFF ([`super::axes::OmeImage`]; stage positions, scenes, tifffile's series
//! written one after another), each seen alone with its own axes, plane size and pixel size.

use super::axes::{OmeImage, TiffAxes};
use super::read::TiffInfo;
use crate::image::{PixelSize, PixelSizeSource};

impl TiffInfo {
    /// The series the file holds: its OME images, else 1.
    pub fn series_count(&self) -> usize {
        self.images.len().max(1)
    }

    /// The axes of series (OME image) `series`.
    pub fn axes_of(&self, series: usize) -> Option<&TiffAxes> {
        match self.images.is_empty() {
            true => (series == 0).then_some(&self.axes),
            false => self.images.get(series).map(|i| &i.axes),
        }
    }

    /// The file as series `series` alone shows it: that image's axes, plane size (OME `SizeX`,
    /// `SizeY`: the file's first page may belong to another image), channels and pixel size
    /// ([`TiffInfo::image_pixel_size`]), every image kept; `None` for a series the file does
    /// not hold.
    pub fn image(&self, series: usize) -> Option<TiffInfo> {
        if self.images.is_empty() {
            return (series == 0).then(|| self.clone());
        }
        let image = self.images.get(series)?;
        Some(TiffInfo {
            width: image.width,
            height: image.height,
            channels: image.axes.c,
            pixel_size: self.image_pixel_size(image),
            axes: image.axes.clone(),
            ..self.clone()
        })
    }

    /// The pixel size of one image of a multi-image OME-TIFF: its `PhysicalSizeX/Y`, else the
    /// file's own (resolution tags or an ImageJ description; never another image's OME size).
    pub fn image_pixel_size(&self, image: &OmeImage) -> Option<PixelSize> {
        match image.pixel_size_m {
            Some((x_m, y_m)) => Some(PixelSize {
                x_m,
                y_m,
                source: PixelSizeSource::OmeXml,
            }),
            None => self
                .pixel_size
                .filter(|p| p.source != PixelSizeSource::OmeXml),
        }
    }

    /// The files of a multi-file OME set holding planes of any image of this file, as the
    /// OME-XML names them (`UUID FileName`), each once.
    pub fn set_files(&self) -> Vec<&str> {
        let mut names: Vec<&str> = Vec::new();
        let all = std::iter::once(&self.axes).chain(self.images.iter().map(|i| &i.axes));
        for name in all.flat_map(|a| a.other_files.iter()) {
            if !names.contains(&name.as_str()) {
                names.push(name);
            }
        }
        names
    }
}
