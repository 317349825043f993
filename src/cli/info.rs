//! `contactscope info`: describe a TIFF file.

use std::path::PathBuf;

use anyhow::Result;

use contactscope::io::units;
use contactscope::jobs::info::{run_info, InfoRequest};

#[derive(clap::Args)]
pub struct Args {
    /// A TIFF file.
    file: PathBuf,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let i = run_info(&InfoRequest { file: args.file })?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&i)?);
        return Ok(());
    }
    println!("file:         {}", i.path.display());
    println!("pages:        {}", i.pages.len());
    println!(
        "shape:        {} × {} px (width × height)",
        i.width, i.height
    );
    println!(
        "sample type:  {} ({} bits)",
        i.sample_type.name(),
        i.bits_per_sample
    );
    println!(
        "channels:     {} ({})",
        i.channels,
        i.channel_layout.describe()
    );
    println!(
        "compression:  {} (predictor: {}), {}{}, {}-endian",
        i.compression,
        i.predictor,
        if i.tiled { "tiled" } else { "strips" },
        if i.bigtiff { ", BigTIFF" } else { "" },
        i.byte_order
    );
    println!("description:  {}", i.description_kind);
    match i.pixel_size {
        Some(p) => println!(
            "pixel size:   {} × {} from {}",
            units::format_length(p.x_m),
            units::format_length(p.y_m),
            p.source.describe()
        ),
        None => println!("pixel size:   none in the metadata (use --pixel-size)"),
    }
    for note in &i.notes {
        println!("note:         {note}");
    }
    Ok(())
}
