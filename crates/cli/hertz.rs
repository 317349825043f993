//! `contactscope hertz`: the contact modulus E* from a squeeze test.

use std::path::PathBuf;

use anyhow::{Context, Result};

use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::hertz::files::run_to_folder;
use contactscope_jobs::hertz::HertzRequest;
use contactscope_jobs::table::value_pm;

use super::args::{default_out, load_forces, Forces, OutputFolder};
use super::common::{command_line, print_warnings, print_written};

default_out!(Out, "contactscope-out/hertz");

#[derive(clap::Args)]
pub struct Args {
    /// Squeeze CSV: force_mN | force_N and displacement_um (total plate displacement 2δ).
    input: PathBuf,
    /// Sphere radius (e.g. 290um).
    #[arg(long)]
    radius: String,
    /// Normal forces at which to predict the Hertz contact radius: 4,40mN or 4mN..400mN:12
    /// (default: the measured forces).
    #[arg(long, alias = "loads", value_parser = load_forces)]
    forces: Option<Forces>,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let radius_m = units::parse_positive(&args.radius, Dimension::Length).context("--radius")?;
    let request = HertzRequest {
        loads_n: args.forces.as_ref().map(|f| f.0.clone()),
        ..HertzRequest::new(args.input.clone(), radius_m)
    };
    let (outcome, written) = run_to_folder(&request, &args.out.out, &command_line())?;
    let fit = &outcome.fit;
    println!(
        "E* = {} GPa (R² {:.5}, {} points, fit through the origin)",
        value_pm(fit.e_star_pa * 1e-9, fit.e_star_se_pa * 1e-9),
        fit.r_squared,
        outcome.points.len()
    );
    if let Some(free) = &outcome.offset_fit {
        println!(
            "with a free contact point: E* = {} GPa, offset {:.4} µm of plate displacement",
            value_pm(free.e_star_pa * 1e-9, free.e_star_se_pa * 1e-9),
            2.0 * free.offset_m * 1e6
        );
    }
    println!("{:>10} {:>12}", "load_mN", "a_Hertz_µm");
    for p in &outcome.predicted {
        println!(
            "{:>10.3} {:>12.4}",
            p.force_n * 1e3,
            p.contact_radius_m * 1e6
        );
    }
    print_warnings(&outcome.warnings);
    print_written(written.len(), &args.out.out);
    Ok(())
}
