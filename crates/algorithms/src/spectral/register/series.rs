//! Registration of a whole load series at once (docs/methods.md §8, "Registration").
//!
//! The sample does not move between the loads of a series (Weber et al. 2018: one sphere,
//! pressed on one spot of the glass, imaged at each load), so one translation places every
//! simulated map. Registering each load on its own lets a load whose simulated contact matches
//! the micrograph poorly (a model whose disc is much wider than the measured one has no edge to
//! align) lock onto a spurious peak anywhere in the field. Here:
//!
//! 1. **Series shift.** Per dihedral transform, the normalised cross-power spectra
//!    R_i = F_mov,i·F_ref,i*/|F_mov,i·F_ref,i*| of all loads are averaged; the inverse DFT of the
//!    mean is the mean of the loads' phase-correlation surfaces, so the true offset, common to
//!    all loads, adds up while each load's spurious peaks, at different places, average out.
//!    Its highest peak (over the transforms, the identity winning ties) is the series shift,
//!    refined to 1/`upsample` px by the upsampled DFT of [`super`] (Guizar-Sicairos et al.
//!    2008); its height is the mean of the loads' correlations there.
//! 2. **Per-load refinement.** Each load's own correlation surface is searched only within
//!    ±`window_px` pixels of the series' integer peak and refined to 1/`upsample` px inside that
//!    window, so a load's shift can never leave it. The load keeps the series shift instead
//!    ([`Refinement`]) when its best point lies on the window's edge (it has no maximum of its
//!    own near the series shift) or its peak there is below `min_load_peak` (a peak the
//!    correlation surface's noise reaches as well).
//!
//! Everything is deterministic: fixed scan orders, the first of equal maxima wins.

use rustfft::num_complex::Complex64;

use super::{
    check_upsample, correlation, correlation_at, cross_power, highest, refine, signed_position,
    spectrum, Dihedral, Shift, Window,
};
use crate::error::{Error, Result};
use crate::spectral::RealFft2;

/// How a series is registered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeriesOptions {
    /// Sub-pixel resolution, 1/`upsample` px (1 ..= [`super::MAX_UPSAMPLE`]).
    pub upsample: usize,
    /// Try the 8 dihedral transforms (4 for non-square images); otherwise only the identity.
    pub dihedral: bool,
    /// Half-width of the per-load refinement window around the series shift, pixels (≥ 1, and
    /// the window no wider than the image).
    pub window_px: usize,
    /// A load moves away from the series shift only when its own normalised correlation at its
    /// refined shift reaches this (a weaker peak is not told apart from the noise of the
    /// correlation surface).
    pub min_load_peak: f64,
}

/// Where a load's shift comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refinement {
    /// The load's own correlation maximum inside the window.
    Refined,
    /// The series shift: the load's own peak inside the window is below
    /// [`SeriesOptions::min_load_peak`].
    WeakPeak,
    /// The series shift: the load's best point inside the window, not a weak one, lies on its
    /// edge (no maximum of its own near the series shift; the sample may have moved, or the
    /// map matches poorly).
    WindowEdge,
}

impl Refinement {
    /// `refined`, `weak-peak` or `window-edge`.
    pub fn name(self) -> &'static str {
        match self {
            Refinement::Refined => "refined",
            Refinement::WeakPeak => "weak-peak",
            Refinement::WindowEdge => "window-edge",
        }
    }
}

/// One load's registration within a series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadShift {
    /// The load's shift (`moving(x, y) ≈ reference(x − dx, y − dy)`, as
    /// [`super::phase_correlation`]) and its own normalised correlation there (1 = perfect).
    pub shift: Shift,
    /// Where the shift comes from.
    pub refinement: Refinement,
}

/// The result of [`register_series`].
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesRegistration {
    /// The transform applied to every moving image before the shift.
    pub transform: Dihedral,
    /// The series shift and the peak of the mean correlation surface (the mean of the loads'
    /// correlations at that shift).
    pub series: Shift,
    /// Half-width of the refinement window, pixels.
    pub window_px: usize,
    /// One per pair, in order.
    pub loads: Vec<LoadShift>,
}

/// Register a series of `(reference, moving)` pairs of one size (`height` rows of `width`):
/// one dihedral transform and one shift for the series from the mean normalised cross-power
/// spectrum, then each load refined within ±`window_px` pixels of it (module documentation).
/// Images are mean-subtracted and Hann-windowed.
pub fn register_series(
    pairs: &[(&[f64], &[f64])],
    (width, height): (usize, usize),
    options: &SeriesOptions,
) -> Result<SeriesRegistration> {
    let SeriesOptions {
        upsample,
        dihedral,
        window_px,
        ..
    } = *options;
    check_upsample(upsample)?;
    if pairs.is_empty() {
        return Err(Error::TooFew {
            what: "image pairs to register",
            needed: 1,
            got: 0,
        });
    }
    let n = width * height;
    if width < 2 || height < 2 {
        return Err(Error::InvalidArgument(format!(
            "registration needs images of at least 2×2 pixels, got {width}×{height}"
        )));
    }
    for (reference, moving) in pairs {
        for got in [reference.len(), moving.len()] {
            if got != n {
                return Err(Error::SizeMismatch {
                    what: "pixels of an image to register",
                    expected: n,
                    got,
                });
            }
        }
    }
    if !options.min_load_peak.is_finite() {
        return Err(Error::Value {
            what: "smallest correlation peak of a refined load",
            value: options.min_load_peak,
            unit: "",
            requirement: "must be finite",
        });
    }
    if window_px == 0 || 2 * window_px + 1 > width.min(height) {
        return Err(Error::InvalidArgument(format!(
            "a registration window of ±{window_px} px: give 1 to {} for {width}×{height} images",
            (width.min(height) - 1) / 2
        )));
    }
    let fft = RealFft2::new(height, width);
    let references: Vec<Vec<Complex64>> = pairs
        .iter()
        .map(|(r, _)| spectrum(&fft, r, Window::Hann))
        .collect();
    let candidates = if dihedral {
        Dihedral::all(width == height)
    } else {
        vec![Dihedral::IDENTITY]
    };
    let mut best: Option<Candidate> = None;
    for transform in candidates {
        let crosses: Vec<Vec<Complex64>> = pairs
            .iter()
            .zip(&references)
            .map(|((_, moving), reference)| {
                let (img, _, _) = transform.apply(moving, width, height);
                cross_power(&fft, reference, &img, Window::Hann)
            })
            .collect();
        let mean = mean_spectrum(&crosses);
        let (index, peak) = highest(&correlation(&fft, &mean));
        if best.as_ref().is_none_or(|b| peak > b.peak * (1.0 + 1e-9)) {
            best = Some(Candidate {
                transform,
                crosses,
                mean,
                index,
                peak,
            });
        }
    }
    let best = best.expect("at least the identity");
    let coarse = signed_position(best.index, (width, height));
    let (sx, sy, series_peak) = if upsample > 1 {
        refine(&fft, &best.mean, coarse, upsample, None)
    } else {
        (coarse.0, coarse.1, best.peak)
    };
    let series = Shift {
        dx: sx,
        dy: sy,
        peak: series_peak / n as f64,
    };
    let loads = best
        .crosses
        .iter()
        .map(|cross| refine_load(&fft, cross, coarse, series, options))
        .collect();
    Ok(SeriesRegistration {
        transform: best.transform,
        series,
        window_px,
        loads,
    })
}

/// One transform's cross spectra, their mean, and the mean surface's integer peak.
struct Candidate {
    transform: Dihedral,
    crosses: Vec<Vec<Complex64>>,
    mean: Vec<Complex64>,
    index: usize,
    peak: f64,
}

fn mean_spectrum(crosses: &[Vec<Complex64>]) -> Vec<Complex64> {
    let scale = 1.0 / crosses.len() as f64;
    let mut mean = vec![Complex64::new(0.0, 0.0); crosses[0].len()];
    for cross in crosses {
        for (m, c) in mean.iter_mut().zip(cross) {
            *m += c;
        }
    }
    mean.iter().map(|m| m * scale).collect()
}

/// The load's highest integer point within ±`window_px` of the series' integer peak `centre`,
/// refined inside the window; the series shift when the peak is below `min_load_peak`
/// ([`Refinement::WeakPeak`]) or, stronger, lies on the window's edge
/// ([`Refinement::WindowEdge`]).
fn refine_load(
    fft: &RealFft2,
    cross: &[Complex64],
    centre: (f64, f64),
    series: Shift,
    options: &SeriesOptions,
) -> LoadShift {
    let (nx, ny) = (fft.nx() as i64, fft.ny() as i64);
    let n = fft.len() as f64;
    let corr = correlation(fft, cross);
    let w = options.window_px as i64;
    let (cx, cy) = (centre.0 as i64, centre.1 as i64);
    let mut best = ((0, 0), f64::NEG_INFINITY);
    for b in -w..=w {
        for a in -w..=w {
            let (x, y) = ((cx + a).rem_euclid(nx), (cy + b).rem_euclid(ny));
            let v = corr[(y * nx + x) as usize];
            if v > best.1 {
                best = ((a, b), v);
            }
        }
    }
    let ((a, b), value) = best;
    let at_series = |refinement| LoadShift {
        shift: Shift {
            peak: correlation_at(fft, cross, (series.dx, series.dy)) / n,
            ..series
        },
        refinement,
    };
    if a.abs() == w || b.abs() == w {
        // A peak too weak to tell from noise needs no warning, wherever it lies.
        return at_series(if value / n < options.min_load_peak {
            Refinement::WeakPeak
        } else {
            Refinement::WindowEdge
        });
    }
    let point = ((cx + a) as f64, (cy + b) as f64);
    let (dx, dy, value) = if options.upsample > 1 {
        let half = options.window_px as f64;
        let bounds = [
            (centre.0 - half, centre.0 + half),
            (centre.1 - half, centre.1 + half),
        ];
        refine(fft, cross, point, options.upsample, Some(bounds))
    } else {
        (point.0, point.1, value)
    };
    if value / n < options.min_load_peak {
        return at_series(Refinement::WeakPeak);
    }
    LoadShift {
        shift: Shift {
            dx,
            dy,
            peak: value / n,
        },
        refinement: Refinement::Refined,
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{circular_shift, fourier_shift, random_image};
    use super::super::{phase_correlation, MAX_UPSAMPLE};
    use super::*;

    const N: usize = 96;

    fn options(upsample: usize) -> SeriesOptions {
        SeriesOptions {
            upsample,
            dihedral: false,
            window_px: 3,
            min_load_peak: 0.05,
        }
    }

    /// `good` loads: a textured reference and its copy moved by `shift`; then `blank` loads: a
    /// reference and an unrelated, nearly featureless image (a faint independent texture on a
    /// constant), whose own correlation peaks anywhere.
    fn series(good: u64, blank: u64, shift: (i64, i64)) -> Vec<(Vec<f64>, Vec<f64>)> {
        let mut out = Vec::new();
        for seed in 0..good {
            let reference = random_image(N, 10 + seed);
            let moving = circular_shift(&reference, N, shift.0, shift.1);
            out.push((reference, moving));
        }
        for seed in 0..blank {
            let reference = random_image(N, 100 + seed);
            let faint: Vec<f64> = random_image(N, 200 + seed)
                .iter()
                .map(|v| 1000.0 + 1e-3 * v)
                .collect();
            out.push((reference, faint));
        }
        out
    }

    fn refs(pairs: &[(Vec<f64>, Vec<f64>)]) -> Vec<(&[f64], &[f64])> {
        pairs
            .iter()
            .map(|(r, m)| (r.as_slice(), m.as_slice()))
            .collect()
    }

    fn within_window(r: &SeriesRegistration) -> bool {
        let w = r.window_px as f64;
        r.loads.iter().all(|l| {
            (l.shift.dx - r.series.dx).abs() <= w + 0.75
                && (l.shift.dy - r.series.dy).abs() <= w + 0.75
        })
    }

    /// Two textured loads among four featureless ones: the series shift is exact, and so is
    /// every load's, although the featureless loads alone register far away.
    #[test]
    fn series_shift_is_exact_when_most_loads_are_featureless() {
        let pairs = series(2, 4, (17, -9));
        let r = register_series(&refs(&pairs), (N, N), &options(1)).unwrap();
        assert_eq!((r.series.dx, r.series.dy), (17.0, -9.0));
        assert_eq!(r.transform, Dihedral::IDENTITY);
        for (i, l) in r.loads.iter().enumerate() {
            assert_eq!((l.shift.dx, l.shift.dy), (17.0, -9.0), "load {i}: {l:?}");
            let expected = if i < 2 {
                Refinement::Refined
            } else {
                Refinement::WeakPeak
            };
            assert_eq!(l.refinement, expected, "load {i}: {l:?}");
        }
        // Registered one by one, at least one featureless load lands outside the window.
        let far = pairs[2..].iter().any(|(reference, moving)| {
            let s = phase_correlation(reference, moving, (N, N), 1, Window::Hann).unwrap();
            (s.dx - 17.0).abs() > 3.0 || (s.dy + 9.0).abs() > 3.0
        });
        assert!(
            far,
            "the featureless loads must register elsewhere on their own"
        );
        // Sub-pixel: the Hann window pulls a shift of 18 % of the side towards zero by about
        // 0.1 px, on every load alike; the featureless loads add no more than that.
        let r = register_series(&refs(&pairs), (N, N), &options(20)).unwrap();
        for s in std::iter::once(r.series).chain(r.loads.iter().map(|l| l.shift)) {
            assert!(
                (s.dx - 17.0).abs() <= 0.15 && (s.dy + 9.0).abs() <= 0.15,
                "{s:?}"
            );
        }
        assert!(within_window(&r));
    }

    /// A load that moved by a fraction of a pixel inside the window is refined to its own
    /// shift; one that moved beyond the window stays within it, at the series shift.
    #[test]
    fn loads_are_refined_inside_the_window_and_never_leave_it() {
        let mut pairs = series(3, 0, (0, 0));
        pairs[1].1 = fourier_shift(&pairs[1].0, N, 1.4, -0.6);
        pairs[2].1 = circular_shift(&pairs[2].0, N, 9, 0);
        let r = register_series(&refs(&pairs), (N, N), &options(20)).unwrap();
        let l = r.loads[1];
        assert_eq!(l.refinement, Refinement::Refined);
        assert!(
            (l.shift.dx - 1.4).abs() <= 0.05 && (l.shift.dy + 0.6).abs() <= 0.05,
            "{l:?}"
        );
        let l = r.loads[2];
        assert_ne!(l.refinement, Refinement::Refined, "{l:?}");
        assert_eq!((l.shift.dx, l.shift.dy), (r.series.dx, r.series.dy));
        assert!(within_window(&r));
        assert!(r.loads[0].shift.dx.abs() <= 0.05 && r.loads[0].shift.dy.abs() <= 0.05);
    }

    /// A mirrored series: one transform for all loads, found only with the search.
    #[test]
    fn one_dihedral_transform_for_the_series() {
        let mirror = Dihedral {
            transpose: true,
            flip_x: false,
            flip_y: true,
        };
        let pairs: Vec<(Vec<f64>, Vec<f64>)> = series(3, 0, (0, 0))
            .into_iter()
            .map(|(reference, _)| {
                let (m, _, _) = mirror.apply(&reference, N, N);
                (reference, circular_shift(&m, N, 4, 6))
            })
            .collect();
        let search = SeriesOptions {
            dihedral: true,
            ..options(1)
        };
        let r = register_series(&refs(&pairs), (N, N), &search).unwrap();
        // The found transform maps each moving image back onto its reference.
        for (reference, moving) in &pairs {
            let (back, _, _) = r.transform.apply(moving, N, N);
            let s = phase_correlation(reference, &back, (N, N), 1, Window::None).unwrap();
            assert!(s.peak > 0.99, "{:?} {s:?}", r.transform);
        }
        assert!(r.series.peak > 0.5, "{:?}", r.series);
        let plain = register_series(&refs(&pairs), (N, N), &options(1)).unwrap();
        assert!(plain.series.peak < 0.3, "{:?}", plain.series);
    }

    #[test]
    fn bad_arguments_are_errors() {
        let pairs = series(1, 0, (0, 0));
        let good = refs(&pairs);
        assert!(matches!(
            register_series(&[], (N, N), &options(1)),
            Err(Error::TooFew { got: 0, .. })
        ));
        let short = [(good[0].0, &good[0].1[1..])];
        assert!(matches!(
            register_series(&short, (N, N), &options(1)),
            Err(Error::SizeMismatch { .. })
        ));
        for window_px in [0, N / 2] {
            let o = SeriesOptions {
                window_px,
                ..options(1)
            };
            assert!(matches!(
                register_series(&good, (N, N), &o),
                Err(Error::InvalidArgument(_))
            ));
        }
        let o = SeriesOptions {
            min_load_peak: f64::NAN,
            ..options(1)
        };
        assert!(matches!(
            register_series(&good, (N, N), &o),
            Err(Error::Value { .. })
        ));
        assert!(register_series(&good, (N, N), &options(MAX_UPSAMPLE + 1)).is_err());
    }
}
