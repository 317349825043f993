//! Simulated contact maps as a confocal microscope records them: blurred by the PSF, integrated
//! onto image pixels, on a background, with photon shot noise, 12 bits.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Poisson};

use crate::error::{Error, Result};
use crate::optics::blur;

/// Photon shot noise on expected grey levels (Poisson in photons of `counts_per_photon` grey
/// levels each), rounded and clipped to 12 bits.
pub(crate) fn shot_noise_12bit(
    expected: &[f64],
    counts_per_photon: f64,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<u16>> {
    expected
        .iter()
        .map(|&e| {
            let photons = Poisson::new(e.max(1e-9) / counts_per_photon)
                .map_err(|e| Error::InvalidArgument(format!("shot noise: {e}")))?
                .sample(rng);
            Ok((photons * counts_per_photon).round().clamp(0.0, 4095.0) as u16)
        })
        .collect()
}

/// How [`render_micrograph`] turns a simulated contact map into a 12-bit confocal image.
#[derive(Debug, Clone, PartialEq)]
pub struct MicrographParams {
    /// PSF full width at half maximum, m.
    pub fwhm_m: f64,
    /// Image pixel size, m (square pixels).
    pub pixel_m: f64,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Image pixel (x, y) where the map's first pixel corner lands.
    pub corner_px: (usize, usize),
    /// Background grey level.
    pub background: f64,
    /// Grey level added by a fully covered contact pixel.
    pub contact_level: f64,
    /// Grey levels per detected photon (shot noise); 0 for none.
    pub counts_per_photon: f64,
    /// Noise seed.
    pub seed: u64,
}

/// A simulated contact map (1 = contact) as the microscope would record it: blurred by the PSF and
/// integrated onto image pixels ([`crate::optics::blur::microscope_image`]), placed on a
/// background, with shot noise, 12 bits. Errors if the map does not fit the image.
pub fn render_micrograph(map: &blur::Grid, p: &MicrographParams) -> Result<Vec<u16>> {
    let image = blur::microscope_image(map, p.fwhm_m, (p.pixel_m, p.pixel_m))?;
    let (x0, y0) = p.corner_px;
    if x0 + image.width > p.width || y0 + image.height > p.height {
        return Err(Error::InvalidArgument(format!(
            "the rendered map ({}×{} px) at ({x0}, {y0}) does not fit a {}×{} image",
            image.width, image.height, p.width, p.height
        )));
    }
    let mut expected = vec![p.background; p.width * p.height];
    for y in 0..image.height {
        for x in 0..image.width {
            expected[(y + y0) * p.width + x + x0] +=
                p.contact_level * image.values[y * image.width + x];
        }
    }
    if p.counts_per_photon <= 0.0 {
        return Ok(expected
            .iter()
            .map(|v| v.round().clamp(0.0, 4095.0) as u16)
            .collect());
    }
    shot_noise_12bit(
        &expected,
        p.counts_per_photon,
        &mut ChaCha8Rng::seed_from_u64(p.seed),
    )
}
