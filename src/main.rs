//! The `contactscope` command line: parse arguments, call the library, print. No analysis here.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use contactscope::analysis::{self, AnalysisOptions, HertzParams, Pass};
use contactscope::pipeline::{self, AnalyzeRequest};
use contactscope::stack::series::{self, Series};
use contactscope::stack::tiff::TiffReader;
use contactscope::stack::write::Compression;
use contactscope::synth::{self, Layout, SynthParams};
use contactscope::threshold::Method;
use contactscope::units::{self, Dimension};

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
    #[arg(long, default_value_t = analysis::DEFAULT_MEMORY_BUDGET >> 20)]
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
    /// Output folder.
    #[arg(long, default_value = "contactscope-out/demo")]
    out: PathBuf,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Analyze(args) => analyze(args),
        Command::Threshold(args) => threshold(args),
        Command::Info(args) => info(args),
        Command::SynthSeries(args) => synth_series(args),
        Command::Demo(args) => demo(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("contactscope: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn progress_bar(images: usize, quiet: bool) -> ProgressBar {
    let visible = !quiet && images > 3 && std::io::stderr().is_terminal();
    let bar = ProgressBar::with_draw_target(
        Some(images as u64),
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
    let options = AnalysisOptions {
        method: Method::parse(&args.threshold)?,
        pixel_size_override: args
            .pixel_size
            .as_deref()
            .map(units::parse_pixel_size)
            .transpose()
            .context("--pixel-size")?,
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
    let bar = progress_bar(request.series.images.len(), quiet);
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
        contactscope::report::AreaUnit::SquareMicrometre => "µm²",
        contactscope::report::AreaUnit::Pixel => "px",
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
    let (t, pixels, warnings) = analysis::global_threshold(&series, &|_, _, _| {})?;
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
fn bundled_series() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/synthetic-series")
}

fn demo(args: DemoArgs) -> Result<()> {
    let dir = bundled_series();
    let manifest = dir.join("manifest.csv");
    if !manifest.exists() {
        bail!(
            "bundled series not found at {}; regenerate it with `contactscope synth-series --out {}`",
            dir.display(),
            dir.display()
        );
    }
    println!(
        "demo: analysing the bundled synthetic load series {}",
        dir.display()
    );
    let request = AnalyzeRequest {
        series: series::from_manifest(&manifest, None)?,
        options: AnalysisOptions {
            hertz: Some(HertzParams {
                radius_m: 290e-6,
                modulus_pa: 3.7e9,
            }),
            ..AnalysisOptions::default()
        },
        out_dir: args.out.clone(),
        overlays: true,
        save_masks: false,
        command_line: std::env::args().collect(),
    };
    let outcome = run_with_progress(&request, false)?;
    print_outcome(&outcome, &args.out);
    let truth = contactscope::synth::read_truth(&dir.join("truth.csv"))?;
    println!("\nground truth of the generator (truth.csv) against the measurement:");
    println!(
        "{:>10} {:>14} {:>14} {:>9}",
        "force_mN", "true_area_µm²", "measured_µm²", "error_%"
    );
    for (row, true_area) in outcome.report.rows.iter().zip(truth) {
        println!(
            "{:>10.3} {:>14.2} {:>14.2} {:>9.2}",
            row.force_mn.unwrap_or(f64::NAN),
            true_area,
            row.area,
            (row.area / true_area - 1.0) * 100.0
        );
    }
    println!("\ntable: {}", args.out.join("areas.csv").display());
    println!("plot:  {}", args.out.join("area_vs_load.png").display());
    Ok(())
}
