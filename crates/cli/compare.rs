//! `contactscope compare`: simulated contact maps against micrographs, load by load.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use contactscope::compare::CompareSettings;
use contactscope::spectral::register::MAX_UPSAMPLE;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::compare::{run_compare, CompareRequest, ExperimentInput};
use contactscope_jobs::results::fwhm_from_psf_json;

use super::args::{default_out, fraction, LoadAxisArg, OutputFolder, PixelSizeArg, SelectionArgs};
use super::common::{command_line, print_warnings, print_written};

default_out!(Out, "contactscope-out/compare");

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("psf_source").required(true).args(["psf", "psf_fwhm"])))]
pub struct Args {
    /// The micrographs: a manifest CSV (file, page, force_mN), a folder holding manifest.csv,
    /// or TIFF/CZI/ND2/LIF files or folders together with --forces.
    #[arg(long, required = true, num_args = 1..)]
    experiment: Vec<PathBuf>,
    /// Normal force per micrograph when --experiment names image files (e.g. 4mN,8mN or 4mN..40mN:8).
    #[arg(long)]
    forces: Option<String>,
    /// Output folder of `contactscope simulate`.
    #[arg(long)]
    simulation: PathBuf,
    /// psf.json written by `contactscope psf` (uses fwhm_nm_mean).
    #[arg(long)]
    psf: Option<PathBuf>,
    /// PSF full width at half maximum (e.g. 450nm).
    #[arg(long)]
    psf_fwhm: Option<String>,
    #[command(flatten)]
    pixel_size: PixelSizeArg,
    #[command(flatten)]
    select: SelectionArgs,
    /// Axis of a CZI, ND2 or LIF micrograph file whose planes are the loads, in order.
    #[arg(long, value_enum)]
    load_axis: Option<LoadAxisArg>,
    /// Also try mirror images and 90° rotations when registering.
    #[arg(long)]
    dihedral: bool,
    /// Sub-pixel registration resolution: 1/N pixel (N from 1 to 100).
    #[arg(long, default_value_t = 20)]
    upsample: usize,
    /// Largest relative force difference for loads to match (e.g. 1% or 0.01).
    #[arg(long, default_value = "1%")]
    force_tolerance: String,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let single = (args.experiment.len() == 1).then(|| &args.experiment[0]);
    let is_manifest = single.is_some_and(|p| {
        p.is_dir() && p.join("manifest.csv").is_file()
            || p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv"))
    });
    let experiment = match (&args.forces, is_manifest) {
        (None, true) => ExperimentInput::Manifest(args.experiment[0].clone()),
        (Some(_), true) => bail!("--forces goes with TIFF inputs, not with a manifest"),
        (Some(forces), false) => ExperimentInput::Files {
            inputs: args.experiment.clone(),
            forces_n: units::parse_loads(forces).context("--forces")?,
        },
        (None, false) => {
            bail!("--experiment: give a manifest (or a folder with manifest.csv), or TIFFs with --forces")
        }
    };
    let psf_fwhm_m = match (&args.psf, &args.psf_fwhm) {
        (Some(path), _) => fwhm_from_psf_json(path)?,
        (None, Some(text)) => contactscope_formats::ranges::Quantity::Fwhm.check_text(
            units::parse_positive(text, Dimension::Length).context("--psf-fwhm")?,
            "--psf-fwhm",
        )?,
        (None, None) => bail!("give --psf psf.json or --psf-fwhm"),
    };
    if !(1..=MAX_UPSAMPLE).contains(&args.upsample) {
        bail!(
            "--upsample {}: give 1 to {MAX_UPSAMPLE} (a sub-pixel resolution of 1/N pixel)",
            args.upsample
        );
    }
    let request = CompareRequest {
        experiment,
        selection: args.select.selection(),
        load_axis: args.load_axis.map(LoadAxisArg::axis),
        pixel_size_m: args.pixel_size.metres()?,
        simulation: args.simulation.clone(),
        settings: CompareSettings {
            psf_fwhm_m,
            dihedral: args.dihedral,
            upsample: args.upsample,
            force_tolerance: fraction(&args.force_tolerance, "--force-tolerance")?,
        },
        out_dir: args.out.out.clone(),
        command_line: command_line(),
    };
    let outcome = run_compare(&request)?;
    print_warnings(&outcome.warnings);
    println!(
        "thresholds: experiment {:.1}, simulation {:.4} (blurred contact fraction)",
        outcome.thresholds.0, outcome.thresholds.1
    );
    println!(
        "{:>10} {:>10} {:>12} {:>12} {:>7} {:>7} {:>6}",
        "force_mN", "transform", "A_exp_µm²", "A_sim_µm²", "Dice", "Jaccard", "peak"
    );
    for l in &outcome.loads {
        println!(
            "{:>10.3} {:>10} {:>12.2} {:>12.2} {:>7.3} {:>7.3} {:>6.3}",
            l.force_n * 1e3,
            l.transform.name(),
            l.experiment_area_m2 * 1e12,
            l.simulated_area_m2 * 1e12,
            l.dice,
            l.jaccard,
            l.correlation_peak
        );
    }
    print_written(outcome.written.len(), &args.out.out);
    Ok(())
}
