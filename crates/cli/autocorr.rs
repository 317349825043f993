//! `contactscope autocorr`: radially averaged intensity autocorrelation of images.

use std::path::PathBuf;

use anyhow::{Context, Result};

use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::autocorr::files::run_to_folder;
use contactscope_jobs::autocorr::AutocorrRequest;
use contactscope_jobs::images::ImageInput;

use super::args::{default_out, OutputFolder, PixelSizeArg, SelectionArgs};
use super::common::{command_line, print_warnings, print_written};

default_out!(Out, "contactscope-out/autocorr");

#[derive(clap::Args)]
pub struct Args {
    /// TIFF images (every page of a multi-page file counts as one image), or CZI, ND2, LIF, OME-Zarr
    /// files (the one plane the selection flags name).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    pixel_size: PixelSizeArg,
    /// Largest lag (e.g. 20um); default half the smaller image side.
    #[arg(long)]
    max_lag: Option<String>,
    #[command(flatten)]
    select: SelectionArgs,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let request = AutocorrRequest {
        selection: args.select.selection(),
        pixel_size_m: args.pixel_size.metres()?,
        max_lag_m: args
            .max_lag
            .as_deref()
            .map(|t| units::parse_positive(t, Dimension::Length).context("--max-lag"))
            .transpose()?,
        ..AutocorrRequest::new(args.inputs.into_iter().map(ImageInput::File).collect())
    };
    let (outcome, written) = run_to_folder(&request, &args.out.out, &command_line())?;
    print_warnings(&outcome.warnings);
    let um = |m: Option<f64>| m.map_or("—".to_string(), |v| format!("{:.3}", v * 1e6));
    println!("{:>12} {:>14}  image", "ξ_1/e (µm)", "first zero (µm)");
    for c in &outcome.curves {
        println!(
            "{:>12} {:>14}  {}",
            um(c.xi_1e_m),
            um(c.first_zero_m),
            c.label
        );
    }
    print_written(written.len(), &args.out.out);
    Ok(())
}
