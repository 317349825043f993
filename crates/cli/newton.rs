//! `contactscope newton`: the detection gap from Newton rings and the fluorescent contact.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::ValueEnum;

use contactscope::optics::newton::{NewtonOptions, Phase};
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::images::ImageInput;
use contactscope_jobs::newton::files::run_to_folder;
use contactscope_jobs::newton::{NewtonOutcome, NewtonRequest};

use super::args::{default_out, OutputFolder, PixelSizeArg, SelectionArgs};
use super::common::command_line;

default_out!(Out, "contactscope-out/newton");

#[derive(Clone, Copy, ValueEnum)]
enum PhaseArg {
    /// Maxima at (m + ½)λ/(2n), dark contact (paper Eq. 1; n_sphere > n_medium).
    Half,
    /// Maxima at mλ/(2n), bright contact (n_sphere < n_medium, e.g. PTFE).
    Zero,
}

#[derive(clap::Args)]
pub struct Args {
    /// Reflection image with Newton rings (single-page TIFF, or one plane of a CZI, ND2, LIF, OME-Zarr).
    reflection: PathBuf,
    /// Fluorescence image of the contact, same field and size.
    #[arg(long = "contact")]
    contact: PathBuf,
    #[command(flatten)]
    pixel_size: PixelSizeArg,
    #[command(flatten)]
    select: SelectionArgs,
    /// Channel of the contact image when it differs from --channel (e.g. reflection and
    /// fluorescence as two channels of one CZI, ND2, LIF or OME-Zarr file).
    #[arg(long)]
    contact_channel: Option<usize>,
    /// Illumination wavelength.
    #[arg(long, default_value = "488nm")]
    wavelength: String,
    /// Refractive index of the medium in the gap (formamide 1.447).
    #[arg(long, default_value_t = NewtonOptions::default().medium_index)]
    medium_index: f64,
    /// Number of line profiles through the centre, evenly spread over 180°.
    #[arg(long, default_value_t = NewtonOptions::default().profiles)]
    profiles: usize,
    /// Phase of the reflection maxima.
    #[arg(long, value_enum, default_value = "half")]
    phase: PhaseArg,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let request = NewtonRequest {
        pixel_size_m: args.pixel_size.metres()?,
        selection: args.select.selection(),
        contact_channel: args.contact_channel,
        options: NewtonOptions {
            wavelength_m: units::parse_positive(&args.wavelength, Dimension::Length)
                .context("--wavelength")?,
            medium_index: args.medium_index,
            profiles: args.profiles,
            phase: match args.phase {
                PhaseArg::Half => Phase::Half,
                PhaseArg::Zero => Phase::Zero,
            },
            ..NewtonOptions::default()
        },
        ..NewtonRequest::new(
            ImageInput::File(args.reflection),
            ImageInput::File(args.contact),
        )
    };
    let (outcome, written) = run_to_folder(&request, &args.out.out, &command_line())?;
    print_outcome(&outcome, &written);
    Ok(())
}

fn print_outcome(outcome: &NewtonOutcome, written: &[PathBuf]) {
    let a = &outcome.analysis;
    let sd = |s: Option<f64>, scale: f64| s.map_or("n/a".into(), |v| format!("{:.2}", v * scale));
    println!(
        "detection gap: {:.2} ± {} nm over {} of {} profiles",
        a.detection_gap_m.mean * 1e9,
        sd(a.detection_gap_m.sd, 1e9),
        a.used().count(),
        a.profiles.len()
    );
    println!(
        "edge radius {:.3} µm; Hertz fit a = {:.3} µm, R = {:.1} µm",
        a.edge_radius_m.mean * 1e6,
        a.contact_radius_m.mean * 1e6,
        a.sphere_radius_m.mean * 1e6
    );
    for p in a.profiles.iter().filter(|p| p.skipped.is_some()) {
        eprintln!(
            "contactscope: warning: profile {} ({:.1}°) skipped: {}",
            p.index,
            p.angle_deg,
            p.skipped.as_deref().unwrap_or_default()
        );
    }
    for path in written {
        println!("wrote {}", path.display());
    }
}
