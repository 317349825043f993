//! Writing NetCDF-3 files (the 64-bit offset format, `CDF\x02`, as SurfaceTopography and
//! contact.engineering write theirs) with the `netcdf3` crate: fixed dimensions, `f64`, `i32`
//! and `i8` variables, and text, `f64` or `i32` attributes on variables and on the file. A NaN
//! attribute is refused: the crate finds a variable again by comparing it whole, and NaN ≠ NaN.
//!
//! [`height_map_netcdf`] lays a height map out as SurfaceTopography's `write_nc_uniform` does
//! (the layout [`super::netcdf`] reads): `heights(x, y)` as `f64` with the attribute `unit`,
//! coordinate variables `x(x)` and `y(y)` holding `i·L/n` with the attributes `length`,
//! `periodic` (0 or 1) and `unit`, and a variable `mask(x, y)` (1 where a height is undefined)
//! when any is.

use std::path::Path;

use ndarray::Array2;
use netcdf3::{DataSet, FileWriter, Version};

use crate::error::{Error, Result};

/// An attribute's value.
#[derive(Debug, Clone, PartialEq)]
pub enum NcAttr {
    /// Text (ASCII; other characters are written as `?`).
    Text(String),
    /// One or more doubles.
    F64(Vec<f64>),
    /// One or more 32-bit integers.
    I32(Vec<i32>),
}

/// A variable's values, in the row-major order of its dimensions.
#[derive(Debug, Clone, PartialEq)]
pub enum NcData {
    /// Doubles.
    F64(Vec<f64>),
    /// 32-bit integers.
    I32(Vec<i32>),
    /// Bytes (NetCDF `byte`).
    I8(Vec<i8>),
}

/// One variable.
#[derive(Debug, Clone, PartialEq)]
pub struct NcVariable {
    /// Its name.
    pub name: String,
    /// Its dimensions' names, slowest first.
    pub dims: Vec<String>,
    /// Its values.
    pub data: NcData,
    /// Its attributes, in order.
    pub attrs: Vec<(String, NcAttr)>,
}

impl NcVariable {
    /// A variable without attributes.
    pub fn new(name: &str, dims: &[&str], data: NcData) -> Self {
        NcVariable {
            name: name.to_string(),
            dims: dims.iter().map(|d| d.to_string()).collect(),
            data,
            attrs: Vec::new(),
        }
    }

    /// With an attribute added.
    pub fn attr(mut self, name: &str, value: NcAttr) -> Self {
        self.attrs.push((name.to_string(), value));
        self
    }
}

/// A whole file: dimensions, global attributes and variables.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NcFile {
    /// Fixed dimensions (name, length).
    pub dims: Vec<(String, usize)>,
    /// Global attributes.
    pub attrs: Vec<(String, NcAttr)>,
    /// Variables.
    pub vars: Vec<NcVariable>,
}

fn ascii(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_ascii() { c } else { '?' })
        .collect()
}

/// Write `file` to `path` (created or overwritten; callers stage it). Every variable's length
/// must be the product of its dimensions'.
pub fn write_netcdf(path: &Path, file: &NcFile) -> Result<()> {
    let fail = |what: String| Error::Output {
        path: path.to_path_buf(),
        reason: what,
    };
    let mut ds = DataSet::new();
    for (name, len) in &file.dims {
        ds.add_fixed_dim(name, *len)
            .map_err(|e| fail(format!("dimension {name}: {e:?}")))?;
    }
    for (name, value) in &file.attrs {
        match value {
            NcAttr::Text(t) => ds.add_global_attr_string(name, ascii(t)),
            NcAttr::F64(v) => ds.add_global_attr_f64(name, v.clone()),
            NcAttr::I32(v) => ds.add_global_attr_i32(name, v.clone()),
        }
        .map_err(|e| fail(format!("attribute {name}: {e:?}")))?;
    }
    let nan = |attrs: &[(String, NcAttr)]| {
        attrs
            .iter()
            .any(|(_, a)| matches!(a, NcAttr::F64(v) if v.iter().any(|x| x.is_nan())))
    };
    if nan(&file.attrs) || file.vars.iter().any(|v| nan(&v.attrs)) {
        return Err(fail("a NaN attribute cannot be written".into()));
    }
    for var in &file.vars {
        let expected: usize = var
            .dims
            .iter()
            .map(|d| {
                file.dims
                    .iter()
                    .find(|(n, _)| n == d)
                    .map(|(_, l)| *l)
                    .unwrap_or(0)
            })
            .product();
        let (len, added) = match &var.data {
            NcData::F64(v) => (v.len(), ds.add_var_f64(&var.name, &var.dims)),
            NcData::I32(v) => (v.len(), ds.add_var_i32(&var.name, &var.dims)),
            NcData::I8(v) => (v.len(), ds.add_var_i8(&var.name, &var.dims)),
        };
        added.map_err(|e| fail(format!("variable {}: {e:?}", var.name)))?;
        if len != expected {
            return Err(fail(format!(
                "variable {} has {len} values for dimensions of {expected}",
                var.name
            )));
        }
        for (name, value) in &var.attrs {
            match value {
                NcAttr::Text(t) => ds.add_var_attr_string(&var.name, name, ascii(t)),
                NcAttr::F64(v) => ds.add_var_attr_f64(&var.name, name, v.clone()),
                NcAttr::I32(v) => ds.add_var_attr_i32(&var.name, name, v.clone()),
            }
            .map_err(|e| fail(format!("attribute {}.{name}: {e:?}", var.name)))?;
        }
    }
    let mut writer = FileWriter::open(path).map_err(|e| fail(format!("{e:?}")))?;
    writer
        .set_def(&ds, Version::Offset64Bit, 0)
        .map_err(|e| fail(format!("{e:?}")))?;
    for var in &file.vars {
        match &var.data {
            NcData::F64(v) => writer.write_var_f64(&var.name, v),
            NcData::I32(v) => writer.write_var_i32(&var.name, v),
            NcData::I8(v) => writer.write_var_i8(&var.name, v),
        }
        .map_err(|e| fail(format!("variable {}: {e:?}", var.name)))?;
    }
    writer.close().map_err(|e| fail(format!("{e:?}")))?;
    Ok(())
}

/// A height map (`heights` in metres, rows = y, NaN = undefined; pixel size `(dx, dy)` in m)
/// as SurfaceTopography's NetCDF layout (module docs), in metres, with `json` (the
/// measurement's info as JSON text) as the global attribute SurfaceTopography reads back.
pub fn height_map_netcdf(
    heights: &Array2<f64>,
    (dx, dy): (f64, f64),
    periodic: bool,
    json: Option<&str>,
) -> NcFile {
    let (ny, nx) = heights.dim();
    // heights(x, y): x the slow index, so the transpose of our (y, x) rows.
    let mut values = Vec::with_capacity(nx * ny);
    let mut mask = Vec::with_capacity(nx * ny);
    for j in 0..nx {
        for i in 0..ny {
            let h = heights[(i, j)];
            values.push(if h.is_finite() { h } else { 0.0 });
            mask.push(i8::from(!h.is_finite()));
        }
    }
    let coordinate = |name: &str, n: usize, step: f64| {
        NcVariable::new(
            name,
            &[name],
            NcData::F64((0..n).map(|k| k as f64 * step).collect()),
        )
        .attr("length", NcAttr::F64(vec![n as f64 * step]))
        .attr("periodic", NcAttr::I32(vec![i32::from(periodic)]))
        .attr("unit", NcAttr::Text("m".into()))
    };
    let mut vars = vec![NcVariable::new("heights", &["x", "y"], NcData::F64(values))
        .attr("unit", NcAttr::Text("m".into()))];
    if mask.iter().any(|&m| m != 0) {
        vars.push(NcVariable::new("mask", &["x", "y"], NcData::I8(mask)));
    }
    vars.push(coordinate("x", nx, dx));
    vars.push(coordinate("y", ny, dy));
    NcFile {
        dims: vec![("x".into(), nx), ("y".into(), ny)],
        attrs: json
            .map(|j| vec![("json".to_string(), NcAttr::Text(j.to_string()))])
            .unwrap_or_default(),
        vars,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::{read_height_map, ReadOptions};

    #[test]
    fn a_height_map_reads_back_through_our_netcdf_reader() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("h.nc");
        let mut h = Array2::from_shape_fn((3, 5), |(i, j)| 1e-9 * (i as f64 * 10.0 + j as f64));
        h[(2, 4)] = f64::NAN;
        write_netcdf(
            &path,
            &height_map_netcdf(&h, (2e-8, 3e-8), true, Some("{}")),
        )
        .unwrap();
        let back = read_height_map(&path, &ReadOptions::default()).unwrap();
        assert_eq!(back.heights.dim(), (3, 5));
        assert_eq!(back.invalid_points, 1);
        for ((i, j), v) in h.indexed_iter() {
            if v.is_finite() {
                assert_eq!(back.heights[(i, j)], *v, "({i}, {j})");
            }
        }
        assert!((back.dx_m - 2e-8).abs() < 1e-20 && (back.dy_m - 3e-8).abs() < 1e-20);
    }

    #[test]
    fn a_wrong_length_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let file = NcFile {
            dims: vec![("n".into(), 3)],
            attrs: vec![],
            vars: vec![NcVariable::new("v", &["n"], NcData::F64(vec![1.0]))],
        };
        let err = write_netcdf(&dir.path().join("v.nc"), &file).unwrap_err();
        assert!(err.to_string().contains("1 values"), "{err}");
    }
}
