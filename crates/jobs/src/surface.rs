//! The `surface` job: a seeded self-affine random surface ([`contactscope::surface::generate`]) written
//! as `.npy` or `.gsf` (heights in metres).

use std::path::PathBuf;

use crate::error::{Error, Result};
use crate::staging::write_atomic;
use contactscope::surface::generate::{self_affine, SelfAffineParams};
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::Topography;
use contactscope_formats::topography::{encode_gsf, encode_npy};

/// What to generate and where to write it, already validated.
#[derive(Debug, Clone)]
pub struct SurfaceRequest {
    /// Grid, spectrum, target roughness and seed.
    pub params: SelfAffineParams,
    /// Output file, `.npy` or `.gsf`.
    pub out: PathBuf,
}

/// The generated surface and its finite-difference statistics.
#[derive(Debug, Clone)]
pub struct SurfaceOutcome {
    /// The surface as written.
    pub topography: Topography,
    /// h_rms, h'_rms and h''_rms by finite differences.
    pub stats: SurfaceStats,
}

/// Generate and write; an output name that is neither `.npy` nor `.gsf` is an error (after
/// the parameters were checked by generating).
pub fn run_surface(request: &SurfaceRequest) -> Result<SurfaceOutcome> {
    let topography = self_affine(&request.params)?;
    match request.out.extension().and_then(|e| e.to_str()) {
        Some("npy") => write_atomic(&request.out, &encode_npy(&topography.heights))?,
        Some("gsf") => write_atomic(
            &request.out,
            &encode_gsf(&topography.heights, (topography.dx_m, topography.dy_m)),
        )?,
        _ => {
            return Err(Error::InvalidArgument(format!(
                "{}: the output must end in .npy or .gsf",
                request.out.display()
            )))
        }
    }
    let stats = SurfaceStats::finite_differences(&topography)?;
    Ok(SurfaceOutcome { topography, stats })
}
