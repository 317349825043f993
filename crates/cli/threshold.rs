//! `contactscope threshold`: the global Otsu threshold of all pages of all inputs.

use std::path::PathBuf;

use anyhow::Result;

use contactscope_jobs::series::{Micrographs, SeriesSpec};
use contactscope_jobs::threshold::ThresholdRequest;

use super::args::{LoadAxisArg, SelectionArgs};

#[derive(clap::Args)]
pub struct Args {
    /// TIFF, CZI, ND2, LIF or OME-Zarr files, or directories of them.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    select: SelectionArgs,
    /// Axis of a CZI, ND2, LIF or OME-Zarr file whose planes are the loads, in order.
    #[arg(long, value_enum)]
    load_axis: Option<LoadAxisArg>,
    /// Print a JSON object.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let outcome = contactscope_jobs::threshold::run(&ThresholdRequest {
        micrographs: Micrographs::Files(SeriesSpec {
            inputs: args.inputs,
            selection: args.select.selection(),
            load_axis: args.load_axis.map(LoadAxisArg::axis),
            ..SeriesSpec::default()
        }),
    })?;
    super::common::print_warnings(&outcome.warnings);
    if args.json {
        // The warnings went to stderr.
        let mut value = serde_json::to_value(&outcome)?;
        if let Some(fields) = value.as_object_mut() {
            fields.shift_remove("warnings");
        }
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{} (global Otsu over {} pixels in {} images; contact is value > threshold)",
            outcome.threshold, outcome.pixels, outcome.images
        );
    }
    Ok(())
}
