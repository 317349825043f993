//! `contactscope compare`: simulated contact maps against micrographs, load by load.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::compare::files::run_to_folder;
use contactscope_jobs::compare::{CompareRequest, Simulation};
use contactscope_jobs::results::fwhm_from_psf_json;
use contactscope_jobs::series::{Micrographs, SeriesSpec};

use super::args::{
    default_out, fraction, frame_forces, Forces, LoadAxisArg, OutputFolder, PixelSizeArg,
    SelectionArgs,
};
use super::common::{command_line, print_warnings, print_written};

default_out!(Out, "contactscope-out/compare");

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("psf_source").required(true).args(["psf", "psf_fwhm"])))]
pub struct Args {
    /// The micrographs: a manifest CSV (file, page, force_mN), a folder holding manifest.csv,
    /// or TIFF/CZI/ND2/LIF/OME-Zarr files or folders together with --forces.
    #[arg(long, alias = "experiment", required = true, num_args = 1..)]
    micrographs: Vec<PathBuf>,
    /// Normal force per micrograph when --micrographs names image files (e.g. 0,4,8mN or
    /// 4mN..40mN:8; 0 is a reference frame, left out).
    #[arg(long, value_parser = frame_forces)]
    forces: Option<Forces>,
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
    /// Axis of a CZI, ND2, LIF or OME-Zarr micrograph file whose planes are the loads, in order.
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
    let single = (args.micrographs.len() == 1).then(|| &args.micrographs[0]);
    let is_manifest = single.is_some_and(|p| contactscope_jobs::series::is_manifest(p));
    let selection = args.select.selection();
    let load_axis = args.load_axis.map(LoadAxisArg::axis);
    let spec = match (&args.forces, is_manifest) {
        (None, true) => SeriesSpec {
            manifest: Some(args.micrographs[0].clone()),
            selection,
            load_axis,
            ..SeriesSpec::default()
        },
        (Some(_), true) => bail!("--forces goes with TIFF inputs, not with a manifest"),
        (Some(forces), false) => SeriesSpec {
            inputs: args.micrographs.clone(),
            selection,
            load_axis,
            forces_n: Some(forces.0.clone()),
            ..SeriesSpec::default()
        },
        (None, false) => {
            bail!("--micrographs: give a manifest (or a folder with manifest.csv), or TIFFs with --forces")
        }
    };
    let psf_fwhm_m = match (&args.psf, &args.psf_fwhm) {
        (Some(path), _) => fwhm_from_psf_json(path)?,
        (None, Some(text)) => {
            units::parse_positive(text, Dimension::Length).context("--psf-fwhm")?
        }
        (None, None) => bail!("give --psf psf.json or --psf-fwhm"),
    };
    let request = CompareRequest {
        pixel_size_m: args.pixel_size.metres()?,
        dihedral: args.dihedral,
        upsample: args.upsample,
        force_tolerance: fraction(&args.force_tolerance, "--force-tolerance")?,
        ..CompareRequest::new(
            Micrographs::Files(spec),
            Simulation::Folder(args.simulation.clone()),
            psf_fwhm_m,
        )
    };
    let (outcome, written) = run_to_folder(&request, &args.out.out, &command_line())?;
    print_warnings(&outcome.warnings);
    println!(
        "thresholds: experiment {:.1}, simulation {:.4} (blurred contact fraction)",
        outcome.experiment_threshold, outcome.simulated_threshold
    );
    let r = &outcome.series_registration;
    println!(
        "series registration: {}, shift ({:.2}, {:.2}) px, mean correlation peak {:.3}; each load refined within ±{} px",
        r.transform.name(),
        r.shift_px.0,
        r.shift_px.1,
        r.correlation_peak,
        r.window_px
    );
    println!(
        "{:>10} {:>16} {:>12} {:>12} {:>7} {:>7} {:>6}  refinement",
        "force_mN", "shift_px", "A_exp_µm²", "A_sim_µm²", "Dice", "Jaccard", "peak"
    );
    for l in &outcome.loads {
        println!(
            "{:>10.3} {:>16} {:>12.2} {:>12.2} {:>7.3} {:>7.3} {:>6.3}  {}",
            l.force_n * 1e3,
            format!("({:.2}, {:.2})", l.shift_px.0, l.shift_px.1),
            l.experiment_area_m2 * 1e12,
            l.simulated_area_m2 * 1e12,
            l.dice,
            l.jaccard,
            l.correlation_peak,
            l.refinement.name()
        );
    }
    print_written(written.len(), &args.out.out);
    Ok(())
}
