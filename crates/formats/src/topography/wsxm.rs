//! WSxM image files (`.top`, Nanotec Electronica): three text lines (`WSxM file copyright …`,
//! `SxM Image file`, `Image header size: N`), an INI-like header of `[Section]`s with
//! `key: value` lines ending at `[Header end]`, and the data at byte N, row-major, rows from the
//! first line of the header's grid.
//!
//! Heights: the stored numbers times `Z Amplitude / (Maximum − Minimum)` (both from the
//! header; 1 if they are equal), in the unit of `Z Amplitude`. Lateral size: `X Amplitude` and
//! `Y Amplitude` over the number of columns and rows. This is how Gwyddion's and
//! SurfaceTopography's readers interpret the format; it reproduces their numbers for the
//! bundled example (tests).

use std::collections::HashMap;
use std::path::Path;

use super::{HeightMap, TopographyFormat};
use crate::error::Result;

use super::vendor::{choose, grid_bytes, height_map, ChannelEntry};
use super::{bad, latin1, length_unit, slice};

/// Header fields keyed by (section, key).
struct Header {
    fields: HashMap<(String, String), String>,
}

impl Header {
    fn get(&self, path: &Path, section: &str, key: &str) -> Result<&str> {
        self.fields
            .get(&(section.to_string(), key.to_string()))
            .map(String::as_str)
            .ok_or_else(|| bad(path, format!("WSxM header has no [{section}] {key}")))
    }

    fn number(&self, path: &Path, section: &str, key: &str) -> Result<f64> {
        let text = self.get(path, section, key)?;
        text.parse().map_err(|_| {
            bad(
                path,
                format!("WSxM [{section}] {key} = '{text}' is not a number"),
            )
        })
    }

    /// `"600 nm"` → value in metres.
    fn length(&self, path: &Path, section: &str, key: &str) -> Result<f64> {
        let text = self.get(path, section, key)?;
        let (value, unit) = text.split_once(' ').unwrap_or((text, ""));
        let value: f64 = value.trim().parse().map_err(|_| {
            bad(
                path,
                format!("WSxM [{section}] {key} = '{text}' is not a length"),
            )
        })?;
        Ok(value * length_unit(path, unit, &format!("WSxM {key}"))?)
    }

    fn count(&self, path: &Path, key: &str) -> Result<usize> {
        let text = self.get(path, "General Info", key)?;
        match text.parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(bad(
                path,
                format!("WSxM {key} = '{text}' is not a positive integer"),
            )),
        }
    }
}

/// Read a WSxM image (`.top`, `.stp`, …; module docs). Pixel size and height unit come from the
/// header. The one channel is named by `[General Info] Acquisition channel` (else "Default").
pub fn read(path: &Path, bytes: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let (header, data_offset) = parse_header(path, bytes)?;
    let name = header
        .get(path, "General Info", "Acquisition channel")
        .ok()
        .filter(|n| !n.is_empty())
        .unwrap_or("Default");
    let channels = [ChannelEntry {
        name: name.to_string(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let (nx, ny) = (
        header.count(path, "Number of columns")?,
        header.count(path, "Number of rows")?,
    );
    let pixel = (
        header.length(path, "Control", "X Amplitude")? / nx as f64,
        header.length(path, "Control", "Y Amplitude")? / ny as f64,
    );
    let z_amplitude = header.length(path, "General Info", "Z Amplitude")?;
    let kind = header.get(path, "General Info", "Image Data Type")?;
    let (size, integer) = match kind {
        "short" | "integer" => (2, true),
        "float" => (4, false),
        "double" => (8, false),
        other => {
            return Err(bad(
                path,
                format!("WSxM Image Data Type '{other}' is not known"),
            ))
        }
    };
    // Integers span the header's Minimum…Maximum over the Z amplitude; floating-point numbers
    // are heights in the Z amplitude's unit (the header's Minimum and Maximum are those numbers
    // rounded to six digits: their ratio to the amplitude is not a scale).
    let scale = if integer {
        let range = header.number(path, "Miscellaneous", "Maximum")?
            - header.number(path, "Miscellaneous", "Minimum")?;
        if range > 0.0 {
            z_amplitude / range
        } else {
            1.0
        }
    } else {
        let z_text = header.get(path, "General Info", "Z Amplitude")?;
        let (_, unit) = z_text.split_once(' ').unwrap_or((z_text, ""));
        length_unit(path, unit, "WSxM Z Amplitude")?
    };
    let data = slice(path, bytes, data_offset, grid_bytes(path, nx, ny, size)?)?;
    let heights = data
        .chunks_exact(size)
        .map(|c| raw_value(c) * scale)
        .collect();
    height_map(
        path,
        TopographyFormat::Wsxm,
        (&channels, index),
        (ny, nx),
        heights,
        pixel,
    )
}

fn raw_value(c: &[u8]) -> f64 {
    match c.len() {
        2 => f64::from(i16::from_le_bytes([c[0], c[1]])),
        4 => f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        _ => f64::from_le_bytes(c.try_into().expect("8 bytes")),
    }
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<(Header, usize)> {
    let not_wsxm = || {
        bad(
            path,
            "not a WSxM file (first line is not 'WSxM file copyright …')",
        )
    };
    let head = latin1(&bytes[..bytes.len().min(256)]);
    let mut lines = head.lines();
    if !lines
        .next()
        .is_some_and(|l| l.starts_with("WSxM file copyright"))
    {
        return Err(not_wsxm());
    }
    if lines.next().map(str::trim) != Some("SxM Image file") {
        return Err(bad(
            path,
            format!(
                "a WSxM file that is not an image ('{}' instead of 'SxM Image file'): \
                 topography and simulate need a height map",
                lines.next().unwrap_or("").trim()
            ),
        ));
    }
    let size_line = lines.next().unwrap_or("");
    let size: usize = size_line
        .strip_prefix("Image header size:")
        .and_then(|s| s.trim().parse().ok())
        .ok_or_else(|| {
            bad(
                path,
                format!("WSxM header size line '{size_line}' is not readable"),
            )
        })?;
    let text = latin1(slice(path, bytes, 0, size)?);
    let mut fields = HashMap::new();
    let mut section = String::new();
    for line in text.lines().skip(3).map(str::trim) {
        if line == "[Header end]" {
            return Ok((Header { fields }, size));
        }
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = name.to_string();
        } else if let Some((key, value)) = line.split_once(':') {
            fields.insert(
                (section.clone(), key.trim().to_string()),
                value.trim().to_string(),
            );
        }
    }
    Err(bad(
        path,
        "WSxM header has no [Header end] within its stated size",
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small WSxM file: 2 × 3 shorts, X 3 nm, Y 2 nm, Z amplitude 10 nm over 0..100.
    fn sample(kind: &str, payload: &[u8]) -> Vec<u8> {
        let body = format!(
            "[Control]\n    X Amplitude: 3 nm\n    Y Amplitude: 2 nm\n[General Info]\n    \
             Image Data Type: {kind}\n    Number of columns: 3\n    Number of rows: 2\n    \
             Z Amplitude: 10 nm\n[Miscellaneous]\n    Maximum: 100\n    Minimum: 0\n\
             [Header end]\n"
        );
        let mut size = 0;
        let mut text = String::new();
        for _ in 0..3 {
            text = format!(
                "WSxM file copyright Nanotec Electronica\r\nSxM Image file\r\nImage header size: {size}\r\n{body}"
            );
            size = text.len();
        }
        let mut out = text.into_bytes();
        out.extend_from_slice(payload);
        out
    }

    fn read_wsxm(path: &Path) -> Result<HeightMap> {
        read(path, &std::fs::read(path).unwrap(), None)
    }

    fn file(bytes: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.top");
        std::fs::write(&path, bytes).unwrap();
        (dir, path)
    }

    #[test]
    fn reads_a_small_file() {
        let payload: Vec<u8> = [0i16, 10, 20, 30, 40, 100]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let (_dir, path) = file(&sample("short", &payload));
        let t = read_wsxm(&path).unwrap();
        assert_eq!((t.ny(), t.nx()), (2, 3));
        assert!((t.dx_m - 1e-9).abs() < 1e-24 && (t.dy_m - 1e-9).abs() < 1e-24);
        assert!((t.heights[[1, 2]] - 10e-9).abs() < 1e-22);
        assert!((t.heights[[0, 1]] - 1e-9).abs() < 1e-22);
        assert_eq!(t.channel, "Default");
        // Floating-point numbers are heights in the amplitude's unit, whatever Minimum/Maximum.
        let payload: Vec<u8> = [0.5f64, 1.0, 2.0, 3.0, 4.0, 5.0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let (_dir, path) = file(&sample("double", &payload));
        let t = read_wsxm(&path).unwrap();
        assert_eq!(t.heights[[0, 0]], 0.5e-9);
    }

    #[test]
    fn rejects_truncated_and_foreign_files() {
        let (_dir, path) = file(&sample("short", &[0u8; 7]));
        assert!(read_wsxm(&path)
            .unwrap_err()
            .to_string()
            .contains("truncated"));
        let (_dir, path) = file(&sample("complex", &[0u8; 12]));
        assert!(read_wsxm(&path)
            .unwrap_err()
            .to_string()
            .contains("complex"));
        let (_dir, path) = file(b"Hello\n");
        assert!(read_wsxm(&path)
            .unwrap_err()
            .to_string()
            .contains("not a WSxM"));
        let mut cut = sample("short", &[]);
        cut.truncate(60);
        let (_dir, path) = file(&cut);
        assert!(read_wsxm(&path).is_err());
    }
}
