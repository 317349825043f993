//! HDF5 `.h5` (The HDF Group's *HDF5 File Format Specification*): every numeric 2-D dataset of
//! the file is a channel, named by its path below the root group (`dataset1`, `group/map`).
//! Decoding is done by the pure-Rust [`hdf5_reader`] crate, with the file's bytes in memory
//! and every read bounded by [`MAX_PLANE_BYTES`].
//!
//! A dataset's first axis is the map's rows (y), its second the columns (x): the row-major
//! order of a NumPy image, as `.npy` files are read (SurfaceTopography keeps `(x, y)` arrays and
//! reads the first axis as x). An HDF5 file states neither a pixel size nor a height unit: the
//! map is returned with a pixel size of NaN, which
//! [`read_height_map`](super::read_height_map) requires as an argument, and heights as stored,
//! which it takes as metres unless a height unit is given.
//!
//! A TopoStats file (`.topostats`, written by TopoStats and read by AFMReader's
//! `load_topostats`) is an HDF5 file whose root holds the image as `image` (the levelled heights
//! TopoStats analyses, in nm), often `image_original` (before levelling, nm) and the scalar
//! `pixel_to_nm_scaling` (nm per pixel, both axes): it is read with that calibration, its
//! channels being those two images.
//!
//! A JPK Instruments HDF5 export (`.h5-jpk`, root attribute `file-format-info` = `JPK SCAN`)
//! is read with its own calibration by [`super::jpk_h5`].
//!
//! A NetCDF-4 file is an HDF5 file too: one that holds a `heights` dataset beside the `x` and
//! `y` coordinate datasets SurfaceTopography writes is read as NetCDF ([`super::netcdf`]), with
//! the sizes and units its attributes state.

use std::path::Path;

use hdf5_reader::{Datatype, Hdf5File, OpenOptions};

use super::netcdf::{self, Attr, Variable};
use super::{choose, grid_bytes, height_like, height_map, ChannelEntry, HeightMap};
use super::{line_scan, TopographyFormat};
use crate::binary::{bad, unsupported, MAX_PLANE_BYTES};
use crate::error::Result;

/// The HDF5 signature at the start of a file.
pub const SIGNATURE: &[u8] = b"\x89HDF\r\n\x1a\n";

/// Deepest group nesting searched for datasets.
const MAX_DEPTH: usize = 8;

/// Most datasets listed.
const MAX_DATASETS: usize = 4096;

/// An error of the HDF5 decoder, naming the file.
fn h5(path: &Path) -> impl Fn(hdf5_reader::error::Error) -> crate::error::Error + '_ {
    move |e| bad(path, format!("HDF5: {e}"))
}

/// Read a 2-D dataset of an HDF5 file (or the heights of a NetCDF-4 file).
pub fn read(path: &Path, data: &[u8], channel: Option<&str>) -> Result<HeightMap> {
    let options = OpenOptions::default()
        .with_max_read_bytes(MAX_PLANE_BYTES)
        .with_max_chunk_bytes(MAX_PLANE_BYTES);
    let file = Hdf5File::from_bytes_with_options(data, options).map_err(h5(path))?;
    let superblock = file.superblock();
    let end = superblock
        .base_address
        .saturating_add(superblock.eof_address);
    if end > data.len() as u64 {
        return Err(bad(
            path,
            format!(
                "file is truncated: the HDF5 superblock puts its end at byte {end}, the file has {}",
                data.len()
            ),
        ));
    }
    let root = file.root_group().map_err(h5(path))?;
    if super::jpk_h5::is_jpk_h5(&root) {
        return super::jpk_h5::read(path, &root, channel, &h5(path));
    }
    let mut datasets = Vec::new();
    collect(path, &root, "", 0, &mut datasets)?;
    // Zygo DATX: the instrument's calibration lives in its `MetaData` table and in converter
    // attributes of `Measurement/Surface`; read as plain datasets its heights would be in an
    // unknown unit.
    let has = |name: &str| datasets.iter().any(|(n, _)| n == name);
    if has("MetaData") && datasets.iter().any(|(n, _)| n.starts_with("Measurement/")) {
        return Err(unsupported(
            path,
            "a Zygo DATX file (HDF5 with a MetaData table and a Measurement group): not read by \
             contactscope (no sample file to test a reader on); export the map as .gsf or a \
             text matrix",
        ));
    }
    if let Some(map) = netcdf4(path, &datasets, channel)? {
        return Ok(map);
    }
    if let Some(map) = topostats(path, &datasets, channel)? {
        return Ok(map);
    }
    let maps: Vec<&(String, hdf5_reader::Dataset)> = datasets
        .iter()
        .filter(|(_, d)| d.shape().len() == 2 && numeric(d.dtype()))
        .collect();
    if maps.is_empty() {
        if let Some((_, d)) = datasets
            .iter()
            .find(|(_, d)| d.shape().len() == 1 && numeric(d.dtype()))
        {
            let n = d.shape().first().copied().unwrap_or(0);
            return Err(line_scan(
                path,
                usize::try_from(n).unwrap_or(usize::MAX),
                None,
            ));
        }
        return Err(bad(path, "the HDF5 file holds no numeric 2-D dataset"));
    }
    let channels: Vec<ChannelEntry> = maps
        .iter()
        .map(|(name, _)| ChannelEntry {
            name: name.clone(),
            height: height_like(name),
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let (_, dataset) = maps[index];
    let (ny, nx) = shape2(path, dataset.shape())?;
    grid_bytes(path, nx, ny, 8)?;
    let heights = values(dataset).map_err(h5(path))?;
    height_map(
        path,
        TopographyFormat::Hdf5,
        (&channels, index),
        (ny, nx),
        heights,
        (f64::NAN, f64::NAN),
    )
}

/// The datasets below `group`, by path, depth first.
fn collect(
    path: &Path,
    group: &hdf5_reader::group::Group,
    prefix: &str,
    depth: usize,
    out: &mut Vec<(String, hdf5_reader::Dataset)>,
) -> Result<()> {
    let (groups, datasets) = group.members().map_err(h5(path))?;
    for d in datasets {
        if out.len() >= MAX_DATASETS {
            return Err(unsupported(
                path,
                format!("the HDF5 file holds more than {MAX_DATASETS} datasets"),
            ));
        }
        out.push((format!("{prefix}{}", d.name()), d));
    }
    if depth < MAX_DEPTH {
        for g in groups {
            let prefix = format!("{prefix}{}/", g.name());
            collect(path, &g, &prefix, depth + 1, out)?;
        }
    }
    Ok(())
}

/// Whether values of this type are read (integers and IEEE floats of 4 or 8 bytes).
fn numeric(dtype: &Datatype) -> bool {
    matches!(
        dtype,
        Datatype::FixedPoint {
            size: 1 | 2 | 4 | 8,
            ..
        } | Datatype::FloatingPoint { size: 4 | 8, .. }
    )
}

/// `(rows, columns)` of a 2-D shape, each at least 1 and within `usize`.
fn shape2(path: &Path, shape: &[u64]) -> Result<(usize, usize)> {
    let dim = |i: usize| {
        shape
            .get(i)
            .and_then(|&n| usize::try_from(n).ok())
            .filter(|&n| n > 0)
            .ok_or_else(|| bad(path, format!("HDF5 dataset of shape {shape:?}")))
    };
    Ok((dim(0)?, dim(1)?))
}

/// Every value of a numeric dataset as f64, in row-major order.
pub(super) fn values(
    d: &hdf5_reader::Dataset,
) -> std::result::Result<Vec<f64>, hdf5_reader::error::Error> {
    macro_rules! as_f64 {
        ($t:ty) => {
            d.read_array::<$t>()?.iter().map(|&v| v as f64).collect()
        };
    }
    Ok(match d.dtype() {
        Datatype::FloatingPoint { size: 4, .. } => as_f64!(f32),
        Datatype::FixedPoint {
            size: 1,
            signed: true,
            ..
        } => as_f64!(i8),
        Datatype::FixedPoint { size: 1, .. } => as_f64!(u8),
        Datatype::FixedPoint {
            size: 2,
            signed: true,
            ..
        } => as_f64!(i16),
        Datatype::FixedPoint { size: 2, .. } => as_f64!(u16),
        Datatype::FixedPoint {
            size: 4,
            signed: true,
            ..
        } => as_f64!(i32),
        Datatype::FixedPoint { size: 4, .. } => as_f64!(u32),
        Datatype::FixedPoint {
            size: 8,
            signed: true,
            ..
        } => as_f64!(i64),
        Datatype::FixedPoint { size: 8, .. } => as_f64!(u64),
        _ => d.read_array::<f64>()?.into_iter().collect(),
    })
}

/// The TopoStats images (`image`, `image_original`, nm) on pixels of `pixel_to_nm_scaling` nm, or
/// `None` for another HDF5 file.
fn topostats(
    path: &Path,
    datasets: &[(String, hdf5_reader::Dataset)],
    channel: Option<&str>,
) -> Result<Option<HeightMap>> {
    let find = |name: &str| datasets.iter().find(|(n, _)| n == name).map(|(_, d)| d);
    let (Some(_), Some(scaling)) = (find("image"), find("pixel_to_nm_scaling")) else {
        return Ok(None);
    };
    if !scaling.shape().iter().all(|&n| n == 1) || !numeric(scaling.dtype()) {
        return Ok(None);
    }
    let nm_per_pixel = values(scaling)
        .map_err(h5(path))?
        .first()
        .copied()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| {
            bad(
                path,
                "TopoStats pixel_to_nm_scaling is not a positive number",
            )
        })?;
    let images: Vec<(&str, &hdf5_reader::Dataset)> = ["image", "image_original"]
        .into_iter()
        .filter_map(|name| find(name).map(|d| (name, d)))
        .filter(|(_, d)| d.shape().len() == 2 && numeric(d.dtype()))
        .collect();
    if images.is_empty() {
        return Err(bad(
            path,
            "TopoStats file whose image is not a numeric 2-D dataset",
        ));
    }
    let channels: Vec<ChannelEntry> = images
        .iter()
        .map(|(name, _)| ChannelEntry {
            name: name.to_string(),
            height: true,
        })
        .collect();
    let index = choose(path, &channels, channel)?;
    let dataset = images[index].1;
    let (ny, nx) = shape2(path, dataset.shape())?;
    grid_bytes(path, nx, ny, 8)?;
    let heights = values(dataset)
        .map_err(h5(path))?
        .into_iter()
        .map(|h| h * 1e-9)
        .collect();
    let pixel = nm_per_pixel * 1e-9;
    height_map(
        path,
        TopographyFormat::TopoStats,
        (&channels, index),
        (ny, nx),
        heights,
        (pixel, pixel),
    )
    .map(Some)
}

/// The height map of a NetCDF-4 file laid out as SurfaceTopography writes it (a `heights`
/// dataset and `x`/`y` coordinate datasets), or `None` for another HDF5 file.
fn netcdf4(
    path: &Path,
    datasets: &[(String, hdf5_reader::Dataset)],
    channel: Option<&str>,
) -> Result<Option<HeightMap>> {
    let find = |name: &str| datasets.iter().find(|(n, _)| n == name).map(|(_, d)| d);
    let (Some(heights), Some(x)) = (find("heights"), find("x")) else {
        return Ok(None);
    };
    let y = find("y");
    let mask = find("mask");
    let describe = |name: &str, d: &hdf5_reader::Dataset, dims: Vec<&str>| -> Result<Variable> {
        let shape = d
            .shape()
            .iter()
            .map(|&n| usize::try_from(n).map_err(|_| bad(path, "HDF5 dataset too large")))
            .collect::<Result<Vec<usize>>>()?;
        Ok(Variable {
            name: name.into(),
            dims: dims.iter().map(|s| s.to_string()).zip(shape).collect(),
            attrs: d
                .attributes()
                .into_iter()
                .filter_map(|a| {
                    let value = match a.read_string() {
                        Ok(s) => Attr::Text(s),
                        Err(_) => Attr::Numbers(vec![a.read_as_f64().ok()?]),
                    };
                    Some((a.name.clone(), value))
                })
                .collect(),
        })
    };
    // Dimension names are not read from NetCDF-4's dimension scales: the heights' axes are
    // matched to the lengths of `x` and `y` (SurfaceTopography writes `heights(x, y)`).
    let nx = x.shape().first().copied().unwrap_or(0);
    let ny = y.and_then(|y| y.shape().first().copied());
    let dims = match (heights.shape(), ny) {
        ([a], None) if *a == nx => vec!["x"],
        ([a, b], Some(ny)) if *a == ny && *b == nx && nx != ny => vec!["y", "x"],
        ([a, b], Some(ny)) if *a == nx && *b == ny => vec!["x", "y"],
        _ => return Ok(None),
    };
    let mut vars = vec![
        describe("heights", heights, dims)?,
        describe("x", x, vec!["x"])?,
    ];
    if let Some(y) = y {
        vars.push(describe("y", y, vec!["y"])?);
    }
    let layout = netcdf::layout(path, &vars, channel)?;
    grid_bytes(path, layout.nx, layout.ny, 8)?;
    let stored = values(heights).map_err(h5(path))?;
    let mask = match mask {
        Some(m) => Some(values(m).map_err(h5(path))?),
        None => None,
    };
    layout.height_map(path, &stored, mask.as_deref()).map(Some)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::topography::test_support::truncations_and_corruptions;

    #[test]
    fn not_hdf5_is_an_error_naming_the_file() {
        let p = Path::new("x.h5");
        let err = read(p, b"\x89HDF\r\n\x1a\n\0\0\0", None)
            .unwrap_err()
            .to_string();
        assert!(err.contains("x.h5"), "{err}");
    }

    #[test]
    fn topostats_files_carry_their_calibration() {
        // fixtures/topostats/tiny.topostats (tests/data/topostats_fixture.py, h5py): heights in
        // nm from a formula, 2.5 nm pixels, a grain mask beside the images.
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/topostats/tiny.topostats");
        let data = std::fs::read(&path).unwrap();
        let m = read(&path, &data, None).unwrap();
        assert_eq!(m.format, TopographyFormat::TopoStats);
        assert_eq!(m.channels, ["image", "image_original"]);
        assert_eq!((m.channel.as_str(), m.ny(), m.nx()), ("image", 6, 8));
        assert_eq!((m.dx_m, m.dy_m), (2.5e-9, 2.5e-9));
        let formula =
            |i: usize, j: usize| 0.5 * i as f64 - 0.25 * j as f64 + 0.125 * (i * j) as f64;
        for ((i, j), h) in m.heights.indexed_iter() {
            assert!(
                (h - formula(i, j) * 1e-9).abs() < 1e-24,
                "({i}, {j}): {h:e}"
            );
        }
        let original = read(&path, &data, Some("image_original")).unwrap();
        for ((i, j), h) in original.heights.indexed_iter() {
            let want = (formula(i, j) + 3.0 + 0.5 * j as f64) * 1e-9;
            assert!((h - want).abs() < 1e-24, "({i}, {j}): {h:e}");
        }
        // The grain mask is not a height: asking for it names the two images.
        let err = read(&path, &data, Some("grain")).unwrap_err().to_string();
        assert!(err.contains("'image', 'image_original'"), "{err}");
        truncations_and_corruptions(&path, &data, |d| read(&path, d, None).map(|_| ()));
    }

    #[test]
    fn real_file_lists_its_datasets_and_states_no_pixel_size() {
        let path = &crate::topography::test_support::sample("multiple_data_sets.h5");
        let Ok(data) = std::fs::read(path) else {
            return;
        };
        // Two datasets, neither named as heights: one must be chosen.
        let err = read(path, &data, None).unwrap_err().to_string();
        assert!(err.contains("'dataset1', 'dataset2'"), "{err}");
        let m = read(path, &data, Some("dataset1")).unwrap();
        assert_eq!((m.ny(), m.nx(), m.invalid_points), (256, 256, 0));
        assert_eq!(m.channels, ["dataset1", "dataset2"]);
        assert!(m.dx_m.is_nan() && m.dy_m.is_nan());
        // h5py: float64, min −0.6299615478515626, max −0.4643220520019532.
        let s = crate::topography::test_support::stats(&m.heights);
        assert_eq!((s.min, s.max), (-0.6299615478515626, -0.4643220520019532));
        let m = read(path, &data, Some("dataset2")).unwrap();
        assert_eq!((m.ny(), m.nx()), (640, 480));
        let s = crate::topography::test_support::stats(&m.heights);
        assert_eq!(
            (s.min as f32, s.max as f32),
            (-0.00035255696f32, 0.00057729497f32)
        );
        truncations_and_corruptions(path, &data, |d| read(path, d, Some("dataset2")).map(|_| ()));
    }

    #[test]
    fn read_height_map_asks_for_the_pixel_size_and_takes_a_height_unit() {
        use crate::topography::{detect, read_height_map, ReadOptions};
        let path = &crate::topography::test_support::sample("multiple_data_sets.h5");
        let Ok(data) = std::fs::read(path) else {
            return;
        };
        assert_eq!(detect(&data), Some(TopographyFormat::Hdf5));
        let mut options = ReadOptions {
            channel: Some("dataset1".into()),
            ..ReadOptions::default()
        };
        let err = read_height_map(path, &options).unwrap_err().to_string();
        assert!(
            err.contains("multiple_data_sets.h5")
                && err.contains("the hdf5 file states no pixel size")
                && err.contains(&crate::param::Param::PixelSize.to_string()),
            "{err}"
        );
        options.pixel_size_m = Some((1e-6, 1e-6));
        let metres = read_height_map(path, &options).unwrap();
        options.height_unit_m = Some(1e-6);
        let micrometres = read_height_map(path, &options).unwrap();
        assert_eq!(micrometres.dx_m, 1e-6);
        let (a, b) = (metres.heights[[3, 7]], micrometres.heights[[3, 7]]);
        assert!((b - a * 1e-6).abs() <= 1e-15 * a.abs(), "{a} {b}");
    }
}
