//! Seeded synthetic rheometer friction traces with known static and kinetic friction, and their
//! CSV text in the input format of `contactscope_jobs::mechanics_csv::read_trace`.

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

use crate::mechanics::friction::XAxis;

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

/// A synthetic trace as CSV text in the input format of `contactscope_jobs::mechanics_csv::read_trace`.
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
