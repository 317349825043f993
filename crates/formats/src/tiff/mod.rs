//! TIFF files: the reader ([`read`]: header facts, pages, channels, pixel-size metadata), the
//! ImageJ/OME metadata parsers ([`metadata`]) and the writer ([`mod@write`]); plus the single images
//! and z stacks of the optics commands as [`Image`]s ([`read_pages`], [`read_image`]).

pub mod axes;
pub mod companion;
mod images;
pub mod metadata;
pub mod read;
pub mod spare;
pub mod write;

use std::path::Path;

pub use axes::{AxesSource, OmeImage, Place, TiffAxes};
pub use read::{ChannelLayout, TiffInfo, TiffReader};
pub use write::{
    encode_f32_stack, encode_u16_stack, encode_u16_stack_compressed, encode_u8_stack, Compression,
};

use crate::error::{Error, Location, Result};
use crate::image::{pixel_size_or, Image};

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
                    "file has {} channels ({}); choose one with {}",
                    info.channels,
                    info.channel_layout.describe(),
                    crate::param::Param::Channel.with_value(format!("0..{}", info.channels - 1))
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
            Ok(Image::of_plane(&plane, pixel_size, path, page))
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
    use crate::image::{PixelSizeSource, Samples};

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

    #[test]
    fn pages_decoded_into_handed_back_buffers_are_the_pages() {
        // Uncompressed and LZW pages of one size; each read after the previous page's codes
        // were handed back (so it decodes over them) gives the page, not what was there.
        let (width, height) = (37, 23);
        let page = |k: u16| -> Vec<u16> {
            (0..width * height)
                .map(|i| (i as u16).wrapping_mul(31).wrapping_add(977 * k))
                .collect()
        };
        let pages: Vec<Vec<u16>> = (0..4).map(page).collect();
        let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
        let dir = tempfile::tempdir().unwrap();
        for compression in [Compression::None, Compression::Lzw] {
            let bytes =
                encode_u16_stack_compressed(&refs, width, height, None, "", compression).unwrap();
            let path = dir.path().join("pages.tif");
            std::fs::write(&path, bytes).unwrap();
            let mut reader = TiffReader::open(&path).unwrap();
            for k in [0, 1, 2, 3, 1, 0] {
                let Samples::Int { codes, offset: 0 } = reader.read_page(k, 0).unwrap().samples
                else {
                    panic!("uint16 pages");
                };
                assert_eq!(codes, pages[k], "page {k}");
                spare::give_back(codes);
            }
            // A buffer of another size is not used for these pages.
            spare::give_back(vec![7; 5]);
            let Samples::Int { codes, .. } = reader.read_page(2, 0).unwrap().samples else {
                panic!("uint16 pages");
            };
            assert_eq!(codes, pages[2]);
            // A reader opened with the headers read before decodes the same pages; once the
            // file has fewer pages, asking for a gone one is an error naming the file.
            let info = reader.info().clone();
            let mut again = TiffReader::reopen(info.clone()).unwrap();
            let Samples::Int { codes, .. } = again.read_page(3, 0).unwrap().samples else {
                panic!("uint16 pages");
            };
            assert_eq!(codes, pages[3]);
            let fewer = encode_u16_stack(&refs[..2], width, height, None, "").unwrap();
            std::fs::write(&path, fewer).unwrap();
            let err = TiffReader::reopen(info)
                .unwrap()
                .read_page(3, 0)
                .unwrap_err()
                .to_string();
            assert!(err.contains("pages.tif"), "{err}");
        }
    }

    #[test]
    fn float_maps_round_trip_bit_for_bit() {
        // `simulate`'s maps (Deflate level 1, several strips): every bit of every value comes
        // back through our reader, NaN payloads, −0, ±∞ and subnormals included.
        let (width, height) = (301, 1000);
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut values: Vec<f32> = (0..width * height)
            .map(|i| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                match i % 5 {
                    // Smooth, like a gap or height map, and arbitrary bit patterns.
                    0 | 1 => (i as f32 * 1e-3).sin() * 3.7,
                    2 => f32::from_bits(state as u32),
                    3 => 0.0,
                    _ => (state >> 40) as f32 * 1e-6,
                }
            })
            .collect();
        values[..6].copy_from_slice(&[
            f32::from_bits(0x7fc0_1234),
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::from_bits(1),
            f32::MAX,
        ]);
        let second: Vec<f32> = values.iter().rev().copied().collect();
        let bytes = encode_f32_stack(
            &[&values, &second],
            width,
            height,
            Some((32e-9, 32e-9)),
            "contactscope simulate gap_um\n",
        )
        .unwrap();
        assert!(bytes.len() < 8 * width * height, "compressed");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("map.tif");
        std::fs::write(&path, bytes).unwrap();
        let mut reader = TiffReader::open(&path).unwrap();
        let info = reader.info().clone();
        assert_eq!(info.compression, "Deflate");
        assert_eq!(
            (info.width, info.height, info.pages.len()),
            (width, height, 2)
        );
        assert!((info.pixel_size.unwrap().x_m - 32e-9).abs() < 1e-15);
        for (page, expected) in [values, second].iter().enumerate() {
            let Samples::Float(read) = reader.read_page(page, 0).unwrap().samples else {
                panic!("float32 pages");
            };
            assert_eq!(read.len(), expected.len());
            let differing = read
                .iter()
                .zip(expected)
                .filter(|(a, b)| a.to_bits() != b.to_bits())
                .count();
            assert_eq!(differing, 0, "page {page}");
        }
    }
}
