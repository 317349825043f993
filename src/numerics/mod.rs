//! Small shared numerics kept on purpose rather than taken from a crate, each with its reason
//! beside it: [`stats`] (mean ± sample sd, the median) and [`golden`] (golden-section search
//! with an absolute stopping width).
//!
//! What was taken from crates instead: erfc (`libm`), the complete elliptic integrals
//! (`ellip`), the dense LU solve of the Greenwood–Tripp Newton iteration (`nalgebra`) and the
//! bead fits' Levenberg–Marquardt (`levenberg-marquardt`); `.npy` reading stays ours
//! ([`crate::io::topography`], reason there).

pub mod golden;
pub mod stats;
