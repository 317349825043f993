//! Seeded synthetic Newton-ring data with known truth: a smooth sphere of radius R in a Hertz
//! contact of radius a, seen in reflection (Newton rings) and in rigidochromic fluorescence
//! (bright where the gap is below a known detection gap), as in Weber et al. 2018, Methods and
//! Supplementary Figs. 6–7.
//!
//! Model, per pixel centre (pixel (i, j) at x = i, y = j pixels):
//! * gap g(r) = Hertz exterior gap (Johnson 1985, §4.2), 0 inside r ≤ a;
//! * reflection I = I_bg + B(r)·(1 − cos(4πn·g/λ)) for [`Phase::Half`] (dark contact, maxima at
//!   Eq. 1's d_m), 1 + cos for [`Phase::Zero`]; B(r) = B·exp(−r/L) lets the fringe contrast fade
//!   outward as a finite coherence length and the illumination cone make it do;
//! * fluorescence F = F_bg + S·(area fraction of the pixel with g < d_det), the fraction from
//!   4×4 sub-samples so that the edge is not snapped to the pixel grid;
//! * both blurred by a Gaussian PSF, then optional photon shot noise, rounded to 12 bits.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Poisson};
use serde::Serialize;

use crate::error::{Error, Result};
use crate::optics::blur::isotropic_blur;
use crate::optics::newton::gap::{hertz_gap, Phase};

/// Parameters of [`synth_newton`]. SI units.
#[derive(Debug, Clone, Serialize)]
pub struct NewtonSynthParams {
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Pixel size, m (square pixels).
    pub pixel_size_m: f64,
    /// Contact centre, pixels (off the grid on purpose).
    pub centre_px: (f64, f64),
    /// Hertz contact radius a, m.
    pub contact_radius_m: f64,
    /// Sphere radius R, m.
    pub sphere_radius_m: f64,
    /// Gap below which the rigidochromic layer lights up, m (the paper: 9 nm).
    pub detection_gap_m: f64,
    /// Wavelength, m.
    pub wavelength_m: f64,
    /// Refractive index of the medium in the gap.
    pub medium_index: f64,
    /// Phase convention of the reflection.
    pub phase: Phase,
    /// Reflection background I_bg, counts.
    pub reflection_background: f64,
    /// Fringe amplitude B at the centre, counts (maxima reach I_bg + 2B).
    pub ring_amplitude: f64,
    /// Length L over which the fringe amplitude falls by 1/e, m; `f64::INFINITY` for none.
    pub ring_fade_m: f64,
    /// Fluorescence background, counts.
    pub fluorescence_background: f64,
    /// Fluorescence signal of a fully fluorescent pixel above background, counts.
    pub fluorescence_signal: f64,
    /// PSF full width at half maximum, m (both images).
    pub psf_fwhm_m: f64,
    /// Detector counts per photon for shot noise; `None` for noise-free images.
    pub counts_per_photon: Option<f64>,
    /// Seed of the noise.
    pub seed: u64,
}

impl Default for NewtonSynthParams {
    /// 256² px of 200 nm; R = 290 µm (the paper's spheres), a = 12 µm, d_det = 9 nm, 488 nm in
    /// formamide: four to five rings fit in the field.
    fn default() -> Self {
        NewtonSynthParams {
            width: 256,
            height: 256,
            pixel_size_m: 200e-9,
            centre_px: (127.37, 129.62),
            contact_radius_m: 12e-6,
            sphere_radius_m: 290e-6,
            detection_gap_m: 9e-9,
            wavelength_m: 488e-9,
            medium_index: 1.447,
            phase: Phase::Half,
            reflection_background: 200.0,
            ring_amplitude: 700.0,
            ring_fade_m: 60e-6,
            fluorescence_background: 150.0,
            fluorescence_signal: 1500.0,
            psf_fwhm_m: 450e-9,
            counts_per_photon: None,
            seed: 7,
        }
    }
}

/// Ground truth of a synthetic pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NewtonTruth {
    /// Contact centre, pixels.
    pub centre_px: (f64, f64),
    /// Hertz contact radius a, m.
    pub contact_radius_m: f64,
    /// Sphere radius R, m.
    pub sphere_radius_m: f64,
    /// Detection gap d_det, m.
    pub detection_gap_m: f64,
    /// Radius of the fluorescent disc, where g = d_det, m.
    pub fluorescent_radius_m: f64,
}

/// A synthetic reflection and fluorescence image pair (12-bit in u16, row-major) and its truth.
#[derive(Debug, Clone)]
pub struct NewtonSynth {
    /// Reflection image with Newton rings.
    pub reflection: Vec<u16>,
    /// Fluorescence image of the contact.
    pub fluorescence: Vec<u16>,
    /// What generated them.
    pub truth: NewtonTruth,
}

/// Render a synthetic pair; see the module documentation for the model.
pub fn synth_newton(p: &NewtonSynthParams) -> Result<NewtonSynth> {
    check(p)?;
    let (a, big_r) = (p.contact_radius_m, p.sphere_radius_m);
    let radius_px = |x: f64, y: f64| (x - p.centre_px.0).hypot(y - p.centre_px.1);
    let k = 4.0 * std::f64::consts::PI * p.medium_index / p.wavelength_m;
    let sign = match p.phase {
        Phase::Half => -1.0,
        Phase::Zero => 1.0,
    };
    let reflection: Vec<f64> = pixels(p)
        .map(|(x, y)| {
            let r = radius_px(x, y) * p.pixel_size_m;
            let amplitude = p.ring_amplitude * (-r / p.ring_fade_m).exp();
            p.reflection_background + amplitude * (1.0 + sign * (k * hertz_gap(r, a, big_r)).cos())
        })
        .collect();
    let r_det = fluorescent_radius(p);
    let fluorescence: Vec<f64> = pixels(p)
        .map(|(x, y)| {
            let inside = sub_samples()
                .filter(|(dx, dy)| radius_px(x + dx, y + dy) * p.pixel_size_m < r_det)
                .count();
            p.fluorescence_signal * inside as f64 / 16.0
        })
        .collect();
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let sigma_px = p.psf_fwhm_m / (8.0 * 2f64.ln()).sqrt() / p.pixel_size_m;
    let blur = |v: &[f64]| isotropic_blur(v, p.width, p.height, sigma_px);
    let fluorescence: Vec<f64> = blur(&fluorescence)
        .iter()
        .map(|v| v + p.fluorescence_background)
        .collect();
    Ok(NewtonSynth {
        reflection: quantise(&blur(&reflection), p.counts_per_photon, &mut rng)?,
        fluorescence: quantise(&fluorescence, p.counts_per_photon, &mut rng)?,
        truth: NewtonTruth {
            centre_px: p.centre_px,
            contact_radius_m: a,
            sphere_radius_m: big_r,
            detection_gap_m: p.detection_gap_m,
            fluorescent_radius_m: r_det,
        },
    })
}

fn check(p: &NewtonSynthParams) -> Result<()> {
    let positive = [
        p.pixel_size_m,
        p.contact_radius_m,
        p.sphere_radius_m,
        p.detection_gap_m,
        p.wavelength_m,
        p.medium_index,
        p.ring_fade_m,
    ];
    if p.width < 8 || p.height < 8 || positive.iter().any(|v| v.is_nan() || *v <= 0.0) {
        return Err(Error::InvalidArgument(
            "synthetic Newton rings need at least 8×8 pixels and positive lengths and index".into(),
        ));
    }
    let limits = crate::limits::Limits::DEFAULT;
    let limit = |source| Error::Limit {
        what: "synthetic Newton rings".into(),
        source,
    };
    limits.plane_bytes(p.width, p.height, 8).map_err(limit)?;
    let sigma_px = p.psf_fwhm_m / (8.0 * 2f64.ln()).sqrt() / p.pixel_size_m;
    limits.kernel_radius(sigma_px).map_err(limit)?;
    Ok(())
}

/// Pixel centres (x, y) in row-major order.
fn pixels(p: &NewtonSynthParams) -> impl Iterator<Item = (f64, f64)> + '_ {
    (0..p.width * p.height).map(move |i| ((i % p.width) as f64, (i / p.width) as f64))
}

/// Offsets of a 4×4 grid of sub-samples within a pixel, pixels.
fn sub_samples() -> impl Iterator<Item = (f64, f64)> {
    (0..16).map(|k| {
        let at = |i: usize| (i as f64 + 0.5) / 4.0 - 0.5;
        (at(k % 4), at(k / 4))
    })
}

/// Radius where the Hertz gap equals the detection gap (bisection; g rises monotonically
/// outside a).
pub fn fluorescent_radius(p: &NewtonSynthParams) -> f64 {
    let (a, big_r) = (p.contact_radius_m, p.sphere_radius_m);
    let (mut lo, mut hi) = (a, a + (2.0 * big_r * p.detection_gap_m).sqrt() + a);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if hertz_gap(mid, a, big_r) < p.detection_gap_m {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Shot noise (if asked), rounding and clipping to 12 bits.
fn quantise(
    values: &[f64],
    counts_per_photon: Option<f64>,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<u16>> {
    values
        .iter()
        .map(|&v| {
            let v = match counts_per_photon {
                Some(c) if v > 0.0 => {
                    let poisson = Poisson::new(v / c)
                        .map_err(|e| Error::InvalidArgument(format!("shot noise: {e}")))?;
                    poisson.sample(rng) * c
                }
                _ => v,
            };
            Ok(v.round().clamp(0.0, 4095.0) as u16)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthetic_pair_has_dark_contact_bright_rings_and_a_fluorescent_disc() {
        let p = NewtonSynthParams::default();
        let s = synth_newton(&p).unwrap();
        let at = |v: &[u16], x: usize, y: usize| v[y * p.width + x];
        let (cx, cy) = (127, 130);
        assert!(at(&s.reflection, cx, cy) < 260, "dark contact");
        assert!(at(&s.fluorescence, cx, cy) > 1500, "fluorescent contact");
        assert!(at(&s.fluorescence, 5, 5) < 160);
        let r_det = s.truth.fluorescent_radius_m;
        let g = hertz_gap(r_det, p.contact_radius_m, p.sphere_radius_m);
        assert!((g - 9e-9).abs() < 1e-15);
        assert!(r_det > p.contact_radius_m && r_det < p.contact_radius_m + 1.5e-6);
        let again = synth_newton(&p).unwrap();
        assert_eq!(again.reflection, s.reflection);
    }
}
