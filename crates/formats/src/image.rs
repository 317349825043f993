//! Images in memory and their calibration: one decoded page (a [`Plane`]) with its sample type,
//! the pixel size with the metadata it came from, and plain `f64` images ([`Image`]) for the
//! optics commands. No file access here: readers live in [`crate::tiff`].
//!
//! Integer data of every width is held as `u16` codes plus an offset (`value = code + offset`),
//! so that one 65 536-bin histogram indexes any 8-bit, 16-bit or signed 16-bit image directly and
//! exactly. Float data is held as `f32`.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{Error, Location, Result};

/// Sample type of the data as stored in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SampleType {
    /// Unsigned 8-bit integers.
    U8,
    /// Unsigned 16-bit integers (also 12-bit data in a 16-bit container).
    U16,
    /// Signed 16-bit integers.
    I16,
    /// 32-bit IEEE floats.
    F32,
    /// 64-bit IEEE floats (held as f32 after decoding).
    F64,
}

impl SampleType {
    /// Short lowercase name, as numpy writes it.
    pub fn name(self) -> &'static str {
        match self {
            SampleType::U8 => "uint8",
            SampleType::U16 => "uint16",
            SampleType::I16 => "int16",
            SampleType::F32 => "float32",
            SampleType::F64 => "float64",
        }
    }

    /// Bytes of one sample.
    pub fn bytes(self) -> usize {
        match self {
            SampleType::U8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::F32 => 4,
            SampleType::F64 => 8,
        }
    }

    /// Whether values are integers (one histogram bin per level).
    pub fn is_integer(self) -> bool {
        matches!(self, SampleType::U8 | SampleType::U16 | SampleType::I16)
    }
}

/// The pixel values of one image plane, row-major (y, x).
#[derive(Debug, Clone, PartialEq)]
pub enum Samples {
    /// Integer data: `value = code + offset`.
    Int {
        /// Codes, one per pixel.
        codes: Vec<u16>,
        /// Added to every code to give the stored value (−32768 for int16, else 0).
        offset: i32,
    },
    /// Float data; NaN and ±∞ are kept and excluded from histograms and never count as contact.
    Float(Vec<f32>),
}

/// One decoded image plane of one channel.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// Width in pixels (x, fastest axis).
    pub width: usize,
    /// Height in pixels (y).
    pub height: usize,
    /// Sample type as stored in the file.
    pub sample_type: SampleType,
    /// The values.
    pub samples: Samples,
}

impl Plane {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// Whether the plane has no pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The value of pixel `i` (row-major) as f64.
    pub fn value(&self, i: usize) -> f64 {
        match &self.samples {
            Samples::Int { codes, offset } => f64::from(i32::from(codes[i]) + offset),
            Samples::Float(v) => f64::from(v[i]),
        }
    }

    /// All values as f64, row-major (for plotting and small computations).
    pub fn to_f64(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.value(i)).collect()
    }

    /// Build a plane from u16 values (used by generators and tests).
    pub fn from_u16(width: usize, height: usize, codes: Vec<u16>) -> Self {
        assert_eq!(codes.len(), width * height, "plane size mismatch");
        Plane {
            width,
            height,
            sample_type: SampleType::U16,
            samples: Samples::Int { codes, offset: 0 },
        }
    }

    /// Approximate heap size in bytes.
    pub fn heap_bytes(&self) -> usize {
        match &self.samples {
            Samples::Int { codes, .. } => codes.len() * 2,
            Samples::Float(v) => v.len() * 4,
        }
    }
}

/// Where a pixel size came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PixelSizeSource {
    /// Given by the caller: `--pixel-size` on the command line, `pixel_size=` in Python.
    CommandLine,
    /// OME-XML `PhysicalSizeX`/`PhysicalSizeY` in the ImageDescription.
    OmeXml,
    /// ImageJ `unit=` in the ImageDescription with the X/YResolution rationals.
    ImageJ,
    /// TIFF ResolutionUnit (centimetre or inch) with X/YResolution.
    ResolutionTags,
    /// Zeiss CZI `Metadata/Scaling/Items/Distance[@Id=X|Y]/Value`.
    CziScaling,
    /// Nikon ND2 `SLxPictureMetadata/dCalibration`.
    Nd2Calibration,
    /// Leica LIF `DimensionDescription` (DimID 1, 2) `Length/(NumberOfElements − 1)`.
    LifDimensions,
    /// OME-Zarr: the full-resolution level's `scale` (times the image's own) in the axis `unit`.
    OmeZarrScale,
    /// Given for files that state none (`--pixel-size-default`; a batch's `--pixel-size`),
    /// used because these files state none.
    DefaultForUncalibrated,
}

impl PixelSizeSource {
    /// Human-readable name.
    pub fn describe(self) -> &'static str {
        match self {
            PixelSizeSource::CommandLine => match crate::param::front_end() {
                crate::param::FrontEnd::Python => "given (pixel_size=)",
                crate::param::FrontEnd::CommandLine => "command line (--pixel-size)",
                crate::param::FrontEnd::Library => "given by the caller",
            },
            PixelSizeSource::OmeXml => "OME-XML PhysicalSizeX/Y",
            PixelSizeSource::ImageJ => "ImageJ unit + X/YResolution",
            PixelSizeSource::ResolutionTags => "TIFF ResolutionUnit + X/YResolution",
            PixelSizeSource::CziScaling => "CZI Metadata/Scaling/Items/Distance X/Y",
            PixelSizeSource::Nd2Calibration => "ND2 SLxPictureMetadata/dCalibration",
            PixelSizeSource::LifDimensions => {
                "LIF DimensionDescription DimID 1/2 Length/(NumberOfElements-1)"
            }
            PixelSizeSource::OmeZarrScale => "OME-Zarr scale of the level read × axis unit",
            PixelSizeSource::DefaultForUncalibrated => match crate::param::front_end() {
                crate::param::FrontEnd::Python => {
                    "given for files without one (pixel_size_default=)"
                }
                crate::param::FrontEnd::CommandLine => {
                    "default for files without one (--pixel-size-default)"
                }
                crate::param::FrontEnd::Library => "the default for files without one",
            },
        }
    }
}

/// Lateral pixel size in metres, with its source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PixelSize {
    /// Size along x (columns), metres.
    pub x_m: f64,
    /// Size along y (rows), metres.
    pub y_m: f64,
    /// Where it came from.
    pub source: PixelSizeSource,
}

impl PixelSize {
    /// Pixel area in µm².
    pub fn area_um2(&self) -> f64 {
        self.x_m * self.y_m * 1e12
    }

    /// Whether two pixel sizes agree to 1e-6 relative.
    pub fn same_size(&self, other: &PixelSize) -> bool {
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.abs().max(b.abs());
        close(self.x_m, other.x_m) && close(self.y_m, other.y_m)
    }
}

/// One decoded 2-D image as plain `f64`s, row-major (`values[y * width + x]`), in the file's
/// intensity units, with the pixel size and the page it came from: the input of the optics
/// commands (`psf`, `autocorr`, `newton`, `compare`), which look at one image or one stack at a
/// time rather than at a load series. A z stack is a `Vec<Image>` in page order.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Pixel values, `height` rows of `width`.
    pub values: Vec<f64>,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Pixel size from `--pixel-size` or the file's metadata, if known.
    pub pixel_size: Option<PixelSize>,
    /// The file it came from (a label for messages; nothing here opens it).
    pub path: PathBuf,
    /// Zero-based TIFF page (IFD index) it came from.
    pub page: usize,
}

impl Image {
    /// A decoded plane of `path` (`page`: its IFD, or its place along the load axis) with its
    /// pixel size.
    pub fn of_plane(
        plane: &Plane,
        pixel_size: Option<PixelSize>,
        path: &Path,
        page: usize,
    ) -> Self {
        Image {
            values: plane.to_f64(),
            width: plane.width,
            height: plane.height,
            pixel_size,
            path: path.to_path_buf(),
            page,
        }
    }

    /// Value at column `x`, row `y`.
    pub fn at(&self, x: usize, y: usize) -> f64 {
        self.values[y * self.width + x]
    }

    /// Pixel size, or an error naming the file and asking for `--pixel-size`.
    pub fn require_pixel_size(&self) -> Result<PixelSize> {
        self.pixel_size.ok_or_else(|| {
            Error::bad_input(
                Location::file(&self.path),
                format!(
                    "no pixel size in the file's metadata; give one with {} (e.g. 200nm)",
                    crate::param::Param::PixelSize
                ),
            )
        })
    }
}

/// The override as a [`PixelSize`], else the file's own.
pub fn pixel_size_or(file: Option<PixelSize>, override_m: Option<(f64, f64)>) -> Option<PixelSize> {
    match override_m {
        Some((x_m, y_m)) => Some(PixelSize {
            x_m,
            y_m,
            source: PixelSizeSource::CommandLine,
        }),
        None => file,
    }
}
