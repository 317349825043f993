//! `contactscope psf`: the microscope PSF from a bead image or z stack.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use contactscope::optics::psf::FWHM_PER_SIGMA;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::images::ImageInput;
use contactscope_jobs::psf::files::run_to_folder;
use contactscope_jobs::psf::{PsfOutcome, PsfRequest};

use super::args::{default_out, OutputFolder, PixelSizeArg, SelectionArgs};
use super::common::command_line;

default_out!(Out, "contactscope-out/psf");

#[derive(clap::Args)]
pub struct Args {
    /// Bead image or z stack: TIFF (every page of the chosen channel), or CZI, ND2, LIF, OME-Zarr (every
    /// z plane of the selected series, channel and time point, or the one plane of --z).
    input: PathBuf,
    #[command(flatten)]
    pixel_size: PixelSizeArg,
    /// Bead diameter, e.g. 100nm: turns on the finite-bead correction σ² − a²/5.
    #[arg(long)]
    bead_diameter: Option<String>,
    /// The detector's saturation level in the data's units (beads with two or more window
    /// pixels at it are skipped); default: from the sample type (8-bit 255, 16-bit 65535, or
    /// 4095 for 12-bit data in 16 bits, int16 32767; float data: no check).
    #[arg(long)]
    saturation_level: Option<f64>,
    #[command(flatten)]
    select: SelectionArgs,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let request = PsfRequest {
        selection: args.select.selection(),
        pixel_size_m: args.pixel_size.metres()?,
        bead_diameter_m: args
            .bead_diameter
            .as_deref()
            .map(|t| units::parse_positive(t, Dimension::Length).context("--bead-diameter"))
            .transpose()?,
        saturation_level: args.saturation_level,
        ..PsfRequest::new(ImageInput::File(args.input.clone()))
    };
    let (outcome, written) = run_to_folder(&request, &args.out.out, &command_line())?;
    print_outcome(&args.input, &outcome, &written);
    Ok(())
}

fn print_outcome(input: &Path, outcome: &PsfOutcome, written: &[PathBuf]) {
    let r = &outcome.report;
    let s = &r.summary;
    println!(
        "{}: {} plane(s), pixel {:.2} nm ({}), {} bead candidate(s), {} used",
        input.display(),
        r.planes,
        r.pixel_size.x_m * 1e9,
        r.pixel_size.source.describe(),
        r.beads.len(),
        s.beads_used
    );
    for (i, b) in r.beads.iter().enumerate() {
        if let Some(why) = &b.skip {
            println!(
                "  bead {i} at ({}, {}) plane {}: skipped, {why}",
                b.candidate.x, b.candidate.y, b.candidate.plane
            );
        }
    }
    let sd = |v: Option<f64>| v.map_or("n/a (one bead)".to_string(), |v| format!("{v:.1}"));
    let fwhm = s.sigma_m.scaled(1e9 * FWHM_PER_SIGMA);
    let sigma = s.sigma_m.scaled(1e9);
    let corrected = if r.bead_diameter_m.is_some() {
        " (bead-corrected)"
    } else {
        ""
    };
    println!(
        "FWHM = {:.1} ± {} nm, σ = {:.1} ± {} nm{corrected}",
        fwhm.mean,
        sd(fwhm.sd),
        sigma.mean,
        sd(sigma.sd)
    );
    for path in written {
        println!("wrote {}", path.display());
    }
}
