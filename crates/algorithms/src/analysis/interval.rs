//! An interval on one image's contact area that carries the blur at the contact edges and the
//! threshold's bias (`docs/methods.md`, "Area intervals").
//!
//! A Gaussian PSF turns the true contact's sharp edge into a ramp from the background level b
//! to the contact level c = b + s. For a straight edge the true edge lies where the ramp
//! crosses b + s/2; curvature (small asperity patches, comparable to the PSF), pixel noise and
//! the threshold's own choice move the measured edge from there. The interval brackets the true
//! edge between two levels of the same ramp:
//!
//! * `lo`: pixels brighter than b + (½ + w)·s — inside the true contact however the ramp sits;
//! * `hi`: pixels brighter than b + (½ − w)·s that are connected (8-neighbours) to the measured
//!   contact — a hysteresis region grown from it, so that isolated noise pixels far from any
//!   contact do not count;
//!
//! then both moved out by [`NOISE_WIDENING`] standard deviations of the number of pixels that
//! pixel noise puts on the other side of the ramp's middle (variance Σ p(1 − p), p = Φ(−|v −
//! (b + s/2)|/σ), σ from the differences of neighbouring pixels), and widened to contain the
//! measured area. b is the median of the non-contact pixels, c the median of the interior
//! contact pixels (all four neighbours contact; all contact pixels when none is interior), so
//! the levels follow each image's own background and signal (the signal of rigidochromic probes
//! rises with load). The half-width w is one number for every image, [`EDGE_BAND_HALF_WIDTH`];
//! the coverage of the true area is measured on synthetic series with known truth over seeds,
//! noise levels and PSF widths (`docs/validation.md` B25, `cargo bench --bench intervals`).

use crate::image::{Plane, Samples};
use crate::measure::Mask;

/// Half-width w of the band of levels, as a fraction of the contact signal s (module docs);
/// chosen on calibration seeds of the coverage benchmark, its coverage measured on others.
pub const EDGE_BAND_HALF_WIDTH: f64 = 0.05;

/// The widening for pixel noise, in standard deviations of the count of pixels that noise puts
/// on the other side of the ramp's middle (module docs): 1.96, two-sided 95 %.
pub const NOISE_WIDENING: f64 = 1.96;

/// At most about this many pixels are sampled (every k-th pixel, evenly) for the levels'
/// medians and the noise estimate: a 256² image uses every pixel (the images the coverage was
/// measured on), a 1024² one every 16th.
const MEDIAN_SAMPLES: usize = 1 << 16;

/// The interval on one image's contact area, in pixels, and the levels it came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaBand {
    /// Pixels surely in contact (≤ the measured contact pixels).
    pub lo_pixels: u64,
    /// Pixels possibly in contact (≥ the measured contact pixels).
    pub hi_pixels: u64,
    /// Background level b (median of the non-contact pixels); `None` without any.
    pub background: Option<f64>,
    /// Contact level c (median of the interior contact pixels); `None` without contact.
    pub contact_level: Option<f64>,
}

impl AreaBand {
    /// The degenerate interval of a measurement whose levels cannot be estimated.
    fn point(pixels: u64, background: Option<f64>, contact_level: Option<f64>) -> Self {
        AreaBand {
            lo_pixels: pixels,
            hi_pixels: pixels,
            background,
            contact_level,
        }
    }
}

/// The interval on the contact area of `plane` whose measured contact is `mask` (module docs),
/// with band half-width `w` (a fraction of the signal, 0 < w < ½) widened by `z` standard
/// deviations of the pixel noise.
pub fn area_band(plane: &Plane, mask: &Mask, w: f64, z: f64) -> AreaBand {
    let n = plane.len();
    let measured = mask.contact_pixels();
    let values = |keep: &dyn Fn(usize) -> bool| -> Vec<f64> {
        let stride = n.div_ceil(MEDIAN_SAMPLES).max(1);
        (0..n)
            .step_by(stride)
            .filter(|&i| keep(i))
            .map(|i| plane.value(i))
            .filter(|v| v.is_finite())
            .collect()
    };
    let background = median(values(&|i| mask.data[i] == 0));
    let (wd, ht) = (plane.width, plane.height);
    let interior = |i: usize| {
        let (x, y) = (i % wd, i / wd);
        mask.data[i] != 0
            && x > 0
            && y > 0
            && x + 1 < wd
            && y + 1 < ht
            && [i - 1, i + 1, i - wd, i + wd]
                .iter()
                .all(|&j| mask.data[j] != 0)
    };
    let contact_level =
        median(values(&interior)).or_else(|| median(values(&|i| mask.data[i] != 0)));
    let (Some(b), Some(c)) = (background, contact_level) else {
        return AreaBand::point(measured, background, contact_level);
    };
    let s = c - b;
    if !(s > 0.0 && (0.0..0.5).contains(&w)) {
        return AreaBand::point(measured, background, contact_level);
    }
    let mid = b + 0.5 * s;
    let (upper, lower) = (mid + w * s, mid - w * s);
    let possibly = grown(plane, mask, lower);
    // One pass over the pixels: those surely in contact (above `upper`), and the pixel noise:
    // each pixel is on the other side of the ramp's middle with probability
    // p = Φ(−|v − mid|/σ); the count of such pixels has variance Σ p(1 − p).
    let sd = noise_sd(plane, mask).filter(|&sd| sd > 0.0);
    let (mut surely, mut var) = (0u64, 0.0f64);
    for_each_level(plane, |v, count| {
        surely += u64::from(v > upper) * count;
        if let Some(sd) = sd {
            if v.is_finite() && (v - mid).abs() < 6.0 * sd {
                let p = normal_tail((v - mid).abs() / sd);
                var += count as f64 * p * (1.0 - p);
            }
        }
    });
    let spread = (z * var.sqrt()).round() as u64;
    AreaBand {
        lo_pixels: surely.min(measured).saturating_sub(spread),
        hi_pixels: possibly.max(measured) + spread,
        background,
        contact_level,
    }
}

/// The pixel noise at the middle of the ramp: √((σ_b² + σ_c²)/2) from the noise of the
/// background (σ_b) and of the interior contact (σ_c), each from the differences of
/// horizontally adjacent pixels of the class (1.4826·MAD/√2, robust to edges and gradients).
fn noise_sd(plane: &Plane, mask: &Mask) -> Option<f64> {
    let w = plane.width;
    let class_sd = |contact: bool| {
        let stride = plane.len().div_ceil(MEDIAN_SAMPLES).max(1);
        let diffs: Vec<f64> = (0..plane.len())
            .step_by(stride)
            .filter(|&i| i % w + 1 < w)
            .filter(|&i| (mask.data[i] != 0) == contact && (mask.data[i + 1] != 0) == contact)
            .map(|i| plane.value(i + 1) - plane.value(i))
            .filter(|d| d.is_finite())
            .collect();
        let m = median(diffs.clone())?;
        let mad = median(diffs.into_iter().map(|d| (d - m).abs()).collect())?;
        Some(1.4826 * mad / 2f64.sqrt())
    };
    let (b, c) = (class_sd(false)?, class_sd(true).unwrap_or(0.0));
    Some(((b * b + c * c) / 2.0).sqrt())
}

/// Calls `f(value, pixels)` for every value the plane holds with the number of its pixels: for
/// integer samples once per grey level present (from a histogram of the codes: the erfc of the
/// noise term is then evaluated once per level, not once per pixel), for float samples once per
/// pixel.
fn for_each_level(plane: &Plane, mut f: impl FnMut(f64, u64)) {
    match &plane.samples {
        Samples::Int { codes, offset } => {
            let mut counts = vec![0u32; 1 << 16];
            for &c in codes {
                counts[usize::from(c)] += 1;
            }
            for (c, &n) in counts.iter().enumerate().filter(|(_, &n)| n > 0) {
                // c < 2^16: the code itself.
                f(f64::from(c as i32 + offset), u64::from(n));
            }
        }
        Samples::Float(v) => v.iter().for_each(|&x| f(f64::from(x), 1)),
    }
}

/// Pixels above `level` connected (8-neighbours, through pixels above `level`) to a contact
/// pixel of `mask`; contact pixels count whatever their value. The fill starts from the contact
/// pixels on the contact's edge (a pixel inside it has no other neighbour to reach).
fn grown(plane: &Plane, mask: &Mask, level: f64) -> u64 {
    let (w, h) = (plane.width, plane.height);
    let mut seen: Vec<bool> = mask.data.iter().map(|&m| m != 0).collect();
    let mut count = seen.iter().filter(|&&c| c).count() as u64;
    let neighbours = |i: usize| {
        let (x, y) = ((i % w) as isize, (i / w) as isize);
        (-1..=1isize)
            .flat_map(move |dy| (-1..=1isize).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(nx, ny)| nx >= 0 && ny >= 0 && nx < w as isize && ny < h as isize)
            .map(move |(nx, ny)| ny as usize * w + nx as usize)
    };
    // The contact pixels with a non-contact 8-neighbour, or on the image's border, row by row
    // (direct offsets: this scan touches every pixel).
    let mut stack = Vec::new();
    for y in 0..h {
        let row = y * w;
        for x in 0..w {
            let i = row + x;
            if !seen[i] {
                continue;
            }
            let inner = x > 0 && y > 0 && x + 1 < w && y + 1 < h;
            if !inner
                || [
                    i - w - 1,
                    i - w,
                    i - w + 1,
                    i - 1,
                    i + 1,
                    i + w - 1,
                    i + w,
                    i + w + 1,
                ]
                .iter()
                .any(|&j| !seen[j])
            {
                stack.push(i);
            }
        }
    }
    while let Some(i) = stack.pop() {
        for j in neighbours(i) {
            if !seen[j] && plane.value(j) > level {
                seen[j] = true;
                count += 1;
                stack.push(j);
            }
        }
    }
    count
}

/// P(Z > x) of a standard normal Z (x ≥ 0).
fn normal_tail(x: f64) -> f64 {
    0.5 * libm::erfc(x / std::f64::consts::SQRT_2)
}

/// The median of `v` (the upper one of an even count); `None` when empty.
pub(super) fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    let k = v.len() / 2;
    let (_, m, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    Some(*m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::blur::isotropic_blur;

    /// A disk of radius `r` px (contact 1000 above a background of 200) blurred by σ px.
    fn blurred_disk(size: usize, r: f64, sigma: f64) -> (Plane, u64) {
        let c = size as f64 / 2.0;
        let truth: Vec<f64> = (0..size * size)
            .map(|i| {
                let (x, y) = ((i % size) as f64 + 0.5 - c, (i / size) as f64 + 0.5 - c);
                if x * x + y * y <= r * r {
                    1000.0
                } else {
                    0.0
                }
            })
            .collect();
        let true_pixels = truth.iter().filter(|&&v| v > 0.0).count() as u64;
        let blurred = isotropic_blur(&truth, size, size, sigma);
        let codes = blurred.iter().map(|v| (200.0 + v).round() as u16).collect();
        (Plane::from_u16(size, size, codes), true_pixels)
    }

    fn mask_above(plane: &Plane, t: f64) -> Mask {
        Mask {
            width: plane.width,
            height: plane.height,
            data: (0..plane.len())
                .map(|i| u8::from(plane.value(i) > t))
                .collect(),
        }
    }

    #[test]
    fn the_band_brackets_a_blurred_disk_whatever_the_threshold() {
        // σ = 1 px (a 450 nm PSF on 200 nm pixels), radii from 3 to 20 px; thresholds at 30 %
        // and 70 % of the signal move the measured area by ± the ramp, the band holds the truth.
        for r in [3.0, 5.0, 10.0, 20.0] {
            let (plane, truth) = blurred_disk(64, r, 1.0);
            for t in [500.0, 700.0, 900.0] {
                let band = area_band(
                    &plane,
                    &mask_above(&plane, t),
                    EDGE_BAND_HALF_WIDTH,
                    NOISE_WIDENING,
                );
                assert!(
                    band.lo_pixels <= truth && truth <= band.hi_pixels,
                    "r {r}, t {t}: {truth} not in {band:?}"
                );
            }
        }
        // Without noise the band is narrow: levels 650 and 750 of the ramp, ±0.13 σ.
        let (plane, truth) = blurred_disk(64, 20.0, 1.0);
        let band = area_band(
            &plane,
            &mask_above(&plane, 700.0),
            EDGE_BAND_HALF_WIDTH,
            NOISE_WIDENING,
        );
        let width = (band.hi_pixels - band.lo_pixels) as f64 / truth as f64;
        assert!(width < 0.03, "relative width {width}");
        assert_eq!(band.background, Some(200.0));
        assert_eq!(band.contact_level, Some(1200.0));
        // Noise of ±40 counts (a fixed pseudo-random pattern) widens it, and it still holds
        // the truth.
        let mut state = 12345u64;
        let codes: Vec<u16> = (0..plane.len())
            .map(|i| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 33) as f64 / (1u64 << 31) as f64;
                (plane.value(i) + 80.0 * (u - 0.5)).round() as u16
            })
            .collect();
        let noisy = Plane::from_u16(64, 64, codes);
        let band = area_band(
            &noisy,
            &mask_above(&noisy, 700.0),
            EDGE_BAND_HALF_WIDTH,
            NOISE_WIDENING,
        );
        let noisy_width = (band.hi_pixels - band.lo_pixels) as f64 / truth as f64;
        assert!(noisy_width > width && noisy_width < 0.15, "{noisy_width}");
        assert!(
            band.lo_pixels <= truth && truth <= band.hi_pixels,
            "{band:?}"
        );
    }

    #[test]
    fn isolated_bright_pixels_far_from_contact_do_not_widen_the_band() {
        let (plane, _) = blurred_disk(64, 10.0, 1.0);
        let mut codes: Vec<u16> = (0..plane.len()).map(|i| plane.value(i) as u16).collect();
        codes[64 * 2 + 2] = 600; // above b + s/4 = 450, far from the disk
        let noisy = Plane::from_u16(64, 64, codes);
        let clean = area_band(
            &plane,
            &mask_above(&plane, 700.0),
            EDGE_BAND_HALF_WIDTH,
            NOISE_WIDENING,
        );
        let speck = area_band(
            &noisy,
            &mask_above(&noisy, 700.0),
            EDGE_BAND_HALF_WIDTH,
            NOISE_WIDENING,
        );
        assert_eq!(clean.hi_pixels, speck.hi_pixels);
    }

    #[test]
    fn without_contact_or_background_the_band_is_the_measurement() {
        let plane = Plane::from_u16(4, 4, vec![100; 16]);
        let none = area_band(
            &plane,
            &mask_above(&plane, 500.0),
            EDGE_BAND_HALF_WIDTH,
            NOISE_WIDENING,
        );
        assert_eq!((none.lo_pixels, none.hi_pixels), (0, 0));
        let all = area_band(
            &plane,
            &mask_above(&plane, 50.0),
            EDGE_BAND_HALF_WIDTH,
            NOISE_WIDENING,
        );
        assert_eq!((all.lo_pixels, all.hi_pixels), (16, 16));
    }
}
