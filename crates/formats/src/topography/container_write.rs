//! Writing contact.engineering surface containers ([`super::container`] reads them) in the
//! layout SurfaceTopography's `write_containers` produces: a ZIP archive with one NetCDF file
//! per topography (`topography0.nc`, `topography1.nc`, …, [`super::netcdf_write`]) named as
//! the `squeezed-netcdf` data file (so that no processing is applied when it is read back),
//! the metadata twice with the same content (`index.json`, and `meta.yml` for YAML-only
//! readers), and a `README.txt`.
//!
//! Each topography's metadata carries its name, data file, `size` (x, y) and `unit` (`m`),
//! `is_periodic`, and the schema's defaults written out (`data_source` 0,
//! `fill_undefined_data_mode` `do-not-fill`, `detrend_mode` `center`, …).

use std::io::Write;

use ndarray::Array2;
use serde_json::{json, Value};

use super::netcdf_write::{height_map_netcdf, write_netcdf};
use crate::error::{Error, Result};

/// One topography to write.
#[derive(Debug, Clone)]
pub struct OutTopography<'a> {
    /// Its name in the metadata.
    pub name: String,
    /// Heights, m, rows = y (NaN: undefined).
    pub heights: &'a Array2<f64>,
    /// Pixel size (x, y), m.
    pub pixel_size_m: (f64, f64),
    /// Periodic.
    pub periodic: bool,
    /// What the topography's NetCDF file records of it (its `json` attribute).
    pub info: Value,
}

/// One surface to write.
#[derive(Debug, Clone)]
pub struct OutSurface<'a> {
    /// Its name.
    pub name: String,
    /// Its description.
    pub description: String,
    /// Its topographies.
    pub topographies: Vec<OutTopography<'a>>,
}

/// A container being written: each topography's NetCDF file goes to a temporary folder as it
/// is added (so that a long series is not held in memory), the archive is put together by
/// [`ContainerBuilder::write_to`].
pub struct ContainerBuilder {
    dir: tempfile::TempDir,
    files: Vec<String>,
    surfaces: Vec<Value>,
}

fn fail(what: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("surface container: {what}"))
}

impl ContainerBuilder {
    /// An empty container.
    pub fn new() -> Result<Self> {
        Ok(ContainerBuilder {
            dir: tempfile::tempdir().map_err(fail)?,
            files: Vec::new(),
            surfaces: Vec::new(),
        })
    }

    /// Start a surface; the topographies added next belong to it.
    pub fn surface(&mut self, name: &str, description: &str) {
        self.surfaces.push(json!({
            "name": name,
            "description": description,
            "tags": [],
            "is_published": false,
            "topographies": [],
        }));
    }

    /// Add a topography to the current surface (a surface named `surface0` is started when
    /// there is none).
    pub fn add(&mut self, t: &OutTopography<'_>) -> Result<()> {
        if self.surfaces.is_empty() {
            self.surface("surface0", "");
        }
        let file = format!("topography{}.nc", self.files.len());
        let (ny, nx) = t.heights.dim();
        let path = self.dir.path().join(&file);
        let info = serde_json::to_string(&t.info).map_err(fail)?;
        write_netcdf(
            &path,
            &height_map_netcdf(t.heights, t.pixel_size_m, t.periodic, Some(&info)),
        )?;
        self.files.push(file.clone());
        let meta = json!({
            "name": t.name,
            "datafile": {"squeezed-netcdf": file},
            "size": [nx as f64 * t.pixel_size_m.0, ny as f64 * t.pixel_size_m.1],
            "unit": "m",
            "data_source": 0,
            "has_undefined_data": t.heights.iter().any(|h| !h.is_finite()),
            "fill_undefined_data_mode": "do-not-fill",
            "detrend_mode": "center",
            "is_periodic": t.periodic,
            "measurement_date": "1970-01-01",
            "description": "",
            "tags": [],
        });
        if let Some(Value::Array(list)) = self
            .surfaces
            .last_mut()
            .and_then(|s| s.get_mut("topographies"))
        {
            list.push(meta);
        }
        Ok(())
    }

    /// Write the archive to `out`. `versions`: the software that made it (name, version),
    /// `created_at`: a timestamp as text, `readme`: the text of `README.txt`.
    pub fn write_to<W: std::io::Write + std::io::Seek>(
        self,
        out: W,
        versions: &[(&str, &str)],
        created_at: &str,
        readme: &str,
    ) -> Result<W> {
        let mut zip = zip::ZipWriter::new(out);
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .large_file(true);
        for file in &self.files {
            let path = self.dir.path().join(file);
            let mut f = std::fs::File::open(&path).map_err(|e| Error::io(&path, e))?;
            zip.start_file(file.as_str(), options).map_err(fail)?;
            std::io::copy(&mut f, &mut zip).map_err(fail)?;
        }
        let versions: serde_json::Map<String, Value> = versions
            .iter()
            .map(|(k, v)| (k.to_string(), Value::String(v.to_string())))
            .collect();
        let meta = json!({
            "versions": versions,
            "surfaces": self.surfaces,
            "created_at": created_at,
        });
        let index = serde_json::to_string_pretty(&meta).map_err(fail)?;
        let yaml = to_yaml(&meta)?;
        for (name, text) in [
            (super::container::INDEX_JSON, index.as_str()),
            (super::container::META_YML, yaml.as_str()),
            ("README.txt", readme),
        ] {
            zip.start_file(name, options).map_err(fail)?;
            zip.write_all(text.as_bytes()).map_err(fail)?;
        }
        zip.finish().map_err(fail)
    }
}

/// The container's bytes, for a few topographies held in memory ([`ContainerBuilder`] for
/// more). `versions`, `created_at`, `readme` as for [`ContainerBuilder::write_to`].
pub fn encode_container(
    surfaces: &[OutSurface<'_>],
    versions: &[(&str, &str)],
    created_at: &str,
    readme: &str,
) -> Result<Vec<u8>> {
    let mut builder = ContainerBuilder::new()?;
    for surface in surfaces {
        builder.surface(&surface.name, &surface.description);
        for t in &surface.topographies {
            builder.add(t)?;
        }
    }
    let cursor = builder.write_to(
        std::io::Cursor::new(Vec::new()),
        versions,
        created_at,
        readme,
    )?;
    Ok(cursor.into_inner())
}

/// A float as YAML text that YAML 1.1 readers (PyYAML, which SurfaceTopography uses) also
/// take for a number: a mantissa with a decimal point and a signed exponent (`1.0e-5`; PyYAML
/// reads `1e-5` as a string).
fn yaml_real(v: f64) -> String {
    let s = format!("{v:e}");
    let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
    let mantissa = if mantissa.contains('.') {
        mantissa.to_string()
    } else {
        format!("{mantissa}.0")
    };
    let exponent = if exponent.starts_with('-') {
        exponent.to_string()
    } else {
        format!("+{exponent}")
    };
    format!("{mantissa}e{exponent}")
}

/// The metadata as block-style YAML.
fn to_yaml(value: &Value) -> Result<String> {
    use yaml_rust2::{yaml::Hash, Yaml, YamlEmitter};
    fn convert(v: &Value) -> Yaml {
        match v {
            Value::Null => Yaml::Null,
            Value::Bool(b) => Yaml::Boolean(*b),
            Value::Number(n) => match n.as_i64() {
                Some(i) => Yaml::Integer(i),
                None => Yaml::Real(yaml_real(n.as_f64().unwrap_or(f64::NAN))),
            },
            Value::String(s) => Yaml::String(s.clone()),
            Value::Array(a) => Yaml::Array(a.iter().map(convert).collect()),
            Value::Object(o) => {
                let mut h = Hash::new();
                for (k, v) in o {
                    h.insert(Yaml::String(k.clone()), convert(v));
                }
                Yaml::Hash(h)
            }
        }
    }
    let mut out = String::new();
    YamlEmitter::new(&mut out)
        .dump(&convert(value))
        .map_err(|e| Error::InvalidArgument(format!("meta.yml: {e}")))?;
    out.push('\n');
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::container::Container;

    #[test]
    fn a_written_container_reads_back_with_both_metadata_files() {
        let dir = tempfile::tempdir().unwrap();
        let a = Array2::from_shape_fn((4, 6), |(i, j)| 1e-9 * (i * 6 + j) as f64);
        let b = Array2::from_shape_fn((5, 5), |(i, j)| -2e-9 * (i + 2 * j) as f64);
        let surfaces = [OutSurface {
            name: "rough".into(),
            description: "test".into(),
            topographies: vec![
                OutTopography {
                    name: "a".into(),
                    heights: &a,
                    pixel_size_m: (1e-7, 2e-7),
                    periodic: true,
                    info: json!({"made_by": "test"}),
                },
                OutTopography {
                    name: "b".into(),
                    heights: &b,
                    pixel_size_m: (5e-8, 5e-8),
                    periodic: false,
                    info: json!({}),
                },
            ],
        }];
        let bytes = encode_container(&surfaces, &[("contactscope", "0")], "now", "hi").unwrap();
        let path = dir.path().join("c.zip");
        std::fs::write(&path, &bytes).unwrap();
        assert!(crate::topography::container::is_container(&path));
        let c = Container::open(&path).unwrap();
        assert_eq!(c.measurements.len(), 2);
        let m = c.read(c.find(Some("rough/a")).unwrap(), None).unwrap();
        assert!(m.periodic() && m.detrend_mode().is_none());
        assert_eq!(m.map.heights, a);
        assert!((m.map.dx_m - 1e-7).abs() < 1e-21 && (m.map.dy_m - 2e-7).abs() < 1e-21);
        let m = c.read(c.find(Some("1")).unwrap(), None).unwrap();
        assert_eq!(m.map.heights, b);
        // The YAML copy says the same: a container with only meta.yml reads alike.
        let only_yaml = dir.path().join("y");
        std::fs::create_dir(&only_yaml).unwrap();
        let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
        zip.extract(&only_yaml).unwrap();
        std::fs::remove_file(only_yaml.join("index.json")).unwrap();
        let y = Container::open(&only_yaml).unwrap();
        assert_eq!(y.measurements, c.measurements);
        assert!(c.find(None).is_err(), "two measurements need a choice");
        assert!(c.find(Some("7")).is_err() && c.find(Some("nope")).is_err());
    }

    #[test]
    fn yaml_reals_have_a_point_and_a_signed_exponent() {
        for (v, text) in [
            (1e-5, "1.0e-5"),
            (6.4e-6, "6.4e-6"),
            (2.0, "2.0e+0"),
            (-3e7, "-3.0e+7"),
        ] {
            assert_eq!(yaml_real(v), text);
            assert_eq!(text.parse::<f64>().unwrap(), v);
        }
    }
}
