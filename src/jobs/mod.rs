//! Layer (c), jobs: one command's whole run, files to files. Each job takes a typed, validated
//! request, reads its inputs through [`crate::io`], runs the algorithms of layer (a), writes its
//! outputs atomically ([`crate::io::staging`]) and returns an outcome; it never prints (a job
//! with long work takes a progress callback). The command line (`src/cli/`) and later the
//! Python package call these.

pub mod analyze;
pub mod autocorr;
pub mod compare;
pub mod demo;
pub mod fit_hardening;
pub mod friction;
pub mod hertz;
pub mod info;
pub mod newton;
pub mod psf;
pub mod simulate;
pub mod surface;
pub mod synth_series;
pub mod threshold;
pub mod topography;
