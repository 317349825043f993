//! `contactscope topography`: a height map's size, pixel size and roughness statistics.

use std::path::PathBuf;

use anyhow::Result;

use contactscope::io::units;
use contactscope::jobs::topography::{run_topography, TopographyRequest};

use super::args::HeightMapOptions;

#[derive(clap::Args)]
pub struct Args {
    /// Height map file.
    file: PathBuf,
    #[command(flatten)]
    options: HeightMapOptions,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let source = args.options.source(args.file.clone())?;
    let detrend = source.detrend.name();
    let outcome = run_topography(&TopographyRequest { source })?;
    let (topo, stats) = (&outcome.topography, &outcome.stats);
    let (w, h) = topo.size_m();
    if args.json {
        let value = serde_json::json!({
            "file": args.file.display().to_string(),
            "nx": topo.nx(), "ny": topo.ny(),
            "pixel_size_x_nm": topo.dx_m * 1e9, "pixel_size_y_nm": topo.dy_m * 1e9,
            "width_um": w * 1e6, "height_um": h * 1e6,
            "detrend": detrend,
            "h_rms_nm": stats.h_rms_m * 1e9,
            "h_prime_rms": stats.h_prime_rms,
            "h_double_prime_rms_per_um": stats.h_double_prime_rms_per_m * 1e-6,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!("file:        {}", args.file.display());
    println!(
        "size:        {} × {} px = {:.4} × {:.4} µm",
        topo.nx(),
        topo.ny(),
        w * 1e6,
        h * 1e6
    );
    println!(
        "pixel size:  {} × {}",
        units::format_length(topo.dx_m),
        units::format_length(topo.dy_m)
    );
    println!("detrend:     {detrend}");
    println!("h_rms:       {:.5} nm", stats.h_rms_m * 1e9);
    println!(
        "h'_rms:      {:.6} (central differences)",
        stats.h_prime_rms
    );
    println!(
        "h''_rms:     {:.6} 1/µm (5-point Laplacian)",
        stats.h_double_prime_rms_per_m * 1e-6
    );
    Ok(())
}
