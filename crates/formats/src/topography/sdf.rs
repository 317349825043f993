//! ISO 25178-71 surface data file, ASCII variant (`aISO-1.0`): a header of `Key = value` lines
//! (`NumPoints`, `NumProfiles`, `Xscale`, `Yscale`, `Zscale` in m), then `NumPoints ×
//! NumProfiles` numbers, a profile (row) after another, then an optional free-text trailer.
//! A `*` line may close the header. Heights are `value · Zscale` m; `BAD` (or any other
//! non-number) marks an invalid point. The binary variant (`bISO`)
//! is refused.

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, unsupported};
use crate::error::Result;

/// Read an ASCII SDF file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    if !data.starts_with(b"aISO-1.0") {
        return Err(unsupported(
            path,
            "SDF other than the ASCII aISO-1.0 variant",
        ));
    }
    let text = String::from_utf8_lossy(data);
    let mut lines = text.lines().skip(1);
    let mut header = std::collections::HashMap::new();
    let mut values: Vec<f64> = Vec::new();
    for line in lines.by_ref() {
        if let Some((k, v)) = line.split_once('=') {
            header.insert(k.trim().to_string(), v.trim().to_string());
            continue;
        }
        // A line of '*' closes the header (ISO 25178-71, section 5).
        if line.trim().is_empty() || line.trim() == "*" {
            continue;
        }
        // The first line without '=' starts the data.
        values.extend(
            line.split_whitespace()
                .map(|t| t.parse().unwrap_or(f64::NAN)),
        );
        break;
    }
    let num = |k: &str| -> Result<f64> {
        header
            .get(k)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| bad(path, format!("SDF header lacks {k}")))
    };
    let nx = count(path, "NumPoints", num("NumPoints")?)?;
    let ny = count(path, "NumProfiles", num("NumProfiles")?)?;
    grid_bytes(path, nx, ny, 8)?;
    let n = nx * ny;
    for line in lines {
        if values.len() >= n {
            break;
        }
        values.extend(
            line.split_whitespace()
                .map(|t| t.parse().unwrap_or(f64::NAN)),
        );
    }
    if values.len() < n {
        return Err(bad(
            path,
            format!("SDF holds {} values, {nx}×{ny} expected", values.len()),
        ));
    }
    values.truncate(n);
    let z = positive(path, "Zscale", num("Zscale")?)?;
    let channels = [ChannelEntry {
        name: "Height".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let to_m = crate::topography::to_metres(z);
    let heights = values.into_iter().map(to_m).collect();
    let (dx, dy) = (
        positive(path, "Xscale", num("Xscale")?)?,
        positive(path, "Yscale", num("Yscale")?)?,
    );
    height_map(
        path,
        TopographyFormat::Sdf,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_ascii_layout_with_bad_points() {
        let text = "aISO-1.0\nNumPoints = 3\nNumProfiles = 2\nXscale = 2.0E-6\nYscale = 1.0E-6\n\
                    Zscale = 1.0E-9\n*\n1 2 3\n4 BAD 6\n*\ntrailer\n";
        let p = Path::new("s.sdf");
        let m = read(p, text.as_bytes(), None).unwrap();
        assert_eq!((m.nx(), m.ny(), m.invalid_points), (3, 2, 1));
        assert_eq!((m.heights[[1, 2]], m.dx_m), (6e-9, 2e-6));
        let short = text.replace("4 BAD 6\n*\ntrailer\n", "");
        assert!(read(p, short.as_bytes(), None)
            .unwrap_err()
            .to_string()
            .contains("3 values"));
    }
}
