use std::sync::{Mutex, OnceLock};

use super::*;
use crate::solver::simulate::sweep;

/// The small ramps solved so far, by scale and seed.
type Cache = Mutex<Vec<(PatchScale, u64, &'static ContactRamp)>>;

/// One small ramp per (scale, seed) the tests share: solved once.
fn solved(scale: PatchScale, seed: u64) -> &'static ContactRamp {
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    let mut cache = cache.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, _, r)) = cache.iter().find(|(s, k, _)| *s == scale && *k == seed) {
        return r;
    }
    let ramp: &'static ContactRamp =
        Box::leak(Box::new(solve_ramp(&RampSpec::small(scale, seed)).unwrap()));
    cache.push((scale, seed, ramp));
    ramp
}

#[test]
fn the_masks_are_the_solvers_contact_and_grow_with_force() {
    // Seeds 3, 4, 5: elastic, hardness, hardening.
    for seed in [3, 4, 5] {
        let spec = RampSpec::small(PatchScale::PsfSized, seed);
        let ramp = solved(PatchScale::PsfSized, seed);
        let (body, rms) = rough_sphere(&spec).unwrap();
        let steps = sweep(&setup(&spec, &body, rms), &spec.forces_n, &|_, _| {}).unwrap();
        assert_eq!(ramp.loads.len(), steps.len());
        let mut previous = 0.0;
        for (load, step) in ramp.loads.iter().zip(&steps) {
            assert_eq!(load.area_m2, step.area_m2, "seed {seed}");
            assert_eq!(load.stats.patches, step.patches, "seed {seed}");
            let contact: Vec<u8> = step
                .solution
                .pressure
                .iter()
                .map(|&p| u8::from(p > 0.0))
                .collect();
            assert_eq!(load.mask.to_bytes(), contact);
            assert!(load.area_m2 > previous, "seed {seed}: the area grows");
            previous = load.area_m2;
        }
        assert_eq!(
            ramp.model_name(),
            ["elastic", "hardness", "hardening"][seed as usize % 3]
        );
    }
}

#[test]
fn the_same_spec_gives_the_same_ramp_and_seeds_differ() {
    let spec = RampSpec::small(PatchScale::SubPsf, 7);
    assert_eq!(&solve_ramp(&spec).unwrap(), solved(PatchScale::SubPsf, 7));
    assert_eq!(RampSpec::small(PatchScale::SubPsf, 7), spec);
    let other = solved(PatchScale::SubPsf, 10); // 10 % 3 = 7 % 3: the same model
    assert_ne!(other.spec.hurst, spec.hurst);
    assert_ne!(
        other.loads[4].mask,
        solved(PatchScale::SubPsf, 7).loads[4].mask
    );
}

#[test]
fn presets_rotate_the_model_and_span_two_decades() {
    for seed in 0..6 {
        let spec = RampSpec::paper(PatchScale::Coarse, seed);
        spec.validate().unwrap();
        assert_eq!(spec.forces_n.len(), PRESET_LOADS);
        let span = spec.forces_n[PRESET_LOADS - 1] / spec.forces_n[0];
        assert!((span - 100.0).abs() < 1e-9, "{span}");
        assert!((0.7..=0.9).contains(&spec.hurst));
        let slope = spec.rms_slope / PatchScale::Coarse.rms_slope();
        assert!((0.7..=1.3).contains(&slope), "{slope}");
        match (seed % 3, spec.model) {
            (0, Model::Elastic) => {}
            (1, Model::Hardness { hardness_pa, .. }) => {
                assert!((HARDNESS_RANGE_PA.0..=HARDNESS_RANGE_PA.1).contains(&hardness_pa))
            }
            (2, Model::Hardening { .. }) => {}
            other => panic!("seed {seed}: {other:?}"),
        }
    }
    // The paper's pressures: the largest load's Hertz contact has p₀ = 230 MPa and a radius of
    // 21 % of the field, R = 2E*a/(πp₀): 110 µm and 55.7 mN on 51.2 µm, 27.5 µm and 3.5 mN on
    // 12.8 µm.
    for (spec, field, share, radius, largest) in [
        (
            RampSpec::paper(PatchScale::Coarse, 0),
            51.2e-6,
            HERTZ_RADIUS_SHARE,
            110.1e-6,
            55.68e-3,
        ),
        (
            RampSpec::small(PatchScale::Coarse, 0),
            12.8e-6,
            HERTZ_RADIUS_SHARE_SMALL,
            27.52e-6,
            3.480e-3,
        ),
    ] {
        assert!(
            (spec.radius_m / radius - 1.0).abs() < 1e-3,
            "{}",
            spec.radius_m
        );
        let top = spec.forces_n[PRESET_LOADS - 1];
        assert!((top / largest - 1.0).abs() < 1e-3, "{top}");
        let a = (3.0 * top * spec.radius_m / (4.0 * spec.e_star_pa)).cbrt();
        assert!((a / field - share).abs() < 1e-9);
        let p0 = 2.0 * spec.e_star_pa * a / (std::f64::consts::PI * spec.radius_m);
        assert!((p0 / TOP_HERTZ_PRESSURE_PA - 1.0).abs() < 1e-9, "{p0}");
    }
    assert_eq!(
        RampSpec::paper(PatchScale::SubPsf, 4).preset,
        Some(Preset::Paper)
    );
    assert_eq!(
        RampSpec::small(PatchScale::SubPsf, 4).preset,
        Some(Preset::Small)
    );
}

/// The cloud is the sub-PSF preset before the paper's pressures: R = 290 µm, 0.24–24.3 mN (the
/// Hertz radius 22 % of the field), h′_rms 0.20 ± 30 %, λ_s = 0.2 µm, λ_r = 0.8 µm, with the
/// same draws as the paper preset of its seed.
#[test]
fn the_cloud_is_the_stress_case_of_before() {
    for seed in 0..6 {
        let cloud = RampSpec::cloud(seed);
        let paper = RampSpec::paper(PatchScale::SubPsf, seed);
        cloud.validate().unwrap();
        assert_eq!(
            (cloud.scale, cloud.preset),
            (Some(PatchScale::SubPsf), Some(Preset::Cloud))
        );
        assert_eq!((cloud.size, cloud.sim_pixel_m), (1024, 50e-9));
        assert_eq!((cloud.radius_m, cloud.e_star_pa), (290e-6, 3.7e9));
        assert_eq!((cloud.cutoff_m, cloud.rolloff_m), (0.2e-6, 0.8e-6));
        assert_eq!((cloud.hurst, cloud.model), (paper.hurst, paper.model));
        let factor = cloud.rms_slope / CLOUD_RMS_SLOPE;
        assert!((0.7..=1.3).contains(&factor), "{factor}");
        assert!((factor - paper.rms_slope / PatchScale::SubPsf.rms_slope()).abs() < 1e-12);
        let largest = cloud.forces_n[PRESET_LOADS - 1];
        assert!((largest / 24.31e-3 - 1.0).abs() < 1e-3, "{largest}");
        assert!((cloud.forces_n[0] / largest - 0.01).abs() < 1e-12);
    }
}

#[test]
fn bad_specs_are_refused() {
    let good = RampSpec::small(PatchScale::PsfSized, 0);
    let cases = [
        RampSpec {
            size: 8,
            ..good.clone()
        },
        RampSpec {
            hurst: 1.5,
            ..good.clone()
        },
        RampSpec {
            radius_m: -1.0,
            ..good.clone()
        },
        RampSpec {
            forces_n: vec![2e-3, 1e-3],
            ..good.clone()
        },
        RampSpec {
            forces_n: vec![],
            ..good.clone()
        },
        RampSpec {
            cutoff_m: 50e-9,
            ..good.clone()
        },
    ];
    for spec in cases {
        assert!(solve_ramp(&spec).is_err(), "{spec:?}");
    }
    // A load that pushes the contact to the border is refused, not cut off.
    let too_heavy = RampSpec {
        forces_n: vec![0.5],
        ..good
    };
    let e = solve_ramp(&too_heavy).unwrap_err().to_string();
    assert!(e.contains("border"), "{e}");
}

#[test]
fn encode_decode_round_trip() {
    let ramp = solved(PatchScale::PsfSized, 4);
    let bytes = ramp.encode();
    assert_eq!(&ContactRamp::decode(&bytes).unwrap(), ramp);
    // 8 masks of 256² bits and a little more.
    assert!(bytes.len() < 8 * 256 * 256 / 8 + 2000, "{}", bytes.len());
    // Every label survives, the cloud's and none included.
    for (scale, preset) in [
        (Some(PatchScale::SubPsf), Some(Preset::Cloud)),
        (Some(PatchScale::Coarse), Some(Preset::Paper)),
        (None, None),
    ] {
        let mut labelled = ramp.clone();
        labelled.spec.scale = scale;
        labelled.spec.preset = preset;
        assert_eq!(ContactRamp::decode(&labelled.encode()).unwrap(), labelled);
    }
}

#[test]
fn a_cache_of_another_format_version_is_refused_by_name() {
    let bytes = solved(PatchScale::PsfSized, 4).encode();
    let mut old = bytes[..bytes.len() - 8].to_vec();
    old[8..12].copy_from_slice(&1u32.to_le_bytes());
    let sum = codec_checksum(&old);
    old.extend_from_slice(&sum.to_le_bytes());
    let e = ContactRamp::decode(&old).unwrap_err().to_string();
    assert!(
        e.contains("format version 1, this build reads 2") && e.contains("solve the ramp again"),
        "{e}"
    );
}

#[test]
fn truncated_or_corrupt_bytes_are_errors_not_panics() {
    let bytes = solved(PatchScale::PsfSized, 4).encode();
    for len in [0, 3, 8, 12, 100, 115, 200, bytes.len() / 2, bytes.len() - 1] {
        assert!(ContactRamp::decode(&bytes[..len]).is_err(), "{len}");
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(ContactRamp::decode(&longer).is_err());
    for at in [0, 9, 20, 60, 120, 300, bytes.len() - 3] {
        let mut flipped = bytes.clone();
        flipped[at] ^= 0x10;
        assert!(ContactRamp::decode(&flipped).is_err(), "byte {at}");
    }
    // Sizes beyond the limits with a valid checksum: refused before allocating.
    let mut huge = bytes[..bytes.len() - 8].to_vec();
    huge[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    huge[20..24].copy_from_slice(&u32::MAX.to_le_bytes());
    let sum = codec_checksum(&huge);
    huge.extend_from_slice(&sum.to_le_bytes());
    let e = ContactRamp::decode(&huge).unwrap_err().to_string();
    assert!(e.contains("beyond"), "{e}");
    // A stored area that disagrees with its mask, checksum valid.
    let mut lying = bytes[..bytes.len() - 8].to_vec();
    let area_at = 115 + 8; // the header, then the first load's force
    let area = f64::from_le_bytes(lying[area_at..area_at + 8].try_into().unwrap());
    lying[area_at..area_at + 8].copy_from_slice(&(area * 2.0).to_le_bytes());
    let sum = codec_checksum(&lying);
    lying.extend_from_slice(&sum.to_le_bytes());
    let e = ContactRamp::decode(&lying).unwrap_err().to_string();
    assert!(e.contains("does not match"), "{e}");
}

fn codec_checksum(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[test]
fn bit_masks_pack_and_unpack() {
    let bytes: Vec<u8> = (0..7 * 11).map(|i| u8::from(i % 3 == 0)).collect();
    let mask = BitMask::from_bytes(&bytes, 7, 11).unwrap();
    assert_eq!(mask.to_bytes(), bytes);
    assert_eq!(mask.count(), 26);
    assert!(mask.get(0, 0) && !mask.get(1, 0) && mask.get(3, 0));
    assert!(BitMask::from_bytes(&bytes, 7, 12).is_err());
    assert!(BitMask::from_words(vec![u64::MAX, u64::MAX], 7, 11).is_err());
}

#[test]
fn patch_statistics_of_known_shapes() {
    // Two patches of 4 and 1 pixels of 1 m: diameters 2√(4/π) and 2√(1/π).
    let mask = [1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0, 1];
    let s = PatchStats::of(&mask, 4, 1.0);
    assert_eq!(s.patches, 2);
    let (d4, d1) = (
        2.0 * (4.0 / std::f64::consts::PI).sqrt(),
        2.0 * (1.0 / std::f64::consts::PI).sqrt(),
    );
    assert!((s.mean_diameter_m - (4.0 * d4 + d1) / 5.0).abs() < 1e-12);
    assert!((s.number_mean_diameter_m - (d4 + d1) / 2.0).abs() < 1e-12);
    assert_eq!(s.largest_m2, 4.0);
    assert_eq!(PatchStats::of(&[0; 4], 2, 1.0).mean_diameter_m, 0.0);
}

/// The small presets at seeds 0, 1, 2 (elastic, hardness, hardening) are in the paper's regime:
/// the paper's mean pressures, a compact contact at the largest load, and patches ordered by the
/// scale at the smallest load (where the label holds: the patches merge as the load grows).
#[test]
fn small_presets_are_in_the_papers_regime() {
    for scale in PatchScale::ALL {
        for seed in 0..3 {
            let ramp = solved(scale, seed);
            let (first, last) = (&ramp.loads[0], &ramp.loads[PRESET_LOADS - 1]);
            let what = format!("{scale:?} seed {seed}");
            let (p_first, p_last) = (first.mean_pressure_pa, last.mean_pressure_pa);
            match ramp.spec.model {
                Model::Elastic => {
                    // The paper: ≈ 100 MPa at the smallest load, 250 MPa at the largest. The
                    // coarse scale carries the smallest load on one asperity, at less.
                    assert!((40e6..160e6).contains(&p_first), "{what}: {p_first:e}");
                    assert!((130e6..260e6).contains(&p_last), "{what}: {p_last:e}");
                }
                Model::Hardness { hardness_pa, .. } => {
                    assert!((30e6..160e6).contains(&p_first), "{what}: {p_first:e}");
                    assert!((130e6..hardness_pa).contains(&p_last), "{what}: {p_last:e}");
                }
                // Hardening flattens the fine roughness: below the paper's pressures.
                Model::Hardening { .. } => {
                    assert!((10e6..60e6).contains(&p_first), "{what}: {p_first:e}");
                    assert!((90e6..200e6).contains(&p_last), "{what}: {p_last:e}");
                }
            }
            // Almost Hertzian at the largest load.
            let fill = ramp.central_fill(PRESET_LOADS - 1);
            let least = if seed % 3 == 0 { 0.75 } else { 0.9 };
            assert!(fill >= least, "{what}: central fill {fill}");
            assert!(last.contact_radius_m < 0.375 * 12.8e-6, "{what}");
            assert!(
                last.stats.largest_m2 > 4.0 * first.stats.largest_m2,
                "{what}: the contact grows together"
            );
        }
    }
    // Elastic and hardness: the patches at the smallest load follow the scale, and the sub-PSF
    // ones are below the PSF.
    for seed in 0..2 {
        let smallest = |scale| solved(scale, seed).loads[0].stats.mean_diameter_m;
        let (sub, psf, coarse) = (
            smallest(PatchScale::SubPsf),
            smallest(PatchScale::PsfSized),
            smallest(PatchScale::Coarse),
        );
        assert!(
            sub < psf && psf < coarse,
            "seed {seed}: {sub:e} {psf:e} {coarse:e}"
        );
        assert!(sub < 0.3e-6, "seed {seed}: {sub:e}");
        let share = solved(PatchScale::SubPsf, seed).area_share_below(0, 0.45e-6);
        assert!(share > 0.9, "seed {seed}: {share}");
        assert!((0.35e-6..0.9e-6).contains(&psf), "seed {seed}: {psf:e}");
    }
}

#[test]
fn fill_and_small_patch_share_of_known_masks() {
    let ramp = solved(PatchScale::PsfSized, 4);
    let last = PRESET_LOADS - 1;
    // Within half a pixel of the centre of an even map: the central four pixels.
    let centre = [(127, 127), (128, 127), (127, 128), (128, 128)];
    let on = centre
        .iter()
        .filter(|&&(x, y)| ramp.loads[last].mask.get(x, y))
        .count();
    assert_eq!(ramp.fill_within(last, 0.75 * 50e-9), on as f64 / 4.0);
    assert!(ramp.fill_within(last, 0.1 * 50e-9).is_nan());
    // The whole map: the contact fraction.
    let all = ramp.fill_within(last, 1.0);
    let count = ramp.loads[last].mask.count() as f64;
    assert!((all - count / (256.0 * 256.0)).abs() < 1e-12);
    assert_eq!(ramp.area_share_below(last, 1.0), 1.0);
    assert_eq!(ramp.area_share_below(last, 0.0), 0.0);
    let largest = ramp.loads[last].stats.largest_m2;
    let share = ramp.area_share_below(last, 2.0 * (largest / std::f64::consts::PI).sqrt());
    assert!((0.0..1.0).contains(&share), "{share}");
}

#[test]
fn measured_scales_follow_the_diameter() {
    assert_eq!(PatchScale::of_diameter(0.2e-6), PatchScale::SubPsf);
    assert_eq!(PatchScale::of_diameter(1.0e-6), PatchScale::PsfSized);
    assert_eq!(PatchScale::of_diameter(3.0e-6), PatchScale::Coarse);
    let load = &solved(PatchScale::SubPsf, 0).loads[0];
    assert_eq!(load.measured_scale(), PatchScale::SubPsf);
}

/// The paper presets (1024², 7–18 s a ramp on 2 cores) at seeds 0 and 1 (elastic, hardness):
/// the paper's pressures, the scale's patches at the smallest load, an almost Hertzian contact at
/// the largest, every load inside the map.
/// `cargo test --release -p contactscope synth::solved -- --ignored`.
#[test]
#[ignore = "one to three minutes: six 1024² ramps"]
fn paper_presets_are_in_the_papers_regime() {
    for scale in PatchScale::ALL {
        for seed in [0, 1] {
            let ramp = solve_ramp(&RampSpec::paper(scale, seed)).unwrap();
            let what = format!("{scale:?} seed {seed}");
            let (first, last) = (&ramp.loads[0], &ramp.loads[PRESET_LOADS - 1]);
            let (p_first, p_last) = (first.mean_pressure_pa, last.mean_pressure_pa);
            assert!((60e6..150e6).contains(&p_first), "{what}: {p_first:e}");
            assert!((150e6..280e6).contains(&p_last), "{what}: {p_last:e}");
            let fill = ramp.central_fill(PRESET_LOADS - 1);
            assert!(fill >= 0.78, "{what}: central fill {fill}");
            assert!(last.contact_radius_m < 0.3 * 51.2e-6, "{what}");
            let d = first.stats.mean_diameter_m;
            match scale {
                PatchScale::SubPsf => {
                    let share = ramp.area_share_below(0, 0.45e-6);
                    assert!(share > 0.6, "{what}: {share}");
                    assert!(d < 0.5e-6, "{what}: {d:e}");
                }
                _ => assert_eq!(PatchScale::of_diameter(d), scale, "{what}: {d:e}"),
            }
        }
    }
}
