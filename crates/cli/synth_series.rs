//! `contactscope synth-series`: a seeded synthetic load series with known ground truth.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::ValueEnum;

use super::args::{load_forces, Forces};
use contactscope::synth::SynthParams;
use contactscope_formats::tiff::Compression;
use contactscope_formats::units;
use contactscope_jobs::synth_series::{run_to_folder, Layout, SynthSeriesRequest};

#[derive(Clone, Copy, ValueEnum)]
enum LayoutArg {
    /// One multi-page TIFF.
    Multipage,
    /// One file per load.
    Files,
}

#[derive(Clone, Copy, ValueEnum)]
enum CompressionArg {
    /// Uncompressed.
    None,
    /// LZW.
    Lzw,
    /// Deflate.
    Deflate,
}

#[derive(clap::Args)]
pub struct Args {
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Image size in pixels (square).
    #[arg(long, default_value_t = 256)]
    size: usize,
    /// Normal forces, one per image: 4,10,40mN or 4mN..100mN:8 (log-spaced).
    #[arg(long, alias = "loads", value_parser = load_forces, default_value = "4,6,10,16,25,40,63,100mN")]
    forces: Forces,
    /// Random seed.
    #[arg(long, default_value_t = 2018)]
    seed: u64,
    /// Pixel size.
    #[arg(long, default_value = "200nm")]
    pixel_size: String,
    /// multipage or files.
    #[arg(long, value_enum, default_value = "multipage")]
    layout: LayoutArg,
    /// TIFF compression.
    #[arg(long, value_enum, default_value = "none")]
    compression: CompressionArg,
}

pub fn run(args: Args) -> Result<()> {
    let (pixel, _) = units::parse_pixel_size(&args.pixel_size).context("--pixel-size")?;
    let defaults = SynthSeriesRequest::default();
    let request = SynthSeriesRequest {
        params: SynthParams {
            width: args.size,
            height: args.size,
            pixel_size_m: pixel,
            forces_n: args.forces.0.clone(),
            seed: args.seed,
            ..defaults.params
        },
    };
    let layout = match args.layout {
        LayoutArg::Multipage => Layout::MultiPage,
        LayoutArg::Files => Layout::Files,
    };
    let compression = match args.compression {
        CompressionArg::None => Compression::None,
        CompressionArg::Lzw => Compression::Lzw,
        CompressionArg::Deflate => Compression::Deflate,
    };
    let (_, written) = run_to_folder(&request, &args.out, layout, compression)?;
    for path in written {
        println!("{}", path.display());
    }
    Ok(())
}
