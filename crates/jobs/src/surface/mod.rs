//! The `surface` job: a seeded self-affine random surface ([`contactscope::surface::generate`])
//! and its finite-difference roughness statistics, in memory. Every front-end builds a
//! [`SurfaceRequest`] (the command line from its flags, Python from its keywords) with the same
//! defaults, [`SurfaceRequest::check`] applies the same range checks, and [`run`] returns a
//! [`SurfaceOutcome`] (the heights and their statistics; serialised, the statistics in lab units,
//! or in SI units for Python, [`crate::lab`]). [`files`] writes the heights as `.npy` or `.gsf`.

pub mod files;

use serde::Serialize;

use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::Topography;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::{Error, Result};
use crate::heights::Roughness;
use crate::lab;

/// Everything `surface` needs. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceRequest {
    /// Columns (x).
    pub nx: usize,
    /// Rows (y).
    pub ny: usize,
    /// Pixel size, m.
    pub pixel_size_m: f64,
    /// Hurst exponent H in (0, 1]; the PSD falls as q^(−2−2H).
    pub hurst: f64,
    /// The rms height (m) or rms slope the surface is scaled to.
    pub target: RmsTarget,
    /// Roll-off wavelength (PSD flat above it), m.
    pub rolloff_m: Option<f64>,
    /// Short-wavelength cutoff (no roughness below it), m.
    pub cutoff_m: Option<f64>,
    /// Seed of the white noise.
    pub seed: u64,
}

impl SurfaceRequest {
    /// Default grid, pixels per side.
    pub const SIZE: usize = 1024;
    /// Default Hurst exponent.
    pub const HURST: f64 = 0.8;
    /// Default seed.
    pub const SEED: u64 = 7;

    /// A request with the defaults: 1024 × 1024 pixels, H = 0.8, no roll-off, no cutoff, seed 7.
    pub fn new(pixel_size_m: f64, target: RmsTarget) -> Self {
        SurfaceRequest {
            nx: Self::SIZE,
            ny: Self::SIZE,
            pixel_size_m,
            hurst: Self::HURST,
            target,
            rolloff_m: None,
            cutoff_m: None,
            seed: Self::SEED,
        }
    }

    /// Every range check, the same for every front-end; each refusal names the parameter. (The
    /// generator's own checks, such as at least 4 × 4 pixels and wavelengths that fit the map,
    /// follow in [`run`].)
    pub fn check(&self) -> Result<()> {
        Quantity::PixelSize.check(self.pixel_size_m, Param::PixelSize)?;
        if !(self.hurst > 0.0 && self.hurst <= 1.0) {
            return Err(Error::InvalidArgument(format!(
                "{}: the Hurst exponent {} must lie in (0, 1]",
                Param::Hurst,
                self.hurst
            )));
        }
        match self.target {
            RmsTarget::Height(h) => {
                Quantity::Height.check(h, Param::RmsHeight)?;
            }
            RmsTarget::Slope(s) | RmsTarget::SpectralSlope(s) => {
                if !(s > 0.0 && s <= 1.0) {
                    return Err(Error::InvalidArgument(format!(
                        "{}: the rms slope {s} must lie in (0, 1]",
                        Param::RmsSlope
                    )));
                }
            }
        }
        if let Some(r) = self.rolloff_m {
            Quantity::Length.check(r, Param::Rolloff)?;
        }
        if let Some(c) = self.cutoff_m {
            Quantity::Length.check(c, Param::Cutoff)?;
        }
        Ok(())
    }

    /// The generator's parameters.
    pub fn params(&self) -> SelfAffineParams {
        SelfAffineParams {
            nx: self.nx,
            ny: self.ny,
            dx_m: self.pixel_size_m,
            hurst: self.hurst,
            rolloff_wavelength_m: self.rolloff_m,
            short_cutoff_wavelength_m: self.cutoff_m,
            target: self.target,
            seed: self.seed,
        }
    }
}

/// The generated surface and its finite-difference statistics.
#[derive(Debug, Clone, Serialize)]
pub struct SurfaceOutcome {
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Pixel size, m.
    #[serde(rename = "pixel_size_nm", serialize_with = "lab::m_as_nm")]
    pub pixel_size_m: f64,
    /// Roughness (written as `h_rms_nm`, `h_prime_rms`, `h_double_prime_rms_per_um`).
    #[serde(flatten)]
    pub roughness: Roughness,
    /// The heights (m, rows = y) and pixel size.
    #[serde(skip)]
    pub topography: Topography,
}

/// Run `surface` in memory: check, generate, compute the statistics. Nothing is written.
pub fn run(request: &SurfaceRequest) -> Result<SurfaceOutcome> {
    request.check()?;
    let topography = self_affine(&request.params())?;
    let stats = SurfaceStats::finite_differences(&topography)?;
    Ok(SurfaceOutcome {
        nx: topography.nx(),
        ny: topography.ny(),
        pixel_size_m: topography.dx_m,
        roughness: Roughness::from(&stats),
        topography,
    })
}
