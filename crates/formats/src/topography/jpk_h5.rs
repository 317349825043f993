//! JPK Instruments HDF5 exports (`.h5-jpk`, JPK SPM software 8: "Export to HDF5", a pycroscopy
//! USID layout): an HDF5 file whose root attribute `file-format-info` is `JPK SCAN`. Each
//! `Measurement_NNN` group states the scan grid (`position-pattern.grid.ilength` points along the
//! fast axis over `ulength`, `jlength` lines over `vlength`, in `position-pattern.grid.unit`);
//! each of its `Channel_NNN` groups one channel (`channel.name`, `retrace` true or false) with one
//! dataset of raw integers shaped (points, frames): a video of `frames` images, point index
//! `line · ilength + column`, lines stored bottom first.
//!
//! A channel's values are `raw · multiplier + offset` of its `net-encoder.scaling` attributes,
//! in `net-encoder.scaling.unit.unit`: the product of its calibration chain up to its default
//! slot (for a height: encoder volts → nominal → calibrated metres, the numbers JPK's own
//! software shows, and the scaling AFMReader applies); a channel without it is listed, not read. Channels are named as the JPK TIFF
//! reader names them, with their direction and, for a video, the frame: `height (trace)`,
//! `height (retrace, frame 3)`. Lines are flipped so that row 0 is the top of the image. The
//! pixel size is `ulength/ilength` by `vlength/jlength`. A phase in degrees or a signal in volts
//! is refused as heights.

use std::path::Path;

use hdf5_reader::group::Group;
use hdf5_reader::Attribute;

use super::{choose, grid_bytes, height_map, length_factor, ChannelEntry, HeightMap};
use super::{count, positive, TopographyFormat};
use crate::binary::{bad, unsupported};
use crate::error::Result;

/// Most channels (channel groups × frames) listed.
const MAX_CHANNELS: usize = 4096;

/// One frame of one channel group, as listed.
struct Entry {
    name: String,
    unit: String,
    grid: Grid,
    dataset: hdf5_reader::Dataset,
    frame: usize,
    frames: usize,
    scaling: Option<(f64, f64)>,
}

/// A measurement's scan grid.
#[derive(Clone, Copy)]
struct Grid {
    nx: usize,
    ny: usize,
    dx_m: f64,
    dy_m: f64,
}

/// Whether the root group says the file is a JPK HDF5 export.
pub(super) fn is_jpk_h5(root: &Group) -> bool {
    root.attribute("file-format-info")
        .ok()
        .and_then(|a| a.read_string().ok())
        .is_some_and(|s| s.trim_end_matches('\0').trim() == "JPK SCAN")
}

/// Read a channel (and frame) of a JPK HDF5 export (module docs).
pub(super) fn read(
    path: &Path,
    root: &Group,
    channel: Option<&str>,
    h5: &dyn Fn(hdf5_reader::error::Error) -> crate::error::Error,
) -> Result<HeightMap> {
    let measurements = children(root, "Measurement_", h5)?;
    let several = measurements.len() > 1;
    let mut entries = Vec::new();
    for m in &measurements {
        let attrs = m.attributes().map_err(h5)?;
        let grid = grid(path, &attrs)?;
        for g in children(m, "Channel_", h5)? {
            let attrs = g.attributes().map_err(h5)?;
            let Some(name) = text(&attrs, "channel.name") else {
                continue;
            };
            let direction = match text(&attrs, "retrace").as_deref() {
                Some("true") => "retrace",
                _ => "trace",
            };
            let Some(dataset) = g
                .datasets()
                .map_err(h5)?
                .into_iter()
                .find(|d| d.name() != "thumbnail" && d.shape().len() == 2)
            else {
                continue;
            };
            let frames = usize::try_from(dataset.shape()[1]).unwrap_or(usize::MAX);
            if frames == 0 || entries.len().saturating_add(frames) > MAX_CHANNELS {
                return Err(unsupported(
                    path,
                    format!(
                        "JPK channel '{name}' holds {frames} frames; 1 to {MAX_CHANNELS} are read"
                    ),
                ));
            }
            // Without its scaling a channel's counts have no unit (it is listed, not read).
            let scaling = number(&attrs, "net-encoder.scaling.multiplier").map(|multiplier| {
                let offset = number(&attrs, "net-encoder.scaling.offset").unwrap_or(0.0);
                (multiplier, offset)
            });
            let unit = text(&attrs, "net-encoder.scaling.unit.unit").unwrap_or_default();
            for frame in 0..frames {
                let mut label = format!("{name} ({direction}");
                if frames > 1 {
                    label.push_str(&format!(", frame {}", frame + 1));
                }
                label.push(')');
                if several {
                    label = format!("{} {label}", m.name());
                }
                entries.push(Entry {
                    name: label,
                    unit: unit.clone(),
                    grid,
                    dataset: dataset.clone(),
                    frame,
                    frames,
                    scaling,
                });
            }
        }
    }
    let channels: Vec<ChannelEntry> = entries
        .iter()
        .map(|e| ChannelEntry {
            name: e.name.clone(),
            height: e.scaling.is_some() && length_factor(&e.unit).is_some(),
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let e = &entries[index];
    let factor = length_factor(&e.unit).ok_or_else(|| {
        bad(
            path,
            format!("channel '{}' is in '{}', not a length", e.name, e.unit),
        )
    })?;
    let Grid { nx, ny, dx_m, dy_m } = e.grid;
    grid_bytes(path, nx, ny, 8)?;
    let points = usize::try_from(e.dataset.shape()[0]).unwrap_or(usize::MAX);
    if points != nx * ny {
        return Err(bad(
            path,
            format!(
                "JPK channel '{}' holds {points} points; its scan grid is {nx} × {ny}",
                e.name
            ),
        ));
    }
    let raw = super::hdf5::values(&e.dataset).map_err(h5)?;
    if raw.len() != points.saturating_mul(e.frames) {
        return Err(bad(
            path,
            format!(
                "JPK channel '{}' holds {} values for {points} points × {} frames",
                e.name,
                raw.len(),
                e.frames
            ),
        ));
    }
    let (multiplier, offset) = e.scaling.ok_or_else(|| {
        bad(
            path,
            format!("JPK channel '{}' states no net-encoder scaling", e.name),
        )
    })?;
    let mut heights = Vec::with_capacity(nx * ny);
    for line in (0..ny).rev() {
        for column in 0..nx {
            let v = raw[(line * nx + column) * e.frames + e.frame];
            heights.push((v * multiplier + offset) * factor);
        }
    }
    height_map(
        path,
        TopographyFormat::JpkHdf5,
        (&channels, index),
        (ny, nx),
        heights,
        (dx_m, dy_m),
    )
}

/// The groups below `group` whose names start with `prefix`, in name order.
fn children(
    group: &Group,
    prefix: &str,
    h5: &dyn Fn(hdf5_reader::error::Error) -> crate::error::Error,
) -> Result<Vec<Group>> {
    let mut found: Vec<Group> = group
        .groups()
        .map_err(h5)?
        .into_iter()
        .filter(|g| g.name().starts_with(prefix))
        .collect();
    found.sort_by(|a, b| a.name().cmp(b.name()));
    Ok(found)
}

/// The scan grid a measurement group states.
fn grid(path: &Path, attrs: &[Attribute]) -> Result<Grid> {
    let need = |key: &str| {
        number(attrs, key).ok_or_else(|| bad(path, format!("JPK measurement has no '{key}'")))
    };
    let nx = count(
        path,
        "JPK grid ilength",
        need("position-pattern.grid.ilength")?,
    )?;
    let ny = count(
        path,
        "JPK grid jlength",
        need("position-pattern.grid.jlength")?,
    )?;
    let unit = text(attrs, "position-pattern.grid.unit.unit").unwrap_or_else(|| "m".into());
    let factor = length_factor(&unit)
        .ok_or_else(|| bad(path, format!("JPK scan grid in '{unit}', not a length")))?;
    let length = |key: &str| -> Result<f64> {
        Ok(positive(path, &format!("JPK '{key}'"), need(key)?)? * factor)
    };
    Ok(Grid {
        nx,
        ny,
        dx_m: length("position-pattern.grid.ulength")? / nx as f64,
        dy_m: length("position-pattern.grid.vlength")? / ny as f64,
    })
}

fn find<'a>(attrs: &'a [Attribute], key: &str) -> Option<&'a Attribute> {
    attrs.iter().find(|a| a.name == key)
}

/// A text attribute, without the NULs that pad fixed-length strings.
fn text(attrs: &[Attribute], key: &str) -> Option<String> {
    let s = find(attrs, key)?.read_string().ok()?;
    Some(s.trim_end_matches('\0').trim().to_string())
}

/// A number attribute (or a text attribute holding one).
fn number(attrs: &[Attribute], key: &str) -> Option<f64> {
    let a = find(attrs, key)?;
    a.read_as_f64()
        .ok()
        .or_else(|| a.read_string().ok()?.trim().parse().ok())
}
