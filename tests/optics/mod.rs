//! The optics commands: PSF from beads, Newton rings, autocorrelation, and `compare`
//! (simulated maps blurred, registered and scored against micrographs).

mod autocorr;
mod compare;
mod newton;
mod psf;
