//! Every real microscope TIFF in `../shared/data/real-tiff` opens and gives a global threshold
//! (or, for multi-channel files without `--channel`, a clear error), with the pixel size its
//! metadata states.
//!
//! External reference: the thresholds below were computed with scikit-image 0.26.0
//! `threshold_otsu` on the arrays tifffile 2026.3.3 returns (all pages together; channel 0 where
//! the file has channels). For integer data skimage uses one bin per level, like contactscope, so
//! the values must agree exactly, except where skimage's float32 class weights pick a near-tie:
//! on those two files exact rational arithmetic (Python `fractions`) gives contactscope's value,
//! whose between-class variance exceeds skimage's choice by 1.5e-9 and 3.5e-8 relative.

use std::path::PathBuf;

use contactscope::analysis::global_threshold;
use contactscope_formats::microscopy::select::{LoadAxis, Selection};
use contactscope_formats::tiff::TiffReader;
use contactscope_formats::Error;
use contactscope_jobs::series;

/// (path under real-tiff, channel, skimage threshold, exact threshold when skimage differs)
const INTEGER_FILES: &[(&str, Option<usize>, f64, Option<f64>)] = &[
    ("aicsimageio/s_1_t_1_c_1_z_1.ome.tiff", None, 3669.0, None),
    ("neubias/xy_12bit__saturated_plant.tif", None, 1399.0, None),
    ("neubias/xy_16bit__autophagosomes.tif", None, 397.0, None),
    (
        "neubias/xy_16bit__nuclei_high_dynamic_range.tif",
        None,
        700.0,
        None,
    ),
    (
        "neubias/xy_16bit__rat_hippocampal_neuron.tif",
        None,
        1579.0,
        None,
    ),
    (
        "neubias/xy_16bit__scanR_datatype_issue.tif",
        None,
        33427.0,
        None,
    ),
    (
        "neubias/xy_calibrated_16bit__nuclear_protein_control.tif",
        None,
        615.0,
        None,
    ),
    (
        "neubias/xyc_16bit__hela-cells.tif",
        Some(0),
        791.0,
        Some(792.0),
    ),
    ("neubias/xyz_16bit__spots.tif", None, 5501.0, None),
    (
        "neubias/xyz_calibrated_16bit__golgi_bfa.tif",
        None,
        2073.0,
        None,
    ),
    (
        "neubias/xyzc_16bit__dna_conf_wf.tif",
        Some(0),
        13003.0,
        Some(13022.0),
    ),
    ("pycudadecon/psf.tif", None, 1961.0, None),
    ("stardist/img2d.tif", None, 47.0, None),
    ("stardist/img3d.tif", None, 206.0, None),
];

fn threshold_of(
    paths: &[PathBuf],
    channel: Option<usize>,
) -> contactscope_jobs::Result<(f64, u64)> {
    // A z stack (ImageJ `slices` with a `spacing`, no frames) is a series only along z.
    let z_stack = paths
        .iter()
        .any(|p| p.to_string_lossy().contains("xyz") && !p.to_string_lossy().contains("xyt"));
    let along = z_stack.then_some(LoadAxis::Z);
    let s = series::from_files_selected(paths, &Selection::channel(channel), along)?;
    let (t, pixels, _) = global_threshold(&s.planes(0), &|_, _, _| {})?;
    Ok((t.value, pixels))
}

#[test]
fn integer_files_match_scikit_image() {
    let Some(dir) = crate::common::shared_data("real-tiff") else {
        return;
    };
    for &(file, channel, skimage, exact) in INTEGER_FILES {
        let (t, pixels) =
            threshold_of(&[dir.join(file)], channel).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert_eq!(t, exact.unwrap_or(skimage), "{file}");
        assert!(pixels > 0);
    }
}

#[test]
fn multi_channel_files_need_a_channel() {
    crate::common::cli_names();
    let Some(dir) = crate::common::shared_data("real-tiff") else {
        return;
    };
    for (file, channels) in [
        ("neubias/xyc_16bit__hela-cells.tif", 3),
        ("neubias/xyzc_16bit__dna_conf_wf.tif", 2),
    ] {
        let err = threshold_of(&[dir.join(file)], None).unwrap_err();
        let text = err.to_string();
        assert!(text.contains(file) && text.contains("--channel"), "{text}");
        assert!(text.contains(&format!("{channels} channels")), "{text}");
        assert!(threshold_of(&[dir.join(file)], Some(channels)).is_err());
    }
    // The hyperstack's channel 1 is the other 45 pages, along z.
    let dna = dir.join("neubias/xyzc_16bit__dna_conf_wf.tif");
    let s = series::from_files_selected(
        std::slice::from_ref(&dna),
        &Selection::channel(Some(1)),
        Some(LoadAxis::Z),
    )
    .unwrap();
    assert_eq!(s.images.len(), 45);
    assert!(s.images.iter().all(|i| i.page % 2 == 1));
    // Without the load axis, the z stack is refused, naming the channels too.
    let err = series::from_files(std::slice::from_ref(&dna), None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("z stack (45 focal planes")
            && err.contains("--load-axis z")
            && err.contains("2 channels"),
        "{err}"
    );
}

#[test]
fn float_series_gives_a_threshold_inside_its_range() {
    let Some(dir) = crate::common::shared_data("real-tiff") else {
        return;
    };
    let file = dir.join("neubias/xyt_calibrated_16bit__golgi_bfa_sum_projection.tif");
    let (t, pixels) = threshold_of(&[file], None).unwrap();
    assert_eq!(pixels, 30 * 137 * 147);
    // README: values 0..103016; skimage's 256-bin threshold is 18309, ours uses 4096 bins.
    assert!(t > 0.0 && t < 103016.0);
    assert!((t - 18309.0).abs() < 103016.0 / 256.0 * 2.0, "t = {t}");
}

#[test]
fn file_series_in_natural_order_gives_one_threshold() {
    let Some(dir) = crate::common::shared_data("real-tiff/neubias/mitocheck-movie") else {
        return;
    };
    let s = series::from_files(std::slice::from_ref(&dir), None).unwrap();
    assert_eq!(s.images.len(), 30);
    let names: Vec<String> = s
        .images
        .iter()
        .map(|i| i.path.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    let mut sorted = names.clone();
    sorted.sort();
    assert_eq!(
        names, sorted,
        "zero-padded names: natural order equals plain order"
    );
    // skimage on the stacked 30 uint8 frames: 28.
    assert_eq!(threshold_of(&[dir], None).unwrap().0, 28.0);
}

#[test]
fn pixel_sizes_from_real_metadata() {
    let Some(dir) = crate::common::shared_data("real-tiff") else {
        return;
    };
    // (file, µm per pixel as the data README states it)
    for (file, um) in [
        ("neubias/xy_12bit__saturated_plant.tif", 2.486),
        ("neubias/xy_16bit__rat_hippocampal_neuron.tif", 0.16),
        (
            "neubias/xy_calibrated_16bit__nuclear_protein_control.tif",
            0.11321,
        ),
        ("neubias/xyz_16bit__spots.tif", 0.09413),
        ("neubias/xyzc_16bit__dna_conf_wf.tif", 0.5119),
        ("aicsimageio/s_1_t_1_c_1_z_1.ome.tiff", 1.0833),
    ] {
        let info = TiffReader::open(&dir.join(file)).unwrap().info().clone();
        let size = info
            .pixel_size
            .unwrap_or_else(|| panic!("{file}: no pixel size"));
        assert!(
            (size.x_m * 1e6 - um).abs() < 1e-3 * um,
            "{file}: {}",
            size.x_m * 1e6
        );
    }
    let blank = TiffReader::open(&dir.join("neubias/xy_16bit__scanR_datatype_issue.tif")).unwrap();
    assert!(blank.info().pixel_size.is_none(), "ImageJ unit is blank");
}

#[test]
fn offset_data_keeps_its_offset() {
    let Some(dir) = crate::common::shared_data("real-tiff") else {
        return;
    };
    let file = dir.join("neubias/xy_16bit__scanR_datatype_issue.tif");
    let (t, _) = threshold_of(&[file], None).unwrap();
    // 12-bit camera data stored as 32768 + value: the threshold lies in the offset range.
    assert!((32963.0..36863.0).contains(&t));
    match threshold_of(&[dir.join("does-not-exist.tif")], None) {
        Err(contactscope_jobs::Error::Format(Error::Io { at, .. })) => {
            assert!(at.path.ends_with("does-not-exist.tif"))
        }
        other => panic!("{other:?}"),
    }
}
