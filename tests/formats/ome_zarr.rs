//! OME-Zarr stores: read as load series (NGFF 0.4 on Zarr v2, 0.5 on Zarr v3, chunks that split
//! a plane or hold several), analysed with the same threshold, areas and pixel size as the same
//! planes in a TIFF; the masks and the table written back (`--zarr-out`) into the store analysed
//! and into a new one; the batch taking stores whole; clear errors for what is not read.
//!
//! The stores here are written byte by byte from the Zarr and NGFF specifications (JSON
//! metadata, raw little-endian chunks), not by the library under test; stores written by
//! ome-zarr-py and ngff-zarr are read in `python/tests/test_ome_zarr.py`.

use std::path::{Path, PathBuf};

use serde_json::json;

use crate::common::{read_csv, run, run_ok, stderr};
use contactscope_formats::microscopy::{MicroscopyFile, PlaneIndex};

const W: usize = 96;
const H: usize = 80;
const N: usize = 4;

/// Four planes of a growing contact: a bright disc on a dim background with a fixed pattern of
/// noise (no random source: the test is the same every run).
pub(super) fn planes() -> Vec<Vec<u16>> {
    (0..N)
        .map(|t| {
            let r = 8.0 + 7.0 * t as f64;
            (0..W * H)
                .map(|i| {
                    let (x, y) = ((i % W) as f64 - 47.5, (i / W) as f64 - 39.5);
                    let noise = ((i * 7919 + t * 104_729) % 61) as u16;
                    let base = if x * x + y * y < r * r { 1800 } else { 120 };
                    base + noise
                })
                .collect()
        })
        .collect()
}

fn le(v: &[u16]) -> Vec<u8> {
    v.iter().flat_map(|s| s.to_le_bytes()).collect()
}

fn write_json(path: &Path, value: &serde_json::Value) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, serde_json::to_vec_pretty(value).unwrap()).unwrap();
}

/// NGFF `multiscales` for axes t, c, y, x with a 0.2 µm pixel.
fn multiscales(version: Option<&str>) -> serde_json::Value {
    let mut m = json!({
        "name": "ramp",
        "axes": [
            {"name": "t", "type": "time", "unit": "second"},
            {"name": "c", "type": "channel"},
            {"name": "y", "type": "space", "unit": "micrometer"},
            {"name": "x", "type": "space", "unit": "micrometer"}
        ],
        "datasets": [{"path": "0", "coordinateTransformations": [
            {"type": "scale", "scale": [1.0, 1.0, 0.2, 0.2]}
        ]}]
    });
    if let Some(v) = version {
        m["version"] = json!(v);
    }
    json!([m])
}

fn omero() -> serde_json::Value {
    json!({"channels": [{"label": "rigidochromic", "color": "00FF00",
        "window": {"min": 0, "max": 4095, "start": 0, "end": 4095}}]})
}

/// An NGFF 0.4 store on Zarr v2: one chunk per plane, no compressor.
pub(super) fn store_v2(dir: &Path, planes: &[Vec<u16>]) -> PathBuf {
    let store = dir.join("ramp04.ome.zarr");
    write_json(&store.join(".zgroup"), &json!({"zarr_format": 2}));
    write_json(
        &store.join(".zattrs"),
        &json!({"multiscales": multiscales(Some("0.4")), "omero": omero()}),
    );
    write_json(
        &store.join("0/.zarray"),
        &json!({"zarr_format": 2, "shape": [N, 1, H, W], "chunks": [1, 1, H, W],
            "dtype": "<u2", "compressor": null, "fill_value": 0, "order": "C",
            "filters": null, "dimension_separator": "/"}),
    );
    for (t, p) in planes.iter().enumerate() {
        let chunk = store.join(format!("0/{t}/0/0/0"));
        std::fs::create_dir_all(chunk.parent().unwrap()).unwrap();
        std::fs::write(chunk, le(p)).unwrap();
    }
    store
}

/// An NGFF 0.5 store on Zarr v3 whose chunks hold two planes and split each plane in four
/// (chunk shape 2 × 1 × H/2 × W/2): a plane is read from four chunks, a chunk serves two planes.
pub(super) fn store_v3(dir: &Path, planes: &[Vec<u16>]) -> PathBuf {
    let store = dir.join("ramp05.ome.zarr");
    write_json(
        &store.join("zarr.json"),
        &json!({"zarr_format": 3, "node_type": "group", "attributes": {"ome": {
            "version": "0.5", "multiscales": multiscales(None), "omero": omero()}}}),
    );
    let (cy, cx) = (H / 2, W / 2);
    write_json(
        &store.join("0/zarr.json"),
        &json!({"zarr_format": 3, "node_type": "array", "shape": [N, 1, H, W],
            "data_type": "uint16",
            "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [2, 1, cy, cx]}},
            "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
            "fill_value": 0,
            "codecs": [{"name": "bytes", "configuration": {"endian": "little"}}],
            "dimension_names": ["t", "c", "y", "x"]}),
    );
    for ct in 0..N / 2 {
        for by in 0..2 {
            for bx in 0..2 {
                let mut chunk = Vec::new();
                for plane in &planes[2 * ct..2 * ct + 2] {
                    for y in by * cy..(by + 1) * cy {
                        chunk.extend_from_slice(&plane[y * W + bx * cx..y * W + (bx + 1) * cx]);
                    }
                }
                let key = store.join(format!("0/c/{ct}/0/{by}/{bx}"));
                std::fs::create_dir_all(key.parent().unwrap()).unwrap();
                std::fs::write(key, le(&chunk)).unwrap();
            }
        }
    }
    store
}

/// The same planes as a TIFF with the same pixel size.
pub(super) fn tiff(dir: &Path, planes: &[Vec<u16>]) -> PathBuf {
    let path = dir.join("ramp.tif");
    let refs: Vec<&[u16]> = planes.iter().map(Vec::as_slice).collect();
    let bytes =
        contactscope_formats::tiff::encode_u16_stack(&refs, W, H, Some((2e-7, 2e-7)), "").unwrap();
    std::fs::write(&path, bytes).unwrap();
    path
}

pub(super) fn analyze(input: &Path, out: &Path, extra: &[&str]) -> (Vec<String>, Vec<Vec<String>>) {
    let mut args = vec![
        "analyze",
        input.to_str().unwrap(),
        "--forces",
        "4mN..400mN:4",
        "--out",
        out.to_str().unwrap(),
    ];
    if input.extension().is_none_or(|e| e != "tif") {
        args.extend(["--load-axis", "t"]);
    }
    args.extend(extra);
    run_ok(&args);
    read_csv(&out.join("areas.csv"))
}

/// Every column but the file name.
pub(super) fn numbers(table: &(Vec<String>, Vec<Vec<String>>)) -> Vec<Vec<String>> {
    table.1.iter().map(|r| r[1..].to_vec()).collect()
}

#[test]
fn stores_of_both_versions_analyse_as_the_same_planes_in_a_tiff() {
    let dir = tempfile::tempdir().unwrap();
    let planes = planes();
    let reference = analyze(&tiff(dir.path(), &planes), &dir.path().join("t"), &[]);
    for (k, store) in [store_v2(dir.path(), &planes), store_v3(dir.path(), &planes)]
        .iter()
        .enumerate()
    {
        // The planes themselves, sample for sample.
        let mut file = MicroscopyFile::open(store).unwrap();
        let s = &file.series[0];
        assert_eq!((s.axes.t, s.axes.c, s.axes.y, s.axes.x), (N, 1, H, W));
        assert_eq!(s.channels[0].name.as_deref(), Some("rigidochromic"));
        assert_eq!(
            (s.pixel_size.x_m, s.pixel_size.y_m),
            (Some(2e-7), Some(2e-7))
        );
        for (t, p) in planes.iter().enumerate() {
            let read = file.read_plane(0, &PlaneIndex::tzc(t, 0, 0)).unwrap();
            let expected: Vec<f64> = p.iter().map(|&v| f64::from(v)).collect();
            assert_eq!(read.to_f64(), expected, "store {k}, plane {t}");
        }
        // The analysis: threshold, pixels, areas and intervals equal to the TIFF's.
        let table = analyze(
            store,
            &dir.path().join(format!("z{k}")),
            &["--channel", "rigidochromic"],
        );
        assert_eq!(table.0, reference.0);
        assert_eq!(numbers(&table), numbers(&reference), "store {k}");
        let summary: serde_json::Value = serde_json::from_slice(
            &std::fs::read(dir.path().join(format!("z{k}/summary.json"))).unwrap(),
        )
        .unwrap();
        let text = summary.to_string();
        assert!(text.contains("OME-Zarr"), "{text}");
    }
}

/// Every file below a folder with its bytes, in path order.
fn files_below(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(files_below(&path));
        } else {
            out.push((path.clone(), std::fs::read(&path).unwrap()));
        }
    }
    out.sort();
    out
}

/// The contact pixels of each plane of a label image read back through the reader.
fn label_pixels(store: &Path) -> Vec<f64> {
    let mut labels = MicroscopyFile::open(store).unwrap();
    let axes = labels.series[0].axes.clone();
    assert_eq!(axes.c, 1, "a label image has one channel");
    (0..axes.t)
        .map(|t| {
            let plane = labels.read_plane(0, &PlaneIndex::tzc(t, 0, 0)).unwrap();
            plane.to_f64().iter().sum()
        })
        .collect()
}

#[test]
fn masks_and_table_go_into_the_store_analysed_and_into_a_new_one() {
    let dir = tempfile::tempdir().unwrap();
    let planes = planes();
    for store in [store_v2(dir.path(), &planes), store_v3(dir.path(), &planes)] {
        let image_before = files_below(&store.join("0"));
        let out = dir.path().join(format!(
            "o-{}",
            store.file_name().unwrap().to_string_lossy()
        ));
        let arg = store.to_str().unwrap().to_string();
        let table = analyze(&store, &out, &["--zarr-out", &arg]);
        let pixels = crate::common::column(&table.0, &table.1, "contact_pixels");
        // Into the store: labels beside the image, which is unchanged.
        assert_eq!(label_pixels(&store.join("labels/contact")), pixels);
        let meta = if store.join("zarr.json").exists() {
            "zarr.json"
        } else {
            ".zattrs"
        };
        let labels = std::fs::read_to_string(store.join("labels").join(meta)).unwrap();
        assert!(labels.contains("\"contact\""), "{labels}");
        assert_eq!(files_below(&store.join("0")), image_before);
        let parquet = store.join("tables/contact_areas/table.parquet");
        assert!(std::fs::read(&parquet).unwrap().starts_with(b"PAR1"));
        // A second run replaces what the first wrote (and nothing hidden is left).
        analyze(&store, &out.with_extension("2"), &["--zarr-out", &arg]);
        let hidden: Vec<_> = std::fs::read_dir(store.join("labels"))
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().contains("partial"))
            .collect();
        assert!(hidden.is_empty(), "{hidden:?}");
        assert_eq!(label_pixels(&store.join("labels/contact")), pixels);
    }
    // A new store from the TIFF: its image analyses as the TIFF did, its labels are the masks.
    let tif = tiff(dir.path(), &planes);
    let new = dir.path().join("new.ome.zarr");
    let reference = analyze(
        &tif,
        &dir.path().join("t"),
        &["--zarr-out", new.to_str().unwrap()],
    );
    let again = analyze(&new, &dir.path().join("t2"), &[]);
    assert_eq!(numbers(&again), numbers(&reference));
    let pixels = crate::common::column(&reference.0, &reference.1, "contact_pixels");
    assert_eq!(label_pixels(&new.join("labels/contact")), pixels);
}

#[test]
fn what_cannot_be_written_or_read_is_refused_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let planes = planes();
    let store = store_v3(dir.path(), &planes);
    let out = dir.path().join("o");
    let s = store.to_str().unwrap();
    // Someone else's `labels/contact` is not replaced; nothing is written.
    write_json(
        &store.join("labels/contact/zarr.json"),
        &json!({"zarr_format": 3, "node_type": "group", "attributes": {}}),
    );
    let o = run(&[
        "analyze",
        s,
        "--load-axis",
        "t",
        "--forces",
        "4mN..400mN:4",
        "--out",
        out.to_str().unwrap(),
        "--zarr-out",
        s,
    ]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("not written by contactscope"),
        "{e}"
    );
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(!out.exists() && !store.join("tables").exists());
    // An analysis that fails after the output was begun leaves no store, hidden or not.
    let blank = dir.path().join("blank.tif");
    let zeros = vec![0u16; W * H];
    std::fs::write(
        &blank,
        contactscope_formats::tiff::encode_u16_stack(&[&zeros, &zeros], W, H, None, "").unwrap(),
    )
    .unwrap();
    let new = dir.path().join("new.ome.zarr");
    let o = run(&[
        "analyze",
        blank.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--zarr-out",
        new.to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "{}", stderr(&o));
    let left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("new.ome.zarr"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // A plane whose chunks are all missing (an incomplete copy) is refused, not read as zeros.
    let partial = store_v2(&dir.path().join("p"), &planes);
    std::fs::remove_dir_all(partial.join("0/2")).unwrap();
    let o = run(&[
        "analyze",
        partial.to_str().unwrap(),
        "--load-axis",
        "t",
        "--forces",
        "4mN..400mN:4",
        "--out",
        dir.path().join("op").to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(
        !o.status.success() && e.contains("none of its chunks"),
        "{e}"
    );
    assert!(e.contains("plane t 2"), "{e}");
    // An existing path that is not the store analysed.
    let o = run(&[
        "analyze",
        s,
        "--load-axis",
        "t",
        "--forces",
        "4mN..400mN:4",
        "--out",
        out.to_str().unwrap(),
        "--zarr-out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(stderr(&o).contains("exists"), "{}", stderr(&o));
    // A folder that is no store, a store without images, an unreadable data type, no y axis.
    let plain = dir.path().join("plain");
    std::fs::create_dir_all(&plain).unwrap();
    let empty = dir.path().join("empty.zarr");
    write_json(
        &empty.join("zarr.json"),
        &json!({"zarr_format": 3, "node_type": "group", "attributes": {}}),
    );
    let complex = store_v3(&dir.path().join("c"), &planes);
    let mut meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(complex.join("0/zarr.json")).unwrap()).unwrap();
    meta["data_type"] = json!("complex64");
    write_json(&complex.join("0/zarr.json"), &meta);
    let flat = store_v3(&dir.path().join("f"), &planes);
    let mut group: serde_json::Value =
        serde_json::from_slice(&std::fs::read(flat.join("zarr.json")).unwrap()).unwrap();
    group["attributes"]["ome"]["multiscales"][0]["axes"][2]["name"] = json!("q");
    write_json(&flat.join("zarr.json"), &group);
    // Chunks far larger than memory, refused from the metadata before any is decoded.
    let huge = store_v3(&dir.path().join("h"), &planes);
    let mut meta: serde_json::Value =
        serde_json::from_slice(&std::fs::read(huge.join("0/zarr.json")).unwrap()).unwrap();
    meta["chunk_grid"]["configuration"]["chunk_shape"] = json!([1, 1, 200_000, 200_000]);
    write_json(&huge.join("0/zarr.json"), &meta);
    for (path, expected) in [
        (&huge, "exceeds"),
        (&plain, "not a Zarr store"),
        (&empty, "without OME-Zarr images"),
        (&complex, "complex64"),
        (&flat, "have no 'y' and 'x'"),
    ] {
        let o = run(&["info", path.to_str().unwrap()]);
        let e = stderr(&o);
        assert!(
            !o.status.success() && e.contains(expected),
            "{}: {e}",
            path.display()
        );
        assert!(
            e.contains(&*path.file_name().unwrap().to_string_lossy()),
            "{e}"
        );
        assert_eq!(e.trim().lines().count(), 1, "{e}");
    }
}

#[test]
fn a_batch_takes_each_store_whole_and_hashes_it() {
    let dir = tempfile::tempdir().unwrap();
    let planes = planes();
    let archive = dir.path().join("archive");
    let glass = archive.join("glass");
    std::fs::create_dir_all(&glass).unwrap();
    store_v2(&glass, &planes);
    store_v3(&glass, &planes);
    let out = dir.path().join("res");
    let args = [
        "batch",
        archive.to_str().unwrap(),
        "--load-axis",
        "t",
        "--forces",
        "4mN..400mN:4",
        "--out",
        out.to_str().unwrap(),
    ];
    run_ok(&args);
    let (header, rows) = read_csv(&out.join("samplesheet.csv"));
    let ids: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(ids, ["glass-ramp04", "glass-ramp05"], "{header:?}");
    let record: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("records/glass-ramp05.json")).unwrap())
            .unwrap();
    let text = record.to_string();
    assert!(
        text.contains("ramp05.ome.zarr") && text.contains("sha256"),
        "{text}"
    );
    // A changed chunk is a changed input: the series is analysed again.
    let chunk = glass.join("ramp05.ome.zarr/0/c/0/0/0/0");
    let mut bytes = std::fs::read(&chunk).unwrap();
    bytes[0] ^= 1;
    std::fs::write(&chunk, bytes).unwrap();
    let o = run_ok(&args);
    let said = String::from_utf8_lossy(&o.stderr).to_string() + &String::from_utf8_lossy(&o.stdout);
    assert!(said.contains("1 analysed, 1 reused"), "{said}");
}
