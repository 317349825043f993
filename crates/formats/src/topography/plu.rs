//! Sensofar `.plu` (SensoSCAN 2000–2012 layout, little-endian): a 388-byte header (date text,
//! time, comment), the calibration (y size, x size, …, µm per pixel in x and y at bytes 404 and
//! 408), the measurement configuration (type 3 = topography; area type), 40 bytes of scan
//! settings, 12 bytes of further configuration (number of layers at byte 489), then per layer
//! its y and x size (u32) and the heights in µm as float32, rows along x; 1000001 marks
//! invalid points. The format has no magic number: a file is taken as PLU when its sizes
//! account for it (type 3, at least one layer, the first layer's sizes equal the calibration's
//! and its data fit in the file).

use std::path::Path;

use super::{
    choose, count, grid_bytes, height_map, positive, ChannelEntry, HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, FileSource, Reader};
use crate::error::Result;

const CALIBRATION: usize = 388;
const CONFIG2: usize = 488;
const LAYERS: usize = 500;
const UNDEFINED: f64 = 1_000_001.0;

/// The fields of the header that matter.
struct Header {
    /// Calibration grid (y, x).
    grid: (usize, usize),
    /// µm per pixel (x, y).
    um_per_px: (f64, f64),
    /// Measurement type (3 = topography).
    kind: u32,
    /// Number of layers.
    layers: usize,
    /// First layer's grid (y, x).
    first: (usize, usize),
}

/// The header from the first 508 bytes, if they are there.
fn header(path: &Path, head: &[u8]) -> Option<Header> {
    let u32_at = |at: usize| Reader::new(path, head, at).u32().ok().map(|v| v as usize);
    let f32_at = |at: usize| Reader::new(path, head, at).f32().ok().map(f64::from);
    Some(Header {
        grid: (u32_at(CALIBRATION)?, u32_at(CALIBRATION + 4)?),
        um_per_px: (f32_at(CALIBRATION + 16)?, f32_at(CALIBRATION + 20)?),
        kind: u32_at(428)? as u32,
        layers: *head.get(CONFIG2 + 1)? as usize,
        first: (u32_at(LAYERS)?, u32_at(LAYERS + 4)?),
    })
}

/// Whether a file has the PLU layout (module docs).
pub(crate) fn is_plu(source: &mut FileSource) -> Result<bool> {
    let path = source.path.clone();
    let head = source.read_up_to(0, LAYERS + 8)?;
    Ok(match header(&path, &head) {
        Some(h) => {
            let (ny, nx) = h.grid;
            h.kind == 3
                && h.layers >= 1
                && h.first == h.grid
                && nx > 0
                && ny > 0
                && (LAYERS as u64 + 8 + 4 * nx as u64 * ny as u64) <= source.len
        }
        None => false,
    })
}

/// Read the first layer of a PLU file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let h =
        header(path, data).ok_or_else(|| bad(path, "file is truncated: no complete PLU header"))?;
    let (kind, layers, (ly, lx), (px, py)) = (h.kind, h.layers, h.first, h.um_per_px);
    if kind != 3 || layers == 0 {
        return Err(bad(
            path,
            format!("PLU measurement type {kind} with {layers} layers (topography is type 3)"),
        ));
    }
    let (nx, ny) = (
        count(path, "x size", lx as f64)?,
        count(path, "y size", ly as f64)?,
    );
    let bytes = grid_bytes(path, nx, ny, 4)?;
    let channels = [ChannelEntry {
        name: "layer0".into(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let raw = decode_values(
        slice(path, data, LAYERS + 8, bytes, "the PLU heights")?,
        4,
        true,
        true,
        false,
    );
    let heights = raw
        .into_iter()
        .map(|v| if v == UNDEFINED { f64::NAN } else { v * 1e-6 })
        .collect();
    let (dx, dy) = (
        positive(path, "µm per pixel x", px)? * 1e-6,
        positive(path, "µm per pixel y", py)? * 1e-6,
    );
    height_map(
        path,
        TopographyFormat::Plu,
        (&channels, index),
        (ny, nx),
        heights,
        (dx, dy),
    )
}
