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
//! length for a layer to count as heights by unit; the layer name (`Height…`) also counts. A
//! wave without data units (TN003: an empty string means "no units") is taken to hold metres,
//! as a Gwyddion field without `si_unit_z` is. A wave of one layer is read whatever its name
//! (an unlabelled layer is called `layer 0`).
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
    let unit = if !e_units.is_empty() {
        e_units
    } else if data_units.trim().is_empty() {
        "m".to_string()
    } else {
        data_units
    };
    let length = length_factor(&unit);
    let channels: Vec<ChannelEntry> = (0..layers)
        .map(|k| {
            let name = labels
                .get((k + 1) * 32..(k + 2) * 32)
                // A C string: up to its first NUL; a label with control characters (a
                // damaged header) is no name.
                .map(|b| {
                    let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
                    String::from_utf8_lossy(&b[..end]).to_string()
                })
                .filter(|s| !s.is_empty() && !s.chars().any(char::is_control))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A little-endian version-5 wave of float64 values, `layers` layers of 2 × 2, no labels.
    fn wave(unit: &str, layers: usize, values: &[f64]) -> Vec<u8> {
        let npnts = 4 * layers;
        assert_eq!(values.len(), npnts);
        let mut b = vec![0u8; BIN_HEADER + WAVE_HEADER];
        b[0..2].copy_from_slice(&5i16.to_le_bytes());
        let wfm = (WAVE_HEADER + 8 * npnts) as i32;
        b[4..8].copy_from_slice(&wfm.to_le_bytes());
        let w = BIN_HEADER;
        b[w + 12..w + 16].copy_from_slice(&(npnts as i32).to_le_bytes());
        b[w + 16..w + 18].copy_from_slice(&4i16.to_le_bytes());
        let dims = [2i32, 2, if layers > 1 { layers as i32 } else { 0 }, 0];
        for (k, d) in dims.iter().enumerate() {
            b[w + 68 + 4 * k..w + 72 + 4 * k].copy_from_slice(&d.to_le_bytes());
        }
        for k in 0..2 {
            b[w + 84 + 8 * k..w + 92 + 8 * k].copy_from_slice(&1e-6f64.to_le_bytes());
        }
        b[w + 148..w + 148 + unit.len()].copy_from_slice(unit.as_bytes());
        b[w + 152] = b'm';
        for v in values {
            b.extend(v.to_le_bytes());
        }
        b
    }

    #[test]
    fn a_single_unlabelled_layer_is_read_whatever_its_name() {
        let p = Path::new("one.ibw");
        let values = [1e-9, 2e-9, 3e-9, 4e-9];
        let m = read(p, &wave("", 1, &values), None).unwrap();
        assert_eq!(m.channel, "layer 0");
        assert_eq!((m.nx(), m.ny()), (2, 2));
        assert_eq!(m.heights[[1, 0]], 3e-9);
        assert_eq!((m.dx_m, m.dy_m), (1e-6, 1e-6));
        let nm = read(p, &wave("nm", 1, &values), None).unwrap();
        assert!((nm.heights[[0, 1]] - 2e-18).abs() < 1e-30);
        // One layer in volts is no height map, named or not.
        let err = read(p, &wave("V", 1, &values), None)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("one.ibw") && err.contains("'V', not a length"),
            "{err}"
        );
        // Of two unlabelled layers neither is chosen by itself.
        let two = read(p, &wave("", 2, &[0.0; 8]), None)
            .unwrap_err()
            .to_string();
        assert!(
            two.contains("no height channel") && two.contains("'layer 1'"),
            "{two}"
        );
        assert_eq!(
            read(p, &wave("", 2, &[0.0; 8]), Some("layer 1"))
                .unwrap()
                .channel,
            "layer 1"
        );
    }
}
