//! surfalize `.sflz`, the native format of the surfalize Python package (version 1.0 of the
//! layout, as its `surfalize.file.sflz` module writes it in 0.19.2): little-endian throughout.
//!
//! | bytes | field |
//! |---|---|
//! | 4 | `SFLZ` |
//! | 10 | version, ASCII padded with spaces (`1.0`) |
//! | 8 + 8 | x and y step (f64), in the file's unit |
//! | 8 | the unit, ASCII padded with NULs (`um`, `nm`, `mm`, `m`, …) |
//! | 2 + 2 | number of layers, number of metadata entries (u16) |
//! | 1 | compression of every layer: 0 none, 1 zlib, 2 LZMA (an `.xz` stream) |
//! | 4 | bytes of metadata (JSON, skipped) |
//!
//! then per layer: name length (u16) and name, `is_height` (u8), width and height (u32),
//! channels (u8), the NumPy dtype string in 4 bytes (`<u4`, `<f8`, `|u1`), `scaled` and
//! `has_nan` (u8), minimum and maximum (f64), payload bytes (u32) and the payload: height × width
//! (× channels) values, row 0 first. A scaled layer holds integers mapping the dtype's range
//! linearly onto [minimum, maximum]; with `has_nan` the dtype's largest value marks an invalid
//! point and the one below it is the maximum. The height layer (`topography`) is in the file's
//! unit; other layers are camera images and are listed as channels but not read as heights.
//!
//! The earlier layout (as surfalize 0.17.1 writes it, also version `1.0`) is told apart by what
//! follows the steps: a scaling flag (a byte 0 or 1, where a unit starts with a letter) and the
//! height range (f64 minimum, maximum) instead of a unit, then
//! the counts and the compression, no metadata; its layers have no height flag (the first,
//! named `topography`, is the heights), a 3-byte dtype, and are in µm. Its integer heights map
//! the dtype's range onto [minimum, maximum] as its writer maps them (surfalize's reader of that
//! layout adds the dtype's minimum instead of subtracting it: the same for unsigned types, its
//! default, and wrong for signed ones).

use std::io::Read;
use std::path::Path;

use super::{choose, grid_bytes, height_map, length_factor, ChannelEntry, HeightMap};
use super::{count, positive, TopographyFormat};
use crate::binary::{bad, slice, unsupported, Reader};
use crate::error::Result;

/// The first bytes of every `.sflz` file.
pub(crate) const MAGIC: &[u8] = b"SFLZ";

/// Layers looked through at most (a corrupt count cannot loop for long: each layer also needs
/// its header's bytes).
const MAX_LAYERS: usize = 4096;

/// One layer's header.
struct Layer<'a> {
    name: String,
    is_height: bool,
    width: usize,
    height: usize,
    channels: usize,
    dtype: Dtype,
    scaled: bool,
    has_nan: bool,
    min: f64,
    max: f64,
    payload: &'a [u8],
}

/// A NumPy dtype as the layer names it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Dtype {
    kind: u8,
    width: usize,
    big: bool,
}

impl Dtype {
    /// `<u4`, `>f8`, `|u1`, `=i2`: byte order, kind (`u`, `i`, `f`) and width.
    fn parse(path: &Path, field: &[u8]) -> Result<Dtype> {
        let text = padded_text(field);
        let b = text.as_bytes();
        let parsed = match b {
            [order @ (b'<' | b'>' | b'|' | b'='), kind @ (b'u' | b'i' | b'f'), w] => {
                let width = usize::from(w.wrapping_sub(b'0'));
                let ok = match kind {
                    b'f' => matches!(width, 4 | 8),
                    _ => matches!(width, 1 | 2 | 4 | 8),
                };
                ok.then_some(Dtype {
                    kind: *kind,
                    width,
                    big: *order == b'>',
                })
            }
            _ => None,
        };
        parsed.ok_or_else(|| {
            unsupported(
                path,
                format!(
                    "SFLZ layer data type '{text}' (only integers and float32/float64 are read)"
                ),
            )
        })
    }

    /// The smallest and largest value of an integer dtype, as numbers.
    fn int_range(self) -> (f64, f64) {
        let bits = 8 * self.width as u32;
        match self.kind {
            b'i' => (
                -(2f64.powi(bits as i32 - 1)),
                2f64.powi(bits as i32 - 1) - 1.0,
            ),
            _ => (0.0, 2f64.powi(bits as i32) - 1.0),
        }
    }
}

/// Read the height layer of a surfalize `.sflz` file (module docs); `channel` may name it, and
/// an image layer named is refused as not heights.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let version = padded_text(slice(path, data, MAGIC.len(), 10, "the SFLZ version")?);
    if !version.starts_with("1.") {
        return Err(unsupported(
            path,
            format!("SFLZ version '{version}': only version 1.x files are read"),
        ));
    }
    let mut r = Reader::new(path, data, MAGIC.len() + 10);
    let step_x = r.f64()?;
    let step_y = r.f64()?;
    // The layout of 0.19 has the unit here; the earlier one (also "1.0") a scaling flag and
    // the height range, in µm.
    // A unit is text; the earlier layout's scaling flag is a byte 0 or 1.
    let unit_field = slice(path, data, r.pos, 8, "the SFLZ header")?;
    let earlier = unit_field[0] <= 1;
    let unit_field = padded_text(unit_field);
    let (unit, scaling) = if earlier {
        let scaled = r.u8()? != 0;
        let (min, max) = (r.f64()?, r.f64()?);
        ("um".to_string(), Some((scaled, min, max)))
    } else {
        r.take(8)?;
        (unit_field, None)
    };
    let layers = usize::from(r.u16()?);
    let _entries = r.u16()?;
    let compression = r.u8()?;
    if compression > 2 {
        return Err(bad(
            path,
            format!("SFLZ compression {compression} is none of 0 (none), 1 (zlib), 2 (LZMA)"),
        ));
    }
    if !earlier {
        let metadata = r.usize_u32()?;
        r.take(metadata)?;
    }
    if layers == 0 {
        return Err(bad(path, "the SFLZ file holds no layer"));
    }
    let mut found = Vec::new();
    for k in 0..layers.min(MAX_LAYERS) {
        found.push(layer(path, &mut r, k, scaling)?);
    }
    let channels: Vec<ChannelEntry> = found
        .iter()
        .map(|l| ChannelEntry {
            name: l.name.clone(),
            height: l.is_height,
        })
        .collect();
    let index = match channel {
        Some(_) => choose(path, &channels, channel)?,
        None => found.iter().position(|l| l.is_height).ok_or_else(|| {
            bad(
                path,
                "the SFLZ file holds no height layer (only camera images)",
            )
        })?,
    };
    let chosen = &found[index];
    if !chosen.is_height {
        return Err(bad(
            path,
            format!(
                "layer '{}' is a camera image, not heights; the height layer is '{}'",
                chosen.name,
                found
                    .iter()
                    .find(|l| l.is_height)
                    .map_or("(none)", |l| l.name.as_str())
            ),
        ));
    }
    if chosen.channels != 1 {
        return Err(bad(
            path,
            format!(
                "height layer '{}' has {} values per point; heights have one",
                chosen.name, chosen.channels
            ),
        ));
    }
    let factor = length_factor(&unit).ok_or_else(|| {
        bad(
            path,
            format!("SFLZ unit '{unit}' is not a length unit (m, mm, um, nm, pm)"),
        )
    })?;
    let dx = positive(path, "SFLZ x step", step_x)? * factor;
    let dy = positive(path, "SFLZ y step", step_y)? * factor;
    let values = decode(path, chosen, compression)?;
    let heights = values.into_iter().map(|v| v * factor).collect();
    height_map(
        path,
        TopographyFormat::Sflz,
        (&channels, index),
        (chosen.height, chosen.width),
        heights,
        (dx, dy),
    )
}

/// A fixed-width text field without the spaces or NULs that pad it.
fn padded_text(field: &[u8]) -> String {
    String::from_utf8_lossy(field)
        .trim_end_matches([' ', '\0'])
        .to_string()
}

/// The next layer's header and its payload's bytes. `earlier` is the file header's scaling of
/// the earlier layout (module docs), whose layers have no height flag (the first, when it is
/// named `topography`, holds the heights), a 3-byte dtype and no scaling of their own.
fn layer<'a>(
    path: &Path,
    r: &mut Reader<'a>,
    k: usize,
    earlier: Option<(bool, f64, f64)>,
) -> Result<Layer<'a>> {
    let name_len = usize::from(r.u16()?);
    let name = String::from_utf8_lossy(r.take(name_len)?).into_owned();
    let flag = match earlier {
        None => r.u8()? != 0,
        Some(_) => k == 0 && name == "topography",
    };
    let width = count(path, "SFLZ layer width", f64::from(r.u32()?))?;
    let height = count(path, "SFLZ layer height", f64::from(r.u32()?))?;
    let channels = usize::from(r.u8()?);
    if channels == 0 {
        return Err(bad(path, format!("SFLZ layer '{name}' has 0 channels")));
    }
    let dtype = Dtype::parse(path, r.take(if earlier.is_some() { 3 } else { 4 })?)?;
    let (scaled, has_nan, min, max) = match earlier {
        None => (r.u8()? != 0, r.u8()? != 0, r.f64()?, r.f64()?),
        Some((scaled, min, max)) => (flag && scaled, false, min, max),
    };
    let size = r.usize_u32()?;
    let payload = r.take(size)?;
    Ok(Layer {
        name,
        is_height: flag,
        width,
        height,
        channels,
        dtype,
        scaled,
        has_nan,
        min,
        max,
        payload,
    })
}

/// The layer's values as numbers (NaN where a scaled layer marks an invalid point).
fn decode(path: &Path, layer: &Layer, compression: u8) -> Result<Vec<f64>> {
    let points = grid_bytes(path, layer.width, layer.height, 1)?;
    let expected = grid_bytes(path, layer.width, layer.height, layer.dtype.width)?;
    let raw = match compression {
        0 => layer.payload.to_vec(),
        1 => inflate(
            path,
            flate2::read::ZlibDecoder::new(layer.payload),
            expected,
        )?,
        _ => unxz(path, layer.payload, expected)?,
    };
    if raw.len() != expected {
        let held = match raw.len() > expected {
            true => "more".to_string(),
            false => raw.len().to_string(),
        };
        return Err(bad(
            path,
            format!(
                "SFLZ layer '{}' holds {held} bytes of data; {}×{} values of {} bytes need \
                 {expected}",
                layer.name, layer.height, layer.width, layer.dtype.width
            ),
        ));
    }
    let d = layer.dtype;
    let values = crate::binary::decode_values(&raw, d.width, d.kind == b'f', d.kind == b'i', d.big);
    debug_assert_eq!(values.len(), points);
    if !layer.scaled {
        return Ok(values);
    }
    if d.kind == b'f' {
        return Err(bad(
            path,
            format!(
                "SFLZ layer '{}' is marked scaled but holds floats",
                layer.name
            ),
        ));
    }
    // A range that is not one (max below min, NaN) would map every point onto the minimum.
    if !(layer.min.is_finite() && layer.max.is_finite() && layer.max >= layer.min) {
        return Err(bad(
            path,
            format!(
                "SFLZ layer '{}' states the height range {} … {}",
                layer.name, layer.min, layer.max
            ),
        ));
    }
    let (lo, hi) = d.int_range();
    let top = if layer.has_nan { hi - 1.0 } else { hi };
    let levels = top - lo;
    let spread = layer.max - layer.min;
    Ok(values
        .into_iter()
        .map(|q| {
            if layer.has_nan && q == hi {
                f64::NAN
            } else if levels > 0.0 && spread > 0.0 {
                (q - lo) / levels * spread + layer.min
            } else {
                layer.min
            }
        })
        .collect())
}

/// A zlib stream's bytes, at most `limit + 1` of them (more says the layer is not what its
/// header states).
fn inflate(path: &Path, decoder: impl Read, limit: usize) -> Result<Vec<u8>> {
    // The buffer grows with the data, not with the header's claim.
    let mut out = Vec::new();
    decoder
        .take(limit as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| bad(path, format!("SFLZ zlib data are corrupt: {e}")))?;
    Ok(out)
}

/// An `.xz` stream's bytes (Python's `lzma.compress`), at most `limit + 1` of them.
fn unxz(path: &Path, payload: &[u8], limit: usize) -> Result<Vec<u8>> {
    let mut out = Capped {
        bytes: Vec::new(),
        limit: limit + 1,
    };
    let mut input = payload;
    match lzma_rs::xz_decompress(&mut input, &mut out) {
        Ok(()) => Ok(out.bytes),
        // Past the cap: the size check after decoding names what was expected.
        Err(_) if out.bytes.len() >= out.limit => Ok(out.bytes),
        Err(e) => Err(bad(path, format!("SFLZ LZMA data are corrupt: {e}"))),
    }
}

/// A buffer that refuses bytes past its limit (a corrupt stream cannot grow memory).
struct Capped {
    bytes: Vec<u8>,
    limit: usize,
}

impl std::io::Write for Capped {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let room = self.limit - self.bytes.len();
        if room == 0 {
            return Err(std::io::Error::other("more data than the layer's size"));
        }
        let n = buf.len().min(room);
        self.bytes.extend_from_slice(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `.sflz` file as surfalize lays it out (module docs), for tests.
    fn sflz(unit: &str, compression: u8, layers: &[(&str, bool, Vec<u8>)]) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        out.extend(b"1.0       ");
        out.extend(0.5f64.to_le_bytes());
        out.extend(0.25f64.to_le_bytes());
        let mut u = unit.as_bytes().to_vec();
        u.resize(8, b' ');
        out.extend(u);
        out.extend((layers.len() as u16).to_le_bytes());
        out.extend(1u16.to_le_bytes());
        out.push(compression);
        let meta = br#"{"a": 1}"#;
        out.extend((meta.len() as u32).to_le_bytes());
        out.extend(meta);
        for (name, is_height, header_and_payload) in layers {
            out.extend((name.len() as u16).to_le_bytes());
            out.extend(name.as_bytes());
            out.push(u8::from(*is_height));
            out.extend(header_and_payload);
        }
        out
    }

    /// A layer's header after its name, then its payload.
    fn body(
        (w, h): (u32, u32),
        dtype: &str,
        (scaled, has_nan): (bool, bool),
        (min, max): (f64, f64),
        payload: &[u8],
    ) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend(w.to_le_bytes());
        out.extend(h.to_le_bytes());
        out.push(1);
        let mut d = dtype.as_bytes().to_vec();
        d.resize(4, b' ');
        out.extend(d);
        out.push(u8::from(scaled));
        out.push(u8::from(has_nan));
        out.extend(min.to_le_bytes());
        out.extend(max.to_le_bytes());
        out.extend((payload.len() as u32).to_le_bytes());
        out.extend(payload);
        out
    }

    fn zlib(bytes: &[u8]) -> Vec<u8> {
        use std::io::Write;
        let mut e = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        e.write_all(bytes).unwrap();
        e.finish().unwrap()
    }

    #[test]
    fn reads_float_and_scaled_layers() {
        let p = Path::new("synthetic.sflz");
        let floats: Vec<u8> = [1.0f64, 2.0, f64::NAN, 4.0, 5.0, 6.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let float_layer = body((3, 2), "<f8", (false, false), (0.0, 0.0), &floats);
        let image = body((3, 2), "|u1", (false, false), (0.0, 0.0), &[9; 6]);
        let bytes = sflz(
            "um",
            0,
            &[
                ("intensity", false, image.clone()),
                ("topography", true, float_layer),
            ],
        );
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.ny(), m.nx()), (2, 3));
        assert_eq!(m.channels, ["intensity", "topography"]);
        assert_eq!(m.channel, "topography");
        assert!((m.dx_m - 0.5e-6).abs() < 1e-18 && (m.dy_m - 0.25e-6).abs() < 1e-18);
        assert!((m.heights[[1, 2]] - 6e-6).abs() < 1e-18);
        assert_eq!(m.invalid_points, 1);
        let err = read(p, &bytes, Some("intensity")).unwrap_err().to_string();
        assert!(
            err.contains("camera image") && err.contains("'topography'"),
            "{err}"
        );

        // u2 scaled with a NaN sentinel: 0 → min, 65534 → max, 65535 → invalid.
        let q: Vec<u8> = [0u16, 65534, 65535, 32767, 1, 2]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let scaled = body((2, 3), "<u2", (true, true), (-1.0, 3.0), &zlib(&q));
        let bytes = sflz("nm", 1, &[("topography", true, scaled)]);
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.ny(), m.nx()), (3, 2));
        assert_eq!(m.heights[[0, 0]], -1e-9);
        assert!((m.heights[[0, 1]] - 3e-9).abs() < 1e-24);
        assert!(m.heights[[1, 0]].is_nan());
        let mid = (32767.0 / 65534.0 * 4.0 - 1.0) * 1e-9;
        assert!((m.heights[[1, 1]] - mid).abs() < 1e-24);
        assert_eq!(m.invalid_points, 1);

        // Truncations and corruptions are errors naming the file.
        for cut in [0, 4, 13, 20, 40, 60, bytes.len() - 3] {
            let err = read(p, &bytes[..cut.max(4)], None).unwrap_err().to_string();
            assert!(err.contains("synthetic.sflz"), "{cut}: {err}");
        }
        let mut v2 = bytes.clone();
        v2[4] = b'2';
        let err = read(p, &v2, None).unwrap_err().to_string();
        assert!(err.contains("version '2.0'"), "{err}");
        let bad_unit = sflz("furlong", 0, &[("topography", true, image.clone())]);
        let err = read(p, &bad_unit, None).unwrap_err().to_string();
        assert!(err.contains("'furlong'"), "{err}");
        let images = sflz("um", 0, &[("intensity", false, image)]);
        let err = read(p, &images, None).unwrap_err().to_string();
        assert!(err.contains("no height layer"), "{err}");
    }

    #[test]
    fn a_stream_longer_than_its_header_says_is_refused() {
        let p = Path::new("long.sflz");
        let q = vec![0u8; 4 * 100];
        let layer = body((2, 2), "<u4", (true, false), (0.0, 1.0), &zlib(&q));
        let err = read(p, &sflz("um", 1, &[("topography", true, layer)]), None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("holds more bytes") && err.contains("need 16"),
            "{err}"
        );
        let short = body((2, 2), "<u4", (true, false), (0.0, 1.0), &zlib(&q[..12]));
        let err = read(p, &sflz("um", 1, &[("topography", true, short)]), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("holds 12 bytes"), "{err}");
        let reversed = body((2, 2), "<u4", (true, false), (1.0, 0.0), &zlib(&q[..16]));
        let err = read(p, &sflz("um", 1, &[("topography", true, reversed)]), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("height range 1 … 0"), "{err}");
    }
}
