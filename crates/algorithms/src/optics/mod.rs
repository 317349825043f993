//! Optics of the contact microscope: the point-spread function measured on beads, blurring and
//! resampling simulated maps onto the microscope's grid, and Newton-ring gap profiles
//! (Weber et al. 2018, Methods: Microscopy, Comparison with experiments; `docs/conventions.md`).
pub mod blur;
pub mod newton;
pub mod psf;
