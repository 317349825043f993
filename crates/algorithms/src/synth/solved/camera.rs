//! The imaging stage: a solved ramp as a confocal microscope with a 12-bit detector records it
//! (Weber et al. 2018, Methods: "Confocal microscopy"; Supplementary Fig. 1).
//!
//! Per load, on the simulation grid of the ramp:
//!
//! 1. the binary contact mask φ is blurred by a Gaussian PSF of σ = FWHM/2.354820 **on the
//!    simulation grid**, then integrated exactly over camera pixels by area fraction
//!    ([`crate::optics::blur::microscope_image`]; both steps conserve the contact area,
//!    docs/validation.md B24);
//! 2. the camera grid sits at a seeded sub-pixel placement: the map is padded by
//!    `0..ratio` simulation pixels on the left and top (ratio = camera / simulation pixel, 2 at
//!    100 nm and 4 at 200 nm on 50 nm), one draw per ramp and camera seed, and the image is
//!    ⌈field / pixel⌉ camera pixels square, so it covers the whole field;
//! 3. expected photons per camera pixel
//!    `λ = I(x, y) · (b + S₀ · (1 + γ · log₁₀(N / N₀)) · φ̄(x, y))`, with b
//!    [`Camera::background_photons`], S₀ [`Camera::photons_at_contact`] (a fully covered contact
//!    pixel at the first load N₀), γ [`Camera::signal_gain_per_decade`] (the rigidochromic signal
//!    rises with load, Supplementary Fig. 1c) and φ̄ the blurred, integrated coverage;
//!    the illumination `I = (1 + G · t) · (1 − V · ρ²)` is a linear gradient of relative amplitude
//!    G along a seeded direction (t ∈ [−1, 1] across the field) times a radial vignetting that
//!    dims the field's corners (ρ = 1) by V;
//! 4. counts = Poisson(λ) · gain + N(0, read noise²) + dark offset, rounded and clipped to
//!    0..=4095. Without an explicit gain, the gain puts the brightest expected level of the ramp
//!    (background plus full contact at the largest load, at the brightest illumination) at
//!    [`TARGET_BRIGHTEST_COUNTS`], as a lab sets its photomultiplier: most of the 12 bits used,
//!    nothing saturated on average (with a few tens of photons per contact pixel, a pixel's
//!    Poisson tail can still reach 4095 and is clipped, as on a real detector).
//!
//! Every random draw comes from ChaCha8 seeded by the camera's and the ramp's seeds, one stream
//! per image: the codes do not depend on the number of threads.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Poisson, StandardNormal};
use rayon::prelude::*;

use super::ContactRamp;
use crate::error::{Error, Result};
use crate::optics::blur::{microscope_image, Grid};

/// Where an automatic gain puts the ramp's brightest expected level, counts.
pub const TARGET_BRIGHTEST_COUNTS: f64 = 3000.0;
/// Largest 12-bit code.
pub const MAX_CODE: f64 = 4095.0;

/// The microscope and its detector.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Camera pixel, m (square); at least the simulation pixel.
    pub pixel_m: f64,
    /// PSF full width at half maximum, m.
    pub psf_fwhm_m: f64,
    /// Mean detected photons of a fully covered contact pixel at the first load.
    pub photons_at_contact: f64,
    /// Mean detected photons of a background pixel (default 15 % of the contact's).
    pub background_photons: f64,
    /// Counts per photon; `None` (default): chosen per ramp so that the brightest expected level
    /// is [`TARGET_BRIGHTEST_COUNTS`].
    pub gain_counts_per_photon: Option<f64>,
    /// Gaussian read noise, counts rms (default 3).
    pub read_noise_counts: f64,
    /// Dark offset, counts (default 100).
    pub dark_offset_counts: f64,
    /// Relative amplitude G of the linear illumination gradient: the illumination runs from
    /// 1 − G to 1 + G across the field (default 0.05).
    pub illumination_gradient: f64,
    /// Relative dimming V of the field's corners by radial vignetting (default 0.03).
    pub vignetting: f64,
    /// Relative rise γ of the contact signal per decade of load (default 0.15; 0: constant).
    pub signal_gain_per_decade: f64,
    /// Seed of the placement, the gradient's direction and the noise.
    pub seed: u64,
}

impl Camera {
    /// A camera with the documented defaults for everything but the pixel, the PSF, the photon
    /// count of a contact pixel and the seed.
    pub fn new(pixel_m: f64, psf_fwhm_m: f64, photons_at_contact: f64, seed: u64) -> Self {
        Camera {
            pixel_m,
            psf_fwhm_m,
            photons_at_contact,
            background_photons: 0.15 * photons_at_contact,
            gain_counts_per_photon: None,
            read_noise_counts: 3.0,
            dark_offset_counts: 100.0,
            illumination_gradient: 0.05,
            vignetting: 0.03,
            signal_gain_per_decade: 0.15,
            seed,
        }
    }

    /// A camera without noise sources beyond the photons and without illumination structure:
    /// no read noise, no gradient, no vignetting (for checks of the forward model).
    pub fn flat(self) -> Self {
        Camera {
            read_noise_counts: 0.0,
            illumination_gradient: 0.0,
            vignetting: 0.0,
            ..self
        }
    }

    fn validate(&self, sim_pixel_m: f64, field_m: f64) -> Result<()> {
        let checks: [(&'static str, f64, &'static str, bool, &'static str); 9] = [
            (
                "camera pixel",
                self.pixel_m,
                "m",
                self.pixel_m >= sim_pixel_m * (1.0 - 1e-9) && self.pixel_m <= field_m,
                "must lie between the simulation pixel and the field",
            ),
            (
                "PSF FWHM",
                self.psf_fwhm_m,
                "m",
                self.psf_fwhm_m >= 0.0,
                "must be a non-negative length",
            ),
            (
                "photons at contact",
                self.photons_at_contact,
                "",
                self.photons_at_contact > 0.0,
                "must be positive",
            ),
            (
                "background photons",
                self.background_photons,
                "",
                self.background_photons >= 0.0,
                "must not be negative",
            ),
            (
                "gain",
                self.gain_counts_per_photon.unwrap_or(1.0),
                "counts/photon",
                self.gain_counts_per_photon.unwrap_or(1.0) > 0.0,
                "must be positive",
            ),
            (
                "read noise",
                self.read_noise_counts,
                "counts",
                self.read_noise_counts >= 0.0,
                "must not be negative",
            ),
            (
                "dark offset",
                self.dark_offset_counts,
                "counts",
                (0.0..TARGET_BRIGHTEST_COUNTS).contains(&self.dark_offset_counts),
                "must lie in [0, 3000)",
            ),
            (
                "illumination gradient",
                self.illumination_gradient,
                "",
                (0.0..1.0).contains(&self.illumination_gradient),
                "must lie in [0, 1)",
            ),
            (
                "vignetting",
                self.vignetting,
                "",
                (0.0..1.0).contains(&self.vignetting),
                "must lie in [0, 1)",
            ),
        ];
        for (what, value, unit, ok, requirement) in checks {
            if !(value.is_finite() && ok) {
                return Err(Error::Value {
                    what,
                    value,
                    unit,
                    requirement,
                });
            }
        }
        if !self.signal_gain_per_decade.is_finite() {
            return Err(Error::Value {
                what: "signal gain per decade",
                value: self.signal_gain_per_decade,
                unit: "",
                requirement: "must be finite",
            });
        }
        Ok(())
    }
}

/// The nominal levels of one image (illumination 1), counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Levels {
    /// Counts per photon used.
    pub gain_counts_per_photon: f64,
    /// Dark offset.
    pub dark_counts: f64,
    /// Expected level of a background pixel: dark + gain · b.
    pub background_counts: f64,
    /// Expected increment of a fully covered contact pixel at this load: gain · S(N).
    pub contact_counts: f64,
}

/// One load as the camera recorded it.
#[derive(Debug, Clone, PartialEq)]
pub struct ImagedLoad {
    /// Normal force, N.
    pub force_n: f64,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Camera pixel, m.
    pub pixel_m: f64,
    /// 12-bit codes (0..=4095), row-major.
    pub codes: Vec<u16>,
    /// Expected counts before photon, read and rounding noise, row-major.
    pub expected_counts: Vec<f64>,
    /// True contact area, m².
    pub true_area_m2: f64,
    /// True contact area in camera pixels (area / pixel²).
    pub true_area_px: f64,
    /// The nominal levels.
    pub levels: Levels,
    /// Simulation pixels (x, y) the map was padded by on the left and top (the placement).
    pub placement_sim_px: (usize, usize),
}

/// A 64-bit mix of two seeds (SplitMix64's finaliser on their combination).
fn mix(a: u64, b: u64) -> u64 {
    let mut z = a ^ b.rotate_left(32) ^ 0x9e37_79b9_7f4a_7c15;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The contact signal of a load relative to the first, 1 + γ·log₁₀(N/N₀).
fn signal_factor(camera: &Camera, force_n: f64, first_n: f64) -> f64 {
    1.0 + camera.signal_gain_per_decade * (force_n / first_n).log10()
}

/// Image every load of `ramp` with `camera` (module docs). Deterministic for given seeds.
pub fn image_ramp(ramp: &ContactRamp, camera: &Camera) -> Result<Vec<ImagedLoad>> {
    let n = ramp.width;
    let dx = ramp.sim_pixel_m;
    let field = n as f64 * dx;
    camera.validate(dx, field)?;
    let first = ramp.loads.first().map_or(1.0, |l| l.force_n);
    let factors: Vec<f64> = ramp
        .loads
        .iter()
        .map(|l| signal_factor(camera, l.force_n, first))
        .collect();
    if let Some(&bad) = factors.iter().find(|f| f.is_nan() || **f <= 0.0) {
        return Err(Error::Value {
            what: "contact signal relative to the first load (signal gain per decade)",
            value: bad,
            unit: "",
            requirement: "must stay positive at every load",
        });
    }
    let ratio = ((camera.pixel_m / dx) * (1.0 + 1e-9)).floor().max(1.0) as usize;
    let side = ((field / camera.pixel_m) * (1.0 - 1e-12)).ceil() as usize;
    let mut rng = ChaCha8Rng::seed_from_u64(mix(camera.seed, ramp.spec.seed));
    let placement = (rng.random_range(0..ratio), rng.random_range(0..ratio));
    let angle = rng.random_range(0.0..std::f64::consts::TAU);
    let illumination = illumination(camera, side, placement, dx, field, angle);
    let brightest_illumination = illumination.iter().copied().fold(0.0, f64::max);
    let top = factors.iter().copied().fold(0.0, f64::max);
    let gain = camera.gain_counts_per_photon.unwrap_or(
        (TARGET_BRIGHTEST_COUNTS - camera.dark_offset_counts)
            / (brightest_illumination
                * (camera.background_photons + camera.photons_at_contact * top)),
    );
    ramp.loads
        .par_iter()
        .zip(&factors)
        .enumerate()
        .map(|(i, (load, &factor))| {
            // Contact in the strip the placement pushes past the image would be lost.
            let (ox, oy) = placement;
            let lost = (0..n).any(|k| {
                (n - ox..n).any(|x| load.mask.get(x, k)) || (n - oy..n).any(|y| load.mask.get(k, y))
            });
            if lost {
                return Err(Error::InvalidArgument(format!(
                    "camera: the contact at {:.4e} N reaches the last {} simulation pixels of the \
                     field, which the camera's placement leaves out",
                    load.force_n,
                    ox.max(oy)
                )));
            }
            let mut padded = vec![0.0; (n + ox) * (n + oy)];
            for y in 0..n {
                for x in 0..n {
                    if load.mask.get(x, y) {
                        padded[(y + oy) * (n + ox) + x + ox] = 1.0;
                    }
                }
            }
            let map = Grid::new(padded, n + ox, n + oy, dx, dx)?;
            let image =
                microscope_image(&map, camera.psf_fwhm_m, (camera.pixel_m, camera.pixel_m))?;
            let signal = camera.photons_at_contact * factor;
            let expected_photons: Vec<f64> = (0..side * side)
                .map(|j| {
                    let (x, y) = (j % side, j / side);
                    let phi = image.values[y * image.width + x].max(0.0);
                    illumination[j] * (camera.background_photons + signal * phi)
                })
                .collect();
            let levels = Levels {
                gain_counts_per_photon: gain,
                dark_counts: camera.dark_offset_counts,
                background_counts: camera.dark_offset_counts + gain * camera.background_photons,
                contact_counts: gain * signal,
            };
            let mut rng = ChaCha8Rng::seed_from_u64(mix(camera.seed, ramp.spec.seed));
            rng.set_stream(1 + i as u64);
            let codes = detect(&expected_photons, camera, gain, &mut rng)?;
            Ok(ImagedLoad {
                force_n: load.force_n,
                width: side,
                height: side,
                pixel_m: camera.pixel_m,
                codes,
                expected_counts: expected_photons
                    .iter()
                    .map(|p| camera.dark_offset_counts + gain * p)
                    .collect(),
                true_area_m2: load.area_m2,
                true_area_px: load.area_m2 / (camera.pixel_m * camera.pixel_m),
                levels,
                placement_sim_px: placement,
            })
        })
        .collect()
}

/// The illumination I(x, y) of every camera pixel (module docs).
fn illumination(
    camera: &Camera,
    side: usize,
    (ox, oy): (usize, usize),
    dx: f64,
    field: f64,
    angle: f64,
) -> Vec<f64> {
    let (c, s) = (angle.cos(), angle.sin());
    let half = field / 2.0;
    let reach = half * (c.abs() + s.abs());
    (0..side * side)
        .map(|j| {
            // Camera pixel centre in field coordinates, relative to the field's centre.
            let x = ((j % side) as f64 + 0.5) * camera.pixel_m - ox as f64 * dx - half;
            let y = ((j / side) as f64 + 0.5) * camera.pixel_m - oy as f64 * dx - half;
            let t = ((x * c + y * s) / reach).clamp(-1.0, 1.0);
            let rho2 = ((x * x + y * y) / (2.0 * half * half)).min(1.0);
            (1.0 + camera.illumination_gradient * t) * (1.0 - camera.vignetting * rho2)
        })
        .collect()
}

/// Poisson photons × gain + read noise + dark offset, rounded, clipped to 12 bits.
fn detect(expected: &[f64], camera: &Camera, gain: f64, rng: &mut ChaCha8Rng) -> Result<Vec<u16>> {
    expected
        .iter()
        .map(|&lambda| {
            let photons = if lambda > 0.0 {
                Poisson::new(lambda)
                    .map_err(|e| Error::InvalidArgument(format!("camera: photons: {e}")))?
                    .sample(rng)
            } else {
                0.0
            };
            let read: f64 = rng.sample(StandardNormal);
            let counts =
                photons * gain + camera.read_noise_counts * read + camera.dark_offset_counts;
            Ok(counts.round().clamp(0.0, MAX_CODE) as u16)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::{solve_ramp, PatchScale, RampSpec};
    use super::*;

    fn ramp() -> ContactRamp {
        solve_ramp(&RampSpec::small(PatchScale::PsfSized, 4)).unwrap()
    }

    /// docs/validation.md B24 through the camera: the blur and the area integration conserve
    /// the contact's mass, so Σ(level − background)/contact level is the true area in camera
    /// pixels.
    #[test]
    fn imaging_conserves_the_contact_area() {
        let ramp = ramp();
        for pixel in [100e-9, 200e-9] {
            // Noiseless: the expected counts, to round-off.
            let camera = Camera::new(pixel, 500e-9, 1e6, 9).flat();
            let images = image_ramp(&ramp, &camera).unwrap();
            for im in &images {
                let sum: f64 = im
                    .expected_counts
                    .iter()
                    .map(|c| (c - im.levels.background_counts) / im.levels.contact_counts)
                    .sum();
                assert!(
                    (sum / im.true_area_px - 1.0).abs() < 1e-9,
                    "{pixel:e} m, {} N: {sum} vs {} px",
                    im.force_n,
                    im.true_area_px
                );
                // Through the photons and 12 bits: 1e6 photons per contact pixel.
                let counted: f64 = im
                    .codes
                    .iter()
                    .map(|&c| {
                        (f64::from(c) - im.levels.background_counts) / im.levels.contact_counts
                    })
                    .sum();
                assert!(
                    (counted / im.true_area_px - 1.0).abs() < 0.01,
                    "{pixel:e} m, {} N: {counted} vs {} px",
                    im.force_n,
                    im.true_area_px
                );
            }
        }
    }

    #[test]
    fn the_camera_covers_the_field_and_uses_most_of_12_bits() {
        let ramp = ramp();
        let camera = Camera::new(200e-9, 400e-9, 40.0, 1);
        let images = image_ramp(&ramp, &camera).unwrap();
        assert_eq!(images.len(), ramp.loads.len());
        let last = images.last().unwrap();
        assert_eq!((last.width, last.height), (64, 64));
        let brightest = last.expected_counts.iter().copied().fold(0.0, f64::max);
        assert!((2000.0..3000.0 + 1e-9).contains(&brightest), "{brightest}");
        assert!(last.codes.iter().all(|&c| c <= 4095));
        let dark = images[0].codes.iter().copied().min().unwrap();
        assert!(dark > 50, "{dark}");
        assert!(
            last.levels.contact_counts > images[0].levels.contact_counts,
            "the signal rises with load"
        );
    }

    #[test]
    fn same_seed_same_codes_other_seed_other_codes() {
        let ramp = ramp();
        let a = image_ramp(&ramp, &Camera::new(100e-9, 600e-9, 30.0, 5)).unwrap();
        let b = image_ramp(&ramp, &Camera::new(100e-9, 600e-9, 30.0, 5)).unwrap();
        let c = image_ramp(&ramp, &Camera::new(100e-9, 600e-9, 30.0, 6)).unwrap();
        assert_eq!(a, b);
        assert_ne!(a[3].codes, c[3].codes);
        assert_ne!(a[0].codes, a[1].codes, "each image has its own noise");
    }

    #[test]
    fn bad_cameras_are_refused() {
        let ramp = ramp();
        let good = Camera::new(100e-9, 600e-9, 30.0, 5);
        for bad in [
            Camera {
                pixel_m: 20e-9,
                ..good.clone()
            },
            Camera {
                psf_fwhm_m: f64::NAN,
                ..good.clone()
            },
            Camera {
                photons_at_contact: 0.0,
                ..good.clone()
            },
            Camera {
                illumination_gradient: 1.5,
                ..good.clone()
            },
            Camera {
                signal_gain_per_decade: -1.0,
                ..good.clone()
            },
        ] {
            assert!(image_ramp(&ramp, &bad).is_err(), "{bad:?}");
        }
    }
}
