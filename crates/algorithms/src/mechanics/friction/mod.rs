//! Friction traces from the rheometer: static friction at the onset of slip, kinetic friction
//! after it, the friction coefficients μ = F/N, and the interfacial shear strength τ of
//! F_s = τ·A (Weber et al. 2018, Fig. 3b: τ ≈ 50 MPa; μ is not constant because A grows
//! sublinearly with N).
//!
//! # Trace CSV format (`contactscope_jobs::mechanics_csv::read_trace`)
//! One row per sample, in recording order; column names carry the unit and are the contract:
//!
//! * **x** (one of, first found wins in this order): `displacement_um`, `angle_rad`, `time_s`.
//!   Values must increase from row to row.
//! * **friction** (exactly one of): `friction_mN`, `friction_N`, or the rheometer's torque
//!   `torque_mNm`, `torque_Nm`. Torque T becomes force F = T / r with the sphere's rotation
//!   radius r (`rotation_radius_m`), as in the paper's Methods; torque without r is an error.
//! * **normal force** (optional): `normal_force_mN` or `normal_force_N`; its median is the
//!   trace's N. Without it the caller's N (`--forces`) is used; neither is an error.
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

mod shear;
mod slip;
mod trace;

pub use shear::{fit_shear_strength, mu_trend, MuTrend, ShearFit};
pub use slip::{detect_slip, Slip, SlipCriterion, SlipOptions};
pub use trace::{Trace, XAxis, MIN_SAMPLES};
