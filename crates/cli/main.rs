//! The `contactscope` command line: parse the arguments, dispatch to the command's file, print
//! one line per error. No analysis here: each command builds the request of its job in
//! `contactscope-jobs`, runs it and prints the outcome (`docs/architecture.md`).

mod args;
mod common;
mod errors;
mod signals;

mod analyze;
mod autocorr;
mod batch;
mod compare;
mod demo;
mod fit_hardening;
mod friction;
mod hertz;
mod info;
mod newton;
mod psf;
mod simulate;
mod surface;
mod synth_series;
mod threshold;
mod topography;
#[cfg(test)]
mod vocabulary;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use common::Finished;

#[derive(Parser)]
#[command(
    name = "contactscope",
    version = env!("CONTACTSCOPE_LONG_VERSION"),
    about = "Real-contact-area microscopy: confocal load series → contact area versus load"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// On failure, print every cause of the error on its own line (default: one line)
    #[arg(long, global = true)]
    verbose: bool,
    /// S3-compatible server for s3:// inputs (MinIO, Ceph, a lab's object store), e.g.
    /// http://127.0.0.1:9000; default: AWS_ENDPOINT_URL_S3, AWS_ENDPOINT_URL, else Amazon S3
    #[arg(long, global = true, value_name = "URL")]
    endpoint_url: Option<String>,
}

#[derive(Subcommand)]
enum Command {
    /// Analyse a load series: one global Otsu threshold, contact area per image, fits, plots.
    #[command(
        after_help = "Examples:\n  contactscope analyze series.tif --forces 4,10,20,40mN --out results\n  contactscope analyze ramp.czi --load-axis t --forces 1mN..100mN:8 --overlays\n  contactscope analyze my-experiment/   (a folder holding manifest.csv: file,page,force_mN)"
    )]
    Analyze(analyze::Args),
    /// A lab's archive in one command: every series of a samplesheet or a folder, one table.
    #[command(
        long_about = "A lab's archive in one command: every series of a samplesheet (id, input, per-series options, metadata columns) or of a folder walk is analysed as `analyze` would (series/ID), fitted with fit-hardening where a row names a height map (fit/ID), and tabulated: images.parquet/.csv (one row per image), series.parquet/.csv (one row per series), batch.json (provenance), index.html (QC page). A re-run redoes only the series whose inputs, options or outputs changed.\n\nExit status: 0 when every series succeeded, 3 when some failed (their rows in series.csv say why; the tables and the page are written), 1 when the batch could not run.",
        after_help = "Examples:\n  contactscope batch archive/ --out results   (every folder with manifest.csv, every .czi/.nd2/.lif/.zarr)\n  contactscope batch --samplesheet sheet.csv --out results --color-by lubricant\n  contactscope batch archive/ --pattern '*.czi' --load-axis t --forces 4mN..400mN:8 --out results"
    )]
    Batch(Box<batch::Args>),
    /// Print the global Otsu threshold of all pages of all inputs.
    #[command(
        after_help = "Examples:\n  contactscope threshold series.tif\n  contactscope threshold ramp.czi --channel 0"
    )]
    Threshold(threshold::Args),
    /// Describe a micrograph file (TIFF, CZI, ND2, LIF, OME-Zarr): series, axes, channels, sample type, pixel size.
    #[command(
        after_help = "Examples:\n  contactscope info ramp.czi\n  contactscope info series.tif"
    )]
    Info(info::Args),
    /// Generate a synthetic load series with known ground truth (seeded).
    #[command(
        after_help = "Examples:\n  contactscope synth-series --out synthetic --forces 4mN..100mN:8\n  contactscope analyze synthetic"
    )]
    SynthSeries(synth_series::Args),
    /// The whole method on a generated paper-regime experiment, with an HTML report.
    #[command(after_help = "Examples:\n  contactscope demo\n  contactscope demo --out report")]
    Demo(demo::Args),
    /// Simulate contact of a rough topography under a load sweep (elastic, hardness, hardening, gt).
    #[command(
        after_help = "Examples:\n  contactscope simulate --topography sphere.npy --pixel-size 32nm --height-unit 1nm --modulus 3.7GPa --model hardening --hardening 4MPa/nm --forces 4mN..400mN:12 --out sim\n  contactscope simulate --topography scan.gwy --radius 290um --modulus 3.7GPa --model elastic --forces 4,40,400mN\n  contactscope simulate --topography rough2048.npy --pixel-size 32nm --radius 290um --modulus 3.7GPa --model hardening --hardening 4MPa/nm --forces 4,40,400mN --maps contact --out ramp"
    )]
    Simulate(simulate::Args),
    /// Generate a self-affine random surface (Fourier filtering, seeded).
    #[command(
        after_help = "Examples:\n  contactscope surface --size 1024 --pixel-size 32nm --rms-slope 0.2 --rolloff 8um --out rough.npy"
    )]
    Surface(surface::Args),
    /// Print a topography's size, pixel size and roughness statistics.
    #[command(
        after_help = "Examples:\n  contactscope topography scan.gwy\n  contactscope topography rough.npy --pixel-size 32nm --height-unit 1nm"
    )]
    Topography(topography::Args),
    /// Radially averaged intensity autocorrelation of images (several go on one plot).
    #[command(
        after_help = "Examples:\n  contactscope autocorr contact_4mN.tif contact_40mN.tif --out acf"
    )]
    Autocorr(autocorr::Args),
    /// Compare simulated contact maps with micrographs load by load (blur, register, score).
    #[command(
        after_help = "Examples:\n  contactscope compare --micrographs results/ --simulation sim --psf psf/psf.json --out cmp\n  contactscope compare --micrographs series.tif --forces 4,40,400mN --simulation sim --psf-fwhm 450nm"
    )]
    Compare(compare::Args),
    /// Fit the hardening coefficient k (and p_Y, and score elastic and GT) to a measured area–load curve.
    #[command(
        after_help = "Examples:\n  contactscope fit-hardening --areas results/areas.csv --topography sphere.npy --pixel-size 32nm --height-unit 1nm --modulus 3.7GPa\n  contactscope fit-hardening --areas areas.csv --topography scan.gwy --radius 290um --modulus 3.7GPa --models hardening --psf psf.json --imaged-areas --micrograph-pixel-size 200nm"
    )]
    FitHardening(fit_hardening::Args),
    /// Detection gap from Newton rings in a reflection image and the fluorescent contact.
    #[command(
        after_help = "Examples:\n  contactscope newton reflection.tif --contact fluorescence.tif --wavelength 488nm"
    )]
    Newton(newton::Args),
    /// Measure the microscope PSF on a bead image or z stack (radial Gaussian fits, FWHM).
    #[command(
        after_help = "Examples:\n  contactscope psf beads.tif --bead-diameter 100nm --out psf"
    )]
    Psf(psf::Args),
    /// Static and kinetic friction from rheometer traces; τ of F = τ·A with measured areas.
    #[command(
        after_help = "Examples:\n  contactscope friction trace_4mN.csv trace_40mN.csv --areas results/areas.csv\n  contactscope friction torque.csv --rotation-radius 5mm --forces 40mN"
    )]
    Friction(friction::Args),
    /// Contact modulus E* from a squeeze test of one sphere between two plates (Hertz).
    #[command(
        after_help = "Examples:\n  contactscope hertz squeeze.csv --radius 290um --forces 4mN..400mN:12"
    )]
    Hertz(hertz::Args),
}

/// The command line's grammar, with option values allowed to start with `-` (`--radius -1um` is
/// then refused by the range check with its reason, not by clap as an unknown flag `-1`).
fn grammar() -> clap::Command {
    fn hyphen_values(arg: clap::Arg) -> clap::Arg {
        let one_value = arg
            .get_num_args()
            .is_none_or(|r| r.min_values() == 1 && r.max_values() == 1);
        if arg.get_long().is_some() && arg.get_action().takes_values() && one_value {
            arg.allow_hyphen_values(true)
        } else {
            arg
        }
    }
    Cli::command().mut_subcommands(|sub| sub.mut_args(hyphen_values))
}

fn main() -> ExitCode {
    signals::end_quietly_on_closed_output();
    let parsed = grammar()
        .try_get_matches()
        .and_then(|m| Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => {
            // --help and --version
            let _ = e.print();
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("{}", errors::usage_line(&e));
            return ExitCode::from(2);
        }
    };
    let (command, verbose) = (cli.command, cli.verbose);
    if let Err(e) = contactscope_formats::remote::set_endpoint_url(cli.endpoint_url.as_deref()) {
        eprintln!("contactscope: error: --endpoint-url: {e} (see --help)");
        return ExitCode::from(2);
    }
    // Messages name parameters as flags (`--pixel-size`).
    contactscope_formats::param::set_front_end(contactscope_formats::param::FrontEnd::CommandLine);
    signals::discard_on_interrupt();
    contactscope_jobs::provenance::set_source_revision(env!("CONTACTSCOPE_SOURCE_REVISION"));
    let done = |r: anyhow::Result<()>| r.map(|()| Finished::Complete);
    let result = match command {
        Command::Analyze(args) => analyze::run(args),
        Command::Batch(args) => batch::run(*args).map(|all_ok| match all_ok {
            true => Finished::Complete,
            false => Finished::SomeFailed,
        }),
        Command::Threshold(args) => done(threshold::run(args)),
        Command::Info(args) => done(info::run(args)),
        Command::SynthSeries(args) => done(synth_series::run(args)),
        Command::Demo(args) => done(demo::run(args)),
        Command::Simulate(args) => simulate::run(args),
        Command::Surface(args) => done(surface::run(args)),
        Command::Topography(args) => done(topography::run(args)),
        Command::Autocorr(args) => done(autocorr::run(args)),
        Command::Compare(args) => done(compare::run(args)),
        Command::FitHardening(args) => done(fit_hardening::run(args)),
        Command::Newton(args) => done(newton::run(args)),
        Command::Psf(args) => done(psf::run(args)),
        Command::Friction(args) => done(friction::run(args)),
        Command::Hertz(args) => done(hertz::run(args)),
    };
    match result {
        Ok(Finished::Complete) => ExitCode::SUCCESS,
        // A batch whose tables are written but some series failed (docs/errors.md).
        Ok(Finished::SomeFailed) => ExitCode::from(3),
        // Outputs written, but no load valid (docs/errors.md).
        Ok(Finished::NothingValid) => ExitCode::from(4),
        Err(e) if signals::closed_output(&e) => signals::end_by_sigpipe(),
        Err(_) if signals::interrupted() => loop {
            // The signal handler reports and exits; the run's error is a consequence.
            std::thread::park();
        },
        Err(e) => {
            eprintln!("{}", errors::report(&e, verbose));
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Flattened argument groups (selection flags, height-map options) must not clash with a
    /// command's own flags. clap checks this only with debug assertions, which the release
    /// profile the tests run in turns off, so the long names are compared here.
    #[test]
    fn no_command_has_two_flags_of_one_name() {
        for command in super::Cli::command().get_subcommands() {
            let mut names: Vec<&str> = command
                .get_arguments()
                .filter_map(|a| a.get_long())
                .collect();
            let n = names.len();
            names.sort_unstable();
            names.dedup();
            assert_eq!(names.len(), n, "{}: {names:?}", command.get_name());
        }
        let analyze = super::Cli::command();
        let analyze = analyze.find_subcommand("analyze").unwrap();
        for flag in ["series", "channel", "z", "t", "axis", "load-axis"] {
            assert!(
                analyze.get_arguments().any(|a| a.get_long() == Some(flag)),
                "analyze --{flag}"
            );
        }
    }
}
