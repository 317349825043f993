//! The contact area from the light it gives, with a 95 % interval that carries what imaging does
//! to a contact (`docs/methods.md`, "Corrected areas from the light budget").
//!
//! Each image's light budget ([`super::light`]) holds M = s·A + noise: the true area A times the
//! contact signal s, whatever the PSF did to the patches (shrunk, vanished, bridged: the light
//! stays). A = M/s once s is known; this module finds what the series says about s at every
//! load and propagates it, with the light's own noise, to each area and to the fits.
//!
//! **Readings of the signal.** Where a contact has a deep interior (contact farther than
//! 3σ_PSF + 1 px from any edge), the blurred image is the signal itself, unless holes narrower
//! than the PSF darken it (a hole below the PSF and a dimmer spot look the same). Two readings:
//! the **top** (the 90th percentile of the PSF-smoothed interior less 1.2816 standard deviations
//! of its smoothed white noise: what is not dark is contact) and the **mean**. The signal is
//! taken to lie between the mean and an upper reading, uniformly in ln s: the top raised by
//! [`Assumptions::porosity`] times the interior's relative texture (the more its darkness varies,
//! the less sure the top is), or the mean raised by the **hidden porosity** if that is higher.
//! Holes far below the PSF darken an interior almost evenly: a fill fraction f of holes whose
//! indicator has correlation area a_h, blurred by the PSF and averaged over a tile, leaves
//! tile means of relative spread τ² = (1 − f)/f · a_h/A_eff, A_eff = 4π(σ² + T²/12) the area
//! the PSF and the T × T tile average over. Holes no smaller than [`Assumptions::hole_area_um2`]
//! then darken the interior by at most 1/f = 1 + τ²·A_eff/a_h: the finer the holes the PSF
//! hides, the more a little texture stands for. The image cannot tell such holes from coarser
//! ones (or from a signal that varies over the PSF's width): the range is the worst case.
//!
//! **From load to load.** The signal is one property of the coverslip and the detector; it rises
//! modestly with load (Weber et al. 2018, Supplementary Fig. 1c). Between loads it is taken as
//! s(N) = s(N_ref)·(N/N_ref)^γ, γ uniform in [[`Assumptions::gamma_min`],
//! [`Assumptions::gamma_max`]] (one γ for the whole series), N_ref the heaviest load with a
//! reading (the most compact contact: holes close with load, so its interior is the least
//! darkened); every image takes that reading carried by γ, and never less than its own
//! interior's mean. γ's upper end is lowered to the fastest rise that a lighter load's own
//! interior allows — the largest of those rises, not the smallest: the signal's trend need not be
//! a power law (one that rises 15 % per decade, linear in log N, climbs at γ ≈ 0.065 at the
//! lightest loads and 0.05 at the heaviest), and the images that have an interior are held above
//! its mean draw by draw anyway. Two bounds hold whatever the model: the signal is at least the
//! image's brightest smoothed excess less five standard deviations of its noise (no pixel is
//! brighter than full contact), and at most the detector's ceiling less the background (a lab
//! sets the gain so that contact does not saturate, Methods). A series without any interior has
//! no reading: its signal is only bounded, log-uniformly between the two, and the intervals say
//! so by their width.
//!
//! **Propagation.** [`SeriesLight::draws`] draws everything at once, [`DRAWS`] times, seeded:
//! one γ, each reading's place in its range and its statistical error, each image's light noise.
//! An image's interval is the 2.5th and 97.5th percentiles of its drawn areas; the fits'
//! bootstrap ([`super::bootstrap`]) refits the same joint draws, so that an error shared by the
//! loads or trending with them (the signal's) moves the exponent as it does the areas.
//!
//! **The estimate.** The corrected area is the light over the signal the readings give: the top
//! reading of the image's own interior, or the reference's carried by γ at the middle of its
//! range (a series without a reading: the middle of its bounds, in ln), held within the
//! interval. The allowance above the top reading (texture, hidden porosity) bounds what the
//! image cannot show; it is not evidence of a higher signal. The drawn areas' median, which
//! spreads it evenly, read the true areas up to 26 % low where it is wide (median errors per
//! cell and load rank on both generators of `docs/validation.md` B25); the readings, −6…+6 %.
//!
//! **A glow instead of an interior** (not carried, not warned of). A cloud of patches below the
//! PSF at every load blurs into a glow as bright as its local fill fraction; its deep tiles
//! pass for an interior and every area of the series comes out too large (the `cloud` stress
//! case of `docs/validation.md` B25: about twice). A contact in full contact reads flat over its
//! interior, a glow follows the pressure, so the reference interior's top reading over its mean
//! ([`SeriesLight::reference_interior`]) was tried as a warning: 1.00–1.42 on the cloud, up to
//! 1.13 on the paper's own porous contacts at 500 photons, and no threshold warns of the
//! clouds without warning of some of the paper's contacts, so no warning is given (B25, "A
//! glow instead of an interior"). The rise of the readings with load separates them no
//! better.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rayon::prelude::*;

use super::light::LightBudget;
use super::Analysis;
use crate::image::SampleType;

/// The PSF's FWHM taken when it is not known: wider than a confocal microscope's at visible
/// wavelengths (the paper's is 450 nm), so that the light's region and the plateau's depth are
/// drawn generously, m.
pub const UNKNOWN_PSF_FWHM_M: f64 = 1.0e-6;

/// Joint draws of the propagation.
pub const DRAWS: usize = 2000;

/// Seed of the draws.
const SEED: u64 = 41;

/// Relative standard deviation of the signal over a contact against the signal where it was
/// read: the illumination varies across the field (a few per cent from corner to corner, the
/// contact sits in part of it).
const ILLUMINATION_SD: f64 = 0.01;

/// Standard deviations of smoothed noise the brightest smoothed pixel is lowered by before it
/// bounds the signal (the largest of many correlated noise values).
const PEAK_NOISE_SD: f64 = 5.0;

/// What the series model takes for granted (module docs), each a number a user can change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Assumptions {
    /// Smallest exponent γ of s ∝ N^γ.
    pub gamma_min: f64,
    /// Largest exponent γ.
    pub gamma_max: f64,
    /// How far above the top reading the signal may lie, in units of the interior's relative
    /// texture.
    pub porosity: f64,
    /// The smallest correlation area of an interior's holes, µm² (module docs: the hidden
    /// porosity). The reasoning: a hole much narrower than about 100 nm opens by roughly the
    /// surface's slope times its width, a few nanometres, within the rigidochromic detection gap
    /// (9 nm, Weber et al. 2018), and fluoresces as contact (an estimate, not measured). The
    /// value sits below the 0.011 µm² the solver-made sub-PSF contacts of seeds 0–19 needed
    /// (`docs/validation.md` B25) and was checked on seeds 20–39. Without a pixel size it is
    /// taken as [`HOLE_SHARE_OF_PSF`] of the PSF's area 4πσ².
    pub hole_area_um2: f64,
}

/// The holes' correlation area against the PSF's area 4πσ² when the pixel size is unknown: the
/// 0.01 µm² of [`Assumptions::hole_area_um2`] against the 0.46 µm² of a 450 nm FWHM.
pub const HOLE_SHARE_OF_PSF: f64 = 0.02;

impl Default for Assumptions {
    /// γ in [0, 0.10] (the signal does not fall with load, and rises by at most 26 % per decade);
    /// porosity 2.5; holes of at least 0.01 µm² (about 110 nm across).
    fn default() -> Self {
        Assumptions {
            gamma_min: 0.0,
            gamma_max: 0.10,
            porosity: 2.5,
            hole_area_um2: 0.01,
        }
    }
}

/// One image as the series model sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageLight {
    /// Normal force, N; `None` when unknown (the image can then only use its own reading).
    pub force_n: Option<f64>,
    /// Its light budget; `None` without contact.
    pub budget: Option<LightBudget>,
    /// The largest signal the detector can record over this image's background (the ceiling
    /// of its codes less the background), grey levels; `None` for float data.
    pub ceiling: Option<f64>,
}

/// Where an image's signal comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SignalSource {
    /// Its own interior.
    Own,
    /// The interior of image `0` (index in the series), carried by γ.
    Image(usize),
    /// No image of the series has an interior: only the bounds.
    Bounds,
}

/// One image's corrected area and interval, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectedArea {
    /// The corrected area: the light over the signal the readings give (module docs, "The
    /// estimate"), within the interval.
    pub area_px: f64,
    /// Lower end of the 95 % interval.
    pub lo_px: f64,
    /// Upper end.
    pub hi_px: f64,
    /// The signal the corrected area is taken at (the light over it), grey levels.
    pub signal: f64,
    /// Where the signal comes from.
    pub source: SignalSource,
}

/// The interior that sets a series' signal ([`SeriesLight::reference_interior`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceInterior {
    /// Index of its image in the series.
    pub image: usize,
    /// Its top reading over its mean (1 for a flat interior).
    pub top_over_mean: f64,
}

/// A reading of the signal: ln of its range's lower end, the range's width in ln, and the
/// standard error of ln.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reading {
    ln_low: f64,
    ln_width: f64,
    ln_se: f64,
    /// ln of the top reading itself (inside the range).
    ln_top: f64,
}

/// The series' light and signal, ready to be drawn from.
#[derive(Debug, Clone)]
pub struct SeriesLight {
    assumptions: Assumptions,
    /// Per image: M and its standard deviation, the bounds on ln s, and the source.
    images: Vec<Option<ImagePlan>>,
    readings: Vec<Option<Reading>>,
    /// The image whose interior sets the signal (the heaviest load with a reading); without
    /// forces, where each image takes its own, the one with the most light
    /// ([`SeriesLight::reference_interior`]).
    reference: Option<usize>,
    /// The largest γ the readings allow (module docs).
    gamma_up: f64,
    /// The detector's gain estimated from the plateaus (variance per grey level of signal).
    pub gain: f64,
}

#[derive(Debug, Clone, Copy)]
struct ImagePlan {
    light: f64,
    light_sd: f64,
    /// ln of the lowest signal the image allows: its brightest tile less its noise, and its own
    /// plateau's mean (no reading of another load can put the signal below what this image's
    /// interior shows).
    ln_floor: f64,
    ln_ceiling: f64,
    source: SignalSource,
    /// ln(N_i/N_ref) for a reading carried from another image.
    distance: f64,
}

impl ImagePlan {
    /// ln of the highest signal a series without any reading allows: the ceiling, or for float
    /// data without one ten times the floor.
    fn ln_top_bound(&self) -> f64 {
        if self.ln_ceiling.is_finite() {
            self.ln_ceiling
        } else {
            self.ln_floor + 10f64.ln()
        }
    }
}

/// The texture of an interior is correlated over about the PSF's area: 4πσ² pixels.
fn correlated_pixels(sigma_px: f64) -> f64 {
    4.0 * std::f64::consts::PI * sigma_px.max(0.5).powi(2)
}

/// The darkening 1/f − 1 that holes of correlation area `hole_px` (pixels) may hide behind a
/// relative tile texture `texture` under a PSF of `sigma_px` (module docs: τ²·A_eff/a_h).
pub fn hidden_porosity(texture: f64, sigma_px: f64, hole_px: f64) -> f64 {
    let tile = super::light::TILE as f64;
    let averaged = correlated_pixels(sigma_px) + std::f64::consts::PI * tile * tile / 3.0;
    texture * texture * averaged / hole_px.max(f64::MIN_POSITIVE)
}

/// The corrected areas of a series and the joint draws behind them (for the fits' bootstrap).
#[derive(Debug, Clone)]
pub struct SeriesCorrection {
    /// Per image (input order); `None` without a light budget.
    pub areas: Vec<Option<CorrectedArea>>,
    /// [`DRAWS`] rows of one drawn area per image, pixels (NaN where `areas` is `None`).
    pub draws: Vec<Vec<f64>>,
    /// The model the draws came from.
    pub model: SeriesLight,
}

/// The ceiling of integer data's codes: 255 for 8-bit data; for 16-bit data the smallest
/// 2^b − 1 (b ≥ 8) at or above the brightest smoothed contact (a 12-bit camera's 4095 in a
/// 16-bit file); `None` for signed or float data.
fn code_ceiling(analysis: &Analysis) -> Option<f64> {
    match analysis.sample_type {
        SampleType::U8 => Some(255.0),
        SampleType::U16 => {
            let brightest = analysis
                .images
                .iter()
                .filter_map(|r| r.light)
                .map(|b| b.background_level + b.peak)
                .fold(0.0f64, f64::max);
            let bits = (brightest.max(1.0) + 1.0).log2().ceil().clamp(8.0, 16.0);
            Some(2f64.powf(bits) - 1.0)
        }
        _ => None,
    }
}

/// The corrected areas of `analysis` (module docs) with each image's force (`None`: unknown;
/// the same length as the images), under `assumptions`. Deterministic.
pub fn correct_series(
    analysis: &Analysis,
    forces_n: &[Option<f64>],
    assumptions: Assumptions,
) -> SeriesCorrection {
    let ceiling = code_ceiling(analysis);
    let lights: Vec<ImageLight> = analysis
        .images
        .iter()
        .enumerate()
        .map(|(i, r)| ImageLight {
            force_n: forces_n.get(i).copied().flatten(),
            budget: r.light,
            ceiling: ceiling.zip(r.light).map(|(c, b)| c - b.background_level),
        })
        .collect();
    let sigma_px = analysis.light_sigma_px;
    let hole_px = match analysis.pixel_size {
        Some(p) => assumptions.hole_area_um2 / p.area_um2(),
        None => HOLE_SHARE_OF_PSF * correlated_pixels(sigma_px),
    };
    let model = SeriesLight::new(&lights, sigma_px, hole_px, assumptions);
    let draws = model.draws();
    SeriesCorrection {
        areas: model.corrected(&draws),
        draws,
        model,
    }
}

impl SeriesLight {
    /// The largest exponent γ the series' readings allow (module docs), and the assumptions.
    pub fn gamma_range(&self) -> (f64, f64) {
        (
            self.assumptions.gamma_min,
            self.gamma_up.max(self.assumptions.gamma_min),
        )
    }

    /// The assumptions the model was made with.
    pub fn assumptions(&self) -> Assumptions {
        self.assumptions
    }

    /// The interior that sets the series' signal and how flat it reads (module docs, "A glow
    /// instead of an interior"; a diagnostic): the reference image (the heaviest load with a
    /// reading; without forces, the image with the most light among those with one) and its top
    /// reading over its mean. `None` without any reading.
    pub fn reference_interior(&self) -> Option<ReferenceInterior> {
        let image = self.reference?;
        let r = self.readings[image]?;
        Some(ReferenceInterior {
            image,
            top_over_mean: (r.ln_top - r.ln_low).exp(),
        })
    }

    /// The model of a series (module docs); `sigma_px`: the PSF's standard deviation in pixels;
    /// `hole_px`: [`Assumptions::hole_area_um2`] in pixels.
    pub fn new(
        images: &[ImageLight],
        sigma_px: f64,
        hole_px: f64,
        assumptions: Assumptions,
    ) -> Self {
        let gain = estimate_gain(images);
        let readings: Vec<Option<Reading>> = images
            .iter()
            .map(|im| {
                let p = im.budget?.plateau?;
                let se = p.standard_error(correlated_pixels(sigma_px));
                let top = p.top();
                if !(top > 0.0 && p.level > 0.0) {
                    return None;
                }
                let texture = p.texture_variance.sqrt() / p.level;
                // From the mean (a signal that varies over the interior) to the top raised by
                // the texture allowance, or the mean raised by the porosity the PSF may hide.
                let raised = top / p.level * (1.0 + assumptions.porosity * texture);
                let hidden = 1.0 + hidden_porosity(texture, sigma_px, hole_px);
                Some(Reading {
                    ln_low: p.level.ln(),
                    ln_width: raised.max(hidden).ln(),
                    ln_se: se / p.level,
                    ln_top: top.ln(),
                })
            })
            .collect();
        let forces: Vec<f64> = images
            .iter()
            .map(|im| im.force_n.filter(|f| *f > 0.0).unwrap_or(f64::NAN))
            .collect();
        let reference = (0..images.len())
            .filter(|&j| readings[j].is_some() && forces[j].is_finite())
            .max_by(|&a, &b| forces[a].total_cmp(&forces[b]));
        // A lighter load's interior holds at least its mean: the signal cannot rise faster from
        // there to the reference than to the reference's highest reading. The largest of these
        // rises is the cap (module docs: a rise that slows with load is steeper over the
        // lightest loads than between the heaviest).
        let gamma_up = reference
            .and_then(|r| {
                let top = readings[r]?;
                let highest = top.ln_low + top.ln_width + 2.0 * top.ln_se;
                (0..images.len())
                    .filter(|&j| j != r && forces[j] < forces[r])
                    .filter_map(|j| {
                        let lowest = readings[j].map(|q| q.ln_low - 2.0 * q.ln_se)?;
                        let span = (forces[r] / forces[j]).ln();
                        (span > 0.0).then(|| (highest - lowest) / span)
                    })
                    .max_by(f64::total_cmp)
            })
            .unwrap_or(assumptions.gamma_max)
            .clamp(assumptions.gamma_min, assumptions.gamma_max);
        let plans = images
            .iter()
            .enumerate()
            .map(|(i, im)| {
                let b = im.budget.filter(LightBudget::has_light)?;
                let noise_var = b.region_pixels as f64 * b.background_variance
                    + gain * b.excess
                    + b.fit_variance;
                let peak_sd = ((b.background_variance + gain * b.peak.max(0.0))
                    / (super::light::TILE * super::light::TILE) as f64)
                    .sqrt();
                let own =
                    readings[i].map_or(f64::MIN_POSITIVE, |r| (r.ln_low - 2.0 * r.ln_se).exp());
                let floor = (b.peak - PEAK_NOISE_SD * peak_sd)
                    .max(own)
                    .max(f64::MIN_POSITIVE);
                let ceiling = im.ceiling.filter(|c| *c > floor).unwrap_or(f64::INFINITY);
                // The reading of the heaviest load that has one (the most compact contact:
                // holes close with load), carried by γ; without forces, the image's own.
                let (source, distance) = match (reference, im.force_n) {
                    (Some(j), Some(f)) if j == i => (SignalSource::Own, 0.0 * f),
                    (Some(j), Some(f)) => (SignalSource::Image(j), (f / forces[j]).ln()),
                    _ if readings[i].is_some() => (SignalSource::Own, 0.0),
                    _ => (SignalSource::Bounds, 0.0),
                };
                Some(ImagePlan {
                    light: b.excess,
                    light_sd: noise_var.max(0.0).sqrt(),
                    ln_floor: floor.ln(),
                    ln_ceiling: ceiling.ln(),
                    source,
                    distance,
                })
            })
            .collect();
        // Without forces, the image with the most light stands for the heaviest load.
        let reference = reference.or_else(|| {
            (0..images.len())
                .filter(|&j| readings[j].is_some())
                .max_by(|&a, &b| {
                    let light = |k: usize| images[k].budget.map_or(0.0, |b| b.excess);
                    light(a).total_cmp(&light(b))
                })
        });
        SeriesLight {
            assumptions,
            images: plans,
            readings,
            reference,
            gamma_up,
            gain,
        }
    }

    /// The joint draws (module docs): `DRAWS` rows of one area per image (pixels; NaN for an
    /// image without a budget). Deterministic.
    pub fn draws(&self) -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(SEED);
        let a = self.assumptions;
        (0..DRAWS)
            .map(|_| {
                let gamma = rng.random_range(a.gamma_min..=self.gamma_up.max(a.gamma_min));
                let illumination: f64 = rng.sample(StandardNormal);
                let ln_s: Vec<Option<f64>> = self
                    .readings
                    .iter()
                    .map(|r| {
                        let u: f64 = rng.random();
                        let z: f64 = rng.sample(StandardNormal);
                        r.map(|r| r.ln_low + u * r.ln_width + z * r.ln_se)
                    })
                    .collect();
                self.images
                    .iter()
                    .enumerate()
                    .map(|(i, plan)| {
                        let u: f64 = rng.random();
                        let z: f64 = rng.sample(StandardNormal);
                        let Some(p) = plan else {
                            return f64::NAN;
                        };
                        let ln_signal = match p.source {
                            SignalSource::Own => ln_s[i].unwrap_or(p.ln_floor),
                            SignalSource::Image(j) => {
                                ln_s[j].unwrap_or(p.ln_floor) + gamma * p.distance
                            }
                            SignalSource::Bounds => {
                                p.ln_floor + u * (p.ln_top_bound() - p.ln_floor)
                            }
                        };
                        let ln_signal = (ln_signal + ILLUMINATION_SD * illumination)
                            .clamp(p.ln_floor, p.ln_ceiling.max(p.ln_floor));
                        (p.light + z * p.light_sd) / ln_signal.exp()
                    })
                    .collect()
            })
            .collect()
    }

    /// ln of the signal at the readings themselves (module docs, "The estimate"): image `i`'s
    /// own top reading, or the reference's carried by γ at the middle of its range, or the
    /// middle of the bounds; within the image's floor and ceiling. `None` without a budget.
    fn ln_read_signal(&self, i: usize) -> Option<f64> {
        let p = self.images[i].as_ref()?;
        let (g0, g1) = self.gamma_range();
        let top = |j: usize| self.readings[j].map_or(p.ln_floor, |r| r.ln_top);
        let ln_signal = match p.source {
            SignalSource::Own => top(i),
            SignalSource::Image(j) => top(j) + 0.5 * (g0 + g1) * p.distance,
            SignalSource::Bounds => 0.5 * (p.ln_floor + p.ln_top_bound()),
        };
        Some(ln_signal.clamp(p.ln_floor, p.ln_ceiling.max(p.ln_floor)))
    }

    /// Every image's corrected area and 95 % interval from the draws; `None` without a budget.
    pub fn corrected(&self, draws: &[Vec<f64>]) -> Vec<Option<CorrectedArea>> {
        self.images
            .par_iter()
            .enumerate()
            .map(|(i, plan)| {
                let p = plan.as_ref()?;
                let mut v: Vec<f64> = draws.iter().map(|d| d[i]).collect();
                // The nearest-rank quantiles, each by selection (what a sort would put there).
                let mut at = |q: f64| {
                    let k = ((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
                    *v.select_nth_unstable_by(k, f64::total_cmp).1
                };
                let (lo, hi) = (at(0.025).max(0.0), at(0.975).max(0.0));
                let read = self
                    .ln_read_signal(i)
                    .map_or(f64::NAN, |ln_s| p.light / ln_s.exp());
                let area = if read.is_finite() {
                    read.max(lo).min(hi)
                } else {
                    at(0.5).max(0.0)
                };
                Some(CorrectedArea {
                    area_px: area,
                    lo_px: lo,
                    hi_px: hi,
                    signal: if area > 0.0 { p.light / area } else { f64::NAN },
                    source: p.source,
                })
            })
            .collect()
    }
}

/// The detector's gain: the white noise of the plateaus above the background's, per grey level
/// of signal; without plateaus, the background's variance per grey level of background (a
/// detector without offset).
fn estimate_gain(images: &[ImageLight]) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for b in images.iter().filter_map(|im| im.budget) {
        if let Some(p) = b.plateau {
            num += p.pixels as f64 * (p.white_variance - b.background_variance);
            den += p.pixels as f64 * p.level;
        }
    }
    if den > 0.0 {
        return (num / den).max(0.0);
    }
    images
        .iter()
        .filter_map(|im| im.budget)
        .map(|b| b.background_variance / b.background_level.max(1.0))
        .next()
        .unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::blur::isotropic_blur;

    /// A series whose signal rises 15 % per decade of load, linearly in log N (a rise that
    /// slows with load, as in `synth::solved`'s camera), 4–400 mN, every interior clean but the
    /// lightest, which holes darken by 3 % (the solved sub-PSF ramp of seed 32 under a 600 nm
    /// PSF, 100 nm pixels, 20 photons). Carried down from the heaviest reading by one power law,
    /// the lightest image needs γ ≈ 0.057; the rise between the two heaviest interiors is 0.05.
    /// Capped at the slowest rise an interior allows, the lightest interval lay below its true
    /// area; capped at the fastest, every interval holds its truth.
    #[test]
    fn a_signal_rising_slower_at_heavy_loads_is_carried_to_the_lightest_load() {
        let n = 8;
        let force = |k: usize| 4e-3 * 10f64.powf(2.0 * k as f64 / (n - 1) as f64);
        let signal = |k: usize| 2000.0 * (1.0 + 0.15 * (force(k) / force(0)).log10());
        let area = |k: usize| 1000.0 * (force(k) / force(0)).powf(0.8);
        let images: Vec<ImageLight> = (0..n)
            .map(|k| {
                let s = signal(k);
                let darkened = if k == 0 { 0.97 } else { 1.0 };
                let plateau = super::super::light::Plateau {
                    level: darkened * s,
                    tiles: 100,
                    pixels: 1600,
                    white_variance: 25.0 + 0.04 * s,
                    texture_variance: if k == 0 { (0.027 * s).powi(2) } else { 0.0 },
                    tile_q90: darkened * s,
                };
                ImageLight {
                    force_n: Some(force(k)),
                    budget: Some(LightBudget {
                        excess: s * area(k),
                        region_pixels: (4.0 * area(k)) as u64,
                        background_variance: 25.0,
                        fit_variance: 0.0,
                        background_level: 400.0,
                        plateau: Some(plateau),
                        faint_tiles: 0,
                        peak: darkened * s,
                    }),
                    ceiling: None,
                }
            })
            .collect();
        let model = SeriesLight::new(&images, 2.5, 1.0, Assumptions::default());
        let areas = model.corrected(&model.draws());
        for (k, a) in areas.iter().enumerate() {
            let a = a.expect("a budget");
            assert!(
                a.lo_px <= area(k) && area(k) <= a.hi_px,
                "image {k}: truth {:.0} px outside [{:.0}, {:.0}]",
                area(k),
                a.lo_px,
                a.hi_px
            );
        }
        // The rise from the lightest load to the heaviest is inside the range.
        let (_, up) = model.gamma_range();
        let chord = (signal(n - 1) / signal(0)).ln() / (force(n - 1) / force(0)).ln();
        assert!(
            up > chord,
            "γ up to {up}, the lightest interior's rise {chord}"
        );
    }

    /// The estimate sits at the readings, not in the middle of the allowance above them: clean
    /// interiors (the top reading is the signal) with a texture of 8 % (a signal varying over
    /// the contact), read without forces (each image its own reading). The corrected areas are
    /// the true areas to 0.5 %; the drawn areas' median, which spreads the allowance evenly,
    /// reads them more than 3 % low.
    #[test]
    fn the_corrected_area_is_taken_at_the_top_reading() {
        let signal = 2000.0;
        let tile_sd = ((25.0 + 0.04 * signal) / 16.0f64).sqrt();
        let images: Vec<ImageLight> = [500.0, 1500.0, 4000.0]
            .iter()
            .map(|&area| ImageLight {
                force_n: None,
                budget: Some(LightBudget {
                    excess: signal * area,
                    region_pixels: (4.0 * area) as u64,
                    background_variance: 25.0,
                    fit_variance: 0.0,
                    background_level: 400.0,
                    plateau: Some(super::super::light::Plateau {
                        level: 0.85 * signal,
                        tiles: 100,
                        pixels: 1600,
                        white_variance: 25.0 + 0.04 * signal,
                        texture_variance: (0.08 * 0.85 * signal).powi(2),
                        tile_q90: signal + 1.2816 * tile_sd,
                    }),
                    faint_tiles: 0,
                    peak: signal,
                }),
                ceiling: None,
            })
            .collect();
        let model = SeriesLight::new(&images, 2.5, 1.0, Assumptions::default());
        let draws = model.draws();
        let areas = model.corrected(&draws);
        for (i, a) in areas.iter().enumerate() {
            let a = a.expect("a budget");
            let truth = images[i].budget.unwrap().excess / signal;
            assert!(a.lo_px <= a.area_px && a.area_px <= a.hi_px);
            assert!(
                (a.area_px / truth - 1.0).abs() < 0.005,
                "image {i}: corrected {:.1} px, truth {truth:.1}",
                a.area_px
            );
            assert!(
                (a.signal / signal - 1.0).abs() < 0.005,
                "signal {}",
                a.signal
            );
            let mut v: Vec<f64> = draws.iter().map(|d| d[i]).collect();
            v.sort_by(f64::total_cmp);
            let median = v[v.len() / 2];
            assert!(
                median < 0.97 * truth,
                "median {median:.1} px, truth {truth:.1}"
            );
        }
    }

    /// The reference interior is the heaviest load's with a reading; without forces, the image
    /// with the most light. Its top over mean is the top reading (the 90th percentile less the
    /// noise's share) over the plateau's mean.
    #[test]
    fn the_reference_interior_is_the_heaviest_reading() {
        let image = |force: Option<f64>, light: f64, q90: f64| ImageLight {
            force_n: force,
            budget: Some(LightBudget {
                excess: light,
                region_pixels: 4000,
                background_variance: 25.0,
                fit_variance: 0.0,
                background_level: 400.0,
                plateau: Some(super::super::light::Plateau {
                    level: 1000.0,
                    tiles: 100,
                    pixels: 1600,
                    white_variance: 16.0,
                    texture_variance: 0.0,
                    tile_q90: q90,
                }),
                faint_tiles: 0,
                peak: q90,
            }),
            ceiling: None,
        };
        // A tile's noise: 1 grey level; the top reading is q90 − 1.2816.
        let with_forces = [
            image(Some(0.01), 3e6, 1100.0),
            image(Some(0.04), 1e6, 1051.2816),
            image(None, 9e6, 1300.0),
        ];
        let r = SeriesLight::new(&with_forces, 2.0, 1.0, Assumptions::default())
            .reference_interior()
            .unwrap();
        assert_eq!(r.image, 1);
        assert!((r.top_over_mean - 1.05).abs() < 1e-9, "{r:?}");
        let without: Vec<ImageLight> = with_forces
            .iter()
            .map(|i| ImageLight {
                force_n: None,
                ..*i
            })
            .collect();
        let r = SeriesLight::new(&without, 2.0, 1.0, Assumptions::default())
            .reference_interior()
            .unwrap();
        assert_eq!(r.image, 2);
        assert!((r.top_over_mean - (1300.0 - 1.2816) / 1000.0).abs() < 1e-9);
    }

    /// The hidden porosity's model against a porous interior made on purpose: holes of one
    /// pixel each (an indicator correlated over exactly 1 px²) filling 1 − f of a plane, blurred
    /// by a PSF of σ = 2 and 3 px; the relative spread of the 4 × 4 tile means gives back 1/f
    /// to within 10 %, and a hole area four times too large gives a quarter of the darkening.
    #[test]
    fn hidden_porosity_recovers_the_fill_of_pixel_holes() {
        let side = 512;
        for (fill, sigma) in [(0.8, 2.0), (0.7, 3.0), (0.9, 3.0)] {
            let mut rng = ChaCha8Rng::seed_from_u64(11);
            let plane: Vec<f64> = (0..side * side)
                .map(|_| f64::from(u8::from(rng.random::<f64>() < fill)))
                .collect();
            let blurred = isotropic_blur(&plane, side, side, sigma);
            // Tile means away from the mirrored edges.
            let tile = crate::measure::tiles::TILE;
            let margin = 4 * sigma as usize;
            let mut means = Vec::new();
            for ty in (margin / tile)..((side - margin) / tile) {
                for tx in (margin / tile)..((side - margin) / tile) {
                    let mut sum = 0.0;
                    for y in ty * tile..(ty + 1) * tile {
                        for x in tx * tile..(tx + 1) * tile {
                            sum += blurred[y * side + x];
                        }
                    }
                    means.push(sum / (tile * tile) as f64);
                }
            }
            let mean = means.iter().sum::<f64>() / means.len() as f64;
            let var =
                means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (means.len() - 1) as f64;
            let texture = var.sqrt() / mean;
            let darkening = 1.0 + hidden_porosity(texture, sigma, 1.0);
            assert!(
                (darkening * mean - 1.0).abs() < 0.1,
                "fill {fill}, σ {sigma}: 1/f = {}, the model {darkening}",
                1.0 / mean
            );
            let coarser = hidden_porosity(texture, sigma, 4.0);
            assert!((coarser * 4.0 - (darkening - 1.0)).abs() < 1e-12);
        }
    }
}
