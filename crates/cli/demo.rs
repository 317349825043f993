//! `contactscope demo`: the whole method on a generated experiment with known truth.

use std::path::PathBuf;

use anyhow::Result;

use contactscope_jobs::demo::{run_demo, DemoParams};

use super::args::{DeviceArg, Quiet};

#[derive(clap::Args)]
pub struct Args {
    /// Report folder (an earlier demo report there is replaced).
    #[arg(long, default_value = "contactscope-out/demo")]
    out: PathBuf,
    /// The reduced demo of the test suite (smaller maps, fewer loads).
    #[arg(long)]
    small: bool,
    /// Where the contact solver runs: `cpu`, `cuda` (an NVIDIA GPU; needs a build with
    /// `--features cuda`) or `auto` (a GPU when one is usable).
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    device: DeviceArg,
    #[command(flatten)]
    quiet: Quiet,
}

pub fn run(args: Args) -> Result<()> {
    let mut params = if args.small {
        DemoParams::reduced()
    } else {
        DemoParams::standard()
    };
    params.device = args.device.into();
    let start = std::time::Instant::now();
    let quiet = args.quiet.quiet;
    let progress = |stage: &str| {
        if !quiet {
            eprintln!("[{:>5.1} s] {stage}", start.elapsed().as_secs_f64());
        }
    };
    let outcome = run_demo(&args.out, &params, &progress)?;
    println!(
        "{:<32} {:>12} {:>22} {:>8}  by",
        "quantity", "truth", "recovered", "error"
    );
    for r in &outcome.recovered {
        let recovered = contactscope_jobs::table::value_pm_or(r.recovered, r.uncertainty, 3);
        let interval = r.interval.map_or(String::new(), |(lo, hi)| {
            format!(" (95 % interval {lo:.3}…{hi:.3})")
        });
        println!(
            "{:<32} {:>12} {:>22} {:>7.1}%  {}{interval}",
            r.quantity,
            format!("{:.3} {}", r.truth, r.unit),
            recovered,
            100.0 * r.relative_error(),
            r.by
        );
    }
    for (model, dice) in &outcome.dice {
        println!("mean Dice against the micrographs, {model}: {dice:.3}");
    }
    println!(
        "report: {} ({:.1} s)",
        outcome.index.display(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
