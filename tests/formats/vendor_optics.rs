//! The optics commands on CZI, ND2 and LIF files through the built binary (issue 14, item 1):
//! `autocorr`, `psf`, `newton` and `compare` read the planes the selection flags name and give
//! exactly the results of the same planes exported to TIFF by our own writer. Real samples from
//! `../shared/data/real-formats` (skipped with a message when absent); small CZI files from the
//! test writer in `tests/common/czi.rs`. Load series for `analyze`: `tests/series/vendor.rs`.

use std::path::Path;

use crate::common::czi::{czi, Tile};
use crate::common::{column, export_tiff, read_csv, run, run_ok, shared_data, stderr};
use contactscope_formats::microscopy::{MicroscopyFile, PlaneIndex};
use contactscope_formats::tiff::encode_u16_stack;
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// One square Gray16 tile of `n`² samples at the origin.
fn plane_tile(t: i32, z: i32, c: i32, values: &[u16], n: usize) -> Tile {
    Tile {
        s: 0,
        t,
        z,
        c,
        m: 0,
        x: 0,
        y: 0,
        w: n as i32,
        h: n as i32,
        values: values.to_vec(),
    }
}

#[test]
fn autocorr_reads_the_selected_plane_as_its_tiff_export() {
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let file = dir.join("nd2/cluster.nd2");
    let tmp = tempfile::tempdir().unwrap();
    let tiff = tmp.path().join("plane.tif");
    let px = 0.167_808_983_232_682_45e-6;
    export_tiff(
        &file,
        &[(0, PlaneIndex::tzc(2, 4, 1))],
        Some((px, px)),
        &tiff,
    );
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    run_ok(&[
        "autocorr",
        s(&file),
        "--channel",
        "1",
        "--t",
        "2",
        "--z",
        "4",
        "--out",
        s(&a),
    ]);
    run_ok(&["autocorr", s(&tiff), "--out", s(&b)]);
    let (ha, ra) = read_csv(&a.join("autocorr.csv"));
    let (hb, rb) = read_csv(&b.join("autocorr.csv"));
    assert_eq!(ra.len(), rb.len());
    let value = |h: &[String]| h.iter().find(|n| n.contains("acf")).cloned().unwrap();
    let (ca, cb) = (column(&ha, &ra, &value(&ha)), column(&hb, &rb, &value(&hb)));
    for (x, y) in ca.iter().zip(&cb) {
        assert!((x - y).abs() < 1e-9, "{x} vs {y}");
    }
}

#[test]
fn psf_and_newton_readers_take_the_selected_planes() {
    crate::common::cli_names();
    use contactscope_formats::microscopy::select::{
        read_images, read_one_image, LoadAxis, Selection,
    };
    let Some(dir) = shared_data("real-formats") else {
        return;
    };
    let file = dir.join("nd2/cluster.nd2");
    let mut f = MicroscopyFile::open(&file).unwrap();
    // psf: a z stack of the selected channel and time point, in z order, with the ND2 pixel size.
    let sel = Selection {
        channel: Some(1.into()),
        t: Some(2),
        ..Selection::default()
    };
    let stack = read_images(&file, &sel, Some(LoadAxis::Z), None).unwrap();
    assert_eq!(stack.len(), 10);
    for (z, image) in stack.iter().enumerate() {
        let plane = f.read_plane(0, &PlaneIndex::tzc(2, z, 1)).unwrap();
        assert_eq!(image.values, plane.to_f64(), "z = {z}");
        assert_eq!(image.page, z);
        let px = image.pixel_size.unwrap();
        assert_eq!(px.source.describe(), "ND2 SLxPictureMetadata/dCalibration");
    }
    // newton: one plane; an unselected axis is named.
    let seven = Selection {
        z: Some(7),
        ..sel.clone()
    };
    let one = read_one_image(&file, &seven, Some((1e-7, 1e-7))).unwrap();
    assert_eq!(one.values, stack[7].values);
    assert!((one.pixel_size.unwrap().x_m - 1e-7).abs() < 1e-20);
    let e = read_one_image(&file, &sel, None).unwrap_err().to_string();
    assert!(e.contains("10 z planes; choose one with --z 0..9"), "{e}");
}

#[test]
fn psf_of_a_czi_z_stack_equals_psf_of_its_tiff_export() {
    use contactscope::synth::beads::{synth_beads, BeadParams};
    let beads = synth_beads(&BeadParams {
        planes: 7,
        sigma_px: 2.0,
        seed: 3,
        ..BeadParams::default()
    })
    .unwrap();
    let (w, h) = (beads.width, beads.height);
    let tmp = tempfile::tempdir().unwrap();
    let tiles: Vec<Tile> = beads
        .planes
        .iter()
        .enumerate()
        .map(|(z, plane)| Tile {
            s: 0,
            t: 0,
            z: z as i32,
            c: 0,
            m: 0,
            x: 0,
            y: 0,
            w: w as i32,
            h: h as i32,
            values: plane.clone(),
        })
        .collect();
    let stack = tmp.path().join("beads.czi");
    std::fs::write(&stack, czi(&tiles)).unwrap();
    let tiff = tmp.path().join("beads.tif");
    let pages: Vec<&[u16]> = beads.planes.iter().map(Vec::as_slice).collect();
    std::fs::write(&tiff, encode_u16_stack(&pages, w, h, None, "").unwrap()).unwrap();
    let psf = |input: &Path, out: &str| -> Value {
        let out = tmp.path().join(out);
        run_ok(&["psf", s(input), "--pixel-size", "100nm", "--out", s(&out)]);
        serde_json::from_str(&std::fs::read_to_string(out.join("psf.json")).unwrap()).unwrap()
    };
    let (a, b) = (psf(&stack, "czi"), psf(&tiff, "tif"));
    assert!(a["fwhm_nm_mean"].as_f64().unwrap() > 0.0, "{a}");
    assert_eq!(a["fwhm_nm_mean"], b["fwhm_nm_mean"]);
    assert_eq!(a["planes"], 7);
    assert_eq!(
        std::fs::read(tmp.path().join("czi/beads.csv")).unwrap(),
        std::fs::read(tmp.path().join("tif/beads.csv")).unwrap()
    );
}

#[test]
fn newton_on_two_channels_of_one_czi_equals_newton_on_two_tiffs() {
    use contactscope::synth::rings::{synth_newton, NewtonSynthParams};
    let n = 128;
    let synth = synth_newton(&NewtonSynthParams {
        width: n,
        height: n,
        centre_px: (63.4, 64.7),
        contact_radius_m: 6e-6,
        seed: 5,
        ..NewtonSynthParams::default()
    })
    .unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let tile = |c: i32, values: &[u16]| Tile {
        s: 0,
        t: 0,
        z: 0,
        c,
        m: 0,
        x: 0,
        y: 0,
        w: n as i32,
        h: n as i32,
        values: values.to_vec(),
    };
    let both = tmp.path().join("rings.czi");
    let tiles = [tile(0, &synth.reflection), tile(1, &synth.fluorescence)];
    std::fs::write(&both, czi(&tiles)).unwrap();
    let write = |name: &str, codes: &[u16]| {
        let p = tmp.path().join(name);
        std::fs::write(&p, encode_u16_stack(&[codes], n, n, None, "").unwrap()).unwrap();
        p
    };
    let (r, f) = (
        write("r.tif", &synth.reflection),
        write("f.tif", &synth.fluorescence),
    );
    let newton = |args: &[&str], out: &str| -> Value {
        let out = tmp.path().join(out);
        let mut all = vec!["newton", "--pixel-size", "200nm", "--out", s(&out)];
        all.extend_from_slice(args);
        run_ok(&all);
        serde_json::from_str(&std::fs::read_to_string(out.join("newton.json")).unwrap()).unwrap()
    };
    let a = newton(
        &[
            s(&both),
            "--contact",
            s(&both),
            "--channel",
            "0",
            "--contact-channel",
            "1",
        ],
        "czi",
    );
    let b = newton(&[s(&r), "--contact", s(&f)], "tif");
    let gap = a["detection_gap_nm_mean"].as_f64().unwrap();
    assert!(gap > 0.0, "{a}");
    assert_eq!(a["detection_gap_nm_mean"], b["detection_gap_nm_mean"]);
    // Without --channel the two-channel file is refused naming the axis.
    let o = run(&[
        "newton",
        s(&both),
        "--contact",
        s(&both),
        "--out",
        s(tmp.path()),
    ]);
    assert!(
        stderr(&o).contains("2 channels; choose one with --channel 0..1"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn compare_reads_a_czi_load_series_as_its_tiff_export() {
    use contactscope::optics::blur::Grid;
    use contactscope::synth::{render_micrograph, MicrographParams};
    use contactscope_formats::tiff::read_image;
    let tmp = tempfile::tempdir().unwrap();
    // A small rough sphere simulated at two loads, rendered as 48² micrographs at 200 nm.
    let topo = tmp.path().join("rough.npy");
    crate::common::rough_surface(&topo, 128, "50nm", 4, &["--rolloff", "2um"]);
    let sim = tmp.path().join("sim");
    crate::common::run_written(&[
        "simulate",
        "--topography",
        s(&topo),
        "--pixel-size",
        "50nm",
        "--radius",
        "290um",
        "--modulus",
        "3.7GPa",
        "--forces",
        "0.5mN,1mN",
        "--model",
        "elastic",
        "--quiet",
        "--out",
        s(&sim),
    ]);
    let n = 48;
    let pages: Vec<Vec<u16>> = (0..2)
        .map(|i| {
            let map = read_image(
                &sim.join(format!("load_{:03}_contact.tif", i + 1)),
                None,
                None,
            )
            .unwrap();
            let px = map.pixel_size.unwrap();
            let grid = Grid::new(map.values, map.width, map.height, px.x_m, px.y_m).unwrap();
            let params = MicrographParams {
                fwhm_m: 450e-9,
                pixel_m: 200e-9,
                width: n,
                height: n,
                corner_px: (10, 9),
                background: 300.0,
                contact_level: 2500.0,
                counts_per_photon: 4.0,
                seed: i as u64,
            };
            render_micrograph(&grid, &params).unwrap()
        })
        .collect();
    let tiff = tmp.path().join("series.tif");
    let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
    std::fs::write(&tiff, encode_u16_stack(&refs, n, n, None, "").unwrap()).unwrap();
    let along_t = tmp.path().join("series.czi");
    let tiles: Vec<Tile> = pages
        .iter()
        .enumerate()
        .map(|(t, p)| plane_tile(t as i32, 0, 0, p, n))
        .collect();
    std::fs::write(&along_t, czi(&tiles)).unwrap();
    let compare = |experiment: &Path, out: &str, extra: &[&str]| {
        let out = tmp.path().join(out);
        let mut args = vec![
            "compare",
            "--micrographs",
            s(experiment),
            "--forces",
            "0.5,1mN",
            "--simulation",
            s(&sim),
            "--psf-fwhm",
            "450nm",
            "--pixel-size",
            "200nm",
            "--out",
            s(&out),
        ];
        args.extend_from_slice(extra);
        run_ok(&args);
        read_csv(&out.join("compare.csv"))
    };
    let (ha, ra) = compare(&along_t, "czi", &["--load-axis", "t"]);
    let (hb, rb) = compare(&tiff, "tif", &[]);
    assert_eq!(ha, hb);
    assert_eq!(ra.len(), 2);
    for name in [
        "force_mN",
        "dice",
        "jaccard",
        "shift_x_px",
        "shift_y_px",
        "area_ratio",
    ] {
        assert_eq!(column(&ha, &ra, name), column(&hb, &rb, name), "{name}");
    }
    assert!(column(&ha, &ra, "dice").iter().all(|d| *d > 0.5), "{ra:?}");
}
