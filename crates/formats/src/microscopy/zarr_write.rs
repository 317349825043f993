//! Writing OME-Zarr groups and arrays through `zarrs`: NGFF 0.4 on Zarr v2 (attributes at the
//! top of `.zattrs`) or NGFF 0.5 on Zarr v3 (attributes under `ome` in `zarr.json`), arrays
//! chunked one 2-D plane per chunk and compressed with zstd, so that each plane is written on
//! its own (from any thread) as it is measured.

use std::path::Path;
use std::sync::Arc;

use serde_json::{json, Map, Value};
use zarrs::array::Array;
use zarrs::filesystem::FilesystemStore;
use zarrs::group::Group;
use zarrs::metadata::{ArrayMetadata, GroupMetadata};

use crate::binary::bad;
use crate::error::Result;
use crate::image::SampleType;

/// The NGFF version a store is written in (and so its Zarr version).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NgffVersion {
    /// NGFF 0.4 on Zarr v2.
    V04,
    /// NGFF 0.5 on Zarr v3.
    V05,
}

impl NgffVersion {
    /// `0.4` or `0.5`.
    pub fn name(self) -> &'static str {
        match self {
            NgffVersion::V04 => "0.4",
            NgffVersion::V05 => "0.5",
        }
    }

    /// The version of an NGFF version string read from a store (`0.4` and older → 0.4).
    pub fn of(text: &str) -> NgffVersion {
        match text {
            "0.5" | "0.6" => NgffVersion::V05,
            _ => NgffVersion::V04,
        }
    }
}

/// A Zarr store being written (a folder).
pub struct ZarrStore {
    store: Arc<FilesystemStore>,
    version: NgffVersion,
    path: std::path::PathBuf,
}

impl ZarrStore {
    /// Open (or create) the folder `path` as a store written in `version`.
    pub fn open(path: &Path, version: NgffVersion) -> Result<Self> {
        std::fs::create_dir_all(path).map_err(|e| bad(path, format!("cannot create: {e}")))?;
        let fs = FilesystemStore::new(path)
            .map_err(|e| bad(path, format!("not a writable Zarr store: {e}")))?;
        Ok(ZarrStore {
            store: Arc::new(fs),
            version,
            path: path.to_path_buf(),
        })
    }

    /// The store's folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The NGFF version written.
    pub fn version(&self) -> NgffVersion {
        self.version
    }

    /// Write the group at `node` with the NGFF attributes `ome` (an object: `multiscales`,
    /// `labels`, `image-label`, …) and further top-level attributes `extra`.
    pub fn write_group(
        &self,
        node: &str,
        ome: Map<String, Value>,
        extra: Map<String, Value>,
    ) -> Result<()> {
        let mut attrs = extra;
        match self.version {
            NgffVersion::V04 => attrs.extend(ome),
            NgffVersion::V05 => {
                let mut ome = ome;
                ome.insert("version".into(), json!("0.5"));
                attrs.insert("ome".into(), Value::Object(ome));
            }
        }
        let metadata = match self.version {
            NgffVersion::V04 => {
                let mut flat = Map::new();
                flat.insert("zarr_format".into(), json!(2));
                flat.extend(attrs);
                GroupMetadata::V2(self.parse(node, Value::Object(flat))?)
            }
            NgffVersion::V05 => GroupMetadata::V3(self.parse(
                node,
                json!({"zarr_format": 3, "node_type": "group", "attributes": attrs}),
            )?),
        };
        let group = Group::new_with_metadata(self.store.clone(), node, metadata)
            .map_err(|e| bad(&self.path, format!("group '{node}': {e}")))?;
        group
            .store_metadata()
            .map_err(|e| bad(&self.path, format!("group '{node}': {e}")))
    }

    fn parse<T: serde::de::DeserializeOwned>(&self, node: &str, value: Value) -> Result<T> {
        serde_json::from_value(value)
            .map_err(|e| bad(&self.path, format!("metadata of '{node}': {e}")))
    }

    /// Create the array at `node`: `shape` (the last two dimensions y, x), one plane per chunk,
    /// zstd-compressed, fill value 0, the dimension names given (Zarr v3 only).
    pub fn create_array(
        &self,
        node: &str,
        shape: &[u64],
        dtype: SampleType,
        names: &[&str],
    ) -> Result<PlaneArray> {
        let n = shape.len();
        if n < 2 || names.len() != n {
            return Err(bad(&self.path, format!("array '{node}': {n} dimensions")));
        }
        let chunks: Vec<u64> = (0..n)
            .map(|i| if i + 2 >= n { shape[i].max(1) } else { 1 })
            .collect();
        let (v2, v3, fill) = match dtype {
            SampleType::U8 => ("|u1", "uint8", json!(0)),
            SampleType::U16 => ("<u2", "uint16", json!(0)),
            SampleType::I16 => ("<i2", "int16", json!(0)),
            SampleType::F32 => ("<f4", "float32", json!(0.0)),
            SampleType::F64 => ("<f8", "float64", json!(0.0)),
        };
        let metadata = match self.version {
            NgffVersion::V04 => ArrayMetadata::V2(self.parse(
                node,
                json!({
                    "zarr_format": 2, "shape": shape, "chunks": chunks, "dtype": v2,
                    "compressor": {"id": "zstd", "level": 3}, "fill_value": fill,
                    "order": "C", "filters": null, "dimension_separator": "/"
                }),
            )?),
            NgffVersion::V05 => ArrayMetadata::V3(self.parse(
                node,
                json!({
                    "zarr_format": 3, "node_type": "array", "shape": shape,
                    "data_type": v3,
                    "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": chunks}},
                    "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
                    "fill_value": fill,
                    "codecs": [
                        {"name": "bytes", "configuration": {"endian": "little"}},
                        {"name": "zstd", "configuration": {"level": 3, "checksum": false}}
                    ],
                    "dimension_names": names,
                }),
            )?),
        };
        let array = Array::new_with_metadata(self.store.clone(), node, metadata)
            .map_err(|e| bad(&self.path, format!("array '{node}': {e}")))?;
        array
            .store_metadata()
            .map_err(|e| bad(&self.path, format!("array '{node}': {e}")))?;
        Ok(PlaneArray {
            array,
            node: node.to_string(),
            path: self.path.clone(),
        })
    }
}

/// An array written one 2-D plane (one chunk) at a time.
pub struct PlaneArray {
    array: Array<FilesystemStore>,
    node: String,
    path: std::path::PathBuf,
}

impl PlaneArray {
    /// Store the plane at `at` (the indices of every dimension before y and x) from its
    /// row-major samples.
    pub fn write_plane<T: zarrs::array::Element>(&self, at: &[u64], samples: &[T]) -> Result<()> {
        let mut chunk = at.to_vec();
        chunk.extend([0, 0]);
        // Every plane is stored, zeros too: a plane without chunks reads as never written.
        let options = zarrs::array::CodecOptions::default().with_store_empty_chunks(true);
        let stored = self.array.store_chunk_opt(&chunk, samples, &options);
        stored.map_err(|e| {
            bad(
                &self.path,
                format!("array '{}', plane {at:?}: {e}", self.node),
            )
        })
    }
}

/// The NGFF `multiscales` list of one image: `axes` as (name, type, unit), its levels as
/// (path, scale per axis in the axis unit), the full resolution first.
pub fn multiscales(
    version: NgffVersion,
    name: &str,
    axes: &[(String, String, Option<String>)],
    levels: &[(String, Vec<f64>)],
) -> Value {
    let axes: Vec<Value> = axes
        .iter()
        .map(|(n, t, u)| {
            let mut a = json!({"name": n, "type": t});
            if let (Some(u), Some(o)) = (u, a.as_object_mut()) {
                o.insert("unit".into(), json!(u));
            }
            a
        })
        .collect();
    let mut image = json!({
        "name": name,
        "axes": axes,
        "datasets": levels
            .iter()
            .map(|(path, scale)| json!({
                "path": path,
                "coordinateTransformations": [{"type": "scale", "scale": scale}]
            }))
            .collect::<Vec<_>>()
    });
    if let (NgffVersion::V04, Some(o)) = (version, image.as_object_mut()) {
        o.insert("version".into(), json!("0.4"));
    }
    json!([image])
}
