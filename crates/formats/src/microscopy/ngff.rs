//! The NGFF attributes of an OME-Zarr group, read leniently with serde (NGFF 0.4 and 0.5): a
//! multiscale image's axes and datasets, the `omero` channel labels, plate and well paths, and
//! what they say about the array: where each axis sits, the scale of a level, and the length of
//! an axis unit.

use std::path::Path;

use serde::Deserialize;
use zarrs::group::Group;
use zarrs::storage::ReadableStorage;

use crate::binary::{bad, unsupported};
use crate::error::Result;

/// One NGFF axis: name, type (`space`, `time`, `channel`, other) and unit, as written.
#[derive(Debug, Clone, Deserialize)]
pub(super) struct Axis {
    pub(super) name: String,
    #[serde(rename = "type", default)]
    pub(super) kind: Option<String>,
    #[serde(default)]
    pub(super) unit: Option<String>,
}

/// One level of a multiscale image (its coordinate transformations are read from the JSON).
#[derive(Debug, Clone, Deserialize)]
pub(super) struct Dataset {
    pub(super) path: String,
}

/// The NGFF facts of one multiscale image, whatever the version (NGFF 0.4 §"multiscales").
/// Read leniently: writers add keys of their own (ngff-zarr's `@type`), which are ignored.
#[derive(Debug, Clone, Deserialize)]
pub(super) struct Multiscale {
    #[serde(default)]
    pub(super) name: Option<String>,
    pub(super) axes: Vec<Axis>,
    pub(super) datasets: Vec<Dataset>,
    /// The entry as JSON, for its transformations' numbers as written.
    #[serde(skip)]
    pub(super) raw: serde_json::Value,
}

/// One group's NGFF attributes, whatever the version: the attributes themselves (0.4) or their
/// `ome` object (0.5).
pub(super) struct GroupFields {
    pub(super) raw: serde_json::Value,
    pub(super) version: String,
    pub(super) bioformats2raw: bool,
}

impl GroupFields {
    pub(super) fn multiscales(&self, path: &Path, node: &str) -> Result<Vec<Multiscale>> {
        let Some(list) = self.raw.get("multiscales") else {
            return Ok(Vec::new());
        };
        let list = list
            .as_array()
            .ok_or_else(|| bad(path, format!("group '{node}': 'multiscales' is not a list")))?;
        list.iter()
            .map(|m| {
                let mut ms: Multiscale = serde_json::from_value(m.clone()).map_err(|e| {
                    bad(path, format!("group '{node}': a 'multiscales' entry: {e}"))
                })?;
                ms.raw = m.clone();
                Ok(ms)
            })
            .collect()
    }

    /// The `omero` channel labels, in channel order.
    pub(super) fn channel_labels(&self) -> Vec<Option<String>> {
        self.raw["omero"]["channels"]
            .as_array()
            .map(|cs| {
                cs.iter()
                    .map(|c| c["label"].as_str().map(str::to_string))
                    .collect()
            })
            .unwrap_or_default()
    }

    /// The paths listed under `key` (`plate.wells`, `well.images`), `None` without the key.
    pub(super) fn paths(&self, group: &str, list: &str) -> Option<Vec<String>> {
        let items = self.raw.get(group)?.get(list)?.as_array()?;
        Some(
            items
                .iter()
                .filter_map(|w| w["path"].as_str())
                .map(|p| p.trim_matches('/').to_string())
                .collect(),
        )
    }
}

/// Read the NGFF attributes of the group at `node` (`/` for the root).
pub(super) fn group_fields(
    path: &Path,
    store: &ReadableStorage,
    node: &str,
) -> Result<GroupFields> {
    let group = Group::open(store.clone(), node).map_err(|e| {
        bad(
            path,
            format!("group '{node}' of the Zarr store cannot be opened: {e}"),
        )
    })?;
    let attrs = serde_json::Value::Object(group.attributes().clone());
    let raw = attrs.get("ome").unwrap_or(&attrs).clone();
    let bioformats2raw = raw.get("bioformats2raw.layout").is_some();
    // 0.5 names its version once, in `ome`; 0.4 in each `multiscales` (or plate, well) entry.
    let version = raw["version"]
        .as_str()
        .or_else(|| raw["multiscales"][0]["version"].as_str())
        .or_else(|| raw["plate"]["version"].as_str())
        .or_else(|| raw["well"]["version"].as_str())
        .unwrap_or(if attrs.get("ome").is_some() {
            "0.5"
        } else {
            "0.4"
        })
        .to_string();
    Ok(GroupFields {
        raw,
        version,
        bioformats2raw,
    })
}

/// Where each axis of an image sits in its array.
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct AxisPlaces {
    pub(super) t: Option<usize>,
    pub(super) c: Option<usize>,
    pub(super) z: Option<usize>,
    pub(super) y: usize,
    pub(super) x: usize,
    /// Other axes by name.
    pub(super) extra: Vec<(String, usize)>,
}

/// Place every axis of a multiscale image in its array.
pub(super) fn place_axes(path: &Path, node: &str, axes: &[Axis]) -> Result<AxisPlaces> {
    let mut places = AxisPlaces::default();
    let (mut y, mut x) = (None, None);
    for (i, axis) in axes.iter().enumerate() {
        let name = axis.name.to_ascii_lowercase();
        let slot = match (name.as_str(), axis.kind.as_deref()) {
            ("x", _) => &mut x,
            ("y", _) => &mut y,
            ("z", _) => &mut places.z,
            ("t", _) | (_, Some("time")) => &mut places.t,
            ("c", _) | (_, Some("channel")) => &mut places.c,
            _ => {
                places.extra.push((axis.name.clone(), i));
                continue;
            }
        };
        if slot.replace(i).is_some() {
            return Err(bad(
                path,
                format!(
                    "image '{node}': two axes are named or typed '{}'",
                    axis.name
                ),
            ));
        }
    }
    match (y, x) {
        (Some(y), Some(x)) if y < x => {
            places.y = y;
            places.x = x;
            Ok(places)
        }
        (Some(_), Some(_)) => Err(unsupported(
            path,
            format!("image '{node}': axis x comes before y (NGFF orders them ... y, x)"),
        )),
        _ => Err(bad(
            path,
            format!(
                "image '{node}': axes [{}] have no 'y' and 'x'",
                axes.iter()
                    .map(|a| a.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// The `scale` of a JSON list of coordinate transformations (NGFF: at most one, before any
/// translation), its numbers as written.
pub(super) fn scale_of(transforms: &serde_json::Value) -> Option<Vec<f64>> {
    transforms.as_array()?.iter().find_map(|t| {
        if t.get("type")?.as_str()? != "scale" {
            return None;
        }
        t.get("scale")?
            .as_array()?
            .iter()
            .map(|v| v.as_f64())
            .collect()
    })
}

/// Metres per unit of a space axis, or `None` for an axis without a length unit.
pub(super) fn metres_per_unit(unit: Option<&str>) -> Option<f64> {
    // The UDUNITS-2 length names NGFF lists (0.4 §"axes"), prefixed metres and the rest.
    let m = match unit? {
        "angstrom" => 1e-10,
        "attometer" => 1e-18,
        "femtometer" => 1e-15,
        "picometer" => 1e-12,
        "nanometer" => 1e-9,
        "micrometer" => 1e-6,
        "millimeter" => 1e-3,
        "centimeter" => 1e-2,
        "decimeter" => 1e-1,
        "meter" => 1.0,
        "hectometer" => 1e2,
        "kilometer" => 1e3,
        "inch" => 0.0254,
        "foot" => 0.3048,
        // A unit outside those names (`µm`, `um`, `nm`) read as a length where it is one.
        text => crate::units::parse_positive(&format!("1{text}"), crate::units::Dimension::Length)
            .ok()?,
    };
    Some(m)
}
