//! One bead on one plane: window, background, centre of intensity, radial profile and the two
//! Gaussian fits (Weber et al. 2018, Methods: Microscopy; `docs/methods.md` §7.3 steps 1–5).
//!
//! Pixel coordinates are pixel centres: pixel (x, y) sits at (x, y), so a spot centred between
//! two pixels has a half-integer centre.

use super::lm::{self, LmOutcome, Problem};
use crate::numerics::stats::median_in_place as median;

/// A plane as a borrowed row-major grid.
#[derive(Debug, Clone, Copy)]
pub struct PlaneView<'a> {
    /// Values, `height` rows of `width`.
    pub values: &'a [f64],
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

/// How one spot is measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpotOptions {
    /// Half-width of the square window in pixels (the window is 2·half + 1 wide).
    pub half_window_px: usize,
    /// Pixels above this fraction of the background-subtracted peak enter the centre of intensity.
    pub centroid_fraction: f64,
    /// Re-centring passes of the window on the centre of intensity.
    pub centroid_iterations: usize,
    /// Width of the radial-profile bins in pixels.
    pub bin_px: f64,
}

impl Default for SpotOptions {
    fn default() -> Self {
        SpotOptions {
            half_window_px: 9,
            centroid_fraction: 0.2,
            centroid_iterations: 3,
            bin_px: 0.5,
        }
    }
}

/// Radial-profile Gaussian I(r) = I0·exp(−r²/(2σ²)) + c, fitted to the binned radial average.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialFit {
    /// I0 above the window background.
    pub amplitude: f64,
    /// σ in pixels.
    pub sigma_px: f64,
    /// Residual offset c (after the border median was subtracted).
    pub offset: f64,
    /// RMS of the bin residuals relative to I0.
    pub rms_rel: f64,
    /// Whether Levenberg–Marquardt converged.
    pub converged: bool,
    /// Profile points (mean radius of the bin's pixels in px, mean background-subtracted value).
    pub profile: Vec<(f64, f64)>,
}

/// Axis-aligned elliptical Gaussian with a free centre, fitted to every window pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Gauss2dFit {
    /// Peak above the window background.
    pub amplitude: f64,
    /// Centre column (plane coordinates, px).
    pub x_px: f64,
    /// Centre row (plane coordinates, px).
    pub y_px: f64,
    /// σ along x in pixels.
    pub sigma_x_px: f64,
    /// σ along y in pixels.
    pub sigma_y_px: f64,
    /// Residual offset.
    pub offset: f64,
    /// RMS of the pixel residuals relative to the amplitude.
    pub rms_rel: f64,
    /// Whether Levenberg–Marquardt converged.
    pub converged: bool,
}

/// Everything measured on one spot.
#[derive(Debug, Clone, PartialEq)]
pub struct SpotFit {
    /// Centre of intensity (plane coordinates, px) after the re-centring passes.
    pub centroid_px: (f64, f64),
    /// Median of the window border (the subtracted background).
    pub background: f64,
    /// Highest background-subtracted value in the window.
    pub peak: f64,
    /// The paper's radial-profile fit.
    pub radial: RadialFit,
    /// The 2-D cross-check.
    pub gauss2d: Gauss2dFit,
}

/// Why a spot could not be measured.
#[derive(Debug, Clone, PartialEq)]
pub enum SpotFailure {
    /// The window around the spot does not fit inside the plane.
    AtEdge,
    /// No positive signal above the border background.
    NoSignal,
    /// A fit did not converge (which one).
    NotConverged(&'static str),
}

/// Measure the spot near pixel (x, y) of `grid`.
pub fn fit_spot(
    grid: PlaneView,
    x: usize,
    y: usize,
    opts: &SpotOptions,
) -> Result<SpotFit, SpotFailure> {
    let half = opts.half_window_px;
    let mut window = Window::crop(grid, x, y, half).ok_or(SpotFailure::AtEdge)?;
    let passes = opts.centroid_iterations.max(1);
    let mut centre = (x as f64, y as f64);
    for pass in 0..passes {
        centre = window
            .centroid(opts.centroid_fraction)
            .ok_or(SpotFailure::NoSignal)?;
        let (rx, ry) = (centre.0.round(), centre.1.round());
        let centred = (rx, ry) == ((window.x0 + half) as f64, (window.y0 + half) as f64);
        if centred || pass + 1 == passes {
            break;
        }
        if rx < 0.0 || ry < 0.0 {
            return Err(SpotFailure::AtEdge);
        }
        window = Window::crop(grid, rx as usize, ry as usize, half).ok_or(SpotFailure::AtEdge)?;
    }
    let (cx, cy) = centre;
    let radial = fit_radial(&window, (cx, cy), opts.bin_px)?;
    let gauss2d = fit_gauss2d(&window, (cx, cy), radial.sigma_px)?;
    Ok(SpotFit {
        centroid_px: (cx, cy),
        background: window.background,
        peak: window.peak(),
        radial,
        gauss2d,
    })
}

/// A background-subtracted square crop.
struct Window {
    /// Plane coordinates of the crop's first pixel.
    x0: usize,
    y0: usize,
    size: usize,
    values: Vec<f64>,
    background: f64,
}

impl Window {
    fn crop(grid: PlaneView, x: usize, y: usize, half: usize) -> Option<Window> {
        if x < half || y < half || x + half >= grid.width || y + half >= grid.height {
            return None;
        }
        let (x0, y0, size) = (x - half, y - half, 2 * half + 1);
        let mut values = Vec::with_capacity(size * size);
        for row in y0..y0 + size {
            values.extend_from_slice(
                &grid.values[row * grid.width + x0..row * grid.width + x0 + size],
            );
        }
        // Median of the border ring: robust to a neighbour's tail entering one side.
        let mut border: Vec<f64> = (0..size * size)
            .filter(|i| {
                let (c, r) = (i % size, i / size);
                c == 0 || r == 0 || c == size - 1 || r == size - 1
            })
            .map(|i| values[i])
            .collect();
        let background = median(&mut border);
        values.iter_mut().for_each(|v| *v -= background);
        Some(Window {
            x0,
            y0,
            size,
            values,
            background,
        })
    }

    fn peak(&self) -> f64 {
        self.values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Plane coordinates of window pixel i.
    fn coords(&self, i: usize) -> (f64, f64) {
        (
            (self.x0 + i % self.size) as f64,
            (self.y0 + i / self.size) as f64,
        )
    }

    /// Centre of intensity over pixels above `fraction` of the peak (plane coordinates).
    ///
    /// The weights are the values minus the cut level, so they fall continuously to zero at the
    /// cut: with the plain values, whether a pixel just above the cut enters is decided by the
    /// pixel grid, and B15's spot (σ = 2 px, centre (20.37, 19.81)) comes out 0.09 px off
    /// instead of 0.002 px, widening its radial profile's σ by 1.5e-3 px.
    fn centroid(&self, fraction: f64) -> Option<(f64, f64)> {
        let peak = self.peak();
        if peak.is_nan() || peak <= 0.0 {
            return None;
        }
        let cut = fraction * peak;
        let (mut sw, mut sx, mut sy) = (0.0, 0.0, 0.0);
        for (i, &v) in self.values.iter().enumerate() {
            if v > cut {
                let (x, y) = self.coords(i);
                sw += v - cut;
                sx += (v - cut) * x;
                sy += (v - cut) * y;
            }
        }
        (sw > 0.0).then(|| (sx / sw, sy / sw))
    }
}

/// Pixels of a window grouped into radial bins, out to the inscribed circle.
struct RadialBins {
    /// Per bin, the squared radii of its pixels.
    r2: Vec<Vec<f64>>,
    /// Per bin, the mean pixel value.
    mean: Vec<f64>,
}

impl RadialBins {
    fn new(window: &Window, centre: (f64, f64), bin_px: f64) -> RadialBins {
        let r_max = (window.size / 2) as f64;
        let n_bins = (r_max / bin_px).ceil() as usize;
        let (mut r2, mut sum) = (vec![Vec::new(); n_bins], vec![0.0; n_bins]);
        for (i, &v) in window.values.iter().enumerate() {
            let (x, y) = window.coords(i);
            let d2 = (x - centre.0).powi(2) + (y - centre.1).powi(2);
            let bin = (d2.sqrt() / bin_px) as usize;
            if d2.sqrt() < r_max && bin < n_bins {
                r2[bin].push(d2);
                sum[bin] += v;
            }
        }
        let keep: Vec<usize> = (0..n_bins).filter(|&b| !r2[b].is_empty()).collect();
        RadialBins {
            mean: keep.iter().map(|&b| sum[b] / r2[b].len() as f64).collect(),
            r2: keep
                .into_iter()
                .map(|b| std::mem::take(&mut r2[b]))
                .collect(),
        }
    }

    /// (mean radius, mean value) per bin, for plots.
    fn profile(&self) -> Vec<(f64, f64)> {
        self.r2
            .iter()
            .zip(&self.mean)
            .map(|(r2, &m)| {
                (
                    r2.iter().map(|v| v.sqrt()).sum::<f64>() / r2.len() as f64,
                    m,
                )
            })
            .collect()
    }
}

/// The model is averaged over each bin's pixels exactly as the data are, so binning adds no
/// bias (a Gaussian evaluated at a bin's mean radius would not equal the bin's mean); bins are
/// weighted by √(pixel count), the inverse standard error of their mean under uniform noise.
impl Problem for RadialBins {
    fn residual_count(&self) -> usize {
        self.mean.len()
    }

    fn evaluate(&self, p: &[f64], r: &mut [f64], j: &mut [f64]) {
        let (i0, sigma, c) = (p[0], p[1], p[2]);
        let s2 = sigma * sigma;
        for (b, (r2s, &m)) in self.r2.iter().zip(&self.mean).enumerate() {
            let n = r2s.len() as f64;
            let (mut e_sum, mut de_sum) = (0.0, 0.0);
            for &r2 in r2s {
                let e = (-r2 / (2.0 * s2)).exp();
                e_sum += e;
                de_sum += e * r2 / (s2 * sigma);
            }
            let w = n.sqrt();
            r[b] = w * (i0 * e_sum / n + c - m);
            j[3 * b] = w * e_sum / n;
            j[3 * b + 1] = w * i0 * de_sum / n;
            j[3 * b + 2] = w;
        }
    }
}

/// σ from the second moment of the pixels above `fraction` of the peak. For a Gaussian cut at
/// level f, ⟨r²⟩ = 2σ²·(1 − u·f/(1 − f)) with u = ln(1/f); dividing that factor out gives an
/// unbiased start for noise-free spots.
fn second_moment_sigma(window: &Window, centre: (f64, f64), fraction: f64) -> f64 {
    let peak = window.peak();
    let (mut sw, mut sr2) = (0.0, 0.0);
    for (i, &v) in window.values.iter().enumerate() {
        if v > fraction * peak {
            let (x, y) = window.coords(i);
            sw += v;
            sr2 += v * ((x - centre.0).powi(2) + (y - centre.1).powi(2));
        }
    }
    let u = (1.0 / fraction).ln();
    let factor = 2.0 * (1.0 - u * fraction / (1.0 - fraction));
    (sr2 / sw / factor).sqrt().max(0.5)
}

fn fit_radial(window: &Window, centre: (f64, f64), bin_px: f64) -> Result<RadialFit, SpotFailure> {
    let bins = RadialBins::new(window, centre, bin_px);
    if bins.mean.len() < 4 {
        return Err(SpotFailure::NoSignal);
    }
    let start = [window.peak(), second_moment_sigma(window, centre, 0.2), 0.0];
    let out = lm::minimise(&bins, &start, 200);
    if !out.converged {
        return Err(SpotFailure::NotConverged("radial-profile fit"));
    }
    let (amplitude, sigma_px, offset) = (out.params[0], out.params[1].abs(), out.params[2]);
    let rms_rel = rms_of_bins(&bins, &out) / amplitude.abs();
    Ok(RadialFit {
        amplitude,
        sigma_px,
        offset,
        rms_rel,
        converged: true,
        profile: bins.profile(),
    })
}

/// Unweighted RMS of bin residuals (the fit residuals carry √n weights).
fn rms_of_bins(bins: &RadialBins, out: &LmOutcome) -> f64 {
    let mut r = vec![0.0; bins.mean.len()];
    let mut j = vec![0.0; 3 * bins.mean.len()];
    bins.evaluate(&out.params, &mut r, &mut j);
    let sq: f64 = r
        .iter()
        .zip(&bins.r2)
        .map(|(v, r2)| v * v / r2.len() as f64)
        .sum();
    (sq / r.len() as f64).sqrt()
}

/// Pixels of a window for the 2-D fit.
struct Pixels<'a>(&'a Window);

impl Problem for Pixels<'_> {
    fn residual_count(&self) -> usize {
        self.0.values.len()
    }

    fn evaluate(&self, p: &[f64], r: &mut [f64], j: &mut [f64]) {
        let (a, x0, y0, sx, sy, c) = (p[0], p[1], p[2], p[3], p[4], p[5]);
        for (i, &v) in self.0.values.iter().enumerate() {
            let (x, y) = self.0.coords(i);
            let (dx, dy) = (x - x0, y - y0);
            let e = (-(dx * dx) / (2.0 * sx * sx) - (dy * dy) / (2.0 * sy * sy)).exp();
            r[i] = a * e + c - v;
            let row = &mut j[6 * i..6 * i + 6];
            row[0] = e;
            row[1] = a * e * dx / (sx * sx);
            row[2] = a * e * dy / (sy * sy);
            row[3] = a * e * dx * dx / (sx * sx * sx);
            row[4] = a * e * dy * dy / (sy * sy * sy);
            row[5] = 1.0;
        }
    }
}

fn fit_gauss2d(window: &Window, centre: (f64, f64), sigma: f64) -> Result<Gauss2dFit, SpotFailure> {
    let start = [window.peak(), centre.0, centre.1, sigma, sigma, 0.0];
    let out = lm::minimise(&Pixels(window), &start, 200);
    if !out.converged {
        return Err(SpotFailure::NotConverged("2-D Gaussian fit"));
    }
    let p = &out.params;
    Ok(Gauss2dFit {
        amplitude: p[0],
        x_px: p[1],
        y_px: p[2],
        sigma_x_px: p[3].abs(),
        sigma_y_px: p[4].abs(),
        offset: p[5],
        rms_rel: (out.cost / window.values.len() as f64).sqrt() / p[0].abs(),
        converged: true,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(size: usize, centre: (f64, f64), sigma: (f64, f64)) -> Vec<f64> {
        (0..size * size)
            .map(|i| {
                let (x, y) = ((i % size) as f64 - centre.0, (i / size) as f64 - centre.1);
                10.0 + 1000.0
                    * (-x * x / (2.0 * sigma.0 * sigma.0) - y * y / (2.0 * sigma.1 * sigma.1)).exp()
            })
            .collect()
    }

    #[test]
    fn elliptical_spot_gives_both_sigmas() {
        let values = spot(41, (20.3, 19.6), (2.0, 3.0));
        let grid = PlaneView {
            values: &values,
            width: 41,
            height: 41,
        };
        let opts = SpotOptions {
            half_window_px: 15,
            ..SpotOptions::default()
        };
        let fit = fit_spot(grid, 20, 20, &opts).unwrap();
        assert!(
            (fit.gauss2d.sigma_x_px - 2.0).abs() < 1e-6,
            "{:?}",
            fit.gauss2d
        );
        assert!(
            (fit.gauss2d.sigma_y_px - 3.0).abs() < 1e-6,
            "{:?}",
            fit.gauss2d
        );
        // The radial average of an ellipse lies between its two σ.
        assert!(fit.radial.sigma_px > 2.0 && fit.radial.sigma_px < 3.0);
        assert!((fit.background - 10.0).abs() < 1.0);
    }

    #[test]
    fn window_off_the_plane_is_at_edge() {
        let values = spot(21, (3.0, 10.0), (2.0, 2.0));
        let grid = PlaneView {
            values: &values,
            width: 21,
            height: 21,
        };
        assert_eq!(
            fit_spot(grid, 3, 10, &SpotOptions::default()),
            Err(SpotFailure::AtEdge)
        );
    }

    #[test]
    fn flat_window_has_no_signal() {
        let values = vec![5.0; 21 * 21];
        let grid = PlaneView {
            values: &values,
            width: 21,
            height: 21,
        };
        assert_eq!(
            fit_spot(grid, 10, 10, &SpotOptions::default()),
            Err(SpotFailure::NoSignal)
        );
    }
}
