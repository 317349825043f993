//! Slip detection: the onset of slip, static and kinetic friction of one trace (module docs of
//! [`super`]).

use super::trace::MIN_SAMPLES;
use crate::numerics::stats::median;

/// Tuning of [`detect_slip`]; the defaults suit rheometer traces with ≳ 20 samples on the
/// loading ramp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipOptions {
    /// Half-width h of the centred running median, samples (window 2h + 1).
    pub smoothing_half_width: usize,
    /// k: the drop must exceed k noise levels σ.
    pub drop_noise_levels: f64,
    /// f: and at least this fraction of the trace's force range (guards noise-free data).
    pub min_drop_fraction: f64,
    /// Samples before the peak in the line fit that gives F_s.
    pub peak_fit_samples: usize,
}

impl Default for SlipOptions {
    fn default() -> Self {
        SlipOptions {
            smoothing_half_width: 2,
            drop_noise_levels: 8.0,
            min_drop_fraction: 0.02,
            peak_fit_samples: 8,
        }
    }
}

/// A detected slip event.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slip {
    /// Sample index of the onset of slip (the peak).
    pub index: usize,
    /// x at the onset, in the trace's SI unit.
    pub x: f64,
    /// Static friction F_s at the onset, N.
    pub static_friction_n: f64,
    /// Kinetic friction: median after the slip transient, N.
    pub kinetic_friction_n: f64,
    /// First sample of the kinetic window.
    pub kinetic_from: usize,
    /// Estimated noise σ of the raw force, N.
    pub noise_n: f64,
    /// Drop D that counted as slip, N.
    pub drop_threshold_n: f64,
    /// How the slip was recognised.
    pub criterion: SlipCriterion,
}

/// How a slip was recognised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlipCriterion {
    /// The force dropped from a maximum (static above kinetic friction).
    Drop,
    /// No drop: the loading slope collapsed into a plateau (F_s = F_k).
    Plateau,
}

impl SlipCriterion {
    /// Name in tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            SlipCriterion::Drop => "drop",
            SlipCriterion::Plateau => "plateau",
        }
    }
}

/// Find the onset of slip in `force_n` sampled at increasing `x` (see the module documentation):
/// the first sustained drop, or else the point where the loading slope collapses into a plateau.
/// `None` when neither is found, or when fewer than 2h + 3 samples follow the transient
/// (h = [`SlipOptions::smoothing_half_width`]).
pub fn detect_slip(x: &[f64], force_n: &[f64], opts: &SlipOptions) -> Option<Slip> {
    let n = force_n.len().min(x.len());
    if n < MIN_SAMPLES {
        return None;
    }
    let f = &force_n[..n];
    let h = opts.smoothing_half_width;
    let smooth = running_median(f, h);
    let noise = noise_level(f);
    let (lo, hi) = min_max(&smooth);
    let drop = (opts.drop_noise_levels * noise).max(opts.min_drop_fraction * (hi - lo));
    if drop <= 0.0 {
        return None;
    }
    let signal = Signal {
        x: &x[..n],
        f,
        smooth,
        noise,
        drop,
        h,
    };
    match first_sustained_drop(&signal.smooth, drop, 4 * h + 1) {
        Some((peak, dropped_at)) => drop_slip(&signal, peak, dropped_at, opts),
        None => plateau_slip(&signal),
    }
}

/// A trace prepared for slip detection.
struct Signal<'a> {
    x: &'a [f64],
    f: &'a [f64],
    smooth: Vec<f64>,
    noise: f64,
    drop: f64,
    h: usize,
}

impl Signal<'_> {
    fn slip(&self, index: usize, static_n: f64, kinetic_from: usize, how: SlipCriterion) -> Slip {
        Slip {
            index,
            x: self.x[index],
            static_friction_n: static_n,
            kinetic_friction_n: median(&self.f[kinetic_from..]),
            kinetic_from,
            noise_n: self.noise,
            drop_threshold_n: self.drop,
            criterion: how,
        }
    }
}

fn drop_slip(s: &Signal, peak: usize, dropped_at: usize, opts: &SlipOptions) -> Option<Slip> {
    let onset = drop_onset(s.f, peak.saturating_sub(s.h), dropped_at, 4.0 * s.noise);
    let kinetic_from = first_local_min(&s.smooth, dropped_at);
    if s.f.len() - kinetic_from < 2 * s.h + 3 {
        return None;
    }
    let static_n = line_value_at(s.x, s.f, onset, opts.peak_fit_samples);
    Some(s.slip(onset, static_n, kinetic_from, SlipCriterion::Drop))
}

/// Slope below this fraction of the loading slope counts as sliding.
const PLATEAU_SLOPE: f64 = 0.1;

/// No drop: slip where the loading slope collapses. The loading slope k₀ is the median
/// centred-difference slope (over ±5h samples) while the force is between 20 % and 60 % of its
/// range; the plateau starts at the first sample above 60 % from which the slope stays below
/// 0.1·k₀ for 5h samples. F_s = F_k there; the onset is where the smoothed force first comes
/// within max(2σ, 0.5 %) of the plateau level.
fn plateau_slip(s: &Signal) -> Option<Slip> {
    let n = s.f.len();
    let w = 5 * s.h.max(1);
    let (lo, hi) = min_max(&s.smooth);
    if hi - lo < 2.0 * s.drop || n < 4 * w {
        return None;
    }
    let level_at = |frac: f64| lo + frac * (hi - lo);
    let slope = |i: usize| (s.smooth[i + w] - s.smooth[i - w]) / (s.x[i + w] - s.x[i - w]);
    let ramp: Vec<f64> = (w..n - w)
        .filter(|&i| (level_at(0.2)..=level_at(0.6)).contains(&s.smooth[i]))
        .map(slope)
        .collect();
    let k0 = median(&ramp);
    if ramp.len() < 3 || k0.is_nan() || k0 <= 0.0 {
        return None;
    }
    let corner = (w..n - 2 * w).find(|&i| {
        s.smooth[i] >= level_at(0.6) && (i..i + w).all(|j| slope(j) < PLATEAU_SLOPE * k0)
    })?;
    let level = median(&s.f[corner..corner + 2 * w]);
    let near = (2.0 * s.noise).max(0.005 * level.abs());
    let onset = (0..=corner)
        .find(|&j| s.smooth[j] >= level - near)
        .unwrap_or(corner);
    Some(s.slip(onset, level, corner, SlipCriterion::Plateau))
}

/// The last sample before the drop: the steepest raw step down in `from..to`, walked back over
/// the preceding steps that also fall by more than `step` (a drop spread over several samples).
/// On a creeping, nearly flat top the raw maximum is decided by noise; the drop is not.
fn drop_onset(f: &[f64], from: usize, to: usize, step: f64) -> usize {
    let to = to.min(f.len() - 1);
    let Some(mut k) = (from..to).max_by(|&a, &b| (f[a] - f[a + 1]).total_cmp(&(f[b] - f[b + 1])))
    else {
        return from;
    };
    while k > from && f[k - 1] - f[k] > step.max(0.0) {
        k -= 1;
    }
    k
}

/// (index of the running maximum, index where the drop was confirmed) for the first drop below
/// the running maximum by more than `drop` whose median over `sustain` samples stays below.
fn first_sustained_drop(smooth: &[f64], drop: f64, sustain: usize) -> Option<(usize, usize)> {
    let mut peak = 0;
    for j in 1..smooth.len() {
        if smooth[j] > smooth[peak] {
            peak = j;
            continue;
        }
        let level = smooth[peak] - drop;
        if smooth[j] < level {
            let ahead = &smooth[j..(j + sustain).min(smooth.len())];
            if ahead.len() == sustain && median(ahead) < level {
                return Some((peak, j));
            }
        }
    }
    None
}

fn first_local_min(smooth: &[f64], from: usize) -> usize {
    (from..smooth.len() - 1)
        .find(|&k| smooth[k + 1] >= smooth[k])
        .unwrap_or(smooth.len() - 1)
}

/// Least-squares line through the `samples` points ending at `end`, evaluated at `x[end]`.
fn line_value_at(x: &[f64], f: &[f64], end: usize, samples: usize) -> f64 {
    let start = end.saturating_sub(samples.max(2) - 1);
    let (xs, fs) = (&x[start..=end], &f[start..=end]);
    let m = xs.len() as f64;
    if xs.len() < 2 {
        return f[end];
    }
    let mx = xs.iter().sum::<f64>() / m;
    let mf = fs.iter().sum::<f64>() / m;
    let sxx: f64 = xs.iter().map(|v| (v - mx).powi(2)).sum();
    let sxf: f64 = xs.iter().zip(fs).map(|(a, b)| (a - mx) * (b - mf)).sum();
    if sxx <= 0.0 {
        return mf;
    }
    mf + sxf / sxx * (x[end] - mx)
}

/// Centred running median of half-width `h`, truncated at the ends: it keeps the slip step
/// sharp and removes outliers up to `h` samples long (a moving average would smear a dropout
/// into a drop).
fn running_median(f: &[f64], h: usize) -> Vec<f64> {
    (0..f.len())
        .map(|i| median(&f[i.saturating_sub(h)..(i + h + 1).min(f.len())]))
        .collect()
}

/// Robust σ of white noise on a smooth signal: second differences remove the loading slope, the
/// median absolute deviation ignores the few samples at a slip step. Var(Δ²) = 6σ².
fn noise_level(f: &[f64]) -> f64 {
    let d2: Vec<f64> = f.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
    if d2.is_empty() {
        return 0.0;
    }
    let centre = median(&d2);
    let dev: Vec<f64> = d2.iter().map(|v| (v - centre).abs()).collect();
    1.4826 * median(&dev) / 6f64.sqrt()
}

pub(crate) fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    use crate::synth::traces::{synthetic_trace, TraceParams};

    #[test]
    fn noise_level_ignores_the_slope() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let f: Vec<f64> = (0..4000)
            .map(|i| {
                let e: f64 = StandardNormal.sample(&mut rng);
                0.5 * i as f64 + 2.0 * e
            })
            .collect();
        let s = noise_level(&f);
        assert!((s / 2.0 - 1.0).abs() < 0.05, "σ = {s}");
    }

    #[test]
    fn exact_trace_gives_exact_static_friction() {
        let p = TraceParams {
            noise_n: 0.0,
            wiggle_n: 0.0,
            creep_fraction: 0.0,
            ..TraceParams::default()
        };
        let t = synthetic_trace(&p);
        let slip = detect_slip(&t.displacement_m, &t.friction_n, &SlipOptions::default()).unwrap();
        assert_eq!(slip.index, t.slip_index);
        let peak = t.friction_n[t.slip_index];
        assert!((slip.static_friction_n - peak).abs() < 1e-12 * peak);
        assert!((slip.kinetic_friction_n - p.kinetic_friction_n).abs() < 1e-15);
    }
}
