//! NetCDF `.nc` height maps as SurfaceTopography and contact.engineering write them, in the
//! classic formats of Unidata's *NetCDF Classic Format Specification*: `CDF\x01` (classic),
//! `CDF\x02` (64-bit offset) and `CDF\x05` (64-bit data). (NetCDF-4 files are HDF5 files, read
//! by [`super::hdf5`] through the same layout rules.)
//!
//! A classic file is a big-endian header (the magic, the record count, then the lists of
//! dimensions, global attributes and variables; each variable with its dimension ids,
//! attributes, type, size and the offset of its data) followed by the data. Names and attribute
//! values are padded to 4 bytes; counts and sizes are 4 bytes (8 in `CDF\x05`), data offsets 4
//! bytes in `CDF\x01` and 8 otherwise. Variables along the unlimited (record) dimension are not
//! read.
//!
//! The layout read: a variable `heights` of two dimensions named `x` and `y` (`heights(x, y)`,
//! x the first index, as SurfaceTopography writes it; `heights(y, x)` is read as such), the
//! coordinate variables `x` and `y` whose attribute `length` is the map's size along that axis,
//! and an attribute `unit` (or `units`) on `heights` and on `x`/`y`: the unit of the heights is
//! that of `heights`, else that of `x`; the unit of each length that of its variable, else that
//! of `heights`. Without a `length` on both `x` and `y` the file states no pixel size (NaN, see
//! [`read_height_map`](super::read_height_map)). `scale_factor` and `add_offset` on `heights`
//! are applied; a value equal to its `_FillValue` or `missing_value`, or where a variable `mask`
//! of the same shape is non-zero, is an invalid point. A `heights` of one dimension is a line
//! scan and refused as such.

use std::path::Path;

use super::{
    choose, grid_bytes, height_map, length_factor, line_scan, ChannelEntry, HeightMap,
    TopographyFormat,
};
use crate::binary::{bad, decode_values, slice, unsupported, Reader};
use crate::error::Result;

/// Whether `head` starts with a classic NetCDF magic number.
pub(crate) fn is_netcdf(head: &[u8]) -> bool {
    head.len() >= 4 && head.starts_with(b"CDF") && matches!(head[3], 1 | 2 | 5)
}

/// An attribute's value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Attr {
    /// A character attribute.
    Text(String),
    /// A numeric attribute (every element).
    Numbers(Vec<f64>),
}

/// A variable's name, dimensions (name, length) and attributes.
#[derive(Debug, Clone)]
pub(crate) struct Variable {
    pub name: String,
    pub dims: Vec<(String, usize)>,
    pub attrs: Vec<(String, Attr)>,
}

impl Variable {
    fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|(n, _)| n == name).map(|(_, a)| a)
    }

    fn number(&self, name: &str) -> Option<f64> {
        match self.attr(name)? {
            Attr::Numbers(v) => v.first().copied(),
            Attr::Text(t) => t.trim().parse().ok(),
        }
    }

    fn unit(&self) -> Option<&str> {
        ["unit", "units"].iter().find_map(|k| match self.attr(k)? {
            Attr::Text(t) if !t.trim().is_empty() => Some(t.trim()),
            _ => None,
        })
    }
}

/// How the stored heights become a [`HeightMap`]: grid, pixel size, scaling, invalid values.
#[derive(Debug)]
pub(crate) struct Layout {
    pub nx: usize,
    pub ny: usize,
    /// Stored with x as the first index (to be transposed to rows of y).
    transposed: bool,
    dx_m: f64,
    dy_m: f64,
    /// Metres per stored height unit.
    unit_m: f64,
    scale_factor: f64,
    add_offset: f64,
    fill: Vec<f64>,
    channels: Vec<ChannelEntry>,
    index: usize,
}

/// The layout of the variables of a file (module docs).
pub(crate) fn layout(path: &Path, vars: &[Variable], channel: Option<&str>) -> Result<Layout> {
    let find = |name: &str| vars.iter().find(|v| v.name == name);
    let heights = find("heights").ok_or_else(|| {
        let names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
        bad(
            path,
            format!(
                "the NetCDF file has no variable 'heights' (it has {})",
                names.join(", ")
            ),
        )
    })?;
    let channels = vec![ChannelEntry {
        name: heights.name.clone(),
        height: true,
    }];
    let index = choose(path, &channels, channel)?;
    let x = find("x");
    let y = find("y");
    let height_unit = heights
        .unit()
        .or(x.and_then(Variable::unit))
        .ok_or_else(|| {
            bad(
            path,
            "the NetCDF file states no unit for its heights (attribute 'unit' of 'heights' or 'x')",
        )
        })?;
    let factor = |u: &str| {
        length_factor(u).ok_or_else(|| bad(path, format!("NetCDF unit '{u}' is not a length")))
    };
    let unit_m = factor(height_unit)?;
    let size = |v: Option<&Variable>, n: usize| -> Result<Option<f64>> {
        let Some(v) = v else { return Ok(None) };
        let Some(length) = v.number("length") else {
            return Ok(None);
        };
        let d = length * factor(v.unit().unwrap_or(height_unit))? / n as f64;
        if d.is_finite() && d > 0.0 {
            Ok(Some(d))
        } else {
            Err(bad(
                path,
                format!("NetCDF length of '{}' is {length}", v.name),
            ))
        }
    };
    let (transposed, nx, ny) = match heights.dims.as_slice() {
        [(_, n)] => return Err(line_scan(path, *n, size(x, *n)?)),
        [(a, n0), (b, n1)] => {
            let y_first = a == "y" || b == "x";
            if y_first {
                (false, *n1, *n0)
            } else {
                (true, *n0, *n1)
            }
        }
        dims => {
            return Err(unsupported(
                path,
                format!("NetCDF 'heights' of {} dimensions", dims.len()),
            ))
        }
    };
    if nx == 0 || ny == 0 {
        return Err(unsupported(
            path,
            "NetCDF 'heights' along the unlimited (record) dimension or empty",
        ));
    }
    let (dx_m, dy_m) = match (size(x, nx)?, size(y, ny)?) {
        (Some(dx), Some(dy)) => (dx, dy),
        _ => (f64::NAN, f64::NAN),
    };
    let fill = ["_FillValue", "missing_value"]
        .iter()
        .filter_map(|k| heights.number(k))
        .collect();
    Ok(Layout {
        nx,
        ny,
        transposed,
        dx_m,
        dy_m,
        unit_m,
        scale_factor: heights.number("scale_factor").unwrap_or(1.0),
        add_offset: heights.number("add_offset").unwrap_or(0.0),
        fill,
        channels,
        index,
    })
}

impl Layout {
    /// The map of `stored` heights (`nx · ny` in the file's order) and an optional mask of the
    /// same shape (non-zero: invalid).
    pub(crate) fn height_map(
        &self,
        path: &Path,
        stored: &[f64],
        mask: Option<&[f64]>,
    ) -> Result<HeightMap> {
        let n = self.nx * self.ny;
        if stored.len() != n || mask.is_some_and(|m| m.len() != n) {
            return Err(bad(
                path,
                format!("NetCDF data do not fill a {}×{} grid", self.nx, self.ny),
            ));
        }
        let to_m = super::to_metres(self.unit_m);
        let mut heights = vec![f64::NAN; n];
        for (k, &v) in stored.iter().enumerate() {
            let masked = mask.is_some_and(|m| m.get(k).is_some_and(|&f| f != 0.0));
            if masked || self.fill.contains(&v) {
                continue;
            }
            let h = to_m(v * self.scale_factor + self.add_offset);
            // Stored (x, y): element k is x = k / ny, y = k % ny.
            let at = if self.transposed {
                (k % self.ny) * self.nx + k / self.ny
            } else {
                k
            };
            if let Some(slot) = heights.get_mut(at) {
                *slot = h;
            }
        }
        height_map(
            path,
            TopographyFormat::NetCdf,
            (&self.channels, self.index),
            (self.ny, self.nx),
            heights,
            (self.dx_m, self.dy_m),
        )
    }
}

/// A variable of a classic file: its description, type and data offset.
struct Stored {
    var: Variable,
    nc_type: u32,
    begin: usize,
}

/// Bytes of one value of a NetCDF type, whether it is a float and whether signed.
fn type_info(nc_type: u32) -> Option<(usize, bool, bool)> {
    Some(match nc_type {
        1 => (1, false, true),  // byte
        2 => (1, false, false), // char
        3 => (2, false, true),  // short
        4 => (4, false, true),  // int
        5 => (4, true, true),   // float
        6 => (8, true, true),   // double
        7 => (1, false, false), // ubyte
        8 => (2, false, false), // ushort
        9 => (4, false, false), // uint
        10 => (8, false, true), // int64
        11 => (8, false, false),
        _ => return None,
    })
}

/// The header of a classic file, read with bounds checks on every count.
struct Header<'a> {
    r: Reader<'a>,
    path: &'a Path,
    /// `CDF\x05`: 8-byte counts.
    wide: bool,
}

impl Header<'_> {
    /// A count or size (4 bytes, 8 in CDF-5), at most `remaining / min_bytes` elements.
    fn count(&mut self, what: &str, min_bytes: usize) -> Result<usize> {
        let v = if self.wide {
            self.r.u64()?
        } else {
            u64::from(self.r.u32()?)
        };
        let limit = (self.r.remaining() / min_bytes.max(1)) as u64;
        if min_bytes > 0 && v > limit {
            return Err(bad(
                self.path,
                format!("NetCDF header: {what} of {v} does not fit the file"),
            ));
        }
        usize::try_from(v).map_err(|_| bad(self.path, format!("NetCDF {what} of {v}")))
    }

    /// `n` bytes and the padding to a multiple of 4.
    fn padded(&mut self, n: usize) -> Result<&[u8]> {
        let bytes = self.r.take(n)?;
        self.r.take((4 - n % 4) % 4)?;
        Ok(bytes)
    }

    fn name(&mut self) -> Result<String> {
        let n = self.count("name length", 1)?;
        Ok(String::from_utf8_lossy(self.padded(n)?).into_owned())
    }

    /// A list's tag and element count; `None` for an absent list.
    fn list(&mut self, tag: u32, what: &str) -> Result<usize> {
        let t = self.r.u32()?;
        let n = self.count(what, 4)?;
        if t == tag || (t == 0 && n == 0) {
            Ok(n)
        } else {
            Err(bad(self.path, format!("NetCDF header: bad {what} tag {t}")))
        }
    }

    fn attributes(&mut self) -> Result<Vec<(String, Attr)>> {
        let n = self.list(0x0C, "attribute list")?;
        let mut attrs = Vec::with_capacity(n);
        for _ in 0..n {
            let name = self.name()?;
            let nc_type = self.r.u32()?;
            let (width, float, signed) = type_info(nc_type).ok_or_else(|| {
                bad(
                    self.path,
                    format!("NetCDF attribute '{name}' of type {nc_type}"),
                )
            })?;
            let count = self.count("attribute length", width)?;
            let bytes = self.padded(count * width)?;
            let value = if nc_type == 2 {
                Attr::Text(
                    String::from_utf8_lossy(bytes)
                        .trim_end_matches('\0')
                        .to_string(),
                )
            } else {
                Attr::Numbers(decode_values(bytes, width, float, signed, true))
            };
            attrs.push((name, value));
        }
        Ok(attrs)
    }
}

/// The variables of a classic NetCDF file.
fn variables(path: &Path, data: &[u8]) -> Result<Vec<Stored>> {
    if !is_netcdf(data) {
        return Err(bad(path, "not a classic NetCDF file (no CDF magic)"));
    }
    let version = data[3];
    let mut h = Header {
        r: Reader::new(path, data, 4).big_endian(true),
        path,
        wide: version == 5,
    };
    let _records = h.count("record count", 0)?;
    let ndims = h.list(0x0A, "dimension list")?;
    let mut dims = Vec::with_capacity(ndims);
    for _ in 0..ndims {
        let name = h.name()?;
        let len = h.count("dimension length", 0)?;
        dims.push((name, len));
    }
    h.attributes()?;
    let nvars = h.list(0x0B, "variable list")?;
    let mut vars = Vec::with_capacity(nvars);
    for _ in 0..nvars {
        let name = h.name()?;
        let rank = h.count("variable rank", 4)?;
        let mut var_dims = Vec::with_capacity(rank);
        for _ in 0..rank {
            let id = h.count("dimension id", 0)?;
            let dim = dims
                .get(id)
                .cloned()
                .ok_or_else(|| bad(path, format!("NetCDF variable '{name}': no dimension {id}")))?;
            var_dims.push(dim);
        }
        let attrs = h.attributes()?;
        let nc_type = h.r.u32()?;
        let _vsize = h.count("variable size", 0)?;
        let begin = if version == 1 {
            h.r.usize_u32()?
        } else {
            h.r.usize_u64()?
        };
        // Every fixed-size variable's data must lie in the file: a file cut short is refused
        // even where the part lost is not read.
        let (width, _, _) = type_info(nc_type)
            .ok_or_else(|| bad(path, format!("NetCDF variable '{name}' of type {nc_type}")))?;
        let fixed = var_dims.first().is_none_or(|d| d.1 > 0);
        let bytes = var_dims
            .iter()
            .try_fold(width, |acc, d| acc.checked_mul(d.1))
            .and_then(|b| b.checked_add(begin));
        if fixed && bytes.is_none_or(|end| end > data.len()) {
            return Err(bad(
                path,
                format!(
                    "file is truncated: NetCDF variable '{name}' needs data up to byte {}, the \
                     file has {}",
                    bytes.map_or("beyond 2^64".into(), |b| b.to_string()),
                    data.len()
                ),
            ));
        }
        vars.push(Stored {
            var: Variable {
                name,
                dims: var_dims,
                attrs,
            },
            nc_type,
            begin,
        });
    }
    Ok(vars)
}

/// The values of a variable as f64 (checked against the size limit and the file).
fn values(path: &Path, data: &[u8], s: &Stored) -> Result<Vec<f64>> {
    let (width, float, signed) =
        type_info(s.nc_type)
            .filter(|_| s.nc_type != 2)
            .ok_or_else(|| {
                bad(
                    path,
                    format!("NetCDF variable '{}' of type {}", s.var.name, s.nc_type),
                )
            })?;
    let (rows, cols) = match s.var.dims.as_slice() {
        [(_, a), (_, b)] => (*a, *b),
        [(_, a)] => (1, *a),
        _ => return Err(bad(path, format!("NetCDF variable '{}'", s.var.name))),
    };
    if rows == 0 || cols == 0 {
        return Err(unsupported(
            path,
            format!(
                "NetCDF variable '{}' along the record dimension",
                s.var.name
            ),
        ));
    }
    let bytes = grid_bytes(path, cols, rows, width)?;
    let raw = slice(path, data, s.begin, bytes, "NetCDF variable data")?;
    Ok(decode_values(raw, width, float, signed, true))
}

/// Read the `heights` of a classic NetCDF file.
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let stored = variables(path, data)?;
    let vars: Vec<Variable> = stored.iter().map(|s| s.var.clone()).collect();
    let layout = layout(path, &vars, channel)?;
    let find = |name: &str| stored.iter().find(|s| s.var.name == name);
    let heights = find("heights").ok_or_else(|| bad(path, "no 'heights'"))?;
    let values_h = values(path, data, heights)?;
    let mask = match find("mask") {
        Some(m)
            if m.var
                .dims
                .iter()
                .map(|d| d.1)
                .eq(heights.var.dims.iter().map(|d| d.1)) =>
        {
            Some(values(path, data, m)?)
        }
        _ => None,
    };
    layout.height_map(path, &values_h, mask.as_deref())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_support::{
        assert_close, assert_stats, truncations_and_corruptions,
    };

    /// A file of format `version` (1, 2 or 5): dims x = `nx`, y = `ny`; `heights(x, y)`
    /// doubles in nm, `x` and `y` with `length` attributes, and `heights:_FillValue = -1`.
    fn synthetic(version: u8, nx: usize, ny: usize, heights: &[f64]) -> Vec<u8> {
        let count = |out: &mut Vec<u8>, n: usize| {
            if version == 5 {
                out.extend((n as u64).to_be_bytes());
            } else {
                out.extend((n as u32).to_be_bytes());
            }
        };
        let name = |out: &mut Vec<u8>, s: &str| {
            count(out, s.len());
            out.extend(s.as_bytes());
            out.resize(out.len().next_multiple_of(4), 0);
        };
        let mut h = vec![b'C', b'D', b'F', version];
        count(&mut h, 0);
        h.extend(0x0Au32.to_be_bytes());
        count(&mut h, 2);
        name(&mut h, "x");
        count(&mut h, nx);
        name(&mut h, "y");
        count(&mut h, ny);
        h.extend(0u32.to_be_bytes()); // no global attributes
        count(&mut h, 0);
        h.extend(0x0Bu32.to_be_bytes());
        count(&mut h, 3);
        let mut offsets = Vec::new();
        for (var, dims, len, length) in [
            ("heights", vec![0, 1], nx * ny, None),
            ("x", vec![0], nx, Some(2.0 * nx as f64)),
            ("y", vec![1], ny, Some(3.0 * ny as f64)),
        ] {
            name(&mut h, var);
            count(&mut h, dims.len());
            for d in dims {
                count(&mut h, d);
            }
            h.extend(0x0Cu32.to_be_bytes());
            count(&mut h, 2);
            name(&mut h, "unit");
            h.extend(2u32.to_be_bytes());
            name(&mut h, "nm");
            name(
                &mut h,
                if length.is_some() {
                    "length"
                } else {
                    "_FillValue"
                },
            );
            h.extend(6u32.to_be_bytes());
            count(&mut h, 1);
            h.extend(length.unwrap_or(-1.0).to_be_bytes());
            h.extend(6u32.to_be_bytes());
            count(&mut h, len * 8);
            offsets.push((h.len(), len));
            h.extend(if version == 1 {
                &[0u8; 4][..]
            } else {
                &[0u8; 8][..]
            });
        }
        let mut body = Vec::new();
        let start = h.len();
        for (k, (at, len)) in offsets.iter().enumerate() {
            let begin = start + body.len();
            if version == 1 {
                h[*at..*at + 4].copy_from_slice(&(begin as u32).to_be_bytes());
            } else {
                h[*at..*at + 8].copy_from_slice(&(begin as u64).to_be_bytes());
            }
            let values: Vec<f64> = if k == 0 {
                heights.to_vec()
            } else {
                (0..*len).map(|i| i as f64).collect()
            };
            for v in values {
                body.extend(v.to_be_bytes());
            }
        }
        h.extend(body);
        h
    }

    #[test]
    fn synthetic_file_reads_back() {
        let p = Path::new("s.nc");
        // heights(x, y) with x = 2, y = 3: x·10 + y, and one fill value.
        let stored = [0.0, 1.0, 2.0, 10.0, -1.0, 12.0];
        for version in [1, 5] {
            let m = read(p, &synthetic(version, 2, 3, &stored), None).unwrap();
            assert_eq!((m.heights[[0, 1]], m.invalid_points), (10e-9, 1));
        }
        let data = synthetic(2, 2, 3, &stored);
        let m = read(p, &data, None).unwrap();
        assert_eq!((m.ny(), m.nx(), m.invalid_points), (3, 2, 1));
        assert_eq!(m.heights[[0, 1]], 10e-9);
        assert_eq!(m.heights[[2, 0]], 2e-9);
        assert!(m.heights[[1, 1]].is_nan());
        assert_close(m.dx_m, 2e-9);
        assert_close(m.dy_m, 3e-9);
        assert_eq!(
            (m.channel.as_str(), m.format),
            ("heights", TopographyFormat::NetCdf)
        );
        for cut in [0, 3, 8, 40, 100, data.len() - 1] {
            let err = read(p, &data[..cut], None).unwrap_err().to_string();
            assert!(err.contains("s.nc"), "{err}");
        }
        assert!(is_netcdf(b"CDF\x01") && !is_netcdf(b"CDF\x03") && !is_netcdf(b"CD"));
    }

    #[test]
    fn netcdf4_and_other_classic_variants_read_as_the_original() {
        // Written from nc-1.nc by netCDF4-python (formats NETCDF4, NETCDF4_CLASSIC,
        // NETCDF3_CLASSIC, NETCDF3_64BIT_DATA) when present.
        for name in ["h2-nc4.nc", "h2-nc4c.nc", "h2-nc3c.nc", "h2-nc5.nc"] {
            let path = std::path::PathBuf::from("/tmp").join(name);
            if !path.exists() {
                continue;
            }
            let m = crate::topography::read(&path, None).unwrap();
            assert_eq!(m.format, TopographyFormat::NetCdf, "{name}");
            assert_eq!((m.nx(), m.ny(), m.valid_points()), (5, 10, 50), "{name}");
            assert_close(m.dx_m, 1e-09);
            assert_close(m.dy_m, 1e-09);
            assert_eq!(m.heights[[0, 0]], 9e-9, "{name}");
            assert_eq!(m.heights[[9, 4]], -9e-9, "{name}");
        }
    }

    #[test]
    fn real_file_matches_surface_topography() {
        let path = &crate::topography::test_support::sample("nc-1.nc");
        let Ok(data) = std::fs::read(path) else {
            return;
        };
        assert_eq!(
            crate::topography::detect(&data),
            Some(TopographyFormat::NetCdf)
        );
        let m = read(path, &data, None).unwrap();
        // SurfaceTopography 1.27.1: nx 5, ny 10, dx = dy = 1 nm, 50 valid points.
        assert_eq!((m.nx(), m.ny(), m.valid_points()), (5, 10, 50));
        assert_close(m.dx_m, 1e-09);
        assert_close(m.dy_m, 1e-09);
        assert_stats(
            &m.heights,
            [
                -9.000000000000001e-09,
                9.000000000000001e-09,
                6.617444900424222e-26,
                5.744562646538029e-09,
            ],
        );
        truncations_and_corruptions(path, &data, |d| read(path, d, None).map(|_| ()));
    }
}
