//! JPK Instruments TIFF images (`.jpk`, `.jpk-qi-image`; JPK/Bruker NanoWizard), as JPK's
//! "JPKImageSpec" describes them: a TIFF whose first page is an 8-bit thumbnail carrying the
//! scan's metadata in JPK's private tags, then one page per channel and direction holding the
//! stored integers.
//!
//! * Channel: tag 32848 (`height`, `measuredHeight`, `amplitude`, …), direction tag 32849
//!   (0 trace, 1 retrace); named here `height (trace)`, `height (retrace)`, and a second page
//!   of the same channel and direction (QI maps) `measuredHeight (trace, 2)`.
//! * Calibration: a page has tag 32896 slots (calibration levels: `raw`, `volts`, `nominal`,
//!   `calibrated`, …) and names its default slot in tag 32897. Slot `k`'s tags start at
//!   32912 + 48·k: its name (+0), its unit (+18), its scaling type (+19: `LinearScaling` or
//!   `NullScaling`), multiplier (+20) and offset (+21). A slot's linear scaling maps the stored
//!   integers to that slot directly (its multiplier is the product along the chain of slots:
//!   −1.51·10⁻¹⁵ m per count for a nominal height), so the value is
//!   `raw · multiplier + offset` of the default slot, in its unit — as JPK's software and
//!   AFMReader read it.
//! * Pixel size: the first page's grid lengths (tags 32834 fast, 32835 slow, metres) over its
//!   grid points (32838, 32839).
//! * Orientation: lines are stored bottom first; they are flipped so that row 0 is the top of
//!   the image (as AFMReader does by default).

use std::io::Cursor;
use std::path::Path;

use tiff::decoder::ifd::Value;
use tiff::decoder::{Decoder, DecodingResult, Limits};
use tiff::tags::Tag;
use tiff::Directory;

use super::vendor::{choose, grid_bytes, height_map, length_factor, length_scale, ChannelEntry};
use super::{HeightMap, TopographyFormat};
use crate::binary::{bad, unsupported, FileSource, MAX_PLANE_BYTES};
use crate::error::Result;

const JPK_VERSION: u16 = 32768;
const CHANNEL_NAME: u16 = 32848;
const RETRACE: u16 = 32849;
const SLOT_COUNT: u16 = 32896;
const DEFAULT_SLOT: u16 = 32897;
const FIRST_SLOT: u16 = 32912;
const SLOT_SIZE: u16 = 48;
const GRID_U: u16 = 32834;
const GRID_V: u16 = 32835;
const GRID_I: u16 = 32838;
const GRID_J: u16 = 32839;

/// Most pages looked at.
const MAX_PAGES: usize = 1024;

/// Whether a TIFF's first IFD carries JPK's version and scan-grid tags.
pub(crate) fn is_jpk(source: &mut FileSource) -> Result<bool> {
    let tags = super::park::entries_of(source)?;
    let has = |t: u16| tags.iter().any(|e| e.0 == t);
    Ok(has(JPK_VERSION) && has(GRID_U) && has(GRID_I))
}

fn tiff_error(path: &Path) -> impl Fn(tiff::TiffError) -> crate::error::Error + '_ {
    move |e| bad(path, format!("JPK TIFF: {e}"))
}

/// The current page's directory, read once for the tag look-ups below.
fn directory(path: &Path, decoder: &mut Decoder<Cursor<&[u8]>>) -> Result<Directory> {
    let pointer = decoder
        .ifd_pointer()
        .ok_or_else(|| bad(path, "JPK TIFF page without a directory"))?;
    decoder.read_directory(pointer).map_err(tiff_error(path))
}

/// A tag's value when the directory has it with a count the file can hold (a corrupt count is
/// never handed to the decoder, which would allocate or report it on stderr).
fn value(
    decoder: &mut Decoder<Cursor<&[u8]>>,
    dir: &Directory,
    tag: u16,
    file_len: usize,
) -> Option<Value> {
    let entry = dir.get(Tag::Unknown(tag))?;
    if entry.count() > file_len as u64 {
        return None;
    }
    decoder
        .read_directory_tags(dir)
        .find_tag(Tag::Unknown(tag))
        .ok()?
}

/// A tag's text, if it is one.
fn text(d: &mut Decoder<Cursor<&[u8]>>, dir: &Directory, tag: u16, len: usize) -> Option<String> {
    match value(d, dir, tag, len)? {
        Value::Ascii(s) => Some(s.trim_end_matches('\0').to_string()),
        _ => None,
    }
}

/// A tag's number, if it is one.
fn number(d: &mut Decoder<Cursor<&[u8]>>, dir: &Directory, tag: u16, len: usize) -> Option<f64> {
    let v = match value(d, dir, tag, len)? {
        Value::Double(v) => v,
        Value::Float(v) => f64::from(v),
        Value::Unsigned(v) => f64::from(v),
        Value::Signed(v) => f64::from(v),
        Value::Short(v) => f64::from(v),
        Value::SignedShort(v) => f64::from(v),
        Value::Byte(v) => f64::from(v),
        Value::SignedByte(v) => f64::from(v),
        Value::UnsignedBig(v) => v as f64,
        Value::SignedBig(v) => v as f64,
        Value::Ascii(s) => s.trim().parse().ok()?,
        _ => return None,
    };
    v.is_finite().then_some(v)
}

/// One channel page: its name, IFD index and calibration (multiplier, offset, unit).
struct Page {
    entry: ChannelEntry,
    index: usize,
    scale: (f64, f64),
    unit: String,
}

/// Read one channel of a JPK TIFF (module docs).
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let mut limits = Limits::default();
    limits.decoding_buffer_size = MAX_PLANE_BYTES;
    let mut decoder = Decoder::new(Cursor::new(data))
        .map_err(tiff_error(path))?
        .with_limits(limits);
    let len = data.len();
    let first = directory(path, &mut decoder)?;
    if text(&mut decoder, &first, JPK_VERSION, len).is_none() {
        return Err(bad(path, "not a JPK TIFF (no JPK version tag 32768)"));
    }
    let grid = |d: &mut Decoder<Cursor<&[u8]>>, tag: u16, what: &str| {
        number(d, &first, tag, len)
            .filter(|v| *v > 0.0)
            .ok_or_else(|| bad(path, format!("JPK TIFF has no positive {what} (tag {tag})")))
    };
    let (length_x, length_y) = (
        grid(&mut decoder, GRID_U, "grid length")?,
        grid(&mut decoder, GRID_V, "grid length")?,
    );
    let (points_x, points_y) = (
        grid(&mut decoder, GRID_I, "grid points")?,
        grid(&mut decoder, GRID_J, "grid points")?,
    );
    let mut pages = Vec::new();
    let mut index = 0;
    while decoder.more_images() && index < MAX_PAGES {
        decoder.next_image().map_err(tiff_error(path))?;
        index += 1;
        check_data_in_file(path, &mut decoder, index, len)?;
        let dir = directory(path, &mut decoder)?;
        let Some(name) = text(&mut decoder, &dir, CHANNEL_NAME, len) else {
            continue;
        };
        let direction = match number(&mut decoder, &dir, RETRACE, len) {
            Some(v) if v != 0.0 => "retrace",
            _ => "trace",
        };
        let (scale, unit) = calibration(path, (&mut decoder, &dir, len), &name)?;
        // A QI map can hold two pages of one channel and direction (two measured heights):
        // the second is numbered.
        let label = format!("{name} ({direction}");
        let same = pages
            .iter()
            .filter(|p: &&Page| p.entry.name.starts_with(&label))
            .count();
        let label = match same {
            0 => format!("{label})"),
            n => format!("{label}, {})", n + 1),
        };
        pages.push(Page {
            entry: ChannelEntry {
                name: label,
                height: length_factor(&unit).is_some(),
            },
            index,
            scale,
            unit,
        });
    }
    let entries: Vec<ChannelEntry> = pages.iter().map(|p| p.entry.clone()).collect();
    if entries.is_empty() {
        return Err(bad(
            path,
            "JPK TIFF holds no channel page after its thumbnail",
        ));
    }
    let chosen = choose(path, &entries, channel)?;
    let page = &pages[chosen];
    let to_metres = length_scale(path, &page.entry, &page.unit)?;
    decoder
        .seek_to_image(page.index)
        .map_err(tiff_error(path))?;
    let (width, height) = decoder.dimensions().map_err(tiff_error(path))?;
    let (nx, ny) = (width as usize, height as usize);
    grid_bytes(path, nx, ny, 8)?;
    // The pixel size comes from the scan grid: a page of another size would get a wrong one.
    if (nx as f64, ny as f64) != (points_x, points_y) {
        return Err(bad(
            path,
            format!(
                "JPK channel '{}' is {nx} × {ny} pixels but the scan grid has {points_x} × \
                 {points_y} points",
                page.entry.name
            ),
        ));
    }
    let raw: Vec<f64> = match decoder.read_image().map_err(tiff_error(path))? {
        DecodingResult::I32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::I16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::U16(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F32(v) => v.into_iter().map(f64::from).collect(),
        DecodingResult::F64(v) => v,
        _ => return Err(unsupported(path, "JPK channel of an unknown sample type")),
    };
    if raw.len() != nx * ny {
        return Err(bad(
            path,
            format!(
                "JPK channel page holds {} values for {nx} × {ny}",
                raw.len()
            ),
        ));
    }
    let (multiplier, offset) = page.scale;
    let mut heights = Vec::with_capacity(nx * ny);
    for line in raw.chunks_exact(nx).rev() {
        heights.extend(line.iter().map(|r| (r * multiplier + offset) * to_metres));
    }
    height_map(
        path,
        TopographyFormat::Jpk,
        (&entries, chosen),
        (ny, nx),
        heights,
        (length_x / points_x, length_y / points_y),
    )
}

/// An error when the current page's strips or tiles reach past the end of the file (a truncated
/// file is refused whole, even where the channel read lies before the cut).
fn check_data_in_file(
    path: &Path,
    decoder: &mut Decoder<Cursor<&[u8]>>,
    page: usize,
    len: usize,
) -> Result<()> {
    let chunks = |offsets: Tag, counts: Tag, d: &mut Decoder<Cursor<&[u8]>>| {
        Some((
            d.find_tag_unsigned_vec::<u64>(offsets).ok()??,
            d.find_tag_unsigned_vec::<u64>(counts).ok()??,
        ))
    };
    let (offsets, counts) = chunks(Tag::StripOffsets, Tag::StripByteCounts, decoder)
        .or_else(|| chunks(Tag::TileOffsets, Tag::TileByteCounts, decoder))
        .ok_or_else(|| {
            bad(
                path,
                format!("JPK TIFF page {page} has no strip or tile offsets"),
            )
        })?;
    let end = offsets
        .iter()
        .zip(&counts)
        .map(|(o, c)| o.saturating_add(*c))
        .max()
        .unwrap_or(0);
    if end > len as u64 {
        return Err(bad(
            path,
            format!("file is truncated: page {page}'s data end at byte {end}, the file has {len}"),
        ));
    }
    Ok(())
}

/// The default slot's (multiplier, offset) and unit of the current page.
fn calibration(
    path: &Path,
    (decoder, dir, len): (&mut Decoder<Cursor<&[u8]>>, &Directory, usize),
    channel: &str,
) -> Result<((f64, f64), String)> {
    let slots = number(decoder, dir, SLOT_COUNT, len)
        .unwrap_or(0.0)
        .clamp(0.0, 64.0) as u16;
    let Some(default) = text(decoder, dir, DEFAULT_SLOT, len) else {
        // No calibration: the stored numbers, without a unit (refused as heights).
        return Ok(((1.0, 0.0), String::new()));
    };
    for k in 0..slots {
        let base = FIRST_SLOT + SLOT_SIZE * k;
        if text(decoder, dir, base, len).as_deref() != Some(default.as_str()) {
            continue;
        }
        let unit = text(decoder, dir, base + 18, len).unwrap_or_default();
        return match text(decoder, dir, base + 19, len).as_deref() {
            Some("LinearScaling") => {
                let multiplier = number(decoder, dir, base + 20, len);
                let offset = number(decoder, dir, base + 21, len);
                match (multiplier, offset) {
                    (Some(m), Some(o)) => Ok(((m, o), unit)),
                    _ => Err(bad(
                        path,
                        format!(
                            "JPK channel '{channel}': slot '{default}' has no multiplier or offset"
                        ),
                    )),
                }
            }
            Some("NullScaling") | None => Ok(((1.0, 0.0), unit)),
            Some(other) => Err(unsupported(
                path,
                format!("JPK channel '{channel}': scaling '{other}' of slot '{default}'"),
            )),
        };
    }
    Err(bad(
        path,
        format!("JPK channel '{channel}': default slot '{default}' is not among its {slots} slots"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_support::truncations_and_corruptions;

    fn fixture() -> (std::path::PathBuf, Vec<u8>) {
        // fixtures/jpk/tiny.jpk (tests/data/jpk_fixture.py, tifffile): 5 × 4 int32 pages
        // raw = 1000·line + 10·column, height calibrated as raw·(−1.5e−15) + 2.5e−6 m.
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/jpk/tiny.jpk");
        let data = std::fs::read(&path).unwrap();
        (path, data)
    }

    #[test]
    fn channels_calibration_grid_and_orientation() {
        let (path, data) = fixture();
        let mut source = FileSource::open(&path).unwrap();
        assert!(is_jpk(&mut source).unwrap());
        let m = read(&path, &data, None).unwrap();
        assert_eq!(
            m.channels,
            ["height (retrace)", "height (trace)", "vDeflection (trace)"]
        );
        assert_eq!(
            (m.channel.as_str(), m.nx(), m.ny()),
            ("height (retrace)", 5, 4)
        );
        assert!((m.dx_m - 4e-9).abs() < 1e-20 && (m.dy_m - 4e-9).abs() < 1e-20);
        let expect = |line: usize, column: usize, shift: f64| {
            (1000.0 * line as f64 + 10.0 * column as f64 + shift) * -1.5e-15 + 2.5e-6
        };
        // Lines are stored bottom first: row 0 is the last stored line.
        for ((r, c), h) in m.heights.indexed_iter() {
            assert!(
                (h - expect(3 - r, c, 0.0)).abs() < 1e-21,
                "({r}, {c}) {h:e}"
            );
        }
        let trace = read(&path, &data, Some("height (trace)")).unwrap();
        assert!((trace.heights[[3, 0]] - expect(0, 0, 5.0)).abs() < 1e-21);
        let err = read(&path, &data, Some("vDeflection"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("'N', not a length") && err.contains("tiny.jpk"),
            "{err}"
        );
    }

    #[test]
    fn a_page_that_does_not_match_the_scan_grid_is_refused() {
        // The first page's grid-points tag (32838, one SLONG: 5) says 6: the pixel size would be
        // wrong, so the page is refused naming both sizes.
        let (path, mut data) = fixture();
        let entry = [0x46, 0x80, 9, 0, 1, 0, 0, 0, 5, 0, 0, 0];
        let at = data.windows(12).position(|w| w == entry).unwrap();
        data[at + 8] = 6;
        let err = read(&path, &data, None).unwrap_err().to_string();
        assert!(
            err.contains("5 × 4 pixels") && err.contains("6 × 4 points"),
            "{err}"
        );
    }

    #[test]
    fn damaged_files_give_errors_naming_the_file() {
        let (path, data) = fixture();
        truncations_and_corruptions(&path, &data, |d| read(&path, d, None).map(|_| ()));
    }
}
