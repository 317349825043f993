//! The bundled contact-mechanics solver (Weber et al. 2018, Methods: GT model, Elastic
//! interactions, Plasticity models): elastic half-space operators with free or periodic
//! boundaries ([`halfspace`], [`greens`]), Polonsky–Keer constrained conjugate gradients with
//! bounded pressure and implicit hardening ([`cg`]), load sweeps with the paper's models
//! ([`simulate`]) and the Greenwood–Tripp rough-sphere model with its bearing-area map ([`gt`]).

pub mod cg;
pub mod gpu;
pub mod greens;
pub mod gt;
pub mod halfspace;
pub mod simulate;
