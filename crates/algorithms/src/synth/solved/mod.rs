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
//! let ramp = solve_ramp(&RampSpec::small(PatchScale::PsfSized, 1))?; // hardness, under a second
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
//! Every preset: pixels of 50 nm, E* = 3.7 GPa (polystyrene on glass), 8 loads log-spaced over
//! two decades (the paper's 4–400 mN is two decades). The model rotates with the seed:
//! `seed % 3` = 0 elastic, 1 penetration hardness (Eq. 4, p_Y drawn in [`HARDNESS_RANGE_PA`]),
//! 2 linear hardening (k = 4 MPa/nm, p_Y0 = 0, the paper's fit). Per seed the Hurst exponent is
//! drawn in 0.7–0.9 and the rms slope within ±30 % of the scale's value.
//!
//! **The paper's pressures.** The paper's sphere (R = 290 µm) at 400 mN has a Hertz contact
//! radius of 29 µm, wider than a 51 µm field, and a Hertz centre pressure p₀ of 232 MPa; the mean
//! real pressure N/A rises from ≈ 100 MPa at 4 mN to 250 MPa at 400 mN (Fig. 2), and the contact
//! "evolves from a discrete collection of asperities in contact at 4 mN to an almost Hertzian
//! contact circle at 400 mN". The presets keep the pressures and shrink the sphere: the largest
//! load's Hertz contact has the paper's p₀ = 230 MPa ([`TOP_HERTZ_PRESSURE_PA`]) and a radius of
//! 21 % of the field ([`HERTZ_RADIUS_SHARE`]), so R = 2E*a/(πp₀) and N = 4E*a³/(3R) (Johnson
//! 1985). As p₀ ∝ N^⅓ at a given R, every load of the ramp has the nominal
//! pressures of its counterpart in the paper's 4–400 mN (p₀ = 50 MPa at the smallest).
//!
//! * [`RampSpec::paper`]: 1024² (a 51.2 µm field), R = 110 µm, 0.56–55.7 mN.
//! * [`RampSpec::small`]: 256² (12.8 µm), R = 27.5 µm, 0.035–3.5 mN, 0.4–1 s a ramp, for tests.
//!   The whole contact is a few micrometres wide, so the coarse scale gives one patch.
//! * [`RampSpec::cloud`]: the **stress case outside the paper's regime**, the sub-PSF preset of
//!   before: 1024², R = 290 µm, 0.24–24.3 mN (the largest load's Hertz radius 22 % of the field,
//!   p₀ = 90 MPa), h′_rms = 0.20 ± 30 % ([`CLOUD_RMS_SLOPE`]), λ_s = 0.2 µm, λ_r = 0.8 µm. The
//!   real pressure (200–390 MPa elastic, measured) stays far above the nominal one, so the
//!   contact is a cloud of sub-PSF patches at every load (contact fraction 0.2–0.45 even at the
//!   centre of the largest load, hardening aside): a 300–750 nm PSF images every load of such a
//!   series as a grey disc without the contact's signal, and its area cannot be measured by
//!   fluorescence. It is labelled [`Preset::Cloud`] (scale [`PatchScale::SubPsf`]).
//!
//! The roughness is set by its **rms slope** (central differences,
//! [`crate::surface::generate::RmsTarget::Slope`]), not its rms height: the slope fixes the
//! elastic mean pressure over the real contact (Persson: p̄ ≈ h′_rms E*/κ, κ ≈ 2) and with it
//! the contact fraction p_nominal/p̄, which together with the short-wavelength cutoff λ_s decides
//! how the contact is cut into patches. A narrow band (λ_r = 2 λ_s) keeps the patches from
//! clustering on longer wavelengths. The slopes give the paper's ≈ 100 MPa at the smallest load
//! (measured p̄ ≈ 1600–1900 MPa × h′_rms there for the sub-PSF and PSF-sized scales; the coarse
//! scale's few asperities carry it at less, so it has a steeper slope), and the ±30 % draws stay
//! within ≈ 60–150 MPa; a steeper slope would keep the smallest load's patches apart but leaves
//! the paper's pressures (the cloud).
//!
//! | scale | λ_s | λ_r | h′_rms | patches meant (area-weighted, smallest load) |
//! |---|---|---|---|---|
//! | [`PatchScale::SubPsf`] | 0.15 µm | 0.3 µm | 0.07 | ≈ 0.2–0.6 µm, most of the area in patches below a 300–750 nm PSF |
//! | [`PatchScale::PsfSized`] | 0.5 µm | 1.0 µm | 0.06 | ≈ 0.7–2 µm, the paper's "0.3–1.5 µm" |
//! | [`PatchScale::Coarse`] | 3.2 µm | 6.4 µm | 0.075 (small: 0.0525) | two or three asperities of ≈ 2–3 µm, many PSF widths |
//!
//! ## Measured
//!
//! Per scale and model, at the smallest, the middle (4th of 8) and the largest load: the
//! area-weighted mean equivalent diameter d_A = Σ aᵢ·2√(aᵢ/π) / Σ aᵢ of the 8-connected
//! patches ([`PatchStats`]), the patches, the share of the true area in patches of equivalent
//! diameter below 0.45 µm ([`ContactRamp::area_share_below`]); the contact fraction within half
//! the contact radius of the centre at the largest load ([`ContactRamp::central_fill`]); the mean
//! real pressure p̄ = N/A_true at the smallest and the largest load; the farthest contact pixel
//! from the centre at the largest load (2 r_max / field side); the seconds per ramp
//! (`solve_ramp` only) on the 2-core development machine, shared with another job while measured.
//! Imaging a paper ramp ([`camera::image_ramp`], 8 loads) takes 0.3–0.6 s; its encoded form is
//! 1.05 MB and encodes and decodes in 4 ms.
//!
//! [`RampSpec::paper`], seeds 0–8 (three per model):
//!
//! | scale | model | h′_rms drawn | d_A (µm) | patches | area share < 0.45 µm | central fill | p̄ (MPa) | 2r/L | s |
//! |---|---|---|---|---|---|---|---|---|---|
//! | sub-PSF | elastic | 0.053–0.082 | **0.20–0.47** / 2.0–5.3 / 16–19 | 177–235 / 190–386 / 257–455 | 0.67–1.00 / 0.10–0.38 / 0.01–0.04 | 0.81–0.94 | 102–143 / 190–231 | 0.44 | 17 |
//! | sub-PSF | hardness | 0.050–0.067 | **0.32–0.63** / 4.5–5.6 / 19–20 | 130–190 / 193–239 / 203–295 | 0.44–0.79 / 0.11–0.14 / 0.01–0.02 | 0.99–1.00 | 93–111 / 174–181 | 0.44 | 14–18 |
//! | sub-PSF | hardening | 0.063–0.080 | **5.0–5.1** / 9.7–9.8 / 23 | 43–48 / 38–79 / 41–70 | 0.02–0.04 / 0.00–0.01 / 0.00 | 1.00 | 25–26 / 137 | 0.46 | 9–10 |
//! | PSF-sized | elastic | 0.046–0.071 | **0.66–1.5** / 4.4–6.6 / 18–20 | 20–26 / 19–43 / 20–33 | 0.10–0.30 / 0.02–0.06 / 0.00 | 0.91–0.99 | 77–128 / 170–199 | 0.45 | 12–13 |
//! | PSF-sized | hardness | 0.043–0.058 | **0.81–2.0** / 5.6–6.7 / 20–21 | 17–23 / 20–23 / 15–27 | 0.08–0.18 / 0.02–0.03 / 0.00 | 1.00 | 79–105 / 164–171 | 0.45 | 11–14 |
//! | PSF-sized | hardening | 0.054–0.068 | **4.1–4.8** / 9.2–9.7 / 23 | 9–13 / 8–11 / 5–11 | 0.02–0.03 / 0.00–0.01 / 0.00 | 1.00 | 28–32 / 137–138 | 0.47 | 7–8 |
//! | coarse | elastic | 0.057–0.088 | **2.0–2.2** / 5.5–6.2 / 18–20 | 3 / 2–4 / 1–2 | 0.00–0.01 / 0.00 / 0.00 | 0.87–0.97 | 70–94 / 169–217 | 0.51 | 12–13 |
//! | coarse | hardness | 0.053–0.072 | **1.9–2.6** / 3.6–6.0 / 20–21 | 2–3 / 3–5 / 1–3 | 0.00–0.02 / 0.00 / 0.00 | 0.96–1.00 | 87–140 / 163–175 | 0.54 | 12–15 |
//! | coarse | hardening | 0.067–0.085 | **2.4–3.0** / 4.9–7.8 / 21–22 | 1–2 / 2–4 / 1–2 | 0.00 / 0.00 / 0.00 | 0.93–1.00 | 46–124 / 147–160 | 0.53 | 7–11 |
//!
//! [`RampSpec::small`], seeds 0–29 (ten per model):
//!
//! | scale | model | h′_rms drawn | d_A (µm) | patches | area share < 0.45 µm | central fill | p̄ (MPa) | 2r/L | s |
//! |---|---|---|---|---|---|---|---|---|---|
//! | sub-PSF | elastic | 0.053–0.090 | **0.16–0.42** / 0.44–1.4 / 3.9–4.7 | 14–25 / 20–49 / 23–60 | 0.33–1.00 / 0.12–0.66 / 0.01–0.07 | 0.77–0.94 | 89–144 / 188–240 | 0.47 | 0.6–1.0 |
//! | sub-PSF | hardness | 0.050–0.086 | **0.16–0.32** / 0.67–1.4 / 4.4–5.0 | 13–24 / 17–40 / 18–45 | 0.56–1.00 / 0.11–0.29 / 0.01–0.04 | 0.89–1.00 | 80–139 / 170–207 | 0.47 | 0.7–1.0 |
//! | sub-PSF | hardening | 0.053–0.087 | **1.2–1.6** / 2.8–2.9 / 6.2–6.3 | 3–16 / 4–11 / 2–17 | 0.00–0.13 / 0.00–0.01 / 0.00 | 1.00 | 17–19 / 112–113 | 0.52 | 0.5–0.9 |
//! | PSF-sized | elastic | 0.046–0.077 | **0.30–0.64** / 0.84–1.7 / 4.7–5.1 | 2–7 / 2–9 / 1–8 | 0.02–1.00 / 0.02–0.24 / 0.00–0.02 | 0.88–1.00 | 81–110 / 170–195 | 0.51 | 0.6–0.8 |
//! | PSF-sized | hardness | 0.043–0.074 | **0.34–0.65** / 1.2–1.9 / 4.8–5.3 | 1–6 / 1–5 / 1–7 | 0.00–1.00 / 0.00–0.12 / 0.00–0.01 | 0.95–1.00 | 66–120 / 159–190 | 0.50 | 0.6–0.9 |
//! | PSF-sized | hardening | 0.045–0.075 | **0.91–1.6** / 2.5–2.9 / 6.2–6.3 | 1–5 / 1–4 / 1–4 | 0.00–0.12 / 0.00–0.04 / 0.00–0.01 | 1.00 | 17–32 / 112–116 | 0.56 | 0.4–0.6 |
//! | coarse | elastic | 0.040–0.068 | **0.70–1.2** / 1.4–2.2 / 4.7–5.6 | 1–2 / 1–2 / 1 | 0.00–0.12 / 0.00 / 0.00 | 0.84–1.00 | 29–90 / 142–197 | 0.62 | 0.6–0.8 |
//! | coarse | hardness | 0.037–0.065 | **0.75–1.2** / 1.5–2.2 / 4.9–5.6 | 1 / 1 / 1 | 0.00 / 0.00 / 0.00 | 0.75–1.00 | 32–79 / 143–185 | 0.56 | 0.7–0.8 |
//! | coarse | hardening | 0.040–0.066 | **1.2–1.6** / 2.2–3.2 / 5.5–6.4 | 1 / 1 / 1 | 0.00 / 0.00 / 0.00 | 0.96–1.00 | 18–30 / 109–144 | 0.69 | 0.4–0.6 |
//!
//! [`RampSpec::cloud`], seeds 0–8 (three per model):
//!
//! | scale | model | h′_rms drawn | d_A (µm) | patches | area share < 0.45 µm | central fill | p̄ (MPa) | 2r/L | s |
//! |---|---|---|---|---|---|---|---|---|---|
//! | cloud | elastic | 0.153–0.235 | **0.17–0.18** / 0.20–0.25 / 0.34–0.53 | 53–83 / 269–294 / 1368–1555 | 1.00 / 0.96–1.00 / 0.47–0.79 | 0.19–0.29 | 198–368 / 267–391 | 0.55 | 15–20 |
//! | cloud | hardness | 0.142–0.192 | **0.20–0.24** / 0.31–0.32 / 1.1–3.1 | 72–92 / 282–301 / 958–1110 | 1.00 / 0.82–0.86 / 0.20–0.22 | 0.42–0.45 | 155–162 / 172–187 | 0.55 | 13–15 |
//! | cloud | hardening | 0.179–0.228 | **0.40** / 1.4–2.6 / 18–20 | 129–140 / 239–272 / 307–412 | 0.56–0.64 / 0.16–0.22 / 0.02–0.04 | 0.83–0.91 | 31–36 / 69–76 | 0.58 | 7–16 |
//!
//! What the numbers say:
//!
//! * **Pressures.** The elastic seeds carry the smallest load at 70–143 MPa and the largest at
//!   169–231 MPa (the paper: ≈ 100 and 250 MPa); the hardness seeds at 79–140 and 163–181 MPa
//!   (capped by p_Y = 200–280 MPa only on the highest asperities).
//! * **Almost Hertzian at the largest load.** Within half the contact radius of the centre the
//!   contact covers 0.81–0.99 of the map for the elastic seeds (the steepest draws, h′_rms ≈ 0.08,
//!   leave ≈ 20 % open: at p₀ = 230 MPa that is what the paper's pressures give) and 0.93–1.00
//!   for the plastic ones. The widest contact spans at most 54 % of the field (no contact on the
//!   border: [`solve_ramp`] refuses one).
//! * **The scale holds at the smallest loads only.** At p₀ = 50 MPa against p̄ ≈ 100 MPa the
//!   centre of the smallest load is already 25–50 % in contact (within half its contact radius,
//!   elastic and hardness), near where 8-connected patches join: from the second or third load
//!   the patches merge into a network of micrometre clusters for every scale (d_A 2–7 µm at the
//!   middle load, 9–10 µm for hardening) and into one disc at the largest (d_A 16–23 µm). At the smallest load the sub-PSF seeds keep 0.44–1.00 of their area in
//!   patches below 0.45 µm (1.00 for the steeper draws; the shallowest, ×0.7–0.8, merge at the
//!   centre already), the PSF-sized ones have d_A 0.7–2 µm, the coarse ones two or three
//!   asperities of 2–3 µm.
//! * **Linear hardening** (k = 4 MPa/nm, p_Y0 = 0) flattens the fine roughness: the rms height of
//!   the sub-PSF and PSF-sized bands is only 3–11 nm, so k·h_rms ≈ 10–45 MPa, and those seeds
//!   carry the smallest load at 17–32 MPa in micrometre patches (d_A 4–5 µm on the paper map):
//!   below the paper's pressures and one or two scales coarser than the label. Only the coarse
//!   band (h_rms 50–85 nm) gives hardening the paper's pressures. A wider band would give the
//!   height but clusters the other models' patches (λ_r = 4.8 µm instead of 0.3 µm on the
//!   sub-PSF scale raised hardening's smallest-load pressure only from 26 to 49 MPa, and the
//!   elastic seed's d_A there from 0.20 to 0.78 µm).
//!   Group by the measured scale ([`SolvedLoad::measured_scale`]) or leave out `seed % 3 == 2`
//!   where a pure scale is wanted.
//! * **The small map** keeps the pressures and the compact largest load (central fill ≥ 0.75),
//!   but its contact is only a few micrometres wide: the coarse scale is one or two patches at
//!   every load and carries the smallest load on one asperity, at 29–90 MPa (elastic). Its slope
//!   is lower than the paper map's ([`PatchScale::small_rms_slope`]): at 0.075 a roughness valley
//!   at the centre left the largest load open in a sixth of the seeds (central fill down to
//!   0.52).

pub mod camera;
pub mod codec;
mod mask;
mod spec;

pub use camera::{image_ramp, Camera, ImagedLoad};
pub use mask::{BitMask, PatchStats};
pub use spec::*;

use crate::error::{Error, Result};
use crate::measure::patches::patch_sizes;
use crate::solver::cg::SolverOptions;
use crate::solver::halfspace::Boundary;
use crate::solver::simulate::{sweep_each, LoadStep, Model, Setup};
use crate::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use crate::surface::Topography;

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

    /// The share of load `i`'s true area in patches (8-connected) whose equivalent diameter
    /// 2√(a/π) is below `diameter_m`; 0 without contact. Panics if `i` is not a load.
    pub fn area_share_below(&self, i: usize, diameter_m: f64) -> f64 {
        let sizes = patch_sizes(&self.loads[i].mask.to_bytes(), self.width);
        let pixel_area = self.sim_pixel_m * self.sim_pixel_m;
        let total: u64 = sizes.iter().sum();
        let below: u64 = sizes
            .iter()
            .filter(|&&px| {
                2.0 * (px as f64 * pixel_area / std::f64::consts::PI).sqrt() < diameter_m
            })
            .sum();
        if total == 0 {
            0.0
        } else {
            below as f64 / total as f64
        }
    }

    /// The contact fraction of load `i` within `radius_m` of the map centre (the sphere's apex):
    /// contact pixels over the pixels whose centres lie within it; NaN if none do. Panics if `i`
    /// is not a load.
    pub fn fill_within(&self, i: usize, radius_m: f64) -> f64 {
        let mask = &self.loads[i].mask;
        let r = radius_m / self.sim_pixel_m;
        let (cx, cy) = (
            (self.width as f64 - 1.0) / 2.0,
            (self.height as f64 - 1.0) / 2.0,
        );
        let span = |c: f64, n: usize| {
            let lo = (c - r).ceil().max(0.0) as usize;
            let hi = ((c + r).floor().min(n as f64 - 1.0)).max(-1.0);
            (lo, hi as isize)
        };
        let ((x0, x1), (y0, y1)) = (span(cx, self.width), span(cy, self.height));
        let (mut inside, mut contact) = (0u64, 0u64);
        for y in y0..(y1 + 1).max(0) as usize {
            for x in x0..(x1 + 1).max(0) as usize {
                if (x as f64 - cx).hypot(y as f64 - cy) <= r {
                    inside += 1;
                    contact += u64::from(mask.get(x, y));
                }
            }
        }
        contact as f64 / inside as f64
    }

    /// How compact load `i` is at its centre: [`ContactRamp::fill_within`] half its contact
    /// radius ([`SolvedLoad::contact_radius_m`], the farthest contact pixel). Near 1 for an
    /// almost Hertzian disc, the contact fraction of the cloud for scattered patches. Panics if
    /// `i` is not a load.
    pub fn central_fill(&self, i: usize) -> f64 {
        self.fill_within(i, self.loads[i].contact_radius_m / 2.0)
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
