//! # contactscope
//!
//! Real-contact-area microscopy after Weber et al., Nat. Commun. 9, 888 (2018): confocal images of a
//! rough sphere pressed on a rigidochromic coverslip, one per normal load, become an
//! area-versus-load table.
//!
//! The pipeline, one module per stage:
//!
//! 1. [`stack`] — TIFF pages to [`stack::Plane`]s with pixel-size metadata; [`stack::series`]
//!    turns files, directories and manifests into an ordered load series.
//! 2. [`threshold`] — a mergeable [`threshold::Histogram`] and an exact Otsu threshold over the
//!    whole series (Otsu 1979).
//! 3. [`measure`] — contact pixels, area, intensities and 8-connected patches per image.
//! 4. [`fit`] — power-law and proportional area–load fits; [`hertz`] reference formulas.
//! 5. [`analysis`] — runs 1–4 over a series in two streaming passes with bounded memory.
//! 6. [`report`], [`plot`], [`output`] — CSV, JSON and PNG/SVG outputs, written atomically;
//!    [`pipeline`] runs the whole `analyze` job.
//! 7. [`synth`] — a seeded generator of realistic load series with known ground truth.
//!
//! Units: SI inside the library; names of output fields carry their unit (`area_um2`,
//! `force_mN`). Conventions are written down once in `docs/conventions.md`.

#![warn(missing_docs)]

pub mod analysis;
pub mod error;
pub mod fit;
pub mod hertz;
pub mod measure;
pub mod output;
pub mod pipeline;
pub mod plot;
pub mod report;
pub mod stack;
pub mod synth;
pub mod threshold;
pub mod units;

pub use error::{Error, Result};
