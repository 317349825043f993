//! contact.engineering surface containers ("digital surface twins"), as contact.engineering
//! downloads them and SurfaceTopography reads and writes them (`read_container`,
//! `write_containers`).
//!
//! A container is a ZIP archive, or the folder it unpacks to, holding one metadata file and the
//! data files of its measurements:
//!
//! * `index.json` (the container schema of SurfaceTopography ≥ 1.20: `surfaces[]`, each with a
//!   `name` and `topographies[]`), else `meta.yml` (the same structure in YAML, older
//!   downloads). When both are present `index.json` is read.
//! * Each topography names its data file under `datafile`: `original` (the file as uploaded,
//!   any format of [`super::read_height_map`]) is read when present, else `squeezed-netcdf` (a
//!   NetCDF file of the heights after contact.engineering's processing).
//!
//! What a measurement's metadata does, as SurfaceTopography applies it ([`Container::read`]):
//!
//! | key | effect |
//! |---|---|
//! | `size` | the physical size (x, y) in `unit`, used when the data file states no pixel size (a file's own size wins; a difference above 1e-4 relative is noted) |
//! | `unit` | the unit of `size` and of the heights when the data file states none |
//! | `data_source` | SurfaceTopography's index of the data file's channel: 0 (the schema's default) or absent is read as the file's height channel (SurfaceTopography's channel 0 of the formats tested, `.di`, `.ibw`, `.mi`, `.nid`); another index is the channel SurfaceTopography's reader lists at that place (Nanoscope, Igor, PicoView: every channel in file order; Nanosurf: the channels in a length unit), refused for other formats, naming the channels for `--channel` |
//! | `is_periodic` | the measurement is periodic ([`MeasurementMap::periodic`]) |
//! | `height_scale` | heights multiplied by it (original files only) |
//! | `fill_undefined_data_mode` | `do-not-fill`, or `harmonic` (original files only; applied by the caller) |
//! | `detrend_mode` | `center`, `height`, `curvature`, … (original files only; applied by the caller) |
//!
//! A squeezed NetCDF file already holds the processed heights: no scale, filling or detrending
//! is applied to it. In `index.json` an absent `detrend_mode` means `center` and an absent
//! `fill_undefined_data_mode` `do-not-fill` (the schema's defaults); in `meta.yml` an absent key
//! means no such step (as SurfaceTopography reads it).
//!
//! A measurement is chosen by its index over the whole container (0, 1, …, in the order of the
//! metadata), by its name, or as `surface/name` ([`Container::find`]).

use std::io::Read;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::{read_height_map, HeightMap, ReadOptions, MAX_FILE_BYTES};
use crate::binary::bad;
use crate::error::{Error, Location, Result};

/// The container's metadata files.
pub const INDEX_JSON: &str = "index.json";
/// The YAML metadata of older containers.
pub const META_YML: &str = "meta.yml";

/// Whether `path` is a surface container: a ZIP archive with `index.json` or `meta.yml` at its
/// top, or a folder with one of them.
pub fn is_container(path: &Path) -> bool {
    if path.is_dir() {
        return path.join(INDEX_JSON).is_file() || path.join(META_YML).is_file();
    }
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut head = [0u8; 4];
    if (&file).read_exact(&mut head).is_err() || &head != b"PK\x03\x04" {
        return false;
    }
    match zip::ZipArchive::new(file) {
        Ok(z) => z.index_for_name(INDEX_JSON).is_some() || z.index_for_name(META_YML).is_some(),
        Err(_) => false,
    }
}

/// One measurement (topography) of a container, as its metadata describes it.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// Index over the whole container, in the metadata's order.
    pub index: usize,
    /// The surface it belongs to.
    pub surface: String,
    /// Its name (the data file's name when the metadata gives none).
    pub name: String,
    /// The data file inside the container.
    pub datafile: String,
    /// Whether the data file is the squeezed NetCDF (no processing applied to it).
    pub squeezed: bool,
    /// Physical size (x, y) in `unit`.
    pub size: Option<Vec<f64>>,
    /// Lateral and height unit.
    pub unit: Option<String>,
    /// SurfaceTopography's channel index in the data file (only 0, the height channel, is read).
    pub data_source: Option<usize>,
    /// Height multiplier.
    pub height_scale: Option<f64>,
    /// SurfaceTopography's detrend mode to apply.
    pub detrend_mode: Option<String>,
    /// SurfaceTopography's fill mode for undefined data to apply (`do-not-fill` is none).
    pub fill_mode: Option<String>,
    /// Periodic measurement.
    pub periodic: bool,
}

impl Measurement {
    /// `surface/name`, as listings and messages name it.
    pub fn label(&self) -> String {
        format!("{}/{}", self.surface, self.name)
    }
}

/// A measurement read: the height map (heights in metres, scaled; not filled or detrended) and
/// what remains to apply.
#[derive(Debug, Clone)]
pub struct MeasurementMap {
    /// The heights as the data file holds them, in metres, multiplied by `height_scale`.
    pub map: HeightMap,
    /// The measurement.
    pub measurement: Measurement,
    /// Notes for the user (a size that differs from the file's).
    pub notes: Vec<String>,
}

impl MeasurementMap {
    /// Whether the measurement is periodic.
    pub fn periodic(&self) -> bool {
        self.measurement.periodic
    }

    /// The fill mode still to apply (none for `do-not-fill` and squeezed files).
    pub fn fill_mode(&self) -> Option<&str> {
        match self.measurement.fill_mode.as_deref() {
            _ if self.measurement.squeezed => None,
            Some("do-not-fill") | None => None,
            Some(m) => Some(m),
        }
    }

    /// The detrend mode still to apply (none for squeezed files).
    pub fn detrend_mode(&self) -> Option<&str> {
        if self.measurement.squeezed {
            None
        } else {
            self.measurement.detrend_mode.as_deref()
        }
    }
}

/// An opened container: its metadata.
#[derive(Debug, Clone)]
pub struct Container {
    /// The ZIP file or folder.
    pub path: PathBuf,
    /// Every measurement, in the metadata's order.
    pub measurements: Vec<Measurement>,
    /// The surfaces' names, in order.
    pub surfaces: Vec<String>,
    zipped: bool,
}

/// The pixel size a data file is first read with (plausible, and unlikely to be any file's
/// own): replaced by the file's own pixel size when it states one, else by the container's.
const PLACEHOLDER_PIXEL_M: (f64, f64) = (1.234_567_9e-6, 1.234_567_9e-6);

/// The most bytes of a metadata file read.
const MAX_METADATA_BYTES: u64 = 64 << 20;

impl Container {
    /// Open a container and parse its metadata (the data files are read by [`Self::read`]).
    pub fn open(path: &Path) -> Result<Container> {
        crate::inputs::note_input(path);
        let zipped = !path.is_dir();
        let (text, yaml) = if zipped {
            let mut zip = open_zip(path)?;
            if zip.index_for_name(INDEX_JSON).is_some() {
                (
                    read_member(path, &mut zip, INDEX_JSON, MAX_METADATA_BYTES)?,
                    false,
                )
            } else if zip.index_for_name(META_YML).is_some() {
                (
                    read_member(path, &mut zip, META_YML, MAX_METADATA_BYTES)?,
                    true,
                )
            } else {
                return Err(bad(
                    path,
                    "a ZIP archive without index.json or meta.yml: not a contact.engineering \
                     surface container",
                ));
            }
        } else if path.join(INDEX_JSON).is_file() {
            (read_limited(&path.join(INDEX_JSON))?, false)
        } else if path.join(META_YML).is_file() {
            (read_limited(&path.join(META_YML))?, true)
        } else {
            return Err(bad(
                path,
                "a folder without index.json or meta.yml: not a contact.engineering surface \
                 container",
            ));
        };
        let which = if yaml { META_YML } else { INDEX_JSON };
        let text =
            String::from_utf8(text).map_err(|_| bad(path, format!("{which} is not UTF-8 text")))?;
        let meta: Value = if yaml {
            yaml_to_json(path, &text)?
        } else {
            serde_json::from_str(&text)
                .map_err(|e| bad(path, format!("{which} is not valid JSON: {e}")))?
        };
        let (surfaces, measurements) = parse_metadata(path, which, &meta, !yaml)?;
        Ok(Container {
            path: path.to_path_buf(),
            measurements,
            surfaces,
            zipped,
        })
    }

    /// The measurement named by `selector`: its index over the container, its name (unique
    /// within the container), or `surface/name`. Without a selector, the only measurement; a
    /// container of several needs one (the error lists them).
    pub fn find(&self, selector: Option<&str>) -> Result<&Measurement> {
        let listing = || {
            self.measurements
                .iter()
                .map(|m| format!("{} {}", m.index, m.label()))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let Some(selector) = selector.map(str::trim) else {
            return match self.measurements.as_slice() {
                [one] => Ok(one),
                _ => Err(bad(
                    &self.path,
                    format!(
                        "the container holds {} measurements; choose one with {} (index or \
                         name): {}",
                        self.measurements.len(),
                        crate::param::Param::Measurement,
                        listing()
                    ),
                )),
            };
        };
        if let Ok(i) = selector.parse::<usize>() {
            return self.measurements.get(i).ok_or_else(|| {
                bad(
                    &self.path,
                    format!(
                        "no measurement {i}: the container holds {} ({})",
                        self.measurements.len(),
                        listing()
                    ),
                )
            });
        }
        let matches: Vec<&Measurement> = self
            .measurements
            .iter()
            .filter(|m| m.label() == selector || m.name == selector)
            .collect();
        match matches.as_slice() {
            [one] => Ok(one),
            [] => Err(bad(
                &self.path,
                format!(
                    "no measurement named '{selector}'; the container holds {}",
                    listing()
                ),
            )),
            _ => Err(bad(
                &self.path,
                format!(
                    "{} measurements are named '{selector}'; name one as surface/name or by \
                     index: {}",
                    matches.len(),
                    listing()
                ),
            )),
        }
    }

    /// Read a measurement's data file with its metadata applied up to the height scale (module
    /// docs); filling and detrending are left to the caller ([`MeasurementMap::fill_mode`],
    /// [`MeasurementMap::detrend_mode`]). `channel` by name overrides `data_source`.
    pub fn read(&self, m: &Measurement, channel: Option<&str>) -> Result<MeasurementMap> {
        let shown = PathBuf::from(format!("{}:{}", self.path.display(), m.datafile));
        let (_dir, file) = self.extract(m)?;
        let relabel = |e: Error| relabel(e, &file, &shown);
        let unit_m = match &m.unit {
            Some(u) => Some(super::length_factor(u).ok_or_else(|| {
                bad(
                    &self.path,
                    format!("measurement {}: unit '{u}' is not a length unit", m.label()),
                )
            })?),
            None => None,
        };
        // The channel: by name as asked, else the file's height channel; a `data_source` other
        // than 0 names a channel in SurfaceTopography's order ([`surface_topography_channel`]).
        let mut options = ReadOptions {
            // A placeholder: replaced below by the file's own pixel size, or by `size`.
            pixel_size_m: Some(PLACEHOLDER_PIXEL_M),
            height_unit_m: unit_m,
            channel: channel.map(str::to_string),
        };
        let map_read = match (channel, m.data_source) {
            (None, Some(k @ 1..)) => {
                read_data_source(&file, &mut options, (k, &m.label())).map_err(relabel)
            }
            _ => read_with_unit(&file, &mut options).map_err(relabel),
        };
        let mut map = map_read?;
        let mut notes = Vec::new();
        let stated = map.replaced_pixel_size_m.take();
        let from_size = match (&m.size, unit_m) {
            (Some(size), Some(u)) if size.len() == 2 && size.iter().all(|s| *s > 0.0) => {
                Some((size[0] * u / map.nx() as f64, size[1] * u / map.ny() as f64))
            }
            (Some(size), _) if size.len() != 2 => {
                return Err(bad(
                    &self.path,
                    format!(
                        "measurement {}: size has {} value(s); a height map needs two (a line \
                         scan is not read)",
                        m.label(),
                        size.len()
                    ),
                ))
            }
            _ => None,
        };
        match (stated, from_size) {
            (Some(file_px), Some(meta_px)) => {
                if !close(file_px.0, meta_px.0) || !close(file_px.1, meta_px.1) {
                    notes.push(format!(
                        "{}: the data file's pixel size {:.6e} × {:.6e} m differs from the \
                         container's size ({:.6e} × {:.6e} m per pixel); the file's is used",
                        shown.display(),
                        file_px.0,
                        file_px.1,
                        meta_px.0,
                        meta_px.1
                    ));
                }
                (map.dx_m, map.dy_m) = file_px;
            }
            (Some(file_px), None) => (map.dx_m, map.dy_m) = file_px,
            (None, Some(meta_px)) => (map.dx_m, map.dy_m) = meta_px,
            (None, None) => {
                return Err(bad(
                    &shown,
                    format!(
                        "measurement {}: {}",
                        m.label(),
                        if m.size.is_some() {
                            "the data file states no physical size, and the container's size \
                             has no unit"
                        } else {
                            "neither the data file nor the container states the physical size"
                        }
                    ),
                ))
            }
        }
        if let (Some(scale), false) = (m.height_scale, m.squeezed) {
            if !(scale.is_finite() && scale != 0.0) {
                return Err(bad(
                    &self.path,
                    format!(
                        "measurement {}: height_scale {scale} is not usable",
                        m.label()
                    ),
                ));
            }
            map.heights.mapv_inplace(|h| h * scale);
        }
        Ok(MeasurementMap {
            map,
            measurement: m.clone(),
            notes,
        })
    }

    /// The data file as a path: the folder's own file, or a temporary copy of the zipped one
    /// (with the temporary folder that holds it).
    fn extract(&self, m: &Measurement) -> Result<(Option<tempfile::TempDir>, PathBuf)> {
        let inside = safe_member(&self.path, &m.datafile)?;
        if !self.zipped {
            return Ok((None, self.path.join(inside)));
        }
        let mut zip = open_zip(&self.path)?;
        let dir = tempfile::tempdir().map_err(|e| Error::io(&self.path, e))?;
        let name = inside
            .file_name()
            .map(|n| n.to_os_string())
            .unwrap_or_else(|| "data".into());
        let file = dir.path().join(name);
        let mut out = std::fs::File::create(&file).map_err(|e| Error::io(&file, e))?;
        copy_member(&self.path, &mut zip, &m.datafile, MAX_FILE_BYTES, &mut out)?;
        Ok((Some(dir), file))
    }
}

/// Read with the container's unit as the height unit of a file that states none; a file that
/// states its own is read with its own (the container's unit is then dropped, as
/// SurfaceTopography prefers the file's).
fn read_with_unit(file: &Path, options: &mut ReadOptions) -> Result<HeightMap> {
    match read_height_map(file, options) {
        Err(e) if options.height_unit_m.is_some() && e.to_string().contains("height unit") => {
            options.height_unit_m = None;
            read_height_map(file, options)
        }
        other => other,
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-4 * a.abs().max(b.abs())
}

/// Put the container's name for a member in place of its temporary copy's path.
fn relabel(e: Error, temp: &Path, shown: &Path) -> Error {
    let fix = |at: Location| {
        if at.path == temp {
            Location {
                path: shown.to_path_buf(),
                page: at.page,
            }
        } else {
            at
        }
    };
    match e {
        Error::Io { at, source } => Error::Io {
            at: fix(at),
            source,
        },
        Error::BadTiff { at, reason } => Error::BadTiff {
            at: fix(at),
            reason,
        },
        Error::Unsupported { at, reason } => Error::Unsupported {
            at: fix(at),
            reason,
        },
        Error::BadInput { at, reason } => Error::BadInput {
            at: fix(at),
            reason,
        },
        other => other,
    }
}

fn open_zip(path: &Path) -> Result<zip::ZipArchive<std::fs::File>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    zip::ZipArchive::new(file).map_err(|e| bad(path, format!("not a readable ZIP archive: {e}")))
}

/// Copy a member to `out`, refused above `limit` bytes (the size the archive states, then the
/// bytes decompressed: a forged size cannot make it read more); returns the bytes copied.
fn copy_member(
    path: &Path,
    zip: &mut zip::ZipArchive<std::fs::File>,
    name: &str,
    limit: u64,
    out: &mut dyn std::io::Write,
) -> Result<u64> {
    let mut member = zip
        .by_name(name)
        .map_err(|e| bad(path, format!("member '{name}': {e}")))?;
    if member.size() > limit {
        return Err(bad(
            path,
            format!(
                "member '{name}' states {} bytes, more than the {limit} read",
                member.size()
            ),
        ));
    }
    let copied = std::io::copy(&mut (&mut member).take(limit + 1), out)
        .map_err(|e| bad(path, format!("member '{name}' does not decompress: {e}")))?;
    if copied > limit {
        return Err(bad(path, format!("member '{name}' exceeds {limit} bytes")));
    }
    Ok(copied)
}

/// A member's bytes, refused above `limit` ([`copy_member`]).
fn read_member(
    path: &Path,
    zip: &mut zip::ZipArchive<std::fs::File>,
    name: &str,
    limit: u64,
) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    copy_member(path, zip, name, limit, &mut bytes)?;
    Ok(bytes)
}

fn read_limited(path: &Path) -> Result<Vec<u8>> {
    let len = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    if len > MAX_METADATA_BYTES {
        return Err(bad(
            path,
            format!("{len} bytes: too large for container metadata"),
        ));
    }
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// A member's path inside the container, refused when it would leave it (absolute, `..`).
fn safe_member(container: &Path, name: &str) -> Result<PathBuf> {
    let p = Path::new(name);
    let ok = !name.is_empty()
        && p.components().all(|c| {
            matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::CurDir
            )
        });
    if ok {
        Ok(p.to_path_buf())
    } else {
        Err(bad(
            container,
            format!("data file '{name}' points outside the container"),
        ))
    }
}

/// The surfaces' names and every measurement from the metadata. `schema_defaults`: apply the
/// `index.json` schema's defaults (module docs).
fn parse_metadata(
    path: &Path,
    which: &str,
    meta: &Value,
    schema_defaults: bool,
) -> Result<(Vec<String>, Vec<Measurement>)> {
    let fail = |what: String| bad(path, format!("{which}: {what}"));
    let surfaces = meta
        .get("surfaces")
        .and_then(Value::as_array)
        .ok_or_else(|| fail("no list 'surfaces'".into()))?;
    let mut names = Vec::new();
    let mut measurements = Vec::new();
    for (s, surface) in surfaces.iter().enumerate() {
        let surface_name = surface
            .get("name")
            .and_then(Value::as_str)
            .map(str::to_string)
            .unwrap_or_else(|| format!("surface{s}"));
        let topographies = match surface.get("topographies") {
            None | Some(Value::Null) => &Vec::new(),
            Some(Value::Array(t)) => t,
            Some(_) => {
                return Err(fail(format!(
                    "surface '{surface_name}': 'topographies' is not a list"
                )))
            }
        };
        for (t, topo) in topographies.iter().enumerate() {
            let at = format!("surface '{surface_name}', topography {t}");
            let files = topo
                .get("datafile")
                .ok_or_else(|| fail(format!("{at}: no 'datafile'")))?;
            let (datafile, squeezed) = match (
                files.get("original").and_then(Value::as_str),
                files.get("squeezed-netcdf").and_then(Value::as_str),
            ) {
                (Some(o), _) => (o.to_string(), false),
                (None, Some(s)) => (s.to_string(), true),
                (None, None) => {
                    return Err(fail(format!(
                        "{at}: neither an 'original' nor a 'squeezed-netcdf' data file"
                    )))
                }
            };
            let number = |key: &str| -> Result<Option<f64>> {
                match topo.get(key) {
                    None | Some(Value::Null) => Ok(None),
                    Some(v) => v
                        .as_f64()
                        .map(Some)
                        .ok_or_else(|| fail(format!("{at}: '{key}' is not a number"))),
                }
            };
            let text = |key: &str| topo.get(key).and_then(Value::as_str).map(str::to_string);
            let size = match topo.get("size") {
                None | Some(Value::Null) => None,
                Some(Value::Array(v)) => Some(
                    v.iter()
                        .map(|x| x.as_f64().ok_or_else(|| fail(format!("{at}: bad 'size'"))))
                        .collect::<Result<Vec<f64>>>()?,
                ),
                Some(_) => return Err(fail(format!("{at}: 'size' is not a list"))),
            };
            let data_source = match number("data_source")? {
                None => None,
                Some(k) if k >= 0.0 && k.fract() == 0.0 && k < 1e6 => Some(k as usize),
                Some(k) => return Err(fail(format!("{at}: data_source {k} is not an index"))),
            };
            let default =
                |v: Option<String>, d: &str| v.or_else(|| schema_defaults.then(|| d.to_string()));
            measurements.push(Measurement {
                index: measurements.len(),
                surface: surface_name.clone(),
                name: text("name").unwrap_or_else(|| {
                    Path::new(&datafile)
                        .file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_else(|| datafile.clone())
                }),
                datafile,
                squeezed,
                size,
                unit: text("unit"),
                data_source,
                height_scale: number("height_scale")?,
                detrend_mode: default(text("detrend_mode"), "center"),
                fill_mode: default(text("fill_undefined_data_mode"), "do-not-fill"),
                periodic: topo
                    .get("is_periodic")
                    .and_then(Value::as_bool)
                    .unwrap_or(false),
            });
        }
        names.push(surface_name);
    }
    Ok((names, measurements))
}

/// `meta.yml` as JSON: mappings, sequences, strings, numbers, booleans and nulls (tags such
/// as `!!python/tuple` are read as what they tag).
fn yaml_to_json(path: &Path, text: &str) -> Result<Value> {
    use yaml_rust2::{Yaml, YamlLoader};
    let docs = YamlLoader::load_from_str(text)
        .map_err(|e| bad(path, format!("meta.yml is not valid YAML: {e}")))?;
    fn convert(y: &Yaml) -> Value {
        match y {
            Yaml::Real(r) => r
                .parse::<f64>()
                .ok()
                .and_then(serde_json::Number::from_f64)
                .map(Value::Number)
                .unwrap_or(Value::Null),
            Yaml::Integer(i) => Value::from(*i),
            Yaml::String(s) => Value::String(s.clone()),
            Yaml::Boolean(b) => Value::Bool(*b),
            Yaml::Array(a) => Value::Array(a.iter().map(convert).collect()),
            Yaml::Hash(h) => Value::Object(
                h.iter()
                    .filter_map(|(k, v)| {
                        let key = match k {
                            Yaml::String(s) => s.clone(),
                            Yaml::Integer(i) => i.to_string(),
                            _ => return None,
                        };
                        Some((key, convert(v)))
                    })
                    .collect(),
            ),
            _ => Value::Null,
        }
    }
    Ok(docs.first().map(convert).unwrap_or(Value::Null))
}

/// Read the channel SurfaceTopography's reader gives as channel `k` of this file (`data_source`
/// of a container's measurement). Checked against SurfaceTopography's own readers on their
/// example files (`python/tests/test_contact_engineering.py`): its Nanoscope, Igor and PicoView
/// readers list every channel of the file in the file's order, as ours do, so `k` is our
/// channel `k`, read at once (whatever the file's default channel holds); its Nanosurf reader
/// lists only the channels in a length unit (`Dim2Unit`), found among ours after a first read.
/// Other formats are refused: which of their channels SurfaceTopography counts is not known.
fn read_data_source(
    file: &Path,
    options: &mut ReadOptions,
    (k, label): (usize, &str),
) -> Result<HeightMap> {
    use super::TopographyFormat as F;
    // A reader's error (a channel not in a length unit) says which measurement asked for it.
    let read = |options: &mut ReadOptions| {
        read_with_unit(file, options).map_err(|e| match e {
            Error::BadInput { at, reason } => Error::BadInput {
                at,
                reason: format!("measurement {label}: data_source {k}: {reason}"),
            },
            other => other,
        })
    };
    let format = super::vendor::detect_file(file)?;
    let refuse = |why: String, channels: &[String]| {
        let list = if channels.is_empty() {
            String::new()
        } else {
            format!(" (the file has '{}')", channels.join("', '"))
        };
        bad(
            file,
            format!(
                "measurement {label}: data_source {k} {why}; name the channel with {}{list}",
                crate::param::Param::Channel
            ),
        )
    };
    match format {
        Some(F::Nanoscope | F::Ibw | F::Mi) => {
            options.channel = Some(k.to_string());
            let map = read(options)?;
            match map.channels.get(k) {
                Some(name) if *name == map.channel => Ok(map),
                // A channel named like the number was read by its name: read the k-th.
                Some(name) => {
                    options.channel = Some(name.clone());
                    read(options)
                }
                None => Err(refuse(
                    format!(
                        "is beyond the {} channel(s) of the file",
                        map.channels.len()
                    ),
                    &map.channels,
                )),
            }
        }
        Some(F::Nid) => {
            let first = read(options)?;
            let lengths: Vec<&String> = first
                .channels
                .iter()
                .zip(&first.height_channels)
                .filter_map(|(name, &height)| height.then_some(name))
                .collect();
            let name = lengths.get(k).ok_or_else(|| {
                refuse(
                    format!(
                        "is beyond the {} channel(s) SurfaceTopography's reader lists for this \
                         file (those in a length unit)",
                        lengths.len()
                    ),
                    &first.channels,
                )
            })?;
            if **name == first.channel {
                return Ok(first);
            }
            options.channel = Some(name.to_string());
            read(options)
        }
        other => {
            // Read as by default only to name the format and list the channels.
            let map = read_with_unit(file, &mut options.clone()).ok();
            let name = other
                .or(map.as_ref().map(|m| m.format))
                .map_or("this file's format", |f| f.name());
            let channels = map.map(|m| m.channels).unwrap_or_default();
            Err(refuse(
                format!(
                    "is a channel index in SurfaceTopography's order, which is not known for \
                     {name} files"
                ),
                &channels,
            ))
        }
    }
}
