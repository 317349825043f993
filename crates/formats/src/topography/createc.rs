//! Createc STM/AFM images (`.dat` of the `[Paramco32]` layout, as Createc's STMAFM software
//! writes them): a text header of `Label / Key=value` lines (NUL-padded), the line `DATA`, then
//! one zlib stream of little-endian float32 values: `Channels` planes of `Num.Y` lines of
//! `Num.X` values (a few values more may follow; they are ignored).
//!
//! Calibration, from the header's own numbers:
//!
//! * **Pixel size**: `Length x[A]` / `Num.X` (and y), in ångström. The lengths are the DAC steps
//!   times `Dacto[A]xy`: `Delta X [Dac]=213` × `Dacto[A]xy=0.00183` = 0.390 nm per step, × 256 =
//!   99.8 nm = `Length x[A]=998.468`; so `Dacto` values are nm per DAC count despite their label.
//! * **Heights**: Z planes are DAC counts × `Dacto[A]z` (nm per count) × `GainZ`/10 (the
//!   high-voltage gain; `Dacto[A]z` is stated for a gain of 10). Without `Dacto[A]z`:
//!   2 · 10 V / 2^bits (`DAC-Type`, default 20 bit) × `ZPiezoconst` (nm/V) × `GainZ`/10.
//!   This is how ProbeFlow (SPMQT-Lab's Createc converter, whose samples test this reader)
//!   and Gwyddion scale them.
//! * **Channels**: the planes are the selected signals (`Channelselectval`, bit 0 Z, bit 1
//!   current, bit n ≥ 2 auxiliary input n − 1) forward, then the same backward, when their count
//!   is twice the bits set; else the STM layout Z, current forward, Z, current backward, and the
//!   rest numbered. Only Z planes are heights; currents (A) and auxiliary inputs (DAC counts) are
//!   listed and refused as heights.
//! * **Grid**: the first stored column holds no image (it is dropped, as Createc's software and
//!   ProbeFlow drop it); lines after the last one scanned (zeros in the first plane: a scan
//!   stopped early) are not part of the image, and a last line scanned only in part is dropped.
//!   Backward lines are stored in display order. Row 0 is the first line stored.
//!
//! The older layouts (`[Parameter]`, `[Paramet32]`: uncompressed integers or floats) are
//! recognised and refused: no sample of them was found to test a reader on.

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, unsupported};
use crate::error::Result;

/// The first line of a compressed Createc image.
pub(crate) const MAGIC: &[u8] = b"[Paramco32]";

/// Longest header looked through for the `DATA` line (bytes; Createc's is 16 kB).
const MAX_HEADER: usize = 1 << 20;

/// Most planes read (Createc's software saves tens), checked before they are named.
const MAX_PLANES: usize = 4096;

/// What a plane holds.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Signal {
    Z,
    Current,
    Other,
}

/// Read a Z plane of a Createc `[Paramco32]` image (module docs).
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let limit = data.len().min(MAX_HEADER);
    let marker = data[..limit]
        .windows(5)
        .position(|w| w == b"\nDATA")
        .ok_or_else(|| {
            bad(
                path,
                "the Createc header has no DATA line (file truncated?)",
            )
        })?;
    let header = parse_header(&data[..marker]);
    let number = |key: &str| -> Result<f64> {
        let text = header
            .get(key)
            .ok_or_else(|| bad(path, format!("the Createc header has no '{key}'")))?;
        text.trim().parse::<f64>().map_err(|_| {
            bad(
                path,
                format!("Createc header '{key}={text}' is not a number"),
            )
        })
    };
    let optional = |key: &str| header.get(key).and_then(|t| t.trim().parse::<f64>().ok());
    let nx = count(path, "Createc Num.X", number("Num.X")?)?;
    let ny = count(path, "Createc Num.Y", number("Num.Y")?)?;
    let planes = count(path, "Createc Channels", number("Channels")?)?;
    if planes > MAX_PLANES {
        return Err(unsupported(
            path,
            format!("Createc Channels is {planes}; at most {MAX_PLANES} planes are read"),
        ));
    }
    if nx < 2 {
        return Err(bad(
            path,
            format!("Createc Num.X is {nx}: the first column is not image, nothing is left"),
        ));
    }
    if optional("ScanmodeSine").is_some_and(|s| s != 0.0) {
        return Err(unsupported(
            path,
            "a Createc scan in sine mode (its lines are not evenly spaced): not read",
        ));
    }
    let lx = positive(path, "Createc 'Length x[A]'", number("Length x[A]")?)?;
    let ly = positive(path, "Createc 'Length y[A]'", number("Length y[A]")?)?;
    let names = plane_names(planes, optional("Channelselectval"));
    let channels: Vec<ChannelEntry> = names
        .iter()
        .map(|(name, signal)| ChannelEntry {
            name: name.clone(),
            height: *signal == Signal::Z,
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let (name, signal) = &names[index];
    if *signal != Signal::Z {
        let unit = match signal {
            Signal::Current => "A",
            _ => "DAC counts",
        };
        return Err(bad(
            path,
            format!("channel '{name}' is in '{unit}', not a length"),
        ));
    }

    let plane_bytes = grid_bytes(path, nx, ny, 4)?;
    // All planes are inflated (a short stream is a truncated file), within the size limit of a
    // whole height-map file; the buffer grows with the data, not with the header's claim.
    let needed = plane_bytes
        .checked_mul(planes)
        .filter(|&n| n as u64 <= super::MAX_FILE_BYTES)
        .ok_or_else(|| {
            unsupported(
                path,
                format!("{planes} Createc planes of {nx}×{ny} values exceed the size limit"),
            )
        })?;
    let mut raw = Vec::new();
    flate2::read::ZlibDecoder::new(&data[marker + 5..])
        .take(needed as u64)
        .read_to_end(&mut raw)
        .map_err(|e| bad(path, format!("Createc image data do not decompress: {e}")))?;
    if raw.len() < needed {
        return Err(bad(
            path,
            format!(
                "file is truncated: the Createc data hold {} of the {needed} bytes of {planes} \
                 planes of {nx}×{ny} values",
                raw.len()
            ),
        ));
    }
    let plane = |k: usize| -> Vec<f32> {
        raw[k * plane_bytes..(k + 1) * plane_bytes]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let rows = scanned_lines(&plane(0), nx);
    if rows == 0 {
        return Err(bad(
            path,
            "no line of the Createc scan was recorded (the first plane is all zeros)",
        ));
    }
    let scale = z_metres_per_count(path, &header, &optional)?;
    let values = plane(index);
    let heights: Vec<f64> = values
        .chunks_exact(nx)
        .take(rows)
        .flat_map(|line| line[1..].iter().map(|&v| f64::from(v) * scale))
        .collect();
    height_map(
        path,
        TopographyFormat::Createc,
        (&channels, index),
        (rows, nx - 1),
        heights,
        (lx * 1e-10 / nx as f64, ly * 1e-10 / ny as f64),
    )
}

/// `Label / Key=value` lines as `Key → value` (the text after the last `/` before `=`; a key
/// given twice keeps its last value).
fn parse_header(text: &[u8]) -> HashMap<String, String> {
    let text = String::from_utf8_lossy(text);
    text.lines()
        .filter_map(|line| {
            let (key, value) = line.split_once('=')?;
            let key = key.rsplit('/').next().unwrap_or(key).trim();
            (!key.is_empty()).then(|| (key.to_string(), value.trim().to_string()))
        })
        .collect()
}

/// Metres per DAC count of a Z plane (module docs); a calibration that is not positive (a gain
/// or `Dacto[A]z` of 0) is an error, not a flat map.
fn z_metres_per_count(
    path: &Path,
    header: &HashMap<String, String>,
    optional: &dyn Fn(&str) -> Option<f64>,
) -> Result<f64> {
    let gain = optional("GainZ").unwrap_or(10.0) / 10.0;
    let scale = match optional("Dacto[A]z") {
        Some(nm_per_count) => nm_per_count * gain * 1e-9,
        None => {
            // `DAC-Type=20bit`: the number of bits leads the value.
            let bits: f64 = header
                .get("DAC-Type")
                .map(|t| {
                    t.trim()
                        .chars()
                        .take_while(char::is_ascii_digit)
                        .collect::<String>()
                })
                .and_then(|d| d.parse().ok())
                .filter(|b| (8.0..=32.0).contains(b))
                .unwrap_or(20.0);
            let volts_per_count = 10.0 / 2f64.powf(bits);
            let nm_per_volt = optional("ZPiezoconst").unwrap_or(19.2);
            2.0 * volts_per_count * nm_per_volt * gain * 1e-9
        }
    };
    positive(
        path,
        "Createc Z calibration (Dacto[A]z × GainZ/10, m per count)",
        scale,
    )
}

/// The lines of a plane that were scanned: up to the last line with a recorded (non-zero,
/// finite) value, less that line if its last point was not recorded.
fn scanned_lines(first: &[f32], nx: usize) -> usize {
    let recorded = |v: &f32| v.is_finite() && *v != 0.0;
    let Some(last) = first.iter().rposition(recorded) else {
        return 0;
    };
    let (line, column) = (last / nx, last % nx);
    if column == nx - 1 {
        line + 1
    } else {
        line
    }
}

/// Each plane's name and signal (module docs).
fn plane_names(planes: usize, select: Option<f64>) -> Vec<(String, Signal)> {
    let bits: Vec<u32> = match select {
        Some(s) if s > 0.0 && s < 4_294_967_296.0 => {
            (0..32).filter(|b| (s as u64) & (1 << b) != 0).collect()
        }
        _ => Vec::new(),
    };
    let named = |bit: u32| match bit {
        0 => ("Z".to_string(), Signal::Z),
        1 => ("Current".to_string(), Signal::Current),
        n => (format!("Aux{}", n - 1), Signal::Other),
    };
    if !bits.is_empty() && planes == 2 * bits.len() {
        let half = bits.len();
        return (0..planes)
            .map(|k| {
                let (name, signal) = named(bits[k % half]);
                let direction = if k < half { "forward" } else { "backward" };
                (format!("{name} ({direction})"), signal)
            })
            .collect();
    }
    let stm = [
        ("Z (forward)", Signal::Z),
        ("Current (forward)", Signal::Current),
        ("Z (backward)", Signal::Z),
        ("Current (backward)", Signal::Current),
    ];
    (0..planes)
        .map(|k| match stm.get(k) {
            Some((name, signal)) if planes >= 2 => (name.to_string(), *signal),
            _ => (format!("plane {k}"), Signal::Other),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    /// A `[Paramco32]` file: `planes` planes of `nx × ny`, values from `value(plane, row, col)`.
    fn createc(
        (nx, ny, planes): (usize, usize, usize),
        extra: &str,
        value: impl Fn(usize, usize, usize) -> f32,
    ) -> Vec<u8> {
        let mut out = format!(
            "[Paramco32]\nDAC-Type=20bit\nNum.X / Num.X={nx}\nNum.Y / Num.Y={ny}\n\
             GainZ / GainZ=5\nChannels / Channels={planes}\nLength x[A]={}\n\
             Length y[A]={}\nDacto[A]z=0.0004\n{extra}",
            nx as f64 * 2.0,
            ny as f64 * 3.0
        )
        .into_bytes();
        out.resize(512, 0);
        out.extend(b"\nDATA");
        let mut floats = Vec::new();
        for p in 0..planes {
            for r in 0..ny {
                for c in 0..nx {
                    floats.extend(value(p, r, c).to_le_bytes());
                }
            }
        }
        floats.extend([0u8; 64]);
        let mut e = flate2::write::ZlibEncoder::new(out, flate2::Compression::default());
        e.write_all(&floats).unwrap();
        e.finish().unwrap()
    }

    #[test]
    fn reads_z_planes_calibrated_without_the_first_column() {
        let p = Path::new("scan.dat");
        let bytes = createc((5, 4, 4), "Channelselectval=3\n", |plane, r, c| {
            (100 * plane + 10 * r + c + 1) as f32
        });
        let m = read(p, &bytes, None).unwrap();
        assert_eq!(
            m.channels,
            [
                "Z (forward)",
                "Current (forward)",
                "Z (backward)",
                "Current (backward)"
            ]
        );
        assert_eq!((m.channel.as_str(), m.ny(), m.nx()), ("Z (forward)", 4, 4));
        // 2 Å per point in x, 3 Å in y; 0.0004 nm per count at gain 5 of 10.
        assert!((m.dx_m - 2e-10).abs() < 1e-22 && (m.dy_m - 3e-10).abs() < 1e-22);
        let per_count = 0.0004 * 0.5 * 1e-9;
        assert!((m.heights[[0, 0]] - 2.0 * per_count).abs() < 1e-24);
        assert!((m.heights[[3, 3]] - 35.0 * per_count).abs() < 1e-24);
        let back = read(p, &bytes, Some("z (backward)")).unwrap();
        assert!((back.heights[[0, 0]] - 202.0 * per_count).abs() < 1e-24);
        let err = read(p, &bytes, Some("Current (forward)"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("'A', not a length"), "{err}");
    }

    #[test]
    fn a_scan_stopped_early_keeps_its_complete_lines() {
        let p = Path::new("stopped.dat");
        // Lines 0–1 complete, line 2 recorded up to column 2 of 5, then zeros.
        let bytes = createc((5, 6, 2), "", |plane, r, c| {
            if r < 2 || (r == 2 && c <= 2) {
                (1 + plane * 7 + r + c) as f32
            } else {
                0.0
            }
        });
        let m = read(p, &bytes, None).unwrap();
        assert_eq!((m.ny(), m.nx(), m.invalid_points), (2, 4, 0));
        assert!(
            (m.dy_m - 3e-10).abs() < 1e-22,
            "the line spacing stays the header's"
        );
        let zeros = createc((5, 6, 2), "", |_, _, _| 0.0);
        let err = read(p, &zeros, None).unwrap_err().to_string();
        assert!(err.contains("no line"), "{err}");
    }

    #[test]
    fn selected_channels_name_the_planes_and_bad_headers_are_errors() {
        let names: Vec<String> = plane_names(6, Some(1.0 + 2.0 + 128.0))
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        assert_eq!(
            names,
            [
                "Z (forward)",
                "Current (forward)",
                "Aux6 (forward)",
                "Z (backward)",
                "Current (backward)",
                "Aux6 (backward)"
            ]
        );
        let names: Vec<String> = plane_names(6, Some(3.0))
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        assert_eq!(names[4], "plane 4");

        let p = Path::new("bad.dat");
        let bytes = createc((5, 4, 2), "", |_, r, c| (r + c + 1) as f32);
        for cut in [20, 300, 530, bytes.len() - 10] {
            let err = read(p, &bytes[..cut], None).unwrap_err().to_string();
            assert!(err.contains("bad.dat"), "{cut}: {err}");
        }
        let text = String::from_utf8_lossy(&bytes[..512]).to_string();
        for (from, to, says) in [
            ("Num.X=5", "Num.X=0", "Num.X is 0"),
            ("Num.X=5", "Num.X=1", "nothing is left"),
            ("Length x[A]=10", "Length x[A]=-1", "must be positive"),
            ("Channels=2", "Channels=many", "not a number"),
            (
                "Dacto[A]z=0.0004\n",
                "Dacto[A]z=0.0004\nScanmodeSine=1\n",
                "sine mode",
            ),
            ("Channels=2", "Channels=9", "truncated"),
            ("GainZ=5", "GainZ=0", "Z calibration"),
            ("Channels=2", "Channels=99999999", "at most 4096 planes"),
        ] {
            let mut edited = text.replace(from, to).into_bytes();
            edited.resize(512, 0);
            edited.extend(&bytes[512..]);
            let err = read(p, &edited, Some("Z (forward)"))
                .unwrap_err()
                .to_string();
            assert!(err.contains(says), "{to}: {err}");
        }
    }
}
