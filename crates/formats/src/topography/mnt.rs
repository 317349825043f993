//! Digital Surf MountainsMap studiable (`.mnt`): an OLE2 / Microsoft Compound File Binary
//! container (magic `D0 CF 11 E0 A1 B1 1A E1`, [MS-CFB]; opened with the `cfb` crate) whose
//! `ScopedContents` stream holds the document. (Its other streams, `XmlHeader`,
//! `ScopedResults` and `ImagePreview`, are not needed for the heights.)
//!
//! `ScopedContents` is a `u64` byte count followed by a tree of little-endian entries: a `u16`
//! tag, a `u64` size, then that many bytes, either a value or further entries. Text is a marker
//! byte `0x04` followed by UTF-16LE characters. The path to the measurement, by tags:
//!
//! - `0x0001` main → `0x02BD` contents → `0x0002` document → `0x0001` the list of document
//!   objects, in which each entry is preceded by one more `u64` (its own length);
//! - an object is `0x0001` class (`0x0001`: `u32` class number), `0x0002` body, `0x0003` GUID.
//!   Only the measured surface (class 9012) stores heights: derived layers (levelled, filtered…)
//!   store their operators and are recomputed by Mountains when it opens the file;
//! - the surface's body holds `0x0001`, an object of class 9062 whose body is `0xFFFF` → the
//!   measurement: `0xFFFF` grid, `0x0001` heights (object of class 9049), `0x0002` height axis;
//! - grid: `0xFFFF` → `0xFFFF` → `0x0001` the channel name (text); `0x0001` and `0x0002` the x
//!   and y axes (`0xFFFF` → `0xFFFF` scale, `0x0001` number of points, `u32`); `0x0003` an
//!   optional mask object (class 9056: `0x0001`, `0x0002` width and height, `0x0005` an array
//!   object of class 9048 of `(width + 2)·(height + 2)` bytes, a one-pixel border around the
//!   grid, in which 9 marks a measured point);
//! - scale: `0x0001` step (`f64`: grid spacing, or height per count), `0x0002` its unit (text),
//!   `0x0003` the display unit, `0x0005` the origin (`f64`, in the display unit);
//! - height axis: `0xFFFF` scale, `0x0001` and `0x0002` the smallest and largest count;
//! - an array object's body: `0x0001` number of elements (`u32`), `0x0002` the data: the total
//!   byte count (`u64`), then blocks, each an element offset (`u64`), an element count (`u32`),
//!   a compressed size (`u32`) and a zlib stream. The heights are int32 (or int16) counts, x
//!   fastest, rows in y.
//!
//! Height = count · step (in its unit) + origin (in the display unit), in metres; the pixel size
//! is the x and y steps. Every 9012 surface with heights is a channel, named from its grid
//! (else the surface's title); a channel whose height unit is not a length is refused when chosen.
//!
//! No public specification of the studiable exists: this layout is SurfaceTopography's reading
//! of it (ContactEngineering/SurfaceTopography, `SurfaceTopography/IO/MNT.py`, version 1.27.1,
//! MIT), checked against its two sample files. An OLE2 file that is not a studiable (an old
//! Office `.doc`/`.xls`, an Outlook `.msg`) is refused in one line saying so.
//!
//! [MS-CFB]: https://learn.microsoft.com/en-us/openspecs/windows_protocols/ms-cfb/

use std::io::Read;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, length_factor, length_scale, positive, ChannelEntry,
    HeightMap, TopographyFormat,
};
use crate::binary::{bad, slice, unsupported};
use crate::error::{Error, Result};

mod tree;
use tree::{array, block_array, object, ArrayData, Entries};

/// First bytes of every OLE2 / Compound File Binary file.
pub const OLE2_MAGIC: [u8; 8] = [0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1];

/// Class numbers of the document objects read.
const CLASS_SURFACE: u32 = 9012;
const CLASS_MEASUREMENT: u32 = 9062;
const CLASS_HEIGHTS: u32 = 9049;
const CLASS_MASK: u32 = 9056;
const CLASS_MASK_ARRAY: u32 = 9048;

/// Mask value of a measured point (non-measured points are 22).
const MEASURED: u8 = 9;

/// Largest `ScopedContents` stream read (bytes).
const MAX_STREAM_BYTES: u64 = 2 << 30;

/// Read a MountainsMap `.mnt` studiable.
pub fn read(path: &Path, channel: Option<&str>) -> Result<HeightMap> {
    read_contents(path, &scoped_contents(path)?, channel)
}

/// Read the measured surface of a `ScopedContents` stream.
fn read_contents(path: &Path, contents: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let surfaces = surfaces(path, contents)?;
    if surfaces.is_empty() {
        return Err(bad(
            path,
            "the MountainsMap studiable holds no measured surface (an object of class 9012 with \
             heights); derived layers are not stored in the file",
        ));
    }
    let channels: Vec<ChannelEntry> = surfaces
        .iter()
        .map(|s| ChannelEntry {
            name: s.name.clone(),
            height: length_factor(s.z.display_unit()).is_some(),
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let s = &surfaces[index];
    let unit = |scale: &Scale, u: &str| {
        length_factor(u).ok_or_else(|| {
            bad(
                path,
                format!("MNT {} unit '{u}' is not a length", scale.axis),
            )
        })
    };
    // The z step and origin: refused through the channel when they are not lengths.
    let z_step = length_scale(path, &channels[index], &s.z.unit)?;
    let z_origin = length_scale(path, &channels[index], s.z.display_unit())?;
    let dx = positive(path, "MNT x step", s.x.step * unit(&s.x, &s.x.unit)?)?;
    let dy = positive(path, "MNT y step", s.y.step * unit(&s.y, &s.y.unit)?)?;
    let (nx, ny) = (s.nx, s.ny);
    grid_bytes(path, nx, ny, 8)?;
    if s.heights.count != nx * ny {
        return Err(bad(
            path,
            format!(
                "MNT surface '{}' has {} heights for a {nx}×{ny} grid",
                s.name, s.heights.count
            ),
        ));
    }
    let (raw, width) = block_array(path, s.heights, &[2, 4], "heights")?;
    let step = s.z.step * z_step;
    let origin = s.z.origin * z_origin;
    if !(step.is_finite() && step != 0.0 && origin.is_finite()) {
        return Err(bad(
            path,
            format!("MNT height step {step:e} m or origin {origin:e} m is not usable"),
        ));
    }
    let mut heights: Vec<f64> = raw
        .chunks_exact(width)
        .map(|c| {
            let v = match *c {
                [a, b] => f64::from(i16::from_le_bytes([a, b])),
                [a, b, c, d] => f64::from(i32::from_le_bytes([a, b, c, d])),
                _ => f64::NAN,
            };
            v * step + origin
        })
        .collect();
    if let Some(mask) = &s.mask {
        apply_mask(path, mask, (nx, ny), &mut heights)?;
    }
    height_map(
        path,
        TopographyFormat::Mnt,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

/// The `ScopedContents` stream of the compound file; a compound file without one is not a
/// MountainsMap studiable.
fn scoped_contents(path: &Path) -> Result<Vec<u8>> {
    crate::inputs::note_input(path);
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let file_len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut cfb = cfb::CompoundFile::open(file)
        .map_err(|e| bad(path, format!("not a readable OLE2 compound file: {e}")))?;
    const STREAM: &str = "/ScopedContents";
    if !cfb.is_stream(STREAM) {
        let names: Vec<String> = cfb
            .read_root_storage()
            .take(6)
            .map(|e| format!("'{}'", e.name().escape_debug()))
            .collect();
        let holds = if names.is_empty() {
            "nothing".to_string()
        } else {
            names.join(", ")
        };
        return Err(unsupported(
            path,
            format!(
                "an OLE2 compound file (the container of old Office documents too) that is not a \
                 Digital Surf MountainsMap studiable: it has no ScopedContents stream (it holds \
                 {holds})"
            ),
        ));
    }
    let stream = cfb.open_stream(STREAM).map_err(|e| {
        bad(
            path,
            format!("the ScopedContents stream does not open: {e}"),
        )
    })?;
    let len = stream.len();
    if len > file_len.min(MAX_STREAM_BYTES) {
        return Err(bad(
            path,
            format!("the ScopedContents stream claims {len} bytes, the file has {file_len}"),
        ));
    }
    let mut out = Vec::with_capacity(len as usize);
    stream.take(len).read_to_end(&mut out).map_err(|e| {
        bad(
            path,
            format!("the ScopedContents stream does not read: {e}"),
        )
    })?;
    if out.len() as u64 != len {
        return Err(bad(
            path,
            format!(
                "the ScopedContents stream is truncated: {} of {len} bytes",
                out.len()
            ),
        ));
    }
    Ok(out)
}

/// An axis scale: step per grid point or per count, and origin.
#[derive(Debug)]
struct Scale {
    axis: &'static str,
    step: f64,
    unit: String,
    display: Option<String>,
    origin: f64,
}

impl Scale {
    fn parse(path: &Path, data: &[u8], axis: &'static str) -> Result<Scale> {
        let e = Entries::parse(path, data, "axis scale", false)?;
        let unit = e
            .text(0x0002)
            .filter(|u| !u.is_empty())
            .ok_or_else(|| bad(path, format!("MNT {axis} axis has no unit")))?;
        Ok(Scale {
            axis,
            step: e.f64(0x0001, "axis step")?,
            unit,
            display: e.text(0x0003).filter(|u| !u.is_empty()),
            origin: match e.get(0x0005) {
                Some(_) => e.f64(0x0005, "axis origin")?,
                None => 0.0,
            },
        })
    }

    /// The unit of the origin.
    fn display_unit(&self) -> &str {
        self.display.as_deref().unwrap_or(&self.unit)
    }
}

/// A mask of measured points: grid size without the border, and its bytes.
struct Mask<'a> {
    width: usize,
    height: usize,
    array: ArrayData<'a>,
}

/// One measured surface of the document.
struct Surface<'a> {
    name: String,
    nx: usize,
    ny: usize,
    x: Scale,
    y: Scale,
    z: Scale,
    heights: ArrayData<'a>,
    mask: Option<Mask<'a>>,
}

/// The measured surfaces of the document, in file order.
fn surfaces<'a>(path: &'a Path, contents: &'a [u8]) -> Result<Vec<Surface<'a>>> {
    let not_studiable = |what: &str| {
        unsupported(
            path,
            format!(
                "an OLE2 compound file with a ScopedContents stream, but not a MountainsMap \
                 studiable: {what}"
            ),
        )
    };
    let body = contents
        .get(8..)
        .ok_or_else(|| not_studiable("the stream is shorter than its 8-byte size"))?;
    let top = Entries::parse(path, body, "ScopedContents", false)?;
    let main = top.child(0x0001, "main container")?;
    let Some(document) = main.get(0x02BD) else {
        return Err(not_studiable(
            "its main container has no document (tag 0x02bd)",
        ));
    };
    let document = Entries::parse(path, document, "document contents", false)?
        .child(0x0002, "document")?
        .need(0x0001, "object list")?;
    let objects = Entries::parse(path, document, "object list", true)?;
    let mut out = Vec::new();
    for &(tag, data) in &objects.list {
        if tag != 0x0001 {
            continue;
        }
        let (class, body) = object(path, data, "document object")?;
        if class != CLASS_SURFACE {
            continue;
        }
        if let Some(s) = surface(path, body)? {
            out.push(s);
        }
    }
    Ok(out)
}

/// A 9012 surface object's measurement, or `None` when it holds no heights.
fn surface<'a>(path: &'a Path, body: &'a [u8]) -> Result<Option<Surface<'a>>> {
    let e = Entries::parse(path, body, "surface", false)?;
    let title = match e.get(0xFFFF) {
        Some(h) => Entries::parse(path, h, "surface header", false)?.text(0x0004),
        None => None,
    };
    let Some(measurement) = e.get(0x0001) else {
        return Ok(None);
    };
    let (class, body) = object(path, measurement, "surface measurement")?;
    if class != CLASS_MEASUREMENT {
        return Ok(None);
    }
    let m = Entries::parse(path, body, "measurement", false)?.child(0xFFFF, "measurement")?;
    let Some(heights) = m.get(0x0001) else {
        return Ok(None);
    };
    let (class, heights) = object(path, heights, "height array")?;
    if class != CLASS_HEIGHTS {
        return Ok(None);
    }
    let heights = array(path, heights, "height array")?;
    let grid = m.child(0xFFFF, "grid")?;
    let name = match grid.get(0xFFFF) {
        Some(h) => match Entries::parse(path, h, "grid header", false)?.get(0xFFFF) {
            Some(d) => Entries::parse(path, d, "grid description", false)?.text(0x0001),
            None => None,
        },
        None => None,
    };
    let lateral = |tag: u16, axis: &'static str| -> Result<(usize, Scale)> {
        let a = grid.child(tag, axis)?.child(0xFFFF, axis)?;
        let n = count(path, axis, f64::from(a.u32(0x0001, "number of points")?))?;
        Ok((n, Scale::parse(path, a.need(0xFFFF, "axis scale")?, axis)?))
    };
    let (nx, x) = lateral(0x0001, "x")?;
    let (ny, y) = lateral(0x0002, "y")?;
    let z_axis = m.child(0x0002, "height axis")?;
    let z = Scale::parse(path, z_axis.need(0xFFFF, "height scale")?, "z")?;
    let mask = match grid.get(0x0003) {
        Some(data) => match object(path, data, "mask")? {
            (CLASS_MASK, body) => {
                let e = Entries::parse(path, body, "mask", false)?;
                let (class, arr) = object(path, e.need(0x0005, "mask array")?, "mask array")?;
                if class != CLASS_MASK_ARRAY {
                    return Err(bad(path, format!("MNT mask array of class {class}")));
                }
                Some(Mask {
                    width: e.u32(0x0001, "mask width")? as usize,
                    height: e.u32(0x0002, "mask height")? as usize,
                    array: array(path, arr, "mask array")?,
                })
            }
            _ => None,
        },
        None => None,
    };
    let name = name
        .filter(|n| !n.is_empty())
        .or(title.filter(|t| !t.is_empty()))
        .unwrap_or_else(|| "Default".into());
    Ok(Some(Surface {
        name,
        nx,
        ny,
        x,
        y,
        z,
        heights,
        mask,
    }))
}

/// Set the points the mask marks as not measured to NaN.
fn apply_mask(path: &Path, mask: &Mask<'_>, (nx, ny): (usize, usize), h: &mut [f64]) -> Result<()> {
    let (w, hgt) = (nx + 2, ny + 2);
    if (mask.width, mask.height) != (nx, ny) || mask.array.count != w * hgt {
        return Err(bad(
            path,
            format!(
                "MNT mask of {}×{} ({} bytes) does not match the {nx}×{ny} grid",
                mask.width, mask.height, mask.array.count
            ),
        ));
    }
    let (bytes, _) = block_array(path, mask.array, &[1], "mask")?;
    for (row, line) in h.chunks_exact_mut(nx).enumerate() {
        let m = slice(path, &bytes, (row + 1) * w + 1, nx, "the MNT mask")?;
        for (v, &flag) in line.iter_mut().zip(m) {
            if flag != MEASURED {
                *v = f64::NAN;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;
    use std::path::PathBuf;

    fn entry(tag: u16, body: &[u8]) -> Vec<u8> {
        let mut v = tag.to_le_bytes().to_vec();
        v.extend((body.len() as u64).to_le_bytes());
        v.extend(body);
        v
    }

    fn text(s: &str) -> Vec<u8> {
        let mut v = vec![0x04];
        v.extend(s.encode_utf16().flat_map(u16::to_le_bytes));
        v
    }

    fn object(class: u32, body: &[u8]) -> Vec<u8> {
        [entry(1, &entry(1, &class.to_le_bytes())), entry(2, body)].concat()
    }

    fn scale(step: f64, unit: &str, display: &str, origin: f64) -> Vec<u8> {
        [
            entry(1, &step.to_le_bytes()),
            entry(2, &text(unit)),
            entry(3, &text(display)),
            entry(5, &origin.to_le_bytes()),
        ]
        .concat()
    }

    /// An array body of `count` elements in two zlib blocks, the second written first.
    fn array(count: usize, bytes: &[u8]) -> Vec<u8> {
        let width = bytes.len() / count;
        let half = count / 2;
        let mut data = (bytes.len() as u64).to_le_bytes().to_vec();
        for (first, n) in [(half, count - half), (0, half)] {
            let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
            z.write_all(&bytes[first * width..(first + n) * width])
                .unwrap();
            let c = z.finish().unwrap();
            data.extend((first as u64).to_le_bytes());
            data.extend((n as u32).to_le_bytes());
            data.extend((c.len() as u32).to_le_bytes());
            data.extend(c);
        }
        [entry(1, &(count as u32).to_le_bytes()), entry(2, &data)].concat()
    }

    /// A `ScopedContents` stream with one surface of `nx`×`ny` int32 counts.
    fn studiable(nx: usize, ny: usize, counts: &[i32], mask: Option<&[u8]>) -> Vec<u8> {
        let axis = |tag: u16, n: usize, step: f64| {
            let inner = [
                entry(0xFFFF, &scale(step, "µm", "mm", 0.0)),
                entry(1, &(n as u32).to_le_bytes()),
            ]
            .concat();
            entry(tag, &entry(0xFFFF, &inner))
        };
        let name = entry(0xFFFF, &entry(0xFFFF, &entry(1, &text("Synthetic"))));
        let mut grid = [name, axis(1, nx, 2.0), axis(2, ny, 3.0)].concat();
        if let Some(m) = mask {
            let body = [
                entry(1, &(nx as u32).to_le_bytes()),
                entry(2, &(ny as u32).to_le_bytes()),
                entry(5, &object(CLASS_MASK_ARRAY, &array(m.len(), m))),
            ]
            .concat();
            grid.extend(entry(3, &object(CLASS_MASK, &body)));
        }
        let bytes: Vec<u8> = counts.iter().flat_map(|c| c.to_le_bytes()).collect();
        let measurement = [
            entry(0xFFFF, &grid),
            entry(1, &object(CLASS_HEIGHTS, &array(counts.len(), &bytes))),
            entry(2, &entry(0xFFFF, &scale(0.5, "nm", "µm", 1.0))),
        ]
        .concat();
        let measurement = object(CLASS_MEASUREMENT, &entry(0xFFFF, &measurement));
        let surface = [
            entry(0xFFFF, &entry(4, &text("1 : title"))),
            entry(1, &measurement),
        ]
        .concat();
        let other = object(9013, &[]);
        let mut list = Vec::new();
        for o in [other, object(CLASS_SURFACE, &surface)] {
            let e = entry(1, &o);
            list.extend((e.len() as u64).to_le_bytes());
            list.extend(e);
        }
        let contents = entry(0x02BD, &entry(2, &entry(1, &list)));
        let body = [entry(3, &[1]), entry(1, &contents)].concat();
        [(body.len() as u64).to_le_bytes().to_vec(), body].concat()
    }

    fn compound(dir: &Path, name: &str, streams: &[(&str, &[u8])]) -> PathBuf {
        let path = dir.join(name);
        let mut c = cfb::create(&path).unwrap();
        for (s, data) in streams {
            c.create_stream(s).unwrap().write_all(data).unwrap();
        }
        c.flush().unwrap();
        path
    }

    #[test]
    fn reads_a_synthetic_studiable_with_its_mask() {
        let dir = tempfile::tempdir().unwrap();
        let counts = [0, 1, 2, -3, 4, 5];
        let plain = studiable(3, 2, &counts, None);
        let p = compound(dir.path(), "a.mnt", &[("ScopedContents", &plain)]);
        let m = read(&p, None).unwrap();
        assert_eq!((m.nx(), m.ny(), m.invalid_points), (3, 2, 0));
        assert_eq!((m.channel.as_str(), m.format.name()), ("Synthetic", "mnt"));
        assert!((m.dx_m - 2e-6).abs() < 1e-21 && (m.dy_m - 3e-6).abs() < 1e-21);
        // count · 0.5 nm + 1 µm, x fastest.
        assert!((m.heights[[1, 0]] - (1e-6 - 1.5e-9)).abs() < 1e-18);
        assert!((m.heights[[0, 2]] - (1e-6 + 1e-9)).abs() < 1e-18);
        // A 5×4 mask with a one-pixel border: 9 is measured, 22 not.
        let mut mask = vec![0u8; 5 * 4];
        for r in 1..3 {
            for c in 1..4 {
                mask[r * 5 + c] = 9;
            }
        }
        mask[2 * 5 + 2] = 22;
        let masked = studiable(3, 2, &counts, Some(&mask));
        let p = compound(dir.path(), "b.mnt", &[("ScopedContents", &masked)]);
        let m = read(&p, Some("synth")).unwrap();
        assert_eq!(m.invalid_points, 1);
        assert!(m.heights[[1, 1]].is_nan());
        // Cut short: an error naming the file, whatever the cut.
        for cut in [9, 40, plain.len() / 2, plain.len() - 3] {
            let p = compound(dir.path(), "c.mnt", &[("ScopedContents", &plain[..cut])]);
            let err = read(&p, None).unwrap_err().to_string();
            assert!(err.contains("c.mnt"), "{cut}: {err}");
        }
    }

    #[test]
    fn damaged_streams_give_errors_not_panics() {
        let mut mask = vec![9u8; 6 * 5];
        mask[8] = 22;
        let good = studiable(4, 3, &[7; 12], Some(&mask));
        let p = Path::new("d.mnt");
        assert_eq!(read_contents(p, &good, None).unwrap().invalid_points, 1);
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        for round in 0..3000 {
            let mut d = good.clone();
            for _ in 0..1 + round % 4 {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                let at = (seed as usize >> 8) % d.len();
                d[at] = (seed >> 40) as u8;
            }
            if let Err(e) = read_contents(p, &d, None) {
                assert!(e.to_string().contains("d.mnt"), "{e}");
            }
        }
    }

    #[test]
    fn refuses_other_compound_files_in_one_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = compound(dir.path(), "old.xls", &[("Workbook", b"\x09\x08")]);
        let err = read(&p, None).unwrap_err().to_string();
        assert!(
            err.contains("not a Digital Surf MountainsMap studiable")
                && err.contains("'Workbook'")
                && err.contains("old.xls")
                && !err.contains('\n'),
            "{err}"
        );
        let p = dir.path().join("x.mnt");
        std::fs::write(&p, [&OLE2_MAGIC[..], &[0u8; 100]].concat()).unwrap();
        assert!(read(&p, None).is_err());
    }

    /// SurfaceTopography 1.27.1's reading (tests/data/surface_topography_maps.csv): nx, ny, dx,
    /// dy, valid points, min, max, mean, rms (m).
    type Reference = (&'static str, usize, usize, f64, f64, usize, [f64; 4]);

    const REFERENCE: [Reference; 2] = [
        (
            "A48_10x_P1",
            960,
            600,
            1.853393117831074e-06,
            1.8545542570951588e-06,
            576000,
            [
                4.936861033455114e-05,
                5.159236903455114e-05,
                5.0631545534565205e-05,
                2.4560210679676396e-08,
            ],
        ),
        (
            "Si_1mm_B16_1x_polish_clean_50x",
            1280,
            960,
            7.48801903682761e-08,
            7.488019036827609e-08,
            1183395,
            [
                -3.6864654541015614e-07,
                3.3550585937499997e-06,
                2.2178659980786606e-06,
                7.232508502674527e-07,
            ],
        ),
    ];

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * b.abs()
    }

    #[test]
    fn sample_files_match_surface_topography() {
        for (k, r) in REFERENCE.iter().enumerate() {
            let p = crate::topography::test_support::sample(&format!("mnt-{}.mnt", k + 1));
            if !p.exists() {
                return;
            }
            let m = super::super::read(&p, None).unwrap();
            assert_eq!(m.format, TopographyFormat::Mnt);
            assert_eq!((m.channel.as_str(), m.nx(), m.ny()), (r.0, r.1, r.2));
            assert!(close(m.dx_m, r.3, 1e-9) && close(m.dy_m, r.4, 1e-9));
            assert_eq!(m.valid_points(), r.5);
            let valid: Vec<f64> = m.heights.iter().copied().filter(|h| !h.is_nan()).collect();
            let n = valid.len() as f64;
            let mean = valid.iter().sum::<f64>() / n;
            let rms = (valid.iter().map(|h| (h - mean).powi(2)).sum::<f64>() / n).sqrt();
            let min = valid.iter().copied().fold(f64::INFINITY, f64::min);
            let max = valid.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let [rmin, rmax, rmean, rrms] = r.6;
            assert!(
                close(min, rmin, 1e-9) && close(max, rmax, 1e-9),
                "{min} {max}"
            );
            assert!((mean - rmean).abs() <= 1e-9 * rrms, "{mean} {rmean}");
            assert!(close(rms, rrms, 1e-9), "{rms} {rrms}");
        }
    }

    #[test]
    fn damaged_sample_files_give_errors_not_panics() {
        let dir = tempfile::tempdir().unwrap();
        for k in 1..=2 {
            let Ok(bytes) = std::fs::read(crate::topography::test_support::sample(&format!(
                "mnt-{k}.mnt"
            ))) else {
                return;
            };
            let whole = read(
                &crate::topography::test_support::sample(&format!("mnt-{k}.mnt")),
                None,
            )
            .unwrap();
            let p = dir.path().join("cut.mnt");
            for i in 1..=10 {
                std::fs::write(&p, &bytes[..bytes.len() * i / 11]).unwrap();
                if let Ok(m) = read(&p, None) {
                    assert_eq!(m, HeightMap { ..whole.clone() }, "cut {i}/11");
                }
            }
            // The first 4 KiB (CFB header and, here, the first sectors) scrambled.
            let mut seed = 0x9E37_79B9_7F4A_7C15u64 ^ k;
            for round in 0..8 {
                let mut damaged = bytes.clone();
                for b in damaged
                    .iter_mut()
                    .take(4096)
                    .skip(if round % 2 == 0 { 8 } else { 0 })
                {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    if seed.is_multiple_of(5) {
                        *b = (seed >> 24) as u8;
                    }
                }
                std::fs::write(&p, &damaged).unwrap();
                let _ = read(&p, None);
            }
        }
    }
}
