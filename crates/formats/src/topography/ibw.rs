//! Igor binary wave, version 5 (Asylum Research AFM images), from WaveMetrics' Technical Note
//! 003 ("Igor Binary Format"). A 64-byte `BinHeader5` (version 5, sizes of the wave record,
//! formula, note, extended units, dimension labels, …) is followed by the 320-byte
//! `WaveHeader5` (point count, data type, dimension sizes `nDim`, deltas `sfA`, units) and the
//! data, dimension 0 fastest (Igor's rows: x along a scan line). Dimension labels (32 bytes
//! each, the first the dimension's own name) follow the formula, note and units; the labels of
//! dimension 2 name the layers (channels: `HeightTrace`, `AmplitudeRetrace`, …). Byte order is
//! the one in which the version reads 5.
//!
//! Heights: the wave's data units (`dataUnits`, or the extended units when longer) must be a
//! length for a layer to count as heights by unit; the layer name (`Height…`) also counts.
//! Pixel size: `sfA[0]`, `sfA[1]` in the dimension units (m for Asylum files).

use std::path::Path;

use super::{
    choose, grid_bytes, height_like, height_map, length_factor, length_scale, ChannelEntry,
    HeightMap, TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

const BIN_HEADER: usize = 64;
const WAVE_HEADER: usize = 320;

/// Whether the first bytes are a version-5 Igor binary wave header.
pub(crate) fn is_ibw(head: &[u8]) -> bool {
    head.len() >= 2 && (head[..2] == [5, 0] || head[..2] == [0, 5])
}

/// Read one layer of an Igor binary wave.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    if !is_ibw(data) {
        return Err(unsupported(path, "Igor binary waves other than version 5"));
    }
    let big = data[0] == 0;
    let mut r = Reader::new(path, data, 2).big_endian(big);
    r.i16()?;
    let wfm_size = r.i32()?.max(0) as usize;
    let formula = r.i32()?.max(0) as usize;
    let note = r.i32()?.max(0) as usize;
    let data_e_units = r.i32()?.max(0) as usize;
    let dim_e_units: Vec<usize> = (0..4)
        .map(|_| Ok(r.i32()?.max(0) as usize))
        .collect::<Result<_>>()?;
    let dim_labels: Vec<usize> = (0..4)
        .map(|_| Ok(r.i32()?.max(0) as usize))
        .collect::<Result<_>>()?;
    let w = BIN_HEADER;
    let mut r = Reader::new(path, data, w + 12).big_endian(big);
    let npnts = r.i32()?.max(0) as usize;
    let kind = r.i16()?;
    let mut r = Reader::new(path, data, w + 68).big_endian(big);
    let n_dim: Vec<usize> = (0..4)
        .map(|_| Ok(r.i32()?.max(0) as usize))
        .collect::<Result<_>>()?;
    let sf_a: Vec<f64> = (0..4).map(|_| r.f64()).collect::<Result<_>>()?;
    let units = |b: &[u8]| {
        String::from_utf8_lossy(b)
            .trim_end_matches('\0')
            .to_string()
    };
    let data_units = units(slice(path, data, w + 148, 4, "data units")?);
    let (width, float, signed) = match kind {
        2 => (4, true, true),
        4 => (8, true, true),
        8 => (1, false, true),
        0x10 => (2, false, true),
        0x20 => (4, false, true),
        0x48 => (1, false, false),
        0x50 => (2, false, false),
        0x60 => (4, false, false),
        k => {
            return Err(unsupported(
                path,
                format!("Igor wave data type {k:#x} (complex or text)"),
            ))
        }
    };
    let (nx, ny) = (n_dim[0], n_dim[1].max(1));
    let layers = n_dim[2].max(1);
    grid_bytes(path, nx, ny, width * layers)?;
    if n_dim[3] > 1 || nx * ny * layers != npnts || wfm_size < WAVE_HEADER + npnts * width {
        return Err(bad(
            path,
            format!("Igor wave of {npnts} points does not match dimensions {n_dim:?}"),
        ));
    }
    // Extended units and dimension labels follow the data, formula and note.
    let mut pos = w + wfm_size + formula + note;
    let e_units = units(slice(path, data, pos, data_e_units, "extended data units")?);
    pos += data_e_units + dim_e_units.iter().sum::<usize>();
    pos += dim_labels[0] + dim_labels[1];
    let labels = slice(path, data, pos, dim_labels[2], "layer labels")?;
    let unit = if e_units.is_empty() {
        data_units
    } else {
        e_units
    };
    let length = length_factor(&unit);
    let channels: Vec<ChannelEntry> = (0..layers)
        .map(|k| {
            let name = labels
                .get((k + 1) * 32..(k + 2) * 32)
                .map(|b| {
                    String::from_utf8_lossy(b)
                        .trim_end_matches('\0')
                        .to_string()
                })
                .filter(|s| !s.is_empty())
                .unwrap_or_else(|| format!("layer {k}"));
            let height = height_like(&name) || (layers == 1 && length.is_some());
            ChannelEntry { name, height }
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let scale = length_scale(path, &channels[index], &unit)?;
    let n = nx * ny;
    let raw = slice(
        path,
        data,
        w + WAVE_HEADER + index * n * width,
        n * width,
        "wave data",
    )?;
    let heights = decode_values(raw, width, float, signed, big)
        .into_iter()
        .map(|v| v * scale)
        .collect();
    let dim_unit = units(slice(path, data, w + 152, 4, "dimension units")?);
    let xy = length_factor(&dim_unit).unwrap_or(1.0);
    height_map(
        path,
        TopographyFormat::Ibw,
        (&channels, index),
        (ny, nx),
        heights,
        (sf_a[0] * xy, sf_a[1] * xy),
    )
}
