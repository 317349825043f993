//! Single images and z stacks as plain `f64` grids with their origin and pixel size: the input
//! of the optics commands (`psf`, `autocorr`, `newton`, `compare`), which look at one image or
//! one stack at a time rather than at a load series.

use std::path::{Path, PathBuf};

use crate::error::{Error, Location, Result};
use crate::stack::tiff::TiffReader;
use crate::stack::{PixelSize, PixelSizeSource};

/// One decoded 2-D image, row-major (`values[y * width + x]`), in the file's intensity units.
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
    /// The file it came from.
    pub path: PathBuf,
    /// Zero-based TIFF page (IFD index) it came from.
    pub page: usize,
}

impl Image {
    /// Value at column `x`, row `y`.
    pub fn at(&self, x: usize, y: usize) -> f64 {
        self.values[y * self.width + x]
    }

    /// Pixel size, or an error naming the file and asking for `--pixel-size`.
    pub fn require_pixel_size(&self) -> Result<PixelSize> {
        self.pixel_size.ok_or_else(|| {
            Error::bad_input(
                Location::file(&self.path),
                "no pixel size in the file's metadata; give one with --pixel-size (e.g. 200nm)",
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

/// Every page of one channel of a TIFF file (a z stack, a time series or a single image), in
/// page order. `channel` may be `None` for single-channel files only.
pub fn read_pages(
    path: &Path,
    channel: Option<usize>,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<Vec<Image>> {
    let mut reader = TiffReader::open(path)?;
    let info = reader.info().clone();
    let channel = match channel {
        None if info.channels > 1 => {
            return Err(Error::bad_input(
                Location::file(path),
                format!(
                    "file has {} channels ({}); choose one with --channel 0..{}",
                    info.channels,
                    info.channel_layout.describe(),
                    info.channels - 1
                ),
            ))
        }
        Some(c) if c >= info.channels => {
            return Err(Error::bad_input(
                Location::file(path),
                format!(
                    "channel {c} requested but the file has {} channel(s)",
                    info.channels
                ),
            ))
        }
        c => c.unwrap_or(0),
    };
    let pixel_size = pixel_size_or(info.pixel_size, pixel_size_m);
    info.pages_of_channel(channel)
        .into_iter()
        .map(|page| {
            let plane = reader.read_page(page, channel)?;
            Ok(Image {
                values: plane.to_f64(),
                width: plane.width,
                height: plane.height,
                pixel_size,
                path: path.to_path_buf(),
                page,
            })
        })
        .collect()
}

/// The one image of a single-page file (per channel); a file with several pages is an error
/// naming the page count.
pub fn read_image(
    path: &Path,
    channel: Option<usize>,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<Image> {
    let mut pages = read_pages(path, channel, pixel_size_m)?;
    match pages.len() {
        1 => Ok(pages.remove(0)),
        0 => Err(Error::bad_input(
            Location::file(path),
            "file holds no image",
        )),
        n => Err(Error::bad_input(
            Location::file(path),
            format!("file holds {n} pages; a single 2-D image is expected here"),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stack::write::encode_u16_stack;

    #[test]
    fn pages_and_single_image() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("two.tif");
        let page = |k: u16| (0..6u16).map(|i| i + 10 * k).collect::<Vec<_>>();
        let (p0, p1) = (page(0), page(1));
        let bytes = encode_u16_stack(&[&p0, &p1], 3, 2, Some((0.2e-6, 0.2e-6)), "").unwrap();
        std::fs::write(&path, bytes).unwrap();
        let pages = read_pages(&path, None, None).unwrap();
        assert_eq!(pages.len(), 2);
        assert_eq!((pages[1].width, pages[1].height), (3, 2));
        assert_eq!(pages[1].at(2, 1), 15.0);
        let px = pages[0].require_pixel_size().unwrap();
        assert!((px.x_m - 0.2e-6).abs() < 1e-12);
        let err = read_image(&path, None, None).unwrap_err().to_string();
        assert!(err.contains("2 pages") && err.contains("two.tif"), "{err}");
        let over = read_pages(&path, None, Some((1e-7, 1e-7))).unwrap();
        assert_eq!(
            over[0].pixel_size.unwrap().source,
            PixelSizeSource::CommandLine
        );
        assert!(read_pages(&path, Some(1), None).is_err());
    }
}
