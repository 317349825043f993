//! Writing TIFF stacks with ImageJ calibration (for generated series and saved masks).
//!
//! The ImageJ convention (read back by [`super::read`]): ImageDescription on the first page
//! with `ImageJ=`, `images=`, `slices=` and `unit=micron`, and X/YResolution as pixels per
//! micron with ResolutionUnit = NONE.

use std::io::Cursor;

use tiff::encoder::compression::DeflateLevel;
use tiff::encoder::{colortype, Compression as TiffCompression, Rational, TiffEncoder, TiffValue};
use tiff::tags::{ResolutionUnit, Tag};

use crate::error::{Error, Result};

fn encode_error(e: tiff::TiffError) -> Error {
    Error::Output {
        path: "<tiff encoder>".into(),
        reason: e.to_string(),
    }
}

/// Pixels per micron as a rational with six decimal places.
fn per_micron(size_m: f64) -> Rational {
    let d = (size_m * 1e12).round().clamp(1.0, f64::from(u32::MAX)) as u32;
    Rational { n: 1_000_000, d }
}

fn imagej_description(pages: usize, pixel_size: Option<(f64, f64)>, extra: &str) -> String {
    let mut d = format!("ImageJ=1.11a\nimages={pages}\nslices={pages}\nloop=false\n");
    if pixel_size.is_some() {
        d.push_str("unit=micron\n");
    }
    d.push_str(extra);
    d
}

/// What a written file's values are, for its ImageJ description: `quantity=` and, for values with
/// a unit, `vunit=` (ImageJ's key for the unit of calibrated values). contactscope's readers
/// honour both: `topography` reads a `height` map in its `vunit` and refuses other quantities,
/// `compare` takes only `contact` maps, `analyze` only `intensity` images.
pub fn values_description(quantity: &str, unit: Option<&str>) -> String {
    match unit {
        Some(u) => format!("quantity={quantity}\nvunit={u}\n"),
        None => format!("quantity={quantity}\n"),
    }
}

/// The quantities contactscope writes (`quantity=` of [`values_description`]).
pub mod quantity {
    /// Heights of a surface (the deformed topography of `simulate`).
    pub const HEIGHT: &str = "height";
    /// Contact pressure.
    pub const PRESSURE: &str = "pressure";
    /// Gap between the surfaces.
    pub const GAP: &str = "gap";
    /// Plastic displacement.
    pub const PLASTIC: &str = "plastic_displacement";
    /// Computed contact, 1 in contact and 0 elsewhere.
    pub const CONTACT: &str = "contact";
    /// A thresholded micrograph's contact mask, 255 in contact and 0 elsewhere.
    pub const CONTACT_MASK: &str = "contact_mask";
    /// Fluorescence intensity (camera counts): a micrograph.
    pub const INTENSITY: &str = "intensity";
}

/// Compression of written TIFF pages.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compression {
    /// Uncompressed strips.
    #[default]
    None,
    /// LZW, no predictor.
    Lzw,
    /// Adobe Deflate, no predictor.
    Deflate,
    /// Adobe Deflate at level 1, no predictor: the same format as [`Compression::Deflate`] (every
    /// reader that opens one opens the other), written about six times faster. On the float32
    /// maps of a 2048² `simulate` ramp (measured) a map takes 57–88 ms against 350–550 ms at the
    /// default level 6; the maps of real-valued fields come out as large as at level 6 (within
    /// 4 %; 21 % larger for the mostly-zero pressure of the lightest load), the 0/1 contact maps
    /// 2.7–3.6× larger (0.09–0.16 MB), the whole folder 0.5 % larger.
    DeflateFast,
}

impl Compression {
    fn to_tiff(self) -> TiffCompression {
        match self {
            Compression::None => TiffCompression::Uncompressed,
            Compression::Lzw => TiffCompression::Lzw,
            Compression::Deflate => TiffCompression::Deflate(Default::default()),
            Compression::DeflateFast => TiffCompression::Deflate(DeflateLevel::Fast),
        }
    }
}

fn encode_stack<C: colortype::ColorType>(
    pages: &[&[C::Inner]],
    width: usize,
    height: usize,
    pixel_size: Option<(f64, f64)>,
    extra_description: &str,
    compression: Compression,
) -> Result<Vec<u8>>
where
    [C::Inner]: TiffValue,
{
    // Room for the uncompressed pages, so that the buffer does not grow (and copy itself) while
    // a large page is written; what is not written is never touched.
    let raw = pages.len() * width * height * std::mem::size_of::<C::Inner>();
    let mut bytes = Cursor::new(Vec::with_capacity(raw + 4096));
    let mut encoder = TiffEncoder::new(&mut bytes)
        .map_err(encode_error)?
        .with_compression(compression.to_tiff());
    let description = imagej_description(pages.len(), pixel_size, extra_description);
    for (i, page) in pages.iter().enumerate() {
        if page.len() != width * height {
            return Err(Error::InvalidArgument(format!(
                "page {i} has {} values, expected {width}×{height}",
                page.len()
            )));
        }
        let mut image = encoder
            .new_image::<C>(width as u32, height as u32)
            .map_err(encode_error)?;
        if i == 0 {
            image
                .encoder()
                .write_tag(Tag::ImageDescription, description.as_str())
                .map_err(encode_error)?;
        }
        if let Some((x, y)) = pixel_size {
            image.resolution_unit(ResolutionUnit::None);
            image.x_resolution(per_micron(x));
            image.y_resolution(per_micron(y));
        }
        image.write_data(page).map_err(encode_error)?;
    }
    Ok(bytes.into_inner())
}

/// Encode 16-bit grey pages (micrographs: described as `quantity=intensity`) as one
/// uncompressed multi-page TIFF with ImageJ calibration (pixel size in m).
pub fn encode_u16_stack(
    pages: &[&[u16]],
    width: usize,
    height: usize,
    pixel_size: Option<(f64, f64)>,
    extra_description: &str,
) -> Result<Vec<u8>> {
    encode_u16_stack_compressed(
        pages,
        width,
        height,
        pixel_size,
        extra_description,
        Compression::None,
    )
}

/// [`encode_u16_stack`] with a choice of compression.
pub fn encode_u16_stack_compressed(
    pages: &[&[u16]],
    width: usize,
    height: usize,
    pixel_size: Option<(f64, f64)>,
    extra_description: &str,
    compression: Compression,
) -> Result<Vec<u8>> {
    let description = format!(
        "{extra_description}{}",
        values_description(quantity::INTENSITY, None)
    );
    encode_stack::<colortype::Gray16>(pages, width, height, pixel_size, &description, compression)
}

/// Encode 8-bit grey pages (masks: 0 or 255) as one multi-page TIFF with ImageJ calibration,
/// described as `quantity=contact_mask`.
pub fn encode_u8_stack(
    pages: &[&[u8]],
    width: usize,
    height: usize,
    pixel_size: Option<(f64, f64)>,
) -> Result<Vec<u8>> {
    let description = values_description(quantity::CONTACT_MASK, None);
    encode_stack::<colortype::Gray8>(
        pages,
        width,
        height,
        pixel_size,
        &description,
        Compression::Deflate,
    )
}

/// Encode 32-bit float grey pages (maps of the solver) as one TIFF with ImageJ calibration,
/// Deflate-compressed at level 1 ([`Compression::DeflateFast`]; no predictor, so that ImageJ's
/// own TIFF reader, which ignores the floating-point predictor, opens them as well).
pub fn encode_f32_stack(
    pages: &[&[f32]],
    width: usize,
    height: usize,
    pixel_size: Option<(f64, f64)>,
    extra_description: &str,
) -> Result<Vec<u8>> {
    encode_stack::<colortype::Gray32Float>(
        pages,
        width,
        height,
        pixel_size,
        extra_description,
        Compression::DeflateFast,
    )
}
