//! `contactscope psf`: the microscope PSF from a bead image or z stack.

use std::path::PathBuf;

use anyhow::Result;

use contactscope::optics::psf::FWHM_PER_SIGMA;
use contactscope_jobs::psf::{run_psf, PsfRequest};

use super::args::{default_out, optional_length, OutputFolder, PixelSizeArg, SelectionArgs};
use super::common::command_line;

default_out!(Out, "contactscope-out/psf");

#[derive(clap::Args)]
pub struct Args {
    /// Bead image or z stack: TIFF (every page of the chosen channel), or CZI, ND2, LIF (every
    /// z plane of the selected series, channel and time point, or the one plane of --z).
    input: PathBuf,
    #[command(flatten)]
    pixel_size: PixelSizeArg,
    /// Bead diameter, e.g. 100nm: turns on the finite-bead correction σ² − a²/5.
    #[arg(long)]
    bead_diameter: Option<String>,
    #[command(flatten)]
    select: SelectionArgs,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let request = PsfRequest {
        input: args.input.clone(),
        selection: args.select.selection(),
        pixel_size_m: args.pixel_size.metres()?,
        bead_diameter_m: optional_length(&args.bead_diameter, "--bead-diameter")?,
        out_dir: args.out.out.clone(),
        command_line: command_line(),
    };
    let outcome = run_psf(&request)?;
    let r = &outcome.report;
    let s = &r.summary;
    println!(
        "{}: {} plane(s), pixel {:.2} nm ({}), {} bead candidate(s), {} used",
        args.input.display(),
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
    for path in &outcome.written {
        println!("wrote {}", path.display());
    }
    Ok(())
}
