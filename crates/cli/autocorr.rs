//! `contactscope autocorr`: radially averaged intensity autocorrelation of images.

use std::path::PathBuf;

use anyhow::Result;

use contactscope_jobs::autocorr::{run_autocorr, AutocorrRequest};

use super::args::{default_out, optional_length, OutputFolder, PixelSizeArg, SelectionArgs};
use super::common::{command_line, print_warnings, print_written};

default_out!(Out, "contactscope-out/autocorr");

#[derive(clap::Args)]
pub struct Args {
    /// TIFF images (every page of a multi-page file counts as one image), or CZI, ND2, LIF
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
        inputs: args.inputs.clone(),
        selection: args.select.selection(),
        pixel_size_m: args.pixel_size.metres()?,
        max_lag_m: optional_length(&args.max_lag, "--max-lag")?,
        out_dir: args.out.out.clone(),
        command_line: command_line(),
    };
    let outcome = run_autocorr(&request)?;
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
    print_written(outcome.written.len(), &args.out.out);
    Ok(())
}
