//! `contactscope analyze`: a load series → one global Otsu threshold, contact area per image,
//! fits, plots.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use contactscope::analysis::Pass;
use contactscope::threshold::Method;
use contactscope_formats::ranges::short;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::analyze::files::{run_to_folder, ImageOutputs};
use contactscope_jobs::analyze::{AnalyzeOutcome, AnalyzeRequest, AreaUnit, HertzParams};
use contactscope_jobs::series::{Micrographs, SeriesSpec, DEFAULT_MEMORY_BUDGET};

use super::args::{
    default_out, frame_forces, Forces, LoadAxisArg, OutputFolder, PixelSizeArg, Quiet,
    SelectionArgs,
};
use super::common::{command_line, progress_bar, Finished};

default_out!(Out, "contactscope-out/analyze");

#[derive(clap::Args)]
pub struct Args {
    /// TIFF, CZI, ND2, LIF or OME-Zarr files, or directories of them (natural sort order). Not with
    /// --manifest.
    inputs: Vec<PathBuf>,
    /// Manifest CSV with columns file, [page], force_mN (or force_N), [friction_mN]; paths
    /// relative to the CSV. A folder holding manifest.csv (also as the only input) is read as it.
    #[arg(long, conflicts_with_all = ["inputs", "forces"])]
    manifest: Option<PathBuf>,
    /// Normal forces, one per image: 4,10,20,40mN, 0,4,10mN (0: a reference frame, left out of
    /// the fits) or 1mN..100mN:12 (log-spaced). Without forces: per-image areas, no fits.
    #[arg(long, value_parser = frame_forces)]
    forces: Option<Forces>,
    #[command(flatten)]
    select: SelectionArgs,
    /// Axis of a CZI, ND2, LIF or OME-Zarr file whose planes are the loads, in order.
    #[arg(long, value_enum)]
    load_axis: Option<LoadAxisArg>,
    /// otsu (one threshold for the series), per-image, or a number (contact is value > t).
    #[arg(long, default_value = "otsu")]
    threshold: String,
    #[command(flatten)]
    pixel_size: PixelSizeArg,
    /// Pixel size for files whose metadata states none (a stated one is kept): 200nm, or
    /// 200x210nm.
    #[arg(long, conflicts_with = "pixel_size")]
    pixel_size_default: Option<String>,
    /// Relative uncertainty of the pixel size (given or the files'), as bounds: 1% or 0.01;
    /// widens the area and fit intervals (also written --pixel-size 200nm±1%).
    #[arg(long)]
    pixel_size_uncertainty: Option<String>,
    /// psf.json written by `contactscope psf` (uses fwhm_nm_mean): the PSF the area intervals
    /// take (without it or --psf-fwhm, a 1 µm FWHM, wider than a confocal microscope's).
    #[arg(long, conflicts_with = "psf_fwhm")]
    psf: Option<PathBuf>,
    /// PSF full width at half maximum for the area intervals (e.g. 450nm), instead of --psf.
    #[arg(long)]
    psf_fwhm: Option<String>,
    /// Sphere radius for Hertz columns, e.g. 290um (needs --modulus).
    #[arg(long, requires = "modulus")]
    radius: Option<String>,
    /// Contact modulus E* for Hertz columns, e.g. 3.7GPa (needs --radius).
    #[arg(long, requires = "radius")]
    modulus: Option<String>,
    #[command(flatten)]
    out: OutputFolder<Out>,
    /// Write one PNG per image with contact edges in green.
    #[arg(long)]
    overlays: bool,
    /// Write the contact masks as TIFF.
    #[arg(long)]
    save_masks: bool,
    /// Also write the contact masks (NGFF label image `labels/contact`) and the per-image table
    /// (`tables/contact_areas`) into an OME-Zarr store: a new one (the analysed planes copied
    /// beside them), or the one OME-Zarr store analysed (its images untouched).
    #[arg(long, value_name = "STORE")]
    zarr_out: Option<PathBuf>,
    /// Decoded images of compressed files kept in memory between the two passes, in MiB.
    #[arg(long, default_value_t = DEFAULT_MEMORY_BUDGET >> 20)]
    memory_mib: usize,
    #[command(flatten)]
    quiet: Quiet,
}

fn micrographs(args: &Args) -> Result<Micrographs> {
    if args.manifest.is_none() && args.inputs.is_empty() {
        bail!("give image files or directories, or --manifest");
    }
    let forces_n = args.forces.as_ref().map(|f| f.0.clone());
    Ok(Micrographs::Files(SeriesSpec {
        inputs: args.inputs.clone(),
        manifest: args.manifest.clone(),
        selection: args.select.selection(),
        load_axis: args.load_axis.map(LoadAxisArg::axis),
        forces_n,
    }))
}

pub fn run(args: Args) -> Result<Finished> {
    let hertz = match (&args.radius, &args.modulus) {
        (Some(r), Some(e)) => Some(HertzParams {
            radius_m: units::parse_positive(r, Dimension::Length).context("--radius")?,
            modulus_pa: units::parse_positive(e, Dimension::Pressure).context("--modulus")?,
        }),
        _ => None,
    };
    let (pixel_size_m, pixel_size_uncertainty) = args
        .pixel_size
        .metres_and_uncertainty(&args.pixel_size_uncertainty)?;
    let psf_fwhm_m = match (&args.psf, &args.psf_fwhm) {
        (Some(json), _) => Some(contactscope_jobs::results::fwhm_from_psf_json(json)?),
        (None, Some(text)) => {
            Some(units::parse_positive(text, Dimension::Length).context("--psf-fwhm")?)
        }
        (None, None) => None,
    };
    let request = AnalyzeRequest {
        method: Method::parse(&args.threshold)?,
        psf_fwhm_m,
        pixel_size_m,
        pixel_size_default_m: crate::args::optional_pixel_size(
            &args.pixel_size_default,
            "--pixel-size-default",
        )?,
        pixel_size_uncertainty,
        hertz,
        memory_budget: args.memory_mib << 20,
        ..AnalyzeRequest::new(micrographs(&args)?)
    };
    let images = ImageOutputs {
        overlays: args.overlays,
        masks: args.save_masks,
        zarr: args.zarr_out.clone(),
    };
    let bar = progress_bar(
        match &request.micrographs {
            Micrographs::Files(spec) => spec.forces_n.as_ref().map_or(0, Vec::len).max(4),
            Micrographs::Memory(m) => m.planes.len(),
        },
        4,
        args.quiet.quiet,
    );
    let progress = |pass: Pass, done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_message(match pass {
            Pass::Histogram => "histogram",
            Pass::Measure => "measure",
        });
        bar.set_position(done as u64);
    };
    let outcome = run_to_folder(&request, &args.out.out, &command_line(), images, &progress);
    bar.finish_and_clear();
    let (outcome, written) = outcome?;
    print_outcome(&outcome, &written, &args.out.out);
    Ok(Finished::unless_nothing_valid(outcome.nothing_valid()))
}

fn print_outcome(outcome: &AnalyzeOutcome, written: &[PathBuf], out: &Path) {
    let a = &outcome.analysis;
    let r = &outcome.rows;
    super::common::print_warnings(&a.warnings);
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
            "pixel size: {:.5} × {:.5} µm{} from {}",
            p.x_m * 1e6,
            p.y_m * 1e6,
            match outcome.area_interval.pixel_size_uncertainty {
                u if u > 0.0 => format!(" ± {} %", short(u * 100.0)),
                _ => String::new(),
            },
            p.source.describe()
        ),
        None => println!("pixel size: unknown, areas in pixels"),
    }
    println!(
        "images: {} in load order by {}",
        outcome.inputs.images, outcome.inputs.order
    );
    let unit = match r.unit {
        AreaUnit::SquareMicrometre => "µm²",
        AreaUnit::Pixel => "px",
    };
    println!(
        "{:>10} {:>12} {:>12} {:>19} {:>8} {:>10}  image",
        "force_mN",
        format!("area_{unit}"),
        "corrected",
        "95 % interval",
        "patches",
        "p_MPa"
    );
    for row in &r.rows {
        let f = row.force_mn.map_or("-".into(), |f| format!("{f:.3}"));
        let p = row
            .mean_pressure_mpa
            .map_or("-".into(), |p| format!("{p:.1}"));
        let name = Path::new(&row.image)
            .file_name()
            .map_or(row.image.clone(), |n| n.to_string_lossy().into_owned());
        let interval = format!("{:.2}…{:.2}", row.area_lo, row.area_hi);
        // No corrected area where the interval is the edge band's.
        let corrected = if row.area_corrected.is_finite() {
            format!("{:.2}", row.area_corrected)
        } else {
            "-".into()
        };
        println!(
            "{f:>10} {:>12.2} {corrected:>12} {interval:>19} {:>8} {p:>10}  {name} p{}",
            row.area, row.patches, row.page
        );
    }
    if let Some(fit) = outcome.fits.power_law {
        let beta = contactscope_jobs::table::value_pm_or(fit.exponent, fit.exponent_se, 3);
        let r2 = fit
            .r_squared
            .map_or("— (fewer than 3 distinct forces)".into(), |r| {
                format!("{r:.4}")
            });
        let of = match outcome.fits.power_law_corrected {
            Some(_) => "true β",
            None => "β (edge band)",
        };
        let ci = outcome.fits.intervals.as_ref().map_or(String::new(), |i| {
            format!("; {of} in {:.3}…{:.3} (95 %)", i.exponent.0, i.exponent.1)
        });
        let corrected = outcome.fits.power_law_corrected.map_or(String::new(), |c| {
            format!("; corrected β = {:.3}", c.exponent)
        });
        println!("power law: A ∝ N^β, β = {beta} (contact pixels), R² = {r2}{corrected}{ci}");
    }
    if let Some((p, _)) = outcome.fits.proportional_mpa {
        let ci = outcome
            .fits
            .intervals
            .as_ref()
            .and_then(|i| i.proportional_slope)
            .filter(|(lo, _)| *lo > 0.0)
            .map_or(String::new(), |(lo, hi)| {
                format!(" (95 % interval {:.1}…{:.1} MPa)", 1e3 / hi, 1e3 / lo)
            });
        let corrected = outcome
            .fits
            .proportional_corrected_mpa
            .map_or(String::new(), |c| format!("; corrected p = {c:.1} MPa"));
        println!("proportional fit: A = N/p, p = {p:.1} MPa (contact pixels){corrected}{ci}");
    }
    println!("wrote {} files to {}:", written.len(), out.display());
    for path in written.iter().filter(|p| !is_per_image(p)) {
        println!("  {}", path.display());
    }
    let per_image = written.iter().filter(|p| is_per_image(p)).count();
    if per_image > 0 {
        println!("  … and {per_image} overlay/mask files");
    }
}

fn is_per_image(path: &Path) -> bool {
    path.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.starts_with("overlay_") || n.starts_with("mask_"))
}
