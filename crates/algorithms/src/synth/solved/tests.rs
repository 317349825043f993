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
    // 24.3 mN: the Hertz contact radius is 22 % of the 51.2 µm field; small: 18 % of 12.8 µm.
    let largest = RampSpec::paper(PatchScale::Coarse, 0).forces_n[PRESET_LOADS - 1];
    assert!((largest / 24.31e-3 - 1.0).abs() < 1e-3, "{largest}");
    let small = RampSpec::small(PatchScale::Coarse, 0);
    assert_eq!(small.radius_m, 50e-6);
    let largest = small.forces_n[PRESET_LOADS - 1];
    assert!((largest / 1.207e-3 - 1.0).abs() < 1e-3, "{largest}");
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
}

#[test]
fn truncated_or_corrupt_bytes_are_errors_not_panics() {
    let bytes = solved(PatchScale::PsfSized, 4).encode();
    for len in [0, 3, 8, 12, 100, 114, 200, bytes.len() / 2, bytes.len() - 1] {
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
    let area_at = 114 + 8;
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

/// The small presets at seeds 0, 1, 2 (elastic, hardness, hardening): what their patches are at
/// the middle load (the 4th of 8). On the small map the contact is only a few micrometres wide,
/// so the coarse scale gives one or two ≈ 1 µm patches there; the sub-PSF and PSF-sized scales
/// keep their meaning for the elastic and hardness models.
#[test]
fn small_presets_order_their_patch_scales() {
    for seed in 0..3 {
        let middle = |scale| solved(scale, seed).loads[3].stats.mean_diameter_m;
        let (sub, psf, coarse) = (
            middle(PatchScale::SubPsf),
            middle(PatchScale::PsfSized),
            middle(PatchScale::Coarse),
        );
        assert!(
            sub < psf && psf < coarse,
            "seed {seed}: {sub:e} {psf:e} {coarse:e}"
        );
        if seed % 3 != 2 {
            assert!(sub < SUB_PSF_BELOW_M, "seed {seed}: {sub:e}");
            assert!((0.3e-6..0.9e-6).contains(&psf), "seed {seed}: {psf:e}");
        } else {
            // Hardening (p_Y0 = 0) flattens the fine roughness: larger patches.
            assert!(sub < 1.2e-6, "seed {seed}: {sub:e}");
        }
        assert!(
            (0.8e-6..2.2e-6).contains(&coarse),
            "seed {seed}: {coarse:e}"
        );
        for scale in PatchScale::ALL {
            let loads = &solved(scale, seed).loads;
            let (first, last) = (&loads[0], &loads[PRESET_LOADS - 1]);
            assert!(
                last.stats.largest_m2 > 4.0 * first.stats.largest_m2,
                "{scale:?} seed {seed}: the contact grows together"
            );
            assert!(
                last.contact_radius_m < 0.5 * 12.8e-6,
                "{scale:?} seed {seed}"
            );
        }
    }
}

#[test]
fn measured_scales_follow_the_diameter() {
    assert_eq!(PatchScale::of_diameter(0.2e-6), PatchScale::SubPsf);
    assert_eq!(PatchScale::of_diameter(1.0e-6), PatchScale::PsfSized);
    assert_eq!(PatchScale::of_diameter(3.0e-6), PatchScale::Coarse);
    let load = &solved(PatchScale::SubPsf, 0).loads[3];
    assert_eq!(load.measured_scale(), PatchScale::SubPsf);
}

/// The paper presets (1024², 10–20 s a ramp on 2 cores): the elastic and hardness seeds give
/// the patch scale they are named for at the middle load; every ramp stays inside its map.
/// `cargo test --release -p contactscope synth::solved -- --ignored`.
#[test]
#[ignore = "about a minute: six 1024² ramps"]
fn paper_presets_give_their_patch_scales() {
    for scale in PatchScale::ALL {
        for seed in [0, 1] {
            let ramp = solve_ramp(&RampSpec::paper(scale, seed)).unwrap();
            let middle = &ramp.loads[3];
            assert_eq!(
                middle.measured_scale(),
                scale,
                "seed {seed}: {:e} m",
                middle.stats.mean_diameter_m
            );
            let widest = ramp.loads[PRESET_LOADS - 1].contact_radius_m;
            assert!(
                widest < 0.4 * 51.2e-6,
                "{scale:?} seed {seed}: {widest:e} m"
            );
        }
    }
}
