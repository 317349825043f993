//! `contactscope surface`: a self-affine random surface (Fourier filtering, seeded).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use contactscope::surface::generate::RmsTarget;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::surface::files::run_to_file;
use contactscope_jobs::surface::SurfaceRequest;

#[derive(clap::Args)]
pub struct Args {
    /// Grid size in pixels (square).
    #[arg(long, default_value_t = SurfaceRequest::SIZE)]
    size: usize,
    /// Pixel size, e.g. 32nm.
    #[arg(long)]
    pixel_size: String,
    /// Hurst exponent H in (0, 1].
    #[arg(long, default_value_t = SurfaceRequest::HURST)]
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
    #[arg(long, default_value_t = SurfaceRequest::SEED)]
    seed: u64,
    /// Output file: .npy, .gsf (heights in metres) or .zip (a contact.engineering surface
    /// container, readable by SurfaceTopography).
    #[arg(long)]
    out: PathBuf,
}

/// An optional length (`8um`) in metres.
fn length(text: &Option<String>, flag: &str) -> Result<Option<f64>> {
    text.as_deref()
        .map(|t| units::parse_positive(t, Dimension::Length).with_context(|| flag.to_string()))
        .transpose()
}

pub fn run(args: Args) -> Result<()> {
    let (dx, _) = units::parse_pixel_size(&args.pixel_size).context("--pixel-size")?;
    let target = match (&args.rms_slope, &args.rms_height) {
        (Some(slope), None) => RmsTarget::Slope(*slope),
        (None, Some(h)) => {
            RmsTarget::Height(units::parse_positive(h, Dimension::Length).context("--rms-height")?)
        }
        _ => bail!("give --rms-slope or --rms-height"),
    };
    let request = SurfaceRequest {
        nx: args.size,
        ny: args.size,
        hurst: args.hurst,
        rolloff_m: length(&args.rolloff, "--rolloff")?,
        cutoff_m: length(&args.cutoff, "--cutoff")?,
        seed: args.seed,
        ..SurfaceRequest::new(dx, target)
    };
    let outcome = run_to_file(&request, &args.out)?;
    println!(
        "{}: {}×{} px of {}, h_rms = {:.4} nm, h'_rms = {:.5}, h''_rms = {:.5} 1/µm",
        args.out.display(),
        outcome.nx,
        outcome.ny,
        units::format_length(outcome.pixel_size_m),
        outcome.roughness.h_rms_m * 1e9,
        outcome.roughness.h_prime_rms,
        outcome.roughness.h_double_prime_rms_per_m * 1e-6
    );
    Ok(())
}
