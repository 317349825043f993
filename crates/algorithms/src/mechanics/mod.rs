//! Mechanical tests beside the microscopy: friction traces from the rheometer (static friction,
//! kinetic friction, interfacial shear strength τ from F = τ·A) and squeeze tests of single
//! spheres between two plates (contact modulus E* from Hertz theory). Weber et al. 2018, Methods
//! ("Mechanical testing") and Fig. 3b; and the Hertz formulas both lean on ([`hertz`]).
//! Conventions: `docs/mechanics.md`.

pub mod friction;
pub mod hertz;
pub mod squeeze;
