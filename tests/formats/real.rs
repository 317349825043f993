//! Every sample file of `../shared/data/real-formats` (and the vendor files of
//! `../shared/data/real-afm`) read by `contactscope_formats` gives the dimensions, pixel sizes and
//! statistics that trusted Python readers give; truncated and corrupted copies give one clean
//! error naming the file. Skipped with a message when the shared data are absent.
//!
//! References:
//! * Confocal planes: `tests/data/real_formats_planes.csv`, written by
//!   `tests/data/real_formats_reference.py` (pylibCZIrw 6.1.0, nd2 0.12.0, liffile 2026.2.16);
//!   min, max and sum of every plane must agree exactly (integer images).
//! * Confocal pixel sizes: the same readers' metadata (`Scaling/Items/Distance/Value` as
//!   pylibCZIrw's metadata dict prints it; `ND2File.voxel_size()`; liffile's coordinate steps).
//! * Height maps: SurfaceTopography 1.27.1, `open_topography(path).topography(channel_index=0)`,
//!   heights converted to m with its `unit` (mask → invalid points); `valid`, min, max, mean
//!   and rms (about the mean, `np.sqrt(((h - mean)**2).mean())` over valid points) printed with
//!   `repr`; compared to 1e-6 relative (the mean to 1e-6 of the rms, as it can be ~0).
//!   Gwyddion's `test.gwy` with gwyfile 0.3.0 (`get_datafields`), whose units are empty.

// Reference values are kept digit for digit as the Python readers print them.
#![allow(clippy::excessive_precision)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use contactscope_formats::microscopy::summary::info_summary;
use contactscope_formats::microscopy::MicroscopyFile;
use contactscope_formats::topography::{self, detect_file};
use contactscope_jobs::heights::read_topography;
use contactscope_jobs::topography::topography_summary;

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        ((a - b) / b).abs()
    }
}

/// Rows of the reference CSV: (file, series, plane key) → (min, max, sum).
fn plane_references() -> HashMap<(String, usize, String), (i64, i64, i64)> {
    let (_, rows) =
        crate::common::read_csv(&crate::common::root().join("tests/data/real_formats_planes.csv"));
    rows.into_iter()
        .map(|r| {
            let n = |i: usize| r[i].parse::<i64>().unwrap();
            (
                (r[0].clone(), r[1].parse().unwrap(), r[2].clone()),
                (n(3), n(4), n(5)),
            )
        })
        .collect()
}

/// (file, series, axes "T,Z,C,Y,X[,extra=n]", dtype, x m, y m, z m, first channel name)
type Dims = (
    &'static str,
    usize,
    &'static str,
    &'static str,
    Option<f64>,
    Option<f64>,
    Option<f64>,
    Option<&'static str>,
);

#[rustfmt::skip]
const CONFOCAL: &[Dims] = &[
    ("czi/CellDivision_T3_Z5_CH2_X240_Y170.czi", 0, "3,5,2,170,240", "uint16", Some(9.0576674152210312E-08), Some(9.0576674152210312E-08), Some(3.2E-07), Some("LED555")),
    ("czi/LSM880_AiryScan.czi", 0, "1,1,8,36,38,H=32", "uint16", Some(3.52979560689887E-08), Some(3.5297956068988692E-08), Some(1.594517652019319E-07), Some("ChA-T1")),
    ("czi/RGB-multichannel.czi", 0, "1,1,7,81,147,S=3", "uint8", Some(2.9584899946757142E-06), Some(2.9584899946757142E-06), None, Some("Bright")),
    // Scaling values are 0 in this file: absent.
    ("czi/newCZI_compressed.czi", 0, "1,1,1,512,512", "uint16", None, None, None, None),
    ("czi/s_1_t_1_c_1_z_1.czi", 0, "1,1,1,325,475", "uint16", Some(1.0833333333333333E-06), Some(1.0833333333333333E-06), None, Some("Bright")),
    ("nd2/cluster.nd2", 0, "3,10,2,31,38", "uint16", Some(0.16780898323268245e-6), Some(0.16780898323268245e-6), Some(0.5e-6), Some("5-FAM/pH 9.0")),
    ("lif/LeicaLASX_wavelength-sweep_example.lif", 0, "1,1,1,64,64,lambda_emission=20", "uint8", Some(6.603309e-6 / 63.0), Some(6.603309e-6 / 63.0), None, None),
    ("lif/LeicaLASX_wavelength-sweep_example.lif", 1, "1,1,1,64,64,lambda_excitation=15", "uint8", Some(6.603309e-6 / 63.0), Some(6.603309e-6 / 63.0), None, None),
    ("lif/LeicaLASX_wavelength-sweep_example.lif", 2, "2,11,1,64,64,lambda_emission=10", "uint8", Some(6.603309e-6 / 63.0), Some(6.603309e-6 / 63.0), Some(5.002027e-6 / 10.0), None),
];

fn close_opt(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => rel(a, b) < 1e-9,
        _ => false,
    }
}

#[test]
fn confocal_files_match_the_trusted_readers() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    let refs = plane_references();
    let mut planes_checked = 0;
    for &(file, series, axes, dtype, x, y, z, channel) in CONFOCAL {
        let path = dir.join(file);
        let summary = info_summary(&path, true).unwrap_or_else(|e| panic!("{file}: {e}"));
        let s = &summary.series[series];
        let a = &s.axes;
        let mut got = format!("{},{},{},{},{}", a.t, a.z, a.c, a.y, a.x);
        for (k, n) in &a.extra {
            got += &format!(",{k}={n}");
        }
        assert_eq!(got, axes, "{file} series {series}");
        assert_eq!(s.dtype, dtype, "{file}");
        let um = |m: Option<f64>| m.map(|v| v * 1e6);
        assert!(
            close_opt(s.pixel_size_um.x, um(x)),
            "{file}: x {:?} vs {x:?}",
            s.pixel_size_um.x
        );
        assert!(
            close_opt(s.pixel_size_um.y, um(y)),
            "{file}: y {:?}",
            s.pixel_size_um.y
        );
        assert!(
            close_opt(s.pixel_size_um.z, um(z)),
            "{file}: z {:?}",
            s.pixel_size_um.z
        );
        assert_eq!(s.pixel_size_source.is_some(), x.is_some(), "{file}");
        let file_handle = MicroscopyFile::open(&path).unwrap();
        let name = file_handle.series[series]
            .channels
            .first()
            .and_then(|c| c.name.clone());
        assert_eq!(name.as_deref(), channel, "{file}: channel name");
        let planes = s.planes.as_ref().unwrap();
        let expected = refs.keys().filter(|k| k.0 == file && k.1 == series).count();
        assert_eq!(
            planes.len(),
            expected,
            "{file} series {series}: plane count"
        );
        for p in planes {
            let mut key = format!("t={};z={};c={}", p.index.t, p.index.z, p.index.c);
            for (k, v) in &p.index.extra {
                key += &format!(";{k}={v}");
            }
            let &(min, max, sum) = refs
                .get(&(file.to_string(), series, key.clone()))
                .unwrap_or_else(|| panic!("{file}: no reference for {key}"));
            assert_eq!(
                (p.min, p.max, p.sum),
                (min as f64, max as f64, sum as f64),
                "{file} {key}"
            );
            planes_checked += 1;
        }
    }
    // Every row of the reference table was compared.
    assert_eq!(planes_checked, refs.len());
}

/// SurfaceTopography 1.27.1 numbers (module docs): file, channel, nx, ny, dx m, dy m, valid,
/// min m, max m, mean m, rms m.
type HeightRow = (
    &'static str,
    &'static str,
    usize,
    usize,
    f64,
    f64,
    usize,
    f64,
    f64,
    f64,
    f64,
);

#[rustfmt::skip]
const HEIGHTS: &[HeightRow] = &[
    ("ibw/spot_1-1000nm.ibw", "HeightTrace", 256, 256, 7.843137254901961e-08, 7.843137254901961e-08, 65536, -7.046238579277997e-07, -3.3123345133390103e-07, -5.38691195036984e-07, 8.945481491256412e-08),
    ("nid/nid-1.nid", "Scan forward (Z-Axis)", 256, 256, 7.8125e-08, 7.8125e-08, 65536, -1.982578380569816e-06, -9.253918035998941e-07, -1.4467831843995989e-06, 2.395896706764167e-07),
    ("mi/mi-1.mi", "Topography (Trace)", 256, 256, 7.8125e-08, 7.8125e-08, 65536, -6.299615478515625e-07, -4.643220520019532e-07, -5.588049271074125e-07, 3.3215426493512656e-08),
    ("park-tiff/example_ps.tiff", "Z Height", 512, 512, 1.953125e-09, 1.953125e-09, 262144, -1.4981494690361127e-08, 2.170887119199494e-08, -7.865169306278037e-21, 3.933333733759224e-09),
    ("gwy/test.gwy", "Test", 128, 128, 1.0, 1.0, 16384, 0.0, 0.001, 0.0005152968462939743, 0.00018771126171581148),
    ("x3p/x3p-2.x3p", "Default", 650, 650, 1.27656509837346e-07, 3.14582113527746e-07, 422500, -3.144206865877671e-07, 2.3991551341223285e-07, -2.491824169305576e-09, 7.728033273597876e-08),
    ("sdf/sdf-1.sdf", "Height", 7, 4, 1e-06, 1e-06, 28, 9.4907e-07, 1e-06, 9.835632142857143e-07, 1.3602897289488263e-08),
    ("opd/opd-1.opd", "Raw", 640, 480, 1.9673303177114576e-07, 1.9673303177114576e-07, 307084, -3.525569773640418e-07, -2.2340281517711265e-07, -2.722895251054526e-07, 8.356451162720974e-09),
    ("plu/plu-1.plu", "layer0", 768, 576, 1.6600000858306884e-06, 1.6600000858306884e-06, 442368, -0.00011123046875, -0.00010121484375, -0.00010623766881448251, 2.834390987634884e-06),
    ("sur/sur-2.sur", "Z", 563, 484, 3.4840002190321683e-06, 3.4840002190321683e-06, 272375, 8.912000104146501e-06, 1.0388000121395181e-05, 1.015737639515718e-05, 1.7517881243588177e-08),
    ("frt/frt-2.frt", "default", 150, 300, 0.00019999999999999998, 0.00019999999999999998, 32686, 2.636799218726158e-07, 0.00030365184484389785, 7.262714207028706e-05, 8.826763181113768e-06),
];

#[test]
fn height_maps_match_surface_topography() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    for &(file, channel, nx, ny, dx, dy, valid, min, max, mean, rms) in HEIGHTS {
        let path = dir.join(file);
        let s = topography_summary(&path, None).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(
            (s.channel.as_str(), s.nx, s.ny, s.valid_points),
            (channel, nx, ny, valid),
            "{file}"
        );
        assert!(
            rel(s.pixel_size.x_m, dx) < 1e-6 && rel(s.pixel_size.y_m, dy) < 1e-6,
            "{file}: pixel"
        );
        for (what, got, want) in [
            ("min", s.height_min_m, min),
            ("max", s.height_max_m, max),
            ("rms", s.h_rms_m, rms),
        ] {
            assert!(rel(got, want) < 1e-6, "{file}: {what} {got} m vs {want} m");
        }
        assert!(
            (s.height_mean_m - mean).abs() < 1e-6 * rms,
            "{file}: mean {}",
            s.height_mean_m
        );
        assert!(
            s.h_prime_rms.unwrap() > 0.0 && s.h_double_prime_rms_per_m.unwrap() > 0.0,
            "{file}"
        );
        // Format found from the content, also under another name.
        let renamed = tempfile::tempdir().unwrap();
        let copy = renamed.path().join("no_extension");
        std::fs::copy(&path, &copy).unwrap();
        assert_eq!(
            detect_file(&copy).unwrap().map(|f| f.name()),
            Some(s.format.as_str()),
            "{file}"
        );
    }
}

#[test]
fn channels_are_chosen_by_name_and_listed_when_missing() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    let ibw = dir.join("ibw/spot_1-1000nm.ibw");
    let retrace = topography::read(&ibw, Some("HeightRetrace")).unwrap();
    assert_eq!(retrace.channel, "HeightRetrace");
    // SurfaceTopography channel 1: min −6.877405667182757e-07 m.
    let min = retrace
        .heights
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    assert!(rel(min, -6.877405667182757e-07) < 1e-6, "{min}");
    let err = topography::read(&ibw, Some("Friction"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("spot_1-1000nm.ibw") && err.contains("'AmplitudeTrace'"),
        "{err}"
    );
    // Phase is not a height: refused rather than scaled as metres.
    let nid = dir.join("nid/nid-1.nid");
    let backward = topography::read(&nid, Some("Scan backward (Z-AxisSensor)")).unwrap();
    let max = backward
        .heights
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(rel(max, -2.871063219156861e-06) < 1e-6, "{max}");
    let err = topography::read(&dir.join("mi/mi-1.mi"), Some("Deflection"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("not a length"), "{err}");
}

#[test]
fn invalid_points_are_counted_and_refused_for_contact_calculations() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    let path = dir.join("opd/opd-1.opd");
    let map = topography::read(&path, None).unwrap();
    assert_eq!(
        map.invalid_points, 116,
        "SurfaceTopography masks 116 points"
    );
    let err = read_topography(&path, None, None).unwrap_err().to_string();
    assert!(err.contains("116 of 307200 points"), "{err}");
    // Maps without invalid points go through the surface reader's content-sniffing hook.
    let t = read_topography(&dir.join("x3p/x3p-2.x3p"), None, None).unwrap();
    assert!(rel(t.rms_height(), 7.728033273597876e-08) < 1e-6);
    let err = read_topography(&dir.join("sdf/sdf-1.sdf"), None, Some(1e-9)).unwrap_err();
    assert!(err.to_string().contains("states its height unit"), "{err}");
}

#[test]
fn real_afm_copies_read_the_same() {
    let (Some(afm), Some(formats)) = (
        crate::common::shared_data("real-afm"),
        crate::common::shared_data("real-formats"),
    ) else {
        return;
    };
    for (a, f) in [
        ("spot_1-1000nm.ibw", "ibw/spot_1-1000nm.ibw"),
        ("nid-1.nid", "nid/nid-1.nid"),
        ("mi-1.mi", "mi/mi-1.mi"),
        ("example_ps.tiff", "park-tiff/example_ps.tiff"),
    ] {
        let x = topography_summary(&afm.join(a), None).unwrap();
        let y = topography_summary(&formats.join(f), None).unwrap();
        assert_eq!(
            (x.nx, x.h_rms_m, x.height_min_m),
            (y.nx, y.h_rms_m, y.height_min_m),
            "{a}"
        );
    }
    // Nanoscope and WSxM are recognised by their content too (tests/mechanics/surface.rs checks
    // their numbers).
    for (file, format) in [("di-3.di", "nanoscope"), ("top-1.top", "wsxm")] {
        let found = detect_file(&afm.join(file)).unwrap().map(|f| f.name());
        assert_eq!(found, Some(format), "{file}");
    }
}

/// A sample file read by its reader (confocal files: every plane decoded), as the summary's
/// JSON without the file name.
fn try_read(path: &Path, confocal: bool) -> Result<String, contactscope_jobs::Error> {
    if confocal {
        Ok(info_summary(path, true).map(|mut s| {
            s.file.clear();
            serde_json::to_string(&s).unwrap()
        })?)
    } else {
        topography_summary(path, None).map(|mut s| {
            s.file.clear();
            serde_json::to_string(&s).unwrap()
        })
    }
}

fn samples(dir: &Path) -> Vec<(PathBuf, bool)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let sub = entry.unwrap().path();
        if !sub.is_dir() {
            continue;
        }
        let confocal = ["czi", "nd2", "lif"].iter().any(|c| sub.ends_with(c));
        for f in std::fs::read_dir(&sub).unwrap() {
            out.push((f.unwrap().path(), confocal));
        }
    }
    out.sort();
    out
}

#[test]
fn truncated_files_give_one_clean_error() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    for (path, confocal) in samples(&dir) {
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let cut_path = tmp.path().join(&name);
        let n = bytes.len();
        let full = try_read(&path, confocal).unwrap();
        let mut cuts: Vec<usize> = (0..24).map(|k| k * n / 24).collect();
        cuts.extend([1, 2, 9, 17, 64, 300, 600]);
        for cut in cuts.into_iter().filter(|&c| c < n) {
            std::fs::write(&cut_path, &bytes[..cut]).unwrap();
            // A truncated copy fails with an error naming the file, or, when only bytes the
            // reader does not use were cut (trailing notes, previews), reads exactly as the
            // whole file: never a different answer.
            match try_read(&cut_path, confocal) {
                Err(e) => assert!(e.to_string().contains(&name), "{name} cut at {cut}: {e}"),
                Ok(s) => assert!(
                    s == full,
                    "{name} cut at {cut} of {n} bytes read differently"
                ),
            }
        }
    }
}

#[test]
fn corrupted_bytes_never_panic() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    // A fixed xorshift sequence of positions in the first 4 KiB (the headers) and values.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for (path, confocal) in samples(&dir) {
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let bad_path = tmp.path().join(&name);
        for _ in 0..25 {
            let mut b = bytes.clone();
            for _ in 0..4 {
                let at = (next() as usize) % b.len().min(4096);
                b[at] = next() as u8;
            }
            std::fs::write(&bad_path, &b).unwrap();
            if let Err(e) = try_read(&bad_path, confocal) {
                assert!(e.to_string().contains(&name), "{name}: {e}");
            }
        }
    }
}

#[test]
fn czi_compressions_other_than_zstd_are_refused_by_name() {
    let Some(dir) = crate::common::shared_data("real-formats") else {
        return;
    };
    // A temporary copy of a sample whose directory entries claim JPEG-XR (4) or LZW (2).
    let mut bytes = std::fs::read(dir.join("czi/s_1_t_1_c_1_z_1.czi")).unwrap();
    let dir_pos = i64::from_le_bytes(bytes[84..92].try_into().unwrap()) as usize;
    let compression_at = dir_pos + 160 + 18;
    assert_eq!(&bytes[dir_pos + 160..dir_pos + 162], b"DV");
    let tmp = tempfile::tempdir().unwrap();
    for (code, name) in [(4u8, "JPEG-XR"), (2, "LZW")] {
        bytes[compression_at] = code;
        let path = tmp.path().join("refused.czi");
        std::fs::write(&path, &bytes).unwrap();
        let mut file = MicroscopyFile::open(&path).unwrap();
        let err = file
            .read_plane(
                0,
                &contactscope_formats::microscopy::PlaneIndex::tzc(0, 0, 0),
            )
            .unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(err, contactscope_formats::Error::Unsupported { .. }),
            "{text}"
        );
        assert!(
            text.contains(name) && text.contains("refused.czi"),
            "{text}"
        );
    }
}

#[test]
fn tiff_is_described_by_the_same_model() {
    use contactscope_formats::tiff::write::encode_u16_stack;
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("stack.tif");
    let pages: Vec<Vec<u16>> = (0..3u16)
        .map(|k| (0..12u16).map(|i| i * (k + 1)).collect())
        .collect();
    let refs: Vec<&[u16]> = pages.iter().map(|p| p.as_slice()).collect();
    let bytes = encode_u16_stack(&refs, 4, 3, Some((0.2e-6, 0.25e-6)), "").unwrap();
    std::fs::write(&path, bytes).unwrap();
    let s = info_summary(&path, true).unwrap();
    assert_eq!(s.format, "tiff");
    let series = &s.series[0];
    let a = &series.axes;
    assert_eq!((a.t, a.z, a.c, a.y, a.x), (1, 3, 1, 3, 4));
    assert!(rel(series.pixel_size_um.y.unwrap(), 0.25) < 1e-9);
    assert!(series.pixel_size_source.is_some());
    let planes = series.planes.as_ref().unwrap();
    // Sum of 0..12 is 66; page k holds (k + 1)·i.
    let sums: Vec<f64> = planes.iter().map(|p| p.sum).collect();
    assert_eq!(sums, vec![66.0, 132.0, 198.0]);
    assert_eq!((planes[2].min, planes[2].max), (0.0, 33.0));
}
