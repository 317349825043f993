//! Keyence ZON (`.zon`), the files of Keyence's VR-series one-shot 3D measuring macroscopes, as
//! SurfaceTopography's `ZONReader` (1.27) and surfalize's `zon` reader (after Gwyddion's
//! `zonfile.c`) describe the layout; little-endian throughout:
//!
//! | bytes | field |
//! |---|---|
//! | 4 | `KPK0` (members stored as they are) or `KPK1` (each member one zstd frame) |
//! | 4 | bytes of the BMP preview that follows (u32) |
//! | … | the preview (`BM`…), then 8 bytes not described, then a ZIP archive |
//!
//! The archive's members are named by UUIDs that do not change between files: XML documents
//! (acquisition, device, calibration) and arrays, each a 16-byte header — columns, rows, bytes
//! per value, bytes per row (u32) — then the rows, first row first, each padded to its stated
//! length. Read here:
//!
//! * `686613b8-27b5-4a29-8ffc-438c2780873e`, the XML `Calibration`: `XYCalibration/MeterPerPixel`
//!   (the pixel size along x and y, m) and `ZCalibration/MeterPerUnit` (m per height count);
//! * `4cdb0c75-5706-48cc-a9a1-adf395d609ae`, the heights: int32 counts × `MeterPerUnit`;
//! * `9e7ca6dd-0e6a-4d7b-8986-f0a7b773c916` (optional), one byte per pixel: a pixel with either
//!   of the two low bits set was not measured (NaN), SurfaceTopography's rule. On the one sample
//!   at hand (a VR-6100 scan, 1024 × 769) it flags the last two rows, with values 1 and 2.
//!
//! The other members (colour images of the surface, device settings) are not read. Rows are kept
//! in the file's order: row 0 of the map is the first row stored, SurfaceTopography's y = 0.

use std::io::{Cursor, Read};
use std::path::Path;

use super::{choose, grid_bytes, height_map, ChannelEntry, HeightMap, TopographyFormat};
use crate::binary::{bad, unsupported};
use crate::error::Result;

/// The first three bytes of every ZON file (then `0` or `1`).
pub(crate) const MAGIC: &[u8] = b"KPK";

/// The member holding the calibration.
const CALIBRATION: &str = "686613b8-27b5-4a29-8ffc-438c2780873e";
/// The member holding the heights.
const HEIGHTS: &str = "4cdb0c75-5706-48cc-a9a1-adf395d609ae";
/// The member flagging pixels not measured.
const VALIDITY: &str = "9e7ca6dd-0e6a-4d7b-8986-f0a7b773c916";

/// The first bytes of a zstd frame.
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];

/// Largest XML member read (the calibration is a few hundred bytes).
const MAX_XML_BYTES: u64 = 1 << 20;

/// How far past the preview the archive may start (8 bytes on the sample).
const ARCHIVE_SEARCH: usize = 1024;

/// The header of an array member.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Grid {
    nx: usize,
    ny: usize,
    value_bytes: usize,
    row_bytes: usize,
}

/// Read the height map of a ZON file (module docs).
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let entries = [ChannelEntry {
        name: "Height".into(),
        height: true,
    }];
    let index = choose(path, &entries, channel)?;
    if data.len() < 8 || !data.starts_with(MAGIC) {
        return Err(bad(path, "not a Keyence ZON file (no KPK header)"));
    }
    let preview = u32::from_le_bytes([data[4], data[5], data[6], data[7]]) as usize;
    let after = 8usize.saturating_add(preview);
    let window = data
        .get(after..data.len().min(after.saturating_add(ARCHIVE_SEARCH)))
        .ok_or_else(|| {
            bad(
                path,
                format!(
                    "ZON preview of {preview} bytes runs past the end of the file ({} bytes)",
                    data.len()
                ),
            )
        })?;
    let start = window
        .windows(4)
        .position(|w| w == b"PK\x03\x04")
        .map(|at| after + at)
        .ok_or_else(|| {
            bad(
                path,
                format!("no ZIP archive within {ARCHIVE_SEARCH} bytes after the ZON preview"),
            )
        })?;
    let mut zip = zip::ZipArchive::new(Cursor::new(&data[start..])).map_err(|e| {
        bad(
            path,
            format!("ZON archive is not a readable ZIP archive: {e}"),
        )
    })?;

    let xml = match open_member(path, &mut zip, CALIBRATION)? {
        Some(stream) => read_xml(path, stream)?,
        None => {
            return Err(bad(
                path,
                format!("ZON file has no calibration member ({CALIBRATION})"),
            ))
        }
    };
    let (pixel_m, unit_m) = calibration(path, &xml)?;

    let stream = open_member(path, &mut zip, HEIGHTS)?
        .ok_or_else(|| bad(path, format!("ZON file has no height member ({HEIGHTS})")))?;
    let (grid, raw) = read_array(path, stream, 4, "heights")?;
    let mut heights = Vec::with_capacity(grid.nx * grid.ny);
    for row in raw.chunks_exact(grid.row_bytes) {
        heights.extend(
            row[..grid.nx * 4]
                .chunks_exact(4)
                .map(|v| f64::from(i32::from_le_bytes([v[0], v[1], v[2], v[3]])) * unit_m),
        );
    }
    if let Some(stream) = open_member(path, &mut zip, VALIDITY)? {
        let (m, flags) = read_array(path, stream, 1, "validity mask")?;
        if (m.nx, m.ny) != (grid.nx, grid.ny) {
            return Err(bad(
                path,
                format!(
                    "ZON validity mask is {} × {} pixels, the heights {} × {}",
                    m.nx, m.ny, grid.nx, grid.ny
                ),
            ));
        }
        for (row, out) in flags
            .chunks_exact(m.row_bytes)
            .zip(heights.chunks_exact_mut(grid.nx))
        {
            for (&flag, h) in row[..m.nx].iter().zip(out) {
                if flag & 0b11 != 0 {
                    *h = f64::NAN;
                }
            }
        }
    }
    height_map(
        path,
        TopographyFormat::Zon,
        (&entries, index),
        (grid.ny, grid.nx),
        heights,
        (pixel_m, pixel_m),
    )
}

/// A member's bytes as a stream (decompressed when it is a zstd frame), or `None` where the
/// archive lacks it.
fn open_member<'a>(
    path: &Path,
    zip: &'a mut zip::ZipArchive<Cursor<&[u8]>>,
    name: &str,
) -> Result<Option<Box<dyn Read + 'a>>> {
    let entry = match zip.by_name(name) {
        Ok(e) => e,
        Err(zip::result::ZipError::FileNotFound) => return Ok(None),
        Err(e) => return Err(bad(path, format!("ZON member {name}: {e}"))),
    };
    let mut stream: Box<dyn Read + 'a> = Box::new(entry);
    let mut magic = [0u8; 4];
    let got = read_up_to(&mut stream, &mut magic).map_err(|e| member_error(path, name, e))?;
    let stream: Box<dyn Read + 'a> = Box::new(Cursor::new(magic[..got].to_vec()).chain(stream));
    if got == 4 && magic == ZSTD_MAGIC {
        let decoder =
            zstd::stream::read::Decoder::new(stream).map_err(|e| member_error(path, name, e))?;
        return Ok(Some(Box::new(decoder)));
    }
    Ok(Some(stream))
}

fn member_error(path: &Path, name: &str, e: std::io::Error) -> crate::error::Error {
    bad(path, format!("ZON member {name} does not read: {e}"))
}

/// An XML member's bytes, refused above [`MAX_XML_BYTES`].
fn read_xml(path: &Path, stream: Box<dyn Read + '_>) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    stream
        .take(MAX_XML_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| member_error(path, CALIBRATION, e))?;
    if out.len() as u64 > MAX_XML_BYTES {
        return Err(unsupported(
            path,
            format!(
                "ZON member {CALIBRATION} (the calibration) is larger than {MAX_XML_BYTES} bytes"
            ),
        ));
    }
    Ok(out)
}

/// An array member: its checked header ([`grid_of`]) and the rows it states, all of them.
fn read_array(
    path: &Path,
    mut stream: Box<dyn Read + '_>,
    value_bytes: usize,
    what: &str,
) -> Result<(Grid, Vec<u8>)> {
    let fail = |e| bad(path, format!("ZON {what} member does not read: {e}"));
    let mut head = [0u8; 16];
    let got = read_up_to(&mut stream, &mut head).map_err(fail)?;
    let grid = grid_of(path, &head[..got], value_bytes, what)?;
    let wanted = grid.row_bytes * grid.ny;
    let mut out = Vec::with_capacity(wanted);
    stream
        .take(wanted as u64)
        .read_to_end(&mut out)
        .map_err(fail)?;
    if out.len() < wanted {
        return Err(bad(
            path,
            format!(
                "ZON {what} member holds {} bytes of rows; its header states {} rows of {} \
                 bytes",
                out.len(),
                grid.ny,
                grid.row_bytes
            ),
        ));
    }
    Ok((grid, out))
}

/// Fill `buf` as far as the stream allows; the bytes read.
fn read_up_to(stream: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match stream.read(&mut buf[got..])? {
            0 => break,
            n => got += n,
        }
    }
    Ok(got)
}

/// An array member's header, checked: `value_bytes` per value, rows of at least `nx` values,
/// and a grid within the size limit.
fn grid_of(path: &Path, head: &[u8], value_bytes: usize, what: &str) -> Result<Grid> {
    if head.len() < 16 {
        return Err(bad(
            path,
            format!("ZON {what} member is shorter than its 16-byte header"),
        ));
    }
    let field = |k: usize| {
        u32::from_le_bytes([
            head[4 * k],
            head[4 * k + 1],
            head[4 * k + 2],
            head[4 * k + 3],
        ]) as usize
    };
    let grid = Grid {
        nx: field(0),
        ny: field(1),
        value_bytes: field(2),
        row_bytes: field(3),
    };
    if grid.value_bytes != value_bytes {
        return Err(bad(
            path,
            format!(
                "ZON {what} member has {} bytes per value; {value_bytes} expected",
                grid.value_bytes
            ),
        ));
    }
    if grid.nx == 0 || grid.ny == 0 {
        return Err(bad(
            path,
            format!(
                "ZON {what} member is an empty {} × {} grid",
                grid.nx, grid.ny
            ),
        ));
    }
    grid_bytes(path, grid.nx, grid.ny, value_bytes)?;
    if grid.row_bytes < grid.nx * value_bytes || !grid.row_bytes.is_multiple_of(value_bytes) {
        return Err(bad(
            path,
            format!(
                "ZON {what} member states {} bytes per row for {} values of {value_bytes} bytes",
                grid.row_bytes, grid.nx
            ),
        ));
    }
    // The padded rows within the size limit too.
    grid_bytes(path, grid.row_bytes / value_bytes, grid.ny, value_bytes)?;
    Ok(grid)
}

/// `MeterPerPixel` and `MeterPerUnit` of the calibration member.
fn calibration(path: &Path, xml: &[u8]) -> Result<(f64, f64)> {
    let text = std::str::from_utf8(xml.strip_prefix(b"\xef\xbb\xbf").unwrap_or(xml))
        .map_err(|_| bad(path, "ZON calibration is not UTF-8 text"))?;
    let doc = roxmltree::Document::parse(text)
        .map_err(|e| bad(path, format!("ZON calibration does not parse: {e}")))?;
    let value = |group: &str, key: &str| -> Result<f64> {
        let text = doc
            .root_element()
            .children()
            .find(|n| n.has_tag_name(group))
            .and_then(|g| g.children().find(|n| n.has_tag_name(key)))
            .and_then(|n| n.text())
            .ok_or_else(|| bad(path, format!("ZON calibration has no {group}/{key}")))?;
        text.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                bad(
                    path,
                    format!(
                        "ZON calibration {group}/{key} '{}' is not a positive number",
                        text.trim()
                    ),
                )
            })
    };
    Ok((
        value("XYCalibration", "MeterPerPixel")?,
        value("ZCalibration", "MeterPerUnit")?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// A member of an array: its header, then `rows` of `row_bytes` (values then zeros).
    fn array(nx: u32, rows: &[Vec<u8>], value_bytes: u32, row_bytes: u32) -> Vec<u8> {
        let mut out: Vec<u8> = [nx, rows.len() as u32, value_bytes, row_bytes]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        for r in rows {
            let mut r = r.clone();
            r.resize(row_bytes as usize, 0);
            out.extend(r);
        }
        out
    }

    fn calibration_xml() -> Vec<u8> {
        b"<Calibration><XYCalibration><MeterPerPixel>2E-06</MeterPerPixel></XYCalibration>\
          <ZCalibration><MeterPerUnit>1E-08</MeterPerUnit></ZCalibration></Calibration>"
            .to_vec()
    }

    /// A 3 × 2 map (counts 1…6, rows padded to 16 bytes) with a validity mask flagging the
    /// pixels whose value is given in `flags`.
    fn members(flags: [u8; 6]) -> Vec<(&'static str, Vec<u8>)> {
        let row = |a: i32, b: i32, c: i32| -> Vec<u8> {
            [a, b, c].iter().flat_map(|v| v.to_le_bytes()).collect()
        };
        vec![
            (CALIBRATION, calibration_xml()),
            (HEIGHTS, array(3, &[row(1, 2, 3), row(4, 5, 6)], 4, 16)),
            (
                VALIDITY,
                array(3, &[flags[..3].to_vec(), flags[3..].to_vec()], 1, 3),
            ),
        ]
    }

    /// A ZON file of `members`, each a zstd frame when `zstd` (`KPK1`), else stored (`KPK0`).
    fn zon(members: &[(&str, Vec<u8>)], zstd: bool) -> Vec<u8> {
        let mut archive = Cursor::new(Vec::new());
        let mut zip = zip::ZipWriter::new(&mut archive);
        let opts = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored);
        for (name, data) in members {
            zip.start_file(*name, opts).unwrap();
            let data = if zstd {
                zstd::encode_all(&data[..], 3).unwrap()
            } else {
                data.clone()
            };
            zip.write_all(&data).unwrap();
        }
        zip.finish().unwrap();
        let preview = b"BM preview";
        let mut out = if zstd {
            b"KPK1".to_vec()
        } else {
            b"KPK0".to_vec()
        };
        out.extend((preview.len() as u32).to_le_bytes());
        out.extend(preview);
        out.extend([4, 0, 0, 0, 2, 0, 0, 0]);
        out.extend(archive.into_inner());
        out
    }

    fn read_zon(data: &[u8]) -> Result<HeightMap> {
        read(Path::new("a.zon"), data, None)
    }

    #[test]
    fn reads_counts_calibration_and_the_low_validity_bits() {
        for compressed in [false, true] {
            let m = read_zon(&zon(&members([0, 1, 0, 4, 2, 3]), compressed)).unwrap();
            assert_eq!((m.nx(), m.ny(), m.dx_m, m.dy_m), (3, 2, 2e-6, 2e-6));
            assert_eq!(m.channels, ["Height"]);
            let h = |y: usize, x: usize| m.heights[(y, x)];
            // Row 0 is the first row stored; bit 2 alone (4) leaves a pixel measured.
            assert_eq!((h(0, 0), h(0, 2), h(1, 0)), (1e-8, 3.0 * 1e-8, 4.0 * 1e-8));
            assert!(h(0, 1).is_nan() && h(1, 1).is_nan() && h(1, 2).is_nan());
            assert_eq!(m.invalid_points, 3);
        }
        // Without a validity member every point is measured.
        let mut no_mask = members([0; 6]);
        no_mask.pop();
        assert_eq!(read_zon(&zon(&no_mask, true)).unwrap().invalid_points, 0);
    }

    #[test]
    fn missing_short_or_mismatched_members_are_refused_naming_the_file() {
        let err = |data: Vec<u8>| read_zon(&data).unwrap_err().to_string();
        let mut m = members([0; 6]);
        m.remove(0);
        assert!(err(zon(&m, true)).contains("no calibration member"));
        let mut m = members([0; 6]);
        m.remove(1);
        assert!(err(zon(&m, false)).contains("no height member"));
        let mut m = members([0; 6]);
        m[1].1.truncate(16 + 16 + 8);
        let e = err(zon(&m, true));
        assert!(
            e.contains("holds 24 bytes of rows") && e.contains("a.zon"),
            "{e}"
        );
        let mut m = members([0; 6]);
        m[2].1 = array(2, &[vec![0, 0], vec![0, 0]], 1, 2);
        assert!(err(zon(&m, false)).contains("validity mask is 2 × 2 pixels, the heights 3 × 2"));
        let mut data = zon(&members([0; 6]), true);
        data[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(data).contains("runs past the end of the file"));
        let data = zon(&members([0; 6]), false);
        let path = Path::new("a.zon");
        crate::topography::test_support::truncations_and_corruptions(path, &data, |d| {
            read(path, d, None).map(|_| ())
        });
    }

    #[test]
    fn array_headers_are_checked() {
        let p = Path::new("a.zon");
        let head = |v: [u32; 4]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let g = grid_of(p, &head([3, 2, 4, 16]), 4, "heights").unwrap();
        assert_eq!((g.nx, g.ny, g.row_bytes), (3, 2, 16));
        for (bad_head, needle) in [
            (head([3, 2, 2, 16]), "2 bytes per value"),
            (head([0, 2, 4, 16]), "empty 0 × 2"),
            (head([3, 2, 4, 8]), "8 bytes per row"),
            (head([3, 2, 4, 14]), "14 bytes per row"),
            (head([3, 2, 4, 1 << 30]), "limit"),
            (head([u32::MAX, u32::MAX, 4, 16]), "limit"),
        ] {
            let err = grid_of(p, &bad_head, 4, "heights").unwrap_err().to_string();
            assert!(err.contains(needle) && err.contains("a.zon"), "{err}");
        }
        assert!(grid_of(p, &[0; 8], 4, "heights").is_err());
    }

    #[test]
    fn calibration_needs_both_numbers() {
        let p = Path::new("a.zon");
        let xml = |xy: &str, z: &str| {
            format!(
                "\u{feff}<?xml version=\"1.0\" encoding=\"utf-8\"?><Calibration><XYCalibration>\
                 <MeterPerPixel>{xy}</MeterPerPixel></XYCalibration><ZCalibration>\
                 <MeterPerUnit>{z}</MeterPerUnit></ZCalibration></Calibration>"
            )
        };
        assert_eq!(
            calibration(p, xml("2.5E-05", "1E-08").as_bytes()).unwrap(),
            (2.5e-5, 1e-8)
        );
        let err = calibration(p, xml("-1", "1E-08").as_bytes()).unwrap_err();
        assert!(err.to_string().contains("MeterPerPixel '-1'"), "{err}");
        let err = calibration(p, b"<Calibration/>").unwrap_err();
        assert!(
            err.to_string().contains("no XYCalibration/MeterPerPixel"),
            "{err}"
        );
    }
}
