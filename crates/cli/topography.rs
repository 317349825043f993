//! `contactscope topography`: a height map's size, pixel size and statistics, as stored and after
//! detrending.

use std::path::PathBuf;

use anyhow::Result;

use contactscope_formats::units;
use contactscope_jobs::topography::{self as job, TopographyRequest};

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
    /// The measurement of a contact.engineering surface container (ZIP or folder), by index
    /// (0, 1, …) or name (`name` or `surface/name`); without it every measurement is
    /// summarised, then all of them pooled.
    #[arg(long)]
    measurement: Option<String>,
    /// Print JSON: the stored map's summary (file, format, channel, channels, nx, ny,
    /// pixel_size_um,
    /// valid_points, height_*_um, h_rms_as_stored_um, h_prime_rms_as_stored,
    /// h_double_prime_rms_as_stored_per_um) and, under "detrended", the roughness after
    /// --detrend (h_rms_nm, h_prime_rms, h_double_prime_rms_per_um, as simulate names them).
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let mut source = args.options.source(args.file.clone())?;
    source.channel = args.channel.clone();
    source.measurement = args.measurement.clone();
    let detrend = source.detrend.name();
    if source.measurement.is_none() && source.is_container() {
        return whole_container(TopographyRequest { source }, args.json);
    }
    let outcome = job::run(&TopographyRequest { source })?;
    // A pixel size that replaced the file's own, points filled: on stderr, as every command's.
    super::common::print_warnings(&outcome.notes);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&outcome.summary)?);
        return Ok(());
    }
    let summary = &outcome.summary.stored;
    println!("file:        {}", args.file.display());
    if let Some(m) = &args.measurement {
        println!("measurement: {m}");
    }
    println!(
        "format:      {} (channel {})",
        summary.format, summary.channel
    );
    if summary.channels.len() > 1 {
        let listed: Vec<String> = summary
            .channels
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{k} '{c}'"))
            .collect();
        println!(
            "channels:    {} (choose with --channel NAME or --channel N)",
            listed.join(", ")
        );
    }
    println!(
        "size:        {} × {} px = {:.4} × {:.4} µm",
        summary.nx,
        summary.ny,
        summary.nx as f64 * (summary.pixel_size.x_m * 1e6),
        summary.ny as f64 * (summary.pixel_size.y_m * 1e6)
    );
    println!(
        "pixel size:  {} × {}",
        units::format_length(summary.pixel_size.x_m * 1e6 * 1e-6),
        units::format_length(summary.pixel_size.y_m * 1e6 * 1e-6)
    );
    println!(
        "valid:       {} of {} points",
        summary.valid_points,
        summary.nx * summary.ny
    );
    println!(
        "heights:     {:.5} … {:.5} µm as stored (mean {:.5} µm)",
        summary.height_min_m * 1e6,
        summary.height_max_m * 1e6,
        summary.height_mean_m * 1e6
    );
    let Some(stats) = &outcome.summary.detrended else {
        println!(
            "note:        {}",
            outcome.summary.note.as_deref().unwrap_or("no statistics")
        );
        return Ok(());
    };
    println!("detrend:     {detrend}");
    println!("h_rms:       {:.5} nm", stats.roughness.h_rms_m * 1e9);
    println!(
        "h'_rms:      {:.6} (central differences)",
        stats.roughness.h_prime_rms
    );
    println!(
        "h''_rms:     {:.6} 1/µm (5-point Laplacian)",
        stats.roughness.h_double_prime_rms_per_m * 1e-6
    );
    Ok(())
}

/// Every measurement of a surface container, one line each, then the pooled statistics.
fn whole_container(request: TopographyRequest, json: bool) -> Result<()> {
    let (description, notes) = job::run_container(&request)?;
    super::common::print_warnings(&notes);
    if json {
        println!("{}", serde_json::to_string_pretty(&description)?);
        return Ok(());
    }
    println!("container:   {}", description.container);
    println!(
        "{:>5}  {:<32} {:>11} {:>14} {:>11} {:>9} {:>13}",
        "index", "surface/name", "grid", "pixel size", "h_rms_nm", "h'_rms", "h''_rms_per_um"
    );
    for m in &description.measurements {
        let s = &m.description.stored;
        let label = format!("{}/{}", m.surface, m.name);
        let grid = format!("{}×{}", s.nx, s.ny);
        let pixel = units::format_length(s.pixel_size.x_m);
        match &m.description.detrended {
            Some(d) => println!(
                "{:>5}  {:<32} {:>11} {:>14} {:>11.4} {:>9.5} {:>13.5}{}",
                m.index,
                label,
                grid,
                pixel,
                d.roughness.h_rms_m * 1e9,
                d.roughness.h_prime_rms,
                d.roughness.h_double_prime_rms_per_m * 1e-6,
                if m.periodic { "  periodic" } else { "" }
            ),
            None => println!(
                "{:>5}  {:<32} {:>11} {:>14}  {}",
                m.index,
                label,
                grid,
                pixel,
                m.description.note.as_deref().unwrap_or("no statistics")
            ),
        }
    }
    if let Some(c) = &description.combined {
        println!(
            "pooled ({} measurements, {} points, detrend {}): h_rms {:.4} nm, h'_rms {:.5}, \
             h''_rms {:.5} 1/µm",
            c.measurements,
            c.points,
            c.detrend,
            c.roughness.h_rms_m * 1e9,
            c.roughness.h_prime_rms,
            c.roughness.h_double_prime_rms_per_m * 1e-6
        );
    }
    Ok(())
}
