//! # contactscope-formats
//!
//! The bottom layer of contactscope (`docs/architecture.md`): every file format the project reads,
//! decoded into plain in-memory data with its calibration, and the [`limits`] on every size a
//! file states. It depends on no other crate of the project and computes no science: no
//! thresholds, no statistics, no detrending (those are in the `contactscope` crate, which takes
//! these types in memory).
//!
//! | module | what |
//! |---|---|
//! | [`image`] | one decoded page ([`image::Plane`]: sample type, integer codes or floats), the pixel size with its source, `f64` images |
//! | [`tiff`] | TIFF reading (pages, channels, pixel-size metadata of ImageJ and OME) and writing |
//! | [`microscopy`] | confocal files: Zeiss CZI, Nikon ND2, Leica LIF, and TIFF described the same way; the selection of a plane |
//! | [`topography`] | height maps: `.npy`, float TIFF, `.gsf`, text, WSxM, Nanoscope, and the vendor AFM/profilometer formats (`.ibw`, `.nid`, `.mi`, Park TIFF, `.gwy`, `.x3p`, `.sdf`, `.opd`, `.plu`, `.sur`, `.frt`) as a [`topography::HeightMap`] |
//! | [`ranges`] | plausible ranges of physical values (pixel sizes, forces, moduli, …) from metadata, manifests and arguments |
//! | [`units`] | quantities as text: `290um`, `3.7GPa`, `4,10,20mN`, ranges and ratios |
//! | [`param`] | the parameters a person sets, named as their front-end names them (`--pixel-size`, `pixel_size=`) |
//! | [`limits`] | the largest plane, side, kernel and profile any reader or algorithm may allocate |
//! | [`inputs`] | the files this process has read (outputs never overwrite them) |
//! | [`error`] | typed errors naming the file, page or line |
//!
//! Units: heights and lengths in metres; intensities in the file's own grey values. Every size
//! and count read from a file is checked against the file's length and against [`limits`]
//! before anything is allocated.

#![warn(missing_docs)]

pub(crate) mod binary;
pub mod error;
pub mod image;
pub mod inputs;
pub mod limits;
pub mod microscopy;
pub mod param;
pub mod ranges;
pub mod remote;
pub mod tiff;
pub mod topography;
pub mod units;

pub use error::{Error, Location, Result};
pub use limits::Limits;
