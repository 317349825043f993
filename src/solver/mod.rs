//! The bundled contact-mechanics solver (Weber et al. 2018, Methods: Elastic interactions,
//! Plasticity models): elastic half-space operators with free or periodic boundaries, and
//! Polonsky–Keer constrained conjugate gradients with bounded pressure and implicit hardening.

pub mod cg;
pub mod greens;
pub mod halfspace;
pub mod simulate;
