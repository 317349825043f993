//! `psf` on planes in memory against the same planes as a file, the saturation rule, and the
//! two unit systems of the outcome.

use contactscope::image::SampleType;
use contactscope::optics::psf::FWHM_PER_SIGMA;
use contactscope::synth::beads::{synth_beads, BeadParams, SyntheticBeads};
use contactscope_formats::tiff::write::encode_u16_stack;

use super::files::run_to_folder;
use super::*;
use crate::images::MemoryImages;

fn beads() -> SyntheticBeads {
    synth_beads(&BeadParams {
        crowded_pair: true,
        saturated_bead: true,
        seed: 3,
        ..BeadParams::default()
    })
    .unwrap()
}

fn in_memory(b: &SyntheticBeads) -> ImageInput {
    ImageInput::Memory(MemoryImages {
        label: "beads".into(),
        width: b.width,
        height: b.height,
        planes: b
            .planes
            .iter()
            .map(|p| p.iter().map(|&v| f64::from(v)).collect())
            .collect(),
        sample_type: SampleType::U16,
    })
}

#[test]
fn planes_in_memory_give_the_outcome_of_their_file() {
    let b = beads();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("beads.tif");
    let pages: Vec<&[u16]> = b.planes.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(&pages, b.width, b.height, Some((1e-7, 1e-7)), "").unwrap();
    std::fs::write(&path, tiff).unwrap();
    let (file, written) = run_to_folder(
        &PsfRequest::new(ImageInput::File(path.clone())),
        &dir.path().join("out"),
        &["test".into()],
    )
    .unwrap();
    assert_eq!(written.len(), 3);
    let memory = run(&PsfRequest {
        pixel_size_m: Some((1e-7, 1e-7)),
        ..PsfRequest::new(in_memory(&b))
    })
    .unwrap();
    // 12-bit data in 16 bits: saturation at 4095 for both; the saturated and the crowded
    // beads are left out.
    assert_eq!(memory.saturation_level, Some(4095.0));
    let reasons: Vec<&str> = memory.skipped.iter().map(|s| s.reason).collect();
    assert!(
        reasons.contains(&"saturated") && reasons.contains(&"crowded"),
        "{reasons:?}"
    );
    let mut a = serde_json::to_value(&file).unwrap();
    let mut m = serde_json::to_value(&memory).unwrap();
    for v in [&mut a, &mut m] {
        let o = v.as_object_mut().unwrap();
        o.shift_remove("input");
        o.shift_remove("pixel_size_source");
    }
    assert_eq!(a, m);
    // psf.json is the outcome without its rows; beads.csv has them.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("out/psf.json")).unwrap()).unwrap();
    assert!(json.get("beads").is_none() && json["fwhm_nm_mean"].is_number());
    let csv = std::fs::read_to_string(dir.path().join("out/beads.csv")).unwrap();
    assert_eq!(csv.lines().count(), memory.beads.len() + 1);
    assert!(csv.starts_with("bead,x_px,y_px,plane,page,x_um,y_um,peak,background,"));
}

#[test]
fn saturation_follows_the_sample_type() {
    let image = |max: f64| Image {
        values: vec![0.0, max],
        width: 2,
        height: 1,
        pixel_size: None,
        path: "x".into(),
        page: 0,
    };
    let level = |t, bits, max| saturation_level((t, bits), &[image(max)]);
    assert_eq!(level(SampleType::U8, 8, 10.0), Some(255.0));
    assert_eq!(level(SampleType::U16, 16, 4095.0), Some(4095.0));
    assert_eq!(level(SampleType::U16, 16, 4096.0), Some(65535.0));
    assert_eq!(level(SampleType::U16, 14, 9000.0), Some(16383.0));
    assert_eq!(level(SampleType::I16, 16, 10.0), Some(32767.0));
    assert_eq!(level(SampleType::F32, 32, 1e9), None);
}

#[test]
fn the_request_checks_what_it_can() {
    let b = beads();
    // Planes in memory have no pixel size of their own.
    let e = PsfRequest::new(in_memory(&b)).check().unwrap_err();
    assert!(e.to_string().contains("pixel size"), "{e}");
    let bad = PsfRequest {
        pixel_size_m: Some((1e-7, 1e-7)),
        bead_diameter_m: Some(5.0),
        ..PsfRequest::new(in_memory(&b))
    };
    assert!(bad.check().is_err());
    let selected = PsfRequest {
        pixel_size_m: Some((1e-7, 1e-7)),
        selection: Selection {
            z: Some(1),
            ..Selection::default()
        },
        ..PsfRequest::new(in_memory(&b))
    };
    assert!(selected.check().is_err());
}

#[test]
fn fwhm_in_nm_in_the_file_and_in_m_in_si() {
    let s = MeanSd {
        mean: 1.9e-7,
        sd: Some(1e-9),
    };
    let spreads = PsfSpreads {
        sigma_m: s,
        sigma_raw_m: s,
        sigma_x_m: s,
        sigma_y_m: s,
    };
    let lab = serde_json::to_value(spreads).unwrap();
    assert_eq!(lab["fwhm_nm_mean"], 1.9e-7 * (1e9 * FWHM_PER_SIGMA));
    assert_eq!(lab["sigma_nm_sd"], 1e-9 * 1e9);
    let si = lab::to_si_value(&spreads).unwrap();
    assert_eq!(si["fwhm_m_mean"], 1.9e-7 * FWHM_PER_SIGMA);
    assert_eq!(si["sigma_x_2d_m_sd"], 1e-9);
    assert_eq!(si.as_object().unwrap().len(), 12);
}
