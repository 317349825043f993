//! `contactscope threshold`: the global Otsu threshold of all pages of all inputs.

use std::path::PathBuf;

use anyhow::Result;

use contactscope::jobs::threshold::{run_threshold, ThresholdRequest};

#[derive(clap::Args)]
pub struct Args {
    /// TIFF files or directories.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Channel of multi-channel files.
    #[arg(long)]
    channel: Option<usize>,
    /// Print a JSON object.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args) -> Result<()> {
    let outcome = run_threshold(&ThresholdRequest {
        inputs: args.inputs,
        channel: args.channel,
    })?;
    super::print_warnings(&outcome.warnings);
    if args.json {
        let value = serde_json::json!({
            "threshold": outcome.threshold.value,
            "method": "otsu-global",
            "contact_rule": "value > threshold",
            "pixels": outcome.pixels,
            "images": outcome.images,
            "files": outcome.files,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{} (global Otsu over {} pixels in {} images; contact is value > threshold)",
            outcome.threshold.value, outcome.pixels, outcome.images
        );
    }
    Ok(())
}
