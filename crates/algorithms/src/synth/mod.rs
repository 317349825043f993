//! Every seeded generator of synthetic data with known ground truth, for tests, benchmarks and the
//! demo: load series of confocal micrographs ([`series`]), simulated contact maps imaged by the
//! microscope ([`micrograph`]), bead images for the PSF ([`beads`]), Newton-ring and fluorescence
//! pairs ([`rings`]) and rheometer friction traces ([`traces`]); contact ramps solved by the
//! half-space solver for self-affine rough spheres at three patch scales and imaged by a 12-bit
//! confocal camera, with exact truth, for validating area intervals ([`solved`]). Rough
//! surfaces are generated in [`crate::surface::generate`]. The same parameters and seed give the
//! same data (ChaCha8).

pub mod beads;
pub mod micrograph;
pub mod rings;
pub mod series;
pub mod solved;
pub mod traces;

pub use micrograph::{render_micrograph, MicrographParams};
pub use series::{generate, SynthImage, SynthParams};
