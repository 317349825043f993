//! Nanonis scan files (`.sxm`, SPECS Nanonis SPM controllers). The layout, as the Nanonis
//! documentation ("SXM file format" in the Nanonis help) describes it: a text header of tags,
//! each a line `:NAME:` followed by its value lines, from `:NANONIS_VERSION:` to `:SCANIT_END:`;
//! then the bytes `0x1A 0x04`; then the images as 32-bit floats (`:SCANIT_TYPE:` `FLOAT
//! MSBFIRST`, big-endian, or `LSBFIRST`), one image of `SCAN_PIXELS` = `nx ny` values per
//! channel and direction, in the order of the `:DATA_INFO:` table (its `Direction` column is
//! `both`: forward then backward; or one direction). The values are the signal in the table's
//! `Unit` (already calibrated: the `Calibration` column says how the controller converted volts,
//! it is not applied again); NaN marks points not scanned (an interrupted scan).
//!
//! Orientation, as Nanonis and Gwyddion show a scan: lines are stored in the order they were
//! scanned, each from left to right for forward and right to left for backward. Backward lines
//! are mirrored so that both directions lie on the same grid, and a scan `up` (`:SCAN_DIR:`,
//! first line at the bottom) is flipped so that row 0 is the top of the frame. Pixel size:
//! `SCAN_RANGE` (m) over the pixels. `SCAN_ANGLE` (the frame's rotation on the sample) does not
//! change the map's own grid and is not applied.

use std::path::Path;

use super::vendor::{choose, grid_bytes, height_map, length_factor, length_scale, ChannelEntry};
use super::{latin1, HeightMap, TopographyFormat};
use crate::binary::{bad, decode_values, slice, unsupported};
use crate::error::Result;

/// The first bytes of every SXM file.
pub const MAGIC: &[u8] = b":NANONIS_VERSION:";

const END_TAG: &[u8] = b":SCANIT_END:";

/// Header tags with their value lines (tags may repeat; the first is used).
struct Header {
    tags: Vec<(String, Vec<String>)>,
}

impl Header {
    fn parse(text: &str) -> Header {
        let mut tags: Vec<(String, Vec<String>)> = Vec::new();
        for line in text.lines() {
            let trimmed = line.trim_end();
            let is_tag = trimmed.len() >= 2 && trimmed.starts_with(':') && trimmed.ends_with(':');
            if is_tag {
                tags.push((trimmed[1..trimmed.len() - 1].to_string(), Vec::new()));
            } else if let Some((_, lines)) = tags.last_mut() {
                lines.push(line.to_string());
            }
        }
        Header { tags }
    }

    fn lines(&self, tag: &str) -> Option<&[String]> {
        self.tags
            .iter()
            .find(|(t, _)| t == tag)
            .map(|(_, l)| l.as_slice())
    }

    /// The value of a tag as one line of whitespace-separated words.
    fn words(&self, tag: &str) -> Option<Vec<&str>> {
        self.lines(tag)
            .map(|lines| lines.iter().flat_map(|l| l.split_whitespace()).collect())
    }

    /// Two numbers (`nx ny`, `x y`) of a tag, or an error naming the tag.
    fn pair<T: std::str::FromStr>(&self, path: &Path, tag: &str) -> Result<(T, T)> {
        let words = self
            .words(tag)
            .ok_or_else(|| bad(path, format!("SXM header has no :{tag}:")))?;
        let pair = match words.as_slice() {
            [a, b] => a.parse().ok().zip(b.parse().ok()),
            _ => None,
        };
        pair.ok_or_else(|| {
            bad(
                path,
                format!("SXM :{tag}: '{}' is not two numbers", words.join(" ")),
            )
        })
    }
}

/// Whether a file starts as a Nanonis SXM file.
pub fn is_sxm(head: &[u8]) -> bool {
    head.starts_with(MAGIC)
}

/// One image of the file: its channel entry, its place in the data, and whether it is a
/// backward scan.
struct Image {
    entry: ChannelEntry,
    unit: String,
    backward: bool,
}

/// Read one channel (one direction of one signal) of a Nanonis `.sxm` file (module docs).
/// Channels are named `Z (forward)`, `Z (backward)` for a signal saved in both directions, by the
/// signal's name alone otherwise.
pub fn read(path: &Path, bytes: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    if !is_sxm(bytes) {
        return Err(bad(
            path,
            "not a Nanonis SXM file (no ':NANONIS_VERSION:' at the start)",
        ));
    }
    let end = find(bytes, END_TAG).ok_or_else(|| {
        bad(
            path,
            "SXM header has no ':SCANIT_END:' (file truncated or not an SXM scan)",
        )
    })?;
    let header = Header::parse(&latin1(&bytes[..end]));
    // The data start after 0x1A 0x04, a few line ends after the end tag.
    let after = end + END_TAG.len();
    let marker = bytes[after..bytes.len().min(after + 64)]
        .windows(2)
        .position(|w| w == [0x1a, 0x04])
        .ok_or_else(|| {
            bad(
                path,
                "SXM header's ':SCANIT_END:' is not followed by the data marker 0x1A 0x04",
            )
        })?;
    let data_start = after + marker + 2;
    let big_endian = byte_order(path, &header)?;
    let (nx, ny) = header.pair::<usize>(path, "SCAN_PIXELS")?;
    if nx == 0 || ny == 0 {
        return Err(bad(path, format!("SXM :SCAN_PIXELS: is {nx} × {ny}")));
    }
    let image_bytes = grid_bytes(path, nx, ny, 4)?;
    let (range_x, range_y) = header.pair::<f64>(path, "SCAN_RANGE")?;
    if !(range_x.is_finite() && range_y.is_finite() && range_x > 0.0 && range_y > 0.0) {
        return Err(bad(
            path,
            format!("SXM :SCAN_RANGE: {range_x} × {range_y} m is not positive"),
        ));
    }
    let scan_up = match header.words("SCAN_DIR").as_deref() {
        Some(["up"]) => true,
        Some(["down"]) | None => false,
        Some(other) => {
            return Err(bad(
                path,
                format!(
                    "SXM :SCAN_DIR: '{}' is neither up nor down",
                    other.join(" ")
                ),
            ))
        }
    };
    let images = data_info(path, &header)?;
    let entries: Vec<ChannelEntry> = images.iter().map(|i| i.entry.clone()).collect();
    let index = choose(path, &entries, channel)?;
    let image = &images[index];
    let scale = length_scale(path, &image.entry, &image.unit)?;
    let offset = index
        .checked_mul(image_bytes)
        .and_then(|o| o.checked_add(data_start))
        .ok_or_else(|| unsupported(path, "SXM data offset overflows"))?;
    let raw = slice(path, bytes, offset, image_bytes, "channel data")?;
    let values = decode_values(raw, 4, true, true, big_endian);
    let mut heights = Vec::with_capacity(nx * ny);
    let mut add = |line: &[f64]| match image.backward {
        true => heights.extend(line.iter().rev().map(|v| v * scale)),
        false => heights.extend(line.iter().map(|v| v * scale)),
    };
    match scan_up {
        true => values.chunks_exact(nx).rev().for_each(&mut add),
        false => values.chunks_exact(nx).for_each(&mut add),
    }
    height_map(
        path,
        TopographyFormat::Sxm,
        (&entries, index),
        (ny, nx),
        heights,
        (range_x / nx as f64, range_y / ny as f64),
    )
}

/// `true` for big-endian floats (`FLOAT MSBFIRST`, also when the tag is absent, as every
/// Nanonis version writes them), `false` for `LSBFIRST`; other types are refused.
fn byte_order(path: &Path, header: &Header) -> Result<bool> {
    match header.words("SCANIT_TYPE").as_deref() {
        None | Some(["FLOAT", "MSBFIRST"]) => Ok(true),
        Some(["FLOAT", "LSBFIRST"]) => Ok(false),
        Some(other) => Err(unsupported(
            path,
            format!(
                "SXM data type '{}' (only FLOAT MSBFIRST/LSBFIRST are known)",
                other.join(" ")
            ),
        )),
    }
}

/// The images of the file in data order, from the `:DATA_INFO:` table (a header row naming the
/// columns, then one tab-separated row per signal).
fn data_info(path: &Path, header: &Header) -> Result<Vec<Image>> {
    let rows = header
        .lines("DATA_INFO")
        .ok_or_else(|| bad(path, "SXM header has no :DATA_INFO: table of channels"))?;
    let mut rows = rows.iter().map(|r| r.trim()).filter(|r| !r.is_empty());
    let columns: Vec<&str> = rows
        .next()
        .ok_or_else(|| bad(path, "SXM :DATA_INFO: table is empty"))?
        .split('\t')
        .map(str::trim)
        .collect();
    let column = |name: &str| {
        columns
            .iter()
            .position(|c| c.eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                bad(
                    path,
                    format!("SXM :DATA_INFO: table has no '{name}' column"),
                )
            })
    };
    let (name_at, unit_at, direction_at) = (column("Name")?, column("Unit")?, column("Direction")?);
    let mut images = Vec::new();
    for (i, row) in rows.enumerate() {
        let cells: Vec<&str> = row.split('\t').map(str::trim).collect();
        let cell = |at: usize, what: &str| {
            cells
                .get(at)
                .copied()
                .ok_or_else(|| bad(path, format!("SXM :DATA_INFO: row {} has no {what}", i + 1)))
        };
        let (name, unit) = (cell(name_at, "name")?, cell(unit_at, "unit")?);
        let directions: &[bool] = match cell(direction_at, "direction")?.to_lowercase().as_str() {
            "both" => &[false, true],
            "forward" | "fwd" => &[false],
            "backward" | "bwd" => &[true],
            other => {
                return Err(bad(
                    path,
                    format!("SXM :DATA_INFO: direction '{other}' of '{name}' is not known"),
                ))
            }
        };
        for &backward in directions {
            let label = match (directions.len(), backward) {
                (1, false) => name.to_string(),
                (_, false) => format!("{name} (forward)"),
                (_, true) => format!("{name} (backward)"),
            };
            images.push(Image {
                entry: ChannelEntry {
                    name: label,
                    height: length_factor(unit).is_some(),
                },
                unit: unit.to_string(),
                backward,
            });
        }
        if images.len() > 4096 {
            return Err(bad(path, "SXM :DATA_INFO: lists more than 4096 images"));
        }
    }
    Ok(images)
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// One signal of an SXM file written by [`encode_sxm`].
#[derive(Debug, Clone, Copy)]
pub struct SxmSignal<'a> {
    /// Name in the `DATA_INFO` table.
    pub name: &'a str,
    /// Unit in the table.
    pub unit: &'a str,
    /// The forward image, `nx·ny` values in stored order (lines as scanned).
    pub forward: &'a [f32],
    /// The backward image, if saved (lines as scanned: right to left).
    pub backward: Option<&'a [f32]>,
}

/// The bytes of an SXM file (for tests and the fuzz harness' templates).
pub fn encode_sxm(
    (nx, ny): (usize, usize),
    (range_x_m, range_y_m): (f64, f64),
    scan_dir: &str,
    signals: &[SxmSignal],
) -> Vec<u8> {
    let mut header = format!(
        ":NANONIS_VERSION:\n2\n:SCANIT_TYPE:\n              FLOAT            MSBFIRST\n\
         :SCAN_PIXELS:\n       {nx}       {ny}\n:SCAN_RANGE:\n           {range_x_m:E}           \
         {range_y_m:E}\n:SCAN_DIR:\n{scan_dir}\n:DATA_INFO:\n\tChannel\tName\tUnit\tDirection\t\
         Calibration\tOffset\n"
    );
    for (i, signal) in signals.iter().enumerate() {
        let (name, unit) = (signal.name, signal.unit);
        let direction = if signal.backward.is_some() {
            "both"
        } else {
            "forward"
        };
        header.push_str(&format!(
            "\t{i}\t{name}\t{unit}\t{direction}\t1.000E+0\t0.000E+0\n"
        ));
    }
    header.push_str("\n:SCANIT_END:\n\n\n");
    let mut out = header.into_bytes();
    out.extend_from_slice(&[0x1a, 0x04]);
    for signal in signals {
        let backward = signal.backward.iter().flat_map(|b| b.iter());
        for v in signal.forward.iter().chain(backward) {
            out.extend_from_slice(&v.to_be_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, bytes: &[u8]) -> std::path::PathBuf {
        let path = dir.join("scan.sxm");
        std::fs::write(&path, bytes).unwrap();
        path
    }

    // A 3 × 2 scan: stored lines [1 2 3], [4 5 6] (nm) forward; backward lines as scanned
    // right to left.
    const FWD: [f32; 6] = [1e-9, 2e-9, 3e-9, 4e-9, 5e-9, 6e-9];
    const BWD: [f32; 6] = [13e-9, 12e-9, 11e-9, 16e-9, 15e-9, 14e-9];

    fn read_file(path: &Path, channel: Option<&str>) -> Result<HeightMap> {
        read(path, &std::fs::read(path).unwrap(), channel)
    }

    #[test]
    fn channels_directions_and_orientation() {
        let dir = tempfile::tempdir().unwrap();
        let current = [0.5f32; 6];
        let signals = [
            SxmSignal {
                name: "Current",
                unit: "A",
                forward: &current,
                backward: None,
            },
            SxmSignal {
                name: "Z",
                unit: "m",
                forward: &FWD,
                backward: Some(&BWD),
            },
        ];
        let path = write(
            dir.path(),
            &encode_sxm((3, 2), (3e-8, 4e-8), "down", &signals),
        );
        // The height is chosen by its unit: the current is not a length.
        let map = read_file(&path, None).unwrap();
        assert_eq!(map.channels, ["Current", "Z (forward)", "Z (backward)"]);
        assert_eq!(map.channel, "Z (forward)");
        assert_eq!((map.nx(), map.ny()), (3, 2));
        assert!((map.dx_m - 1e-8).abs() < 1e-20 && (map.dy_m - 2e-8).abs() < 1e-20);
        let nm: Vec<f64> = map.heights.iter().map(|h| (h * 1e9).round()).collect();
        assert_eq!(nm, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        // Backward lines mirrored onto the forward grid.
        let back = read_file(&path, Some("z (backward)")).unwrap();
        let nm: Vec<f64> = back.heights.iter().map(|h| (h * 1e9).round()).collect();
        assert_eq!(nm, [11.0, 12.0, 13.0, 14.0, 15.0, 16.0]);
        // A scan up stored its bottom line first: row 0 is the top.
        let up = write(
            dir.path(),
            &encode_sxm((3, 2), (3e-8, 4e-8), "up", &signals),
        );
        let map = read_file(&up, Some("Z (forward)")).unwrap();
        let nm: Vec<f64> = map.heights.iter().map(|h| (h * 1e9).round()).collect();
        assert_eq!(nm, [4.0, 5.0, 6.0, 1.0, 2.0, 3.0]);
        // A current is refused as heights, naming its unit.
        let err = read_file(&path, Some("Current")).unwrap_err().to_string();
        assert!(err.contains("'A', not a length"), "{err}");
    }

    #[test]
    fn unscanned_points_are_invalid_and_bad_headers_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let mut partial = FWD;
        partial[3..].fill(f32::NAN);
        let signals = [SxmSignal {
            name: "Z",
            unit: "m",
            forward: &partial,
            backward: None,
        }];
        let bytes = encode_sxm((3, 2), (3e-8, 4e-8), "down", &signals);
        let map = read_file(&write(dir.path(), &bytes), None).unwrap();
        assert_eq!((map.channel.as_str(), map.invalid_points), ("Z", 3));
        // Truncated data.
        let err = read_file(&write(dir.path(), &bytes[..bytes.len() - 5]), None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("scan.sxm") && err.contains("truncated"),
            "{err}"
        );
        // No end tag.
        let cut = find(&bytes, END_TAG).unwrap();
        let err = read_file(&write(dir.path(), &bytes[..cut]), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("SCANIT_END"), "{err}");
        // Pixels that are not two numbers; an unknown data type.
        let text = String::from_utf8_lossy(&bytes).replace("       3       2", "3 x");
        let err = read_file(&write(dir.path(), text.as_bytes()), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("SCAN_PIXELS"), "{err}");
        let mut typed = bytes.clone();
        let at = find(&typed, b"MSBFIRST").unwrap();
        typed.splice(at..at + 8, b"MSBLAST!".iter().copied());
        let err = read_file(&write(dir.path(), &typed), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("MSBLAST!"), "{err}");
        // Absurd sizes are refused before any allocation.
        let huge =
            String::from_utf8_lossy(&bytes).replace("       3       2", "4000000000 4000000000");
        let err = read_file(&write(dir.path(), huge.as_bytes()), None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("scan.sxm"), "{err}");
    }
}
