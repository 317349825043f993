//! Seeded synthetic bead images and stacks with known PSF, for tests and demonstrations.
//!
//! Each bead is a Gaussian spot of in-focus σ0 at a random sub-pixel position (at least
//! `min_separation_px` from every other bead and `margin_px` from the edges). Across the planes
//! of a stack it defocuses as a Gaussian beam, σ(z) = σ0·√(1 + (z/z_R)²), with its peak scaled
//! by σ0²/σ(z)² so that the integrated intensity is the same on every plane; each bead's focus
//! is an interior plane drawn at random. Values are the background plus the spots, with
//! Poisson shot noise (one count per photon) if asked, rounded and clipped to `max_code`.
//!
//! Sampling: [`Sampling::Point`] evaluates the Gaussian at pixel centres (σ is recovered
//! exactly); [`Sampling::Integrated`] averages it over each pixel's area (8 × 8 sub-samples),
//! as a camera pixel does, which widens the imaged spot to σ² + 1/12 px².

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Poisson};

use crate::error::{Error, Result};

/// How a spot is turned into pixel values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sampling {
    /// Value at the pixel centre.
    Point,
    /// Mean over the pixel's square (σ² grows by 1/12 px²).
    Integrated,
}

/// Parameters of a synthetic bead image or stack.
#[derive(Debug, Clone, PartialEq)]
pub struct BeadParams {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Planes (1 for a single image).
    pub planes: usize,
    /// Isolated beads.
    pub beads: usize,
    /// In-focus σ0 in pixels.
    pub sigma_px: f64,
    /// In-focus peak above the background, counts.
    pub peak: f64,
    /// Background, counts.
    pub background: f64,
    /// Rayleigh range z_R in planes (defocus length of the spot).
    pub rayleigh_planes: f64,
    /// Point or pixel-integrated sampling.
    pub sampling: Sampling,
    /// Poisson shot noise, one count per photon.
    pub noise: bool,
    /// Highest code (clipping level), e.g. 4095 for 12-bit data.
    pub max_code: u16,
    /// Smallest distance between beads that are not meant to be crowded, pixels.
    pub min_separation_px: f64,
    /// Smallest distance of a bead from the image edge, pixels.
    pub margin_px: f64,
    /// Add two beads 3.5 σ0 apart (they should be skipped as crowded).
    pub crowded_pair: bool,
    /// Add one bead four times brighter than `max_code` (it should be skipped as saturated).
    pub saturated_bead: bool,
    /// Random seed (ChaCha8).
    pub seed: u64,
}

impl Default for BeadParams {
    /// Six beads of σ0 = 1.91 px (191 nm at 100 nm pixels, Weber et al.'s FWHM 450 nm) on a
    /// 128² single image, 12-bit, with shot noise.
    fn default() -> Self {
        BeadParams {
            width: 128,
            height: 128,
            planes: 1,
            beads: 6,
            sigma_px: 1.91,
            peak: 1000.0,
            background: 100.0,
            rayleigh_planes: 3.0,
            sampling: Sampling::Point,
            noise: true,
            max_code: 4095,
            min_separation_px: 25.0,
            margin_px: 14.0,
            crowded_pair: false,
            saturated_bead: false,
            seed: 7,
        }
    }
}

/// What a generated bead is meant to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BeadKind {
    /// An isolated, unsaturated bead: it should be used.
    Isolated,
    /// One of the crowded pair.
    Crowded,
    /// The saturated bead.
    Saturated,
}

/// Ground truth of one bead.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeadTruth {
    /// Centre column, pixels.
    pub x_px: f64,
    /// Centre row, pixels.
    pub y_px: f64,
    /// Plane of best focus.
    pub focus_plane: usize,
    /// Its role.
    pub kind: BeadKind,
}

/// Generated planes and their truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticBeads {
    /// Planes of `width × height` codes.
    pub planes: Vec<Vec<u16>>,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// One entry per bead.
    pub truth: Vec<BeadTruth>,
}

/// Generate beads as described in the module documentation.
pub fn synth_beads(p: &BeadParams) -> Result<SyntheticBeads> {
    check(p)?;
    let mut rng = ChaCha8Rng::seed_from_u64(p.seed);
    let truth = place(p, &mut rng)?;
    let planes = (0..p.planes)
        .map(|z| render_plane(p, &truth, z, &mut rng))
        .collect::<Result<Vec<_>>>()?;
    Ok(SyntheticBeads {
        planes,
        width: p.width,
        height: p.height,
        truth,
    })
}

fn check(p: &BeadParams) -> Result<()> {
    let ok = p.width > 0
        && p.height > 0
        && p.planes > 0
        && p.sigma_px > 0.0
        && p.peak >= 0.0
        && p.background >= 0.0
        && p.rayleigh_planes > 0.0;
    if ok {
        // One f64 working plane, and the stack of 16-bit planes kept.
        let limits = crate::limits::Limits::DEFAULT;
        let limit = |source| Error::Limit {
            what: "synthetic beads".into(),
            source,
        };
        limits.plane_bytes(p.width, p.height, 8).map_err(limit)?;
        limits
            .plane_bytes(p.width, p.height, p.planes.saturating_mul(2))
            .map_err(limit)?;
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "invalid bead parameters: {p:?}"
        )))
    }
}

fn focus_plane(p: &BeadParams, rng: &mut ChaCha8Rng) -> usize {
    if p.planes >= 3 {
        rng.random_range(1..p.planes - 1)
    } else {
        0
    }
}

/// Random positions by rejection: isolated beads, then the crowded pair, then the saturated one.
fn place(p: &BeadParams, rng: &mut ChaCha8Rng) -> Result<Vec<BeadTruth>> {
    let mut placed: Vec<BeadTruth> = Vec::new();
    let mut wanted = vec![BeadKind::Isolated; p.beads];
    if p.crowded_pair {
        wanted.push(BeadKind::Crowded);
    }
    if p.saturated_bead {
        wanted.push(BeadKind::Saturated);
    }
    for kind in wanted {
        let group = (0..10_000)
            .map(|_| candidate_group(p, kind, rng))
            .find(|g| g.iter().all(|b| fits(p, b, &placed)))
            .ok_or_else(|| {
                Error::InvalidArgument(format!(
                    "cannot place {} beads {} px apart on a {}×{} image",
                    placed.len() + 1,
                    p.min_separation_px,
                    p.width,
                    p.height
                ))
            })?;
        placed.extend(group);
    }
    Ok(placed)
}

/// One bead, or two for the crowded pair (3.5 σ0 apart: resolved, but inside one window).
fn candidate_group(p: &BeadParams, kind: BeadKind, rng: &mut ChaCha8Rng) -> Vec<BeadTruth> {
    let first = BeadTruth {
        x_px: rng.random_range(0.0..p.width as f64),
        y_px: rng.random_range(0.0..p.height as f64),
        focus_plane: focus_plane(p, rng),
        kind,
    };
    if kind != BeadKind::Crowded {
        return vec![first];
    }
    let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let d = 3.5 * p.sigma_px;
    let second = BeadTruth {
        x_px: first.x_px + d * angle.cos(),
        y_px: first.y_px + d * angle.sin(),
        ..first
    };
    vec![first, second]
}

fn fits(p: &BeadParams, b: &BeadTruth, placed: &[BeadTruth]) -> bool {
    let m = p.margin_px;
    let inside = b.x_px >= m
        && b.y_px >= m
        && b.x_px <= p.width as f64 - 1.0 - m
        && b.y_px <= p.height as f64 - 1.0 - m;
    inside
        && placed
            .iter()
            .all(|o| (o.x_px - b.x_px).hypot(o.y_px - b.y_px) >= p.min_separation_px)
}

fn render_plane(
    p: &BeadParams,
    truth: &[BeadTruth],
    z: usize,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<u16>> {
    let mut signal = vec![0.0; p.width * p.height];
    for b in truth {
        let dz = (z as f64 - b.focus_plane as f64) / p.rayleigh_planes;
        let sigma = p.sigma_px * (1.0 + dz * dz).sqrt();
        let brightness = if b.kind == BeadKind::Saturated {
            4.0 * f64::from(p.max_code)
        } else {
            p.peak
        };
        let peak = brightness * (p.sigma_px / sigma).powi(2);
        add_spot(p, &mut signal, (b.x_px, b.y_px), sigma, peak);
    }
    signal
        .iter()
        .map(|s| {
            let expected = p.background + s;
            let value = if p.noise && expected > 0.0 {
                Poisson::new(expected)
                    .map_err(|e| Error::InvalidArgument(format!("shot noise: {e}")))?
                    .sample(rng)
            } else {
                expected
            };
            Ok(value.round().clamp(0.0, f64::from(p.max_code)) as u16)
        })
        .collect()
}

/// Add one spot, evaluated out to 6σ.
fn add_spot(p: &BeadParams, signal: &mut [f64], (cx, cy): (f64, f64), sigma: f64, peak: f64) {
    let reach = 6.0 * sigma;
    let x_range = ((cx - reach).floor().max(0.0) as usize)
        ..=((cx + reach).ceil().min(p.width as f64 - 1.0) as usize);
    let y_range = ((cy - reach).floor().max(0.0) as usize)
        ..=((cy + reach).ceil().min(p.height as f64 - 1.0) as usize);
    let g = |x: f64, y: f64| (-((x - cx).powi(2) + (y - cy).powi(2)) / (2.0 * sigma * sigma)).exp();
    for y in y_range {
        for x in x_range.clone() {
            let v = match p.sampling {
                Sampling::Point => g(x as f64, y as f64),
                Sampling::Integrated => pixel_mean(&g, x as f64, y as f64),
            };
            signal[y * p.width + x] += peak * v;
        }
    }
}

/// Mean of `g` over the pixel centred at (x, y), midpoint rule on 8 × 8 sub-pixels.
fn pixel_mean(g: &impl Fn(f64, f64) -> f64, x: f64, y: f64) -> f64 {
    const N: usize = 8;
    let offset = |k: usize| (k as f64 + 0.5) / N as f64 - 0.5;
    let sum: f64 = (0..N)
        .flat_map(|i| (0..N).map(move |j| (i, j)))
        .map(|(i, j)| g(x + offset(i), y + offset(j)))
        .sum();
    sum / (N * N) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beads_keep_their_distance_and_margins() {
        let p = BeadParams {
            crowded_pair: true,
            saturated_bead: true,
            ..BeadParams::default()
        };
        let s = synth_beads(&p).unwrap();
        assert_eq!(s.truth.len(), p.beads + 3);
        let crowded: Vec<_> = s
            .truth
            .iter()
            .filter(|b| b.kind == BeadKind::Crowded)
            .collect();
        let d = (crowded[0].x_px - crowded[1].x_px).hypot(crowded[0].y_px - crowded[1].y_px);
        assert!((d - 3.5 * p.sigma_px).abs() < 1e-9);
        let sat = s
            .truth
            .iter()
            .find(|b| b.kind == BeadKind::Saturated)
            .unwrap();
        let (x, y) = (sat.x_px.round() as usize, sat.y_px.round() as usize);
        assert_eq!(s.planes[0][y * p.width + x], p.max_code);
    }

    #[test]
    fn defocus_dims_and_same_seed_repeats() {
        let p = BeadParams {
            planes: 9,
            noise: false,
            beads: 2,
            ..BeadParams::default()
        };
        let s = synth_beads(&p).unwrap();
        assert_eq!(s, synth_beads(&p).unwrap());
        let b = s.truth[0];
        let at =
            |z: usize| s.planes[z][b.y_px.round() as usize * p.width + b.x_px.round() as usize];
        let focus = at(b.focus_plane);
        assert!((0..9).all(|z| at(z) <= focus));
        assert!(at(b.focus_plane + 1) < focus);
    }

    #[test]
    fn too_many_beads_is_an_error() {
        let p = BeadParams {
            beads: 200,
            ..BeadParams::default()
        };
        assert!(synth_beads(&p).is_err());
    }
}
