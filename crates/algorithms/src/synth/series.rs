//! Seeded generator of realistic confocal load series with known ground truth.
//!
//! Model (after Weber et al. 2018, Fig. 2 and Methods): a rough sphere of radius R touches a
//! flat. The undeformed separation is s(x) = r²/2R − z(x), with z a Gaussian random roughness
//! built from white noise filtered at two lateral scales (patch sizes of a few µm, as the
//! paper's autocorrelation shows). At load N the true contact is the set of the A(N)/ΔA pixels
//! of smallest s, with A(N) = A₀·(N/N₀)^β, a bearing-area model whose patches grow and merge
//! with load. The micrograph is background fluorescence (with a weak gradient) plus a contact
//! signal that rises modestly with load (Supplementary Fig. 1c), blurred by a Gaussian PSF
//! (FWHM 450 nm), with photon shot noise, rounded and clipped to 12 bits (0..4095).
//!
//! The ground truth per image is the number of true contact pixels and its area.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

use super::micrograph::shot_noise_12bit;
use crate::error::{Error, Result};
use crate::optics::blur::isotropic_blur;

/// Parameters of a synthetic series. SI units.
#[derive(Debug, Clone, Serialize)]
pub struct SynthParams {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// Pixel size, m.
    pub pixel_size_m: f64,
    /// Normal forces, N, one image each.
    pub forces_n: Vec<f64>,
    /// Random seed.
    pub seed: u64,
    /// FWHM of the Gaussian PSF, m.
    pub psf_fwhm_m: f64,
    /// Mean background level, counts.
    pub background: f64,
    /// Contact signal above background at the first load, counts.
    pub signal: f64,
    /// Relative signal increase per decade of load.
    pub signal_gain_per_decade: f64,
    /// Detector counts per photon (sets the shot noise).
    pub counts_per_photon: f64,
    /// True contact area at the first load, m².
    pub first_area_m2: f64,
    /// Exponent β of A ∝ N^β.
    pub area_exponent: f64,
    /// Sphere radius, m.
    pub sphere_radius_m: f64,
    /// RMS roughness height, m.
    pub roughness_rms_m: f64,
    /// Scale of the roughness' two correlation lengths (1.5 µm and 0.4 µm at 1): below 1 the
    /// contact patches are smaller, above 1 coarser (the coverage benchmark's patch scales).
    pub patch_scale: f64,
    /// Gaussian read noise of the detector, grey levels (standard deviation), added to the
    /// shot noise; 0 for none.
    pub read_noise_counts: f64,
}

impl Default for SynthParams {
    /// The bundled fixture: 256×256 px of 200 nm, eight loads 4…100 mN.
    fn default() -> Self {
        SynthParams {
            width: 256,
            height: 256,
            pixel_size_m: 200e-9,
            forces_n: [4.0, 6.0, 10.0, 16.0, 25.0, 40.0, 63.0, 100.0]
                .iter()
                .map(|f| f * 1e-3)
                .collect(),
            seed: 2018,
            psf_fwhm_m: 450e-9,
            background: 300.0,
            signal: 1800.0,
            signal_gain_per_decade: 0.08,
            counts_per_photon: 4.0,
            first_area_m2: 40e-12,
            area_exponent: 0.85,
            sphere_radius_m: 290e-6,
            roughness_rms_m: 0.12e-6,
            patch_scale: 1.0,
            read_noise_counts: 0.0,
        }
    }
}

/// One generated image and its truth.
#[derive(Debug, Clone)]
pub struct SynthImage {
    /// Normal force, N.
    pub force_n: f64,
    /// 12-bit intensities, row-major.
    pub codes: Vec<u16>,
    /// True contact mask, row-major.
    pub truth: Vec<bool>,
    /// Number of true contact pixels.
    pub true_contact_pixels: u64,
    /// True contact area, µm².
    pub true_area_um2: f64,
}

impl SynthParams {
    /// The working planes of one image (f64) and the series kept in memory (a 16-bit image and
    /// a truth mask per force) against the limits, before any is allocated.
    fn check_memory(&self) -> Result<()> {
        let limits = crate::limits::Limits::DEFAULT;
        limits
            .plane_bytes(self.width, self.height, 8)
            .map_err(|source| Error::Limit {
                what: "a synthetic image".into(),
                source,
            })?;
        let total = (self.width * self.height).checked_mul(3 * self.forces_n.len());
        match total {
            Some(bytes) if bytes <= limits.max_plane_bytes => Ok(()),
            _ => Err(Error::InvalidArgument(format!(
                "{} images of {}×{} px would hold {:.1} GiB in memory (the limit is {} GiB); \
                 give fewer forces ({}) or a smaller size ({})",
                self.forces_n.len(),
                self.width,
                self.height,
                (self.width * self.height) as f64 * 3.0 * self.forces_n.len() as f64
                    / (1u64 << 30) as f64,
                limits.max_plane_bytes >> 30,
                contactscope_formats::param::Param::Forces,
                contactscope_formats::param::Param::Size
            ))),
        }
    }

    fn check(&self) -> Result<()> {
        let ok = self.width >= 8
            && self.height >= 8
            && self
                .width
                .checked_mul(self.height)
                .is_some_and(|n| n <= 1 << 26)
            && self.pixel_size_m > 0.0
            && self.patch_scale > 0.0
            && self.patch_scale.is_finite()
            && self.read_noise_counts >= 0.0
            && self.read_noise_counts.is_finite()
            && !self.forces_n.is_empty()
            && self.forces_n.iter().all(|f| f.is_finite() && *f > 0.0);
        if ok {
            self.check_memory()?;
            // The widest blur: the coarse roughness (1.5 µm) or the PSF, in pixels.
            let widest =
                (1.5e-6 * self.patch_scale).max(self.psf_fwhm_m / 2.3548) / self.pixel_size_m;
            crate::limits::Limits::DEFAULT
                .kernel_radius(widest)
                .map(|_| ())
                .map_err(|reason| {
                    Error::InvalidArgument(format!(
                        "{}: {:.4e} m is too small for the generator's blurs: {reason}",
                        contactscope_formats::param::Param::PixelSize,
                        self.pixel_size_m
                    ))
                })
        } else {
            use contactscope_formats::param::Param;
            Err(Error::InvalidArgument(format!(
                "a synthetic series needs 8×8 to 2^26 pixels ({}: {} × {}), a positive pixel size \
                 ({}) and positive forces ({})",
                Param::Size,
                self.width,
                self.height,
                Param::PixelSize,
                Param::Forces
            )))
        }
    }

    /// True contact area at force `n`, m².
    pub fn true_area_m2(&self, n: f64) -> f64 {
        self.first_area_m2 * (n / self.forces_n[0]).powf(self.area_exponent)
    }
}

/// Generate the series in memory.
pub fn generate(p: &SynthParams) -> Result<Vec<SynthImage>> {
    p.check()?;
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let separation = separation_map(p, &mut rng);
    let mut order: Vec<usize> = (0..separation.len()).collect();
    order.sort_by(|&a, &b| separation[a].total_cmp(&separation[b]));
    let pixel_area = p.pixel_size_m * p.pixel_size_m;
    let psf_sigma_px = p.psf_fwhm_m / (8.0 * 2f64.ln()).sqrt() / p.pixel_size_m;
    let mut images = Vec::with_capacity(p.forces_n.len());
    for &force in &p.forces_n {
        let n_contact = (p.true_area_m2(force) / pixel_area).round() as usize;
        if n_contact * 2 > order.len() {
            return Err(Error::InvalidArgument(format!(
                "the true contact at {} mN ({:.0} µm²) would cover more than half the {}×{} px \
                 field; use a larger image ({}) or smaller forces ({})",
                force * 1e3,
                p.true_area_m2(force) * 1e12,
                p.width,
                p.height,
                contactscope_formats::param::Param::Size,
                contactscope_formats::param::Param::Forces
            )));
        }
        let mut truth = vec![false; order.len()];
        for &i in &order[..n_contact] {
            truth[i] = true;
        }
        let signal = p.signal * (1.0 + p.signal_gain_per_decade * (force / p.forces_n[0]).log10());
        let ideal: Vec<f64> = truth
            .iter()
            .map(|&t| if t { signal } else { 0.0 })
            .collect();
        let blurred = isotropic_blur(&ideal, p.width, p.height, psf_sigma_px);
        let codes = render(p, &blurred, &mut rng)?;
        images.push(SynthImage {
            force_n: force,
            codes,
            truth,
            true_contact_pixels: n_contact as u64,
            true_area_um2: n_contact as f64 * pixel_area * 1e12,
        });
    }
    Ok(images)
}

/// Undeformed separation s = r²/2R − z in metres.
fn separation_map(p: &SynthParams, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let coarse = normalised_noise(p, 1.5e-6 * p.patch_scale, rng);
    let fine = normalised_noise(p, 0.4e-6 * p.patch_scale, rng);
    let (cx, cy) = (
        p.width as f64 / 2.0 + rng.random_range(-2.0..2.0),
        p.height as f64 / 2.0 + rng.random_range(-2.0..2.0),
    );
    let norm = (0.8f64 * 0.8 + 0.6 * 0.6).sqrt();
    (0..p.width * p.height)
        .map(|i| {
            let (x, y) = ((i % p.width) as f64 - cx, (i / p.width) as f64 - cy);
            let r2 = (x * x + y * y) * p.pixel_size_m * p.pixel_size_m;
            let z = p.roughness_rms_m * (0.8 * coarse[i] + 0.6 * fine[i]) / norm;
            r2 / (2.0 * p.sphere_radius_m) - z
        })
        .collect()
}

/// White noise blurred at a correlation length, rescaled to zero mean and unit variance.
fn normalised_noise(p: &SynthParams, correlation_m: f64, rng: &mut ChaCha8Rng) -> Vec<f64> {
    let white: Vec<f64> = (0..p.width * p.height)
        .map(|_| rng.sample(StandardNormal))
        .collect();
    let mut field = isotropic_blur(&white, p.width, p.height, correlation_m / p.pixel_size_m);
    let n = field.len() as f64;
    let mean = field.iter().sum::<f64>() / n;
    let sd = (field.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    field.iter_mut().for_each(|v| *v = (*v - mean) / sd);
    field
}

/// Background with a weak gradient, plus signal, with shot noise (and read noise when asked
/// for), clipped to 12 bits.
fn render(p: &SynthParams, signal: &[f64], rng: &mut ChaCha8Rng) -> Result<Vec<u16>> {
    let expected: Vec<f64> = signal
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let x = (i % p.width) as f64 / p.width as f64;
            p.background * (0.95 + 0.1 * x) + s
        })
        .collect();
    let mut codes = shot_noise_12bit(&expected, p.counts_per_photon, rng)?;
    if p.read_noise_counts > 0.0 {
        // Drawn after the shot noise, so that a series without read noise is the same as before
        // the option existed.
        for c in &mut codes {
            let n: f64 = rng.sample(StandardNormal);
            *c = (f64::from(*c) + p.read_noise_counts * n)
                .round()
                .clamp(0.0, 4095.0) as u16;
        }
    }
    Ok(codes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generation_is_deterministic_and_truth_follows_the_area_law() {
        let p = SynthParams {
            width: 64,
            height: 64,
            forces_n: vec![4e-3, 8e-3],
            ..SynthParams::default()
        };
        let a = generate(&p).unwrap();
        let b = generate(&p).unwrap();
        assert_eq!(a[1].codes, b[1].codes);
        assert_eq!(a[0].true_contact_pixels, 1000);
        let expected = (40.0 * 2f64.powf(0.85) / 0.04).round() as u64;
        assert_eq!(a[1].true_contact_pixels, expected);
        assert!(a[1].codes.iter().all(|&c| c <= 4095));
        let other = generate(&SynthParams { seed: 7, ..p }).unwrap();
        assert_ne!(other[0].codes, a[0].codes);
    }
}
