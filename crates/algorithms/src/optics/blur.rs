//! Simulated contact maps as the microscope would see them: blur with a Gaussian PSF, then
//! integrate over the camera's pixels (Weber et al. 2018, Fig. 2 and Methods: "convolved with the
//! point spread function of the microscope"; docs/methods.md §7.4).
//!
//! Recorded choices:
//! * **Order.** Blur on the simulation grid first, then integrate over image pixels. This is the
//!   imaging model itself (a detector pixel collects the blurred intensity falling on it); the
//!   paper does not say which order it used. Blurring first also keeps the PSF well sampled
//!   (σ = 191 nm is 6 pixels at 32 nm but under one pixel at 200 nm).
//! * **Resampling by area fraction.** Each image pixel takes the area-weighted mean of the
//!   simulation pixels it overlaps (exact overlaps, any non-integer ratio such as 200/32 = 6.25),
//!   so a binary map becomes its covered fraction. Image pixels sticking out past the simulated
//!   region count the missing part as zero. Summed intensity × pixel area is conserved exactly.
//! * **Kernel.** Point-sampled Gaussian truncated at 4σ and normalised to sum 1, separable.
//! * **Edges.** [`Edges::Zero`] (the region outside the map is dark, as beyond a simulated
//!   contact) for simulated maps; [`Edges::Mirror`] for synthetic micrographs, where the
//!   background continues past the frame. Zero edges lose the mass blurred past the frame and
//!   nothing else; mirrored edges keep it.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::limits::Limits;

/// FWHM / σ of a Gaussian, 2√(2 ln 2).
pub const FWHM_PER_SIGMA: f64 = 2.354_820_045_030_949_4;

/// What a blur sees beyond the image frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edges {
    /// Zero outside (non-periodic zero padding).
    Zero,
    /// The image mirrored at its border (half-sample symmetric: ... b a | a b c ...).
    Mirror,
}

/// A row-major grid of values with its pixel size.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Values, `height` rows of `width`.
    pub values: Vec<f64>,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Pixel size along x, metres.
    pub dx_m: f64,
    /// Pixel size along y, metres.
    pub dy_m: f64,
}

impl Grid {
    /// A grid after checking that `values` has `width × height` entries and positive pixels.
    pub fn new(
        values: Vec<f64>,
        width: usize,
        height: usize,
        dx_m: f64,
        dy_m: f64,
    ) -> Result<Self> {
        if width == 0 || height == 0 || Some(values.len()) != width.checked_mul(height) {
            return Err(Error::SizeMismatch {
                what: "grid values",
                expected: width * height,
                got: values.len(),
            });
        }
        if !(dx_m > 0.0 && dy_m > 0.0 && dx_m.is_finite() && dy_m.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "pixel size {dx_m:e} × {dy_m:e} m is not positive"
            )));
        }
        Ok(Grid {
            values,
            width,
            height,
            dx_m,
            dy_m,
        })
    }

    /// Σ value × pixel area, in value·m².
    pub fn integral(&self) -> f64 {
        self.values.iter().sum::<f64>() * self.dx_m * self.dy_m
    }
}

/// Normalised point-sampled Gaussian, taps −⌈4σ⌉..=⌈4σ⌉; `[1.0]` for σ ≤ 0.
pub fn gaussian_kernel(sigma_px: f64) -> Vec<f64> {
    if sigma_px <= 0.0 || !sigma_px.is_finite() {
        return vec![1.0];
    }
    // Callers check σ against `Limits::kernel_radius` with their own message; the clamp keeps a
    // missed check from allocating without bound.
    let radius = (4.0 * sigma_px)
        .ceil()
        .min(Limits::DEFAULT.max_kernel_radius as f64) as i64;
    let kernel: Vec<f64> = (-radius..=radius)
        .map(|k| (-((k * k) as f64) / (2.0 * sigma_px * sigma_px)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    kernel.into_iter().map(|k| k / total).collect()
}

/// Separable Gaussian blur of a row-major image with σ given per axis in pixels.
pub fn gaussian_blur(
    data: &[f64],
    width: usize,
    height: usize,
    (sigma_x_px, sigma_y_px): (f64, f64),
    edges: Edges,
) -> Vec<f64> {
    assert_eq!(data.len(), width * height, "blur: image size mismatch");
    // With zero edges, taps farther than the image is long never meet a pixel: drop them (the
    // kernel stays normalised over its full support).
    let trim = |kernel: Vec<f64>, n: usize| match edges {
        Edges::Zero if kernel.len() > 2 * n + 1 => {
            let r = kernel.len() / 2;
            kernel[r - n..=r + n].to_vec()
        }
        _ => kernel,
    };
    let kx = trim(gaussian_kernel(sigma_x_px), width);
    let ky = trim(gaussian_kernel(sigma_y_px), height);
    let mut rows = vec![0.0; data.len()];
    rows.par_chunks_mut(width.max(1))
        .zip(data.par_chunks(width.max(1)))
        .for_each(|(out, row)| convolve_line(row, out, &kx, edges));
    let transposed = transpose(&rows, width, height);
    let mut cols = vec![0.0; data.len()];
    cols.par_chunks_mut(height.max(1))
        .zip(transposed.par_chunks(height.max(1)))
        .for_each(|(out, col)| convolve_line(col, out, &ky, edges));
    transpose(&cols, height, width)
}

/// `out[i] = Σ_k kernel[k] · line[i + k − r]` with the given edge rule.
fn convolve_line(line: &[f64], out: &mut [f64], kernel: &[f64], edges: Edges) {
    let n = line.len();
    let r = (kernel.len() / 2) as i64;
    for (i, o) in out.iter_mut().enumerate() {
        *o = kernel
            .iter()
            .enumerate()
            .filter_map(|(k, w)| {
                let j = i as i64 + k as i64 - r;
                source_index(j, n, edges).map(|j| w * line[j])
            })
            .sum();
    }
}

/// Where sample `j` of a line of `n` comes from, or `None` for zero.
fn source_index(j: i64, n: usize, edges: Edges) -> Option<usize> {
    let n = n as i64;
    match edges {
        Edges::Zero => (0..n).contains(&j).then_some(j as usize),
        Edges::Mirror => {
            let period = 2 * n;
            let m = j.rem_euclid(period);
            Some((if m < n { m } else { period - 1 - m }) as usize)
        }
    }
}

fn transpose(data: &[f64], width: usize, height: usize) -> Vec<f64> {
    let mut out = vec![0.0; data.len()];
    for y in 0..height {
        for x in 0..width {
            out[x * height + y] = data[y * width + x];
        }
    }
    out
}

/// Overlap weights of input cells `[jΔ_in, (j+1)Δ_in)` with output cells `[iΔ_out, (i+1)Δ_out)`,
/// divided by Δ_out: per output cell the `(input index, weight)` pairs. Output cells cover the
/// input extent (the last one may stick out).
fn overlap_weights(n_in: usize, d_in: f64, d_out: f64) -> Vec<Vec<(usize, f64)>> {
    let extent = n_in as f64 * d_in;
    // The tolerance keeps an exact multiple (e.g. 6.25 × 32 nm → 1 µm) from gaining a sliver cell.
    let n_out = ((extent / d_out) * (1.0 - 1e-12)).ceil().max(1.0) as usize;
    (0..n_out)
        .map(|i| {
            let (lo, hi) = (i as f64 * d_out, (i + 1) as f64 * d_out);
            let first = ((lo / d_in).floor() as usize).min(n_in);
            let last = ((hi / d_in).ceil() as usize).min(n_in);
            (first..last)
                .filter_map(|j| {
                    let overlap =
                        (hi.min((j + 1) as f64 * d_in) - lo.max(j as f64 * d_in)).max(0.0);
                    (overlap > 0.0).then_some((j, overlap / d_out))
                })
                .collect()
        })
        .collect()
}

/// [`gaussian_blur`] with one σ in both directions (`sigma_px`, pixels) and mirrored edges: the
/// blur of the generators and of the bead detector.
pub fn isotropic_blur(data: &[f64], width: usize, height: usize, sigma_px: f64) -> Vec<f64> {
    gaussian_blur(data, width, height, (sigma_px, sigma_px), Edges::Mirror)
}

/// Check, before anything is allocated, that resampling a `width × height` grid of `from`
/// pixels (x, y, m) onto `to` pixels gives a plane within the limits (each side, and the plane
/// as a whole: each side alone may pass while their product does not).
pub fn check_resample(
    (width, height): (usize, usize),
    from: (f64, f64),
    to: (f64, f64),
) -> Result<()> {
    let limit = |source| Error::Limit {
        what: "resampling".into(),
        source,
    };
    let nx = Limits::DEFAULT
        .samples(width as f64 * from.0, to.0)
        .map_err(limit)?;
    let ny = Limits::DEFAULT
        .samples(height as f64 * from.1, to.1)
        .map_err(limit)?;
    Limits::DEFAULT
        .plane_bytes(nx.max(1), ny.max(1), 8)
        .map_err(limit)?;
    Ok(())
}

/// Area-fraction resampling of `grid` onto pixels of `dx_m × dy_m` whose first pixel starts at
/// the grid's corner: each output value is the area-weighted mean of the input over the output
/// pixel (the covered fraction for a binary map). Conserves [`Grid::integral`] exactly.
pub fn resample_area(grid: &Grid, dx_m: f64, dy_m: f64) -> Result<Grid> {
    if !(dx_m > 0.0 && dy_m > 0.0 && dx_m.is_finite() && dy_m.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "target pixel size {dx_m:e} × {dy_m:e} m is not positive"
        )));
    }
    check_resample(
        (grid.width, grid.height),
        (grid.dx_m, grid.dy_m),
        (dx_m, dy_m),
    )?;
    let wx = overlap_weights(grid.width, grid.dx_m, dx_m);
    let wy = overlap_weights(grid.height, grid.dy_m, dy_m);
    let (out_w, out_h) = (wx.len(), wy.len());
    // Rows first (width shrinks), then columns.
    let narrow: Vec<f64> = grid
        .values
        .par_chunks(grid.width)
        .flat_map_iter(|row| {
            wx.iter()
                .map(|cell| cell.iter().map(|&(j, w)| w * row[j]).sum::<f64>())
                .collect::<Vec<_>>()
        })
        .collect();
    let values: Vec<f64> = wy
        .par_iter()
        .flat_map_iter(|cell| {
            (0..out_w)
                .map(|x| {
                    cell.iter()
                        .map(|&(j, w)| w * narrow[j * out_w + x])
                        .sum::<f64>()
                })
                .collect::<Vec<_>>()
        })
        .collect();
    Grid::new(values, out_w, out_h, dx_m, dy_m)
}

/// What the microscope makes of a simulated map: blur with a Gaussian PSF of `fwhm_m` on the
/// simulation grid (zero outside), then integrate over image pixels of `pixel_m` (x, y).
/// A binary contact map becomes an image whose values sum to the contact area in image pixels.
pub fn microscope_image(map: &Grid, fwhm_m: f64, pixel_m: (f64, f64)) -> Result<Grid> {
    if !(fwhm_m >= 0.0 && fwhm_m.is_finite()) {
        return Err(Error::Value {
            what: "PSF FWHM",
            value: fwhm_m,
            unit: "m",
            requirement: "is not a non-negative length",
        });
    }
    let sigma_m = fwhm_m / FWHM_PER_SIGMA;
    let sigma_px = (sigma_m / map.dx_m, sigma_m / map.dy_m);
    for s in [sigma_px.0, sigma_px.1] {
        Limits::DEFAULT
            .kernel_radius(s)
            .map_err(|source| Error::Limit {
                what: format!(
                    "PSF FWHM {:.4} µm on a grid of {:.4e} × {:.4e} m pixels",
                    fwhm_m * 1e6,
                    map.dx_m,
                    map.dy_m
                ),
                source,
            })?;
    }
    let blurred = gaussian_blur(&map.values, map.width, map.height, sigma_px, Edges::Zero);
    let blurred = Grid::new(blurred, map.width, map.height, map.dx_m, map.dy_m)?;
    resample_area(&blurred, pixel_m.0, pixel_m.1)
}

/// Least-squares intensity scale `experiment ≈ gain · simulated + offset` over pixels where both
/// are finite: puts a simulated image on the experiment's grey scale, as the paper matched the
/// colour scales of its Fig. 2 by eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntensityScale {
    /// Grey levels per unit of simulated intensity.
    pub gain: f64,
    /// Grey level of zero simulated intensity (the background).
    pub offset: f64,
}

impl IntensityScale {
    /// Fit over paired values; errors if fewer than 2 finite pairs or the simulated values are
    /// constant.
    pub fn fit(simulated: &[f64], experiment: &[f64]) -> Result<Self> {
        let pairs: Vec<(f64, f64)> = simulated
            .iter()
            .zip(experiment)
            .map(|(&s, &e)| (s, e))
            .filter(|(s, e)| s.is_finite() && e.is_finite())
            .collect();
        let n = pairs.len() as f64;
        let (ms, me) = pairs
            .iter()
            .fold((0.0, 0.0), |(a, b), (s, e)| (a + s / n, b + e / n));
        let sxx: f64 = pairs.iter().map(|(s, _)| (s - ms).powi(2)).sum();
        let sxy: f64 = pairs.iter().map(|(s, e)| (s - ms) * (e - me)).sum();
        if pairs.len() < 2 || sxx <= 0.0 {
            return Err(Error::InvalidArgument(
                "the simulated image is constant; no intensity scale can be fitted".into(),
            ));
        }
        let gain = sxy / sxx;
        Ok(IntensityScale {
            gain,
            offset: me - gain * ms,
        })
    }

    /// `gain · value + offset`.
    pub fn apply(&self, value: f64) -> f64 {
        self.gain * value + self.offset
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_resampled_plane_beyond_the_limits_is_refused_though_each_side_passes() {
        // 50,000 × 50,000 output pixels: each side within 65,536, the plane 18.6 GiB.
        let e = check_resample((500, 500), (1e-7, 1e-7), (1e-9, 1e-9))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("resampling"), "{e}");
        assert!(check_resample((500, 500), (1e-7, 1e-7), (2e-7, 2e-7)).is_ok());
    }

    fn disk(n: usize, radius_px: f64, centre: (f64, f64)) -> Vec<f64> {
        (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f64 - centre.0, (i / n) as f64 - centre.1);
                f64::from(u8::from(x * x + y * y <= radius_px * radius_px))
            })
            .collect()
    }

    /// docs/validation.md B24: FWHM 450 nm, 32 nm simulation pixels, 200 nm image pixels: the image
    /// sums to the contact area in image-pixel units to 1e-9.
    #[test]
    fn blur_preserves_mass_and_matches_gaussian_width() {
        let (w, h) = (41, 41);
        let mut delta = vec![0.0; w * h];
        delta[20 * w + 20] = 1.0;
        let out = isotropic_blur(&delta, w, h, 2.0);
        assert!((out.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let var: f64 = out
            .iter()
            .enumerate()
            .map(|(i, v)| v * ((i % w) as f64 - 20.0).powi(2))
            .sum();
        // The kernel is cut at 4σ, which lowers the variance by about 0.03 %.
        assert!((var - 4.0).abs() < 2e-3, "variance {var}");
    }

    #[test]
    fn b24_blur_and_resample_conserve_contact_area() {
        let n = 625; // 20 µm
        let map = Grid::new(disk(n, 150.0, (301.3, 322.7)), n, n, 32e-9, 32e-9).unwrap();
        let contact_px: f64 = map.values.iter().sum();
        let image = microscope_image(&map, 450e-9, (200e-9, 200e-9)).unwrap();
        assert_eq!((image.width, image.height), (100, 100));
        let area_in_image_px = contact_px * (32.0f64 / 200.0).powi(2);
        let sum: f64 = image.values.iter().sum();
        assert!(
            (sum / area_in_image_px - 1.0).abs() < 1e-9,
            "{sum} vs {area_in_image_px}"
        );
        assert!(image
            .values
            .iter()
            .all(|&v| (-1e-12..=1.0 + 1e-12).contains(&v)));
    }

    #[test]
    fn resampling_is_the_covered_fraction() {
        // 5 input pixels of 1 unit onto 2-unit pixels: the third output pixel sticks out.
        let grid = Grid::new(vec![1.0, 0.0, 1.0, 1.0, 1.0], 5, 1, 1.0, 1.0).unwrap();
        let out = resample_area(&grid, 2.0, 1.0).unwrap();
        assert_eq!(out.values, vec![0.5, 1.0, 0.5]);
        assert!((out.integral() - grid.integral()).abs() < 1e-12);
        // Non-integer ratio 6.25 on an exact multiple: 25 pixels of 32 nm → 4 of 200 nm.
        let ones = Grid::new(vec![1.0; 25 * 25], 25, 25, 32e-9, 32e-9).unwrap();
        let out = resample_area(&ones, 200e-9, 200e-9).unwrap();
        assert_eq!((out.width, out.height), (4, 4));
        assert!(out.values.iter().all(|v| (v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn resampling_matches_brute_force_supersampling() {
        let (w, h) = (13, 9);
        let values: Vec<f64> = (0..w * h).map(|i| ((i * 37) % 11) as f64).collect();
        let grid = Grid::new(values.clone(), w, h, 0.3, 0.45).unwrap();
        let out = resample_area(&grid, 0.7, 1.0).unwrap();
        // Brute force: 700 × 1000 sub-samples per output pixel.
        let (sx, sy) = (70, 100);
        for oy in 0..out.height {
            for ox in 0..out.width {
                let mut acc = 0.0;
                for j in 0..sy {
                    for i in 0..sx {
                        let x = (ox as f64 + (i as f64 + 0.5) / sx as f64) * 0.7;
                        let y = (oy as f64 + (j as f64 + 0.5) / sy as f64) * 1.0;
                        let (ix, iy) = ((x / 0.3) as usize, (y / 0.45) as usize);
                        if ix < w && iy < h {
                            acc += values[iy * w + ix];
                        }
                    }
                }
                let expected = acc / (sx * sy) as f64;
                let got = out.values[oy * out.width + ox];
                assert!(
                    (got - expected).abs() < 0.02,
                    "({ox},{oy}) {got} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn blur_matches_direct_2d_convolution_and_spreads_a_point_as_sigma() {
        let (w, h) = (31, 27);
        let mut data = vec![0.0; w * h];
        data[13 * w + 15] = 1.0;
        data[2 * w + 1] = 2.0;
        let sigma = (1.7, 2.3);
        for edges in [Edges::Zero, Edges::Mirror] {
            let out = gaussian_blur(&data, w, h, sigma, edges);
            let (kx, ky) = (gaussian_kernel(sigma.0), gaussian_kernel(sigma.1));
            let (rx, ry) = ((kx.len() / 2) as i64, (ky.len() / 2) as i64);
            for y in 0..h as i64 {
                for x in 0..w as i64 {
                    let mut direct = 0.0;
                    for (b, wy) in ky.iter().enumerate() {
                        for (a, wx) in kx.iter().enumerate() {
                            let sx = source_index(x + a as i64 - rx, w, edges);
                            let sy = source_index(y + b as i64 - ry, h, edges);
                            if let (Some(sx), Some(sy)) = (sx, sy) {
                                direct += wx * wy * data[sy * w + sx];
                            }
                        }
                    }
                    let got = out[y as usize * w + x as usize];
                    assert!((got - direct).abs() < 1e-14, "{edges:?} ({x},{y})");
                }
            }
        }
        // Second moment of the blurred interior point = σ² per axis.
        let mut point = vec![0.0; w * h];
        point[13 * w + 15] = 1.0;
        let out = gaussian_blur(&point, w, h, sigma, Edges::Zero);
        let (mut vx, mut vy) = (0.0, 0.0);
        for (i, v) in out.iter().enumerate() {
            vx += v * ((i % w) as f64 - 15.0).powi(2);
            vy += v * ((i / w) as f64 - 13.0).powi(2);
        }
        // Truncation at 4σ removes about 1e-4 of the mass, from the far tails.
        assert!((vx / 1.7f64.powi(2) - 1.0).abs() < 5e-3, "{vx}");
        assert!((vy / 2.3f64.powi(2) - 1.0).abs() < 5e-3, "{vy}");
        let mirrored: f64 = gaussian_blur(&data, w, h, sigma, Edges::Mirror)
            .iter()
            .sum();
        assert!((mirrored - 3.0).abs() < 1e-12, "mirror edges keep the mass");
    }

    #[test]
    fn intensity_scale_recovers_gain_and_offset() {
        let sim: Vec<f64> = (0..50).map(|i| f64::from(i) / 49.0).collect();
        let exp: Vec<f64> = sim.iter().map(|s| 1800.0 * s + 210.0).collect();
        let scale = IntensityScale::fit(&sim, &exp).unwrap();
        assert!((scale.gain - 1800.0).abs() < 1e-9 && (scale.offset - 210.0).abs() < 1e-9);
        assert!((scale.apply(0.5) - 1110.0).abs() < 1e-9);
        assert!(IntensityScale::fit(&[1.0; 4], &[2.0, 3.0, 4.0, 5.0]).is_err());
        assert!(microscope_image(
            &Grid::new(vec![1.0], 1, 1, 1.0, 1.0).unwrap(),
            f64::NAN,
            (1.0, 1.0)
        )
        .is_err());
    }
}
