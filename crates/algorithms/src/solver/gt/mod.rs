//! Greenwood–Tripp model of a rough elastic sphere on a flat, and the "GT bearing-area" contact
//! map of Weber et al. 2018, Fig. 2b.
//!
//! # Model
//!
//! J. A. Greenwood and J. H. Tripp, "The elastic contact of rough spheres", J. Appl. Mech. 34,
//! 153–159 (1967). Summits with Gaussian heights (standard deviation σ), areal density η and
//! radius β each make a Hertz contact; their averaged pressure deforms the sphere (radius R) as
//! an elastic half-space of contact modulus E*. The equations are those restated in
//! `docs/methods.md` §4.2:
//!
//! * F_n(t) = ∫_t^∞ (z − t)^n φ(z) dz, φ the standard normal density ([`gt_f`]);
//! * mean-plane separation u(r) = d + r²/(2R) + w(r) − w(0), d the central separation;
//! * asperity pressure p(r) = (4/3)·η·E*·β^{1/2}·σ^{3/2}·F_{3/2}(u(r)/σ);
//! * bulk deflection under ring loads w(r) = (4r/(πE*)) ∫_0^∞ p(rξ) Λ(ξ) dξ with
//!   Λ(ξ) = ξK(ξ) for ξ < 1 and K(1/ξ) for ξ > 1 (K: complete elliptic integral of the first
//!   kind, modulus k), integrated against the antiderivative S of (2/π)Λ
//!   ([`ring_kernel_antiderivative`]);
//! * load N = 2π ∫ p r dr; GT real-area density π·η·β·σ·F₁(u/σ).
//!
//! # Notation and choices (`docs/methods.md` §4.1, §10 item 7)
//!
//! Greenwood & Tripp call the sphere radius B and the summit radius β; Weber et al. swap the
//! letters. Here **R is the sphere radius and β the summit radius**, with β = 1/h''_rms and
//! η·h_rms·β = 0.05 (Weber et al.). The summit-height deviation σ is taken as **σ = h_rms**, the
//! same h_rms as in the density relation; the paper does not say which σ it used.
//!
//! # Scaled form
//!
//! With ρ = r/√(2Rσ), p̃ = p/(E*√(σ/(8R))), w̃ = w/σ, d* = d/σ and μ = (8/3)·η·σ·√(2Rβ):
//! p̃ = μ·F_{3/2}(d* + ρ² + w̃(ρ) − w̃(0)), w̃(ρ) = ρ ∫ p̃(ρξ)(2/π)Λ(ξ) dξ, P̃ = 2π ∫ p̃ ρ dρ and
//! N = P̃·E*·σ^{3/2}·√(R/2). This is the parametrisation of ContactMechanics'
//! `GreenwoodTripp` reference function, whose numbers `docs/validation.md` B12 records. At the
//! solution p̃(0) = μ·F_{3/2}(d*), because u(0) = d.
//!
//! # Discretisation and solvers
//!
//! p̃ is piecewise linear on a radial grid ([`RadialKernel`]); w̃ is its exact integral against
//! the kernel (integration by parts onto S, whose interval means come from Gauss–Legendre
//! quadrature, graded towards the logarithmic point ξ = 1). The discrete equations are solved
//! either by the damped fixed point of `docs/methods.md` §4.3 (ContactMechanics' scheme) or by
//! Newton's method on the same equations; [`gt_profile`] uses Newton, because the mixing that
//! keeps the fixed point stable shrinks as μ·F_{1/2}(u/σ)·ρ_max grows, i.e. towards the Hertz
//! limit, where it would need many thousands of iterations.
//!
//! # Bearing area (`docs/methods.md` §4.4)
//!
//! [`gt_bearing_area`] overlays a measured roughness map on the GT separation profile: contact
//! wherever z_rough ≥ u(r). This geometric overlap is what the paper's Fig. 2b shows; it is not
//! GT's own area integral (reported beside it as `gt_area_m2`).

//!
//! # Files
//!
//! [`functions`]: F_n, the elliptic integrals and the ring kernel; [`kernel`]: the radial grid
//! and the scaled solve; [`profile`]: the dimensional profile and its load search;
//! [`bearing`]: the bearing-area map.

pub mod bearing;
pub mod functions;
pub mod kernel;
pub mod profile;

pub use bearing::{gt_bearing_area, ContactMap};
pub use functions::{elliptic_e, elliptic_k, gt_f, ring_kernel, ring_kernel_antiderivative};
pub use kernel::{RadialKernel, ScaledMethod, ScaledOptions, ScaledSolution};
pub use profile::{gt_profile, gt_profile_with, GtNumerics, GtParams, GtProfile};

#[cfg(test)]
mod tests;
