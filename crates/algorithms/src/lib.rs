//! # contactscope
//!
//! Real-contact-area microscopy after Weber et al., Nat. Commun. 9, 888 (2018): confocal images of a
//! rough sphere pressed on a rigidochromic coverslip, one per normal load, become an
//! area-versus-load table, checked against contact mechanics.
//!
//! ## Where this crate sits
//!
//! The algorithms layer of the workspace (`docs/architecture.md`), one module per stage, on
//! in-memory data, SI units, **no file access**:
//! [`image`] (planes and pixel sizes, from `contactscope-formats`) → [`threshold`] (mergeable
//! histogram, exact Otsu 1979) → [`measure`] (contact pixels, intensities, patches) →
//! [`analysis`] (the two-pass series analysis over a [`analysis::PlaneSource`]; area–load fits).
//! Beside them: [`optics`] (PSF, blur, Newton rings), [`spectral`] (FFTs, autocorrelation,
//! registration), [`surface`] (height maps: detrending, statistics, hole filling, generation),
//! [`solver`] (half-space contact, plasticity, Greenwood–Tripp), [`mechanics`] (friction,
//! squeeze tests, Hertz), [`compare`] (simulated maps against micrographs), [`model_fit`]
//! (contact models fitted to an area–load curve), [`synth`] (seeded generators with known
//! truth) and [`numerics`].
//!
//! Below it, `contactscope-formats` reads files into the types these modules take; above it,
//! `contactscope-jobs` runs whole commands (a typed request in, a typed outcome out) for the
//! command line and the Python package.
//!
//! ## The pipeline in memory
//!
//! ```
//! use contactscope::measure::measure;
//! use contactscope::image::Plane;
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
//!
//! // The same two passes as one call: the series analysis over the in-memory planes.
//! use contactscope::analysis::{analyze, AnalysisOptions};
//! let analysis = analyze(planes.as_slice(), &AnalysisOptions::default(), &|_, _, _| {}, &|_, _, _| Ok(()))?;
//! assert_eq!(analysis.series_threshold.map(|s| s.value), Some(t.value));
//! # Ok::<(), contactscope::Error>(())
//! ```
//!
//! Units: SI inside the library; names of output fields carry their unit (`area_um2`,
//! `force_mN`). Conventions are written down once in `docs/conventions.md`.

#![warn(missing_docs)]

pub mod error;

/// Planes, pixel sizes and `f64` images, as the readers of `contactscope-formats` return them.
pub use contactscope_formats::image;
/// Limits on work sizes (shared with the readers).
pub use contactscope_formats::limits;

pub mod analysis;
pub mod compare;
pub mod measure;
pub mod mechanics;
pub mod model_fit;
pub mod numerics;
pub mod optics;
pub mod solver;
pub mod spectral;
pub mod surface;
pub mod synth;
pub mod threshold;

pub use error::{Error, Result};
