//! Image registration by phase correlation with sub-pixel refinement by an upsampled DFT around
//! the peak (Kuglin & Hines 1975; Guizar-Sicairos, Thurman & Fienup, Opt. Lett. 33, 156 (2008)),
//! and a search over the eight dihedral transforms, because the microscope looks up through the
//! coverslip while the AFM scanned the sphere from outside (docs/methods.md §8).
//!
//! [`register_series`] registers a whole load series with one shift ([`series`]).
//!
//! Sign convention (checked by a test): [`phase_correlation`] returns the shift `(dx, dy)` such
//! that `moving(x, y) ≈ reference(x − dx, y − dy)`, i.e. how far the content moved.

pub mod series;

pub use series::{register_series, LoadShift, Refinement, SeriesOptions, SeriesRegistration};

use rustfft::num_complex::Complex64;

use super::RealFft2;
use crate::error::{Error, Result};

/// Result of a phase correlation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shift {
    /// Displacement along x (columns), pixels.
    pub dx: f64,
    /// Displacement along y (rows), pixels.
    pub dy: f64,
    /// Height of the normalised phase-correlation peak (1 for a pure circular shift of an
    /// image, lower for a poorer match); compares candidate transforms.
    pub peak: f64,
}

/// Whether to taper the images before the FFT.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Window {
    /// No taper (exact for circular shifts).
    None,
    /// Separable Hann window: suppresses the cross of spurious correlation from the frame edges.
    Hann,
}

/// The finest sub-pixel resolution offered, 1/`MAX_UPSAMPLE` px: the refinement costs
/// ~(1.5·upsample)² evaluations, and 0.01 px is far below what noise and blur leave resolvable.
pub const MAX_UPSAMPLE: usize = 100;

/// Phase correlation of two images of equal size (`height` rows of `width`); `upsample` in
/// 1 ..= [`MAX_UPSAMPLE`] sets the sub-pixel resolution to 1/`upsample` pixel (1 = integer
/// shifts only).
pub fn phase_correlation(
    reference: &[f64],
    moving: &[f64],
    (width, height): (usize, usize),
    upsample: usize,
    window: Window,
) -> Result<Shift> {
    check_upsample(upsample)?;
    let n = width * height;
    if width < 2 || height < 2 || reference.len() != n || moving.len() != n {
        return Err(Error::InvalidArgument(format!(
            "registration needs two images of {width}×{height} ≥ 2×2, got {} and {} values",
            reference.len(),
            moving.len()
        )));
    }
    let fft = RealFft2::new(height, width);
    let kept = cross_power(&fft, &spectrum(&fft, reference, window), moving, window);
    let (peak_index, peak) = highest(&correlation(&fft, &kept));
    let coarse = signed_position(peak_index, (width, height));
    let (dx, dy, refined_peak) = if upsample > 1 {
        refine(&fft, &kept, coarse, upsample, None)
    } else {
        (coarse.0, coarse.1, peak)
    };
    Ok(Shift {
        dx,
        dy,
        peak: refined_peak / n as f64,
    })
}

fn check_upsample(upsample: usize) -> Result<()> {
    if (1..=MAX_UPSAMPLE).contains(&upsample) {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "registration upsampling {upsample} is outside 1 ..= {MAX_UPSAMPLE} (1/{MAX_UPSAMPLE} px is the finest resolution)"
        )))
    }
}

/// The half spectrum of the mean-subtracted, tapered image.
fn spectrum(fft: &RealFft2, img: &[f64], window: Window) -> Vec<Complex64> {
    let mut input = tapered(img, fft.nx(), fft.ny(), window);
    let mut out = fft.make_spectrum();
    fft.forward(&mut input, &mut out);
    out
}

/// The normalised cross-power spectrum R = F_mov·F_ref*/|F_mov·F_ref*| (zero where either
/// spectrum vanishes), on the half spectrum; its inverse DFT peaks at the shift of `moving`.
fn cross_power(
    fft: &RealFft2,
    reference: &[Complex64],
    moving: &[f64],
    window: Window,
) -> Vec<Complex64> {
    spectrum(fft, moving, window)
        .iter()
        .zip(reference)
        .map(|(m, r)| {
            let c = m * r.conj();
            let norm = c.norm();
            if norm > 1e-300 {
                c / norm
            } else {
                Complex64::new(0.0, 0.0)
            }
        })
        .collect()
}

/// The correlation surface (inverse DFT of a cross spectrum, unnormalised: divide by
/// `fft.len()` for a peak of 1 at a perfect match).
fn correlation(fft: &RealFft2, cross: &[Complex64]) -> Vec<f64> {
    let mut spectrum = cross.to_vec();
    let mut corr = vec![0.0; fft.len()];
    fft.inverse(&mut spectrum, &mut corr);
    corr
}

/// Index and value of the highest element (the first of equal ones).
fn highest(values: &[f64]) -> (usize, f64) {
    values
        .iter()
        .enumerate()
        .fold((0, f64::NEG_INFINITY), |best, (i, &v)| {
            if v > best.1 {
                (i, v)
            } else {
                best
            }
        })
}

/// The signed shift (x, y) of a row-major index: indices past half the side wrap to negative.
fn signed_position(index: usize, (width, height): (usize, usize)) -> (f64, f64) {
    let signed = |k: usize, len: usize| {
        if k > len / 2 {
            k as f64 - len as f64
        } else {
            k as f64
        }
    };
    (signed(index % width, width), signed(index / width, height))
}

fn tapered(img: &[f64], width: usize, height: usize, window: Window) -> Vec<f64> {
    let mean = img.iter().sum::<f64>() / img.len() as f64;
    let hann = |i: usize, n: usize| match window {
        Window::None => 1.0,
        Window::Hann => 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos(),
    };
    let wx: Vec<f64> = (0..width).map(|x| hann(x, width)).collect();
    let wy: Vec<f64> = (0..height).map(|y| hann(y, height)).collect();
    img.iter()
        .enumerate()
        .map(|(i, v)| (v - mean) * wx[i % width] * wy[i / width])
        .collect()
}

/// Inclusive limits `[(x_lo, x_hi), (y_lo, y_hi)]` on a refined shift, pixels.
type Bounds = [(f64, f64); 2];

/// Evaluate the inverse DFT of the normalised cross spectrum on a grid of 1/`upsample` px over
/// ±0.75 px around the coarse peak and return the best point (dx, dy, value), skipping points
/// outside `bounds` (the coarse peak itself must lie inside them). The half spectrum suffices
/// because the correlation of real images is real: r = Σ_half w_kx·Re(R·e^{iθ}).
fn refine(
    fft: &RealFft2,
    cross: &[Complex64],
    coarse: (f64, f64),
    upsample: usize,
    bounds: Option<Bounds>,
) -> (f64, f64, f64) {
    let half = (0.75 * upsample as f64).ceil() as i64;
    let inside = |v: f64, (lo, hi): (f64, f64)| v >= lo - 1e-9 && v <= hi + 1e-9;
    let offsets = |centre: f64, axis: usize| -> Vec<f64> {
        (-half..=half)
            .map(|k| centre + k as f64 / upsample as f64)
            .filter(|&v| bounds.is_none_or(|b| inside(v, b[axis])))
            .collect()
    };
    let (xs, ys) = (offsets(coarse.0, 0), offsets(coarse.1, 1));
    let mut best = (coarse.0, coarse.1, f64::NEG_INFINITY);
    for (y, row) in ys.iter().zip(row_sums(fft, cross, &ys)) {
        for &x in &xs {
            let value = evaluate_row(fft, &row, x);
            if value > best.2 {
                best = (x, *y, value);
            }
        }
    }
    best
}

/// The correlation of a cross spectrum at one (sub-pixel) shift, unnormalised as
/// [`correlation`].
fn correlation_at(fft: &RealFft2, cross: &[Complex64], (x, y): (f64, f64)) -> f64 {
    let row = row_sums(fft, cross, &[y]).swap_remove(0);
    evaluate_row(fft, &row, x)
}

/// T[j][kx] = Σ_ky R(kx, ky) e^{2πi ky y_j / ny}: the column sums of the inverse DFT at rows y_j.
fn row_sums(fft: &RealFft2, cross: &[Complex64], ys: &[f64]) -> Vec<Vec<Complex64>> {
    let ny = fft.ny();
    let tau = 2.0 * std::f64::consts::PI;
    ys.iter()
        .map(|&y| {
            (0..fft.nx() / 2 + 1)
                .map(|kx| {
                    (0..ny)
                        .map(|ky| {
                            let (_, kys) = fft.wavenumbers(kx * ny + ky);
                            cross[kx * ny + ky]
                                * Complex64::from_polar(1.0, tau * kys as f64 * y / ny as f64)
                        })
                        .sum()
                })
                .collect()
        })
        .collect()
}

/// Σ_kx w_kx·Re(T[kx]·e^{2πi kx x / nx}), the real inverse DFT along x at `x`.
fn evaluate_row(fft: &RealFft2, row: &[Complex64], x: f64) -> f64 {
    let nx = fft.nx();
    let tau = 2.0 * std::f64::consts::PI;
    let weight = |kx: usize| {
        if kx == 0 || (nx % 2 == 0 && kx == nx / 2) {
            1.0
        } else {
            2.0
        }
    };
    row.iter()
        .enumerate()
        .map(|(kx, c)| {
            weight(kx) * (c * Complex64::from_polar(1.0, tau * kx as f64 * x / nx as f64)).re
        })
        .sum()
}

/// One of the eight symmetries of the square: optional transpose, then optional flips.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Dihedral {
    /// Swap x and y first (only for square images).
    pub transpose: bool,
    /// Mirror left–right.
    pub flip_x: bool,
    /// Mirror top–bottom.
    pub flip_y: bool,
}

impl Dihedral {
    /// The identity.
    pub const IDENTITY: Dihedral = Dihedral {
        transpose: false,
        flip_x: false,
        flip_y: false,
    };

    /// All eight transforms (identity first), or the four that keep a non-square shape.
    pub fn all(square: bool) -> Vec<Dihedral> {
        let mut out = Vec::new();
        for transpose in [false, true] {
            if transpose && !square {
                continue;
            }
            for flip_y in [false, true] {
                for flip_x in [false, true] {
                    out.push(Dihedral {
                        transpose,
                        flip_x,
                        flip_y,
                    });
                }
            }
        }
        out
    }

    /// Short name: `identity`, or the steps joined by `+` (`transpose+flip-x`).
    pub fn name(&self) -> String {
        let steps: Vec<&str> = [
            (self.transpose, "transpose"),
            (self.flip_x, "flip-x"),
            (self.flip_y, "flip-y"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, s)| *s)
        .collect();
        if steps.is_empty() {
            "identity".into()
        } else {
            steps.join("+")
        }
    }

    /// Apply to a row-major image; returns the image and its new (width, height).
    pub fn apply(&self, img: &[f64], width: usize, height: usize) -> (Vec<f64>, usize, usize) {
        let (w, h) = if self.transpose {
            (height, width)
        } else {
            (width, height)
        };
        let out = (0..w * h)
            .map(|i| {
                let (mut x, mut y) = (i % w, i / w);
                if self.flip_x {
                    x = w - 1 - x;
                }
                if self.flip_y {
                    y = h - 1 - y;
                }
                let (sx, sy) = if self.transpose { (y, x) } else { (x, y) };
                img[sy * width + sx]
            })
            .collect();
        (out, w, h)
    }
}

/// Phase-correlate every dihedral transform of `moving` with `reference` and keep the one with
/// the highest peak (the identity wins ties). With `dihedral == false` only the identity is tried.
pub fn register(
    reference: &[f64],
    moving: &[f64],
    size: (usize, usize),
    upsample: usize,
    dihedral: bool,
) -> Result<(Dihedral, Shift)> {
    let candidates = if dihedral {
        Dihedral::all(size.0 == size.1)
    } else {
        vec![Dihedral::IDENTITY]
    };
    let mut best: Option<(Dihedral, Shift)> = None;
    for d in candidates {
        let (img, w, h) = d.apply(moving, size.0, size.1);
        let coarse = phase_correlation(reference, &img, (w, h), 1, Window::Hann)?;
        if best.is_none_or(|(_, b)| coarse.peak > b.peak * (1.0 + 1e-9)) {
            best = Some((d, coarse));
        }
    }
    let (d, _) = best.expect("at least the identity");
    let (img, w, h) = d.apply(moving, size.0, size.1);
    Ok((
        d,
        phase_correlation(reference, &img, (w, h), upsample, Window::Hann)?,
    ))
}

/// `img` translated by (dx, dy) pixels with bilinear interpolation: `out(x, y) = img(x − dx, y − dy)`;
/// samples from outside the image are `fill`.
pub fn translate(
    img: &[f64],
    (width, height): (usize, usize),
    (dx, dy): (f64, f64),
    fill: f64,
) -> Vec<f64> {
    let sample = |x: i64, y: i64| {
        if (0..width as i64).contains(&x) && (0..height as i64).contains(&y) {
            img[y as usize * width + x as usize]
        } else {
            fill
        }
    };
    (0..width * height)
        .map(|i| {
            let (sx, sy) = ((i % width) as f64 - dx, (i / width) as f64 - dy);
            let (x0, y0) = (sx.floor(), sy.floor());
            let (fx, fy) = (sx - x0, sy - y0);
            let (x0, y0) = (x0 as i64, y0 as i64);
            let top = sample(x0, y0) * (1.0 - fx) + sample(x0 + 1, y0) * fx;
            let bottom = sample(x0, y0 + 1) * (1.0 - fx) + sample(x0 + 1, y0 + 1) * fx;
            top * (1.0 - fy) + bottom * fy
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    pub(super) fn random_image(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let noise: Vec<f64> = (0..n * n).map(|_| rng.random_range(0.0..1.0)).collect();
        crate::optics::blur::isotropic_blur(&noise, n, n, 1.5)
    }

    pub(super) fn circular_shift(img: &[f64], n: usize, dx: i64, dy: i64) -> Vec<f64> {
        let n_i = n as i64;
        (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as i64, (i / n) as i64);
                img[((y - dy).rem_euclid(n_i) * n_i + (x - dx).rem_euclid(n_i)) as usize]
            })
            .collect()
    }

    /// Shift by a Fourier phase ramp: an exact sub-pixel translation of a periodic image.
    pub(super) fn fourier_shift(img: &[f64], n: usize, dx: f64, dy: f64) -> Vec<f64> {
        let fft = RealFft2::new(n, n);
        let mut input = img.to_vec();
        let mut spec = fft.make_spectrum();
        fft.forward(&mut input, &mut spec);
        for (i, c) in spec.iter_mut().enumerate() {
            let (kx, ky) = fft.wavenumbers(i);
            let mut phase =
                -2.0 * std::f64::consts::PI * (kx as f64 * dx + ky as f64 * dy) / n as f64;
            if n % 2 == 0 && kx as usize == n / 2 {
                phase = 0.0; // a Nyquist column cannot carry a sub-pixel phase in a real image
            }
            *c *= Complex64::from_polar(1.0, phase);
        }
        let mut out = vec![0.0; n * n];
        fft.inverse(&mut spec, &mut out);
        out.iter().map(|v| v / (n * n) as f64).collect()
    }

    /// docs/validation.md B18: integer circular shift (17, −9) exactly, with the documented sign.
    #[test]
    fn b18_integer_shift_is_exact() {
        let n = 256;
        let reference = random_image(n, 1);
        let moving = circular_shift(&reference, n, 17, -9);
        let s = phase_correlation(&reference, &moving, (n, n), 1, Window::None).unwrap();
        assert_eq!((s.dx, s.dy), (17.0, -9.0));
        assert!(s.peak > 0.99, "{}", s.peak);
    }

    /// docs/validation.md B18: a Fourier-shifted (−2.4, 1.32) px copy is found to ±0.05 px with
    /// upsampling 20.
    #[test]
    fn b18_subpixel_shift_with_upsampling() {
        let n = 128;
        let reference = random_image(n, 2);
        let moving = fourier_shift(&reference, n, -2.4, 1.32);
        let s = phase_correlation(&reference, &moving, (n, n), 20, Window::None).unwrap();
        assert!(
            (s.dx + 2.4).abs() <= 0.05 && (s.dy - 1.32).abs() <= 0.05,
            "{s:?}"
        );
        let s = phase_correlation(&reference, &moving, (n, n), 20, Window::Hann).unwrap();
        assert!(
            (s.dx + 2.4).abs() <= 0.05 && (s.dy - 1.32).abs() <= 0.05,
            "{s:?}"
        );
    }

    /// docs/validation.md B18: a mirrored copy is found only with the dihedral search on.
    #[test]
    fn b18_mirror_found_only_with_dihedral_search() {
        let n = 96;
        let reference = random_image(n, 3);
        let mirrored = Dihedral {
            transpose: true,
            flip_x: true,
            flip_y: false,
        };
        let (image, _, _) = mirrored.apply(&reference, n, n);
        let moving = circular_shift(&image, n, 5, 3);
        let (d, s) = register(&reference, &moving, (n, n), 10, true).unwrap();
        // Undo: applying the found transform to `moving` must map it back onto `reference`.
        let (back, _, _) = d.apply(&moving, n, n);
        let undone = phase_correlation(&reference, &back, (n, n), 1, Window::None).unwrap();
        assert!(undone.peak > 0.99, "{d:?} {s:?} {undone:?}");
        let (_, plain) = register(&reference, &moving, (n, n), 1, false).unwrap();
        assert!(
            plain.peak < 0.3,
            "without the search the match is poor: {plain:?}"
        );
    }

    #[test]
    fn dihedral_group_has_eight_distinct_members() {
        let img: Vec<f64> = (0..12).map(f64::from).collect();
        let square: Vec<f64> = (0..9).map(f64::from).collect();
        let results: Vec<Vec<f64>> = Dihedral::all(true)
            .iter()
            .map(|d| d.apply(&square, 3, 3).0)
            .collect();
        for (i, a) in results.iter().enumerate() {
            for b in &results[i + 1..] {
                assert_ne!(a, b);
            }
        }
        assert_eq!(Dihedral::all(false).len(), 4);
        let (t, w, h) = Dihedral {
            transpose: true,
            flip_x: false,
            flip_y: false,
        }
        .apply(&img, 4, 3);
        assert_eq!((w, h), (3, 4));
        assert_eq!(t[1], img[4]);
        assert_eq!(Dihedral::IDENTITY.name(), "identity");
    }

    #[test]
    fn translate_moves_content_by_the_shift() {
        let (w, h) = (6, 5);
        let mut img = vec![0.0; w * h];
        img[2 * w + 2] = 1.0;
        let out = translate(&img, (w, h), (1.5, -1.0), 0.0);
        assert!((out[w + 3] - 0.5).abs() < 1e-12 && (out[w + 4] - 0.5).abs() < 1e-12);
        assert!((out.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }
}
