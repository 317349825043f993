//! # contactscope-jobs
//!
//! The jobs layer of contactscope (`docs/architecture.md`): one module per command, each a
//! typed request in and a typed outcome out, shared by every front-end (the command line, the
//! Python package). A job reads its inputs through `contactscope-formats`, runs the algorithms
//! of `contactscope`, and never prints; long jobs take a progress callback.
//!
//! Support modules:
//!
//! | module | what |
//! |---|---|
//! | [`series`] | files, folders and manifests (TIFF, CZI, ND2, LIF) → which page or plane is which load; the file-backed plane source of the series analysis |
//! | [`heights`] | a height-map file read, filled and detrended as every command takes it |
//! | [`images`] | a micrograph file or planes in memory, as the optics commands take them |
//! | [`provenance`] | version, source revision, machine, times, SHA-256 of input files: what `batch.json` records |
//! | [`staging`] | output folders written to a staging folder and renamed into place atomically; inputs never overwritten |
//! | [`table`] | small CSV tables whose column names carry the unit (`force_mN`) |
//! | [`results`] | one command's outputs read by another: `areas.csv`, a `simulate` folder, `psf.json` |
//! | [`mechanics_csv`] | the mechanics CSVs: friction traces, squeeze tests |
//! | `plot` | charts (PNG/SVG) and micrograph panels (PNG); feature `plots` (on by default; the Python wheel builds without it) |

#![warn(missing_docs)]

pub mod container_out;
pub mod error;
pub mod fits;
pub mod heights;
pub mod images;
pub mod lab;
pub mod mechanics_csv;
pub mod physics;
#[cfg(feature = "plots")]
pub mod plot;
pub mod provenance;
pub mod results;
pub mod series;
pub mod staging;
pub mod summary;
pub mod table;

pub mod analyze;
pub mod autocorr;
pub mod batch;
pub mod compare;
// The demo writes an HTML report with figures: it needs the `plots` feature.
#[cfg(feature = "plots")]
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

pub use error::{Error, Result};
