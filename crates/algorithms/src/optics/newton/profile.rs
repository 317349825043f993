//! Image side of the Newton-ring analysis: the fluorescent contact (exact Otsu threshold, largest
//! 8-connected component, centroid), width-averaged line profiles through the centre with
//! bilinear interpolation, light smoothing, the fluorescence edge on a profile and ring maxima
//! found by prominence (`docs/methods.md` §7.5, steps 1–3).

use crate::error::{Error, Location, Result};
use crate::image::Image;
use crate::numerics::stats::median;
use crate::threshold::otsu_of_values;

/// The fluorescent contact found in the fluorescence image.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// Otsu threshold t; contact is value > t (`docs/conventions.md`).
    pub threshold: f64,
    /// Centroid of the largest contact component, pixels (x = column, y = row; pixel centres at
    /// integer coordinates).
    pub centre_px: (f64, f64),
    /// Pixels in the largest component.
    pub pixels: usize,
    /// Mean over the component minus mean over non-contact pixels, in noise standard deviations
    /// of the non-contact pixels.
    pub contrast_sd: f64,
}

/// Smallest contact component taken for a contact, pixels: anything smaller cannot carry a
/// centre or an edge radius.
const MIN_CONTACT_PIXELS: usize = 9;

/// A real contact stands out of the background by many noise deviations; an Otsu split of pure
/// noise gives about 1.6.
const MIN_CONTACT_CONTRAST_SD: f64 = 5.0;

/// Exact Otsu threshold of an image: one bin per level for integer data (as in `analyze`), 4096
/// bins over the finite range otherwise. `Error::BadInput` naming the file when every pixel has
/// one value.
pub fn otsu_threshold(image: &Image) -> Result<f64> {
    otsu_of_values(&[&image.values], &image.path.display().to_string()).map_err(|e| match e {
        Error::ConstantData { value, .. } => Error::bad_input(
            Location::file(&image.path),
            format!(
                "no contact found: every pixel has the value {value}, so no threshold separates contact from background"
            ),
        ),
        other => other,
    })
}

/// The fluorescent contact: Otsu threshold, the largest 8-connected component above it, its
/// centroid. Errors name the file when nothing stands out of the background.
pub fn find_contact(image: &Image) -> Result<Contact> {
    let threshold = otsu_threshold(image)?;
    let above: Vec<bool> = image.values.iter().map(|&v| v > threshold).collect();
    let component = largest_component(&above, image.width, image.height);
    let no_contact = |why: String| {
        Error::bad_input(
            Location::file(&image.path),
            format!("no contact found: {why}"),
        )
    };
    if component.len() < MIN_CONTACT_PIXELS {
        return Err(no_contact(format!(
            "the largest region above the Otsu threshold {threshold} has {} pixel(s)",
            component.len()
        )));
    }
    let contrast_sd = contrast(image, &above, &component);
    if contrast_sd.is_nan() || contrast_sd < MIN_CONTACT_CONTRAST_SD {
        return Err(no_contact(format!(
            "the brightest region stands only {contrast_sd:.1} noise deviations above the background (at least {MIN_CONTACT_CONTRAST_SD} needed)"
        )));
    }
    let n = component.len() as f64;
    let (sx, sy) = component.iter().fold((0.0, 0.0), |(sx, sy), &i| {
        (sx + (i % image.width) as f64, sy + (i / image.width) as f64)
    });
    Ok(Contact {
        threshold,
        centre_px: (sx / n, sy / n),
        pixels: component.len(),
        contrast_sd,
    })
}

/// (mean of the component − mean of the pixels not above threshold) / their standard deviation.
fn contrast(image: &Image, above: &[bool], component: &[usize]) -> f64 {
    let inside = component.iter().map(|&i| image.values[i]).sum::<f64>() / component.len() as f64;
    let outside: Vec<f64> = image
        .values
        .iter()
        .zip(above)
        .filter(|(v, &a)| !a && v.is_finite())
        .map(|(&v, _)| v)
        .collect();
    if outside.len() < 2 {
        return f64::INFINITY;
    }
    let mean = outside.iter().sum::<f64>() / outside.len() as f64;
    let var = outside.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (outside.len() - 1) as f64;
    if var == 0.0 {
        return if inside > mean { f64::INFINITY } else { 0.0 };
    }
    (inside - mean) / var.sqrt()
}

/// Indices of the largest 8-connected region of `true` pixels (first found wins ties).
fn largest_component(mask: &[bool], width: usize, height: usize) -> Vec<usize> {
    let mut seen = vec![false; mask.len()];
    let mut best = Vec::new();
    let mut stack = Vec::new();
    for start in 0..mask.len() {
        if !mask[start] || seen[start] {
            continue;
        }
        let mut region = Vec::new();
        seen[start] = true;
        stack.push(start);
        while let Some(i) = stack.pop() {
            region.push(i);
            let (x, y) = ((i % width) as isize, (i / width) as isize);
            for (dx, dy) in NEIGHBOURS {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= width as isize || ny >= height as isize {
                    continue;
                }
                let j = ny as usize * width + nx as usize;
                if mask[j] && !seen[j] {
                    seen[j] = true;
                    stack.push(j);
                }
            }
        }
        if region.len() > best.len() {
            best = region;
        }
    }
    best
}

const NEIGHBOURS: [(isize, isize); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// Bilinear interpolation at pixel coordinates (x, y); `None` outside the pixel centres' hull.
fn bilinear(image: &Image, x: f64, y: f64) -> Option<f64> {
    let (w, h) = (image.width as f64, image.height as f64);
    if !(x >= 0.0 && y >= 0.0 && x <= w - 1.0 && y <= h - 1.0) {
        return None;
    }
    let (x0, y0) = (
        x.floor().min(w - 2.0).max(0.0),
        y.floor().min(h - 2.0).max(0.0),
    );
    let (fx, fy) = (x - x0, y - y0);
    let (i, j) = (x0 as usize, y0 as usize);
    let at = |di: usize, dj: usize| {
        image.at(
            (i + di).min(image.width - 1),
            (j + dj).min(image.height - 1),
        )
    };
    let top = at(0, 0) * (1.0 - fx) + at(1, 0) * fx;
    let bottom = at(0, 1) * (1.0 - fx) + at(1, 1) * fx;
    Some(top * (1.0 - fy) + bottom * fy)
}

/// Geometry of one half-line: from the centre in direction `angle_rad` (from +x towards +y,
/// i.e. towards increasing rows), in physical units.
#[derive(Debug, Clone, Copy)]
pub struct HalfLine {
    /// Centre, pixels.
    pub centre_px: (f64, f64),
    /// Direction, radians from the +x axis towards +y.
    pub angle_rad: f64,
    /// Pixel size (x, y), m.
    pub pixel_m: (f64, f64),
    /// Width of the band averaged across the line, in samples spaced one (smaller) pixel apart.
    pub width_samples: usize,
    /// Step along the line, m.
    pub step_m: f64,
}

impl HalfLine {
    /// Width-averaged samples at s = 0, step, 2·step, … until the band leaves the image.
    pub fn sample(&self, image: &Image) -> Vec<f64> {
        let (c, s) = (self.angle_rad.cos(), self.angle_rad.sin());
        let across = self.pixel_m.0.min(self.pixel_m.1);
        let half = (self.width_samples.max(1) - 1) as f64 / 2.0;
        // The band leaves the image within its diagonal; the bound makes the loop finite for any
        // pixel size (NaN included).
        let diagonal_m =
            (image.width as f64 * self.pixel_m.0).hypot(image.height as f64 * self.pixel_m.1);
        let max_k = (diagonal_m / self.step_m).min(1e9) as usize + 2;
        let mut out = Vec::new();
        for k in 0..max_k {
            let along = k as f64 * self.step_m;
            let mut sum = 0.0;
            for j in 0..self.width_samples.max(1) {
                let t = (j as f64 - half) * across;
                let x = self.centre_px.0 + (along * c - t * s) / self.pixel_m.0;
                let y = self.centre_px.1 + (along * s + t * c) / self.pixel_m.1;
                match bilinear(image, x, y) {
                    Some(v) => sum += v,
                    None => return out,
                }
            }
            out.push(sum / self.width_samples.max(1) as f64);
        }
        out
    }
}

/// Gaussian smoothing of a 1-D profile (σ in samples), mirrored at the ends.
pub fn smooth(profile: &[f64], sigma: f64) -> Vec<f64> {
    if sigma <= 0.0 || profile.len() < 2 {
        return profile.to_vec();
    }
    let radius = (4.0 * sigma).ceil() as isize;
    let n = profile.len() as isize;
    let kernel: Vec<f64> = (-radius..=radius)
        .map(|k| (-((k * k) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    let mirror = |i: isize| -> usize {
        let period = 2 * n;
        let m = i.rem_euclid(period);
        (if m < n { m } else { period - 1 - m }) as usize
    };
    (0..n)
        .map(|i| {
            (-radius..=radius)
                .zip(&kernel)
                .map(|(k, w)| w * profile[mirror(i + k)])
                .sum::<f64>()
                / total
        })
        .collect()
}

/// Position (in samples, interpolated) where the profile first falls to `threshold` or below
/// going outward; `None` if it starts at or below it or never gets there.
pub fn edge_crossing(profile: &[f64], threshold: f64) -> Option<f64> {
    if profile.first().is_none_or(|&v| v <= threshold) {
        return None;
    }
    let k = profile.iter().position(|&v| v <= threshold)?;
    let (above, below) = (profile[k - 1], profile[k]);
    Some((k - 1) as f64 + (above - threshold) / (above - below))
}

/// The fluorescent edge on one half-line, found by [`half_level_edge`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// Position, samples from the centre (interpolated).
    pub position: f64,
    /// Median of the profile over the plateau inside the edge.
    pub inside: f64,
    /// Median of the profile over the plateau outside the edge.
    pub outside: f64,
}

/// Where a fluorescence profile falls through the level half-way between its inside and outside
/// plateaus, linearly interpolated between samples (`docs/optics.md`, "Fluorescent edge").
///
/// The fluorescence is a step at r_f (on where the gap is below d_det) seen through a symmetric
/// PSF, pixel integration, bilinear sampling and symmetric smoothing along the line: each keeps
/// the half-level point of a straight step where the step is, whatever the widths, whereas any
/// other level (an Otsu threshold among them) moves by the blur width times a factor that depends
/// on the level. On a disc the half-level point lies σ²/(2r_f) inside r_f (σ of the combined
/// blur): 0.9 nm for a 450 nm PSF at r_f = 20 µm, ignored.
///
/// `guess` is a first position (samples); the plateaus are the medians over `window` samples
/// beyond `margin` samples on either side of it (inside: clipped at the centre, at least the
/// first sample). The crossing nearest the guess within ± `margin` is taken, and the plateaus
/// and crossing are found once more around it. `None` when the outside plateau lies beyond the
/// profile's end, when the inside is not brighter than the outside, or when there is no crossing.
pub fn half_level_edge(profile: &[f64], guess: f64, margin: usize, window: usize) -> Option<Edge> {
    let mut edge = None;
    let mut at = guess;
    for _ in 0..2 {
        let centre = at.round().max(0.0) as usize;
        let inside_end = centre.saturating_sub(margin).max(1).min(profile.len());
        let inside_start = inside_end.saturating_sub(window.max(1));
        let outside_start = centre + margin;
        let outside_end = (outside_start + window.max(1)).min(profile.len());
        if outside_start >= outside_end {
            return None;
        }
        let inside = median(&profile[inside_start..inside_end]);
        let outside = median(&profile[outside_start..outside_end]);
        if !(inside > outside && inside.is_finite() && outside.is_finite()) {
            return None;
        }
        let half = 0.5 * (inside + outside);
        let lo = centre.saturating_sub(margin).max(1);
        let hi = (centre + margin).min(profile.len() - 1);
        let position = (lo..=hi)
            .filter(|&k| profile[k - 1] > half && profile[k] <= half)
            .map(|k| (k - 1) as f64 + (profile[k - 1] - half) / (profile[k - 1] - profile[k]))
            .min_by(|x, y| (x - at).abs().total_cmp(&(y - at).abs()))?;
        at = position;
        edge = Some(Edge {
            position,
            inside,
            outside,
        });
    }
    edge
}

/// A local maximum of a profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    /// Position in samples (parabolic sub-sample refinement).
    pub position: f64,
    /// Height above the higher of the two minima that separate it from higher ground (or the
    /// profile's ends), in intensity units.
    pub prominence: f64,
}

/// Interior local maxima of `profile` at sample index ≥ `start`, with their prominence.
/// A plateau counts once, at its middle.
pub fn peaks(profile: &[f64], start: usize) -> Vec<Peak> {
    let n = profile.len();
    let mut found = Vec::new();
    let mut i = start.max(1);
    while i + 1 < n {
        if profile[i] > profile[i - 1] {
            let mut j = i;
            while j + 1 < n && profile[j + 1] == profile[i] {
                j += 1;
            }
            if j + 1 < n && profile[j + 1] < profile[i] {
                let mid = (i + j) / 2;
                found.push(Peak {
                    position: refine(profile, mid),
                    prominence: prominence(profile, mid),
                });
            }
            i = j + 1;
        } else {
            i += 1;
        }
    }
    found
}

/// Vertex of the parabola through the samples around `i`.
fn refine(profile: &[f64], i: usize) -> f64 {
    let (l, c, r) = (profile[i - 1], profile[i], profile[i + 1]);
    let denom = l - 2.0 * c + r;
    if denom >= 0.0 {
        return i as f64;
    }
    i as f64 + (0.5 * (l - r) / denom).clamp(-0.5, 0.5)
}

/// Topographic prominence of the sample at `i`.
fn prominence(profile: &[f64], i: usize) -> f64 {
    let top = profile[i];
    let lowest_until_higher = |range: &mut dyn Iterator<Item = usize>| {
        let mut low = top;
        for k in range {
            if profile[k] > top {
                break;
            }
            low = low.min(profile[k]);
        }
        low
    };
    let left = lowest_until_higher(&mut (0..i).rev());
    let right = lowest_until_higher(&mut (i + 1..profile.len()));
    top - left.max(right)
}

/// Robust noise of a profile: 1.4826 × median absolute deviation of (raw − smoothed).
pub fn noise_sd(raw: &[f64], smoothed: &[f64]) -> f64 {
    let mut dev: Vec<f64> = raw
        .iter()
        .zip(smoothed)
        .map(|(r, s)| (r - s).abs())
        .collect();
    if dev.is_empty() {
        return 0.0;
    }
    dev.sort_by(f64::total_cmp);
    1.4826 * dev[dev.len() / 2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn image(width: usize, height: usize, f: impl Fn(f64, f64) -> f64) -> Image {
        let values = (0..width * height)
            .map(|i| f((i % width) as f64, (i / width) as f64))
            .collect();
        Image {
            values,
            width,
            height,
            pixel_size: None,
            path: PathBuf::from("f.tif"),
            page: 0,
        }
    }

    #[test]
    fn contact_centroid_and_errors() {
        let im = image(40, 30, |x, y| {
            if (x - 20.3).hypot(y - 12.6) < 6.0 || (x < 2.0 && y < 2.0) {
                1000.0
            } else {
                100.0 + (x * 7.0 + y * 3.0) % 5.0
            }
        });
        let c = find_contact(&im).unwrap();
        assert!(
            (c.centre_px.0 - 20.3).abs() < 0.2 && (c.centre_px.1 - 12.6).abs() < 0.2,
            "{c:?}"
        );
        assert!(c.threshold >= 104.0 && c.threshold < 1000.0);
        let blank = image(10, 10, |_, _| 7.0);
        let err = find_contact(&blank).unwrap_err().to_string();
        assert!(err.contains("f.tif") && err.contains("no contact"), "{err}");
        // Pure pseudo-noise: Otsu splits it, but nothing stands out.
        let noise = image(50, 50, |x, y| {
            ((x * 12.9898 + y * 78.233).sin() * 43758.5).fract().abs() * 100.0
        });
        let err = find_contact(&noise).unwrap_err().to_string();
        assert!(err.contains("no contact"), "{err}");
    }

    #[test]
    fn float_images_use_float_bins() {
        let im = image(20, 20, |x, _| if x < 5.0 { 0.75 } else { 0.25 });
        let t = otsu_threshold(&im).unwrap();
        assert!((0.25..0.75).contains(&t), "{t}");
    }

    #[test]
    fn bilinear_profile_of_a_ramp() {
        let im = image(20, 20, |x, y| 2.0 * x + y);
        let line = HalfLine {
            centre_px: (5.5, 5.25),
            angle_rad: 0.0,
            pixel_m: (1.0, 1.0),
            width_samples: 3,
            step_m: 0.5,
        };
        let p = line.sample(&im);
        assert_eq!(p.len(), 28, "x from 5.5 to 19 in half steps");
        assert!((p[0] - 16.25).abs() < 1e-12 && (p[3] - 19.25).abs() < 1e-12);
    }

    /// A step from `inside` to `outside` at `edge` samples (each sample holds the fraction of
    /// its unit cell inside), smoothed with σ samples: a sampled blurred edge.
    fn blurred_step(edge: f64, sigma: f64, inside: f64, outside: f64) -> Vec<f64> {
        let step: Vec<f64> = (0..400)
            .map(|k| {
                let fraction = (edge - k as f64 + 0.5).clamp(0.0, 1.0);
                outside + (inside - outside) * fraction
            })
            .collect();
        smooth(&step, sigma)
    }

    #[test]
    fn half_level_edge_is_where_the_step_is_whatever_the_blur_and_the_guess() {
        for sigma in [0.0, 2.0, 5.0, 10.0] {
            for edge in [150.0, 150.3, 150.5, 150.85] {
                let p = blurred_step(edge, sigma, 1650.0, 150.0);
                // A guess from a low level (an Otsu threshold need not sit half-way).
                let low = edge_crossing(&p, 300.0).unwrap();
                if sigma >= 5.0 {
                    assert!(low - edge > 0.8 * sigma, "σ = {sigma}: {low} vs {edge}");
                }
                let found = half_level_edge(&p, low, 40, 80).unwrap();
                // Without blur, linear interpolation across the one partly covered sample
                // misplaces the crossing by up to 0.08 samples.
                let tolerance = if sigma == 0.0 { 0.1 } else { 0.01 };
                assert!(
                    (found.position - edge).abs() < tolerance,
                    "σ = {sigma}, edge {edge}: {found:?}"
                );
                assert!(
                    (found.inside - 1650.0).abs() < 1e-6 && (found.outside - 150.0).abs() < 1e-6
                );
            }
        }
    }

    #[test]
    fn half_level_edge_under_noise_and_where_it_cannot_be_found() {
        // Pseudo-noise of up to ±120 counts on a 1500-count step, smoothed as profiles are.
        let noisy: Vec<f64> = (0..400)
            .map(|k| {
                let base = if (k as f64) < 123.4 { 1650.0 } else { 150.0 };
                base + 120.0 * (((k as f64) * 12.9898).sin() * 43758.5).fract()
            })
            .collect();
        let found = half_level_edge(&smooth(&noisy, 4.0), 118.0, 30, 60).unwrap();
        assert!((found.position - 123.4).abs() < 1.0, "{found:?}");
        let p = blurred_step(150.0, 3.0, 1000.0, 100.0);
        assert!(
            half_level_edge(&p, 150.0, 300, 20).is_none(),
            "outside plateau off the end"
        );
        let inverted = blurred_step(150.0, 3.0, 100.0, 1000.0);
        assert!(
            half_level_edge(&inverted, 150.0, 20, 20).is_none(),
            "inside darker"
        );
        assert!(half_level_edge(&[], 0.0, 2, 2).is_none());
    }

    #[test]
    fn peaks_edges_and_prominence() {
        let p: Vec<f64> = (0..200)
            .map(|i| {
                let x = i as f64 / 10.0;
                1.0 - (x * 1.3).cos()
            })
            .collect();
        let found = peaks(&p, 0);
        assert_eq!(found.len(), 4, "{found:?}");
        for (k, peak) in found.iter().enumerate() {
            let x = peak.position / 10.0;
            let expected = (2 * k + 1) as f64 * std::f64::consts::PI / 1.3;
            assert!((x - expected).abs() < 0.002, "{x} vs {expected}");
            assert!(peak.prominence > 1.9);
        }
        assert_eq!(peaks(&p, 50).len(), 3);
        assert!(peaks(&[1.0; 10], 0).is_empty());
        let e = edge_crossing(&[10.0, 8.0, 6.0, 2.0], 4.0).unwrap();
        assert!((e - 2.5).abs() < 1e-12);
        assert!(edge_crossing(&[1.0, 8.0], 4.0).is_none());
    }
}
