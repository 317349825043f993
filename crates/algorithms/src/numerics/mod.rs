//! Small shared numerics kept on purpose rather than taken from a crate, each with its reason
//! beside it: [`stats`] (mean ± sample sd, the median) and [`golden`] (golden-section search
//! with an absolute stopping width).
//!
//! What was taken from crates instead: erfc (`libm`) and the bead fits' Levenberg–Marquardt
//! (`levenberg-marquardt`). Kept elsewhere, with the measured reason beside the code: the
//! complete elliptic integrals and the dense solve of the Greenwood–Tripp model
//! ([`crate::solver::gt`], speed) and `.npy` reading (`contactscope_formats::topography`, hostile
//! input).

pub mod golden;
pub mod stats;
