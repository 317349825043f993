//! The light budget of one image: how much contact light it holds, whatever the PSF made of the
//! contact's shape (`docs/methods.md`, "Corrected areas from the light budget").
//!
//! A Gaussian PSF and the detector's pixels move light but conserve it (B24): an image of a
//! contact χ with a uniform signal s over a background b holds Σ (v − b) = s·A pixels' worth
//! of light over the region the light reaches, however small the patches (they shrink or vanish
//! below a threshold, their light does not) and however close (two patches bridged by the blur
//! hold the light of the two). This module measures it with one pass over the pixels, which sums
//! [`TILE`] × [`TILE`] tiles (pixels, their sum, contact pixels); the rest works on the tiles
//! (1/16 of the pixels) and visits pixels again only to estimate the noise:
//!
//! * the **background** b(x, y): a smooth surface (quadratic, else a plane, else a constant)
//!   fitted by weighted least squares to the means of 16 × 16 pixel blocks far from contact,
//!   blocks off by more than five of their standard errors (faint light, dust) rejected and the
//!   fit repeated; its covariance gives the uncertainty of the background summed under the light;
//! * the **pixel noise**: the median variance within tiles (a median of 15-degree-of-freedom
//!   variances, corrected to their mean), of the background blocks and of the plateau;
//! * the **light**: tiles at least half contact at the series threshold, and tiles whose excess
//!   summed over their 3 × 3 neighbourhood lies more than [`DETECTION_SD`] standard errors above
//!   the background (patches too faint for the threshold still shine), are seeds; the region R
//!   is the tiles within 3σ_PSF + 1 px of a seed; M = Σ_R (v − b);
//! * the **plateau**: tiles at least three-quarters contact whose neighbours within
//!   3σ_PSF + 1 px are too (the contact's deep interior, where the blurred contact is the signal
//!   itself), with the mean excess, the noise within the tiles, the spread of the tiles' means
//!   beyond the noise (texture: holes or a varying signal) and their 90th percentile;
//! * the **peak**: the brightest tile mean over the seeds, a lower bound on the signal (no pixel
//!   is brighter than full contact).
//!
//! The light budget does not know s: a patch narrower than the PSF at half the area and twice
//! the signal looks the same. The series analysis ([`super::corrected`]) takes s from the
//! plateaus and its trend with load.

use nalgebra::{DMatrix, DVector};

use crate::image::Plane;
use crate::measure::tiles::{TileSums, BLOCK_TILES};

pub use crate::measure::tiles::TILE;

/// Pixels of a full tile.
const TILE_PIXELS: usize = TILE * TILE;

/// Detection of light below the threshold: standard errors of a 3 × 3-tile sum.
pub const DETECTION_SD: f64 = 4.0;

/// Fewest plateau tiles (of 16 pixels) that make a plateau.
pub const MIN_PLATEAU_TILES: usize = 4;

/// Contact pixels of a tile that make it a seed.
const SEED_PIXELS: u8 = 8;

/// Contact pixels of a tile that make it a candidate for the plateau.
const FULL_PIXELS: u8 = 12;

/// At most this many tiles (evenly spaced) are visited for a noise estimate.
const NOISE_TILES: usize = 2048;

/// The median of a variance with 15 degrees of freedom over its mean (χ²₁₅ median / 15): a
/// full tile's within variance.
const CHI2_15_MEDIAN: f64 = 0.955_53;

/// The deep interior of one image's contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plateau {
    /// Mean excess over the background, grey levels.
    pub level: f64,
    /// Tiles it is made of.
    pub tiles: usize,
    /// Pixels it is made of.
    pub pixels: u64,
    /// The pixel noise's variance at the plateau's level, grey levels².
    pub white_variance: f64,
    /// The variance of its tiles' means beyond what the noise gives them (texture: holes
    /// narrower than the PSF, or a signal that varies), grey levels².
    pub texture_variance: f64,
    /// The 90th percentile of its tiles' mean excess, grey levels.
    pub tile_q90: f64,
}

impl Plateau {
    /// Standard error of [`Plateau::level`]: the noise over its pixels and the texture over
    /// independent areas of `correlated_pixels` pixels.
    pub fn standard_error(&self, correlated_pixels: f64) -> f64 {
        let n = self.pixels.max(1) as f64;
        (self.white_variance / n + self.texture_variance * correlated_pixels.max(1.0) / n).sqrt()
    }

    /// The top reading: the 90th percentile of the tiles' means less what the noise adds to a
    /// 90th percentile (1.2816 standard deviations of a tile's mean), never below the mean.
    pub fn top(&self) -> f64 {
        let tile_sd = (self.white_variance / TILE_PIXELS as f64).sqrt();
        (self.tile_q90 - 1.2816 * tile_sd).max(self.level)
    }
}

/// The light budget of one image (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightBudget {
    /// M = Σ_R (v − b), grey levels × pixels.
    pub excess: f64,
    /// Pixels of the region R.
    pub region_pixels: u64,
    /// Variance of the background's pixel noise, grey levels².
    pub background_variance: f64,
    /// Variance of Σ_R b from the background fit's uncertainty, (grey levels × pixels)².
    pub fit_variance: f64,
    /// Mean background level over R, grey levels.
    pub background_level: f64,
    /// The contact's deep interior, when it has [`MIN_PLATEAU_TILES`] tiles.
    pub plateau: Option<Plateau>,
    /// Seed tiles found by their light alone (fewer than half their pixels above the threshold).
    pub faint_tiles: usize,
    /// The brightest tile mean excess over the seeds, grey levels.
    pub peak: f64,
}

impl LightBudget {
    /// Whether it holds contact light to correct an area with (a positive excess; the series
    /// model skips a budget without: [`super::corrected`]).
    pub fn has_light(&self) -> bool {
        self.excess > 0.0
    }
}

/// The pixel noise over `tiles` (at most [`NOISE_TILES`] of them, evenly spaced): the median of
/// their within-tile variances (full, finite tiles only), corrected to the mean; `None` without
/// any.
fn noise_variance(plane: &Plane, tw: usize, tiles: &[usize]) -> Option<f64> {
    let step = tiles.len().div_ceil(NOISE_TILES).max(1);
    let w = plane.width;
    let variances: Vec<f64> = tiles
        .iter()
        .step_by(step)
        .filter_map(|&k| {
            let (x0, y0) = (k % tw * TILE, k / tw * TILE);
            if x0 + TILE > w || y0 + TILE > plane.height {
                return None;
            }
            let (mut s, mut q) = (0.0, 0.0);
            for y in y0..y0 + TILE {
                for x in x0..x0 + TILE {
                    let v = plane.value(y * w + x);
                    s += v;
                    q += v * v;
                }
            }
            let n = TILE_PIXELS as f64;
            let var = (q - s * s / n) / (n - 1.0);
            var.is_finite().then_some(var.max(0.0))
        })
        .collect();
    super::interval::median(variances).map(|m| m / CHI2_15_MEDIAN)
}

/// A smooth background b(x, y) = Σ θ_j·φ_j(x, y), the basis in coordinates scaled to [−1, 1].
#[derive(Debug, Clone)]
struct Background {
    theta: [f64; 6],
    cov: DMatrix<f64>,
    terms: usize,
    scale: (f64, f64),
    variance: f64,
}

impl Background {
    fn basis((sx, sy): (f64, f64), x: f64, y: f64) -> [f64; 6] {
        let (u, v) = (x * sx - 1.0, y * sy - 1.0);
        [1.0, u, v, u * u, u * v, v * v]
    }

    fn at(&self, x: f64, y: f64) -> f64 {
        let phi = Self::basis(self.scale, x, y);
        phi.iter().zip(&self.theta).map(|(p, t)| p * t).sum()
    }

    /// The level at the centre of every tile, row by row: in each row the surface is a
    /// quadratic in u.
    fn at_tiles(&self, xs: &[f64], ys: &[f64]) -> Vec<f64> {
        let t = &self.theta;
        let us: Vec<f64> = xs.iter().map(|x| x * self.scale.0 - 1.0).collect();
        let mut out = Vec::with_capacity(xs.len() * ys.len());
        for &y in ys {
            let v = y * self.scale.1 - 1.0;
            let (c0, c1, c2) = (t[0] + t[2] * v + t[5] * v * v, t[1] + t[4] * v, t[3]);
            out.extend(us.iter().map(|&u| c0 + u * (c1 + u * c2)));
        }
        out
    }
}

/// Centres of the tiles along one axis of `n` pixels, pixels.
fn tile_centres(n: usize) -> Vec<f64> {
    (0..n.div_ceil(TILE))
        .map(|t| (t * TILE + ((t + 1) * TILE).min(n)) as f64 / 2.0)
        .collect()
}

/// Chebyshev dilation of `set` on a `w × h` grid by `r` cells: a pass along the rows and one
/// along the columns, each forwards and backwards with the distance to the last set cell.
fn dilate(set: &[bool], w: usize, h: usize, r: usize) -> Vec<bool> {
    if r == 0 || w == 0 || h == 0 {
        return set.to_vec();
    }
    let r = r.min(u16::MAX as usize - 1) as u16;
    let far = u16::MAX;
    let mut rows = vec![false; w * h];
    for (line, out) in set.chunks(w).zip(rows.chunks_mut(w)) {
        let mut d = far;
        for (o, &v) in out.iter_mut().zip(line) {
            d = if v { 0 } else { d.saturating_add(1) };
            *o = d <= r;
        }
        d = far;
        for (o, &v) in out.iter_mut().zip(line).rev() {
            d = if v { 0 } else { d.saturating_add(1) };
            *o |= d <= r;
        }
    }
    let mut out = vec![false; w * h];
    let mut d = vec![far; w];
    for (line, o) in rows.chunks(w).zip(out.chunks_mut(w)) {
        for ((d, o), &v) in d.iter_mut().zip(o.iter_mut()).zip(line) {
            *d = if v { 0 } else { d.saturating_add(1) };
            *o = *d <= r;
        }
    }
    d.fill(far);
    for (line, o) in rows.chunks(w).zip(out.chunks_mut(w)).rev() {
        for ((d, o), &v) in d.iter_mut().zip(o.iter_mut()).zip(line) {
            *d = if v { 0 } else { d.saturating_add(1) };
            *o |= *d <= r;
        }
    }
    out
}

/// Sums over the 3 × 3 neighbourhood of every cell of a `w × h` grid (cells beyond it count 0).
fn box3(v: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mut rows = vec![0.0; w * h];
    for (line, out) in v.chunks(w).zip(rows.chunks_mut(w)) {
        out.copy_from_slice(line);
        for x in 1..w {
            out[x] += line[x - 1];
        }
        for x in 0..w - 1 {
            out[x] += line[x + 1];
        }
    }
    let mut out = rows.clone();
    for y in 0..h {
        let target = &mut out[y * w..(y + 1) * w];
        if y > 0 {
            for (o, r) in target.iter_mut().zip(&rows[(y - 1) * w..y * w]) {
                *o += r;
            }
        }
        if y + 1 < h {
            for (o, r) in target.iter_mut().zip(&rows[(y + 1) * w..(y + 2) * w]) {
                *o += r;
            }
        }
    }
    out
}

/// The 16 × 16 pixel blocks of the tile sums: pixels, sums, and whether any tile of the block
/// is a seed.
struct Blocks<'a> {
    bw: usize,
    bh: usize,
    n: &'a [f64],
    sum: &'a [f64],
    contact: Vec<bool>,
}

impl<'a> Blocks<'a> {
    fn of(t: &'a TileSums) -> Blocks<'a> {
        Blocks {
            bw: t.bw,
            bh: t.bh,
            n: &t.block_n,
            sum: &t.block_sum,
            contact: t.block_contact.iter().map(|&c| c >= SEED_PIXELS).collect(),
        }
    }

    /// Centre of block `k`, pixels.
    fn centre(&self, k: usize, plane: &Plane) -> (f64, f64) {
        let block_px = (BLOCK_TILES * TILE) as f64;
        let (bx, by) = ((k % self.bw) as f64, (k / self.bw) as f64);
        let x1 = ((bx + 1.0) * block_px).min(plane.width as f64);
        let y1 = ((by + 1.0) * block_px).min(plane.height as f64);
        ((bx * block_px + x1) / 2.0, (by * block_px + y1) / 2.0)
    }
}

/// Fit the background to the blocks that are not `near` contact (module docs); `None` without
/// any.
fn fit_background(plane: &Plane, t: &TileSums, b: &Blocks, near: &[bool]) -> Option<Background> {
    let (bw, bn, bs) = (b.bw, b.n, b.sum);
    let full = (BLOCK_TILES * BLOCK_TILES * TILE_PIXELS / 2) as f64;
    let far: Vec<usize> = (0..b.bw * b.bh)
        .filter(|&k| bn[k] >= full && !near[k])
        .collect();
    if far.is_empty() {
        return None;
    }
    // The pixel noise from the tiles of the far blocks (one tile per block, the blocks evenly
    // spaced, at most NOISE_TILES).
    let tiles: Vec<usize> = far
        .iter()
        .step_by(far.len().div_ceil(NOISE_TILES).max(1))
        .map(|&b| {
            (b / bw * BLOCK_TILES + 1).min(t.th - 1) * t.tw
                + (b % bw * BLOCK_TILES + 1).min(t.tw - 1)
        })
        .collect();
    let variance = noise_variance(plane, t.tw, &tiles)?;
    let scale = (
        2.0 / plane.width.max(1) as f64,
        2.0 / plane.height.max(1) as f64,
    );
    // Each far block's basis, weight and mean, once.
    let rows: Vec<([f64; 6], f64, f64)> = far
        .iter()
        .map(|&k| {
            let (cx, cy) = b.centre(k, plane);
            (Background::basis(scale, cx, cy), bn[k], bs[k] / bn[k])
        })
        .collect();
    let mut used = vec![true; rows.len()];
    let mut fit = None;
    for _ in 0..4 {
        let count = used.iter().filter(|&&u| u).count();
        let terms = match count {
            n if n >= 40 => 6,
            n if n >= 8 => 3,
            _ => 1,
        };
        let (mut xtwx, mut xtwy) = ([[0.0f64; 6]; 6], [0.0f64; 6]);
        for ((phi, w, y), _) in rows.iter().zip(&used).filter(|(_, &u)| u) {
            for i in 0..terms {
                xtwy[i] += w * phi[i] * y;
                for j in i..terms {
                    xtwx[i][j] += w * phi[i] * phi[j];
                }
            }
        }
        let normal = DMatrix::from_fn(terms, terms, |i, j| xtwx[i.min(j)][i.max(j)]);
        let inverse = normal.try_inverse()?;
        let solved = &inverse * DVector::from_row_slice(&xtwy[..terms]);
        let mut theta = [0.0; 6];
        theta[..terms].copy_from_slice(solved.as_slice());
        let residual =
            |phi: &[f64; 6], y: f64| y - phi.iter().zip(&theta).map(|(p, t)| p * t).sum::<f64>();
        // The misfit beyond the pixel noise inflates the covariance.
        let chi2: f64 = rows
            .iter()
            .zip(&used)
            .filter(|(_, &u)| u)
            .map(|((phi, w, y), _)| w * residual(phi, *y).powi(2))
            .sum();
        let dof = (count as f64 - terms as f64).max(1.0);
        let per_pixel = (chi2 / dof).max(variance);
        fit = Some(Background {
            theta,
            cov: inverse * per_pixel,
            terms,
            scale,
            variance,
        });
        // Blocks off by more than five of their standard errors are dropped and the fit
        // repeated.
        let mut dropped = 0;
        for ((phi, w, y), u) in rows.iter().zip(used.iter_mut()) {
            if *u && residual(phi, *y).abs() > 5.0 * (per_pixel / w).sqrt() {
                *u = false;
                dropped += 1;
            }
        }
        if dropped == 0 || count - dropped < 4 {
            break;
        }
    }
    fit
}

/// The light budget of `plane` from its tile sums at the series threshold
/// ([`crate::measure::measure_with_tiles`]), for a PSF of standard deviation `sigma_px` pixels
/// (an upper estimate when it is not known). `None` without light or without background blocks.
pub fn light_budget(plane: &Plane, t: &TileSums, sigma_px: f64) -> Option<LightBudget> {
    let (w, h) = (plane.width, plane.height);
    if w == 0 || h == 0 || t.tw != w.div_ceil(TILE) || t.th != h.div_ceil(TILE) {
        return None;
    }
    let (tw, th) = (t.tw, t.th);
    let reach_px = (3.0 * sigma_px.max(0.3) + 1.0).ceil() as usize;
    let reach = reach_px.div_ceil(TILE);
    let blocks = Blocks::of(t);
    // Blocks within the light's reach of contact do not enter the background.
    let near = dilate(
        &blocks.contact,
        blocks.bw,
        blocks.bh,
        (reach + 1).div_ceil(BLOCK_TILES),
    );
    let background = fit_background(plane, t, &blocks, &near)?;
    // The window where light lies: contact tiles and blocks whose own light is significant
    // (faint patches far from the contact), with room for the light to reach out.
    let z2 = DETECTION_SD * DETECTION_SD * background.variance;
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    let mut include = |tx0: usize, ty0: usize, tx1: usize, ty1: usize| {
        x0 = x0.min(tx0);
        y0 = y0.min(ty0);
        x1 = x1.max(tx1);
        y1 = y1.max(ty1);
    };
    for k in 0..blocks.bw * blocks.bh {
        let (cx, cy) = blocks.centre(k, plane);
        let e = blocks.sum[k] - blocks.n[k] * background.at(cx, cy);
        if blocks.contact[k] || (e > 0.0 && e * e > z2 * blocks.n[k]) {
            let (bx, by) = (k % blocks.bw * BLOCK_TILES, k / blocks.bw * BLOCK_TILES);
            include(bx, by, bx + BLOCK_TILES - 1, by + BLOCK_TILES - 1);
        }
    }
    if x0 == usize::MAX {
        return None;
    }
    let pad = reach + 1;
    let (x0, y0) = (x0.saturating_sub(pad), y0.saturating_sub(pad));
    let (x1, y1) = ((x1 + pad).min(tw - 1), (y1 + pad).min(th - 1));
    let win = Window::new(t, (x0, y0, x1 - x0 + 1, y1 - y0 + 1));
    let (ww, wh) = (win.w, win.h);
    let xs: Vec<f64> = tile_centres(w)[x0..=x1].to_vec();
    let ys: Vec<f64> = tile_centres(h)[y0..=y1].to_vec();
    let level = background.at_tiles(&xs, &ys);
    let excess: Vec<f64> = win
        .sum
        .iter()
        .zip(&win.n)
        .zip(&level)
        .map(|((s, n), l)| s - n * l)
        .collect();
    // Light: the excess of each 3 × 3 neighbourhood of tiles against its standard error.
    let (e3, n3) = (box3(&excess, ww, wh), box3(&win.n, ww, wh));
    let seeds: Vec<bool> = e3
        .iter()
        .zip(&n3)
        .zip(&win.contact)
        .map(|((&e, &n), &c)| c >= SEED_PIXELS || (e > 0.0 && e * e > z2 * n))
        .collect();
    if !seeds.contains(&true) {
        return None;
    }
    let faint_tiles = seeds
        .iter()
        .zip(&win.contact)
        .filter(|(&s, &c)| s && c < SEED_PIXELS)
        .count();
    let region = dilate(&seeds, ww, wh, reach);
    let (mut m, mut n_region, mut bg_sum, mut peak) = (0.0, 0.0, 0.0, f64::NEG_INFINITY);
    let mut basis_sum = [0.0f64; 6];
    let us: Vec<f64> = xs.iter().map(|x| x * background.scale.0 - 1.0).collect();
    for (ty, &y) in ys.iter().enumerate() {
        // Σ n·(1, u, u²) over the row's region tiles, then times the v terms.
        let (mut r0, mut r1, mut r2) = (0.0, 0.0, 0.0);
        let k0 = ty * ww;
        for (tx, &u) in us.iter().enumerate() {
            let k = k0 + tx;
            if region[k] {
                let n = win.n[k];
                m += excess[k];
                bg_sum += n * level[k];
                r0 += n;
                r1 += n * u;
                r2 += n * u * u;
                if seeds[k] && n > 0.0 {
                    peak = peak.max(excess[k] / n);
                }
            }
        }
        n_region += r0;
        let v = y * background.scale.1 - 1.0;
        for (j, value) in [r0, r1, r0 * v, r2, r1 * v, r0 * v * v]
            .into_iter()
            .enumerate()
        {
            basis_sum[j] += value;
        }
    }
    let terms = background.terms;
    let a = DVector::from_row_slice(&basis_sum[..terms]);
    let fit_variance = (a.transpose() * &background.cov * &a)[(0, 0)].max(0.0);
    Some(LightBudget {
        excess: m,
        region_pixels: n_region as u64,
        background_variance: background.variance,
        fit_variance,
        background_level: if n_region > 0.0 {
            bg_sum / n_region
        } else {
            f64::NAN
        },
        plateau: plateau(plane, &win, &excess, reach),
        faint_tiles,
        peak,
    })
}

/// A rectangle of tiles copied out of [`Tiles`], with the image's tile index of its corner.
struct Window {
    w: usize,
    h: usize,
    /// The image's tiles per row, and the window's corner tile (x, y).
    tw: usize,
    corner: (usize, usize),
    n: Vec<f64>,
    sum: Vec<f64>,
    contact: Vec<u8>,
}

impl Window {
    fn new(t: &TileSums, (x0, y0, w, h): (usize, usize, usize, usize)) -> Window {
        let rows = y0..y0 + h;
        let pick = |v: &[f64]| -> Vec<f64> {
            rows.clone()
                .flat_map(|y| v[y * t.tw + x0..y * t.tw + x0 + w].iter().copied())
                .collect()
        };
        Window {
            w,
            h,
            tw: t.tw,
            corner: (x0, y0),
            n: pick(&t.n),
            sum: pick(&t.sum),
            contact: rows
                .clone()
                .flat_map(|y| t.contact[y * t.tw + x0..y * t.tw + x0 + w].iter().copied())
                .collect(),
        }
    }

    /// The image's tile index of window tile `k`.
    fn image_tile(&self, k: usize) -> usize {
        (self.corner.1 + k / self.w) * self.tw + self.corner.0 + k % self.w
    }
}

/// The plateau (module docs): tiles at least three-quarters contact whose neighbours within
/// `reach` tiles are too.
fn plateau(plane: &Plane, t: &Window, excess: &[f64], reach: usize) -> Option<Plateau> {
    let not_full: Vec<bool> = t.contact.iter().map(|&c| c < FULL_PIXELS).collect();
    let edge = dilate(&not_full, t.w, t.h, reach);
    let interior: Vec<usize> = (0..t.w * t.h)
        .filter(|&k| !edge[k] && t.n[k] == TILE_PIXELS as f64)
        .collect();
    if interior.len() < MIN_PLATEAU_TILES {
        return None;
    }
    let px = (interior.len() * TILE_PIXELS) as f64;
    let level = interior.iter().map(|&k| excess[k]).sum::<f64>() / px;
    let image_tiles: Vec<usize> = interior.iter().map(|&k| t.image_tile(k)).collect();
    let white = noise_variance(plane, t.tw, &image_tiles)?;
    let mut means: Vec<f64> = interior
        .iter()
        .map(|&k| excess[k] / TILE_PIXELS as f64)
        .collect();
    let spread = means.iter().map(|v| (v - level).powi(2)).sum::<f64>()
        / (means.len() as f64 - 1.0).max(1.0);
    let texture = (spread - white / TILE_PIXELS as f64).max(0.0);
    let k = ((means.len() - 1) as f64 * 0.9).round() as usize;
    let (_, q90, _) = means.select_nth_unstable_by(k, f64::total_cmp);
    Some(Plateau {
        level,
        tiles: interior.len(),
        pixels: px as u64,
        white_variance: white,
        texture_variance: texture,
        tile_q90: *q90,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dilation_is_chebyshev() {
        let mut set = vec![false; 7 * 5];
        set[2 * 7 + 3] = true;
        let d = dilate(&set, 7, 5, 1);
        assert_eq!(d.iter().filter(|&&v| v).count(), 9);
        assert!(d[7 + 2] && d[3 * 7 + 4] && !d[3]);
        let d2 = dilate(&set, 7, 5, 2);
        assert_eq!(d2.iter().filter(|&&v| v).count(), 25);
    }

    #[test]
    fn box_sums_count_the_neighbourhood() {
        let v = vec![1.0; 4 * 3];
        let b = box3(&v, 4, 3);
        assert_eq!(b[0], 4.0);
        assert_eq!(b[5], 9.0);
        assert_eq!(b[3], 4.0);
        assert_eq!(b[4], 6.0);
    }
}
