//! `analyze --zarr-out STORE`: the contact masks and the per-image table into an OME-Zarr
//! container, beside the images they were measured on.
//!
//! - **A new store** (STORE does not exist): NGFF 0.5 on Zarr v3. The analysed planes are
//!   copied into the image `0` with axes `t` (the load index) `y` `x`, the pixel size as the
//!   `scale` in micrometres; the masks are the label image `labels/contact` (values 0 and 1)
//!   with the same axes and scale.
//! - **The input store itself** (STORE is the one OME-Zarr store analysed): its images are never
//!   written; each analysed image gets `labels/contact` beside it, in the store's own NGFF and
//!   Zarr version, with the image's axes, shape (one channel) and scale, 1 where a pixel is in
//!   contact in the planes analysed, 0 everywhere else. A `labels/contact` written by an
//!   earlier run of contactscope is replaced; any other is refused.
//!
//! Either way the label image carries NGFF `image-label` metadata (value 1 in magenta, the
//! source image `../../`) and the per-image table (the columns of `areas.csv`) is a Parquet
//! file, `tables/contact_areas/table.parquet`, in a group whose attributes follow the
//! Fractal/ngio table convention (`type`, `backend: parquet`, `region` naming the label image),
//! so that the store is one folder holding images, masks and numbers (`docs/outputs.md`).
//!
//! Nothing is left half written: labels and tables are written under hidden names and renamed
//! into place once the analysis has succeeded (a new store as a whole).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::{json, Map, Value};

use contactscope::image::{Plane, SampleType, Samples};
use contactscope::measure::Mask;
use contactscope_formats::microscopy::zarr::{is_store, ImageLayout, ZarrReader};
use contactscope_formats::microscopy::zarr_write::{
    multiscales, NgffVersion, PlaneArray, ZarrStore,
};

use crate::batch::tables::{Table, Values};
use crate::error::{Error, Result};
use crate::series::OpenSeries;

/// The name of the label image and of the table.
pub const LABEL: &str = "contact";
/// The table's name under `tables/`.
pub const TABLE: &str = "contact_areas";

/// The label arrays beside one image of the input store (every level, with its plane size
/// (width, height)), the hidden folder written and the final folder.
struct InputLabels {
    levels: Vec<(PlaneArray, (usize, usize))>,
    work: PathBuf,
    final_dir: PathBuf,
}

/// Where each analysed image's mask (and, in a new store, its plane) goes.
enum Target {
    /// A new store at `work` (renamed to the final path at the end).
    New {
        image: Box<PlaneArray>,
        labels: Box<PlaneArray>,
        dtype: SampleType,
    },
    /// The input store: one label array per analysed image group, and each image's place in it.
    Input {
        /// The labels of each image group.
        groups: Vec<InputLabels>,
        /// Per image of the series: (group, indices before y and x).
        places: Vec<(usize, Vec<u64>)>,
    },
}

/// Hidden folders written so far, removed unless the output is finished (an analysis that
/// fails, or is refused, leaves nothing behind).
#[derive(Default)]
struct Unfinished(Vec<PathBuf>);

impl Unfinished {
    fn add(&mut self, dir: &Path) {
        crate::staging::register(dir);
        self.0.push(dir.to_path_buf());
    }

    /// Everything is in place: keep it.
    fn done(&mut self) {
        for dir in self.0.drain(..) {
            crate::staging::unregister(&dir);
        }
    }
}

impl Drop for Unfinished {
    fn drop(&mut self) {
        for dir in self.0.drain(..) {
            let _ = std::fs::remove_dir_all(&dir);
            crate::staging::unregister(&dir);
        }
    }
}

/// An OME-Zarr output being written.
pub struct ZarrOut {
    unfinished: Unfinished,
    final_path: PathBuf,
    /// The folder written into: the hidden new store, or the input store.
    root: PathBuf,
    version: NgffVersion,
    target: Target,
    /// Image groups (store nodes) given labels and the table.
    nodes: Vec<String>,
}

fn output_error(path: &Path, reason: impl Into<String>) -> Error {
    Error::Output {
        path: path.to_path_buf(),
        reason: reason.into(),
    }
}

fn hidden(parent: &Path, name: &str) -> PathBuf {
    parent.join(format!(".{name}.partial-{}", std::process::id()))
}

impl ZarrOut {
    /// Prepare the output for the series `open`: a new store at `path`, or the input store
    /// when `path` is it. `pixel_m` is the pixel size used (x, y), m, if any.
    pub fn prepare(path: &Path, open: &OpenSeries, pixel_m: Option<(f64, f64)>) -> Result<Self> {
        let series = &open.series;
        if contactscope_formats::remote::is_url(path) {
            return Err(output_error(
                path,
                "--zarr-out writes a local OME-Zarr store, not one on object storage",
            ));
        }
        let same = |a: &Path| match (a.canonicalize(), path.canonicalize()) {
            (Ok(a), Ok(b)) => a == b,
            _ => false,
        };
        if let Some(file) = series.files.iter().find(|f| same(&f.path)) {
            if series.files.len() != 1 || !is_store(&file.path) {
                return Err(output_error(
                    path,
                    "is an input of this run and not the one OME-Zarr store analysed; \
                     give a new path for --zarr-out",
                ));
            }
            return Self::into_input(path, open);
        }
        if path.exists() {
            return Err(output_error(
                path,
                "exists: --zarr-out writes a new store, or into the one OME-Zarr store analysed",
            ));
        }
        Self::new_store(path, open, pixel_m)
    }

    fn new_store(path: &Path, open: &OpenSeries, pixel_m: Option<(f64, f64)>) -> Result<Self> {
        let series = &open.series;
        let first = series
            .files
            .first()
            .ok_or_else(|| output_error(path, "no images to write"))?;
        let parent = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = path
            .file_name()
            .map_or("out.zarr".into(), |n| n.to_string_lossy().into_owned());
        std::fs::create_dir_all(&parent).map_err(|e| output_error(&parent, e.to_string()))?;
        let work = hidden(&parent, &name);
        let _ = std::fs::remove_dir_all(&work);
        let mut unfinished = Unfinished::default();
        unfinished.add(&work);
        let version = NgffVersion::V05;
        let store = ZarrStore::open(&work, version)?;
        let n = series.images.len() as u64;
        let shape = [n, first.height as u64, first.width as u64];
        let (unit, scale) = match pixel_m {
            Some((x, y)) => (
                Some("micrometer".to_string()),
                [1.0, tidy(y * 1e6), tidy(x * 1e6)],
            ),
            None => (None, [1.0, 1.0, 1.0]),
        };
        let axes = [
            ("t".to_string(), "time".to_string(), None),
            ("y".to_string(), "space".to_string(), unit.clone()),
            ("x".to_string(), "space".to_string(), unit),
        ];
        let title = first
            .path
            .file_name()
            .map_or("image".into(), |n| n.to_string_lossy().into_owned());
        let mut ome = Map::new();
        let level = vec![("0".to_string(), scale.to_vec())];
        ome.insert(
            "multiscales".into(),
            multiscales(version, &title, &axes, &level),
        );
        store.write_group("/", ome, Map::new())?;
        let dtype = match first.sample_type {
            SampleType::F64 => SampleType::F32,
            t => t,
        };
        let image = store.create_array("/0", &shape, dtype, &["t", "y", "x"])?;
        let labels_root = work.join("labels");
        write_label_group(&store, "/", &labels_root)?;
        let levels = [("0".to_string(), shape.to_vec(), scale.to_vec())];
        let mut labels = label_image(&store, "/labels/contact", &axes, &levels, &title)?;
        let labels = labels.remove(0).0;
        Ok(ZarrOut {
            unfinished,
            final_path: path.to_path_buf(),
            root: work,
            version,
            target: Target::New {
                image: Box::new(image),
                labels: Box::new(labels),
                dtype,
            },
            nodes: vec!["/".into()],
        })
    }

    fn into_input(path: &Path, open: &OpenSeries) -> Result<Self> {
        let reader = ZarrReader::open(path)?;
        if reader.level != 0 {
            return Err(output_error(
                path,
                "is one resolution level of an image: the masks go into the image's store \
                 (its parent folder) or a new one",
            ));
        }
        let version = NgffVersion::of(&reader.version);
        let store = ZarrStore::open(path, version)?;
        let mut nodes: Vec<String> = Vec::new();
        let mut unfinished = Unfinished::default();
        let mut groups: Vec<InputLabels> = Vec::new();
        let mut places = Vec::new();
        let mut layouts: BTreeMap<usize, usize> = BTreeMap::new();
        for image in &open.series.images {
            let plane = image
                .plane
                .as_ref()
                .ok_or_else(|| output_error(path, "an image without a plane of the store"))?;
            let layout: &ImageLayout = reader
                .layout(plane.series)
                .ok_or_else(|| output_error(path, "a series the store does not hold"))?;
            let group = match layouts.get(&plane.series) {
                Some(&g) => g,
                None => {
                    let g = groups.len();
                    let labels = Self::input_labels(path, &store, layout)?;
                    unfinished.add(&labels.work);
                    groups.push(labels);
                    nodes.push(layout.node.clone());
                    layouts.insert(plane.series, g);
                    g
                }
            };
            let at = layout.plane_at(&plane.index, true).ok_or_else(|| {
                output_error(
                    path,
                    format!("image '{}': y and x are not its last axes", layout.node),
                )
            })?;
            places.push((group, at));
        }
        Ok(ZarrOut {
            unfinished,
            final_path: path.to_path_buf(),
            root: path.to_path_buf(),
            version,
            target: Target::Input { groups, places },
            nodes,
        })
    }

    /// The hidden label array beside one image of the input store.
    fn input_labels(path: &Path, store: &ZarrStore, layout: &ImageLayout) -> Result<InputLabels> {
        let base = layout.node.trim_end_matches('/');
        let labels_dir = path.join(base.trim_start_matches('/')).join("labels");
        let final_dir = labels_dir.join(LABEL);
        if final_dir.exists() && !written_by_us(&final_dir) {
            return Err(output_error(
                &final_dir,
                "exists and was not written by contactscope; not replaced",
            ));
        }
        let work = hidden(&labels_dir, LABEL);
        let _ = std::fs::remove_dir_all(&work);
        let node = format!(
            "{base}/labels/{}",
            work.file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned())
        );
        // Every level of the image, with one channel: viewers and validators pair the label's
        // levels with the image's.
        let levels: Vec<(String, Vec<u64>, Vec<f64>)> = layout
            .levels
            .iter()
            .map(|(p, shape, scale)| {
                let mut shape = shape.clone();
                if let Some(c) = layout.channel_dim {
                    shape[c] = 1;
                }
                (p.clone(), shape, scale.clone())
            })
            .collect();
        let title = format!("{LABEL} of {}", layout.node);
        let arrays = label_image(store, &node, &layout.axes, &levels, &title)?;
        Ok(InputLabels {
            levels: arrays,
            work,
            final_dir,
        })
    }

    /// Write image `index`'s mask (and, in a new store, its plane); from any thread.
    pub fn write(&self, index: usize, plane: &Plane, mask: &Mask) -> Result<()> {
        match &self.target {
            Target::New {
                image,
                labels,
                dtype,
            } => {
                let at = [index as u64];
                labels.write_plane(&at, &mask.data)?;
                write_samples(image, &at, plane, *dtype)
            }
            Target::Input { groups, places } => {
                let (g, at) = &places[index];
                for (array, size) in &groups[*g].levels {
                    array.write_plane(at, &nearest(mask, *size))?;
                }
                Ok(())
            }
        }
    }

    /// Write the table and put everything in place; the final store path.
    pub fn finish(mut self, rows: &impl serde::Serialize) -> Result<PathBuf> {
        let table = table_of_rows(rows)?;
        let parquet = table.to_parquet(TABLE, &[])?;
        let store = ZarrStore::open(&self.root, self.version)?;
        for node in &self.nodes {
            let base = node.trim_end_matches('/');
            let dir = self.root.join(base.trim_start_matches('/'));
            let tables = dir.join("tables");
            let work = hidden(&tables, TABLE);
            let _ = std::fs::remove_dir_all(&work);
            self.unfinished.add(&work);
            let work_node = format!(
                "{base}/tables/{}",
                work.file_name()
                    .map_or(String::new(), |n| n.to_string_lossy().into_owned())
            );
            let mut attrs = Map::new();
            attrs.insert("type".into(), json!("generic_table"));
            attrs.insert("backend".into(), json!("parquet"));
            attrs.insert("table_version".into(), json!("1"));
            attrs.insert(
                "region".into(),
                json!({"path": format!("../labels/{LABEL}")}),
            );
            attrs.insert(
                "contactscope".into(),
                json!({"version": crate::provenance::version(), "columns": "areas.csv"}),
            );
            store.write_group(&work_node, Map::new(), attrs)?;
            std::fs::write(work.join("table.parquet"), &parquet)
                .map_err(|e| output_error(&work, e.to_string()))?;
            let final_dir = tables.join(TABLE);
            if final_dir.exists() && !written_by_us(&final_dir) {
                return Err(output_error(
                    &final_dir,
                    "exists and was not written by contactscope; not replaced",
                ));
            }
            replace_dir(&work, &final_dir)?;
            let mut listed = listed_tables(&tables);
            if !listed.iter().any(|t| t == TABLE) {
                listed.push(TABLE.into());
            }
            let mut list = Map::new();
            list.insert("tables".into(), json!(listed));
            store.write_group(&format!("{base}/tables"), Map::new(), list)?;
        }
        match &self.target {
            Target::New { .. } => {
                std::fs::rename(&self.root, &self.final_path)
                    .map_err(|e| output_error(&self.final_path, e.to_string()))?;
            }
            Target::Input { groups, .. } => {
                for (
                    k,
                    InputLabels {
                        work, final_dir, ..
                    },
                ) in groups.iter().enumerate()
                {
                    replace_dir(work, final_dir)?;
                    let node = self.nodes[k].trim_end_matches('/');
                    let labels_dir = final_dir.parent().unwrap_or(final_dir);
                    write_label_list(&store, node, labels_dir)?;
                }
            }
        }
        self.unfinished.done();
        Ok(self.final_path)
    }
}

/// A number to 12 significant digits: 0.2, not 0.19999999999999998 from 2e-7 m × 1e6.
fn tidy(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// Replace `final_dir` (if any: ours, checked before) by `work`. The old folder is moved
/// aside first and removed only once the new one is in place, so that a kill between the two
/// renames leaves the earlier result (hidden) rather than none.
fn replace_dir(work: &Path, final_dir: &Path) -> Result<()> {
    let parent = final_dir.parent().unwrap_or(final_dir);
    let name = final_dir
        .file_name()
        .map_or("old".into(), |n| n.to_string_lossy().into_owned());
    let old = parent.join(format!(".{name}.old-{}", std::process::id()));
    let had_old = final_dir.exists();
    if had_old {
        std::fs::rename(final_dir, &old).map_err(|e| output_error(final_dir, e.to_string()))?;
    }
    if let Err(e) = std::fs::rename(work, final_dir) {
        if had_old {
            let _ = std::fs::rename(&old, final_dir);
        }
        return Err(output_error(final_dir, e.to_string()));
    }
    if had_old {
        let _ = std::fs::remove_dir_all(&old);
    }
    Ok(())
}

/// Whether a label image or table folder was written by contactscope (its attributes say so).
fn written_by_us(dir: &Path) -> bool {
    ["zarr.json", ".zattrs"]
        .iter()
        .any(|f| std::fs::read_to_string(dir.join(f)).is_ok_and(|t| t.contains("\"contactscope\"")))
}

/// The names a `tables` group lists already.
fn listed_tables(dir: &Path) -> Vec<String> {
    group_attrs(dir)
        .and_then(|a| a.get("tables").cloned())
        .and_then(|t| serde_json::from_value(t).ok())
        .unwrap_or_default()
}

/// A group's attributes (Zarr v3 `zarr.json` or v2 `.zattrs`), NGFF 0.5 `ome` fields merged
/// to the top.
fn group_attrs(dir: &Path) -> Option<Map<String, Value>> {
    if let Ok(text) = std::fs::read_to_string(dir.join("zarr.json")) {
        let v: Value = serde_json::from_str(&text).ok()?;
        let mut attrs = v.get("attributes")?.as_object()?.clone();
        if let Some(Value::Object(ome)) = attrs.remove("ome") {
            attrs.extend(ome);
        }
        return Some(attrs);
    }
    let text = std::fs::read_to_string(dir.join(".zattrs")).ok()?;
    serde_json::from_str(&text).ok()
}

/// The `labels` group of an image listing `contact` beside any labels it listed before.
fn write_label_list(store: &ZarrStore, node: &str, labels_dir: &Path) -> Result<()> {
    let mut listed: Vec<String> = group_attrs(labels_dir)
        .and_then(|a| a.get("labels").cloned())
        .and_then(|l| serde_json::from_value(l).ok())
        .unwrap_or_default();
    if !listed.iter().any(|l| l == LABEL) {
        listed.push(LABEL.into());
    }
    let mut ome = Map::new();
    ome.insert("labels".into(), json!(listed));
    Ok(store.write_group(&format!("{node}/labels"), ome, Map::new())?)
}

/// The `labels` group of a new store's image.
fn write_label_group(store: &ZarrStore, node: &str, dir: &Path) -> Result<()> {
    write_label_list(store, node.trim_end_matches('/'), dir)
}

/// A mask at another level's plane size (width, height), by the nearest pixel (a label is a
/// class, never an average); the mask itself at its own size.
fn nearest(mask: &Mask, (w, h): (usize, usize)) -> std::borrow::Cow<'_, [u8]> {
    if (w, h) == (mask.width, mask.height) {
        return std::borrow::Cow::Borrowed(&mask.data);
    }
    let pick = |i: usize, n: usize, of: usize| ((2 * i + 1) * of / (2 * n)).min(of - 1);
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let row = pick(y, h, mask.height) * mask.width;
        out.extend((0..w).map(|x| mask.data[row + pick(x, w, mask.width)]));
    }
    std::borrow::Cow::Owned(out)
}

/// A label image group with its levels as (path, shape, scale): NGFF `multiscales` and
/// `image-label`; each level's array with its plane size (width, height).
fn label_image(
    store: &ZarrStore,
    node: &str,
    axes: &[(String, String, Option<String>)],
    levels: &[(String, Vec<u64>, Vec<f64>)],
    title: &str,
) -> Result<Vec<(PlaneArray, (usize, usize))>> {
    let version = store.version();
    let mut label = json!({
        "colors": [{"label-value": 1, "rgba": [255, 0, 255, 255]}],
        "properties": [{"label-value": 1, "class": "contact"}],
        "source": {"image": "../../"}
    });
    if let (NgffVersion::V04, Some(o)) = (version, label.as_object_mut()) {
        o.insert("version".into(), json!("0.4"));
    }
    let mut ome = Map::new();
    let datasets: Vec<(String, Vec<f64>)> = levels
        .iter()
        .map(|(p, _, s)| (p.clone(), s.clone()))
        .collect();
    ome.insert(
        "multiscales".into(),
        multiscales(version, title, axes, &datasets),
    );
    ome.insert("image-label".into(), label);
    let mut extra = Map::new();
    extra.insert(
        "contactscope".into(),
        json!({"version": crate::provenance::version(), "values": {"0": "no contact", "1": "contact"}}),
    );
    store.write_group(node, ome, extra)?;
    let names: Vec<&str> = axes.iter().map(|a| a.0.as_str()).collect();
    let mut arrays = Vec::with_capacity(levels.len());
    for (path, shape, _) in levels {
        let n = shape.len();
        let size = (shape[n - 1] as usize, shape[n - 2] as usize);
        if size.0 == 0 || size.1 == 0 {
            return Err(output_error(
                store.path(),
                format!("label level '{path}' is empty"),
            ));
        }
        let array = store.create_array(&format!("{node}/{path}"), shape, SampleType::U8, &names)?;
        arrays.push((array, size));
    }
    Ok(arrays)
}

/// One plane's samples in the new store's image array.
fn write_samples(array: &PlaneArray, at: &[u64], plane: &Plane, dtype: SampleType) -> Result<()> {
    match (&plane.samples, dtype) {
        (Samples::Int { codes, .. }, SampleType::U8) => {
            let bytes: Vec<u8> = codes.iter().map(|&c| c.min(255) as u8).collect();
            array.write_plane(at, &bytes)
        }
        (Samples::Int { codes, offset }, SampleType::I16) => {
            let values: Vec<i16> = codes
                .iter()
                .map(|&c| (i32::from(c) + offset).clamp(-32768, 32767) as i16)
                .collect();
            array.write_plane(at, &values)
        }
        (Samples::Int { codes, .. }, _) => array.write_plane(at, codes),
        (Samples::Float(v), _) => array.write_plane(at, v),
    }
    .map_err(Into::into)
}

/// The rows of `areas.csv` as a typed table: a column of whole numbers is INT64, of numbers
/// DOUBLE, of true/false BOOLEAN, else text; nulls stay null.
pub fn table_of_rows(rows: &impl serde::Serialize) -> Result<Table> {
    let values = match serde_json::to_value(rows) {
        Ok(Value::Array(values)) => values,
        _ => return Err(Error::InvalidArgument("table: not a list of rows".into())),
    };
    let header: Vec<String> = match values.first() {
        Some(Value::Object(first)) => first.keys().cloned().collect(),
        _ => return Err(Error::InvalidArgument("table: no rows".into())),
    };
    let mut table = Table::new(values.len());
    for name in header {
        let cells: Vec<&Value> = values
            .iter()
            .map(|r| r.get(&name).unwrap_or(&Value::Null))
            .collect();
        let present = || cells.iter().filter(|c| !c.is_null());
        let column = if present().all(|c| c.is_boolean()) && present().count() > 0 {
            Values::Bool(cells.iter().map(|c| c.as_bool()).collect())
        } else if present().all(|c| c.is_i64() || c.is_u64()) && present().count() > 0 {
            Values::Int(cells.iter().map(|c| c.as_i64()).collect())
        } else if present().all(|c| c.is_number()) {
            Values::Float(cells.iter().map(|c| c.as_f64()).collect())
        } else {
            Values::Text(
                cells
                    .iter()
                    .map(|c| match c {
                        Value::Null => None,
                        Value::String(s) => Some(s.clone()),
                        other => Some(other.to_string()),
                    })
                    .collect(),
            )
        };
        table.push(name, column);
    }
    Ok(table)
}
