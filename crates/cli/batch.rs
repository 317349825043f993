//! `contactscope batch`: a lab's archive in one command (`contactscope_jobs::batch`): a
//! samplesheet or a folder walk → one folder per series as `analyze` writes it, the tables
//! `images` and `series` (Parquet and CSV), `batch.json`, the QC page. Re-runs redo only what
//! changed. Exit status 0 when every series succeeded, 3 when some failed (their rows say why;
//! the tables and page are written), 1 when the batch could not run at all.

use std::path::PathBuf;

use anyhow::{bail, Result};
use indicatif::ProgressStyle;

use contactscope::solver::gpu::DeviceChoice;
use contactscope_jobs::batch::{
    self, BatchRequest, Opt, OutputSettings, Rerun, SeriesOptions, SheetSource, WalkSpec,
};
use contactscope_jobs::series::DEFAULT_MEMORY_BUDGET;

use super::args::{default_out, frame_forces, DeviceArg, Forces, Quiet};
use super::common::{command_line, print_warnings, progress_bar};

default_out!(Out, "contactscope-out/batch");

/// Options every series takes unless its samplesheet row gives its own (the columns' names,
/// as flags).
#[derive(clap::Args, Clone, Debug, Default)]
struct Defaults {
    /// Forces of every series not from a manifest (column forces): 4,10,40mN or 1mN..100mN:8.
    #[arg(long, value_parser = frame_forces)]
    forces: Option<Forces>,
    /// Series of CZI/LIF files (column series).
    #[arg(long)]
    series: Option<String>,
    /// Channel (column channel).
    #[arg(long)]
    channel: Option<String>,
    /// Focal plane (column z).
    #[arg(long)]
    z: Option<String>,
    /// Time point (column t).
    #[arg(long)]
    t: Option<String>,
    /// Indices along other axes, e.g. "H=0;S=1" (column axis).
    #[arg(long)]
    axis: Option<String>,
    /// The axis of CZI, ND2, LIF or OME-Zarr files whose planes are the loads: t, z or series (column
    /// load_axis).
    #[arg(long)]
    load_axis: Option<String>,
    /// otsu, per-image or a grey value (column threshold; default otsu).
    #[arg(long)]
    threshold: Option<String>,
    /// Pixel size for the files that state none, e.g. 200nm (a file's own is kept; a row's
    /// pixel_size column replaces it); flagged pixel_size_default where used.
    #[arg(long)]
    pixel_size: Option<String>,
    /// Relative uncertainty of the pixel size (given or the files'), e.g. 1% (column
    /// pixel_size_uncertainty): widens the area and fit intervals.
    #[arg(long)]
    pixel_size_uncertainty: Option<String>,
    /// psf.json written by `contactscope psf` (column psf; relative to the samplesheet's
    /// folder): the PSF the area intervals take.
    #[arg(long, conflicts_with = "psf_fwhm")]
    psf: Option<String>,
    /// The PSF's full width at half maximum for the area intervals, e.g. 450nm (column
    /// psf_fwhm; without it or --psf a 1 µm PSF, wider than a confocal microscope's, is taken).
    #[arg(long)]
    psf_fwhm: Option<String>,
    /// Sphere radius, e.g. 290um (column radius): Hertz columns with --modulus; the fit's sphere.
    #[arg(long)]
    radius: Option<String>,
    /// Contact modulus E*, e.g. 3.7GPa (column modulus).
    #[arg(long)]
    modulus: Option<String>,
    /// Height map of the sphere for fit-hardening (column topography).
    #[arg(long)]
    topography: Option<String>,
    /// Pixel size of the height map (column topography_pixel_size).
    #[arg(long)]
    topography_pixel_size: Option<String>,
    /// Height unit of the height map (column height_unit).
    #[arg(long)]
    height_unit: Option<String>,
    /// Detrending of the height map: none, mean, plane (column detrend; default plane).
    #[arg(long)]
    detrend: Option<String>,
    /// Channel of a multi-channel height map, by name (column topography_channel).
    #[arg(long)]
    topography_channel: Option<String>,
    /// Fill the height map's invalid points: mean or nearest (column fill_invalid).
    #[arg(long)]
    fill_invalid: Option<String>,
    /// Models fitted or scored (column models; default gt,elastic,hardness,hardening).
    #[arg(long)]
    models: Option<String>,
    /// Search range of k (column k_range; default 0.1..100MPa/nm).
    #[arg(long)]
    k_range: Option<String>,
    /// Search range of p_Y (column hardness_range; default 10MPa..10GPa).
    #[arg(long)]
    hardness_range: Option<String>,
}

impl Defaults {
    fn options(&self) -> SeriesOptions {
        let forces = self.forces.as_ref().map(|f| f.1.clone());
        let pairs = [
            (Opt::Forces, &forces),
            (Opt::Series, &self.series),
            (Opt::Channel, &self.channel),
            (Opt::Z, &self.z),
            (Opt::T, &self.t),
            (Opt::Axis, &self.axis),
            (Opt::LoadAxis, &self.load_axis),
            (Opt::Threshold, &self.threshold),
            (Opt::PixelSize, &self.pixel_size),
            (Opt::PixelSizeUncertainty, &self.pixel_size_uncertainty),
            (Opt::PsfFwhm, &self.psf_fwhm),
            (Opt::Psf, &self.psf),
            (Opt::Radius, &self.radius),
            (Opt::Modulus, &self.modulus),
            (Opt::Topography, &self.topography),
            (Opt::TopographyPixelSize, &self.topography_pixel_size),
            (Opt::HeightUnit, &self.height_unit),
            (Opt::Detrend, &self.detrend),
            (Opt::TopographyChannel, &self.topography_channel),
            (Opt::FillInvalid, &self.fill_invalid),
            (Opt::Models, &self.models),
            (Opt::KRange, &self.k_range),
            (Opt::HardnessRange, &self.hardness_range),
        ];
        SeriesOptions(
            pairs
                .into_iter()
                .filter_map(|(o, v)| v.as_ref().map(|v| (o, v.trim().to_string())))
                .collect(),
        )
    }
}

#[derive(clap::Args)]
pub struct Args {
    /// An archive folder to walk: every folder holding manifest.csv is a series, and every file
    /// matching --pattern. Not with --samplesheet.
    #[arg(conflicts_with = "samplesheet")]
    archive: Option<PathBuf>,
    /// A samplesheet CSV: id, input, per-series options (forces, channel, load_axis,
    /// pixel_size, threshold, topography, modulus, …) and any metadata columns.
    #[arg(long)]
    samplesheet: Option<PathBuf>,
    /// File names that are series on their own in a walk (glob, repeatable; default *.czi,
    /// *.nd2, *.lif).
    #[arg(long = "pattern", value_name = "GLOB")]
    patterns: Vec<String>,
    /// In a walk, folders holding TIFF files (without manifest.csv) are series too.
    #[arg(long)]
    tiff_folders: bool,
    #[command(flatten)]
    defaults: Defaults,
    /// Output folder: series/, fit/, the tables, batch.json, index.html.
    #[arg(long, default_value = Out::PATH)]
    out: PathBuf,
    /// What to run again although unchanged: changed (only new or changed series), failed
    /// (also failed ones), all.
    #[arg(long, default_value = "changed", value_parser = ["changed", "failed", "all"])]
    rerun: String,
    /// Metadata column that colours the QC page's combined plot (default: the first).
    #[arg(long)]
    color_by: Option<String>,
    /// Write one overlay PNG per image into each series' folder (analyze --overlays).
    #[arg(long)]
    overlays: bool,
    /// Write the contact masks into each series' folder (analyze --save-masks).
    #[arg(long)]
    save_masks: bool,
    /// Decoded images of compressed files kept between the two passes, MiB (analyze
    /// --memory-mib).
    #[arg(long, default_value_t = DEFAULT_MEMORY_BUDGET >> 20)]
    memory_mib: usize,
    /// Where fit-hardening's contact solver runs: cpu, cuda or auto.
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    device: DeviceArg,
    #[command(flatten)]
    quiet: Quiet,
}

use super::args::DefaultOut;

/// Run the batch; `Ok(false)` when some series failed (exit status 3).
pub fn run(args: Args) -> Result<bool> {
    let source = match (&args.archive, &args.samplesheet) {
        (Some(root), None) => SheetSource::Walk(WalkSpec {
            root: root.clone(),
            patterns: args.patterns.clone(),
            tiff_folders: args.tiff_folders,
        }),
        (None, Some(sheet)) => {
            if !args.patterns.is_empty() || args.tiff_folders {
                bail!("--pattern and --tiff-folders choose series in a walk; with --samplesheet the sheet lists them");
            }
            SheetSource::File(sheet.clone())
        }
        _ => bail!("give an archive folder to walk, or --samplesheet SHEET.csv"),
    };
    let device: DeviceChoice = args.device.into();
    let request = BatchRequest {
        defaults: args.defaults.options(),
        settings: OutputSettings {
            overlays: args.overlays,
            masks: args.save_masks,
            memory_mib: args.memory_mib,
            device,
        },
        rerun: Rerun::parse(&args.rerun).unwrap_or(Rerun::Changed),
        color_by: args.color_by.clone(),
        program: std::env::args()
            .next()
            .unwrap_or_else(|| "contactscope".into()),
        command_line: command_line(),
        ..BatchRequest::new(source, args.out.clone())
    };
    let plan = batch::plan(request)?;
    let todo = plan.to_run().count();
    let bar = progress_bar(todo, 1, args.quiet.quiet);
    bar.set_style(
        ProgressStyle::with_template(
            "[{bar:40}] {pos}/{len} series ({elapsed}, about {eta} left) {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    if !args.quiet.quiet {
        eprintln!(
            "batch: {} series, {} to analyse, {} unchanged",
            plan.tasks.len(),
            todo,
            plan.tasks.len() - todo
        );
    }
    let quiet = args.quiet.quiet;
    let report = |record: &batch::Record, _: usize, _: usize| {
        if let (Some(e), false) = (&record.error, quiet) {
            bar.suspend(|| eprintln!("contactscope: series {} failed: {e}", record.id));
        }
        bar.set_message(record.id.clone());
        bar.inc(1);
    };
    let fresh = batch::run_planned(&plan, &report);
    bar.finish_and_clear();
    let outcome = batch::finish(plan, fresh)?;
    print_warnings(&outcome.warnings);
    println!(
        "batch: {} series: {} ok, {} failed; {} analysed, {} reused (unchanged); {} images",
        outcome.series,
        outcome.ok,
        outcome.failed,
        outcome.analysed,
        outcome.reused,
        outcome.image_rows
    );
    for (id, error) in &outcome.failures {
        println!("  failed: {id}: {error}");
    }
    println!("wrote to {}:", args.out.display());
    for path in &outcome.written {
        println!("  {}", path.display());
    }
    println!("  and per series: series/ID/ (as analyze writes it), records/ID.json, qc/ID.png");
    Ok(outcome.failed == 0)
}
