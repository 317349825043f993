//! The paper's contacts with exact truth, for validating per-image area intervals: contact masks
//! solved by the bundled half-space solver for self-affine rough spheres ([`solve_ramp`]), then
//! imaged as a confocal microscope records them ([`camera::image_ramp`]).
//!
//! Weber et al., Nat. Commun. 9, 888 (2018) press a rough polystyrene sphere (R = 290 µm) on a
//! coverslip coated with rigidochromic molecules, which fluoresce only where the gap is a few
//! nanometres; the contact area is the pixels above one global Otsu threshold. Here the truth is
//! the solver's contact (pressure > 0, the paper's g ≡ 0 maps, Methods: "Numerical
//! simulations"), so every micrograph comes with its exact area, mask and patch statistics.
//!
//! Two stages, so that one solved ramp is re-imaged under many conditions:
//!
//! 1. **The ramp** ([`RampSpec`] → [`solve_ramp`] → [`ContactRamp`]): a self-affine surface
//!    ([`crate::surface::generate::self_affine`], scaled to an rms slope) on a sphere
//!    ([`crate::surface::Topography::add_sphere`]), pressed through log-spaced loads with the
//!    plastic state carried from each load to the next ([`crate::solver::simulate::sweep_each`],
//!    free boundary). A ramp is kept as bit-packed masks and encodes to a small versioned binary
//!    format ([`ContactRamp::encode`], [`ContactRamp::decode`]) so that it can be cached.
//! 2. **The camera** ([`camera::Camera`] → [`camera::image_ramp`]): PSF blur on the simulation
//!    grid, exact area integration onto camera pixels at a seeded sub-pixel placement, an
//!    illumination field, the rigidochromic signal rising with load, Poisson photons, gain, read
//!    noise, dark offset, 12 bits.
//!
//! This is a forward model of its own: it shares nothing with [`super::series`] but the solver,
//! the surface generator, the optics and the patch counter.
//!
//! ```
//! use contactscope::synth::solved::{image_ramp, solve_ramp, Camera, ContactRamp, PatchScale, RampSpec};
//!
//! let ramp = solve_ramp(&RampSpec::small(PatchScale::PsfSized, 1))?; // hardness, ½ s
//! let cached = ramp.encode();
//! assert_eq!(ContactRamp::decode(&cached)?, ramp);
//! // 200 nm pixels, 500 nm FWHM, 40 photons in a fully covered contact pixel at the first load.
//! let images = image_ramp(&ramp, &Camera::new(200e-9, 500e-9, 40.0, 7))?;
//! for (image, truth) in images.iter().zip(&ramp.loads) {
//!     assert_eq!((image.width, image.height), (64, 64)); // the whole 12.8 µm field
//!     assert_eq!(image.true_area_m2, truth.area_m2);
//! }
//! # Ok::<(), contactscope::Error>(())
//! ```
//!
//! ## Presets
//!
//! [`RampSpec::paper`]: 1024² pixels of 50 nm (a 51.2 µm field), R = 290 µm, E* = 3.7 GPa
//! (polystyrene on glass), 8 loads log-spaced over two decades (the paper's 4–400 mN is two
//! decades), 0.24–24 mN: the largest is the Hertz load (N = 4E*a³/(3R)) whose contact radius is
//! 22 % of the field ([`HERTZ_RADIUS_SHARE`]), so that the rough contact, which spreads beyond
//! Hertz's, stays inside the map (measured below). [`RampSpec::small`]: the same physics on 256² pixels of 50 nm
//! (12.8 µm), R = 50 µm, 0.012–1.2 mN (Hertz radius 18 % of the field), about half a second per
//! ramp, for tests.
//!
//! The model rotates with the seed: `seed % 3` = 0 elastic, 1 penetration hardness (Eq. 4, p_Y
//! drawn in [`HARDNESS_RANGE_PA`], so that the mean pressures come out at 135–205 MPa),
//! 2 linear hardening (k = 4 MPa/nm, p_Y0 = 0, the paper's fit). Per seed the Hurst exponent is
//! drawn in 0.7–0.9 and the rms slope within ±30 % of the scale's value.
//!
//! The roughness is set by its **rms slope** (central differences,
//! [`crate::surface::generate::RmsTarget::Slope`]), not its rms height: the slope fixes the
//! elastic mean pressure over the real contact (Persson: p̄ ≈ h′_rms E*/κ, κ ≈ 2) and with it
//! the contact fraction p_nominal/p̄, which together with the short-wavelength cutoff λ_s decides
//! how the contact is cut into patches. A narrow band (λ_r = 4 λ_s) keeps the patches from
//! clustering on longer wavelengths.
//!
//! | scale | λ_s | λ_r | h′_rms | patches meant (area-weighted, middle loads) |
//! |---|---|---|---|---|
//! | [`PatchScale::SubPsf`] | 0.2 µm | 0.8 µm | 0.20 | ≈ 0.1–0.3 µm, below a 300–750 nm PSF |
//! | [`PatchScale::PsfSized`] | 0.6 µm | 2.4 µm | 0.12 | ≈ 0.4–1.5 µm, the paper's "0.3–1.5 µm" |
//! | [`PatchScale::Coarse`] | 3.2 µm | 12.8 µm | 0.08 | ≳ 2–5 µm, many PSF widths |
//!
//! ## Measured
//!
//! Per scale and model: the area-weighted mean equivalent diameter d_A = Σ aᵢ·2√(aᵢ/π) / Σ aᵢ
//! of the 8-connected patches ([`PatchStats`]), the patches and the true area at the smallest,
//! the middle (4th of 8) and the largest load, the mean pressure at the middle load, the
//! farthest contact pixel from the centre (2 r_max / field side) and the seconds per ramp on
//! the 2-core development machine (shared with another job while measured; `solve_ramp` only;
//! on the machine alone a paper ramp took 9–14 s and a small one 0.4–0.7 s). Imaging a paper
//! ramp ([`camera::image_ramp`], 8 loads) takes 0.3–0.6 s; its encoded form is 1.05 MB and
//! encodes and decodes in 4 ms.
//!
//! [`RampSpec::paper`] (seeds 0–8 for the sub-PSF and PSF-sized scales, 0–14 for coarse):
//!
//! | scale | model | seeds | d_A (µm) | patches | area (µm²) | p̄ (MPa) | 2r/L | s |
//! |---|---|---|---|---|---|---|---|---|
//! | sub-PSF | elastic | 3 | 0.17–0.18 / **0.20–0.25** / 0.34–0.53 | 53–83 / 269–294 / 1368–1555 | 0.7–1.2 / 5.0–7.4 / 62–91 | 237–353 | 0.55 | 17 |
//! | sub-PSF | hardness | 3 | 0.20–0.24 / **0.31–0.32** / 1.1–3.2 | 72–92 / 282–301 / 958–1110 | 1.5–1.6 / 10–11 / 130–141 | 159–172 | 0.55 | 13 |
//! | sub-PSF | hardening | 3 | 0.40 / **1.45–2.56** / 18–20 | 129–140 / 239–272 / 307–412 | 6.7–7.9 / 35–41 / 320–353 | 42–50 | 0.58 | 12 |
//! | PSF-sized | elastic | 3 | 0.51–0.60 / **0.59–0.93** / 1.8–4.9 | 7–19 / 45–60 / 134–175 | 1.0–2.3 / 7.9–12.5 / 100–139 | 140–222 | 0.57 | 15 |
//! | PSF-sized | hardness | 3 | 0.54–0.91 / **0.80–1.00** / 5.4–9.9 | 7–17 / 42–46 / 88–120 | 1.4–1.8 / 11–13 / 146–165 | 136–159 | 0.55 | 12 |
//! | PSF-sized | hardening | 3 | 0.92–1.43 / **1.71–3.02** / 16–19 | 11–24 / 41–51 / 57–77 | 4.1–6.6 / 28–40 / 286–333 | 44–63 | 0.59 | 10 |
//! | coarse | elastic | 5 | 1.12–1.56 / **2.24–3.00** / 8.4–14 | 1–4 / 3–7 / 4–6 | 1.9–4.4 / 11–20 / 142–209 | 86–162 | 0.69 | 20 |
//! | coarse | hardness | 5 | 1.36–2.14 / **2.18–3.27** / 7.4–15 | 1–3 / 4–6 / 4–12 | 2.1–4.0 / 12–21 / 148–218 | 82–144 | 0.67 | 20 |
//! | coarse | hardening | 5 | 1.58–2.54 / **3.05–5.85** / 11–19 | 1–3 / 2–6 / 4–10 | 2.8–8.4 / 15–35 / 203–295 | 50–119 | 0.80 | 10 |
//!
//! [`RampSpec::small`] (seeds 0–29, ten per model):
//!
//! | scale | model | d_A (µm) | patches | area (µm²) | p̄ (MPa) | 2r/L | s |
//! |---|---|---|---|---|---|---|---|
//! | sub-PSF | elastic | 0.11–0.18 / **0.16–0.26** / 0.33–0.80 | 2–9 / 12–20 / 69–95 | 0.02–0.1 / 0.2–0.4 / 3–5 | 216–414 | 0.53 | 0.6 |
//! | sub-PSF | hardness | 0.12–0.23 / **0.19–0.31** / 0.47–1.7 | 3–9 / 15–25 / 49–82 | 0.1 / 0.4–0.5 / 5–7 | 161–203 | 0.53 | 0.6 |
//! | sub-PSF | hardening | 0.23–0.36 / **0.39–1.04** / 3.6–4.8 | 8–23 / 22–38 / 25–49 | 0.3–0.6 / 1.9–2.8 / 16–20 | 32–46 | 0.62 | 0.6 |
//! | PSF-sized | elastic | 0.22–0.36 / **0.38–0.69** / 0.93–1.9 | 1–3 / 2–7 / 7–16 | 0.1 / 0.4–0.6 / 4–7 | 140–232 | 0.66 | 0.7 |
//! | PSF-sized | hardness | 0.26–0.37 / **0.38–0.78** / 1.4–3.1 | 1–2 / 2–7 / 3–16 | 0.1 / 0.5–0.6 / 6–9 | 135–179 | 0.61 | 0.7 |
//! | PSF-sized | hardening | 0.41–0.81 / **0.70–1.59** / 2.7–4.8 | 1–7 / 2–9 / 3–13 | 0.3–0.6 / 1.3–3.1 / 14–20 | 28–67 | 0.64 | 0.6 |
//! | coarse | elastic | 0.44–0.64 / **0.86–1.36** / 2.1–3.9 | 1 / 1–3 / 1–3 | 0.2–0.3 / 0.6–2.0 / 4–13 | 43–148 | 0.77 | 0.6 |
//! | coarse | hardness | 0.47–0.65 / **0.92–1.21** / 2.1–3.8 | 1 / 1–2 / 1–3 | 0.2–0.3 / 0.7–1.4 / 6–12 | 61–129 | 0.62 | 0.6 |
//! | coarse | hardening | 0.80–1.07 / **1.39–2.04** / 3.1–5.7 | 1 / 1–3 / 1–3 | 0.5–0.9 / 1.5–3.8 / 9–26 | 23–57 | 0.91 | 0.5 |
//!
//! What the numbers say:
//!
//! * The elastic and hardness seeds give the scale they are named for at the middle loads
//!   ([`PatchScale::of_diameter`] of the 4th load equals the label; the ignored test
//!   `paper_presets_give_their_patch_scales` checks seeds 0 and 1). The contact grows from a
//!   scatter of asperity patches at the smallest load to a much larger, more connected contact
//!   (d_A grows 2–50 fold from the smallest to the largest load); elastic sub-PSF contacts
//!   stay a dense cloud of sub-PSF patches even at the largest load (the real pressure,
//!   h′_rms E*/2 ≈ 240–350 MPa, stays well above the nominal one), which a 300–750 nm PSF
//!   images as a grey disc.
//! * **Linear hardening** (k = 4 MPa/nm, p_Y0 = 0) carries the load at 40–120 MPa: it flattens
//!   the fine roughness, so its patches are one scale coarser than the label at the middle
//!   load (sub-PSF → PSF-sized, PSF-sized → coarse). No roughness within the stated ranges
//!   avoids this (an rms slope of 0.43 at the sub-PSF scale still gave 0.6–0.9 µm). Group by
//!   the measured scale ([`SolvedLoad::measured_scale`]) or leave out `seed % 3 == 2` where a
//!   pure scale is wanted.
//! * On the small map the contact is at most a few micrometres wide: the coarse scale gives one
//!   or two patches of ≈ 1 µm at the middle load there.
//! * Every paper ramp of the seeds above stays inside its map (no contact on the border); the
//!   farthest contact pixel lies at most 0.35 field sides from the centre for the elastic and
//!   hardness seeds (the widest contact ≤ 70 % of the field) and 0.40 for hardening, whose
//!   plastic flattening spreads the contact furthest.

pub mod camera;
pub mod codec;
mod mask;

pub use camera::{image_ramp, Camera, ImagedLoad};
pub use mask::{BitMask, PatchStats};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::{Error, Result};
use crate::solver::cg::SolverOptions;
use crate::solver::halfspace::Boundary;
use crate::solver::simulate::{sweep_each, LoadStep, Model, Setup};
use crate::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use crate::surface::Topography;

/// The ChaCha8 stream the presets draw H, h′_rms and p_Y from (the surface's noise uses
/// stream 0 of the same seed).
const PRESET_STREAM: u64 = 0x0050_17ed;
/// Where the penetration hardness of the hardness seeds is drawn, Pa.
pub const HARDNESS_RANGE_PA: (f64, f64) = (200e6, 280e6);
/// Hardening modulus of the hardening seeds: 4 MPa/nm (the paper's k), Pa/m.
pub const HARDENING_PA_PER_M: f64 = 4e15;
/// Largest Hertz contact radius of a [`RampSpec::paper`] ramp, as a share of the field side.
pub const HERTZ_RADIUS_SHARE: f64 = 0.22;
/// Largest Hertz contact radius of a [`RampSpec::small`] ramp, as a share of the field side:
/// smaller, because the roughness is the paper's and the sphere's sag over the field is not.
pub const HERTZ_RADIUS_SHARE_SMALL: f64 = 0.18;
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

/// Which patch size a preset is made for, relative to a confocal PSF of 300–750 nm FWHM.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PatchScale {
    /// Patches mostly below the PSF (≈ 0.1–0.3 µm at the middle loads).
    SubPsf,
    /// Patches of the PSF's size (≈ 0.4–1.5 µm), as the paper's "patches 0.3–1.5 µm".
    PsfSized,
    /// Patches many times the PSF (≳ 2–5 µm).
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
            PatchScale::SubPsf => 0.2e-6,
            PatchScale::PsfSized => 0.6e-6,
            PatchScale::Coarse => 3.2e-6,
        }
    }

    /// Roll-off wavelength λ_r, m (clamped to half the field on smaller maps).
    pub fn rolloff_m(self) -> f64 {
        match self {
            PatchScale::SubPsf => 0.8e-6,
            PatchScale::PsfSized => 2.4e-6,
            PatchScale::Coarse => 12.8e-6,
        }
    }

    /// Central rms slope h′_rms (each seed draws within ±30 % of it).
    pub fn rms_slope(self) -> f64 {
        match self {
            PatchScale::SubPsf => 0.20,
            PatchScale::PsfSized => 0.12,
            PatchScale::Coarse => 0.08,
        }
    }

    /// The scale a measured area-weighted patch diameter (m) falls in: below 0.35 µm sub-PSF,
    /// from 0.35 µm to 1.75 µm PSF-sized, above coarse (the bounds halve the gaps between the
    /// ranges the presets are made for). The presets' labels describe the surface; the measured
    /// patches also depend on the model and the load (module docs), so a benchmark that groups
    /// by patch size should group by this.
    pub fn of_diameter(mean_diameter_m: f64) -> PatchScale {
        if mean_diameter_m < SUB_PSF_BELOW_M {
            PatchScale::SubPsf
        } else if mean_diameter_m < COARSE_FROM_M {
            PatchScale::PsfSized
        } else {
            PatchScale::Coarse
        }
    }

    fn code(self) -> u8 {
        match self {
            PatchScale::SubPsf => 1,
            PatchScale::PsfSized => 2,
            PatchScale::Coarse => 3,
        }
    }

    fn from_code(code: u8) -> Option<Option<PatchScale>> {
        match code {
            0 => Some(None),
            1 => Some(Some(PatchScale::SubPsf)),
            2 => Some(Some(PatchScale::PsfSized)),
            3 => Some(Some(PatchScale::Coarse)),
            _ => None,
        }
    }
}

/// Everything a contact ramp is solved from. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct RampSpec {
    /// The preset this spec came from (`None`: made by hand); recorded, not used by the solver.
    pub scale: Option<PatchScale>,
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

/// Hertz load whose contact radius is `a`, N = 4E*a³/(3R) (Johnson 1985, Eq. 4.22).
fn hertz_load(a_m: f64, radius_m: f64, e_star_pa: f64) -> f64 {
    4.0 * e_star_pa * a_m.powi(3) / (3.0 * radius_m)
}

impl RampSpec {
    /// A paper-sized ramp (module docs): 1024² × 50 nm, R = 290 µm, E* = 3.7 GPa, 8 loads over
    /// two decades up to 24.3 mN, the model by `seed % 3`, H and h′_rms drawn from the seed.
    pub fn paper(scale: PatchScale, seed: u64) -> Self {
        Self::preset(scale, seed, 1024, 290e-6, HERTZ_RADIUS_SHARE)
    }

    /// The same physics on a map small enough for a test: 256² × 50 nm (12.8 µm), R = 50 µm,
    /// 8 loads over two decades up to 1.2 mN. The contact is at most a few micrometres wide, so
    /// [`PatchScale::Coarse`] gives one or two patches of ≈ 1 µm at the middle loads (module
    /// docs).
    pub fn small(scale: PatchScale, seed: u64) -> Self {
        Self::preset(scale, seed, 256, 50e-6, HERTZ_RADIUS_SHARE_SMALL)
    }

    fn preset(scale: PatchScale, seed: u64, size: usize, radius_m: f64, share: f64) -> Self {
        let sim_pixel_m = 50e-9;
        let e_star_pa = 3.7e9;
        let field = size as f64 * sim_pixel_m;
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
        let largest = hertz_load(share * field, radius_m, e_star_pa);
        RampSpec {
            scale: Some(scale),
            size,
            sim_pixel_m,
            hurst: 0.7 + 0.2 * u_hurst,
            rms_slope: scale.rms_slope() * (0.7 + 0.6 * u_slope),
            rolloff_m: scale.rolloff_m().min(field / 2.0),
            cutoff_m: scale.cutoff_m(),
            radius_m,
            e_star_pa,
            model,
            forces_n: log_spaced(largest / 100.0, largest, PRESET_LOADS),
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

/// The truth at one load of a solved ramp.
#[derive(Debug, Clone, PartialEq)]
pub struct SolvedLoad {
    /// Normal force, N.
    pub force_n: f64,
    /// The contact (pressure > 0) on the simulation grid.
    pub mask: BitMask,
    /// True contact area, m²: contact pixels × pixel area, the solver's `LoadStep::area_m2`.
    pub area_m2: f64,
    /// Force / area, Pa.
    pub mean_pressure_pa: f64,
    /// Distance of the farthest contact pixel centre from the map centre, m.
    pub contact_radius_m: f64,
    /// The patches.
    pub stats: PatchStats,
}

impl SolvedLoad {
    /// The patch scale of this load's measured patches ([`PatchScale::of_diameter`]).
    pub fn measured_scale(&self) -> PatchScale {
        PatchScale::of_diameter(self.stats.mean_diameter_m)
    }
}

/// A solved load ramp: the masks and their truth.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactRamp {
    /// Columns of the simulation grid.
    pub width: usize,
    /// Rows of the simulation grid.
    pub height: usize,
    /// Simulation pixel, m.
    pub sim_pixel_m: f64,
    /// rms height of the generated roughness, m.
    pub rms_height_m: f64,
    /// What it was solved from.
    pub spec: RampSpec,
    /// One per force, in the spec's order.
    pub loads: Vec<SolvedLoad>,
}

impl ContactRamp {
    /// The forces, N.
    pub fn forces_n(&self) -> Vec<f64> {
        self.loads.iter().map(|l| l.force_n).collect()
    }

    /// The true contact areas, m².
    pub fn true_areas_m2(&self) -> Vec<f64> {
        self.loads.iter().map(|l| l.area_m2).collect()
    }

    /// The contact model's name (`elastic`, `hardness`, `hardening`).
    pub fn model_name(&self) -> &'static str {
        self.spec.model.name()
    }

    /// The ramp in its binary form (module [`codec`]).
    pub fn encode(&self) -> Vec<u8> {
        codec::encode(self)
    }

    /// A ramp from [`ContactRamp::encode`]'s bytes; a truncated or corrupt buffer is an error.
    pub fn decode(bytes: &[u8]) -> Result<Self> {
        codec::decode(bytes)
    }
}

/// The solver limits of a ramp (as the demo's truth ramp): tolerance 1e-8 on the gap relative
/// to the roughness' rms height, at most 5000 iterations per load.
fn options(rms_height_m: f64) -> SolverOptions<'static> {
    SolverOptions {
        tolerance: 1e-8,
        gap_scale_m: Some(rms_height_m),
        max_iterations: 5000,
        ..SolverOptions::default()
    }
}

/// The rigid body of a spec: the self-affine roughness on the sphere, and the roughness' rms
/// height, m.
fn rough_sphere(spec: &RampSpec) -> Result<(Topography, f64)> {
    let roughness = self_affine(&SelfAffineParams {
        nx: spec.size,
        ny: spec.size,
        dx_m: spec.sim_pixel_m,
        hurst: spec.hurst,
        rolloff_wavelength_m: Some(spec.rolloff_m),
        short_cutoff_wavelength_m: Some(spec.cutoff_m),
        target: RmsTarget::Slope(spec.rms_slope),
        seed: spec.seed,
    })?;
    let rms_height_m = roughness.rms_height();
    let mut body = roughness;
    body.add_sphere(spec.radius_m)?;
    Ok((body, rms_height_m))
}

/// The solver set-up of a spec's body: free boundary, the spec's model, [`options`].
fn setup<'a>(spec: &RampSpec, body: &'a Topography, rms_height_m: f64) -> Setup<'a> {
    Setup {
        topography: body,
        e_star_pa: spec.e_star_pa,
        boundary: Boundary::Free,
        model: spec.model,
        options: options(rms_height_m),
    }
}

/// Solve a ramp: the rough sphere of `spec` pressed through its forces (free boundary, the
/// plastic state carried from load to load). Errors if the contact touches the border of the map
/// at any load (the truth would be cut off: use a larger map or smaller forces).
pub fn solve_ramp(spec: &RampSpec) -> Result<ContactRamp> {
    spec.validate()?;
    let n = spec.size;
    let (body, rms_height_m) = rough_sphere(spec)?;
    let setup = setup(spec, &body, rms_height_m);
    let mut loads = Vec::with_capacity(spec.forces_n.len());
    sweep_each(&setup, &spec.forces_n, &mut |_, step| {
        loads.push(truth(&step, n, spec.sim_pixel_m)?);
        Ok(())
    })?;
    Ok(ContactRamp {
        width: n,
        height: n,
        sim_pixel_m: spec.sim_pixel_m,
        rms_height_m,
        spec: spec.clone(),
        loads,
    })
}

/// The truth of one solved load.
fn truth(step: &LoadStep, n: usize, pixel_m: f64) -> Result<SolvedLoad> {
    if step.edge_contact {
        return Err(Error::InvalidArgument(format!(
            "solved ramp: the contact at {:.4e} N touches the border of the {n}×{n} map; use a \
             larger map or smaller forces",
            step.force_n
        )));
    }
    let bytes: Vec<u8> = step
        .solution
        .pressure
        .iter()
        .map(|&p| u8::from(p > 0.0))
        .collect();
    let mask = BitMask::from_bytes(&bytes, n, n)?;
    // The solver's own area, LoadStep::area_m2, counts the same pixels on the same grid.
    let area_m2 = mask.count() as f64 * pixel_m * pixel_m;
    let centre = (n as f64 - 1.0) / 2.0;
    let farthest = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b != 0)
        .map(|(i, _)| ((i % n) as f64 - centre).hypot((i / n) as f64 - centre))
        .fold(0.0, f64::max);
    Ok(SolvedLoad {
        force_n: step.force_n,
        area_m2,
        mean_pressure_pa: if area_m2 > 0.0 {
            step.force_n / area_m2
        } else {
            f64::NAN
        },
        contact_radius_m: farthest * pixel_m,
        stats: PatchStats::of(&bytes, n, pixel_m),
        mask,
    })
}

#[cfg(test)]
mod tests;
