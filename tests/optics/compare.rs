//! `contactscope compare`: micrographs rendered from a simulation at a known offset (and mirrored)
//! must be registered back with high overlap; bad inputs fail cleanly.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::{column, read_csv, rough_surface, run, stderr};
use contactscope::optics::blur::Grid;
use contactscope::spectral::register::Dihedral;
use contactscope::synth::{render_micrograph, MicrographParams};
use contactscope_formats::tiff::read_image;
use contactscope_formats::tiff::write::encode_u16_stack;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const FORCES_MN: [f64; 3] = [0.5, 1.0, 2.0];
const IMAGE_PX: usize = 96;

/// A 256² rough sphere at 50 nm (12.8 µm) simulated elastically at three loads.
fn simulation(dir: &Path) -> PathBuf {
    let topo = dir.join("rough.npy");
    rough_surface(
        &topo,
        256,
        "50nm",
        4,
        &["--rolloff", "2um", "--cutoff", "200nm"],
    );
    let sim = dir.join("sim");
    let o = run(&[
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
        "0.5mN,1mN,2mN",
        "--model",
        "elastic",
        "--quiet",
        "--out",
        s(&sim),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    sim
}

/// Micrographs of the simulated maps at 200 nm with FWHM 450 nm, the map's corner at
/// (23, 12) instead of the centred (16, 16), optionally transformed; series.tif + manifest.csv.
fn micrographs(dir: &Path, sim: &Path, transform: Dihedral) -> PathBuf {
    let exp = dir.join(format!("exp-{}", transform.name()));
    fs::create_dir_all(&exp).unwrap();
    let mut pages = Vec::new();
    for (i, _) in FORCES_MN.iter().enumerate() {
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
            width: IMAGE_PX,
            height: IMAGE_PX,
            corner_px: (23, 12),
            background: 300.0,
            contact_level: 2500.0,
            counts_per_photon: 4.0,
            seed: i as u64,
        };
        let codes = render_micrograph(&grid, &params).unwrap();
        let values: Vec<f64> = codes.iter().map(|&c| f64::from(c)).collect();
        let (moved, _, _) = transform.apply(&values, IMAGE_PX, IMAGE_PX);
        pages.push(moved.iter().map(|&v| v as u16).collect::<Vec<u16>>());
    }
    let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(&refs, IMAGE_PX, IMAGE_PX, Some((200e-9, 200e-9)), "").unwrap();
    fs::write(exp.join("series.tif"), tiff).unwrap();
    let mut manifest = String::from("file,page,force_mN\n");
    for (i, f) in FORCES_MN.iter().enumerate() {
        manifest.push_str(&format!("series.tif,{i},{f}\n"));
    }
    fs::write(exp.join("manifest.csv"), manifest).unwrap();
    exp
}

fn compare(exp: &Path, sim: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "compare",
        "--micrographs",
        s(exp),
        "--simulation",
        s(sim),
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn recovers_the_offset_and_overlaps_the_simulation() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulation(dir.path());
    let exp = micrographs(dir.path(), &sim, Dihedral::IDENTITY);
    let out = dir.path().join("cmp");
    let o = compare(&exp, &sim, &out, &["--psf-fwhm", "450nm"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&out.join("compare.csv"));
    assert_eq!(rows.len(), 3);
    let col = |name: &str| column(&header, &rows, name);
    for (i, force) in col("force_mN").iter().enumerate() {
        assert!((force - FORCES_MN[i]).abs() < 1e-9);
        let (dx, dy) = (col("shift_x_px")[i], col("shift_y_px")[i]);
        assert!(
            (dx - 7.0).abs() <= 0.1 && (dy + 4.0).abs() <= 0.1,
            "load {i}: shift ({dx}, {dy})"
        );
        let dice = col("dice")[i];
        assert!(dice > 0.85, "load {i}: Dice {dice}");
        let jaccard = col("jaccard")[i];
        assert!((jaccard - dice / (2.0 - dice)).abs() < 1e-4);
        let ratio = col("area_ratio")[i];
        assert!(
            (0.85..1.15).contains(&ratio),
            "load {i}: area ratio {ratio}"
        );
        assert!(col("acf_rms_distance")[i] < 0.1, "load {i}: ACF distance");
        // Edges agree to about a micrograph pixel (200 nm).
        let edge = col("edge_distance_um")[i];
        assert!(
            edge > 0.0 && edge < 0.3,
            "load {i}: edge distance {edge} µm"
        );
        assert!(out.join(format!("panel_{:03}.png", i + 1)).is_file());
    }
    assert!(rows
        .iter()
        .all(|r| r[header.iter().position(|h| h == "transform").unwrap()] == "identity"));
    // Blurring merges the sub-resolution patches, so thresholding the blurred map gives more area
    // than the raw g = 0 pixels (docs/methods.md §7.1): the reason both are reported.
    let (raw, blurred) = (col("simulated_raw_area_um2"), col("simulated_area_um2"));
    for (r, b) in raw.iter().zip(&blurred) {
        assert!(b > r, "raw {r} µm² vs blurred {b} µm²");
    }
    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(out.join("compare.json")).unwrap()).unwrap();
    assert_eq!(summary["loads_matched"], 3);
    assert_eq!(summary["psf_fwhm_nm"].as_f64().unwrap().round(), 450.0);
    // One shift for the series, each load refined near it; shifts in µm at 200 nm pixels.
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let series = &summary["series_registration"];
    assert_eq!(series["transform"], "identity");
    assert_eq!(series["window_px"], 3);
    assert!(
        (f(&series["shift_x_px"]) - 7.0).abs() <= 0.1
            && (f(&series["shift_y_px"]) + 4.0).abs() <= 0.1,
        "{series}"
    );
    assert!(f(&series["correlation_peak"]) > 0.05, "{series}");
    let loads = summary["loads"].as_array().unwrap();
    for item in loads.iter().chain([series]) {
        for axis in ["x", "y"] {
            let (px, um) = (
                f(&item[format!("shift_{axis}_px")]),
                f(&item[format!("shift_{axis}_um")]),
            );
            assert!((um - 0.2 * px).abs() < 1e-9, "{item}");
        }
    }
    for l in loads {
        assert_eq!(l["refinement"], "refined", "{l}");
        assert!(f(&l["correlation_peak"]) > 0.05, "{l}");
    }
    assert!(
        summary["warnings"].as_array().unwrap().is_empty(),
        "{}",
        summary["warnings"]
    );
}

#[test]
fn a_mirrored_micrograph_needs_the_dihedral_search() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulation(dir.path());
    let mirror = Dihedral {
        transpose: false,
        flip_x: true,
        flip_y: false,
    };
    let exp = micrographs(dir.path(), &sim, mirror);
    let psf = dir.path().join("psf.json");
    fs::write(&psf, r#"{"fwhm_nm_mean": 450.0}"#).unwrap();
    let with = dir.path().join("with");
    let o = compare(&exp, &sim, &with, &["--psf", s(&psf), "--dihedral"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&with.join("compare.csv"));
    let t = header.iter().position(|h| h == "transform").unwrap();
    assert!(rows.iter().all(|r| r[t] == "flip-x"), "{rows:?}");
    let summary: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(with.join("compare.json")).unwrap()).unwrap();
    assert_eq!(summary["series_registration"]["transform"], "flip-x");
    let dice_with = column(&header, &rows, "dice");
    assert!(dice_with.iter().all(|&d| d > 0.85), "{dice_with:?}");

    let without = dir.path().join("without");
    let o = compare(&exp, &sim, &without, &["--psf", s(&psf)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&without.join("compare.csv"));
    let dice_without = column(&header, &rows, "dice");
    for (w, wo) in dice_with.iter().zip(&dice_without) {
        assert!(wo + 0.2 < *w, "mirror not undone: Dice {wo} vs {w}");
    }
}

#[test]
fn bad_inputs_fail_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let sim = simulation(dir.path());
    let exp = micrographs(dir.path(), &sim, Dihedral::IDENTITY);
    let out = dir.path().join("cmp");

    // No common load.
    let far = dir.path().join("far.csv");
    fs::write(
        &far,
        format!("file,page,force_mN\n{},0,7\n", s(&exp.join("series.tif"))),
    )
    .unwrap();
    let o = compare(&far, &sim, &out, &["--psf-fwhm", "450nm"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no common load"), "{}", stderr(&o));

    // Not a simulation folder.
    let o = compare(&exp, &exp, &out, &["--psf-fwhm", "450nm"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("areas.csv"), "{}", stderr(&o));

    // A psf.json without a FWHM; no PSF at all.
    let bad_psf = dir.path().join("bad.json");
    fs::write(&bad_psf, "{}").unwrap();
    let o = compare(&exp, &sim, &out, &["--psf", s(&bad_psf)]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("bad.json") && stderr(&o).contains("fwhm_nm_mean"));
    let o = compare(&exp, &sim, &out, &[]);
    assert!(!o.status.success());
    assert!(!out.exists(), "no output after failures");
}
