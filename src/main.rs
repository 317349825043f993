//! The `contactscope` command line: parse arguments, call the library, print. No analysis here.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use contactscope::analysis::Pass;
use contactscope::compare::CompareSettings;
use contactscope::io::results::fwhm_from_psf_json;
use contactscope::io::series::DEFAULT_MEMORY_BUDGET;
use contactscope::io::series::{self, Series};
use contactscope::io::tiff::write::Compression;
use contactscope::io::tiff::TiffReader;
use contactscope::io::topography::{read_topography, write_gsf, write_npy, TopographySource};
use contactscope::io::units::{self, Dimension};
use contactscope::jobs::analyze::{self as pipeline, AnalyzeRequest};
use contactscope::jobs::analyze::{AnalyzeOptions, HertzParams};
use contactscope::jobs::autocorr::{run_autocorr, AutocorrRequest};
use contactscope::jobs::compare::{self as comparison, CompareRequest, ExperimentInput};
use contactscope::jobs::demo::DemoParams;
use contactscope::jobs::fit_hardening::{self as fit_job, FitRequest, Sweep, SweepMicrographs};
use contactscope::jobs::friction::{self, FrictionRequest};
use contactscope::jobs::hertz::{self as squeeze, HertzRequest};
use contactscope::jobs::newton::{self as newton_rings, NewtonRequest};
use contactscope::jobs::psf::{self as psf_job, PsfRequest};
use contactscope::jobs::simulate::{self as job, ModelChoice, SimulateRequest};
use contactscope::jobs::synth_series::{self as synth, Layout};
use contactscope::mechanics::friction::SlipOptions;
use contactscope::model_fit::{Family, Imaging, Search};
use contactscope::optics::newton::{NewtonOptions, Phase};
use contactscope::optics::psf;
use contactscope::solver::cg::SolverOptions;
use contactscope::solver::simulate::Model;
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::Detrend;
use contactscope::synth::SynthParams;
use contactscope::threshold::Method;

#[derive(Parser)]
#[command(
    name = "contactscope",
    version,
    about = "Real-contact-area microscopy: confocal load series → contact area versus load"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Analyse a load series: one global Otsu threshold, contact area per image, fits, plots.
    Analyze(AnalyzeArgs),
    /// Print the global Otsu threshold of all pages of all inputs.
    Threshold(ThresholdArgs),
    /// Describe a TIFF file: pages, shape, sample type, compression, channels, pixel size.
    Info(InfoArgs),
    /// Generate a synthetic load series with known ground truth (seeded).
    SynthSeries(SynthArgs),
    /// Analyse the bundled synthetic load series and compare with its ground truth.
    Demo(DemoArgs),
    /// Simulate contact of a rough topography under a load sweep (elastic, hardness, hardening, gt).
    Simulate(SimulateArgs),
    /// Generate a self-affine random surface (Fourier filtering, seeded).
    Surface(SurfaceArgs),
    /// Print a topography's size, pixel size and roughness statistics.
    Topography(TopographyArgs),
    /// Radially averaged intensity autocorrelation of images (several go on one plot).
    Autocorr(AutocorrArgs),
    /// Compare simulated contact maps with micrographs load by load (blur, register, score).
    Compare(CompareArgs),
    /// Fit the hardening coefficient k (and p_Y, and score elastic and GT) to a measured area–load curve.
    FitHardening(FitArgs),
    /// Detection gap from Newton rings in a reflection image and the fluorescent contact.
    Newton(NewtonArgs),
    /// Measure the microscope PSF on a bead image or z stack (radial Gaussian fits, FWHM).
    Psf(PsfArgs),
    /// Static and kinetic friction from rheometer traces; τ of F = τ·A with measured areas.
    Friction(FrictionArgs),
    /// Contact modulus E* from a squeeze test of one sphere between two plates (Hertz).
    Hertz(HertzArgs),
}

#[derive(Clone, Copy, ValueEnum)]
enum PhaseArg {
    /// Maxima at (m + ½)λ/(2n), dark contact (paper Eq. 1; n_sphere > n_medium).
    Half,
    /// Maxima at mλ/(2n), bright contact (n_sphere < n_medium, e.g. PTFE).
    Zero,
}

#[derive(clap::Args)]
struct NewtonArgs {
    /// Reflection image with Newton rings (single-page TIFF).
    reflection: PathBuf,
    /// Fluorescence image of the contact, same field and size.
    #[arg(long = "contact")]
    contact: PathBuf,
    /// Pixel size (overrides metadata): 200nm or 200x210nm.
    #[arg(long)]
    pixel_size: Option<String>,
    /// Illumination wavelength.
    #[arg(long, default_value = "488nm")]
    wavelength: String,
    /// Refractive index of the medium in the gap (formamide 1.447).
    #[arg(long, default_value_t = 1.447)]
    medium_index: f64,
    /// Number of line profiles through the centre, evenly spread over 180°.
    #[arg(long, default_value_t = 20)]
    profiles: usize,
    /// Phase of the reflection maxima.
    #[arg(long, value_enum, default_value = "half")]
    phase: PhaseArg,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/newton")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct PsfArgs {
    /// Bead image or z stack (TIFF; every page of the chosen channel).
    input: PathBuf,
    /// Pixel size (overrides metadata), e.g. 101nm; must be square.
    #[arg(long)]
    pixel_size: Option<String>,
    /// Bead diameter, e.g. 100nm: turns on the finite-bead correction σ² − a²/5.
    #[arg(long)]
    bead_diameter: Option<String>,
    /// Channel of multi-channel files.
    #[arg(long)]
    channel: Option<usize>,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/psf")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct FitArgs {
    /// areas.csv of `contactscope analyze` (force_mN, area_um2).
    #[arg(long)]
    experiment: PathBuf,
    #[command(flatten)]
    body: BodyArgs,
    /// Models to fit or score, comma-separated.
    #[arg(long, default_value = "gt,elastic,hardness,hardening")]
    models: String,
    /// Search range for k.
    #[arg(long, default_value = "0.1..100MPa/nm")]
    k_range: String,
    /// Search range for the penetration hardness p_Y.
    #[arg(long, default_value = "10MPa..10GPa")]
    hardness_range: String,
    /// Parameter sweep: k=1..10MPa/nm:10 (evenly spaced), k=1,2,4MPa/nm, or hardness=….
    #[arg(long)]
    sweep: Option<String>,
    /// Micrographs for Dice in the sweep: a manifest CSV or a folder with manifest.csv.
    #[arg(long)]
    micrographs: Option<PathBuf>,
    /// PSF FWHM for Dice in the sweep (e.g. 450nm).
    #[arg(long)]
    psf_fwhm: Option<String>,
    /// Micrograph pixel size (e.g. 200nm): overrides the micrographs' metadata, and sets the
    /// image grid for --imaged-areas.
    #[arg(long)]
    micrograph_pixel_size: Option<String>,
    /// Count simulated areas as the microscope sees them (blur with --psf-fwhm onto
    /// --micrograph-pixel-size pixels, Otsu), like areas measured on micrographs.
    #[arg(long)]
    imaged_areas: bool,
    /// Periodic boundaries (nominally flat periodic maps).
    #[arg(long)]
    periodic: bool,
    /// CG relative tolerance.
    #[arg(long, default_value_t = 1e-8)]
    tolerance: f64,
    /// CG iteration limit per load.
    #[arg(long, default_value_t = 5000)]
    max_iterations: usize,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/fit")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct FrictionArgs {
    /// Trace CSVs: time_s | displacement_um | angle_rad, friction_mN | friction_N | torque_mNm |
    /// torque_Nm, optional normal_force_mN | normal_force_N.
    #[arg(required = true)]
    traces: Vec<PathBuf>,
    /// Normal force for traces without a normal-force column (e.g. 40mN).
    #[arg(long)]
    normal_force: Option<String>,
    /// Rotation radius of the sphere on the rheometer plate, turns torque into force (e.g. 5mm).
    #[arg(long)]
    rotation_radius: Option<String>,
    /// areas.csv from `contactscope analyze` (force_mN, area_um2), for F = τ·A.
    #[arg(long)]
    areas: Option<PathBuf>,
    /// Largest relative difference between a trace's normal force and an area row (e.g. 2%).
    #[arg(long, default_value = "2%")]
    force_tolerance: String,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/friction")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct HertzArgs {
    /// Squeeze CSV: force_mN | force_N and displacement_um (total plate displacement 2δ).
    input: PathBuf,
    /// Sphere radius (e.g. 290um).
    #[arg(long)]
    radius: String,
    /// Loads at which to predict the Hertz contact radius (default: the measured forces).
    #[arg(long)]
    loads: Option<String>,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/hertz")]
    out: PathBuf,
}

#[derive(clap::Args)]
#[command(group(clap::ArgGroup::new("psf_source").required(true).args(["psf", "psf_fwhm"])))]
struct CompareArgs {
    /// The micrographs: a manifest CSV (file, page, force_mN), a folder holding manifest.csv,
    /// or TIFF files/folders together with --forces.
    #[arg(long, required = true, num_args = 1..)]
    experiment: Vec<PathBuf>,
    /// Normal force per micrograph when --experiment names TIFFs (e.g. 4mN,8mN or 4mN..40mN:8).
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
    /// Micrograph pixel size, overriding the files' metadata (e.g. 200nm).
    #[arg(long)]
    pixel_size: Option<String>,
    /// Channel of multi-channel micrographs.
    #[arg(long)]
    channel: Option<usize>,
    /// Also try mirror images and 90° rotations when registering.
    #[arg(long)]
    dihedral: bool,
    /// Sub-pixel registration resolution: 1/N pixel.
    #[arg(long, default_value_t = 20)]
    upsample: usize,
    /// Largest relative force difference for loads to match (e.g. 1% or 0.01).
    #[arg(long, default_value = "1%")]
    force_tolerance: String,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/compare")]
    out: PathBuf,
}

#[derive(clap::Args)]
struct AutocorrArgs {
    /// TIFF images (every page of a multi-page file counts as one image).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Pixel size, overriding the files' metadata (e.g. 200nm or 200x210nm).
    #[arg(long)]
    pixel_size: Option<String>,
    /// Largest lag (e.g. 20um); default half the smaller image side.
    #[arg(long)]
    max_lag: Option<String>,
    /// Channel of multi-channel files.
    #[arg(long)]
    channel: Option<usize>,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/autocorr")]
    out: PathBuf,
}

#[derive(Clone, Copy, ValueEnum)]
enum ModelArg {
    /// Linear elastic hard-wall contact.
    Elastic,
    /// Penetration hardness (bounded pressure).
    Hardness,
    /// Linear contact hardening.
    Hardening,
    /// Greenwood–Tripp bearing area.
    Gt,
}

#[derive(Clone, Copy, ValueEnum)]
enum DetrendArg {
    /// Keep the heights as read.
    None,
    /// Subtract the mean height.
    Mean,
    /// Subtract the least-squares plane.
    Plane,
}

#[derive(clap::Args)]
struct TopographyInput {
    /// Height map: .npy, float TIFF, .gsf, text matrix (.txt/.csv/.dat), WSxM .top, Nanoscope .di.
    #[arg(long = "topography")]
    path: PathBuf,
    /// Pixel size (needed for .npy and text; overrides metadata): 32nm or 32x40nm.
    #[arg(long)]
    pixel_size: Option<String>,
    /// Height unit of files that do not state one (.npy, text, TIFF), e.g. 1nm; default metres.
    #[arg(long)]
    height_unit: Option<String>,
    /// Detrending before anything else.
    #[arg(long, value_enum, default_value = "plane")]
    detrend: DetrendArg,
}

/// The rough sphere and its material, as `simulate` and `fit-hardening` take them.
#[derive(clap::Args)]
struct BodyArgs {
    #[command(flatten)]
    input: TopographyInput,
    /// Sphere radius added to a flattened map (and the GT sphere), e.g. 290um.
    #[arg(long)]
    radius: Option<String>,
    /// Contact modulus E*, e.g. 3.7GPa.
    #[arg(long)]
    modulus: String,
}

#[derive(clap::Args)]
struct SimulateArgs {
    #[command(flatten)]
    body: BodyArgs,
    /// Contact model.
    #[arg(long, value_enum)]
    model: ModelArg,
    /// Penetration hardness p_Y for --model hardness, e.g. 370MPa.
    #[arg(long)]
    hardness: Option<String>,
    /// Hardening modulus k for --model hardening, e.g. 4MPa/nm.
    #[arg(long)]
    hardening: Option<String>,
    /// Initial yield pressure p_Y0 for --model hardening (the paper's model has 0).
    #[arg(long, default_value = "0MPa")]
    initial_hardness: String,
    /// Volume-conserving plastic increment (Eq. 5) for --model hardness, relaxation α in (0, 1].
    #[arg(long, num_args = 0..=1, default_missing_value = "1.0")]
    volume_conserving: Option<f64>,
    /// Periodic boundaries (nominally flat periodic surfaces); free otherwise.
    #[arg(long)]
    periodic: bool,
    /// Loads: 4mN,10mN,40mN or 4mN..400mN:12 (log-spaced).
    #[arg(long)]
    loads: String,
    /// Relative solver tolerance.
    #[arg(long, default_value_t = 1e-8)]
    tolerance: f64,
    /// Most CG iterations per solve.
    #[arg(long, default_value_t = 5000)]
    max_iterations: usize,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/simulate")]
    out: PathBuf,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::Args)]
struct SurfaceArgs {
    /// Grid size in pixels (square).
    #[arg(long, default_value_t = 1024)]
    size: usize,
    /// Pixel size, e.g. 32nm.
    #[arg(long)]
    pixel_size: String,
    /// Hurst exponent H in (0, 1].
    #[arg(long, default_value_t = 0.8)]
    hurst: f64,
    /// RMS slope h'_rms (central differences); or give --rms-height.
    #[arg(long, conflicts_with = "rms_height")]
    rms_slope: Option<f64>,
    /// RMS height, e.g. 50nm.
    #[arg(long)]
    rms_height: Option<String>,
    /// Roll-off wavelength (PSD flat above it), e.g. 8um.
    #[arg(long)]
    rolloff: Option<String>,
    /// Short cutoff wavelength (no roughness below it), e.g. 128nm.
    #[arg(long)]
    cutoff: Option<String>,
    /// Random seed.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Output file: .npy or .gsf (heights in metres).
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct TopographyArgs {
    /// Height map file.
    file: PathBuf,
    /// Pixel size (needed for .npy and text).
    #[arg(long)]
    pixel_size: Option<String>,
    /// Height unit of files that do not state one, e.g. 1nm.
    #[arg(long)]
    height_unit: Option<String>,
    /// Detrending before the statistics.
    #[arg(long, value_enum, default_value = "plane")]
    detrend: DetrendArg,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
struct AnalyzeArgs {
    /// TIFF files or directories of TIFFs (natural sort order). Not with --manifest.
    inputs: Vec<PathBuf>,
    /// CSV with columns file, [page], force_mN, [friction_mN]; paths relative to the CSV.
    #[arg(long, conflicts_with_all = ["inputs", "forces"])]
    manifest: Option<PathBuf>,
    /// Normal forces, one per image, with a unit: 4,10,20,40mN.
    #[arg(long)]
    forces: Option<String>,
    /// Channel of multi-channel files (samples per pixel or ImageJ hyperstack channels).
    #[arg(long)]
    channel: Option<usize>,
    /// otsu (one threshold for the series), per-image, or a number (contact is value > t).
    #[arg(long, default_value = "otsu")]
    threshold: String,
    /// Pixel size overriding the metadata: 200nm, 0.2um or 200x210nm.
    #[arg(long)]
    pixel_size: Option<String>,
    /// Sphere radius for Hertz columns, e.g. 290um (needs --modulus).
    #[arg(long, requires = "modulus")]
    radius: Option<String>,
    /// Contact modulus E* for Hertz columns, e.g. 3.7GPa (needs --radius).
    #[arg(long, requires = "radius")]
    modulus: Option<String>,
    /// Output folder.
    #[arg(long, default_value = "contactscope-out")]
    out: PathBuf,
    /// Write one PNG per image with contact edges in green.
    #[arg(long)]
    overlays: bool,
    /// Write the contact masks as TIFF.
    #[arg(long)]
    save_masks: bool,
    /// Decoded images of compressed files kept in memory between the two passes, in MiB.
    #[arg(long, default_value_t = DEFAULT_MEMORY_BUDGET >> 20)]
    memory_mib: usize,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(clap::Args)]
struct ThresholdArgs {
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

#[derive(clap::Args)]
struct InfoArgs {
    /// A TIFF file.
    file: PathBuf,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, ValueEnum)]
enum LayoutArg {
    /// One multi-page TIFF.
    Multipage,
    /// One file per load.
    Files,
}

#[derive(Clone, Copy, ValueEnum)]
enum CompressionArg {
    /// Uncompressed.
    None,
    /// LZW.
    Lzw,
    /// Deflate.
    Deflate,
}

#[derive(clap::Args)]
struct SynthArgs {
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Image size in pixels (square).
    #[arg(long, default_value_t = 256)]
    size: usize,
    /// Normal forces with a unit.
    #[arg(long, default_value = "4,6,10,16,25,40,63,100mN")]
    loads: String,
    /// Random seed.
    #[arg(long, default_value_t = 2018)]
    seed: u64,
    /// Pixel size.
    #[arg(long, default_value = "200nm")]
    pixel_size: String,
    /// multipage or files.
    #[arg(long, value_enum, default_value = "multipage")]
    layout: LayoutArg,
    /// TIFF compression.
    #[arg(long, value_enum, default_value = "none")]
    compression: CompressionArg,
}

#[derive(clap::Args)]
struct DemoArgs {
    /// Report folder (an earlier demo report there is replaced).
    #[arg(long, default_value = "contactscope-out/demo")]
    out: PathBuf,
    /// The reduced demo of the test suite (smaller maps, fewer loads).
    #[arg(long)]
    small: bool,
    /// No stage messages.
    #[arg(long, short)]
    quiet: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Analyze(args) => analyze(args),
        Command::Threshold(args) => threshold(args),
        Command::Info(args) => info(args),
        Command::SynthSeries(args) => synth_series(args),
        Command::Demo(args) => demo(args),
        Command::Simulate(args) => simulate(args),
        Command::Surface(args) => surface(args),
        Command::Topography(args) => topography(args),
        Command::Autocorr(args) => autocorr(args),
        Command::Compare(args) => compare(args),
        Command::FitHardening(args) => fit_hardening(args),
        Command::Newton(args) => newton(args),
        Command::Friction(args) => friction_cmd(args),
        Command::Hertz(args) => hertz_cmd(args),
        Command::Psf(args) => psf(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("contactscope: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// A progress bar on stderr, hidden with --quiet, when stderr is not a terminal, or when there
/// are fewer than `min_items` items (a short job needs none).
fn progress_bar(items: usize, min_items: usize, quiet: bool) -> ProgressBar {
    let visible = !quiet && items >= min_items && std::io::stderr().is_terminal();
    let bar = ProgressBar::with_draw_target(
        Some(items as u64),
        if visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    bar.set_style(
        ProgressStyle::with_template("{msg:>10} [{bar:40}] {pos}/{len} images ({elapsed})")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

fn build_series(args: &AnalyzeArgs) -> Result<Series> {
    let mut series = match &args.manifest {
        Some(manifest) => series::from_manifest(manifest, args.channel)?,
        None => {
            if args.inputs.is_empty() {
                bail!("give TIFF files or directories, or --manifest");
            }
            series::from_files(&args.inputs, args.channel)?
        }
    };
    if let Some(text) = &args.forces {
        let forces = units::parse_quantity_list(text, Dimension::Force)
            .with_context(|| format!("--forces {text}"))?;
        series::assign_forces(&mut series, &forces)?;
    }
    Ok(series)
}

fn analyze(args: AnalyzeArgs) -> Result<()> {
    let series = build_series(&args)?;
    let hertz = match (&args.radius, &args.modulus) {
        (Some(r), Some(e)) => Some(HertzParams {
            radius_m: units::parse_positive(r, Dimension::Length).context("--radius")?,
            modulus_pa: units::parse_positive(e, Dimension::Pressure).context("--modulus")?,
        }),
        _ => None,
    };
    let options = AnalyzeOptions {
        method: Method::parse(&args.threshold)?,
        pixel_size_override: optional_pixel_size(&args.pixel_size, "--pixel-size")?,
        hertz,
        memory_budget: args.memory_mib << 20,
    };
    let request = AnalyzeRequest {
        series,
        options,
        out_dir: args.out.clone(),
        overlays: args.overlays,
        save_masks: args.save_masks,
        command_line: std::env::args().collect(),
    };
    let outcome = run_with_progress(&request, args.quiet)?;
    print_outcome(&outcome, &args.out);
    Ok(())
}

fn run_with_progress(request: &AnalyzeRequest, quiet: bool) -> Result<pipeline::AnalyzeOutcome> {
    let bar = progress_bar(request.series.images.len(), 4, quiet);
    let progress = |pass: Pass, done: usize, _total: usize| {
        bar.set_message(match pass {
            Pass::Histogram => "histogram",
            Pass::Measure => "measure",
        });
        bar.set_position(done as u64);
    };
    let outcome = pipeline::run_analyze(request, &progress);
    bar.finish_and_clear();
    Ok(outcome?)
}

fn print_outcome(outcome: &pipeline::AnalyzeOutcome, out: &Path) {
    let a = &outcome.analysis;
    let r = &outcome.report;
    for w in &a.warnings {
        eprintln!("contactscope: warning: {w}");
    }
    match a.series_threshold {
        Some(t) => println!(
            "threshold: {} ({}), contact is value > t, from {} pixels",
            t.value,
            a.method.name(),
            a.histogram_pixels
        ),
        None => println!("threshold: one Otsu threshold per image (see areas.csv)"),
    }
    match a.pixel_size {
        Some(p) => println!(
            "pixel size: {:.5} × {:.5} µm from {}",
            p.x_m * 1e6,
            p.y_m * 1e6,
            p.source.describe()
        ),
        None => println!("pixel size: unknown, areas in pixels"),
    }
    let unit = match r.unit {
        contactscope::jobs::analyze::AreaUnit::SquareMicrometre => "µm²",
        contactscope::jobs::analyze::AreaUnit::Pixel => "px",
    };
    println!(
        "{:>10} {:>12} {:>8} {:>10}",
        "force_mN",
        format!("area_{unit}"),
        "patches",
        "p_MPa"
    );
    for row in &r.rows {
        let f = row.force_mn.map_or("-".into(), |f| format!("{f:.3}"));
        let p = row
            .mean_pressure_mpa
            .map_or("-".into(), |p| format!("{p:.1}"));
        println!("{f:>10} {:>12.2} {:>8} {p:>10}", row.area, row.patches);
    }
    if let Some(fit) = r.power_law {
        let se = fit
            .exponent_se
            .map_or(String::new(), |s| format!(" ± {s:.3}"));
        println!(
            "power law: A ∝ N^β, β = {:.3}{se}, R² = {:.4}",
            fit.exponent, fit.r_squared
        );
    }
    if let Some((p, _)) = r.proportional_mpa {
        println!("proportional fit: A = N/p, p = {p:.1} MPa");
    }
    println!(
        "wrote {} files to {}:",
        outcome.written.len(),
        out.display()
    );
    for path in outcome.written.iter().filter(|p| !is_per_image(p)) {
        println!("  {}", path.display());
    }
    let per_image = outcome.written.iter().filter(|p| is_per_image(p)).count();
    if per_image > 0 {
        println!("  … and {per_image} overlay/mask files");
    }
}

fn is_per_image(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.starts_with("overlay_") || n.starts_with("mask_"))
}

fn threshold(args: ThresholdArgs) -> Result<()> {
    let series = series::from_files(&args.inputs, args.channel)?;
    let (t, pixels, warnings) =
        contactscope::analysis::global_threshold(&series.planes(0), &|_, _, _| {})?;
    for w in &warnings {
        eprintln!("contactscope: warning: {w}");
    }
    if args.json {
        let value = serde_json::json!({
            "threshold": t.value,
            "method": "otsu-global",
            "contact_rule": "value > threshold",
            "pixels": pixels,
            "images": series.images.len(),
            "files": series.files.len(),
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        println!(
            "{} (global Otsu over {} pixels in {} images; contact is value > threshold)",
            t.value,
            pixels,
            series.images.len()
        );
    }
    Ok(())
}

fn info(args: InfoArgs) -> Result<()> {
    let reader = TiffReader::open(&args.file)?;
    let i = reader.info();
    if args.json {
        println!("{}", serde_json::to_string_pretty(i)?);
        return Ok(());
    }
    println!("file:         {}", i.path.display());
    println!("pages:        {}", i.pages.len());
    println!(
        "shape:        {} × {} px (width × height)",
        i.width, i.height
    );
    println!(
        "sample type:  {} ({} bits)",
        i.sample_type.name(),
        i.bits_per_sample
    );
    println!(
        "channels:     {} ({})",
        i.channels,
        i.channel_layout.describe()
    );
    println!(
        "compression:  {} (predictor: {}), {}{}, {}-endian",
        i.compression,
        i.predictor,
        if i.tiled { "tiled" } else { "strips" },
        if i.bigtiff { ", BigTIFF" } else { "" },
        i.byte_order
    );
    println!("description:  {}", i.description_kind);
    match i.pixel_size {
        Some(p) => println!(
            "pixel size:   {} × {} from {}",
            units::format_length(p.x_m),
            units::format_length(p.y_m),
            p.source.describe()
        ),
        None => println!("pixel size:   none in the metadata (use --pixel-size)"),
    }
    for note in &i.notes {
        println!("note:         {note}");
    }
    Ok(())
}

fn synth_series(args: SynthArgs) -> Result<()> {
    let (pixel, _) = units::parse_pixel_size(&args.pixel_size).context("--pixel-size")?;
    let params = SynthParams {
        width: args.size,
        height: args.size,
        pixel_size_m: pixel,
        forces_n: units::parse_quantity_list(&args.loads, Dimension::Force).context("--loads")?,
        seed: args.seed,
        ..SynthParams::default()
    };
    let layout = match args.layout {
        LayoutArg::Multipage => Layout::MultiPage,
        LayoutArg::Files => Layout::Files,
    };
    let compression = match args.compression {
        CompressionArg::None => Compression::None,
        CompressionArg::Lzw => Compression::Lzw,
        CompressionArg::Deflate => Compression::Deflate,
    };
    for path in synth::write_series_compressed(&params, &args.out, layout, compression)? {
        println!("{}", path.display());
    }
    Ok(())
}

/// Where the bundled series lives (next to Cargo.toml).
fn demo(args: DemoArgs) -> Result<()> {
    let params = if args.small {
        DemoParams::reduced()
    } else {
        DemoParams::standard()
    };
    let start = std::time::Instant::now();
    let quiet = args.quiet;
    let progress = |stage: &str| {
        if !quiet {
            eprintln!("[{:>5.1} s] {stage}", start.elapsed().as_secs_f64());
        }
    };
    let outcome = contactscope::jobs::demo::run_demo(&args.out, &params, &progress)?;
    println!(
        "{:<32} {:>12} {:>22} {:>8}  by",
        "quantity", "truth", "recovered", "error"
    );
    for r in &outcome.recovered {
        let unc = r
            .uncertainty
            .map_or(String::new(), |u| format!(" ± {u:.3}"));
        println!(
            "{:<32} {:>12} {:>22} {:>7.1}%  {}",
            r.quantity,
            format!("{:.3} {}", r.truth, r.unit),
            format!("{:.3}{unc}", r.recovered),
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

fn detrend_of(arg: DetrendArg) -> Detrend {
    match arg {
        DetrendArg::None => Detrend::None,
        DetrendArg::Mean => Detrend::Mean,
        DetrendArg::Plane => Detrend::Plane,
    }
}

fn topography_source(input: &TopographyInput) -> Result<TopographySource> {
    Ok(TopographySource {
        path: input.path.clone(),
        pixel_size_m: optional_pixel_size(&input.pixel_size, "--pixel-size")?,
        height_unit_m: optional_length(&input.height_unit, "--height-unit")?,
        detrend: detrend_of(input.detrend),
    })
}

fn optional_pixel_size(text: &Option<String>, flag: &str) -> Result<Option<(f64, f64)>> {
    text.as_deref()
        .map(units::parse_pixel_size)
        .transpose()
        .with_context(|| flag.to_string())
}

fn print_written(files: usize, out: &Path) {
    println!("wrote {files} files to {}", out.display());
}

fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("contactscope: warning: {w}");
    }
}

fn optional_length(text: &Option<String>, flag: &str) -> Result<Option<f64>> {
    text.as_deref()
        .map(|t| units::parse_positive(t, Dimension::Length).with_context(|| flag.to_string()))
        .transpose()
}

fn model_of(args: &SimulateArgs) -> Result<ModelChoice> {
    let pressure = |t: &str, flag: &str| {
        units::parse_positive(t, Dimension::Pressure).with_context(|| flag.to_string())
    };
    Ok(match args.model {
        ModelArg::Elastic => ModelChoice::HalfSpace(Model::Elastic),
        ModelArg::Gt => ModelChoice::GreenwoodTripp,
        ModelArg::Hardness => ModelChoice::HalfSpace(Model::Hardness {
            hardness_pa: pressure(
                args.hardness
                    .as_deref()
                    .context("--model hardness needs --hardness, e.g. 370MPa")?,
                "--hardness",
            )?,
            volume_conserving: args.volume_conserving,
        }),
        ModelArg::Hardening => ModelChoice::HalfSpace(Model::Hardening {
            modulus_pa_per_m: units::parse_ratio(
                args.hardening
                    .as_deref()
                    .context("--model hardening needs --hardening, e.g. 4MPa/nm")?,
                Dimension::Pressure,
                Dimension::Length,
            )
            .context("--hardening")?,
            initial_pa: units::parse_quantity(&args.initial_hardness, Dimension::Pressure)
                .context("--initial-hardness")?,
        }),
    })
}

fn simulate(args: SimulateArgs) -> Result<()> {
    let hardness_model = matches!(args.model, ModelArg::Hardness);
    let hardening_model = matches!(args.model, ModelArg::Hardening);
    if args.volume_conserving.is_some() && !hardness_model {
        bail!("--volume-conserving applies to --model hardness only");
    }
    if args.hardness.is_some() && !hardness_model {
        bail!("--hardness applies to --model hardness only");
    }
    if args.hardening.is_some() && !hardening_model {
        bail!("--hardening applies to --model hardening only");
    }
    let request = SimulateRequest {
        topography: topography_source(&args.body.input)?,
        radius_m: optional_length(&args.body.radius, "--radius")?,
        e_star_pa: units::parse_positive(&args.body.modulus, Dimension::Pressure)
            .context("--modulus")?,
        model: model_of(&args)?,
        periodic: args.periodic,
        loads_n: units::parse_loads(&args.loads).context("--loads")?,
        options: SolverOptions {
            max_iterations: args.max_iterations,
            tolerance: args.tolerance,
            monitor: None,
        },
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let bar = progress_bar(request.loads_n.len(), 1, args.quiet);
    bar.set_style(
        ProgressStyle::with_template("[{bar:30}] {pos}/{len} loads ({elapsed}) {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let monitor = |iteration: usize, residual: f64| {
        bar.set_message(format!("CG iteration {iteration}, residual {residual:.2e}"));
    };
    let outcome = job::run_simulate(
        &request,
        &|done, _| bar.set_position(done as u64),
        Some(&monitor),
    );
    bar.finish_and_clear();
    let outcome = outcome?;
    print_warnings(&outcome.warnings);
    println!(
        "topography: h_rms = {:.4} nm, h'_rms = {:.5}, h''_rms = {:.5} 1/µm",
        outcome.stats.h_rms_m * 1e9,
        outcome.stats.h_prime_rms,
        outcome.stats.h_double_prime_rms_per_m * 1e-6
    );
    println!(
        "{:>10} {:>12} {:>9} {:>10} {:>8} {:>6}",
        "force_mN", "area_µm²", "fraction", "p_mean_MPa", "patches", "iters"
    );
    for l in &outcome.loads {
        println!(
            "{:>10.4} {:>12.4} {:>9.5} {:>10.2} {:>8} {:>6}",
            l.force_n * 1e3,
            l.area_m2 * 1e12,
            l.contact_fraction,
            l.mean_pressure_pa * 1e-6,
            l.patches,
            l.iterations
        );
    }
    print_written(outcome.written.len(), &args.out);
    Ok(())
}

fn surface(args: SurfaceArgs) -> Result<()> {
    let (dx, _) = units::parse_pixel_size(&args.pixel_size).context("--pixel-size")?;
    let target = match (&args.rms_slope, &args.rms_height) {
        (Some(slope), None) => RmsTarget::Slope(*slope),
        (None, Some(h)) => {
            RmsTarget::Height(units::parse_positive(h, Dimension::Length).context("--rms-height")?)
        }
        _ => bail!("give --rms-slope or --rms-height"),
    };
    let params = SelfAffineParams {
        nx: args.size,
        ny: args.size,
        dx_m: dx,
        hurst: args.hurst,
        rolloff_wavelength_m: optional_length(&args.rolloff, "--rolloff")?,
        short_cutoff_wavelength_m: optional_length(&args.cutoff, "--cutoff")?,
        target,
        seed: args.seed,
    };
    let topo = self_affine(&params)?;
    match args.out.extension().and_then(|e| e.to_str()) {
        Some("npy") => write_npy(&args.out, &topo)?,
        Some("gsf") => write_gsf(&args.out, &topo)?,
        _ => bail!(
            "{}: the output must end in .npy or .gsf",
            args.out.display()
        ),
    }
    let stats = SurfaceStats::finite_differences(&topo)?;
    println!(
        "{}: {}×{} px of {}, h_rms = {:.4} nm, h'_rms = {:.5}, h''_rms = {:.5} 1/µm",
        args.out.display(),
        topo.nx(),
        topo.ny(),
        units::format_length(dx),
        stats.h_rms_m * 1e9,
        stats.h_prime_rms,
        stats.h_double_prime_rms_per_m * 1e-6
    );
    Ok(())
}

fn topography(args: TopographyArgs) -> Result<()> {
    let mut topo = read_topography(
        &args.file,
        optional_pixel_size(&args.pixel_size, "--pixel-size")?,
        optional_length(&args.height_unit, "--height-unit")?,
    )?;
    topo.detrend(detrend_of(args.detrend));
    let stats = SurfaceStats::finite_differences(&topo)?;
    let (w, h) = topo.size_m();
    if args.json {
        let value = serde_json::json!({
            "file": args.file.display().to_string(),
            "nx": topo.nx(), "ny": topo.ny(),
            "pixel_size_x_nm": topo.dx_m * 1e9, "pixel_size_y_nm": topo.dy_m * 1e9,
            "width_um": w * 1e6, "height_um": h * 1e6,
            "detrend": topo_detrend_name(args.detrend),
            "h_rms_nm": stats.h_rms_m * 1e9,
            "h_prime_rms": stats.h_prime_rms,
            "h_double_prime_rms_per_um": stats.h_double_prime_rms_per_m * 1e-6,
        });
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!("file:        {}", args.file.display());
    println!(
        "size:        {} × {} px = {:.4} × {:.4} µm",
        topo.nx(),
        topo.ny(),
        w * 1e6,
        h * 1e6
    );
    println!(
        "pixel size:  {} × {}",
        units::format_length(topo.dx_m),
        units::format_length(topo.dy_m)
    );
    println!("detrend:     {}", topo_detrend_name(args.detrend));
    println!("h_rms:       {:.5} nm", stats.h_rms_m * 1e9);
    println!(
        "h'_rms:      {:.6} (central differences)",
        stats.h_prime_rms
    );
    println!(
        "h''_rms:     {:.6} 1/µm (5-point Laplacian)",
        stats.h_double_prime_rms_per_m * 1e-6
    );
    Ok(())
}

fn topo_detrend_name(arg: DetrendArg) -> &'static str {
    detrend_of(arg).name()
}

fn autocorr(args: AutocorrArgs) -> Result<()> {
    let request = AutocorrRequest {
        inputs: args.inputs.clone(),
        channel: args.channel,
        pixel_size_m: optional_pixel_size(&args.pixel_size, "--pixel-size")?,
        max_lag_m: optional_length(&args.max_lag, "--max-lag")?,
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let outcome = run_autocorr(&request)?;
    print_warnings(&outcome.warnings);
    let um = |m: Option<f64>| m.map_or("—".to_string(), |v| format!("{:.3}", v * 1e6));
    println!("{:>12} {:>14}  image", "ξ_1/e (µm)", "first zero (µm)");
    for c in &outcome.curves {
        println!(
            "{:>12} {:>14}  {}",
            um(c.xi_1e_m),
            um(c.first_zero_m),
            c.label
        );
    }
    print_written(outcome.written.len(), &args.out);
    Ok(())
}

fn fraction(text: &str, flag: &str) -> Result<f64> {
    let value = match text.trim().strip_suffix('%') {
        Some(pct) => pct.trim().parse::<f64>().map(|p| p / 100.0),
        None => text.trim().parse::<f64>(),
    };
    match value {
        Ok(v) if (0.0..1.0).contains(&v) => Ok(v),
        _ => bail!("{flag}: {text:?} is not a fraction in [0, 1) such as 1% or 0.01"),
    }
}

fn compare(args: CompareArgs) -> Result<()> {
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
        (None, Some(text)) => {
            units::parse_positive(text, Dimension::Length).context("--psf-fwhm")?
        }
        (None, None) => bail!("give --psf psf.json or --psf-fwhm"),
    };
    if args.upsample == 0 {
        bail!("--upsample must be at least 1");
    }
    let request = CompareRequest {
        experiment,
        channel: args.channel,
        pixel_size_m: optional_pixel_size(&args.pixel_size, "--pixel-size")?,
        simulation: args.simulation.clone(),
        settings: CompareSettings {
            psf_fwhm_m,
            dihedral: args.dihedral,
            upsample: args.upsample,
            force_tolerance: fraction(&args.force_tolerance, "--force-tolerance")?,
        },
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let outcome = comparison::run_compare(&request)?;
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
    print_written(outcome.written.len(), &args.out);
    Ok(())
}

fn newton(args: NewtonArgs) -> Result<()> {
    let request = NewtonRequest {
        reflection: args.reflection,
        fluorescence: args.contact,
        pixel_size_m: optional_pixel_size(&args.pixel_size, "--pixel-size")?,
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
        out_dir: args.out,
        command_line: std::env::args().collect(),
    };
    let outcome = newton_rings::run_newton(&request)?;
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
    for path in &outcome.written {
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn psf(args: PsfArgs) -> Result<()> {
    let request = PsfRequest {
        input: args.input.clone(),
        channel: args.channel,
        pixel_size_m: optional_pixel_size(&args.pixel_size, "--pixel-size")?,
        bead_diameter_m: optional_length(&args.bead_diameter, "--bead-diameter")?,
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let outcome = psf_job::run_psf(&request)?;
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
    let fwhm = s.sigma_m.scaled(1e9 * psf::FWHM_PER_SIGMA);
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

fn fit_searches(args: &FitArgs) -> Result<Vec<(Family, Search)>> {
    let k = units::parse_range(&args.k_range, &|t| {
        units::parse_ratio(t, Dimension::Pressure, Dimension::Length)
    })
    .context("--k-range")?;
    let p = units::parse_range(&args.hardness_range, &|t| {
        units::parse_positive(t, Dimension::Pressure)
    })
    .context("--hardness-range")?;
    Ok(vec![
        (
            Family::Hardening,
            Search {
                range: k,
                ..Search::default_for(Family::Hardening)
            },
        ),
        (
            Family::Hardness,
            Search {
                range: p,
                ..Search::default_for(Family::Hardness)
            },
        ),
    ])
}

fn sweep_micrographs(args: &FitArgs) -> Result<Option<SweepMicrographs>> {
    let Some(path) = &args.micrographs else {
        return Ok(None);
    };
    let fwhm = args
        .psf_fwhm
        .as_deref()
        .context("--micrographs needs --psf-fwhm")?;
    Ok(Some(SweepMicrographs {
        experiment: ExperimentInput::Manifest(path.clone()),
        channel: None,
        pixel_size_m: optional_pixel_size(&args.micrograph_pixel_size, "--micrograph-pixel-size")?,
        settings: CompareSettings {
            psf_fwhm_m: units::parse_positive(fwhm, Dimension::Length).context("--psf-fwhm")?,
            dihedral: false,
            upsample: 20,
            force_tolerance: 0.01,
        },
    }))
}

fn fit_imaging(args: &FitArgs) -> Result<Option<Imaging>> {
    if !args.imaged_areas {
        return Ok(None);
    }
    let (Some(fwhm), Some(pixel)) = (&args.psf_fwhm, &args.micrograph_pixel_size) else {
        bail!("--imaged-areas needs --psf-fwhm and --micrograph-pixel-size");
    };
    Ok(Some(Imaging {
        fwhm_m: units::parse_positive(fwhm, Dimension::Length).context("--psf-fwhm")?,
        pixel_m: units::parse_pixel_size(pixel).context("--micrograph-pixel-size")?,
    }))
}

fn fit_hardening(args: FitArgs) -> Result<()> {
    let families = args
        .models
        .split(',')
        .map(Family::parse)
        .collect::<std::result::Result<Vec<_>, _>>()
        .context("--models")?;
    let sweep = args
        .sweep
        .as_deref()
        .map(Sweep::parse)
        .transpose()
        .context("--sweep")?;
    if args.micrographs.is_some() && sweep.is_none() {
        bail!("--micrographs scores a --sweep; give one");
    }
    let request = FitRequest {
        experiment: args.experiment.clone(),
        topography: topography_source(&args.body.input)?,
        radius_m: optional_length(&args.body.radius, "--radius")?,
        e_star_pa: units::parse_positive(&args.body.modulus, Dimension::Pressure)
            .context("--modulus")?,
        periodic: args.periodic,
        families,
        searches: fit_searches(&args)?,
        sweep,
        micrographs: sweep_micrographs(&args)?,
        imaging: fit_imaging(&args)?,
        options: SolverOptions {
            max_iterations: args.max_iterations,
            tolerance: args.tolerance,
            monitor: None,
        },
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let outcome = fit_job::run_fit(&request)?;
    print_warnings(&outcome.warnings);
    println!("{:>10} {:>22} {:>10}", "model", "parameter", "misfit");
    for fit in &outcome.fits {
        let parameter = match (fit.family, fit.best.parameter) {
            (Family::Hardening, Some(k)) => format!(
                "k = {:.3} ± {} MPa/nm",
                k * 1e-15,
                fit.parameter_se
                    .map_or("?".into(), |s| format!("{:.3}", s * 1e-15))
            ),
            (Family::Hardness, Some(p)) => format!(
                "p_Y = {:.1} ± {} MPa",
                p * 1e-6,
                fit.parameter_se
                    .map_or("?".into(), |s| format!("{:.1}", s * 1e-6))
            ),
            _ => "—".into(),
        };
        println!(
            "{:>10} {:>22} {:>10.4}",
            fit.family.name(),
            parameter,
            fit.best.misfit
        );
    }
    if let Some(best) = outcome.best() {
        println!("best model: {}", best.family.name());
    }
    print_written(outcome.written.len(), &args.out);
    Ok(())
}

fn friction_cmd(args: FrictionArgs) -> Result<()> {
    let quantity = |text: &Option<String>, flag: &str, dim: Dimension| -> Result<Option<f64>> {
        text.as_deref()
            .map(|t| units::parse_positive(t, dim))
            .transpose()
            .with_context(|| flag.to_string())
    };
    let request = FrictionRequest {
        traces: args.traces.clone(),
        normal_force_n: quantity(&args.normal_force, "--normal-force", Dimension::Force)?,
        rotation_radius_m: quantity(
            &args.rotation_radius,
            "--rotation-radius",
            Dimension::Length,
        )?,
        areas: args.areas.clone(),
        force_tolerance: fraction(&args.force_tolerance, "--force-tolerance")?,
        slip: SlipOptions::default(),
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let outcome = friction::run_friction(&request)?;
    print_warnings(&outcome.warnings);
    println!(
        "{:>9} {:>9} {:>9} {:>12} {:>7} {:>7}  file",
        "N_mN", "F_s_mN", "F_k_mN", "slip_at", "μ_s", "μ_k"
    );
    for t in &outcome.traces {
        let slip = t.x_axis.to_column_unit(t.slip.x);
        let unit = t.x_axis.slip_column().trim_start_matches("slip_at_");
        println!(
            "{:>9.3} {:>9.4} {:>9.4} {:>12} {:>7.4} {:>7.4}  {}",
            t.normal_force_n * 1e3,
            t.slip.static_friction_n * 1e3,
            t.slip.kinetic_friction_n * 1e3,
            format!("{slip:.4} {unit}"),
            t.mu_static(),
            t.mu_kinetic(),
            t.file.display()
        );
    }
    if let Some(fit) = &outcome.shear {
        let se = fit
            .tau_se_pa
            .map_or(String::new(), |s| format!(" ± {:.2}", s * 1e-6));
        let r2 = fit.r_squared.map_or("—".into(), |r| format!("{r:.4}"));
        println!("F_s = τ·A: τ = {:.2}{se} MPa (R² {r2})", fit.tau_pa * 1e-6);
    }
    if let Some(m) = &outcome.mu_trend {
        let se = m
            .exponent_se
            .map_or(String::new(), |s| format!(" ± {s:.3}"));
        let verdict = match m.varies {
            Some(true) => "μ depends on N (not Amontons)",
            Some(false) => "μ constant within the scatter",
            None => "too few loads to judge",
        };
        println!(
            "μ_s ∝ N^m: m = {:.3}{se}, spread {:.1} %: {verdict}",
            m.exponent,
            m.relative_spread * 100.0
        );
    }
    print_written(outcome.written.len(), &args.out);
    Ok(())
}

fn hertz_cmd(args: HertzArgs) -> Result<()> {
    let request = HertzRequest {
        input: args.input.clone(),
        radius_m: units::parse_positive(&args.radius, Dimension::Length).context("--radius")?,
        loads_n: args
            .loads
            .as_deref()
            .map(units::parse_loads)
            .transpose()
            .context("--loads")?,
        out_dir: args.out.clone(),
        command_line: std::env::args().collect(),
    };
    let outcome = squeeze::run_hertz(&request)?;
    let fit = &outcome.fit;
    println!(
        "E* = {:.4} ± {:.4} GPa (R² {:.5}, {} points, fit through the origin)",
        fit.e_star_pa * 1e-9,
        fit.e_star_se_pa * 1e-9,
        fit.r_squared,
        outcome.points.len()
    );
    if let Some(free) = &outcome.offset_fit {
        println!(
            "with a free contact point: E* = {:.4} ± {:.4} GPa, offset {:.4} µm of plate displacement",
            free.e_star_pa * 1e-9,
            free.e_star_se_pa * 1e-9,
            2.0 * free.offset_m * 1e6
        );
    }
    println!("{:>10} {:>12}", "load_mN", "a_Hertz_µm");
    for (p, a) in &outcome.predicted {
        println!("{:>10.3} {:>12.4}", p * 1e3, a * 1e6);
    }
    print_written(outcome.written.len(), &args.out);
    Ok(())
}
