//! Bruker/Veeco/Digital Instruments Nanoscope files (`.di`, `.spm`, `.001`, …; version 4.3 and
//! later): a text header of `\*Section` lines and `\key: value` lines ending at
//! `\*File list end`, one `\*Ciao image list` section per channel, and int16 (or int32) data
//! at each channel's `Data offset`.
//!
//! A force-volume file (`\*Force file list`) has the same header with `\*Ciao force image list`
//! sections for its force curves (`@4:Image Data`): its image channels are read as above, its
//! force channels listed as `DeflectionError (force curves)` and refused as heights; a file of
//! force curves alone is refused naming them.
//!
//! The height of a channel is `raw · (V_z / 65536) · S` (int32: a further `/65536`), where
//! `V_z` is the last number of `\@2:Z scale: V [Sens. X] (… V/LSB) V_z V` and `S` the soft
//! scale `\@Sens. X: V S nm/V` from the scanner sections. The default channel is the first one
//! whose soft scale is a length per volt (Height or Height Sensor). Lines are stored bottom
//! first; rows are flipped so that row 0 is the top of the image as Gwyddion shows it.

use std::collections::HashMap;
use std::path::Path;

use super::{HeightMap, TopographyFormat};
use crate::error::{Error, Location, Result};

use super::vendor::{choose, grid_bytes, height_map, ChannelEntry};
use super::{bad, latin1, length_unit, slice};

/// One `\*Ciao image list` section.
#[derive(Debug, Default)]
struct Channel {
    fields: HashMap<String, String>,
}

/// The header: scanner fields (every section but the image and force lists), the image
/// channels and, in a force-volume file, the force-curve channels.
struct Header {
    scanner: HashMap<String, String>,
    channels: Vec<Channel>,
    force: Vec<Channel>,
}

/// A channel resolved to numbers.
struct HeightChannel {
    offset: usize,
    bytes_per_pixel: usize,
    nx: usize,
    ny: usize,
    size_m: (f64, f64),
    metres_per_lsb: f64,
}

/// Read a channel of a Nanoscope file (module docs): `channel` by name, else the first height
/// channel ([`super::vendor::choose`]). Pixel size and height unit come from the header.
pub fn read(path: &Path, bytes: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let header = parse_header(path, bytes)?;
    let mut entries = Vec::with_capacity(header.channels.len());
    let mut resolved: Vec<Result<Option<HeightChannel>>> =
        Vec::with_capacity(header.channels.len());
    for c in &header.channels {
        let name = channel_name(c);
        let r = resolve(path, &header, c, &name);
        let length = matches!(r, Ok(Some(_)));
        entries.push((name, c.fields.get("line direction").cloned(), length));
        resolved.push(r);
    }
    let names = distinct_names(&entries);
    let force: Vec<String> = header
        .force
        .iter()
        .map(|c| format!("{} (force curves)", channel_name(c)))
        .collect();
    if header.channels.is_empty() && !header.force.is_empty() {
        return Err(Error::Unsupported {
            at: Location::file(path),
            reason: format!(
                "a Nanoscope force-curve file without an image: its channels hold force curves \
                 ({}), not a height map",
                force.join(", ")
            ),
        });
    }
    // Force curves are listed after the images (so that they can be named), never read.
    let list: Vec<ChannelEntry> = names
        .iter()
        .zip(&entries)
        .map(|(name, (_, _, length))| ChannelEntry {
            name: name.clone(),
            height: *length,
        })
        .chain(force.iter().map(|name| ChannelEntry {
            name: name.clone(),
            height: false,
        }))
        .collect();
    if list.iter().all(|c| !c.height) && channel.is_none() {
        return Err(Error::Unsupported {
            at: Location::file(path),
            reason: format!(
                "no channel with a height (length) scale; channels: {}",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ),
        });
    }
    let index = choose(path, &list, channel)?;
    if index >= resolved.len() {
        return Err(bad(
            path,
            format!(
                "channel '{}' holds force curves, not an image; the file's images are {}",
                list[index].name,
                names
                    .iter()
                    .map(|n| format!("'{n}'"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let Some(chosen) = resolved.swap_remove(index)? else {
        return Err(bad(
            path,
            format!(
                "channel '{}' has no height (length) scale; choose one of {}",
                list[index].name,
                list.iter()
                    .filter(|c| c.height)
                    .map(|c| format!("'{}'", c.name))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    };
    let (nx, ny, b) = (chosen.nx, chosen.ny, chosen.bytes_per_pixel);
    let data =
        slice(path, bytes, chosen.offset, grid_bytes(path, nx, ny, b)?).map_err(|e| match e {
            Error::BadInput { at, reason } => Error::BadInput {
                at,
                reason: format!("channel '{}': {reason}", list[index].name),
            },
            other => other,
        })?;
    let mut heights = Vec::with_capacity(nx * ny);
    for row in data.chunks_exact(nx * b).rev() {
        heights.extend(
            row.chunks_exact(b)
                .map(|c| raw_value(c) * chosen.metres_per_lsb),
        );
    }
    height_map(
        path,
        TopographyFormat::Nanoscope,
        (&list, index),
        (ny, nx),
        heights,
        (chosen.size_m.0 / nx as f64, chosen.size_m.1 / ny as f64),
    )
}

/// The channels' names as the file gives them (`Height`, `ZSensor`); a name the file uses twice
/// gets the line direction (`Height (Retrace)`) or its position so that each can be chosen.
fn distinct_names(entries: &[(String, Option<String>, bool)]) -> Vec<String> {
    let mut names: Vec<String> = Vec::with_capacity(entries.len());
    for (i, (name, direction, _)) in entries.iter().enumerate() {
        let earlier = entries[..i].iter().any(|(n, _, _)| n == name);
        let candidate = match direction {
            Some(d) if earlier => format!("{name} ({d})"),
            _ => name.clone(),
        };
        if names.contains(&candidate) {
            names.push(format!("{name} ({})", i + 1));
        } else {
            names.push(candidate);
        }
    }
    names
}

fn raw_value(c: &[u8]) -> f64 {
    match c.len() {
        2 => f64::from(i16::from_le_bytes([c[0], c[1]])),
        _ => f64::from(i32::from_le_bytes([c[0], c[1], c[2], c[3]])),
    }
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    if !bytes.starts_with(b"\\*File list") && !bytes.starts_with(b"\\*Force file list") {
        return Err(bad(
            path,
            "not a Nanoscope file (it does not start with '\\*File list')",
        ));
    }
    let mut header = Header {
        scanner: HashMap::new(),
        channels: Vec::new(),
        force: Vec::new(),
    };
    let mut in_image = false;
    let mut in_force = false;
    let mut rest = bytes;
    loop {
        let end = rest.iter().position(|&b| b == b'\n').ok_or_else(|| {
            bad(
                path,
                "Nanoscope header has no '\\*File list end' (file truncated?)",
            )
        })?;
        let line = latin1(&rest[..end]);
        rest = &rest[end + 1..];
        let line = line.trim();
        if line.eq_ignore_ascii_case("\\*File list end") {
            return Ok(header);
        }
        if let Some(section) = line.strip_prefix("\\*") {
            in_image = section.eq_ignore_ascii_case("Ciao image list");
            in_force = section.eq_ignore_ascii_case("Ciao force image list");
            if in_image {
                header.channels.push(Channel::default());
            } else if in_force {
                header.force.push(Channel::default());
            }
        } else if let Some((key, value)) = line.strip_prefix('\\').and_then(split_entry) {
            let (key, value) = (key.trim().to_ascii_lowercase(), value.trim().to_string());
            let list = match (in_image, in_force) {
                (true, _) => header.channels.last_mut(),
                (_, true) => header.force.last_mut(),
                _ => None,
            };
            match list {
                Some(channel) => channel.fields.insert(key, value),
                None => header.scanner.insert(key, value),
            };
        }
    }
}

/// `key: value` (keys may contain colons, as in `@2:Z scale`); a bare `key:` has an empty value.
fn split_entry(line: &str) -> Option<(&str, &str)> {
    line.split_once(": ")
        .or_else(|| line.strip_suffix(':').map(|key| (key, "")))
}

/// `S [ZSensor] "Height Sensor"` → `ZSensor` (`@2:Image Data` of an image, `@4:Image Data` of
/// force curves).
fn channel_name(channel: &Channel) -> String {
    let text = channel
        .fields
        .get("@2:image data")
        .or_else(|| channel.fields.get("@4:image data"))
        .map_or("", String::as_str);
    match (text.find('['), text.find(']')) {
        (Some(a), Some(b)) if a < b => text[a + 1..b].to_string(),
        _ => text.to_string(),
    }
}

/// The channel's numbers if its scale is a length, `None` for other quantities.
fn resolve(
    path: &Path,
    header: &Header,
    channel: &Channel,
    name: &str,
) -> Result<Option<HeightChannel>> {
    let field = |key: &str| {
        channel
            .fields
            .get(key)
            .map(String::as_str)
            .ok_or_else(|| bad(path, format!("Nanoscope channel '{name}' has no '{key}'")))
    };
    let Some((soft, unit, volts_per_unit_hard)) = soft_scale(header, field("@2:z scale")?) else {
        return Ok(None);
    };
    let Ok(unit_m) = length_unit(path, &unit, "height") else {
        return Ok(None);
    };
    let integer = |key: &str| -> Result<usize> {
        let text = field(key)?;
        text.parse()
            .map_err(|_| bad(path, format!("Nanoscope '{key}: {text}' is not a count")))
    };
    let bytes_per_pixel = integer("bytes/pixel")?;
    let binary = match bytes_per_pixel {
        2 => 1.0,
        4 => 1.0 / 65536.0,
        n => {
            return Err(bad(
                path,
                format!("Nanoscope data with {n} bytes per pixel"),
            ))
        }
    };
    let (nx, ny) = (integer("samps/line")?, integer("number of lines")?);
    if nx == 0 || ny == 0 {
        return Err(bad(
            path,
            format!("Nanoscope channel '{name}' has an empty grid"),
        ));
    }
    Ok(Some(HeightChannel {
        offset: integer("data offset")?,
        bytes_per_pixel,
        nx,
        ny,
        size_m: scan_size(path, field("scan size")?)?,
        metres_per_lsb: volts_per_unit_hard / 65536.0 * binary * soft * unit_m,
    }))
}

/// From `V [Sens. ZsensSens] (0.000375 V/LSB) 24.57563 V` and the scanner's
/// `@Sens. ZsensSens: V 790.3658 nm/V`: (soft scale 790.3658, unit "nm", hard value 24.57563).
/// `None` when the quantity has no soft scale or its unit is not `<unit>/<hard unit>`.
fn soft_scale(header: &Header, z_scale: &str) -> Option<(f64, String, f64)> {
    let quantity = z_scale
        .split_once('[')?
        .1
        .split_once(']')?
        .0
        .to_ascii_lowercase();
    let mut words = z_scale.rsplit(' ').filter(|w| !w.is_empty());
    let hard_unit = words.next()?;
    let hard: f64 = words.next()?.parse().ok()?;
    let sens = header.scanner.get(&format!("@{quantity}"))?;
    let mut parts = sens.split_whitespace();
    if parts.next()? != "V" {
        return None;
    }
    let soft: f64 = parts.next()?.parse().ok()?;
    let (unit, per) = parts.next()?.split_once('/')?;
    // The hard value may be in another prefix of the soft scale's denominator (mV against nm/V).
    let ratio = if per == hard_unit {
        1.0
    } else {
        volts(hard_unit)? / volts(per)?
    };
    Some((soft, unit.to_string(), hard * ratio))
}

/// Volts per unit of a voltage unit (`V`, `mV`, `uV`/`µV`), else `None`.
fn volts(unit: &str) -> Option<f64> {
    match unit {
        "V" => Some(1.0),
        "mV" => Some(1e-3),
        "uV" | "µV" | "~V" => Some(1e-6),
        _ => None,
    }
}

/// `10 10 ~m` (x y unit) or `10000 nm` (square) → metres.
fn scan_size(path: &Path, text: &str) -> Result<(f64, f64)> {
    let words: Vec<&str> = text.split_whitespace().collect();
    let number = |w: &str| {
        w.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| {
                bad(
                    path,
                    format!("Nanoscope scan size '{text}' is not readable"),
                )
            })
    };
    let (x, y, unit) = match words.as_slice() {
        [x, y, unit] => (number(x)?, number(y)?, *unit),
        [x, unit] => (number(x)?, number(x)?, *unit),
        _ => {
            return Err(bad(
                path,
                format!("Nanoscope scan size '{text}' is not readable"),
            ))
        }
    };
    let unit_m = length_unit(path, unit, "scan size")?;
    Ok((x * unit_m, y * unit_m))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 × 2 file: a phase channel first, then a height channel.
    fn sample(data: &[i16]) -> Vec<u8> {
        let mut text = String::from(
            "\\*File list\r\n\\Data length: 1024\r\n\\*Ciao scan list\r\n\
             \\@Sens. Zsens: V 20 nm/V\r\n\\@Sens. Phase: V 1 deg/V\r\n",
        );
        for (name, quantity, offset) in [("Phase", "Phase", 1024), ("Height", "Zsens", 1032)] {
            text.push_str(&format!(
                "\\*Ciao image list\r\n\\Data offset: {offset}\r\n\\Bytes/pixel: 2\r\n\
                 \\Samps/line: 2\r\n\\Number of lines: 2\r\n\\Scan Size: 4 2 ~m\r\n\
                 \\@2:Image Data: S [{name}] \"{name}\"\r\n\
                 \\@2:Z scale: V [Sens. {quantity}] (0.0001 V/LSB) 6.5536 V\r\n"
            ));
        }
        text.push_str("\\*File list end\r\n");
        let mut out = text.into_bytes();
        out.resize(1032, 0);
        out.extend(data.iter().flat_map(|v| v.to_le_bytes()));
        out
    }

    fn file(bytes: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.di");
        std::fs::write(&path, bytes).unwrap();
        (dir, path)
    }

    fn read_nanoscope(path: &Path, channel: Option<&str>) -> Result<HeightMap> {
        read(path, &std::fs::read(path).unwrap(), channel)
    }

    #[test]
    fn reads_the_first_height_channel_top_row_first() {
        let (_dir, path) = file(&sample(&[1, 2, 3, 4]));
        let t = read_nanoscope(&path, None).unwrap();
        // 0.0001 V/LSB × 20 nm/V = 2 pm per LSB; stored bottom line first.
        let expected = [6e-12, 8e-12, 2e-12, 4e-12];
        for (a, b) in t.heights.iter().zip(expected) {
            assert!((a - b).abs() < 1e-24, "{a} vs {b}");
        }
        assert!((t.dx_m - 2e-6).abs() < 1e-18 && (t.dy_m - 1e-6).abs() < 1e-18);
        assert_eq!(t.channel, "Height");
        assert_eq!(t.channels, ["Phase", "Height"]);
        let err = read_nanoscope(&path, Some("phase"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("'Phase' has no height") && err.contains("'Height'"),
            "{err}"
        );
        let err = read_nanoscope(&path, Some("Friction"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("no channel 'Friction'"), "{err}");
    }

    #[test]
    fn a_name_used_twice_gets_the_line_direction() {
        let e = |n: &str, d: Option<&str>| (n.to_string(), d.map(String::from), true);
        let names = distinct_names(&[
            e("Height", Some("Trace")),
            e("Height", Some("Retrace")),
            e("Phase", Some("Trace")),
            e("Height", Some("Retrace")),
            e("Phase", None),
        ]);
        assert_eq!(
            names,
            [
                "Height",
                "Height (Retrace)",
                "Phase",
                "Height (4)",
                "Phase (5)"
            ]
        );
    }

    /// `sample` as a force-volume file: its header starts `\*Force file list` and holds force
    /// curves (`\*Ciao force image list`, before and after the images).
    fn force_volume(data: &[i16], images: bool) -> Vec<u8> {
        let force = "\\*Ciao force image list\r\n\\Data offset: 40960\r\n\\Bytes/pixel: 2\r\n\
                     \\Samps/line: 512\r\n\\@4:Image Data: S [DeflectionError] \"Deflection \
                     Error\"\r\n\\@4:Z scale: V [Sens. DeflSens] (0.000375 V/LSB) 24.5 V\r\n";
        let text = String::from_utf8_lossy(&sample(data)).into_owned();
        let text = text
            .replacen("\\*File list\r\n", "\\*Force file list\r\n", 1)
            .replacen(
                "\\*Ciao image list",
                &format!("{force}\\*Ciao image list"),
                1,
            )
            .replacen("\\*File list end", &format!("{force}\\*File list end"), 1);
        let text = match images {
            true => text,
            false => text.replace("\\*Ciao image list", "\\*Ciao scan list"),
        };
        text.into_bytes()
    }

    #[test]
    fn a_force_volume_file_reads_its_images_and_names_its_curves() {
        // The header grew by the force sections: the data offsets of `sample` move with it.
        let bytes = force_volume(&[1, 2, 3, 4], true);
        let at = bytes.len() - 8;
        let mut text = String::from_utf8_lossy(&bytes[..at]).into_owned();
        text = text
            .replace("Data offset: 1024", &format!("Data offset: {}", at - 8))
            .replace("Data offset: 1032", &format!("Data offset: {at}"));
        let mut fixed = text.into_bytes();
        fixed.extend(&bytes[at..]);
        let (_dir, path) = file(&fixed);
        let m = read_nanoscope(&path, None).unwrap();
        assert_eq!(m.channel, "Height");
        assert_eq!(
            m.channels,
            [
                "Phase",
                "Height",
                "DeflectionError (force curves)",
                "DeflectionError (force curves)"
            ]
        );
        let plain = file(&sample(&[1, 2, 3, 4]));
        let image = read_nanoscope(&plain.1, None).unwrap();
        assert_eq!(
            m.heights, image.heights,
            "the image reads as in an image file"
        );
        assert_eq!((m.dx_m, m.dy_m), (image.dx_m, image.dy_m));
        let err = read_nanoscope(&path, Some("deflection"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("holds force curves, not an image") && err.contains("'Height'"),
            "{err}"
        );
        let (_dir, path) = file(&force_volume(&[1, 2, 3, 4], false));
        let err = read_nanoscope(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("force-curve file without an image")
                && err.contains("DeflectionError (force curves)"),
            "{err}"
        );
    }

    #[test]
    fn rejects_truncated_and_foreign_files() {
        let mut bytes = sample(&[1, 2, 3, 4]);
        bytes.truncate(bytes.len() - 1);
        let (_dir, path) = file(&bytes);
        let err = read_nanoscope(&path, None).unwrap_err().to_string();
        assert!(err.contains("truncated") && err.contains("Height"), "{err}");
        let mut bytes = sample(&[1, 2, 3, 4]);
        bytes.truncate(200);
        let (_dir, path) = file(&bytes);
        assert!(read_nanoscope(&path, None)
            .unwrap_err()
            .to_string()
            .contains("File list end"));
        let (_dir, path) = file(b"\\*Something else\r\n");
        assert!(read_nanoscope(&path, None)
            .unwrap_err()
            .to_string()
            .contains("not a Nanoscope"));
        let bytes = String::from_utf8_lossy(&sample(&[0; 4])).replace("nm/V", "mV/V");
        let (_dir, path) = file(bytes.as_bytes());
        let err = read_nanoscope(&path, None).unwrap_err().to_string();
        assert!(
            err.contains("no channel with a height") && err.contains("Phase, Height"),
            "{err}"
        );
    }
}
