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
//! 8. [`mechanics`] — rheometer friction traces (F = τ·A) and squeeze tests (Hertz E*).
//!
//! ```
//! use contactscope::measure::measure;
//! use contactscope::stack::Plane;
//! use contactscope::synth::{generate, SynthParams};
//! use contactscope::threshold::{Binning, Histogram, Threshold};
//!
//! // Two loads of a small synthetic series (12-bit, 0.2 µm pixels, known true contact).
//! let params = SynthParams { width: 64, height: 64, forces_n: vec![4e-3, 8e-3], ..SynthParams::default() };
//! let images = generate(&params)?;
//! let planes: Vec<Plane> = images
//!     .iter()
//!     .map(|im| Plane::from_u16(64, 64, im.codes.clone()))
//!     .collect();
//!
//! // One histogram over the whole series, one exact Otsu threshold.
//! let mut pooled = Histogram::new(Binning::Integer { offset: 0 });
//! for plane in &planes {
//!     pooled.add_plane(plane)?;
//! }
//! let t = Threshold::otsu(&pooled, "series")?;
//!
//! // Contact area = contact pixels × pixel area (0.04 µm²).
//! for (plane, truth) in planes.iter().zip(&images) {
//!     let (m, _mask) = measure(plane, &t)?;
//!     let area_um2 = m.contact_pixels as f64 * 0.04;
//!     assert!((area_um2 / truth.true_area_um2 - 1.0).abs() < 0.15);
//! }
//! # Ok::<(), contactscope::Error>(())
//! ```
//!
//! Units: SI inside the library; names of output fields carry their unit (`area_um2`,
//! `force_mN`). Conventions are written down once in `docs/conventions.md`.

#![warn(missing_docs)]

pub mod analysis;
pub mod compare;
pub mod demo;
pub mod error;
pub mod fit;
pub mod fitting;
pub mod hertz;
pub mod io;
pub mod measure;
pub mod mechanics;
pub mod optics;
pub mod output;
pub mod pipeline;
pub mod plot;
pub mod report;
pub mod solver;
pub mod spectral;
pub mod stack;
pub mod stats;
pub mod surface;
pub mod synth;
pub mod threshold;
pub mod units;

pub use error::{Error, Result};
