//! `contactscope surface`: a self-affine random surface (Fourier filtering, seeded).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use contactscope::surface::generate::{RmsTarget, SelfAffineParams};
use contactscope_formats::ranges::Quantity;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::surface::{run_surface, SurfaceRequest};

use super::args::optional_length;

#[derive(clap::Args)]
pub struct Args {
    /// Grid size in pixels (square).
    #[arg(long, default_value_t = 1024)]
    size: usize,
    /// Pixel size, e.g. 32nm.
    #[arg(long)]
    pixel_size: String,
    /// Hurst exponent H in (0, 1].
    #[arg(long, default_value_t = 0.8)]
    hurst: f64,
    /// RMS slope h'_rms (central differences); or give --rms-height.
    #[arg(long, conflicts_with = "rms_height")]
    rms_slope: Option<f64>,
    /// RMS height, e.g. 50nm.
    #[arg(long)]
    rms_height: Option<String>,
    /// Roll-off wavelength (PSD flat above it), e.g. 8um.
    #[arg(long)]
    rolloff: Option<String>,
    /// Short cutoff wavelength (no roughness below it), e.g. 128nm.
    #[arg(long)]
    cutoff: Option<String>,
    /// Random seed.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Output file: .npy or .gsf (heights in metres).
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let (dx, _) = units::parse_pixel_size(&args.pixel_size).context("--pixel-size")?;
    let target = match (&args.rms_slope, &args.rms_height) {
        (Some(slope), None) => RmsTarget::Slope(*slope),
        (None, Some(h)) => {
            let h = units::parse_positive(h, Dimension::Length).context("--rms-height")?;
            RmsTarget::Height(Quantity::Height.check_text(h, "--rms-height")?)
        }
        _ => bail!("give --rms-slope or --rms-height"),
    };
    let params = SelfAffineParams {
        nx: args.size,
        ny: args.size,
        dx_m: dx,
        hurst: args.hurst,
        rolloff_wavelength_m: optional_length(&args.rolloff, "--rolloff")?,
        short_cutoff_wavelength_m: optional_length(&args.cutoff, "--cutoff")?,
        target,
        seed: args.seed,
    };
    let outcome = run_surface(&SurfaceRequest {
        params,
        out: args.out.clone(),
    })?;
    let (topo, stats) = (&outcome.topography, &outcome.stats);
    println!(
        "{}: {}×{} px of {}, h_rms = {:.4} nm, h'_rms = {:.5}, h''_rms = {:.5} 1/µm",
        args.out.display(),
        topo.nx(),
        topo.ny(),
        units::format_length(dx),
        stats.h_rms_m * 1e9,
        stats.h_prime_rms,
        stats.h_double_prime_rms_per_m * 1e-6
    );
    Ok(())
}
