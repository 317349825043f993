//! `contactscope topography`: a height map's size, pixel size and statistics, as stored and after
//! detrending.

use std::path::PathBuf;

use anyhow::Result;

use contactscope_formats::units;
use contactscope_jobs::topography::{run_topography, TopographyRequest};

use super::args::HeightMapOptions;

#[derive(clap::Args)]
pub struct Args {
    /// Height map file (any format of `docs/formats.md`; vendor formats are recognised by
    /// content).
    file: PathBuf,
    #[command(flatten)]
    options: HeightMapOptions,
    /// Channel of a multi-channel vendor file, by name (e.g. HeightRetrace); default: the
    /// file's height channel.
    #[arg(long)]
    channel: Option<String>,
    /// Print JSON: the stored map's summary (issue 14: file, format, channel, nx, ny,
    /// pixel_size_um, valid_points, height_*_um, h_rms_um, slope_rms, curvature_rms) and,
    /// under "detrended", the statistics after --detrend.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let source = args.options.source(args.file.clone())?;
    let detrend = source.detrend.name();
    let outcome = run_topography(&TopographyRequest {
        source,
        channel: args.channel.clone(),
    })?;
    let summary = &outcome.summary;
    if args.json {
        let mut value = serde_json::to_value(summary)?;
        value["detrended"] = match &outcome.detrended {
            Some((topo, stats)) => serde_json::json!({
                "detrend": detrend,
                "pixel_size_x_nm": topo.dx_m * 1e9, "pixel_size_y_nm": topo.dy_m * 1e9,
                "h_rms_nm": stats.h_rms_m * 1e9,
                "h_prime_rms": stats.h_prime_rms,
                "h_double_prime_rms_per_um": stats.h_double_prime_rms_per_m * 1e-6,
            }),
            None => serde_json::Value::Null,
        };
        if let Some(note) = &outcome.note {
            value["note"] = note.clone().into();
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!("file:        {}", args.file.display());
    println!(
        "format:      {} (channel {})",
        summary.format, summary.channel
    );
    println!(
        "size:        {} × {} px = {:.4} × {:.4} µm",
        summary.nx,
        summary.ny,
        summary.nx as f64 * summary.pixel_size_um.x,
        summary.ny as f64 * summary.pixel_size_um.y
    );
    println!(
        "pixel size:  {} × {}",
        units::format_length(summary.pixel_size_um.x * 1e-6),
        units::format_length(summary.pixel_size_um.y * 1e-6)
    );
    println!(
        "valid:       {} of {} points",
        summary.valid_points,
        summary.nx * summary.ny
    );
    println!(
        "heights:     {:.5} … {:.5} µm as stored (mean {:.5} µm)",
        summary.height_min_um, summary.height_max_um, summary.height_mean_um
    );
    let Some((_, stats)) = &outcome.detrended else {
        println!(
            "note:        {}",
            outcome.note.as_deref().unwrap_or("no statistics")
        );
        return Ok(());
    };
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
