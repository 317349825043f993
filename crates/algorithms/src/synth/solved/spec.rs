//! The presets: which patch scale, which model, which sphere and loads a solved ramp is made
//! of ([`RampSpec`]), and the constants they are drawn from (module docs of [`super`]).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::Model;
use crate::error::{Error, Result};

/// The ChaCha8 stream the presets draw H, h′_rms and p_Y from (the surface's noise uses
/// stream 0 of the same seed).
const PRESET_STREAM: u64 = 0x0050_17ed;
/// Where the penetration hardness of the hardness seeds is drawn, Pa: above the paper presets'
/// mean pressures, so that it caps only the highest asperities there (it carries the cloud's
/// contacts at 155–190 MPa).
pub const HARDNESS_RANGE_PA: (f64, f64) = (200e6, 280e6);
/// Hardening modulus of the hardening seeds: 4 MPa/nm (the paper's k), Pa/m.
pub const HARDENING_PA_PER_M: f64 = 4e15;
/// Largest Hertz contact radius of a [`RampSpec::paper`] ramp, as a share of the field side.
pub const HERTZ_RADIUS_SHARE: f64 = 0.21;
/// Largest Hertz contact radius of a [`RampSpec::small`] ramp, as a share of the field side.
pub const HERTZ_RADIUS_SHARE_SMALL: f64 = 0.21;
/// Hertz centre pressure p₀ at the largest load of [`RampSpec::paper`] and [`RampSpec::small`],
/// Pa: the paper's 400 mN on R = 290 µm.
pub const TOP_HERTZ_PRESSURE_PA: f64 = 230e6;
/// Contact modulus of the presets, Pa (polystyrene on glass).
pub const E_STAR_PA: f64 = 3.7e9;
/// Simulation pixel of the presets, m.
pub const SIM_PIXEL_M: f64 = 50e-9;
/// Sphere radius of [`RampSpec::cloud`], m (the paper's).
pub const CLOUD_RADIUS_M: f64 = 290e-6;
/// Largest Hertz contact radius of [`RampSpec::cloud`], as a share of the field side.
pub const CLOUD_HERTZ_RADIUS_SHARE: f64 = 0.22;
/// Short-wavelength cutoff λ_s of [`RampSpec::cloud`], m.
pub const CLOUD_CUTOFF_M: f64 = 0.2e-6;
/// Roll-off wavelength λ_r of [`RampSpec::cloud`], m.
pub const CLOUD_ROLLOFF_M: f64 = 0.8e-6;
/// Central rms slope of [`RampSpec::cloud`] (each seed draws within ±30 % of it).
pub const CLOUD_RMS_SLOPE: f64 = 0.20;
/// Loads per preset ramp.
pub const PRESET_LOADS: usize = 8;
/// Area-weighted patch diameters below this are sub-PSF ([`PatchScale::of_diameter`]), m.
pub const SUB_PSF_BELOW_M: f64 = 0.35e-6;
/// Area-weighted patch diameters from this on are coarse ([`PatchScale::of_diameter`]), m.
pub const COARSE_FROM_M: f64 = 1.75e-6;
/// The largest grid side [`solve_ramp`] takes (a free boundary pads to twice this).
pub const MAX_SIZE: usize = 4096;
/// The most loads a ramp may have.
pub const MAX_LOADS: usize = 1024;

/// Which patch size a preset is made for, relative to a confocal PSF of 300–750 nm FWHM, at the
/// smallest loads of a ramp (at the paper's pressures the patches merge as the load grows: module
/// docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PatchScale {
    /// Patches below the PSF at the smallest loads (area-weighted ≈ 0.2–0.6 µm, most of the area
    /// in patches under 0.45 µm).
    SubPsf,
    /// Patches of the PSF's size at the smallest loads (area-weighted ≈ 0.7–2 µm), as the
    /// paper's "patches 0.3–1.5 µm".
    PsfSized,
    /// Two or three asperity contacts of ≈ 2–3 µm at the smallest load, many PSF widths.
    Coarse,
}

impl PatchScale {
    /// All scales.
    pub const ALL: [PatchScale; 3] = [PatchScale::SubPsf, PatchScale::PsfSized, PatchScale::Coarse];

    /// Name used in outputs (`sub_psf`, `psf_sized`, `coarse`).
    pub fn name(self) -> &'static str {
        match self {
            PatchScale::SubPsf => "sub_psf",
            PatchScale::PsfSized => "psf_sized",
            PatchScale::Coarse => "coarse",
        }
    }

    /// Short-wavelength cutoff λ_s, m: sets the smallest patches.
    pub fn cutoff_m(self) -> f64 {
        match self {
            PatchScale::SubPsf => 0.15e-6,
            PatchScale::PsfSized => 0.5e-6,
            PatchScale::Coarse => 3.2e-6,
        }
    }

    /// Roll-off wavelength λ_r = 2 λ_s, m (clamped to half the field on smaller maps).
    pub fn rolloff_m(self) -> f64 {
        2.0 * self.cutoff_m()
    }

    /// Central rms slope h′_rms of [`RampSpec::paper`] (each seed draws within ±30 % of it): the
    /// elastic mean pressure at the smallest load comes out at the paper's ≈ 100 MPa (module
    /// docs).
    pub fn rms_slope(self) -> f64 {
        match self {
            PatchScale::SubPsf => 0.07,
            PatchScale::PsfSized => 0.06,
            PatchScale::Coarse => 0.075,
        }
    }

    /// Central rms slope h′_rms of [`RampSpec::small`]: [`PatchScale::rms_slope`], but 0.0525
    /// for the coarse scale, whose 3.2–6.4 µm wavelengths are as wide as the small map's whole
    /// contact: at 0.075 a valley at the centre left the largest load open in a sixth of the
    /// seeds (central fill down to 0.52; module docs).
    pub fn small_rms_slope(self) -> f64 {
        match self {
            PatchScale::Coarse => 0.0525,
            other => other.rms_slope(),
        }
    }

    /// The scale a measured area-weighted patch diameter (m) falls in: below 0.35 µm sub-PSF,
    /// from 0.35 µm to 1.75 µm PSF-sized, above coarse. The presets' labels describe the
    /// surface and hold at the smallest loads; the measured patches also depend on the model and
    /// the load (they merge as the load grows: module docs), so a benchmark that groups by patch
    /// size should group by this.
    pub fn of_diameter(mean_diameter_m: f64) -> PatchScale {
        if mean_diameter_m < SUB_PSF_BELOW_M {
            PatchScale::SubPsf
        } else if mean_diameter_m < COARSE_FROM_M {
            PatchScale::PsfSized
        } else {
            PatchScale::Coarse
        }
    }

    pub(super) fn code(self) -> u8 {
        match self {
            PatchScale::SubPsf => 1,
            PatchScale::PsfSized => 2,
            PatchScale::Coarse => 3,
        }
    }

    pub(super) fn from_code(code: u8) -> Option<Option<PatchScale>> {
        match code {
            0 => Some(None),
            1 => Some(Some(PatchScale::SubPsf)),
            2 => Some(Some(PatchScale::PsfSized)),
            3 => Some(Some(PatchScale::Coarse)),
            _ => None,
        }
    }
}

/// Which constructor a [`RampSpec`] came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Preset {
    /// [`RampSpec::paper`]: 1024², the paper's pressures.
    Paper,
    /// [`RampSpec::small`]: 256², the paper's pressures, for tests.
    Small,
    /// [`RampSpec::cloud`]: the stress case outside the paper's regime.
    Cloud,
}

impl Preset {
    /// Name used in outputs (`paper`, `small`, `cloud`).
    pub fn name(self) -> &'static str {
        match self {
            Preset::Paper => "paper",
            Preset::Small => "small",
            Preset::Cloud => "cloud",
        }
    }

    pub(super) fn code(self) -> u8 {
        match self {
            Preset::Paper => 1,
            Preset::Small => 2,
            Preset::Cloud => 3,
        }
    }

    pub(super) fn from_code(code: u8) -> Option<Option<Preset>> {
        match code {
            0 => Some(None),
            1 => Some(Some(Preset::Paper)),
            2 => Some(Some(Preset::Small)),
            3 => Some(Some(Preset::Cloud)),
            _ => None,
        }
    }
}

/// Everything a contact ramp is solved from. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct RampSpec {
    /// The patch scale of the preset this spec came from (`None`: made by hand); recorded, not
    /// used by the solver.
    pub scale: Option<PatchScale>,
    /// The preset this spec came from (`None`: made by hand); recorded, not used by the solver.
    pub preset: Option<Preset>,
    /// Grid side, pixels (square map, free boundary).
    pub size: usize,
    /// Simulation pixel, m.
    pub sim_pixel_m: f64,
    /// Hurst exponent H ∈ (0, 1]: the PSD falls as q^(−2−2H).
    pub hurst: f64,
    /// rms slope of the roughness (central differences); sets the elastic mean pressure.
    pub rms_slope: f64,
    /// Roll-off wavelength λ_r, m.
    pub rolloff_m: f64,
    /// Short-wavelength cutoff λ_s, m.
    pub cutoff_m: f64,
    /// Sphere radius R, m.
    pub radius_m: f64,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// The contact model.
    pub model: Model,
    /// Normal forces, N, strictly increasing (the plastic state carries from each to the next).
    pub forces_n: Vec<f64>,
    /// Seed of the surface (and, for the presets, of the drawn parameters).
    pub seed: u64,
}

/// `n` forces log-spaced from `first` to `last`.
fn log_spaced(first: f64, last: f64, n: usize) -> Vec<f64> {
    let ratio = (last / first).ln();
    (0..n)
        .map(|i| first * (ratio * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// The sphere radius, m, and the preset forces, N, of a `size`² map of [`SIM_PIXEL_M`] pixels:
/// the largest force's Hertz contact radius is `share` of the field and its Hertz centre
/// pressure [`TOP_HERTZ_PRESSURE_PA`] (p₀ = 2E*a/(πR), so R = 2E*a/(πp₀)); the forces span two
/// decades.
fn paper_sphere(size: usize, share: f64) -> (f64, Vec<f64>) {
    let a_m = share * size as f64 * SIM_PIXEL_M;
    let radius_m = 2.0 * E_STAR_PA * a_m / (std::f64::consts::PI * TOP_HERTZ_PRESSURE_PA);
    let largest = hertz_load(a_m, radius_m, E_STAR_PA);
    (radius_m, log_spaced(largest / 100.0, largest, PRESET_LOADS))
}

/// Hertz load whose contact radius is `a`, N = 4E*a³/(3R) (Johnson 1985, Eq. 4.22).
fn hertz_load(a_m: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    4.0 * e_star_pa * a_m.powi(3) / (3.0 * radius_m)
}

impl RampSpec {
    /// A paper-sized ramp at the paper's pressures (module docs): 1024² × 50 nm, R = 110 µm,
    /// E* = 3.7 GPa, 8 loads over two decades up to 55.7 mN (Hertz p₀ = 230 MPa), the model by
    /// `seed % 3`, H and h′_rms drawn from the seed.
    pub fn paper(scale: PatchScale, seed: u64) -> Self {
        let (radius_m, forces_n) = paper_sphere(1024, HERTZ_RADIUS_SHARE);
        let surface = (scale.cutoff_m(), scale.rolloff_m(), scale.rms_slope());
        Self::preset(
            Preset::Paper,
            scale,
            surface,
            seed,
            1024,
            radius_m,
            forces_n,
        )
    }

    /// The same pressures on a map small enough for a test (module docs): 256² × 50 nm,
    /// R = 27.5 µm, 8 loads over two decades up to 3.5 mN. The contact is a few micrometres wide,
    /// so [`PatchScale::Coarse`] gives one or two patches at every load.
    pub fn small(scale: PatchScale, seed: u64) -> Self {
        let (radius_m, forces_n) = paper_sphere(256, HERTZ_RADIUS_SHARE_SMALL);
        let surface = (scale.cutoff_m(), scale.rolloff_m(), scale.small_rms_slope());
        Self::preset(Preset::Small, scale, surface, seed, 256, radius_m, forces_n)
    }

    /// The stress case **outside the paper's regime** (module docs): the sub-PSF preset of
    /// before, 1024² × 50 nm, R = 290 µm, 8 loads over two decades up to 24.3 mN, h′_rms =
    /// 0.20 ± 30 %, λ_s = 0.2 µm, λ_r = 0.8 µm. Its contacts are a cloud of sub-PSF patches at
    /// every load, which no image of the series resolves: their area cannot be measured by
    /// fluorescence. The model and the draws as [`RampSpec::paper`] of the same seed.
    pub fn cloud(seed: u64) -> Self {
        let size = 1024;
        let radius_m = CLOUD_RADIUS_M;
        let field = size as f64 * SIM_PIXEL_M;
        let largest = hertz_load(CLOUD_HERTZ_RADIUS_SHARE * field, radius_m, E_STAR_PA);
        let forces_n = log_spaced(largest / 100.0, largest, PRESET_LOADS);
        let surface = (CLOUD_CUTOFF_M, CLOUD_ROLLOFF_M, CLOUD_RMS_SLOPE);
        Self::preset(
            Preset::Cloud,
            PatchScale::SubPsf,
            surface,
            seed,
            size,
            radius_m,
            forces_n,
        )
    }

    #[allow(clippy::too_many_arguments)]
    fn preset(
        preset: Preset,
        scale: PatchScale,
        (cutoff_m, rolloff_m, rms_slope): (f64, f64, f64),
        seed: u64,
        size: usize,
        radius_m: f64,
        forces_n: Vec<f64>,
    ) -> Self {
        let field = size as f64 * SIM_PIXEL_M;
        // Drawn from a stream of their own, always the same three draws in the same order.
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(PRESET_STREAM);
        let (u_hurst, u_slope, u_hardness): (f64, f64, f64) =
            (rng.random(), rng.random(), rng.random());
        let model = match seed % 3 {
            0 => Model::Elastic,
            1 => Model::Hardness {
                hardness_pa: HARDNESS_RANGE_PA.0
                    + u_hardness * (HARDNESS_RANGE_PA.1 - HARDNESS_RANGE_PA.0),
                volume_conserving: None,
            },
            _ => Model::Hardening {
                modulus_pa_per_m: HARDENING_PA_PER_M,
                initial_pa: 0.0,
            },
        };
        RampSpec {
            scale: Some(scale),
            preset: Some(preset),
            size,
            sim_pixel_m: SIM_PIXEL_M,
            hurst: 0.7 + 0.2 * u_hurst,
            rms_slope: rms_slope * (0.7 + 0.6 * u_slope),
            rolloff_m: rolloff_m.min(field / 2.0),
            cutoff_m,
            radius_m,
            e_star_pa: E_STAR_PA,
            model,
            forces_n,
            seed,
        }
    }

    /// Check the spec; the surface's own checks (wavelengths against the grid) follow in
    /// [`solve_ramp`].
    pub fn validate(&self) -> Result<()> {
        if !(16..=MAX_SIZE).contains(&self.size) {
            return Err(Error::Value {
                what: "solved ramp: grid side",
                value: self.size as f64,
                unit: "px",
                requirement: "must lie in 16..=4096",
            });
        }
        let positive = [
            ("solved ramp: simulation pixel", self.sim_pixel_m, "m"),
            ("solved ramp: rms slope", self.rms_slope, ""),
            ("solved ramp: roll-off wavelength", self.rolloff_m, "m"),
            ("solved ramp: cutoff wavelength", self.cutoff_m, "m"),
            ("solved ramp: sphere radius", self.radius_m, "m"),
            ("solved ramp: contact modulus", self.e_star_pa, "Pa"),
        ];
        for (what, value, unit) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(Error::not_positive(what, value, unit));
            }
        }
        if !(self.hurst > 0.0 && self.hurst <= 1.0) {
            return Err(Error::Value {
                what: "solved ramp: Hurst exponent",
                value: self.hurst,
                unit: "",
                requirement: "must lie in (0, 1]",
            });
        }
        if self.forces_n.is_empty() || self.forces_n.len() > MAX_LOADS {
            return Err(Error::Value {
                what: "solved ramp: number of loads",
                value: self.forces_n.len() as f64,
                unit: "",
                requirement: "must lie in 1..=1024",
            });
        }
        let mut previous = 0.0;
        for &f in &self.forces_n {
            if !(f.is_finite() && f > previous) {
                return Err(Error::Value {
                    what: "solved ramp: force",
                    value: f,
                    unit: "N",
                    requirement: "must be positive, finite and above the previous load",
                });
            }
            previous = f;
        }
        Ok(())
    }
}
