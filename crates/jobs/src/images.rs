//! Images as the optics jobs (`psf`, `newton`, `autocorr`) take them: a file (TIFF, CZI, ND2,
//! LIF) whose planes the request's selection names, or planes already in memory (Python hands
//! over numpy arrays in their stored sample type). Both become [`Image`]s (`f64` values with a
//! pixel size), as the optics algorithms take them; the sample type travels beside them, since
//! the detector's range (`psf`'s saturation level) follows from it.

use std::path::{Path, PathBuf};

use contactscope::image::{pixel_size_or, Image, SampleType};
use contactscope_formats::microscopy::select::{read_images, read_one_image, LoadAxis, Selection};
use contactscope_formats::param::Param;

use crate::error::{Error, Result};

/// Planes in memory: all of one size, in their stored sample type.
#[derive(Debug, Clone, PartialEq)]
pub struct MemoryImages {
    /// What to call them in outputs and messages (`beads`, `reflection`).
    pub label: String,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// The planes' values, row-major, `height` rows of `width` each (exact for every stored
    /// type, float64 included).
    pub planes: Vec<Vec<f64>>,
    /// The sample type the values were stored in.
    pub sample_type: SampleType,
}

/// One input of an optics job.
#[derive(Debug, Clone, PartialEq)]
pub enum ImageInput {
    /// A file; the request's selection names its planes.
    File(PathBuf),
    /// Planes in memory; they carry no pixel size (the request's is needed).
    Memory(MemoryImages),
}

impl ImageInput {
    /// The name outputs give the input: the path as given, or the label of the planes.
    pub fn label(&self) -> String {
        match self {
            ImageInput::File(path) => path.display().to_string(),
            ImageInput::Memory(m) => m.label.clone(),
        }
    }

    /// The file, if the input is one.
    pub fn path(&self) -> Option<&Path> {
        match self {
            ImageInput::File(path) => Some(path),
            ImageInput::Memory(_) => None,
        }
    }

    /// What a request can check before reading: planes in memory are all there, of one size,
    /// with a pixel size given for them and no file selection.
    pub fn check(&self, selection: &Selection, pixel_size_m: Option<(f64, f64)>) -> Result<()> {
        let ImageInput::Memory(m) = self else {
            return Ok(());
        };
        if m.planes.is_empty() || m.width == 0 || m.height == 0 {
            return Err(Error::InvalidArgument(format!(
                "{}: the image stack is empty",
                m.label
            )));
        }
        if let Some(i) = m.planes.iter().position(|p| p.len() != m.width * m.height) {
            return Err(Error::InvalidArgument(format!(
                "{}: plane {i} has {} values, not {}×{}",
                m.label,
                m.planes[i].len(),
                m.width,
                m.height
            )));
        }
        if pixel_size_m.is_none() {
            return Err(Error::InvalidArgument(format!(
                "{}: images in memory carry no pixel size; give one with {}",
                m.label,
                Param::PixelSize
            )));
        }
        if *selection != Selection::default() {
            return Err(Error::InvalidArgument(format!(
                "{}: {}, {}, {}, {} and {} select planes of files, not of images in memory",
                m.label,
                Param::Series,
                Param::Channel,
                Param::Z,
                Param::T,
                Param::Axis
            )));
        }
        Ok(())
    }

    /// Every selected image: of a file as [`read_images`] reads it (pages of a TIFF, planes of
    /// a CZI, ND2 or LIF file along `along`), or every plane in memory; the pixel size is
    /// `pixel_size_m`, else the file's.
    pub fn read(
        &self,
        selection: &Selection,
        along: Option<LoadAxis>,
        pixel_size_m: Option<(f64, f64)>,
    ) -> Result<Vec<Image>> {
        match self {
            ImageInput::File(path) => Ok(read_images(path, selection, along, pixel_size_m)?),
            ImageInput::Memory(m) => Ok(m.images(pixel_size_m)),
        }
    }

    /// The one image the selection names (a TIFF must have a single page; planes in memory
    /// must be one).
    pub fn read_one(
        &self,
        selection: &Selection,
        pixel_size_m: Option<(f64, f64)>,
    ) -> Result<Image> {
        match self {
            ImageInput::File(path) => Ok(read_one_image(path, selection, pixel_size_m)?),
            ImageInput::Memory(m) => {
                let mut images = m.images(pixel_size_m);
                if images.len() != 1 {
                    return Err(Error::InvalidArgument(format!(
                        "{}: one image (a 2-D array) is needed; got {} planes",
                        m.label,
                        images.len()
                    )));
                }
                Ok(images.remove(0))
            }
        }
    }
}

impl MemoryImages {
    /// The planes as images, page = plane index.
    fn images(&self, pixel_size_m: Option<(f64, f64)>) -> Vec<Image> {
        self.planes
            .iter()
            .enumerate()
            .map(|(page, values)| Image {
                values: values.clone(),
                width: self.width,
                height: self.height,
                pixel_size: pixel_size_or(None, pixel_size_m),
                path: PathBuf::from(&self.label),
                page,
            })
            .collect()
    }
}

/// The files among `inputs` (a staging folder never writes over them).
pub fn input_files<'a>(inputs: impl IntoIterator<Item = &'a ImageInput>) -> Vec<PathBuf> {
    inputs
        .into_iter()
        .filter_map(|i| i.path().map(Path::to_path_buf))
        .collect()
}
