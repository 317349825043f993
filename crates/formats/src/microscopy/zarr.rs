//! OME-Zarr (OME-NGFF) images: NGFF 0.4 on Zarr v2 and 0.5 on Zarr v3, read through the
//! `zarrs` crates (chunks, codecs, sharding) from a folder or a server (`crate::remote`); the NGFF
//! attributes by `super::ngff`.
//!
//! A store is a folder (`image.ome.zarr`) whose root group holds one of:
//! - `multiscales` (an image written by ome-zarr-py, ngff-zarr, bioio, …): one series per
//!   multiscale image;
//! - `bioformats2raw.layout` (bioformats2raw's output): the images `0`, `1`, … each a series;
//! - `plate` (a high-content screening plate): every field of every well a series, named
//!   `row/column/field` as the plate's paths give them.
//!
//! Of each multiscale image the full-resolution level (the first `datasets` entry, NGFF 0.4
//! §"multiscales") is read. Axes are taken by name and type (`t`/time, `c`/channel, `z`, `y`,
//! `x`; any other name becomes an extra axis); y must come before x, as NGFF requires of the
//! last two spatial axes. The pixel size is the level's `scale` times the image's own `scale`
//! (when it has one) in the axis's `unit` (NGFF 0.4 §"coordinateTransformations", §"axes"): an
//! axis without a length unit gives no pixel size, and the summary says why. Channel names are
//! the `omero` channel labels. Per the Zarr specification a chunk missing from the store holds
//! the array's fill value.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use zarrs::array::{data_type, Array, ArraySubset};
use zarrs::group::Group;
use zarrs::storage::{ReadableStorage, ReadableStorageTraits, StorageError};

use super::ngff::{
    group_fields, metres_per_unit, place_axes, scale_of, AxisPlaces, GroupFields, Multiscale,
};
use super::{Axes, ChannelInfo, PlaneIndex, Rows, SeriesInfo, VoxelSize};
use crate::binary::{bad, checked_bytes, unsupported};
use crate::error::Result;
use crate::image::{Plane, SampleType, Samples};
use crate::remote::RemoteStore;

/// At most this many bioformats2raw images are looked for.
const MAX_IMAGES: usize = 100_000;

/// Whether `path` is a Zarr store (a folder with `zarr.json`, `.zgroup`, `.zattrs` or, for one
/// level of an image, `.zarray` at its root, or a URL below which the server has one of them).
pub fn is_store(path: &Path) -> bool {
    if crate::remote::is_url(path) {
        return crate::remote::is_zarr_store(path);
    }
    path.is_dir()
        && ["zarr.json", ".zgroup", ".zattrs", ".zarray"]
            .iter()
            .any(|f| path.join(f).is_file())
}

/// Where one image sits in its store and how its axes are described: what a label image
/// written beside it must repeat.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageLayout {
    /// The image's group (`/`, `/A/1/0`, `/0`).
    pub node: String,
    /// Its axes as (name, type, unit), as the store gives them (type `space` when absent for
    /// x, y and z).
    pub axes: Vec<(String, String, Option<String>)>,
    /// The scale per axis of the level read (1 where none is given).
    pub scale: Vec<f64>,
    /// The shape of the level read (level 0 unless the path named another).
    pub shape: Vec<u64>,
    /// Every level (resolution) as (path below the image group, shape, scale per axis with
    /// the image's own scale folded in), the full resolution first.
    pub levels: Vec<(String, Vec<u64>, Vec<f64>)>,
    /// The array dimension of the channel axis, if any.
    pub channel_dim: Option<usize>,
    places: AxisPlaces,
}

impl ImageLayout {
    /// The array indices before y and x of plane `index`, with the channel (if any) at `0`
    /// when `single_channel` (a label image has one channel). `None` unless y and x are the
    /// last two dimensions.
    pub fn plane_at(&self, index: &PlaneIndex, single_channel: bool) -> Option<Vec<u64>> {
        let n = self.shape.len();
        if (self.places.y, self.places.x) != (n - 2, n - 1) {
            return None;
        }
        let mut at = vec![0u64; n - 2];
        let p = &self.places;
        for (dim, i) in [(p.t, index.t), (p.z, index.z)] {
            if let Some(d) = dim {
                at[d] = i as u64;
            }
        }
        if let (Some(d), false) = (p.c, single_channel) {
            at[d] = index.c as u64;
        }
        for (name, d) in &p.extra {
            at[*d] = index.get(name) as u64;
        }
        Some(at)
    }
}

/// One image of the store: its level-0 array and where its axes sit.
struct ZarrImage {
    layout: ImageLayout,
    array: Array<dyn ReadableStorageTraits>,
    places: AxisPlaces,
    info: SeriesInfo,
    /// The store path of the array read (`0`, `A/1/0/0`).
    array_path: String,
}

/// An open OME-Zarr store.
pub struct ZarrReader {
    path: PathBuf,
    images: Vec<ZarrImage>,
    compressed: bool,
    /// NGFF version of the root (`0.4`, `0.5`).
    pub version: String,
    /// The store is an HCS plate (its series are the wells' fields).
    pub plate: bool,
    /// The resolution level read (0: full resolution; another when the path named a level).
    pub level: usize,
    /// The store, when it is on a server.
    remote: Option<Arc<RemoteStore>>,
}

/// The store at `path` (a folder, or an `s3://` or `http(s)://` URL, which is also returned as
/// such).
fn store_at(path: &Path) -> Result<(ReadableStorage, Option<Arc<RemoteStore>>)> {
    if crate::remote::is_url(path) {
        let remote = Arc::new(RemoteStore::new(path)?);
        return Ok((remote.clone(), Some(remote)));
    }
    crate::inputs::note_input(path);
    let fs = zarrs::filesystem::FilesystemStore::new(path)
        .map_err(|e| bad(path, format!("not a readable Zarr store: {e}")))?;
    Ok((Arc::new(fs), None))
}

impl ZarrReader {
    /// Open the store at `path` (a folder, or an `s3://` or `http(s)://` URL) and read the
    /// metadata of every image in it.
    ///
    /// A path to one resolution level of an image (`image.ome.zarr/1`, an array its parent's
    /// `multiscales` lists) reads that level: its shape, and its scale as the pixel size.
    pub fn open(path: &Path) -> Result<Self> {
        let (store, remote) = store_at(path)?;
        match Self::open_images(path, store, 0) {
            Ok(r) => Ok(ZarrReader { remote, ..r }),
            Err(e) => Self::open_level(path)?.ok_or(e),
        }
    }

    /// The image at `path`'s parent, read at the level `path` names; `None` when `path` is no
    /// level of an image.
    fn open_level(path: &Path) -> Result<Option<Self>> {
        let (Some(parent), Some(name)) = (path.parent(), path.file_name()) else {
            return Ok(None);
        };
        let name = name.to_string_lossy();
        if parent.as_os_str().is_empty() || !is_store(parent) {
            return Ok(None);
        }
        let (store, remote) = store_at(parent)?;
        let Ok(root) = group_fields(parent, &store, "/") else {
            return Ok(None);
        };
        let found = root.multiscales(parent, "/")?.iter().find_map(|ms| {
            ms.datasets
                .iter()
                .position(|d| d.path.trim_matches('/') == name)
        });
        let Some(level) = found else {
            return Ok(None);
        };
        let reader = Self::open_images(path, store, level)?;
        Ok(Some(ZarrReader {
            level,
            remote,
            ..reader
        }))
    }

    /// Read the images of a store opened elsewhere; `path` names it in messages.
    pub fn open_store(path: &Path, store: ReadableStorage) -> Result<Self> {
        Self::open_images(path, store, 0)
    }

    /// Read the images of a store, each at resolution level `level` (0: full resolution).
    fn open_images(path: &Path, store: ReadableStorage, level: usize) -> Result<Self> {
        let root = group_fields(path, &store, "/")?;
        // (group node, series name, group fields) of every image.
        let mut groups: Vec<(String, String, GroupFields)> = Vec::new();
        let plate = root.paths("plate", "wells");
        if let Some(wells) = plate.clone() {
            for well in wells {
                let node = format!("/{well}");
                let fields = group_fields(path, &store, &node)?;
                for field in fields.paths("well", "images").unwrap_or_default() {
                    let node = format!("/{well}/{field}");
                    let image = group_fields(path, &store, &node)?;
                    groups.push((node, format!("{well}/{field}"), image));
                }
            }
        } else if !root.multiscales(path, "/")?.is_empty() {
            groups.push(("/".into(), String::new(), root));
        } else if root.bioformats2raw {
            // Bounded by the store: the images are numbered from 0 without gaps.
            for i in 0..MAX_IMAGES {
                let node = format!("/{i}");
                if Group::open(store.clone(), &node).is_err() {
                    break;
                }
                let image = group_fields(path, &store, &node)?;
                groups.push((node, i.to_string(), image));
            }
        }
        let version = groups
            .first()
            .map(|(_, _, f)| f.version.clone())
            .unwrap_or_default();
        let mut images = Vec::new();
        for (node, name, fields) in &groups {
            let labels = fields.channel_labels();
            for (k, ms) in fields.multiscales(path, node)?.iter().enumerate() {
                let index = images.len();
                let name = match (name.is_empty(), ms.name.as_deref()) {
                    (true, Some(n)) => n.to_string(),
                    (true, None) if k > 0 => k.to_string(),
                    _ => name.clone(),
                };
                let at = (index, name, level);
                images.push(open_image(path, &store, node, ms, &labels, at)?);
            }
        }
        if images.is_empty() {
            return Err(unsupported(
                path,
                "a Zarr store without OME-Zarr images (no 'multiscales', 'plate' or \
                 'bioformats2raw.layout' at its root)",
            ));
        }
        let compressed = images.iter().any(|i| !is_uncompressed(&i.array));
        Ok(ZarrReader {
            path: path.to_path_buf(),
            images,
            compressed,
            version,
            plate: plate.is_some(),
            level,
            remote: None,
        })
    }

    /// The fields of an HCS plate store as `row/column/field`, in series order; `None` for a
    /// store that is no plate or cannot be read (the batch then takes it whole).
    pub fn plate_fields(path: &Path) -> Option<Vec<String>> {
        let r = ZarrReader::open(path).ok()?;
        r.plate
            .then(|| r.images.iter().map(|i| i.info.name.clone()).collect())
    }

    /// The series (one per image).
    pub fn series(&self) -> Vec<SeriesInfo> {
        self.images.iter().map(|i| i.info.clone()).collect()
    }

    /// Whether any image's chunks go through a compressor.
    pub fn compressed(&self) -> bool {
        self.compressed
    }

    /// Where series `series` sits and how its axes are described.
    pub fn layout(&self, series: usize) -> Option<&ImageLayout> {
        self.images.get(series).map(|i| &i.layout)
    }

    /// Decode one plane of series `info.index`.
    pub fn read_plane(&mut self, info: &SeriesInfo, index: &PlaneIndex) -> Result<Plane> {
        let image = &self.images[info.index];
        let (w, h) = (info.axes.x, info.axes.y);
        checked_bytes(&self.path, "plane", &[w, h], 8)?;
        let subset = plane_subset(image, index);
        if let Some(remote) = &self.remote {
            // A reader going through the series in order: the next planes' chunks come
            // meanwhile (not for a sharded array, read in parts of its shards).
            let store = self.path.to_string_lossy();
            let next = super::zarr_ahead::note_read(&store, info.index, index, &info.axes);
            if !next.is_empty() && !image.array.metadata().to_string().contains("sharding") {
                let keys: Vec<_> = next
                    .iter()
                    .filter_map(|i| {
                        image
                            .array
                            .chunks_in_array_subset(&plane_subset(image, i))
                            .ok()?
                    })
                    .flat_map(|chunks| chunks.indices().into_iter().collect::<Vec<_>>())
                    .map(|chunk| image.array.chunk_key(&chunk))
                    .collect();
                remote.fetch_ahead(&keys);
            }
        }
        let failed = |e: zarrs::array::ArrayError| {
            bad(
                &self.path,
                format!("array '{}': plane {index:?}: {e}", image.array_path),
            )
        };
        // On a server, whether the chunks were there is known from reading them (below), which
        // saves a request per plane.
        if self.remote.is_none() {
            self.check_written(image, &subset, index, |key| {
                image.array.storage().size_key(key).map(|s| s.is_some())
            })?;
        }
        let array = &image.array;
        let samples = match info.dtype {
            SampleType::U8 => Samples::Int {
                codes: array
                    .retrieve_array_subset::<Vec<u8>>(&subset)
                    .map_err(failed)?
                    .into_iter()
                    .map(u16::from)
                    .collect(),
                offset: 0,
            },
            SampleType::U16 => Samples::Int {
                codes: array
                    .retrieve_array_subset::<Vec<u16>>(&subset)
                    .map_err(failed)?,
                offset: 0,
            },
            SampleType::I16 => Samples::Int {
                codes: array
                    .retrieve_array_subset::<Vec<i16>>(&subset)
                    .map_err(failed)?
                    .into_iter()
                    .map(|v| (i32::from(v) + 32768) as u16)
                    .collect(),
                offset: -32768,
            },
            SampleType::F32 => Samples::Float(
                array
                    .retrieve_array_subset::<Vec<f32>>(&subset)
                    .map_err(failed)?,
            ),
            SampleType::F64 => Samples::Float(
                array
                    .retrieve_array_subset::<Vec<f64>>(&subset)
                    .map_err(failed)?
                    .into_iter()
                    .map(|v| v as f32)
                    .collect(),
            ),
        };
        if let Some(remote) = &self.remote {
            self.check_written(image, &subset, index, |key| Ok(!remote.was_missing(key)))?;
        }
        Ok(Plane {
            width: w,
            height: h,
            sample_type: info.dtype,
            samples,
        })
    }
}

/// The part of `image`'s array that holds plane `index`.
fn plane_subset(image: &ZarrImage, index: &PlaneIndex) -> ArraySubset {
    let p = &image.places;
    let shape = image.array.shape();
    let mut ranges: Vec<std::ops::Range<u64>> = shape.iter().map(|_| 0..1).collect();
    let mut set = |at: Option<usize>, i: usize| {
        if let Some(at) = at {
            ranges[at] = i as u64..i as u64 + 1;
        }
    };
    set(p.t, index.t);
    set(p.c, index.c);
    set(p.z, index.z);
    for (name, at) in &p.extra {
        set(Some(*at), index.get(name));
    }
    ranges[p.y] = 0..shape[p.y];
    ranges[p.x] = 0..shape[p.x];
    ArraySubset::new_with_ranges(&ranges)
}

impl ZarrReader {
    /// A plane none of whose chunks is in the store was never written (an incomplete copy, a
    /// write that stopped): the Zarr rule would read it as the fill value, a plane of zeros
    /// analysed as an image, so it is refused. A plane with some chunks is read as the rule
    /// says (zarr-python leaves out chunks that hold only the fill value).
    fn check_written(
        &self,
        image: &ZarrImage,
        subset: &ArraySubset,
        index: &PlaneIndex,
        present: impl Fn(&zarrs::storage::StoreKey) -> std::result::Result<bool, StorageError>,
    ) -> Result<()> {
        let array = &image.array;
        let Ok(Some(chunks)) = array.chunks_in_array_subset(subset) else {
            return Ok(());
        };
        for chunk in &chunks.indices() {
            let key = array.chunk_key(&chunk);
            let there = present(&key).map_err(|e| {
                bad(
                    &self.path,
                    format!("array '{}': chunk {key}: {e}", image.array_path),
                )
            })?;
            if there {
                return Ok(());
            }
        }
        Err(bad(
            &self.path,
            format!(
                "array '{}': plane t {}, c {}, z {} has none of its chunks in the store (never \
                 written, or an incomplete copy); it would read as the fill value",
                image.array_path, index.t, index.c, index.z
            ),
        ))
    }
}

/// Whether an array's chunks are stored as raw bytes (no compressor).
fn is_uncompressed(array: &Array<dyn ReadableStorageTraits>) -> bool {
    let text = array.metadata().to_string();
    !(text.contains("blosc")
        || text.contains("zstd")
        || text.contains("gzip")
        || text.contains("zlib"))
}

/// The sample type of an array, or an error naming its data type.
fn sample_type(
    path: &Path,
    node: &str,
    array: &Array<dyn ReadableStorageTraits>,
) -> Result<SampleType> {
    let dt = array.data_type();
    let table = [
        (data_type::uint8(), SampleType::U8),
        (data_type::uint16(), SampleType::U16),
        (data_type::int16(), SampleType::I16),
        (data_type::float32(), SampleType::F32),
        (data_type::float64(), SampleType::F64),
    ];
    table
        .into_iter()
        .find(|(d, _)| d == dt)
        .map(|(_, s)| s)
        .ok_or_else(|| {
            unsupported(
                path,
                format!(
                    "array '{node}' holds {dt:?} samples; uint8, uint16, int16, float32 and \
                     float64 are read"
                ),
            )
        })
}

/// Open the array of level `at` (0: full resolution) of one multiscale image and describe it as
/// a series (index and name given).
fn open_image(
    path: &Path,
    store: &ReadableStorage,
    node: &str,
    ms: &Multiscale,
    labels: &[Option<String>],
    (index, name, at): (usize, String, usize),
) -> Result<ZarrImage> {
    let level = ms.datasets.get(at).ok_or_else(|| {
        bad(
            path,
            format!(
                "image '{node}' lists {} datasets, not level {at}",
                ms.datasets.len()
            ),
        )
    })?;
    let base = node.trim_end_matches('/');
    let array_path = format!("{base}/{}", level.path.trim_matches('/'));
    let array = Array::open(store.clone(), &array_path)
        .map_err(|e| bad(path, format!("array '{array_path}' cannot be opened: {e}")))?;
    let shape = array.shape().to_vec();
    if shape.len() != ms.axes.len() {
        return Err(bad(
            path,
            format!(
                "array '{array_path}' has {} dimensions, its image lists {} axes",
                shape.len(),
                ms.axes.len()
            ),
        ));
    }
    let places = place_axes(path, node, &ms.axes)?;
    let dtype = sample_type(path, &array_path, &array)?;
    let size = |at: Option<usize>| at.map_or(Ok(1), |i| to_usize(path, shape[i]));
    let mut extra = BTreeMap::new();
    for (n, at) in &places.extra {
        let len = to_usize(path, shape[*at])?;
        if len > 1 {
            extra.insert(n.clone(), len);
        }
    }
    let axes = Axes {
        t: size(places.t)?,
        z: size(places.z)?,
        c: size(places.c)?,
        y: to_usize(path, shape[places.y])?,
        x: to_usize(path, shape[places.x])?,
        extra,
    };
    checked_bytes(path, "plane", &[axes.x, axes.y], 1)?;
    // A chunk is decoded whole: its size, from the metadata, is checked before any is read.
    let chunk = array
        .chunk_shape(&vec![0; shape.len()])
        .map_err(|e| bad(path, format!("array '{array_path}': {e}")))?;
    let dims: Vec<usize> = chunk
        .iter()
        .map(|n| usize::try_from(n.get()).unwrap_or(usize::MAX))
        .collect();
    let sample = dtype.bytes();
    checked_bytes(
        path,
        &format!("chunk of array '{array_path}'"),
        &dims,
        sample,
    )?;
    // Level scale × image scale, in the axis unit.
    let transforms = |d: usize| &ms.raw["datasets"][d]["coordinateTransformations"];
    let level_scale = scale_of(transforms(at));
    let global = scale_of(&ms.raw["coordinateTransformations"]);
    let scale_at = |i: usize| -> Option<f64> {
        let s = level_scale.as_ref()?.get(i)?
            * global.as_ref().map_or(Some(1.0), |g| g.get(i).copied())?;
        VoxelSize::valid(Some(s * metres_per_unit(ms.axes[i].unit.as_deref())?))
    };
    let (x_m, y_m) = (scale_at(places.x), scale_at(places.y));
    let source = (x_m.is_some() && y_m.is_some())
        .then(|| format!("OME-Zarr {array_path} scale × axis unit"));
    let pixel_size = VoxelSize {
        x_m,
        y_m,
        z_m: places.z.and_then(scale_at),
        source,
    };
    let channels = (0..axes.c)
        .map(|c| ChannelInfo {
            name: labels.get(c).cloned().flatten(),
            ..ChannelInfo::default()
        })
        .collect();
    // The image's own scale folded into a level's (1 where either is absent).
    let fold = |level: Option<&[f64]>| -> Vec<f64> {
        (0..shape.len())
            .map(|i| {
                let l = level.and_then(|s| s.get(i)).copied();
                let g = global.as_ref().and_then(|s| s.get(i)).copied();
                l.unwrap_or(1.0) * g.unwrap_or(1.0)
            })
            .collect()
    };
    let mut levels = Vec::with_capacity(ms.datasets.len());
    for (k, d) in ms.datasets.iter().enumerate() {
        let path_in = d.path.trim_matches('/').to_string();
        let array_at = format!("{base}/{path_in}");
        let level_shape = match array_at == array_path {
            true => shape.clone(),
            false => Array::open(store.clone(), &array_at)
                .map_err(|e| bad(path, format!("array '{array_at}' cannot be opened: {e}")))?
                .shape()
                .to_vec(),
        };
        if level_shape.len() != shape.len() {
            return Err(bad(
                path,
                format!("array '{array_at}' has another number of dimensions than level 0"),
            ));
        }
        levels.push((
            path_in,
            level_shape,
            fold(scale_of(transforms(k)).as_deref()),
        ));
    }
    let layout = ImageLayout {
        node: node.to_string(),
        axes: ms
            .axes
            .iter()
            .map(|a| {
                let space = ["x", "y", "z"].contains(&a.name.to_ascii_lowercase().as_str());
                let kind = a.kind.clone();
                let kind = kind.unwrap_or_else(|| if space { "space" } else { "" }.into());
                (a.name.clone(), kind, a.unit.clone())
            })
            .collect(),
        scale: fold(level_scale.as_deref()),
        shape: shape.clone(),
        levels,
        channel_dim: places.c,
        places: places.clone(),
    };
    Ok(ZarrImage {
        layout,
        array,
        places,
        info: SeriesInfo {
            index,
            name,
            axes,
            dtype,
            pixel_size,
            channels,
            rows: Rows::Y,
            tiff_axes: None,
        },
        array_path,
    })
}

fn to_usize(path: &Path, n: u64) -> Result<usize> {
    usize::try_from(n).map_err(|_| bad(path, format!("an axis of {n} elements")))
}
