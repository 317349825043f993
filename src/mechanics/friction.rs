//! Friction traces from the rheometer: static friction at the onset of slip, kinetic friction
//! after it, the friction coefficients μ = F/N, and the interfacial shear strength τ of
//! F_s = τ·A (Weber et al. 2018, Fig. 3b: τ ≈ 50 MPa; μ is not constant because A grows
//! sublinearly with N).
//!
//! # Trace CSV format
//! One row per sample, in recording order; column names carry the unit and are the contract:
//!
//! * **x** (one of, first found wins in this order): `displacement_um`, `angle_rad`, `time_s`.
//!   Values must increase from row to row.
//! * **friction** (exactly one of): `friction_mN`, `friction_N`, or the rheometer's torque
//!   `torque_mNm`, `torque_Nm`. Torque T becomes force F = T / r with the sphere's rotation
//!   radius r (`rotation_radius_m`), as in the paper's Methods; torque without r is an error.
//! * **normal force** (optional): `normal_force_mN` or `normal_force_N`; its median is the
//!   trace's N. Without it the caller's N (`--normal-force`) is used; neither is an error.
//!
//! Other columns are ignored, except names that start like a known quantity (`friction_`,
//! `torque_`, `normal_force_`, `time_`, `displacement_`, `angle_`) with an unknown unit, which
//! are refused rather than silently skipped. Lines starting with `#` are comments.
//!
//! # Slip detection ([`detect_slip`])
//! The paper defines static friction as "the maximal friction force at the onset of slip"
//! (Fig. 3b caption), not the largest value anywhere in the trace. The force is smoothed by a
//! centred running median (edge-preserving; outliers up to h samples long vanish); the noise
//! level σ is estimated robustly from second differences (MAD/0.6745/√6, insensitive to the
//! loading slope and to isolated steps). Walking forward, the slip is the first running maximum
//! after which the smoothed force falls by more than D = max(k·σ, f·range) and whose median over
//! the next 4h + 1 samples stays below that level (a short dropout is not a slip). The onset is
//! the last raw sample before the steep part of the drop; F_s is the least-squares line through
//! the raw samples up to the onset, evaluated there (a denoised maximum). The kinetic friction
//! is the median raw force after the slip transient (from the first minimum of the smoothed force
//! after the drop to the end).
//!
//! A trace without a drop that bends into a plateau (no stick-slip, F_s = F_k) slips where the
//! loading slope collapses below a tenth of its value on the ramp (see `docs/mechanics.md`); its
//! criterion is reported as `plateau`. A trace with neither is an error, never a guess.

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde_json::{json, Value};

use crate::error::{Error, Location, Result};
use crate::fit::fit_power_law;
use crate::io::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::io::staging::Staging;
use crate::report::read_areas_csv;

use crate::io::table::Table;

/// The quantity on a trace's x axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum XAxis {
    /// Sliding (plate) displacement, column `displacement_um`, stored in m.
    Displacement,
    /// Rheometer plate angle, column `angle_rad`, stored in rad.
    Angle,
    /// Time, column `time_s`, stored in s.
    Time,
}

impl XAxis {
    /// All axes in the order a trace's columns are searched.
    pub const ALL: [XAxis; 3] = [XAxis::Displacement, XAxis::Angle, XAxis::Time];

    /// The input column name.
    pub fn column(self) -> &'static str {
        match self {
            XAxis::Displacement => "displacement_um",
            XAxis::Angle => "angle_rad",
            XAxis::Time => "time_s",
        }
    }

    /// The output column of the slip position.
    pub fn slip_column(self) -> &'static str {
        match self {
            XAxis::Displacement => "slip_at_um",
            XAxis::Angle => "slip_at_rad",
            XAxis::Time => "slip_at_s",
        }
    }

    /// SI value of one unit of the column (µm → m).
    fn si_per_unit(self) -> f64 {
        match self {
            XAxis::Displacement => 1e-6,
            XAxis::Angle | XAxis::Time => 1.0,
        }
    }

    /// An SI value in the column's unit.
    pub fn to_column_unit(self, si: f64) -> f64 {
        si / self.si_per_unit()
    }
}

/// One friction trace in SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// What `x` is.
    pub x_axis: XAxis,
    /// x per sample (m, rad or s), increasing.
    pub x: Vec<f64>,
    /// Friction force per sample, N.
    pub friction_n: Vec<f64>,
    /// Median of the trace's normal-force column, N, if it has one.
    pub normal_force_n: Option<f64>,
}

const FRICTION_COLUMNS: [(&str, f64); 2] = [("friction_mN", 1e-3), ("friction_N", 1.0)];
const TORQUE_COLUMNS: [(&str, f64); 2] = [("torque_mNm", 1e-3), ("torque_Nm", 1.0)];
const NORMAL_COLUMNS: [(&str, f64); 2] = [("normal_force_mN", 1e-3), ("normal_force_N", 1.0)];
const QUANTITY_STEMS: [&str; 6] = [
    "friction_",
    "torque_",
    "normal_force_",
    "time_",
    "displacement_",
    "angle_",
];

/// Fewest samples a trace may have: loading, slip and a kinetic level need some of each.
pub const MIN_SAMPLES: usize = 10;

/// Read a trace CSV (format in the module documentation). `rotation_radius_m` converts torque to
/// force and is required when the file has a torque column.
pub fn read_trace(path: &Path, rotation_radius_m: Option<f64>) -> Result<Trace> {
    let table = Table::read(path)?;
    refuse_unknown_units(&table)?;
    let x_axis = XAxis::ALL
        .into_iter()
        .find(|a| table.header().iter().any(|h| h == a.column()))
        .ok_or_else(|| table.missing("x", &XAxis::ALL.map(XAxis::column)))?;
    let x = table.numbers(x_axis.column(), x_axis.si_per_unit())?;
    let friction_n = friction_column(&table, rotation_radius_m)?;
    let normal_force_n = match pick(&table, &NORMAL_COLUMNS)? {
        Some((name, factor)) => Some(median(&table.numbers(name, factor)?)),
        None => None,
    };
    if table.len() < MIN_SAMPLES {
        return Err(Error::bad_input(
            table.location(),
            format!(
                "{} samples; a trace needs at least {MIN_SAMPLES}",
                table.len()
            ),
        ));
    }
    if let Some(k) = (1..x.len()).find(|&k| x[k] <= x[k - 1]) {
        return Err(Error::bad_input(
            table.location(),
            format!(
                "line {}: {} does not increase ({} after {})",
                table.line(k),
                x_axis.column(),
                x_axis.to_column_unit(x[k]),
                x_axis.to_column_unit(x[k - 1])
            ),
        ));
    }
    Ok(Trace {
        x_axis,
        x,
        friction_n,
        normal_force_n,
    })
}

/// A column such as `friction_lbf` is almost certainly a unit mistake: refuse it.
fn refuse_unknown_units(table: &Table) -> Result<()> {
    let known: Vec<&str> = FRICTION_COLUMNS
        .iter()
        .chain(&TORQUE_COLUMNS)
        .chain(&NORMAL_COLUMNS)
        .map(|c| c.0)
        .chain(XAxis::ALL.map(XAxis::column))
        .collect();
    let unknown = table
        .header()
        .iter()
        .find(|h| QUANTITY_STEMS.iter().any(|s| h.starts_with(s)) && !known.contains(&h.as_str()));
    match unknown {
        Some(h) => Err(Error::bad_input(
            table.location(),
            format!(
                "column {h:?} has a unit contactscope does not read (known: {}); columns found: {}",
                known.join(", "),
                table.found()
            ),
        )),
        None => Ok(()),
    }
}

fn pick(table: &Table, columns: &[(&'static str, f64)]) -> Result<Option<(&'static str, f64)>> {
    let names: Vec<&str> = columns.iter().map(|c| c.0).collect();
    Ok(table
        .one_of(&names)?
        .and_then(|n| columns.iter().copied().find(|c| c.0 == n)))
}

fn friction_column(table: &Table, rotation_radius_m: Option<f64>) -> Result<Vec<f64>> {
    let force = pick(table, &FRICTION_COLUMNS)?;
    let torque = pick(table, &TORQUE_COLUMNS)?;
    match (force, torque) {
        (Some((f, _)), Some((t, _))) => Err(Error::bad_input(
            table.location(),
            format!("both {f} and {t}; keep one friction column"),
        )),
        (Some((name, factor)), None) => table.numbers(name, factor),
        (None, Some((name, factor))) => {
            let r = rotation_radius_m.ok_or_else(|| {
                Error::bad_input(
                    table.location(),
                    format!(
                        "{name} is a torque; give the sphere's rotation radius (--rotation-radius, e.g. 5mm) to turn it into a force"
                    ),
                )
            })?;
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "rotation radius {r:e} m must be positive"
                )));
            }
            // F = T / r: the sphere sits at distance r from the rheometer axis (paper, Methods).
            Ok(table.numbers(name, factor)?.iter().map(|t| t / r).collect())
        }
        (None, None) => {
            let accepted: Vec<&str> = FRICTION_COLUMNS
                .iter()
                .chain(&TORQUE_COLUMNS)
                .map(|c| c.0)
                .collect();
            Err(table.missing("friction or torque", &accepted))
        }
    }
}

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

/// Least-squares line through the `samples` points ending at `end`, evaluated at x[end].
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

fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
            (lo.min(x), hi.max(x))
        })
}

/// Median (mean of the middle two for an even count); NaN for an empty slice.
pub(crate) fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

/// F = τ·A fitted through the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShearFit {
    /// Interfacial shear strength τ = Σ F·A / Σ A², Pa.
    pub tau_pa: f64,
    /// Standard error sqrt(SS_res / (n − 1) / Σ A²), Pa; `None` for one point.
    pub tau_se_pa: Option<f64>,
    /// 1 − SS_res / Σ(F − F̄)², about the mean (negative when a line through the origin fits
    /// worse than a constant); `None` if all F are equal.
    pub r_squared: Option<f64>,
    /// Points used.
    pub points: usize,
}

/// Least squares in F of F = τ·A through the origin (Weber et al. 2018, Fig. 3b), areas in m²,
/// forces in N. `None` without a positive area.
pub fn fit_shear_strength(areas_m2: &[f64], forces_n: &[f64]) -> Option<ShearFit> {
    let pts: Vec<(f64, f64)> = areas_m2
        .iter()
        .zip(forces_n)
        .filter(|(a, f)| a.is_finite() && f.is_finite())
        .map(|(a, f)| (*a, *f))
        .collect();
    let saa: f64 = pts.iter().map(|p| p.0 * p.0).sum();
    if saa <= 0.0 || !saa.is_finite() {
        return None;
    }
    let tau = pts.iter().map(|p| p.0 * p.1).sum::<f64>() / saa;
    let n = pts.len();
    let ss_res: f64 = pts.iter().map(|p| (p.1 - tau * p.0).powi(2)).sum();
    let mean_f = pts.iter().map(|p| p.1).sum::<f64>() / n as f64;
    let ss_tot: f64 = pts.iter().map(|p| (p.1 - mean_f).powi(2)).sum();
    Some(ShearFit {
        tau_pa: tau,
        tau_se_pa: (n > 1).then(|| (ss_res / (n - 1) as f64 / saa).sqrt()),
        r_squared: (ss_tot > 0.0).then(|| 1.0 - ss_res / ss_tot),
        points: n,
    })
}

/// How μ = F/N changes with N: the exponent of μ ∝ N^m (log–log least squares; Amontons' law is
/// m = 0, F ∝ A ∝ N^β gives m = β − 1) and the relative spread (max − min)/mean.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuTrend {
    /// Fitted exponent m.
    pub exponent: f64,
    /// Its standard error (three or more distinct loads).
    pub exponent_se: Option<f64>,
    /// (max μ − min μ) / mean μ.
    pub relative_spread: f64,
    /// `Some(true)` when |m| > 2·se: μ depends on N beyond the scatter; `None` without an se.
    pub varies: Option<bool>,
}

/// μ's dependence on the normal force; `None` with fewer than two distinct positive loads.
pub fn mu_trend(normal_n: &[f64], mu: &[f64]) -> Option<MuTrend> {
    let fit = fit_power_law(normal_n, mu)?;
    let (lo, hi) = min_max(mu);
    let mean = mu.iter().sum::<f64>() / mu.len() as f64;
    Some(MuTrend {
        exponent: fit.exponent,
        exponent_se: fit.exponent_se,
        relative_spread: (hi - lo) / mean,
        varies: fit.exponent_se.map(|se| fit.exponent.abs() > 2.0 * se),
    })
}

/// Parameters of [`synthetic_trace`]: a rheometer plate driven at constant speed loads the
/// contact through the instrument's finite stiffness (the paper's linear build-up, Fig. 3b
/// inset) until F_s, then it slips to the kinetic level with stick-slip wiggles; Gaussian noise
/// on top.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceParams {
    /// F_s, N.
    pub static_friction_n: f64,
    /// Kinetic level after slip, N.
    pub kinetic_friction_n: f64,
    /// Loading stiffness k, N/m (F = k·d on the ramp).
    pub stiffness_n_per_m: f64,
    /// Drive speed, m/s (the paper: ≈ 1 µm/s).
    pub velocity_m_per_s: f64,
    /// Sampling interval, s.
    pub sample_interval_s: f64,
    /// Drive distance recorded after the slip, m.
    pub post_slip_m: f64,
    /// Fraction of F_s over which the ramp bends over before slip (precursor creep): the slope
    /// falls linearly from k to 0.3·k; 0 for a straight ramp.
    pub creep_fraction: f64,
    /// Samples the slip drop takes (≥ 1).
    pub slip_samples: usize,
    /// Amplitude of sinusoidal stick-slip wiggles after slip, N.
    pub wiggle_n: f64,
    /// Their period in drive distance, m.
    pub wiggle_period_m: f64,
    /// Standard deviation of the Gaussian noise, N.
    pub noise_n: f64,
    /// Seed of the noise (ChaCha8).
    pub seed: u64,
}

impl Default for TraceParams {
    /// F_s = 10 mN (τ = 50 MPa on 200 µm²), F_k = 8 mN, 20 µm of loading at 1 µm/s sampled at
    /// 20 Hz, 0.2 % noise.
    fn default() -> Self {
        TraceParams {
            static_friction_n: 10e-3,
            kinetic_friction_n: 8e-3,
            stiffness_n_per_m: 500.0,
            velocity_m_per_s: 1e-6,
            sample_interval_s: 0.05,
            post_slip_m: 15e-6,
            creep_fraction: 0.1,
            slip_samples: 2,
            wiggle_n: 0.1e-3,
            wiggle_period_m: 3e-6,
            noise_n: 0.02e-3,
            seed: 7,
        }
    }
}

/// A generated trace with its ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticTrace {
    /// Sample times, s.
    pub time_s: Vec<f64>,
    /// Drive displacement v·t, m.
    pub displacement_m: Vec<f64>,
    /// Friction force, N.
    pub friction_n: Vec<f64>,
    /// Index of the last sample before the drop (where F = F_s without noise).
    pub slip_index: usize,
}

/// Generate a friction trace (see [`TraceParams`]); the same parameters give the same trace.
pub fn synthetic_trace(p: &TraceParams) -> SyntheticTrace {
    let dx = p.velocity_m_per_s * p.sample_interval_s;
    let (creep_from, creep_len) = creep_zone(p);
    let slip_d = creep_from + creep_len;
    let slip_index = (slip_d / dx).floor() as usize;
    let total = slip_index + 1 + (p.post_slip_m / dx).ceil() as usize;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(p.seed);
    let mut out = SyntheticTrace {
        time_s: Vec::with_capacity(total),
        displacement_m: Vec::with_capacity(total),
        friction_n: Vec::with_capacity(total),
        slip_index,
    };
    for i in 0..total {
        let d = i as f64 * dx;
        let clean = if i <= slip_index {
            loading_force(p, d, creep_from)
        } else {
            sliding_force(
                p,
                i - slip_index,
                d - slip_d,
                loading_force(p, slip_index as f64 * dx, creep_from),
            )
        };
        let noise: f64 = StandardNormal.sample(&mut rng);
        out.time_s.push(i as f64 * p.sample_interval_s);
        out.displacement_m.push(d);
        out.friction_n.push(clean + p.noise_n * noise);
    }
    out
}

/// (start, length) of the creep zone in drive distance. The slope falls linearly from k to r·k
/// over length L, so the force gained there is k·L·(1 + r)/2 = creep_fraction·F_s.
fn creep_zone(p: &TraceParams) -> (f64, f64) {
    const END_SLOPE: f64 = 0.3;
    let k = p.stiffness_n_per_m;
    let creep_force = p.creep_fraction.clamp(0.0, 1.0) * p.static_friction_n;
    let len = 2.0 * creep_force / (k * (1.0 + END_SLOPE));
    ((p.static_friction_n - creep_force) / k, len)
}

fn loading_force(p: &TraceParams, d: f64, creep_from: f64) -> f64 {
    let k = p.stiffness_n_per_m;
    if d <= creep_from {
        return k * d;
    }
    let (_, len) = creep_zone(p);
    let u = (d - creep_from).min(len);
    k * creep_from + k * u - k * 0.7 / (2.0 * len) * u * u
}

/// Force `step` samples after the peak: a linear drop over `slip_samples`, then the kinetic
/// level with wiggles that start at zero phase.
fn sliding_force(p: &TraceParams, step: usize, slid_m: f64, peak_n: f64) -> f64 {
    let steps = p.slip_samples.max(1);
    if step < steps {
        let t = step as f64 / steps as f64;
        return peak_n + (p.kinetic_friction_n - peak_n) * t;
    }
    let phase = std::f64::consts::TAU * slid_m / p.wiggle_period_m.max(f64::MIN_POSITIVE);
    p.kinetic_friction_n + p.wiggle_n * phase.sin()
}

/// How [`trace_csv`] writes a synthetic trace.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CsvLayout {
    /// x column.
    pub x_axis: XAxis,
    /// Write `torque_mNm` (F·r) instead of `friction_mN`.
    pub torque: bool,
    /// Rotation radius r for torque and angle columns, m.
    pub rotation_radius_m: f64,
    /// Write a `normal_force_mN` column with this force (N).
    pub normal_force_n: Option<f64>,
}

/// A synthetic trace as CSV text in the input format of [`read_trace`].
pub fn trace_csv(trace: &SyntheticTrace, layout: &CsvLayout) -> String {
    let r = layout.rotation_radius_m;
    let mut text = String::from(layout.x_axis.column());
    text.push_str(if layout.torque {
        ",torque_mNm"
    } else {
        ",friction_mN"
    });
    if layout.normal_force_n.is_some() {
        text.push_str(",normal_force_mN");
    }
    text.push('\n');
    for i in 0..trace.friction_n.len() {
        let x = match layout.x_axis {
            XAxis::Displacement => trace.displacement_m[i] * 1e6,
            XAxis::Angle => trace.displacement_m[i] / r,
            XAxis::Time => trace.time_s[i],
        };
        let f = trace.friction_n[i];
        let y = if layout.torque { f * r * 1e3 } else { f * 1e3 };
        text.push_str(&format!("{x:.9e},{y:.9e}"));
        if let Some(n) = layout.normal_force_n {
            text.push_str(&format!(",{:.9e}", n * 1e3));
        }
        text.push('\n');
    }
    text
}

/// Everything `friction` needs, already parsed.
#[derive(Debug, Clone)]
pub struct FrictionRequest {
    /// Trace CSV files.
    pub traces: Vec<PathBuf>,
    /// N for traces without a normal-force column, N.
    pub normal_force_n: Option<f64>,
    /// Rotation radius of the sphere for torque traces, m.
    pub rotation_radius_m: Option<f64>,
    /// `analyze` output `areas.csv` (`force_mN`, `area_um2`), for F = τ·A.
    pub areas: Option<PathBuf>,
    /// Largest relative difference between a trace's N and an area row's force.
    pub force_tolerance: f64,
    /// Slip detection settings.
    pub slip: SlipOptions,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the JSON.
    pub command_line: Vec<String>,
}

/// Result for one trace.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceResult {
    /// The trace file.
    pub file: PathBuf,
    /// Its x axis.
    pub x_axis: XAxis,
    /// Normal force N, N.
    pub normal_force_n: f64,
    /// The slip event.
    pub slip: Slip,
    /// Matched real contact area, m² (with `--areas`).
    pub area_m2: Option<f64>,
}

impl TraceResult {
    /// μ_s = F_s / N.
    pub fn mu_static(&self) -> f64 {
        self.slip.static_friction_n / self.normal_force_n
    }

    /// μ_k = F_k / N.
    pub fn mu_kinetic(&self) -> f64 {
        self.slip.kinetic_friction_n / self.normal_force_n
    }
}

/// What `friction` computed and wrote.
#[derive(Debug, Clone)]
pub struct FrictionOutcome {
    /// One result per trace, in input order.
    pub traces: Vec<TraceResult>,
    /// F_s = τ·A (with areas).
    pub shear: Option<ShearFit>,
    /// F_k = τ_k·A (with areas).
    pub kinetic_shear: Option<ShearFit>,
    /// μ_s versus N (two or more distinct loads).
    pub mu_trend: Option<MuTrend>,
    /// Files written.
    pub written: Vec<PathBuf>,
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// Run `friction`: analyse every trace, match areas, fit τ, and write `friction.csv`,
/// `summary.json`, `friction_vs_load.png`, `mu_vs_load.png` and (with areas)
/// `friction_vs_area.png` into the output folder, all or nothing.
pub fn run_friction(request: &FrictionRequest) -> Result<FrictionOutcome> {
    if request.traces.is_empty() {
        return Err(Error::InvalidArgument("no friction traces given".into()));
    }
    let mut warnings = Vec::new();
    let mut traces = request
        .traces
        .iter()
        .map(|path| analyse_trace(path, request, &mut warnings))
        .collect::<Result<Vec<_>>>()?;
    if let Some(path) = &request.areas {
        let areas = read_areas_csv(path)?;
        match_areas(&mut traces, &areas, request.force_tolerance, path)?;
    }
    let fit = |f: fn(&TraceResult) -> f64| {
        let a: Vec<f64> = traces.iter().filter_map(|t| t.area_m2).collect();
        let y: Vec<f64> = traces
            .iter()
            .filter(|t| t.area_m2.is_some())
            .map(f)
            .collect();
        fit_shear_strength(&a, &y)
    };
    let shear = fit(|t| t.slip.static_friction_n);
    let kinetic_shear = fit(|t| t.slip.kinetic_friction_n);
    let normals: Vec<f64> = traces.iter().map(|t| t.normal_force_n).collect();
    let mus: Vec<f64> = traces.iter().map(TraceResult::mu_static).collect();
    let trend = mu_trend(&normals, &mus);
    let mut outcome = FrictionOutcome {
        traces,
        shear,
        kinetic_shear,
        mu_trend: trend,
        written: Vec::new(),
        warnings,
    };
    outcome.written = write_outputs(request, &outcome)?;
    Ok(outcome)
}

fn analyse_trace(
    path: &Path,
    request: &FrictionRequest,
    warnings: &mut Vec<String>,
) -> Result<TraceResult> {
    let trace = read_trace(path, request.rotation_radius_m)?;
    let at = || Location::file(path);
    let normal_force_n = match (trace.normal_force_n, request.normal_force_n) {
        (Some(column), flag) => {
            if let Some(flag) = flag.filter(|f| (column / f - 1.0).abs() > request.force_tolerance)
            {
                warnings.push(format!(
                    "{}: the normal-force column ({:.4} mN) differs from --normal-force ({:.4} mN); using the column",
                    path.display(),
                    column * 1e3,
                    flag * 1e3
                ));
            }
            column
        }
        (None, Some(flag)) => flag,
        (None, None) => {
            return Err(Error::bad_input(
                at(),
                "no normal_force_mN or normal_force_N column; give --normal-force (e.g. 40mN)",
            ))
        }
    };
    if normal_force_n <= 0.0 || !normal_force_n.is_finite() {
        return Err(Error::bad_input(
            at(),
            format!(
                "normal force {:.4} mN must be positive",
                normal_force_n * 1e3
            ),
        ));
    }
    let slip = detect_slip(&trace.x, &trace.friction_n, &request.slip).ok_or_else(|| {
        Error::bad_input(
            at(),
            "no slip found: the friction force never drops clearly below a preceding maximum (or the trace ends during the drop)",
        )
    })?;
    if slip.criterion == SlipCriterion::Plateau {
        warnings.push(format!(
            "{}: no drop after the peak; slip taken where the loading slope collapses (plateau), so static = kinetic friction",
            path.display()
        ));
    }
    Ok(TraceResult {
        file: path.to_path_buf(),
        x_axis: trace.x_axis,
        normal_force_n,
        slip,
        area_m2: None,
    })
}

/// Give each trace the area of the row with the nearest force, within `tolerance` (relative).
fn match_areas(
    traces: &mut [TraceResult],
    areas: &[(f64, f64)],
    tolerance: f64,
    path: &Path,
) -> Result<()> {
    for t in traces.iter_mut() {
        let n = t.normal_force_n;
        let nearest = areas
            .iter()
            .min_by(|a, b| (a.0 - n).abs().total_cmp(&(b.0 - n).abs()))
            .filter(|a| (a.0 / n - 1.0).abs() <= tolerance);
        t.area_m2 = nearest.map(|a| a.1);
    }
    if traces.iter().all(|t| t.area_m2.is_some()) {
        return Ok(());
    }
    let list = |v: Vec<f64>| {
        v.iter()
            .map(|f| format!("{:.4}", f * 1e3))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let unmatched: Vec<String> = traces
        .iter()
        .filter(|t| t.area_m2.is_none())
        .map(|t| t.file.display().to_string())
        .collect();
    Err(Error::bad_input(
        Location::file(path),
        format!(
            "mismatched forces: no area row within {:.2} % for {}; trace forces {} mN, areas.csv forces {} mN",
            tolerance * 100.0,
            unmatched.join(", "),
            list(traces.iter().map(|t| t.normal_force_n).collect()),
            list(areas.iter().map(|a| a.0).collect()),
        ),
    ))
}

fn write_outputs(request: &FrictionRequest, outcome: &FrictionOutcome) -> Result<Vec<PathBuf>> {
    let mut inputs = request.traces.clone();
    inputs.extend(request.areas.iter().cloned());
    let staging = Staging::new(&request.out_dir, &inputs)?;
    staging.write("friction.csv", results_csv(&outcome.traces)?.as_bytes())?;
    let text = serde_json::to_string_pretty(&summary_json(request, outcome))
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    staging.write("summary.json", text.as_bytes())?;
    staging.write(
        "friction_vs_load.png",
        &load_chart(&outcome.traces, outcome.shear.as_ref()).to_png()?,
    )?;
    staging.write("mu_vs_load.png", &mu_chart(&outcome.traces).to_png()?)?;
    if let Some(fit) = &outcome.shear {
        staging.write(
            "friction_vs_area.png",
            &area_chart(&outcome.traces, fit).to_png()?,
        )?;
    }
    staging.commit()
}

/// `friction.csv`: one row per trace; every number's unit is in its column name. Slip positions
/// go in the column of the trace's own x unit (`slip_at_um`, `slip_at_rad`, `slip_at_s`).
pub fn results_csv(traces: &[TraceResult]) -> Result<String> {
    let axes: Vec<XAxis> = XAxis::ALL
        .into_iter()
        .filter(|a| traces.iter().any(|t| t.x_axis == *a))
        .collect();
    let with_area = traces.iter().any(|t| t.area_m2.is_some());
    let mut header = vec![
        "file".to_string(),
        "normal_force_mN".into(),
        "static_friction_mN".into(),
        "kinetic_friction_mN".into(),
    ];
    header.extend(axes.iter().map(|a| a.slip_column().to_string()));
    header.extend([
        "mu_static".into(),
        "mu_kinetic".into(),
        "noise_mN".into(),
        "slip_criterion".into(),
    ]);
    if with_area {
        header.extend(["area_um2".into(), "shear_stress_MPa".into()]);
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    w.write_record(&header).map_err(csv_err)?;
    for t in traces {
        w.write_record(result_row(t, &axes, with_area))
            .map_err(csv_err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

fn result_row(t: &TraceResult, axes: &[XAxis], with_area: bool) -> Vec<String> {
    let mut row = vec![
        t.file.display().to_string(),
        format!("{:.6}", t.normal_force_n * 1e3),
        format!("{:.6}", t.slip.static_friction_n * 1e3),
        format!("{:.6}", t.slip.kinetic_friction_n * 1e3),
    ];
    row.extend(axes.iter().map(|a| {
        if *a == t.x_axis {
            format!("{:.6}", a.to_column_unit(t.slip.x))
        } else {
            String::new()
        }
    }));
    row.extend([
        format!("{:.6}", t.mu_static()),
        format!("{:.6}", t.mu_kinetic()),
        format!("{:.6}", t.slip.noise_n * 1e3),
        t.slip.criterion.name().to_string(),
    ]);
    if with_area {
        match t.area_m2 {
            Some(a) => row.extend([
                format!("{:.6}", a * 1e12),
                format!("{:.6}", t.slip.static_friction_n / a * 1e-6),
            ]),
            None => row.extend([String::new(), String::new()]),
        }
    }
    row
}

fn shear_json(fit: &Option<ShearFit>) -> Value {
    match fit {
        Some(f) => json!({
            "tau_MPa": f.tau_pa * 1e-6,
            "tau_se_MPa": f.tau_se_pa.map(|s| s * 1e-6),
            "r2": f.r_squared,
            "points": f.points,
        }),
        None => Value::Null,
    }
}

fn summary_json(request: &FrictionRequest, outcome: &FrictionOutcome) -> Value {
    let traces: Vec<Value> = outcome
        .traces
        .iter()
        .map(|t| {
            json!({
                "file": t.file.display().to_string(),
                "normal_force_mN": t.normal_force_n * 1e3,
                "static_friction_mN": t.slip.static_friction_n * 1e3,
                "kinetic_friction_mN": t.slip.kinetic_friction_n * 1e3,
                "slip_at": t.x_axis.to_column_unit(t.slip.x),
                "slip_at_unit": t.x_axis.slip_column().trim_start_matches("slip_at_"),
                "slip_sample": t.slip.index,
                "slip_criterion": t.slip.criterion.name(),
                "mu_static": t.mu_static(),
                "mu_kinetic": t.mu_kinetic(),
                "noise_mN": t.slip.noise_n * 1e3,
                "drop_threshold_mN": t.slip.drop_threshold_n * 1e3,
                "area_um2": t.area_m2.map(|a| a * 1e12),
            })
        })
        .collect();
    let shear = outcome.shear;
    let trend = outcome.mu_trend.map(|m| {
        json!({
            "exponent": m.exponent,
            "exponent_se": m.exponent_se,
            "relative_spread": m.relative_spread,
            "varies": m.varies,
        })
    });
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "inputs": {
            "traces": request.traces.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
            "areas": request.areas.as_ref().map(|p| p.display().to_string()),
            "normal_force_mN": request.normal_force_n.map(|n| n * 1e3),
            "rotation_radius_mm": request.rotation_radius_m.map(|r| r * 1e3),
            "force_tolerance_pct": request.force_tolerance * 100.0,
        },
        "method": {
            "static_friction": "denoised force at the onset of slip: the first running maximum of the running-median force after which its median over 4h+1 samples stays more than max(k*noise, f*range) lower; onset = last raw sample before the steep part of the drop; line fit through the raw samples up to the onset, evaluated there; without a drop, where the centred slope over +-5h samples stays below 0.1 of the loading slope (criterion plateau, F_s = F_k)",
            "kinetic_friction": "median raw force from the first minimum after the slip drop to the end of the trace",
            "noise": "1.4826*MAD of second differences / sqrt(6)",
            "smoothing_half_width": request.slip.smoothing_half_width,
            "drop_noise_levels": request.slip.drop_noise_levels,
            "min_drop_fraction": request.slip.min_drop_fraction,
            "torque_to_force": "F = T / rotation radius",
            "shear_strength": "F_s = tau*A, least squares in F through the origin; se = sqrt(SS_res/(n-1)/sum A^2); r2 about the mean",
            "mu_trend": "mu_static = c*N^m by log-log least squares; m = 0 is Amontons' law; varies when |m| > 2 se",
        },
        "tau_MPa": shear.map(|f| f.tau_pa * 1e-6),
        "tau_se_MPa": shear.and_then(|f| f.tau_se_pa).map(|s| s * 1e-6),
        "r2": shear.and_then(|f| f.r_squared),
        "static_shear_fit": shear_json(&outcome.shear),
        "kinetic_shear_fit": shear_json(&outcome.kinetic_shear),
        "mu_static_vs_load": trend,
        "traces": traces,
        "warnings": outcome.warnings,
    })
}

/// Friction against normal force (Fig. 3b of the paper), with τ·A at each load's measured area
/// when τ was fitted.
fn load_chart(traces: &[TraceResult], shear: Option<&ShearFit>) -> Chart {
    let pts = |f: fn(&Slip) -> f64| {
        traces
            .iter()
            .map(|t| (t.normal_force_n * 1e3, f(&t.slip) * 1e3))
            .collect()
    };
    Chart {
        title: "Friction versus normal force".into(),
        x_label: "normal force N (mN)".into(),
        y_label: "friction force F (mN)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperLeft,
        points: vec![
            PointSet {
                label: "static F_s".into(),
                xy: pts(|s| s.static_friction_n),
            },
            PointSet {
                label: "kinetic F_k".into(),
                xy: pts(|s| s.kinetic_friction_n),
            },
        ],
        curves: shear
            .map(|fit| tau_area_curve(traces, fit))
            .into_iter()
            .collect(),
    }
}

/// τ·A at the traces' areas, in order of normal force.
fn tau_area_curve(traces: &[TraceResult], fit: &ShearFit) -> Curve {
    let mut xy: Vec<(f64, f64)> = traces
        .iter()
        .filter_map(|t| {
            t.area_m2
                .map(|a| (t.normal_force_n * 1e3, fit.tau_pa * a * 1e3))
        })
        .collect();
    xy.sort_by(|a, b| a.0.total_cmp(&b.0));
    Curve {
        label: format!("τ·A, τ = {:.1} MPa", fit.tau_pa * 1e-6),
        xy,
    }
}

fn mu_chart(traces: &[TraceResult]) -> Chart {
    let pts = |f: fn(&TraceResult) -> f64| {
        traces
            .iter()
            .map(|t| (t.normal_force_n * 1e3, f(t)))
            .collect()
    };
    Chart {
        title: "Friction coefficient versus normal force".into(),
        x_label: "normal force N (mN)".into(),
        y_label: "friction coefficient μ = F/N".into(),
        axes: Axes::Linear,
        legend: Legend::UpperRight,
        points: vec![
            PointSet {
                label: "μ static".into(),
                xy: pts(TraceResult::mu_static),
            },
            PointSet {
                label: "μ kinetic".into(),
                xy: pts(TraceResult::mu_kinetic),
            },
        ],
        curves: Vec::new(),
    }
}

fn area_chart(traces: &[TraceResult], fit: &ShearFit) -> Chart {
    let xy: Vec<(f64, f64)> = traces
        .iter()
        .filter_map(|t| {
            t.area_m2
                .map(|a| (a * 1e12, t.slip.static_friction_n * 1e3))
        })
        .collect();
    let a_max = xy.iter().map(|p| p.0).fold(0.0, f64::max) * 1.05;
    // τ [MPa] · A [µm²] = τ·A [µN] = 1e-3 · τ·A [mN].
    let tau_mpa = fit.tau_pa * 1e-6;
    Chart {
        title: "Static friction versus real contact area".into(),
        x_label: "real contact area A (µm²)".into(),
        y_label: "static friction F_s (mN)".into(),
        axes: Axes::Linear,
        legend: Legend::UpperLeft,
        points: vec![PointSet {
            label: "measured".into(),
            xy,
        }],
        curves: vec![Curve {
            label: format!("F = τ·A, τ = {tau_mpa:.1} MPa"),
            xy: vec![(0.0, 0.0), (a_max, tau_mpa * a_max * 1e-3)],
        }],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn shear_fit_through_origin() {
        let a = [1e-10, 2e-10, 4e-10];
        let f: Vec<f64> = a.iter().map(|x| 5e7 * x).collect();
        let fit = fit_shear_strength(&a, &f).unwrap();
        assert!((fit.tau_pa / 5e7 - 1.0).abs() < 1e-12);
        assert!(fit.tau_se_pa.unwrap() < 1e-3);
        assert!((fit.r_squared.unwrap() - 1.0).abs() < 1e-12);
        assert!(fit_shear_strength(&[0.0], &[1.0]).is_none());
    }

    #[test]
    fn mu_trend_of_amontons_and_of_a_power_law() {
        let n = [4.0, 10.0, 20.0, 40.0];
        let constant = mu_trend(&n, &[0.3, 0.3, 0.3, 0.3]).unwrap();
        assert!(constant.exponent.abs() < 1e-12 && constant.relative_spread < 1e-12);
        let mu: Vec<f64> = n.iter().map(|x: &f64| 0.5 * x.powf(-0.2)).collect();
        let falling = mu_trend(&n, &mu).unwrap();
        assert!((falling.exponent + 0.2).abs() < 1e-12);
    }

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
