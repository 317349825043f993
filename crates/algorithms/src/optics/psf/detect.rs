//! Bead candidates: local maxima of the lightly smoothed image (or of the maximum projection of
//! the smoothed planes of a stack) well above a robust background, with each bead's best-focus
//! plane and a first guess of the spot width that sizes the fitting window.

use crate::optics::blur::isotropic_blur;

use crate::numerics::stats::median_in_place as median;

/// How candidates are found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectOptions {
    /// σ of the Gaussian smoothing before detection, pixels (suppresses single-pixel noise).
    pub smoothing_px: f64,
    /// A candidate must exceed the background by this many robust noise units …
    pub noise_factor: f64,
    /// … and by this fraction of the brightest spot's height (so that the faint halo of a bright
    /// bead, or a noise ripple, does not count as a neighbour).
    pub relative_height: f64,
}

impl Default for DetectOptions {
    fn default() -> Self {
        DetectOptions {
            smoothing_px: 1.0,
            noise_factor: 10.0,
            relative_height: 0.02,
        }
    }
}

/// One local maximum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Column.
    pub x: usize,
    /// Row.
    pub y: usize,
    /// Index of the plane (within the stack) where the smoothed value at (x, y) is highest.
    pub plane: usize,
    /// Smoothed value there.
    pub smoothed_peak: f64,
}

/// The result of detection.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Candidates, brightest first.
    pub candidates: Vec<Candidate>,
    /// Median of the (projected) smoothed image.
    pub background: f64,
    /// 1.4826 × median absolute deviation of the same.
    pub noise: f64,
    /// Detection level.
    pub threshold: f64,
    /// Median spot σ estimated from the half-maximum areas, pixels (smoothing removed).
    pub sigma_guess_px: f64,
}

/// Find bead candidates on `planes` (one plane for a 2-D image), each `width × height`.
pub fn detect(planes: &[&[f64]], width: usize, height: usize, opts: &DetectOptions) -> Detection {
    let (projection, best_plane) = smoothed_projection(planes, width, height, opts.smoothing_px);
    let background = median(&mut projection.clone());
    let noise = 1.4826
        * median(
            &mut projection
                .iter()
                .map(|v| (v - background).abs())
                .collect::<Vec<_>>(),
        );
    let top = projection.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let threshold =
        background + (opts.noise_factor * noise).max(opts.relative_height * (top - background));
    let mut candidates: Vec<Candidate> = local_maxima(&projection, width, height)
        .into_iter()
        .filter(|&i| projection[i] > threshold && projection[i] > background)
        .map(|i| Candidate {
            x: i % width,
            y: i / width,
            plane: best_plane[i],
            smoothed_peak: projection[i],
        })
        .collect();
    candidates.sort_by(|a, b| b.smoothed_peak.total_cmp(&a.smoothed_peak));
    let mut widths: Vec<f64> = candidates
        .iter()
        .map(|c| half_max_sigma(&projection, width, height, c, background, opts.smoothing_px))
        .collect();
    let sigma_guess_px = median(&mut widths);
    // Two maxima closer than about σ belong to one noisy spot, not to two beads.
    let candidates = suppress_near(candidates, sigma_guess_px.max(1.5));
    Detection {
        candidates,
        background,
        noise,
        threshold,
        sigma_guess_px,
    }
}

/// Per-pixel maximum over the smoothed planes, and the plane it came from.
fn smoothed_projection(
    planes: &[&[f64]],
    width: usize,
    height: usize,
    sigma: f64,
) -> (Vec<f64>, Vec<usize>) {
    let mut projection = vec![f64::NEG_INFINITY; width * height];
    let mut best = vec![0; width * height];
    for (k, plane) in planes.iter().enumerate() {
        let smooth = isotropic_blur(plane, width, height, sigma);
        for (i, &v) in smooth.iter().enumerate() {
            if v > projection[i] {
                projection[i] = v;
                best[i] = k;
            }
        }
    }
    (projection, best)
}

/// Indices of pixels not exceeded by any 8-neighbour; of equal neighbours only the first (in
/// row-major order) counts, so a flat-topped spot yields one maximum.
fn local_maxima(v: &[f64], width: usize, height: usize) -> Vec<usize> {
    let mut out = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let is_max =
                neighbours(x, y, width, height).all(|j| v[j] < v[i] || (v[j] == v[i] && j > i));
            if is_max {
                out.push(i);
            }
        }
    }
    out
}

fn neighbours(x: usize, y: usize, width: usize, height: usize) -> impl Iterator<Item = usize> {
    let (x, y) = (x as isize, y as isize);
    (-1..=1isize)
        .flat_map(move |dy| (-1..=1isize).map(move |dx| (x + dx, y + dy)))
        .filter(move |&(nx, ny)| {
            (nx, ny) != (x, y) && nx >= 0 && ny >= 0 && nx < width as isize && ny < height as isize
        })
        .map(move |(nx, ny)| ny as usize * width + nx as usize)
}

/// σ of a spot from the area A of its connected region above half its height:
/// A = 2π ln2 · σ_s² for a Gaussian; the smoothing's σ² is then subtracted.
fn half_max_sigma(
    v: &[f64],
    width: usize,
    height: usize,
    c: &Candidate,
    background: f64,
    smoothing: f64,
) -> f64 {
    const MAX_RADIUS: usize = 40;
    let level = background + 0.5 * (c.smoothed_peak - background);
    // `seen` covers only the box the flood may reach, so many candidates on a large image stay cheap.
    let side = 2 * MAX_RADIUS + 1;
    let local = |i: usize| {
        let (x, y) = (i % width + MAX_RADIUS - c.x, i / width + MAX_RADIUS - c.y);
        y * side + x
    };
    let mut seen = vec![false; side * side];
    let start = c.y * width + c.x;
    let mut stack = vec![start];
    seen[local(start)] = true;
    let mut area = 0usize;
    while let Some(i) = stack.pop() {
        area += 1;
        let (x, y) = (i % width, i / width);
        for j in neighbours(x, y, width, height) {
            let (jx, jy) = (j % width, j / width);
            let near = jx.abs_diff(c.x) <= MAX_RADIUS && jy.abs_diff(c.y) <= MAX_RADIUS;
            let four_connected = jx == x || jy == y;
            if near && four_connected && !seen[local(j)] && v[j] >= level {
                seen[local(j)] = true;
                stack.push(j);
            }
        }
    }
    let sigma_s2 = area as f64 / (2.0 * std::f64::consts::PI * std::f64::consts::LN_2);
    (sigma_s2 - smoothing * smoothing).max(0.25).sqrt()
}

/// Keep the brightest of candidates closer than `radius` (Euclidean, pixels).
fn suppress_near(sorted: Vec<Candidate>, radius: f64) -> Vec<Candidate> {
    let mut kept: Vec<Candidate> = Vec::new();
    for c in sorted {
        let close = kept.iter().any(|k| {
            let (dx, dy) = (k.x as f64 - c.x as f64, k.y as f64 - c.y as f64);
            dx * dx + dy * dy < radius * radius
        });
        if !close {
            kept.push(c);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_spots(width: usize, height: usize) -> Vec<f64> {
        (0..width * height)
            .map(|i| {
                let (x, y) = ((i % width) as f64, (i / width) as f64);
                let g = |cx: f64, cy: f64, a: f64| {
                    a * (-((x - cx).powi(2) + (y - cy).powi(2)) / 8.0).exp()
                };
                100.0 + g(15.0, 20.0, 500.0) + g(45.0, 30.0, 800.0)
            })
            .collect()
    }

    #[test]
    fn finds_two_spots_and_their_width() {
        let image = two_spots(64, 48);
        let d = detect(&[&image], 64, 48, &DetectOptions::default());
        let found: Vec<(usize, usize)> = d.candidates.iter().map(|c| (c.x, c.y)).collect();
        assert_eq!(found, vec![(45, 30), (15, 20)]);
        assert!((d.background - 100.0).abs() < 1.0);
        assert!((d.sigma_guess_px - 2.0).abs() < 0.5, "{}", d.sigma_guess_px);
    }

    #[test]
    fn best_plane_is_the_brightest() {
        let image = two_spots(64, 48);
        let dim: Vec<f64> = image.iter().map(|v| 100.0 + (v - 100.0) * 0.5).collect();
        let d = detect(&[&dim, &image, &dim], 64, 48, &DetectOptions::default());
        assert!(d.candidates.iter().all(|c| c.plane == 1));
    }

    #[test]
    fn flat_image_has_no_candidates() {
        let flat = vec![7.0; 32 * 32];
        assert!(detect(&[&flat], 32, 32, &DetectOptions::default())
            .candidates
            .is_empty());
    }
}
