//! The command line end to end: happy paths, outputs, and every bad input the series analysis
//! must refuse with a one-line error naming the file, a non-zero exit code and no output.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::{column, read_csv, run, stderr, stdout};
use contactscope::synth::{self, SynthParams};
use contactscope_formats::tiff::write::encode_u16_stack;
use contactscope_formats::tiff::TiffReader;
use contactscope_jobs::synth_series::{write_series, Layout};

fn small_series(dir: &Path, layout: Layout) -> Vec<PathBuf> {
    let p = SynthParams {
        width: 128,
        height: 128,
        forces_n: vec![4e-3, 8e-3, 16e-3, 32e-3],
        ..SynthParams::default()
    };
    write_series(&p, dir, layout).unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A little-endian classic TIFF with one 16-bit grey strip of 8 bytes but a declared size of
/// `width × height`.
fn absurd_tiff(width: u32, height: u32) -> Vec<u8> {
    let entries: [(u16, u16, u32); 8] = [
        (256, 4, width),  // ImageWidth
        (257, 4, height), // ImageLength
        (258, 3, 16),     // BitsPerSample
        (259, 3, 1),      // Compression: none
        (262, 3, 1),      // PhotometricInterpretation: BlackIsZero
        (273, 4, 110),    // StripOffsets
        (278, 4, height), // RowsPerStrip
        (279, 4, 8),      // StripByteCounts
    ];
    let mut b = b"II*\x00\x08\x00\x00\x00".to_vec();
    b.extend_from_slice(&(entries.len() as u16).to_le_bytes());
    for (tag, kind, value) in entries {
        b.extend_from_slice(&tag.to_le_bytes());
        b.extend_from_slice(&kind.to_le_bytes());
        b.extend_from_slice(&1u32.to_le_bytes());
        if kind == 3 {
            b.extend_from_slice(&(value as u16).to_le_bytes());
            b.extend_from_slice(&[0, 0]);
        } else {
            b.extend_from_slice(&value.to_le_bytes());
        }
    }
    b.extend_from_slice(&0u32.to_le_bytes());
    b.extend_from_slice(&[1, 0, 2, 0, 3, 0, 4, 0]);
    b
}

/// The run failed cleanly: non-zero exit, one error line that names `needle`, no output folder.
fn assert_clean_failure(out: &std::process::Output, needle: &str, out_dir: &Path) {
    assert!(!out.status.success(), "should fail: {}", stdout(out));
    let err = stderr(out);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "one error line expected:\n{err}");
    assert!(lines[0].starts_with("contactscope: error:"), "{err}");
    assert!(err.contains(needle), "error should name '{needle}':\n{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out_dir.exists(), "no output on failure");
    let parent = out_dir.parent().unwrap();
    let leftovers: Vec<_> = fs::read_dir(parent)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("staging"))
        .collect();
    assert!(leftovers.is_empty(), "staging folder left behind");
}

#[test]
fn analyze_a_directory_with_forces() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    small_series(&data, Layout::Files);
    // A folder of TIFFs: without the generator's manifest (beside one, --forces is refused:
    // series::first_hour).
    std::fs::remove_file(data.join("manifest.csv")).unwrap();
    let out_dir = dir.path().join("out");
    let out = run(&[
        "analyze",
        s(&data),
        "--forces",
        "4,8,16,32mN",
        "--out",
        s(&out_dir),
        "--radius",
        "290um",
        "--modulus",
        "3.7GPa",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (header, rows) = read_csv(&out_dir.join("areas.csv"));
    assert_eq!(
        header,
        [
            "image",
            "page",
            "force_mN",
            "threshold",
            "contact_pixels",
            "area_um2",
            "area_corrected_um2",
            "area_um2_lo",
            "area_um2_hi",
            "mean_intensity",
            "integrated_intensity",
            "background_mean",
            "patches",
            "largest_patch_um2",
            "mean_pressure_MPa",
            "mean_pressure_MPa_lo",
            "mean_pressure_MPa_hi",
            "equivalent_radius_um",
            "hertz_radius_um",
            "hertz_area_um2",
            "edge_contact"
        ]
    );
    assert_eq!(rows.len(), 4);
    assert!(rows[0][0].ends_with("load_01.tif") && rows[3][0].ends_with("load_04.tif"));
    let forces = column(&header, &rows, "force_mN");
    assert_eq!(forces, [4.0, 8.0, 16.0, 32.0]);
    let pixels = column(&header, &rows, "contact_pixels");
    let areas = column(&header, &rows, "area_um2");
    for (p, a) in pixels.iter().zip(&areas) {
        assert!(
            (a - p * 0.04).abs() < 1e-9,
            "0.2 µm pixels from ImageJ metadata"
        );
    }
    let pressure = column(&header, &rows, "mean_pressure_MPa");
    assert!((pressure[0] - 4.0 / areas[0] * 1e3).abs() < 1e-9);
    let hertz = column(&header, &rows, "hertz_radius_um");
    assert!((hertz[0] - 6.172).abs() < 1e-3);
    let thresholds = column(&header, &rows, "threshold");
    assert!(
        thresholds.iter().all(|t| *t == thresholds[0]),
        "one global threshold"
    );

    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["contactscope_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(summary["threshold"]["method"], "otsu-global");
    assert_eq!(summary["threshold"]["value"], thresholds[0]);
    assert_eq!(summary["threshold"]["histogram_pixels"], 4 * 128 * 128);
    assert_eq!(
        summary["inputs"]["pixel_size_used"]["source"],
        "ImageJ unit + X/YResolution"
    );
    let beta = summary["fits"]["power_law"]["exponent"].as_f64().unwrap();
    assert!(beta > 0.6 && beta < 1.1, "β = {beta}");
    assert!(summary["fits"]["power_law"]["exponent_se"]
        .as_f64()
        .is_some());
    assert!(
        summary["fits"]["proportional"]["pressure_MPa"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    assert!(summary["command_line"].as_array().unwrap().len() > 3);
    let png = fs::read(out_dir.join("area_vs_load.png")).unwrap();
    assert_eq!(&png[..4], b"\x89PNG");
    let svg = fs::read_to_string(out_dir.join("area_vs_load.svg")).unwrap();
    assert!(svg.contains("normal force N (mN)"));
}

#[test]
fn multipage_file_and_single_files_agree() {
    let dir = tempfile::tempdir().unwrap();
    small_series(&dir.path().join("files"), Layout::Files);
    small_series(&dir.path().join("stack"), Layout::MultiPage);
    let areas = |manifest: PathBuf, out: PathBuf| {
        let o = run(&["analyze", "--manifest", s(&manifest), "--out", s(&out)]);
        assert!(o.status.success(), "{}", stderr(&o));
        let (h, r) = read_csv(&out.join("areas.csv"));
        column(&h, &r, "contact_pixels")
    };
    let a = areas(dir.path().join("files/manifest.csv"), dir.path().join("o1"));
    let b = areas(dir.path().join("stack/manifest.csv"), dir.path().join("o2"));
    assert_eq!(a, b);
    assert!(
        a.windows(2).all(|w| w[1] > w[0]),
        "area grows with load: {a:?}"
    );
}

#[test]
fn manifest_with_friction_pages_and_relative_paths() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    small_series(&data, Layout::MultiPage);
    fs::write(
        data.join("ramp.csv"),
        "file,page,force_mN,friction_mN\nseries.tif,3,32,9.5\nseries.tif,0,4,1.25\n",
    )
    .unwrap();
    let out_dir = dir.path().join("out");
    let out = run(&[
        "analyze",
        "--manifest",
        s(&data.join("ramp.csv")),
        "--out",
        s(&out_dir),
        "-q",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (h, r) = read_csv(&out_dir.join("areas.csv"));
    assert_eq!(column(&h, &r, "page"), [3.0, 0.0]);
    assert_eq!(column(&h, &r, "friction_mN"), [9.5, 1.25]);
    assert_eq!(column(&h, &r, "force_mN"), [32.0, 4.0]);
}

#[test]
fn threshold_methods_and_pixel_size_override() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    small_series(&data, Layout::MultiPage);
    let tif = data.join("series.tif");
    let run_csv = |extra: &[&str], name: &str| {
        let out_dir = dir.path().join(name);
        let mut args = vec![
            "analyze",
            s(&tif),
            "--forces",
            "4,8,16,32mN",
            "--out",
            s(&out_dir),
        ];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        read_csv(&out_dir.join("areas.csv"))
    };
    let (h, r) = run_csv(&["--threshold", "per-image"], "per");
    let t = column(&h, &r, "threshold");
    assert!(
        t.iter().any(|v| *v != t[0]),
        "per-image thresholds differ: {t:?}"
    );
    let (h, r) = run_csv(&["--threshold", "1000"], "manual");
    assert!(column(&h, &r, "threshold").iter().all(|v| *v == 1000.0));
    let (h0, r0) = run_csv(&[], "default");
    let (h1, r1) = run_csv(&["--pixel-size", "100nm"], "px100");
    let (a0, a1) = (column(&h0, &r0, "area_um2"), column(&h1, &r1, "area_um2"));
    for (x, y) in a0.iter().zip(&a1) {
        assert!((x / 4.0 - y).abs() < 1e-9);
    }
    let (h2, r2) = run_csv(&["--pixel-size", "100x200nm"], "px100x200");
    for (x, y) in a0.iter().zip(&column(&h2, &r2, "area_um2")) {
        assert!((x / 2.0 - y).abs() < 1e-9, "0.02 µm² pixels");
    }
}

#[test]
fn without_pixel_size_areas_are_in_pixels_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let tif = dir.path().join("plain.tif");
    let images = synth::generate(&SynthParams {
        width: 128,
        height: 128,
        forces_n: vec![4e-3, 8e-3],
        ..SynthParams::default()
    })
    .unwrap();
    let pages: Vec<&[u16]> = images.iter().map(|i| i.codes.as_slice()).collect();
    fs::write(&tif, encode_u16_stack(&pages, 128, 128, None, "").unwrap()).unwrap();
    let out_dir = dir.path().join("out");
    let o = run(&[
        "analyze",
        s(&tif),
        "--forces",
        "4,8mN",
        "--out",
        s(&out_dir),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("warning") && stderr(&o).contains("pixels"),
        "{}",
        stderr(&o)
    );
    let (h, r) = read_csv(&out_dir.join("areas.csv"));
    assert!(h.contains(&"area_px".to_string()) && !h.contains(&"mean_pressure_MPa".to_string()));
    assert_eq!(column(&h, &r, "area_px"), column(&h, &r, "contact_pixels"));
    // The PSF the intervals took is in pixels only: no micrometres without a pixel size.
    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    let psf = &summary["area_interval"];
    assert!(psf["psf_fwhm_um"].is_null(), "{psf}");
    let px = psf["psf_fwhm_px"].as_f64().unwrap();
    assert!((px - 2.5 * 2.354_820).abs() < 1e-3, "{px}");
}

#[test]
fn overlays_and_masks() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    small_series(&data, Layout::MultiPage);
    let out_dir = dir.path().join("out");
    let o = run(&[
        "analyze",
        "--manifest",
        s(&data.join("manifest.csv")),
        "--out",
        s(&out_dir),
        "--overlays",
        "--save-masks",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, r) = read_csv(&out_dir.join("areas.csv"));
    let pixels = column(&h, &r, "contact_pixels");
    for (i, expected) in pixels.iter().enumerate() {
        let overlay = out_dir.join(format!("overlay_{:03}_series_p{i}.png", i + 1));
        assert!(overlay.exists(), "{}", overlay.display());
        let mask_path = out_dir.join(format!("mask_{:03}_series_p{i}.tif", i + 1));
        let mut reader = TiffReader::open(&mask_path).unwrap();
        assert!(
            reader.info().pixel_size.is_some(),
            "mask keeps the calibration"
        );
        let mask = reader.read_page(0, 0).unwrap();
        let on = mask.to_f64().iter().filter(|v| **v == 255.0).count();
        assert_eq!(on as f64, *expected);
    }
}

#[test]
fn threshold_and_info_commands() {
    let tif = crate::common::fixture_series().join("series.tif");
    let o = run(&["threshold", s(&tif), "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["method"], "otsu-global");
    assert_eq!(v["pixels"], 8 * 256 * 256);
    let t = v["threshold"].as_f64().unwrap();
    let o = run(&["threshold", s(&tif)]);
    assert!(stdout(&o).starts_with(&format!("{t} ")));
    let o = run(&["info", s(&tif)]);
    let text = stdout(&o);
    for needle in [
        "pages:        8",
        "256 × 256",
        "uint16",
        "none",
        "200.0000 nm",
        "ImageJ",
    ] {
        assert!(text.contains(needle), "{needle} in\n{text}");
    }
}

#[test]
fn bad_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out_dir = d.join("out");
    let good = d.join("good");
    small_series(&good, Layout::MultiPage);
    let series = good.join("series.tif");
    let analyze = |args: &[&str]| {
        let mut all = vec!["analyze"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", s(&out_dir)]);
        run(&all)
    };
    let forces4 = "4,8,16,32mN";

    // Missing file.
    let missing = d.join("missing.tif");
    assert_clean_failure(
        &analyze(&[s(&missing), "--forces", "4mN"]),
        "missing.tif",
        &out_dir,
    );

    // Not a TIFF.
    let text = d.join("notes.tif");
    fs::write(&text, "these are lab notes, not an image").unwrap();
    let o = analyze(&[s(&text), "--forces", "4mN"]);
    assert_clean_failure(&o, "notes.tif", &out_dir);
    assert!(stderr(&o).contains("not a readable TIFF"));

    // Truncated TIFF.
    let bytes = fs::read(&series).unwrap();
    let truncated = d.join("truncated.tif");
    fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    assert_clean_failure(
        &analyze(&[s(&truncated), "--forces", forces4]),
        "truncated.tif",
        &out_dir,
    );

    // Corrupt TIFF: a valid header pointing at a directory beyond the end of the file.
    let corrupt = d.join("corrupt.tif");
    fs::write(&corrupt, b"II*\x00\xff\xff\xff\x00garbage").unwrap();
    assert_clean_failure(
        &analyze(&[s(&corrupt), "--forces", "4mN"]),
        "corrupt.tif",
        &out_dir,
    );

    // Unsupported sample format: 32-bit unsigned integers.
    let u32_file = d.join("uint32.tif");
    {
        let mut f = fs::File::create(&u32_file).unwrap();
        let mut enc = tiff::encoder::TiffEncoder::new(&mut f).unwrap();
        enc.write_image::<tiff::encoder::colortype::Gray32>(4, 4, &[7u32; 16])
            .unwrap();
    }
    let o = analyze(&[s(&u32_file), "--forces", "4mN"]);
    assert_clean_failure(&o, "uint32.tif", &out_dir);
    assert!(stderr(&o).contains("unsupported"), "{}", stderr(&o));

    // A header claiming 200000 × 200000 pixels in a tiny file: refused before allocating.
    let absurd = d.join("absurd.tif");
    fs::write(&absurd, absurd_tiff(200_000, 200_000)).unwrap();
    let o = analyze(&[s(&absurd), "--forces", "4mN"]);
    assert_clean_failure(&o, "absurd.tif", &out_dir);
    assert!(stderr(&o).contains("limit"), "{}", stderr(&o));

    // Mismatched shapes in a series.
    let mixed = d.join("mixed");
    fs::create_dir(&mixed).unwrap();
    let a = vec![100u16; 16 * 16];
    let b = vec![100u16; 16 * 8];
    fs::write(
        mixed.join("img1.tif"),
        encode_u16_stack(&[&a], 16, 16, None, "").unwrap(),
    )
    .unwrap();
    fs::write(
        mixed.join("img2.tif"),
        encode_u16_stack(&[&a], 16, 16, None, "").unwrap(),
    )
    .unwrap();
    fs::write(
        mixed.join("img10.tif"),
        encode_u16_stack(&[&b], 16, 8, None, "").unwrap(),
    )
    .unwrap();
    let o = analyze(&[s(&mixed), "--forces", "1,2,3mN"]);
    assert_clean_failure(&o, "img10.tif (page 0)", &out_dir);
    assert!(stderr(&o).contains("16×8"), "{}", stderr(&o));

    // Constant series.
    let constant = d.join("constant.tif");
    fs::write(
        &constant,
        encode_u16_stack(&[&a, &a], 16, 16, None, "").unwrap(),
    )
    .unwrap();
    let o = analyze(&[s(&constant), "--forces", "1,2mN"]);
    assert_clean_failure(&o, "every pixel has the value 100", &out_dir);

    // Forces count ≠ image count; negative, non-numeric or unit-less forces; unknown units.
    assert_clean_failure(
        &analyze(&[s(&series), "--forces", "4,8mN"]),
        "2 force(s) given for 4 image(s)",
        &out_dir,
    );
    assert_clean_failure(
        &analyze(&[s(&series), "--forces=-4,8,16,32mN"]),
        "negative",
        &out_dir,
    );
    assert_clean_failure(
        &analyze(&[s(&series), "--forces", "4,8,16,32"]),
        "no unit",
        &out_dir,
    );
    assert_clean_failure(
        &analyze(&[s(&series), "--forces", "4,8,16,32furlong"]),
        "unknown force unit 'furlong'",
        &out_dir,
    );
    assert_clean_failure(
        &analyze(&[s(&series), "--forces", forces4, "--pixel-size", "200parsec"]),
        "unknown length unit 'parsec'",
        &out_dir,
    );
    assert_clean_failure(
        &analyze(&[
            s(&series),
            "--forces",
            forces4,
            "--radius",
            "290",
            "--modulus",
            "3.7GPa",
        ]),
        "no unit",
        &out_dir,
    );

    // Manifests: negative force, non-numeric force, missing page, missing column.
    let manifest = |name: &str, body: &str| {
        let p = good.join(name);
        fs::write(&p, body).unwrap();
        p
    };
    let m = manifest("neg.csv", "file,page,force_mN\nseries.tif,0,-4\n");
    assert_clean_failure(&analyze(&["--manifest", s(&m)]), "neg.csv:2", &out_dir);
    let m = manifest(
        "nan.csv",
        "file,page,force_mN\nseries.tif,0,4\nseries.tif,1,lots\n",
    );
    let o = analyze(&["--manifest", s(&m)]);
    assert_clean_failure(&o, "nan.csv:3", &out_dir);
    assert!(stderr(&o).contains("'lots' is not a number"));
    let m = manifest("page.csv", "file,page,force_mN\nseries.tif,9,4\n");
    let o = analyze(&["--manifest", s(&m)]);
    assert_clean_failure(&o, "page 9 is not in", &out_dir);
    assert!(stderr(&o).contains("0..3"), "{}", stderr(&o));
    let m = manifest("cols.csv", "file,force\nseries.tif,4\n");
    assert_clean_failure(&analyze(&["--manifest", s(&m)]), "force_mN", &out_dir);
    let m = manifest("gone.csv", "file,force_mN\nnothere.tif,4\n");
    assert_clean_failure(&analyze(&["--manifest", s(&m)]), "nothere.tif", &out_dir);
}

#[test]
fn an_input_file_is_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    small_series(&data, Layout::MultiPage);
    // A manifest that happens to be called areas.csv, with --out pointing at its own folder.
    let manifest = data.join("areas.csv");
    fs::copy(data.join("manifest.csv"), &manifest).unwrap();
    let before = fs::read(&manifest).unwrap();
    let o = run(&["analyze", "--manifest", s(&manifest), "--out", s(&data)]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("areas.csv") && stderr(&o).contains("input file"),
        "{}",
        stderr(&o)
    );
    assert_eq!(fs::read(&manifest).unwrap(), before);
    assert!(!data.join("summary.json").exists(), "nothing written");
}
