//! Radially averaged, mean-subtracted, normalised autocorrelation of an image (Wiener–Khinchin),
//! as the paper compares experimental and simulated fluorescence images (Weber et al. 2018,
//! Methods: patch scale ≈ 5 µm; docs/methods.md §7.2).
//!
//! Recorded choices: the mean over the finite pixels is subtracted; the image is zero-padded to
//! 2N_y × 2N_x so there is no wrap-around; the estimate is **unbiased**: the raw correlation at
//! each lag is divided by the number of pixel pairs at that lag (the autocorrelation of the mask
//! of finite pixels), then by its value at zero lag, so C(0) = 1. Lags with fewer than a quarter of
//! the pairs of lag zero (beyond about half the image) are dropped. The radial average bins
//! r = √((l_xΔx)² + (l_yΔy)²) in rings one pixel wide, weighted by the pair counts.
//! Correlation lengths: ξ_1/e is the first radius where C ≤ 1/e (linear interpolation between
//! rings); the first zero crossing is reported too.

use super::RealFft2;
use crate::error::{Error, Result};

/// The 2-D autocorrelation at lags (l_y, l_x), each in −(n−1)..=(n−1), with pair counts.
#[derive(Debug, Clone)]
pub struct Autocorrelation2 {
    width: usize,
    height: usize,
    /// C at padded index ((l_y mod 2N_y)·2N_x + (l_x mod 2N_x)).
    values: Vec<f64>,
    pairs: Vec<f64>,
}

impl Autocorrelation2 {
    fn index(&self, ly: i64, lx: i64) -> usize {
        let (px, py) = (2 * self.width as i64, 2 * self.height as i64);
        (ly.rem_euclid(py) * px + lx.rem_euclid(px)) as usize
    }

    /// C at lag (l_y, l_x) in pixels, normalised so C(0, 0) = 1.
    pub fn at(&self, ly: i64, lx: i64) -> f64 {
        self.values[self.index(ly, lx)]
    }

    /// Number of pixel pairs at lag (l_y, l_x).
    pub fn pairs(&self, ly: i64, lx: i64) -> f64 {
        self.pairs[self.index(ly, lx)]
    }
}

/// Autocorrelation of `values` (row-major, `height` rows of `width`); non-finite pixels are left
/// out. Errors for a constant image (no variance) or one with fewer than 2 finite pixels.
pub fn autocorrelation(values: &[f64], width: usize, height: usize) -> Result<Autocorrelation2> {
    if width == 0 || height == 0 || values.len() != width * height {
        return Err(Error::InvalidArgument(format!(
            "image of {} values is not {width}×{height}",
            values.len()
        )));
    }
    // The zero-padded FFT grid (2h × 2w), the largest array, before any is allocated.
    crate::limits::Limits::DEFAULT
        .plane_bytes(width.saturating_mul(2), height.saturating_mul(2), 8)
        .map_err(|source| Error::Limit {
            what: format!(
                "the autocorrelation of a {width}×{height} image (padded to twice its size)"
            ),
            source,
        })?;
    let finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.len() < 2 {
        return Err(Error::InvalidArgument(
            "image has fewer than 2 finite pixels".into(),
        ));
    }
    let mean = finite.iter().sum::<f64>() / finite.len() as f64;
    let centred: Vec<f64> = values
        .iter()
        .map(|v| if v.is_finite() { v - mean } else { 0.0 })
        .collect();
    let mask: Vec<f64> = values
        .iter()
        .map(|v| f64::from(u8::from(v.is_finite())))
        .collect();
    let fft = RealFft2::new(2 * height, 2 * width);
    let raw = self_correlation(&fft, &centred, width, height);
    let pairs = self_correlation(&fft, &mask, width, height);
    let zero = raw[0] / pairs[0];
    if zero.is_nan() || zero <= 0.0 {
        return Err(Error::ConstantData {
            what: "image".into(),
            value: mean,
        });
    }
    let values = raw
        .iter()
        .zip(&pairs)
        .map(|(r, m)| if *m > 0.5 { r / m / zero } else { f64::NAN })
        .collect();
    Ok(Autocorrelation2 {
        width,
        height,
        values,
        pairs: pairs.iter().map(|m| m.round()).collect(),
    })
}

/// Σ_x f(x) f(x + l) for every lag on the padded grid, by |FFT|² and an inverse FFT.
fn self_correlation(fft: &RealFft2, field: &[f64], width: usize, height: usize) -> Vec<f64> {
    let px = 2 * width;
    let mut padded = vec![0.0; height * px];
    for (row, src) in padded.chunks_mut(px).zip(field.chunks(width)) {
        row[..width].copy_from_slice(src);
    }
    let mut spectrum = fft.make_spectrum();
    let mut scratch = Vec::new();
    fft.forward_rows(&mut padded, height, &mut spectrum, &mut scratch);
    for c in spectrum.iter_mut() {
        *c = super::Complex64::new(c.norm_sqr(), 0.0);
    }
    let mut out = vec![0.0; fft.len()];
    fft.inverse(&mut spectrum, &mut out);
    let scale = 1.0 / fft.len() as f64;
    out.iter_mut().for_each(|v| *v *= scale);
    out
}

/// Radial average: (lag in the unit of `dx`/`dy`, C) for rings one pixel (min(dx, dy)) wide up to
/// `max_lag`, weighted by pair counts; lags with fewer than a quarter of the zero-lag pairs are
/// left out.
pub fn radial_average(acf: &Autocorrelation2, dx: f64, dy: f64, max_lag: f64) -> Vec<(f64, f64)> {
    let step = dx.min(dy);
    let bins = (max_lag / step).floor() as usize + 1;
    let (mut sum, mut weight, mut radius) = (vec![0.0; bins], vec![0.0; bins], vec![0.0; bins]);
    let floor = 0.25 * acf.pairs(0, 0);
    let (w, h) = (acf.width as i64, acf.height as i64);
    for ly in -(h - 1)..h {
        for lx in -(w - 1)..w {
            let pairs = acf.pairs(ly, lx);
            let r = ((lx as f64 * dx).powi(2) + (ly as f64 * dy).powi(2)).sqrt();
            let bin = (r / step).round() as usize;
            if bin >= bins || pairs < floor {
                continue;
            }
            sum[bin] += pairs * acf.at(ly, lx);
            radius[bin] += pairs * r;
            weight[bin] += pairs;
        }
    }
    (0..bins)
        .filter(|&b| weight[b] > 0.0)
        .map(|b| (radius[b] / weight[b], sum[b] / weight[b]))
        .collect()
}

/// First radius where the radial profile falls to `level`, linearly interpolated.
pub fn first_crossing(profile: &[(f64, f64)], level: f64) -> Option<f64> {
    profile.windows(2).find_map(|w| {
        let ((r0, c0), (r1, c1)) = (w[0], w[1]);
        (c0 > level && c1 <= level).then(|| r0 + (c0 - level) / (c0 - c1) * (r1 - r0))
    })
}

/// Radially averaged autocorrelation of one image with its correlation lengths.
#[derive(Debug, Clone, PartialEq)]
pub struct AcfCurve {
    /// Name in tables and legends: the file name, with `:page N` for multi-page files.
    pub label: String,
    /// `(lag in m, C)`, C(0) = 1.
    pub profile: Vec<(f64, f64)>,
    /// First lag where C ≤ 1/e, m.
    pub xi_1e_m: Option<f64>,
    /// First lag where C ≤ 0, m.
    pub first_zero_m: Option<f64>,
}

impl AcfCurve {
    /// The autocorrelation of `values` (`height` rows of `width`, pixel `dx_m × dy_m`) up to
    /// `max_lag_m`.
    pub fn of_grid(
        label: &str,
        values: &[f64],
        (width, height): (usize, usize),
        (dx_m, dy_m): (f64, f64),
        max_lag_m: f64,
    ) -> Result<Self> {
        if !(max_lag_m.is_finite() && max_lag_m > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "largest lag {max_lag_m:e} m is not a positive length"
            )));
        }
        let acf = autocorrelation(values, width, height)?;
        let profile = radial_average(&acf, dx_m, dy_m, max_lag_m);
        Ok(AcfCurve {
            label: label.to_string(),
            xi_1e_m: first_crossing(&profile, (-1.0f64).exp()),
            first_zero_m: first_crossing(&profile, 0.0),
            profile,
        })
    }

    /// C interpolated linearly at `lag_m`, `None` outside the profile.
    pub fn at(&self, lag_m: f64) -> Option<f64> {
        self.profile.windows(2).find_map(|w| {
            let ((r0, c0), (r1, c1)) = (w[0], w[1]);
            (r0..=r1)
                .contains(&lag_m)
                .then(|| c0 + (c1 - c0) * (lag_m - r0) / (r1 - r0))
        })
    }

    /// Root-mean-square difference between two curves over their common lags (sampled at this
    /// curve's lags), or `None` if they share no lag.
    pub fn rms_distance(&self, other: &AcfCurve) -> Option<f64> {
        let diffs: Vec<f64> = self
            .profile
            .iter()
            .filter_map(|&(r, c)| other.at(r).map(|o| c - o))
            .collect();
        (!diffs.is_empty())
            .then(|| (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_whose_padded_grid_is_beyond_the_limits_is_refused() {
        let e = autocorrelation(&vec![1.0; 40_000 * 2], 40_000, 2)
            .unwrap_err()
            .to_string();
        assert!(e.contains("autocorrelation of a 40000×2 image"), "{e}");
    }
    use rand::{Rng, SeedableRng};

    #[test]
    fn fft_estimate_equals_direct_sum() {
        let (w, h) = (9, 7);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut img: Vec<f64> = (0..w * h).map(|_| rng.random_range(0.0..10.0)).collect();
        img[10] = f64::NAN;
        let acf = autocorrelation(&img, w, h).unwrap();
        let finite: Vec<f64> = img.iter().copied().filter(|v| v.is_finite()).collect();
        let mean = finite.iter().sum::<f64>() / finite.len() as f64;
        let direct = |ly: i64, lx: i64| {
            let (mut s, mut n) = (0.0, 0.0);
            for y in 0..h as i64 {
                for x in 0..w as i64 {
                    let (y2, x2) = (y + ly, x + lx);
                    if y2 < 0 || x2 < 0 || y2 >= h as i64 || x2 >= w as i64 {
                        continue;
                    }
                    let (a, b) = (
                        img[(y * w as i64 + x) as usize],
                        img[(y2 * w as i64 + x2) as usize],
                    );
                    if a.is_finite() && b.is_finite() {
                        s += (a - mean) * (b - mean);
                        n += 1.0;
                    }
                }
            }
            (s / n, n)
        };
        let c0 = direct(0, 0).0;
        for ly in -(h as i64 - 1)..h as i64 {
            for lx in -(w as i64 - 1)..w as i64 {
                let (c, n) = direct(ly, lx);
                assert_eq!(acf.pairs(ly, lx), n, "pairs at ({ly},{lx})");
                if n > 0.0 {
                    assert!((acf.at(ly, lx) - c / c0).abs() < 1e-12, "({ly},{lx})");
                }
            }
        }
    }

    #[test]
    fn blurred_noise_has_correlation_length_two_sigma() {
        // docs/validation.md B17: white noise blurred by a Gaussian of σ_g has C(r) = exp(−r²/(4σ_g²)),
        // so ξ_1/e = 2σ_g (±3 %).
        let n = 512;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let noise: Vec<f64> = (0..n * n)
            .map(|_| rng.sample(rand_distr::StandardNormal))
            .collect();
        let field = crate::optics::blur::isotropic_blur(&noise, n, n, 4.0);
        let acf = autocorrelation(&field, n, n).unwrap();
        let profile = radial_average(&acf, 1.0, 1.0, 40.0);
        let xi = first_crossing(&profile, (-1f64).exp()).unwrap();
        assert!((xi / 8.0 - 1.0).abs() < 0.03, "ξ = {xi}");
        for &(r, c) in profile.iter().take(12) {
            assert!((c - (-r * r / 64.0).exp()).abs() < 0.03, "C({r}) = {c}");
        }
    }

    #[test]
    fn constant_image_is_an_error() {
        assert!(autocorrelation(&[3.0; 16], 4, 4).is_err());
        assert!(autocorrelation(&[1.0, 2.0], 3, 1).is_err());
    }
}
