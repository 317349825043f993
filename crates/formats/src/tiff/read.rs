//! TIFF pages → [`Plane`]s, with the facts `contactscope info` prints.
//!
//! Built on the `tiff` crate's decoder. Two of its behaviours are handled here on purpose
//! (`docs/formats.md`, TIFF): `read_image` returns only the first plane of a planar
//! (PlanarConfiguration = 2) file, so we use `read_image_to_buffer` and check that every plane
//! arrived; and packed 12-bit or palette images are reported as unsupported, never guessed at.
//! Reduced-resolution pages (NewSubfileType bit 0, e.g. LSM thumbnails) are skipped.

use std::io::{BufReader, Read, Seek};
use std::path::{Path, PathBuf};

use serde::Serialize;
use tiff::decoder::{Decoder, DecodingResult, DecodingSampleType, Limits};
use tiff::tags::Tag;
use tiff::{ColorType, TiffError};

use super::axes::{AxesSource, OmeImage, TiffAxes};
use super::metadata::{self, ImageJDescription};
use crate::error::{Error, Location, Result};
use crate::image::{PixelSize, PixelSizeSource, Plane, SampleType, Samples};
use crate::remote::{open_input, Input};

/// Largest decoded page we accept (bytes); guards allocations against absurd header dimensions.
pub const MAX_PAGE_BYTES: usize = crate::limits::Limits::DEFAULT.max_plane_bytes;

/// How the channels of a file are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChannelLayout {
    /// One sample per pixel and one channel.
    Single,
    /// Several samples per pixel, interleaved (PlanarConfiguration = 1).
    Contiguous,
    /// Several samples per pixel, one plane each (PlanarConfiguration = 2).
    Planar,
    /// An ImageJ hyperstack: one channel per page, channel index fastest.
    ImageJPages,
    /// An OME-TIFF: one channel per page, in the XML's `DimensionOrder`.
    OmePages,
}

impl ChannelLayout {
    /// A short description for people.
    pub fn describe(self) -> &'static str {
        match self {
            ChannelLayout::Single => "one channel",
            ChannelLayout::Contiguous => "interleaved samples per pixel",
            ChannelLayout::Planar => "one plane per sample (planar)",
            ChannelLayout::ImageJPages => "ImageJ hyperstack, one page per channel",
            ChannelLayout::OmePages => "OME-TIFF, one page per channel",
        }
    }
}

/// What a TIFF file holds, read from its headers without decoding pixel data.
#[derive(Debug, Clone, Serialize)]
pub struct TiffInfo {
    /// The file.
    pub path: PathBuf,
    /// IFD indices of full-resolution pages (thumbnails excluded).
    pub pages: Vec<usize>,
    /// Width of the first page in pixels.
    pub width: usize,
    /// Height of the first page in pixels.
    pub height: usize,
    /// Sample type of the first page.
    pub sample_type: SampleType,
    /// Bits per sample as stored.
    pub bits_per_sample: u8,
    /// Number of channels (samples per pixel, ImageJ `channels=` or OME `SizeC`).
    pub channels: usize,
    /// How the channels are stored.
    pub channel_layout: ChannelLayout,
    /// Compression of the first page, by name.
    pub compression: String,
    /// Predictor of the first page, by name.
    pub predictor: String,
    /// `true` for strips, `false` for tiles.
    pub tiled: bool,
    /// `true` for BigTIFF.
    pub bigtiff: bool,
    /// "little" or "big".
    pub byte_order: String,
    /// Pixel size from the file's metadata, if any.
    pub pixel_size: Option<PixelSize>,
    /// What kind of ImageDescription the file has ("ImageJ", "OME-XML", "text" or "none").
    pub description_kind: String,
    /// What the values are, where the ImageJ description says (`quantity=`; contactscope's maps
    /// and micrographs say it, see [`super::write::values_description`]).
    pub quantity: Option<String>,
    /// The values' unit, where the ImageJ description says (`vunit=`).
    pub value_unit: Option<String>,
    /// Notes about ignored or doubtful metadata.
    pub notes: Vec<String>,
    /// Channels, focal planes and time points, and the page of each plane (of the first image
    /// of a multi-image OME-TIFF).
    pub axes: TiffAxes,
    /// Every image of an OME-TIFF whose XML describes several (image 0 first, its axes those
    /// above); empty for one image. Each is a series (`--series`).
    pub images: Vec<OmeImage>,
    /// The file the OME-XML was read from when the file's own XML only points to it
    /// (`BinaryOnly`: a companion `.companion.ome` or the master TIFF of a multi-file set;
    /// [`super::companion`]).
    pub metadata_file: Option<PathBuf>,
}

impl TiffInfo {
    /// The IFD indices that hold `channel`, time points slowest, then focal planes.
    pub fn pages_of_channel(&self, channel: usize) -> Vec<usize> {
        self.axes.pages_of_channel(channel)
    }
}

/// An open TIFF file that decodes pages on request.
pub struct TiffReader {
    decoder: Decoder<BufReader<Input>>,
    info: TiffInfo,
}

fn tiff_error(at: Location, err: TiffError) -> Error {
    match err {
        TiffError::UnsupportedError(e) => Error::Unsupported {
            at,
            reason: e.to_string(),
        },
        TiffError::LimitsExceeded => Error::Unsupported {
            at,
            reason: format!(
                "page larger than the {} GiB limit (header dimensions too large?)",
                MAX_PAGE_BYTES >> 30
            ),
        },
        // A file on a server that could not be read: the network, not the file.
        TiffError::IoError(e) if crate::remote::is_network_error(&e) => Error::Io { at, source: e },
        TiffError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => Error::BadTiff {
            at,
            reason: "file is truncated".into(),
        },
        other => Error::BadTiff {
            at,
            reason: other.to_string(),
        },
    }
}

fn compression_name(code: u16) -> String {
    match code {
        1 => "none".into(),
        2 => "CCITT RLE".into(),
        5 => "LZW".into(),
        6 | 7 => "JPEG".into(),
        8 | 32946 => "Deflate".into(),
        32773 => "PackBits".into(),
        34887 => "LERC".into(),
        50000 => "zstd".into(),
        other => format!("code {other}"),
    }
}

fn predictor_name(code: u16) -> String {
    match code {
        1 => "none".into(),
        2 => "horizontal".into(),
        3 => "floating-point".into(),
        other => format!("code {other}"),
    }
}

fn rational(value: Option<tiff::decoder::ifd::Value>) -> Option<f64> {
    use tiff::decoder::ifd::Value;
    let v = match value? {
        Value::Rational(n, d) if d != 0 => f64::from(n) / f64::from(d),
        Value::Float(f) => f64::from(f),
        Value::Double(f) => f,
        Value::Unsigned(n) => f64::from(n),
        Value::Short(n) => f64::from(n),
        _ => return None,
    };
    (v.is_finite() && v > 0.0).then_some(v)
}

/// A file that is not a TIFF but a height map contactscope reads with another command: the
/// error that says so and names that command.
fn other_format(path: &Path) -> Option<Error> {
    let mut head = Vec::new();
    open_input(path)
        .ok()?
        .0
        .take(64)
        .read_to_end(&mut head)
        .ok()?;
    if let Some(map) = crate::topography::detect(&head) {
        let what = if crate::topography::container::is_container(path) {
            "a contact.engineering surface container of height maps".to_string()
        } else {
            format!("{} height map", map.with_article())
        };
        return Some(Error::Unsupported {
            at: Location::file(path),
            reason: format!(
                "{what}, not a TIFF micrograph: read it with `contactscope topography` (or \
                 `simulate --topography`)"
            ),
        });
    }
    None
}

/// A decoder of the file at `path` (its first IFD read), pages limited to [`MAX_PAGE_BYTES`];
/// `on_error` turns a decoder error into ours.
fn decoder(
    path: &Path,
    on_error: impl FnOnce(TiffError) -> Error,
) -> Result<Decoder<BufReader<Input>>> {
    let (file, _) = open_input(path)?;
    let mut limits = Limits::default();
    limits.decoding_buffer_size = MAX_PAGE_BYTES;
    Ok(Decoder::new(BufReader::new(file))
        .map_err(on_error)?
        .with_limits(limits))
}

impl TiffReader {
    /// Open a TIFF file and read its headers (every IFD, no pixel data).
    ///
    /// An OME companion file (the XML of a multi-file OME-TIFF set, [`super::companion`]) opens
    /// the set through the TIFF of its first `TiffData` block, with the companion's XML.
    pub fn open(path: &Path) -> Result<Self> {
        crate::inputs::note_input(path);
        let opened = decoder(path, |e| {
            other_format(path).unwrap_or_else(|| tiff_error(Location::file(path), e))
        });
        match opened {
            Ok(mut decoder) => {
                let info = read_info(path, &mut decoder, None)?;
                Ok(TiffReader { decoder, info })
            }
            // Not a TIFF: a companion file is looked for only then (no second open of every
            // TIFF).
            Err(_) if !crate::remote::is_url(path) && is_xml_file(path) => {
                Self::open_companion(path)
            }
            Err(e) => Err(e),
        }
    }

    /// The set of the OME companion file at `path`, through the TIFF of its first `TiffData`
    /// block, with the companion's XML.
    fn open_companion(path: &Path) -> Result<Self> {
        let (anchor, xml) = super::companion::anchor(path).map_err(|why| {
            Error::bad_input(
                Location::file(path),
                format!("an OME companion file whose set cannot be read: {why}"),
            )
        })?;
        crate::inputs::note_input(&anchor);
        let mut decoder = decoder(&anchor, |e| tiff_error(Location::file(&anchor), e))?;
        let metadata = Metadata {
            file: path.to_path_buf(),
            xml,
        };
        let info = read_info(&anchor, &mut decoder, Some(metadata))?;
        Ok(TiffReader { decoder, info })
    }

    /// Open a TIFF file whose headers were read before (`info`, from [`TiffReader::open`] of the
    /// same file): only the first IFD is read again. For the many short-lived readers of a series
    /// analysis, which would otherwise parse every IFD of a multi-page file for each page they
    /// decode. A file that changed since gives errors (or planes of another size, which the
    /// series checks) when its pages are read, never a panic. The file was noted as an input
    /// ([`crate::inputs::note_input`]) when it was first opened.
    pub fn reopen(info: TiffInfo) -> Result<Self> {
        let decoder = decoder(&info.path, |e| tiff_error(Location::file(&info.path), e))?;
        Ok(TiffReader { decoder, info })
    }

    /// Header facts of the file.
    pub fn info(&self) -> &TiffInfo {
        &self.info
    }

    /// Decode page `page` (an IFD index) and return channel `channel` of it. For ImageJ
    /// hyperstacks the channel is the page itself, so `channel` is ignored here.
    pub fn read_page(&mut self, page: usize, channel: usize) -> Result<Plane> {
        let at = Location::page(&self.info.path, page);
        self.decoder
            .seek_to_image(page)
            .map_err(|e| tiff_error(at.clone(), e))?;
        let (width, height) = self
            .decoder
            .dimensions()
            .map_err(|e| tiff_error(at.clone(), e))?;
        let colortype = self
            .decoder
            .colortype()
            .map_err(|e| tiff_error(at.clone(), e))?;
        let samples_per_pixel = check_colortype(colortype, &at)?;
        let planar = self
            .decoder
            .find_tag_unsigned::<u16>(Tag::PlanarConfiguration)
            .ok()
            .flatten()
            == Some(2);
        let (width, height) = (width as usize, height as usize);
        let layout = self
            .decoder
            .image_buffer_layout()
            .map_err(|e| tiff_error(at.clone(), e))?;
        // One-sample 16-bit pages decode into a buffer an earlier page of the same size handed
        // back (`spare`): no allocation and no zeroing of 2 MB per 1024² page.
        let spare = (samples_per_pixel == 1
            && layout.sample_type == Some(DecodingSampleType::U16)
            && layout.complete_len == width * height * 2)
            .then(|| super::spare::take(width * height))
            .flatten();
        let mut buffer = DecodingResult::U8(Vec::new());
        match spare {
            Some(codes) => {
                buffer = DecodingResult::U16(codes);
                self.decoder
                    .read_image_bytes(buffer.as_buffer(0).as_bytes_mut())
                    .map_err(|e| tiff_error(at.clone(), e))?;
            }
            None => {
                self.decoder
                    .read_image_to_buffer(&mut buffer)
                    .map_err(|e| tiff_error(at.clone(), e))?;
            }
        }
        if buffer.as_buffer(0).as_bytes().len() < layout.complete_len {
            return Err(Error::Unsupported {
                at,
                reason: "not all sample planes could be decoded within the size limit".into(),
            });
        }
        let spp = samples_per_pixel as usize;
        // Channels of several page-channels of several samples each count samples fastest.
        let channel = if spp > 1 { channel % spp } else { 0 };
        if channel >= spp {
            return Err(Error::bad_input(
                at,
                format!("channel {channel} requested but the page has {spp} samples per pixel"),
            ));
        }
        let pick = ChannelPick {
            pixels: width * height,
            spp,
            planar,
            channel,
        };
        let (sample_type, samples) = convert_samples(buffer, pick, &at)?;
        Ok(Plane {
            width,
            height,
            sample_type,
            samples,
        })
    }
}

/// Which samples of a decoded buffer form the requested channel.
#[derive(Clone, Copy)]
struct ChannelPick {
    pixels: usize,
    spp: usize,
    planar: bool,
    channel: usize,
}

impl ChannelPick {
    fn apply<T: Copy>(self, mut values: Vec<T>) -> Vec<T> {
        if self.spp == 1 {
            values.truncate(self.pixels);
            values
        } else if self.planar {
            let start = self.channel * self.pixels;
            values[start..start + self.pixels].to_vec()
        } else {
            values
                .iter()
                .skip(self.channel)
                .step_by(self.spp)
                .take(self.pixels)
                .copied()
                .collect()
        }
    }
}

fn convert_samples(
    buffer: DecodingResult,
    pick: ChannelPick,
    at: &Location,
) -> Result<(SampleType, Samples)> {
    let int = |codes: Vec<u16>, offset: i32| Samples::Int { codes, offset };
    let converted = match buffer {
        DecodingResult::U8(v) => (
            SampleType::U8,
            int(pick.apply(v).into_iter().map(u16::from).collect(), 0),
        ),
        DecodingResult::U16(v) => (SampleType::U16, int(pick.apply(v), 0)),
        DecodingResult::I16(v) => (
            SampleType::I16,
            int(
                pick.apply(v)
                    .into_iter()
                    .map(|x| (i32::from(x) + 32768) as u16)
                    .collect(),
                -32768,
            ),
        ),
        DecodingResult::F32(v) => (SampleType::F32, Samples::Float(pick.apply(v))),
        DecodingResult::F64(v) => (
            SampleType::F64,
            Samples::Float(pick.apply(v).into_iter().map(|x| x as f32).collect()),
        ),
        other => {
            return Err(Error::Unsupported {
                at: at.clone(),
                reason: format!(
                "sample format {} (contactscope reads uint8, uint16, int16, float32 and float64)",
                decoding_name(&other)
            ),
            })
        }
    };
    Ok(converted)
}

fn decoding_name(result: &DecodingResult) -> &'static str {
    match result {
        DecodingResult::U8(_) => "uint8",
        DecodingResult::U16(_) => "uint16",
        DecodingResult::U32(_) => "uint32",
        DecodingResult::U64(_) => "uint64",
        DecodingResult::F16(_) => "float16",
        DecodingResult::F32(_) => "float32",
        DecodingResult::F64(_) => "float64",
        DecodingResult::I8(_) => "int8",
        DecodingResult::I16(_) => "int16",
        DecodingResult::I32(_) => "int32",
        DecodingResult::I64(_) => "int64",
    }
}

/// Samples per pixel for colour types we read; a clear error for the rest.
fn check_colortype(colortype: ColorType, at: &Location) -> Result<u16> {
    let unsupported = |reason: String| Error::Unsupported {
        at: at.clone(),
        reason,
    };
    let (bits, spp) = match colortype {
        ColorType::Gray(b) => (b, 1),
        ColorType::GrayA(b) => (b, 2),
        ColorType::RGB(b) => (b, 3),
        ColorType::RGBA(b) => (b, 4),
        ColorType::Multiband {
            bit_depth,
            num_samples,
        } => (bit_depth, num_samples),
        ColorType::Palette(_) => {
            return Err(unsupported(
                "palette (indexed colour) image; a micrograph must store intensities".into(),
            ))
        }
        other => {
            return Err(unsupported(format!(
                "colour type {other:?}; contactscope reads grey or multi-channel intensities"
            )))
        }
    };
    if ![8, 16, 32, 64].contains(&bits) {
        return Err(unsupported(format!(
            "{bits}-bit packed samples (BitsPerSample = {bits}); save the image with 16-bit samples"
        )));
    }
    Ok(spp)
}

fn sample_type_of(bits: u8, format: u16, at: &Location) -> Result<SampleType> {
    match (bits, format) {
        (8, 1) => Ok(SampleType::U8),
        (16, 1) => Ok(SampleType::U16),
        (16, 2) => Ok(SampleType::I16),
        (32, 3) => Ok(SampleType::F32),
        (64, 3) => Ok(SampleType::F64),
        _ => Err(Error::Unsupported {
            at: at.clone(),
            reason: format!(
                "{bits}-bit {} samples (contactscope reads uint8, uint16, int16, float32 and float64)",
                match format {
                    1 => "unsigned integer",
                    2 => "signed integer",
                    3 => "floating-point",
                    _ => "undefined-format",
                }
            ),
        }),
    }
}

/// Whether the local file at `path` starts as OME-XML text (an OME companion file).
fn is_xml_file(path: &Path) -> bool {
    let mut head = Vec::with_capacity(super::companion::HEAD_BYTES);
    std::fs::File::open(path)
        .and_then(|f| {
            f.take(super::companion::HEAD_BYTES as u64)
                .read_to_end(&mut head)
        })
        .is_ok_and(|_| super::companion::looks_like_ome_xml(&head))
}

/// The ImageDescription of the first page of the TIFF at `path`, if it has one.
pub(super) fn first_description(path: &Path) -> Result<Option<String>> {
    crate::inputs::note_input(path);
    let mut decoder = decoder(path, |e| tiff_error(Location::file(path), e))?;
    Ok(match decoder.find_tag(Tag::ImageDescription) {
        Ok(Some(tiff::decoder::ifd::Value::Ascii(s))) => Some(s),
        _ => None,
    })
}

/// OME-XML read from another file than the TIFF's own description.
struct Metadata {
    /// The file it was read from.
    file: PathBuf,
    xml: String,
}

/// The OME-XML a `BinaryOnly` description points to (`None` for any other description), or a
/// note saying why it was not read.
fn followed(path: &Path, description: Option<&str>, notes: &mut Vec<String>) -> Option<Metadata> {
    let pointer = super::companion::pointer(description?)?;
    if crate::remote::is_url(path) {
        notes.push(format!(
            "its OME-XML is kept in {}, which is not read beside a URL; the pages are read in \
             file order",
            pointer.metadata_file
        ));
        return None;
    }
    match super::companion::follow(path, &pointer) {
        Ok((file, xml)) => {
            crate::inputs::note_input(&file);
            Some(Metadata { file, xml })
        }
        Err(why) => {
            notes.push(format!(
                "its OME-XML only points to the set's metadata file {} ({why}); the pages are \
                 read alone, in file order",
                pointer.metadata_file
            ));
            None
        }
    }
}

fn read_info<R: Read + Seek>(
    path: &Path,
    decoder: &mut Decoder<R>,
    metadata: Option<Metadata>,
) -> Result<TiffInfo> {
    let at = Location::page(path, 0);
    let err = |e| tiff_error(at.clone(), e);
    let (width, height) = decoder.dimensions().map_err(err)?;
    let colortype = decoder.colortype().map_err(err)?;
    let spp = check_colortype(colortype, &at)?;
    let bits = decoder
        .find_tag_unsigned_vec::<u16>(Tag::BitsPerSample)
        .map_err(err)?
        .and_then(|v| v.first().copied())
        .unwrap_or(1) as u8;
    let format = decoder
        .find_tag_unsigned_vec::<u16>(Tag::SampleFormat)
        .map_err(err)?
        .and_then(|v| v.first().copied())
        .unwrap_or(1);
    let sample_type = sample_type_of(bits, format, &at)?;
    let tag_u16 = |d: &mut Decoder<R>, tag| d.find_tag_unsigned::<u16>(tag).ok().flatten();
    let compression = compression_name(tag_u16(decoder, Tag::Compression).unwrap_or(1));
    let predictor = predictor_name(tag_u16(decoder, Tag::Predictor).unwrap_or(1));
    let planar = tag_u16(decoder, Tag::PlanarConfiguration) == Some(2);
    let tiled = decoder.find_tag(Tag::TileWidth).ok().flatten().is_some();
    let description = match decoder.find_tag(Tag::ImageDescription) {
        Ok(Some(tiff::decoder::ifd::Value::Ascii(s))) => Some(s),
        _ => None,
    };
    let imagej = description.as_deref().and_then(metadata::parse_imagej);
    let mut notes = Vec::new();
    let metadata = metadata.or_else(|| followed(path, description.as_deref(), &mut notes));
    // The description the axes and the pixel size are read from: the followed XML in place of
    // the pointer; a pointer not followed (said in a note) states no axes.
    let axes_description = match &metadata {
        Some(m) => Some(m.xml.as_str()),
        None => description
            .as_deref()
            .filter(|d| super::companion::pointer(d).is_none()),
    };
    let pixel_size = pixel_size_from_tags(decoder, axes_description, &imagej, &mut notes);
    let bigtiff = is_bigtiff(path);
    let byte_order = match decoder.byte_order() {
        tiff::tags::ByteOrder::LittleEndian => "little",
        tiff::tags::ByteOrder::BigEndian => "big",
    };
    let pages = list_pages(decoder, path)?;

    let (axes, images) = TiffAxes::from_metadata(
        path,
        &pages,
        spp as usize,
        axes_description,
        imagej.as_ref(),
        &mut notes,
    );
    let channels = axes.c;
    let channel_layout = match (spp, axes.source) {
        (1, _) if channels == 1 => ChannelLayout::Single,
        (1, AxesSource::Ome) => ChannelLayout::OmePages,
        (1, _) => ChannelLayout::ImageJPages,
        _ if planar => ChannelLayout::Planar,
        _ => ChannelLayout::Contiguous,
    };
    let description_kind = match (&description, &imagej) {
        (_, Some(_)) => "ImageJ",
        (Some(d), None) if d.contains("<OME") => "OME-XML",
        (Some(_), None) => "text",
        (None, _) => "none",
    };
    Ok(TiffInfo {
        path: path.to_path_buf(),
        pages,
        width: width as usize,
        height: height as usize,
        sample_type,
        bits_per_sample: bits,
        channels,
        channel_layout,
        compression,
        predictor,
        tiled,
        bigtiff,
        byte_order: byte_order.into(),
        pixel_size,
        description_kind: description_kind.into(),
        quantity: imagej.as_ref().and_then(|m| m.quantity.clone()),
        value_unit: imagej.as_ref().and_then(|m| m.value_unit.clone()),
        notes,
        axes,
        images,
        metadata_file: metadata.map(|m| m.file),
    })
}

fn is_bigtiff(path: &Path) -> bool {
    let mut head = [0u8; 4];
    open_input(path).is_ok_and(|(mut f, _)| f.read_exact(&mut head).is_ok())
        && (head[2..] == [0, 43] || head[2..] == [43, 0])
}

/// Walk the IFD chain; keep full-resolution pages. Leaves the decoder on the first page.
fn list_pages<R: Read + Seek>(decoder: &mut Decoder<R>, path: &Path) -> Result<Vec<usize>> {
    let mut pages = Vec::new();
    let mut index = 0;
    loop {
        let reduced = decoder
            .find_tag_unsigned::<u32>(Tag::NewSubfileType)
            .ok()
            .flatten()
            .is_some_and(|t| t & 1 == 1);
        if !reduced {
            pages.push(index);
        }
        if !decoder.more_images() {
            break;
        }
        index += 1;
        decoder
            .next_image()
            .map_err(|e| tiff_error(Location::page(path, index), e))?;
    }
    decoder
        .seek_to_image(0)
        .map_err(|e| tiff_error(Location::page(path, 0), e))?;
    Ok(pages)
}

fn pixel_size_from_tags<R: Read + Seek>(
    decoder: &mut Decoder<R>,
    description: Option<&str>,
    imagej: &Option<ImageJDescription>,
    notes: &mut Vec<String>,
) -> Option<PixelSize> {
    if let Some((x_m, y_m)) = description.and_then(metadata::parse_ome_pixel_size) {
        return Some(PixelSize {
            x_m,
            y_m,
            source: PixelSizeSource::OmeXml,
        });
    }
    let x_res = rational(decoder.find_tag(Tag::XResolution).ok().flatten());
    let y_res = rational(decoder.find_tag(Tag::YResolution).ok().flatten()).or(x_res);
    let unit = decoder
        .find_tag_unsigned::<u16>(Tag::ResolutionUnit)
        .ok()
        .flatten()
        .unwrap_or(2);
    let (x_res, y_res) = (x_res?, y_res?);
    if let Some(meta) = imagej {
        return match meta.unit_m {
            Some(unit_m) => Some(PixelSize {
                x_m: unit_m / x_res,
                y_m: unit_m / y_res,
                source: PixelSizeSource::ImageJ,
            }),
            None => {
                notes.push(format!(
                    "ImageJ unit '{}' is not a length: no pixel size",
                    meta.unit_text.as_deref().unwrap_or("")
                ));
                None
            }
        };
    }
    let unit_m = match unit {
        3 => 0.01,
        2 if metadata::is_display_dpi(x_res) => {
            notes.push(format!(
                "XResolution {x_res} pixels/inch looks like a display default: ignored"
            ));
            return None;
        }
        2 => 0.0254,
        _ => return None,
    };
    let size = PixelSize {
        x_m: unit_m / x_res,
        y_m: unit_m / y_res,
        source: PixelSizeSource::ResolutionTags,
    };
    if size.x_m > 100e-6 {
        notes.push(format!(
            "resolution tags give {:.1} µm pixels, implausibly large for a microscope; check the file or give {}",
            size.x_m * 1e6,
            crate::param::Param::PixelSize
        ));
    }
    Some(size)
}
