//! Load series from CZI, ND2 and LIF files through the built binary (issue 14, items 1–3): the
//! selection flags (`--series`, `--channel`, `--z`, `--t`), `--load-axis`, and lists of vendor
//! files. Every analysis is checked against the same planes exported to TIFF by our own writer
//! (`contactscope_formats::tiff::encode_u16_stack`) and analysed the same way: thresholds, contact pixels and
//! areas must agree. Real samples come from `../shared/data/real-formats` (skipped with a message
//! when absent; never copied into the repository); small CZI files come from the test writer
//! in `tests/common/czi.rs`. The optics commands: `tests/formats/vendor_optics.rs`.

use std::path::{Path, PathBuf};

use crate::common::czi::{czi, Tile};
use crate::common::{column, export_tiff, read_csv, run, run_ok, shared_data, stderr};
use contactscope_formats::microscopy::PlaneIndex;
use contactscope_formats::tiff::encode_u16_stack;
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// `analyze` into `out` with `args`; returns (areas.csv header and rows, summary.json). The
/// sample files are not contact experiments: where every "contact" touches the border or none
/// is found, the outputs are written with exit status 4, which is accepted here.
fn analyze(out: &Path, args: &[&str]) -> ((Vec<String>, Vec<Vec<String>>), Value) {
    let mut all = vec!["analyze", "-q", "--out", s(out)];
    all.extend_from_slice(args);
    crate::common::run_written(&all);
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
    (
        read_csv(&out.join("areas.csv")),
        serde_json::from_str(&summary).unwrap(),
    )
}

/// The two analyses agree: same threshold, contact pixels and patches per image, areas to
/// 1e-5 relative (the exported TIFF stores the pixel size as a rational: 7e-6 relative off for
/// the CZI sample's 90.58 nm; [`assert_areas_from_pixel_size`] checks the vendor areas exactly).
fn assert_same_analysis(
    a: &((Vec<String>, Vec<Vec<String>>), Value),
    b: &((Vec<String>, Vec<Vec<String>>), Value),
) {
    let ((ha, ra), sa) = a;
    let ((hb, rb), sb) = b;
    assert_eq!(ra.len(), rb.len(), "image counts");
    assert_eq!(sa["threshold"]["value"], sb["threshold"]["value"]);
    assert_eq!(sa["area_unit"], sb["area_unit"]);
    for name in [
        "threshold",
        "contact_pixels",
        "patches",
        "integrated_intensity",
    ] {
        assert_eq!(column(ha, ra, name), column(hb, rb, name), "{name}");
    }
    let unit = format!("area_{}", sa["area_unit"].as_str().unwrap());
    for (x, y) in column(ha, ra, &unit).iter().zip(column(hb, rb, &unit)) {
        assert!((x - y).abs() <= 1e-5 * x.abs().max(1e-9), "{x} vs {y}");
    }
}

/// Areas are contact pixels × the pixel area of `px` (m), to 1e-12 relative.
fn assert_areas_from_pixel_size(a: &((Vec<String>, Vec<Vec<String>>), Value), px: f64) {
    let ((h, r), _) = a;
    let pixels = column(h, r, "contact_pixels");
    for (area, n) in column(h, r, "area_um2").iter().zip(pixels) {
        let expected = n * px * px * 1e12;
        assert!(
            (area - expected).abs() <= 1e-12 * expected.max(1e-12),
            "{area} vs {expected}"
        );
    }
}

#[test]
fn czi_load_series_along_t_matches_its_tiff_export() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let file = dir.join("czi/CellDivision_T3_Z5_CH2_X240_Y170.czi");
    let tmp = tempfile::tempdir().unwrap();
    let forces = "1,2,4mN";
    let vendor = analyze(
        &tmp.path().join("czi"),
        &[
            s(&file),
            "--channel",
            "1",
            "--z",
            "2",
            "--load-axis",
            "t",
            "--forces",
            forces,
        ],
    );
    // Pixel size from the CZI's Scaling metadata, named as the source.
    let used = &vendor.1["inputs"]["pixel_size_used"];
    assert!(
        used["source"].as_str().unwrap().starts_with("CZI"),
        "{used}"
    );
    let px = used["x_um"].as_f64().unwrap() * 1e-6;
    assert!((px / 9.057_667_415_221_031e-8 - 1.0).abs() < 1e-9, "{px}");
    assert_areas_from_pixel_size(&vendor, px);
    assert_eq!(vendor.1["inputs"]["load_axis"], "t");
    assert_eq!(vendor.1["inputs"]["files"][0]["format"], "czi");
    assert_eq!(vendor.1["inputs"]["files"][0]["compression"], "none");
    // The same three planes (t = 0, 1, 2 at z = 2, c = 1), in order, as one TIFF.
    let tiff = tmp.path().join("export.tif");
    let planes: Vec<_> = (0..3).map(|t| (0, PlaneIndex::tzc(t, 2, 1))).collect();
    export_tiff(&file, &planes, Some((px, px)), &tiff);
    let exported = analyze(&tmp.path().join("tif"), &[s(&tiff), "--forces", forces]);
    assert_same_analysis(&vendor, &exported);
    let ((h, r), _) = &vendor;
    assert_eq!(column(h, r, "page"), vec![0.0, 1.0, 2.0], "page = t index");
    // Another z plane gives other numbers (the selection is not ignored).
    let other = analyze(
        &tmp.path().join("z0"),
        &[
            s(&file),
            "--channel",
            "1",
            "--z",
            "0",
            "--load-axis",
            "t",
            "--forces",
            forces,
        ],
    );
    assert_ne!(
        column(h, r, "integrated_intensity"),
        column(&other.0 .0, &other.0 .1, "integrated_intensity")
    );
}

#[test]
fn nd2_load_series_along_z_matches_its_tiff_export() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let file = dir.join("nd2/cluster.nd2");
    let tmp = tempfile::tempdir().unwrap();
    let forces = "1,2,3,4,5,6,7,8,9,10mN";
    let vendor = analyze(
        &tmp.path().join("nd2"),
        &[
            s(&file),
            "--t",
            "1",
            "--channel",
            "0",
            "--load-axis",
            "z",
            "--forces",
            forces,
        ],
    );
    let used = &vendor.1["inputs"]["pixel_size_used"];
    assert!(
        used["source"].as_str().unwrap().starts_with("ND2"),
        "{used}"
    );
    let px = used["x_um"].as_f64().unwrap() * 1e-6;
    assert!(
        (px / 0.167_808_983_232_682_45e-6 - 1.0).abs() < 1e-9,
        "{px}"
    );
    let tiff = tmp.path().join("export.tif");
    let planes: Vec<_> = (0..10).map(|z| (0, PlaneIndex::tzc(1, z, 0))).collect();
    export_tiff(&file, &planes, Some((px, px)), &tiff);
    let exported = analyze(&tmp.path().join("tif"), &[s(&tiff), "--forces", forces]);
    assert_same_analysis(&vendor, &exported);
    // The threshold command agrees with analyze on the same planes.
    let out = run_ok(&[
        "threshold",
        s(&file),
        "--t",
        "1",
        "--channel",
        "0",
        "--load-axis",
        "z",
        "--json",
    ]);
    let t: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(t["threshold"], vendor.1["threshold"]["value"]);
    assert_eq!(t["images"], 10);
}

#[test]
fn unselected_axes_and_mismatched_counts_are_clear_errors() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let nd2 = dir.join("nd2/cluster.nd2");
    let tmp = tempfile::tempdir().unwrap();
    let out = s(tmp.path());
    let err = |args: &[&str]| {
        let o = run(args);
        assert!(!o.status.success(), "{args:?} should fail");
        let e = stderr(&o);
        assert_eq!(e.trim().lines().count(), 1, "one line: {e}");
        e
    };
    // Every axis to choose in one message, the channels with their names.
    let e = err(&["analyze", s(&nd2), "--forces", "1mN", "--out", out]);
    assert!(
        e.contains(
            "cluster.nd2: 2 channels, 10 z planes and 3 time points; choose one of each with \
             --channel 0..1 or a name (0 '5-FAM/pH 9.0', 1 'FM 4-64/2% CHAPS'), --z 0..9 and \
             --t 0..2"
        ),
        "{e}"
    );
    // A channel by name (without regard to case) reads the plane its index reads.
    let by_index = run_ok(&[
        "threshold",
        s(&nd2),
        "--channel",
        "1",
        "--z",
        "4",
        "--t",
        "2",
    ]);
    let by_name = run_ok(&[
        "threshold",
        s(&nd2),
        "--channel",
        "fm 4-64/2% chaps",
        "--z",
        "4",
        "--t",
        "2",
    ]);
    assert_eq!(by_index.stdout, by_name.stdout);
    let e = err(&[
        "threshold",
        s(&nd2),
        "--channel",
        "AF488",
        "--z",
        "1",
        "--t",
        "0",
    ]);
    assert!(
        e.contains("--channel AF488: no channel has that name; the channels are 0 '5-FAM/pH 9.0', 1 'FM 4-64/2% CHAPS'"),
        "{e}"
    );
    let e = err(&[
        "analyze",
        s(&nd2),
        "--channel",
        "0",
        "--forces",
        "1mN",
        "--out",
        out,
    ]);
    assert!(
        e.contains("10 z planes and 3 time points; choose one of each with --z 0..9 and --t 0..2"),
        "{e}"
    );
    let e = err(&["threshold", s(&nd2), "--channel", "0", "--z", "1"]);
    assert!(e.contains("3 time points; choose one with --t 0..2"), "{e}");
    let e = err(&[
        "threshold",
        s(&nd2),
        "--channel",
        "2",
        "--z",
        "1",
        "--t",
        "0",
    ]);
    assert!(
        e.contains("--channel 2") && e.contains("2 channels (0..1)"),
        "{e}"
    );
    let e = err(&[
        "analyze",
        s(&nd2),
        "--channel",
        "0",
        "--z",
        "1",
        "--load-axis",
        "t",
        "--forces",
        "1,2mN",
        "--out",
        out,
    ]);
    assert!(
        e.contains("2 force(s) given for 3 image(s)") && e.contains("--load-axis t"),
        "{e}"
    );
    let e = err(&[
        "threshold",
        s(&nd2),
        "--channel",
        "0",
        "--z",
        "1",
        "--t",
        "0",
        "--load-axis",
        "z",
    ]);
    assert!(
        e.contains("--z cannot be combined with --load-axis z"),
        "{e}"
    );
    let lif = dir.join("lif/LeicaLASX_wavelength-sweep_example.lif");
    let e = err(&["threshold", s(&lif)]);
    assert!(
        e.contains(
            "3 series and 20 planes along axis lambda_emission in series 0; choose one of each \
             with --series 0..2 (0 'x_y_lambdaEmi', 1 'x_y_lambdaExc', 2 'x_y_z_t_lambdaEmi') \
             and --axis lambda_emission=0..19"
        ),
        "{e}"
    );
    let airy = dir.join("czi/LSM880_AiryScan.czi");
    let e = err(&["threshold", s(&airy), "--channel", "0"]);
    assert!(e.contains("axis H") && e.contains("Airyscan"), "{e}");
    // A single-page TIFF has one z plane (a TIFF's axes are its metadata's).
    let tiff = tmp.path().join("one.tif");
    std::fs::write(
        &tiff,
        encode_u16_stack(&[&[1, 2, 3, 4]], 2, 2, None, "").unwrap(),
    )
    .unwrap();
    let e = err(&["threshold", s(&tiff), "--z", "1"]);
    assert!(e.contains("--z 1") && e.contains("1 z planes"), "{e}");
    // info: --series beyond the file, and a restricted listing.
    let e = err(&["info", s(&lif), "--series", "3"]);
    assert!(e.contains("--series 3") && e.contains("3 series"), "{e}");
    let o = run_ok(&[
        "info",
        s(&nd2),
        "--json",
        "--stats",
        "--channel",
        "1",
        "--t",
        "2",
    ]);
    let v: Value = serde_json::from_slice(&o.stdout).unwrap();
    let planes = v["series"][0]["planes"].as_array().unwrap();
    assert_eq!(planes.len(), 10);
    assert!(planes.iter().all(|p| p["c"] == 1 && p["t"] == 2));
}

#[test]
fn a_file_without_pixel_size_is_analysed_in_pixels_as_a_tiff_is() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    // zstd-compressed CZI whose Scaling values are 0 ("not calibrated").
    let file = dir.join("czi/newCZI_compressed.czi");
    let tmp = tempfile::tempdir().unwrap();
    let vendor = analyze(&tmp.path().join("a"), &[s(&file), "--forces", "1mN"]);
    assert_eq!(vendor.1["area_unit"], "px");
    assert_eq!(vendor.1["inputs"]["files"][0]["compression"], "compressed");
    let warnings = vendor.1["warnings"].to_string();
    assert!(warnings.contains("--pixel-size"), "{warnings}");
    let tiff = tmp.path().join("export.tif");
    export_tiff(&file, &[(0, PlaneIndex::tzc(0, 0, 0))], None, &tiff);
    let exported = analyze(&tmp.path().join("b"), &[s(&tiff), "--forces", "1mN"]);
    assert_same_analysis(&vendor, &exported);
    // With --pixel-size the areas are in µm² and the source is the command line.
    let given = analyze(
        &tmp.path().join("c"),
        &[s(&file), "--forces", "1mN", "--pixel-size", "0.2um"],
    );
    assert_eq!(given.1["area_unit"], "um2");
    let px = &given.1["inputs"]["pixel_size_used"]["source"];
    assert!(px.as_str().unwrap().contains("command line"), "{px}");
}

/// A disc of `radius` pixels at 1000 on a background of 100 + (x + y) % 7, `size`² pixels.
fn disc(size: usize, radius: f64) -> Vec<u16> {
    let c = (size as f64 - 1.0) / 2.0;
    (0..size * size)
        .map(|i| {
            let (x, y) = ((i % size) as f64, (i / size) as f64);
            if (x - c).hypot(y - c) <= radius {
                1000 + (i % 5) as u16
            } else {
                100 + ((i % size + i / size) % 7) as u16
            }
        })
        .collect()
}

fn disc_tile(t: i32, s: i32, values: Vec<u16>, size: usize) -> Tile {
    Tile {
        s,
        t,
        z: 0,
        c: 0,
        m: 0,
        x: 0,
        y: 0,
        w: size as i32,
        h: size as i32,
        values,
    }
}

#[test]
fn lists_of_czi_files_one_file_along_t_or_series_and_manifests_agree_with_tiff() {
    let tmp = tempfile::tempdir().unwrap();
    let size = 24;
    let discs: Vec<Vec<u16>> = [3.0, 5.5, 8.0].iter().map(|&r| disc(size, r)).collect();
    // Three files of one plane each.
    let files: Vec<PathBuf> = discs
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let p = tmp.path().join(format!("load{}.czi", i + 1));
            std::fs::write(&p, czi(&[disc_tile(0, 0, d.clone(), size)])).unwrap();
            p
        })
        .collect();
    // One file with the loads along T, one with them as scenes.
    let along_t = tmp.path().join("along_t.czi");
    let tiles: Vec<Tile> = (0..3)
        .map(|t| disc_tile(t as i32, 0, discs[t].clone(), size))
        .collect();
    std::fs::write(&along_t, czi(&tiles)).unwrap();
    let scenes = tmp.path().join("scenes.czi");
    let tiles: Vec<Tile> = (0..3)
        .map(|k| disc_tile(0, k as i32, discs[k].clone(), size))
        .collect();
    std::fs::write(&scenes, czi(&tiles)).unwrap();
    // The reference: the same planes as a TIFF.
    let tiff = tmp.path().join("reference.tif");
    let refs: Vec<&[u16]> = discs.iter().map(Vec::as_slice).collect();
    std::fs::write(
        &tiff,
        encode_u16_stack(&refs, size, size, None, "").unwrap(),
    )
    .unwrap();

    let common = ["--forces", "2,4,8mN", "--pixel-size", "0.2um"];
    fn with<'a>(extra: &[&'a str], common: &[&'a str]) -> Vec<&'a str> {
        let mut v: Vec<&str> = extra.to_vec();
        v.extend_from_slice(common);
        v
    }
    let reference = analyze(&tmp.path().join("ref"), &with(&[s(&tiff)], &common));
    let list = analyze(
        &tmp.path().join("list"),
        &with(&[s(&files[0]), s(&files[1]), s(&files[2])], &common),
    );
    assert_same_analysis(&reference, &list);
    let t = analyze(
        &tmp.path().join("t"),
        &with(&[s(&along_t), "--load-axis", "t"], &common),
    );
    assert_same_analysis(&reference, &t);
    let sc = analyze(
        &tmp.path().join("s"),
        &with(&[s(&scenes), "--load-axis", "series"], &common),
    );
    assert_same_analysis(&reference, &sc);
    // The discs grow, so the areas must too (the planes are not all the same one).
    let ((h, r), _) = &list;
    let areas = column(h, r, "area_um2");
    assert!(areas[0] < areas[1] && areas[1] < areas[2], "{areas:?}");
    // A folder of CZI files reads in natural order.
    let folder = tmp.path().join("folder");
    std::fs::create_dir(&folder).unwrap();
    for (i, f) in files.iter().enumerate() {
        std::fs::copy(f, folder.join(format!("img{}.czi", [2, 10, 11][i]))).unwrap();
    }
    let dir = analyze(&tmp.path().join("dir"), &with(&[s(&folder)], &common));
    assert_same_analysis(&reference, &dir);
    // A manifest naming t planes of one file by 'page', out of order.
    let manifest = tmp.path().join("manifest.csv");
    std::fs::write(
        &manifest,
        "file,page,force_mN\nalong_t.czi,2,8\nalong_t.czi,0,2\nalong_t.czi,1,4\n",
    )
    .unwrap();
    let m = analyze(
        &tmp.path().join("m"),
        &[
            "--manifest",
            s(&manifest),
            "--load-axis",
            "t",
            "--pixel-size",
            "0.2um",
        ],
    );
    let ((hm, rm), _) = &m;
    let by_page = column(hm, rm, "area_um2");
    assert_eq!(by_page, vec![areas[2], areas[0], areas[1]]);
    // A page the axis does not have is refused naming it.
    std::fs::write(&manifest, "file,page,force_mN\nalong_t.czi,3,8\n").unwrap();
    let o = run(&[
        "analyze",
        "--manifest",
        s(&manifest),
        "--load-axis",
        "t",
        "--out",
        s(&tmp.path().join("bad")),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("page 3"), "{}", stderr(&o));
}

#[test]
fn extra_axes_are_chosen_by_name() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    // Bgr24 pixels: S = 0 blue, 1 green, 2 red, each its own plane.
    let file = dir.join("czi/RGB-multichannel.czi");
    let tmp = tempfile::tempdir().unwrap();
    let e = stderr(&run(&["threshold", s(&file), "--channel", "0"]));
    assert!(
        e.contains("3 planes along axis S") && e.contains("--axis S=0..2"),
        "{e}"
    );
    let green = analyze(
        &tmp.path().join("g"),
        &[
            s(&file),
            "--channel",
            "2",
            "--axis",
            "S=1",
            "--forces",
            "1mN",
        ],
    );
    let mut index = PlaneIndex::tzc(0, 0, 2);
    index.extra.insert("S".into(), 1);
    let tiff = tmp.path().join("green.tif");
    export_tiff(&file, &[(0, index)], None, &tiff);
    let exported = analyze(
        &tmp.path().join("t"),
        &[
            s(&tiff),
            "--forces",
            "1mN",
            "--pixel-size",
            "2.95848999467571um",
        ],
    );
    assert_eq!(green.0 .0.len(), exported.0 .0.len());
    for name in [
        "threshold",
        "contact_pixels",
        "patches",
        "integrated_intensity",
    ] {
        assert_eq!(
            column(&green.0 .0, &green.0 .1, name),
            column(&exported.0 .0, &exported.0 .1, name),
            "{name}"
        );
    }
    // The blue plane is another image.
    let blue = analyze(
        &tmp.path().join("b"),
        &[
            s(&file),
            "--channel",
            "2",
            "--axis",
            "S=0",
            "--forces",
            "1mN",
        ],
    );
    assert_ne!(
        column(&green.0 .0, &green.0 .1, "integrated_intensity"),
        column(&blue.0 .0, &blue.0 .1, "integrated_intensity")
    );
    let e = stderr(&run(&[
        "threshold",
        s(&file),
        "--channel",
        "0",
        "--axis",
        "S=3",
    ]));
    assert!(e.contains("--axis S=3") && e.contains("(0..2)"), "{e}");
    let e = stderr(&run(&["threshold", s(&file), "--axis", "Z=1"]));
    assert!(e.contains("use --t, --z or --channel"), "{e}");
}

#[test]
fn lif_load_series_along_z_at_one_emission_wavelength_matches_its_tiff_export() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    // Series 2: T 2 × Z 11 × 10 emission wavelengths, uint8 64×64.
    let file = dir.join("lif/LeicaLASX_wavelength-sweep_example.lif");
    let tmp = tempfile::tempdir().unwrap();
    let forces = "1,2,3,4,5,6,7,8,9,10,11mN";
    let vendor = analyze(
        &tmp.path().join("lif"),
        &[
            s(&file),
            "--series",
            "2",
            "--t",
            "1",
            "--axis",
            "lambda_emission=4",
            "--load-axis",
            "z",
            "--forces",
            forces,
        ],
    );
    let used = &vendor.1["inputs"]["pixel_size_used"];
    assert!(
        used["source"].as_str().unwrap().starts_with("LIF"),
        "{used}"
    );
    let px = used["x_um"].as_f64().unwrap() * 1e-6;
    assert_areas_from_pixel_size(&vendor, px);
    let planes: Vec<_> = (0..11)
        .map(|z| {
            let mut index = PlaneIndex::tzc(1, z, 0);
            index.extra.insert("lambda_emission".into(), 4);
            (2, index)
        })
        .collect();
    let tiff = tmp.path().join("export.tif");
    export_tiff(&file, &planes, Some((px, px)), &tiff);
    let exported = analyze(&tmp.path().join("tif"), &[s(&tiff), "--forces", forces]);
    assert_same_analysis(&vendor, &exported);
}
