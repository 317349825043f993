//! Contact-mechanics solvers: reference models and, later, the half-space solvers.

pub mod gt;
