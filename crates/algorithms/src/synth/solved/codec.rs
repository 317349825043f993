//! The binary form of a [`ContactRamp`], for caching solved ramps (a paper ramp is ≈ 1 MiB:
//! 8 masks of 1024² bits).
//!
//! Little-endian throughout:
//!
//! | bytes | field |
//! |---|---|
//! | 8 | magic `CSRAMP\0\x1a` |
//! | 4 | format version ([`VERSION`]) |
//! | 4 + 4 + 4 | width, height, loads |
//! | 8 + 8 | simulation pixel (m), rms height of the roughness (m) |
//! | 1 | patch scale (0 none, 1 sub-PSF, 2 PSF-sized, 3 coarse) |
//! | 1 | preset (0 none, 1 paper, 2 small, 3 cloud) |
//! | 6 × 8 | H, h′_rms, λ_r (m), λ_s (m), R (m), E* (Pa) |
//! | 1 + 8 + 8 | model: 0 elastic, 1 hardness (p_Y), 2 volume-conserving hardness (p_Y, α), 3 hardening (k, p_Y0) |
//! | 8 | seed |
//! | per load | force (N), area (m²), mean pressure (Pa), contact radius (m), patches (u64), area- and number-weighted mean diameters (m), largest patch (m²), contact pixels (u64), then the mask's ⌈width·height/64⌉ words |
//! | 8 | FNV-1a 64 of every byte before it |
//!
//! [`decode`] checks the magic, the version and the checksum, then the sizes against
//! [`MAX_SIZE`] and [`MAX_LOADS`] and the buffer's length before allocating anything, and
//! finally that the stored counts and areas agree with the masks: a truncated or corrupt buffer
//! is an error, never a panic.

use super::{
    BitMask, ContactRamp, PatchScale, PatchStats, Preset, RampSpec, SolvedLoad, MAX_LOADS, MAX_SIZE,
};
use crate::error::{Error, Result};
use crate::solver::simulate::Model;

/// The first eight bytes.
pub const MAGIC: [u8; 8] = *b"CSRAMP\0\x1a";
/// The format version this code writes and reads.
pub const VERSION: u32 = 2;
/// Bytes before the first load.
const HEADER: usize = 8 + 4 + 12 + 16 + 2 + 48 + 17 + 8;
/// Bytes of a load's numbers, before its mask.
const LOAD_FIXED: usize = 9 * 8;

/// FNV-1a, 64 bits.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The ramp's bytes (module docs).
pub fn encode(ramp: &ContactRamp) -> Vec<u8> {
    let words = ramp.width * ramp.height;
    let mut out =
        Vec::with_capacity(HEADER + ramp.loads.len() * (LOAD_FIXED + words.div_ceil(64) * 8) + 8);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    for v in [ramp.width, ramp.height, ramp.loads.len()] {
        out.extend_from_slice(&(v as u32).to_le_bytes());
    }
    let spec = &ramp.spec;
    let f = |out: &mut Vec<u8>, v: f64| out.extend_from_slice(&v.to_le_bytes());
    f(&mut out, ramp.sim_pixel_m);
    f(&mut out, ramp.rms_height_m);
    out.push(spec.scale.map_or(0, PatchScale::code));
    out.push(spec.preset.map_or(0, Preset::code));
    for v in [
        spec.hurst,
        spec.rms_slope,
        spec.rolloff_m,
        spec.cutoff_m,
        spec.radius_m,
        spec.e_star_pa,
    ] {
        f(&mut out, v);
    }
    let (tag, a, b) = match spec.model {
        Model::Elastic => (0, 0.0, 0.0),
        Model::Hardness {
            hardness_pa,
            volume_conserving: None,
        } => (1, hardness_pa, 0.0),
        Model::Hardness {
            hardness_pa,
            volume_conserving: Some(alpha),
        } => (2, hardness_pa, alpha),
        Model::Hardening {
            modulus_pa_per_m,
            initial_pa,
        } => (3, modulus_pa_per_m, initial_pa),
    };
    out.push(tag);
    f(&mut out, a);
    f(&mut out, b);
    out.extend_from_slice(&spec.seed.to_le_bytes());
    for load in &ramp.loads {
        for v in [
            load.force_n,
            load.area_m2,
            load.mean_pressure_pa,
            load.contact_radius_m,
        ] {
            f(&mut out, v);
        }
        out.extend_from_slice(&load.stats.patches.to_le_bytes());
        for v in [
            load.stats.mean_diameter_m,
            load.stats.number_mean_diameter_m,
            load.stats.largest_m2,
        ] {
            f(&mut out, v);
        }
        out.extend_from_slice(&load.mask.count().to_le_bytes());
        for w in load.mask.words() {
            out.extend_from_slice(&w.to_le_bytes());
        }
    }
    let sum = fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

fn corrupt(reason: impl std::fmt::Display) -> Error {
    Error::InvalidArgument(format!("solved ramp bytes: {reason}"))
}

/// Bounds-checked little-endian reads.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(corrupt(format!(
                "truncated: {N} bytes wanted at offset {}, {} present",
                self.at,
                self.bytes.len()
            )));
        };
        let mut out = [0; N];
        out.copy_from_slice(&self.bytes[self.at..end]);
        self.at = end;
        Ok(out)
    }

    fn u8(&mut self) -> Result<u8> {
        Ok(self.take::<1>()?[0])
    }

    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.take()?))
    }

    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.take()?))
    }

    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(self.take()?))
    }
}

/// A ramp from [`encode`]'s bytes (module docs).
pub fn decode(bytes: &[u8]) -> Result<ContactRamp> {
    if bytes.len() < HEADER + 8 {
        return Err(corrupt(format!(
            "truncated: {} bytes, the header alone is {}",
            bytes.len(),
            HEADER + 8
        )));
    }
    if bytes[..8] != MAGIC {
        return Err(corrupt("not a solved ramp (wrong magic)"));
    }
    let (body, tail) = bytes.split_at(bytes.len() - 8);
    let stored = u64::from_le_bytes(tail.try_into().expect("eight bytes"));
    let mut r = Reader { bytes: body, at: 8 };
    let version = r.u32()?;
    if version != VERSION {
        return Err(corrupt(format!(
            "format version {version}, this build reads {VERSION} (a cache written by another version: solve the ramp again)"
        )));
    }
    if fnv1a(body) != stored {
        return Err(corrupt("checksum mismatch (truncated or corrupt)"));
    }
    let (width, height, count) = (r.u32()? as usize, r.u32()? as usize, r.u32()? as usize);
    if width == 0 || height == 0 || width > MAX_SIZE || height > MAX_SIZE || count > MAX_LOADS {
        return Err(corrupt(format!(
            "{width}×{height} px, {count} loads: beyond {MAX_SIZE} px or {MAX_LOADS} loads"
        )));
    }
    let words = (width * height).div_ceil(64);
    let expected = HEADER + count * (LOAD_FIXED + 8 * words) + 8;
    if bytes.len() != expected {
        return Err(corrupt(format!(
            "{} bytes where {width}×{height} px and {count} loads take {expected}",
            bytes.len()
        )));
    }
    let (sim_pixel_m, rms_height_m) = (r.f64()?, r.f64()?);
    let scale = PatchScale::from_code(r.u8()?).ok_or_else(|| corrupt("unknown patch scale"))?;
    let preset = Preset::from_code(r.u8()?).ok_or_else(|| corrupt("unknown preset"))?;
    let mut numbers = [0.0; 6];
    for v in &mut numbers {
        *v = r.f64()?;
    }
    let [hurst, rms_slope, rolloff_m, cutoff_m, radius_m, e_star_pa] = numbers;
    let (tag, a, b) = (r.u8()?, r.f64()?, r.f64()?);
    let model = match tag {
        0 => Model::Elastic,
        1 => Model::Hardness {
            hardness_pa: a,
            volume_conserving: None,
        },
        2 => Model::Hardness {
            hardness_pa: a,
            volume_conserving: Some(b),
        },
        3 => Model::Hardening {
            modulus_pa_per_m: a,
            initial_pa: b,
        },
        other => return Err(corrupt(format!("unknown model {other}"))),
    };
    let seed = r.u64()?;
    let mut loads = Vec::with_capacity(count);
    for _ in 0..count {
        let (force_n, area_m2, mean_pressure_pa, contact_radius_m) =
            (r.f64()?, r.f64()?, r.f64()?, r.f64()?);
        let patches = r.u64()?;
        let (mean_diameter_m, number_mean_diameter_m, largest_m2) = (r.f64()?, r.f64()?, r.f64()?);
        let contact_px = r.u64()?;
        let packed = (0..words).map(|_| r.u64()).collect::<Result<Vec<_>>>()?;
        let mask = BitMask::from_words(packed, width, height).map_err(corrupt)?;
        if mask.count() != contact_px || mask.count() as f64 * sim_pixel_m * sim_pixel_m != area_m2
        {
            return Err(corrupt(format!(
                "a mask of {} px does not match its stored {contact_px} px, {area_m2:e} m²",
                mask.count()
            )));
        }
        loads.push(SolvedLoad {
            force_n,
            mask,
            area_m2,
            mean_pressure_pa,
            contact_radius_m,
            stats: PatchStats {
                patches,
                mean_diameter_m,
                number_mean_diameter_m,
                largest_m2,
            },
        });
    }
    let spec = RampSpec {
        scale,
        preset,
        size: width,
        sim_pixel_m,
        hurst,
        rms_slope,
        rolloff_m,
        cutoff_m,
        radius_m,
        e_star_pa,
        model,
        forces_n: loads.iter().map(|l| l.force_n).collect(),
        seed,
    };
    if width != height {
        return Err(corrupt(format!("a {width}×{height} map is not square")));
    }
    spec.validate().map_err(corrupt)?;
    Ok(ContactRamp {
        width,
        height,
        sim_pixel_m,
        rms_height_m,
        spec,
        loads,
    })
}
