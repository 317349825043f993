//! `contactscope fit-hardening`: fit contact models to a measured area–load curve.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{bail, Context, Result};
use contactscope_formats::ranges::short;

use contactscope::model_fit::{Family, Imaging, ProgressHook, RampEvent, Search};
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::fit_hardening::files::run_to_folder;
use contactscope_jobs::fit_hardening::{
    self, families_from_text, parse_hardness_range, parse_k_range, BodyRequest, FitRequest,
    MeasuredInput, Sweep, SweepMicrographs,
};
use contactscope_jobs::heights::HeightInput;
use contactscope_jobs::results::fwhm_from_psf_json;
use contactscope_jobs::series::{Micrographs, SeriesSpec};
use contactscope_jobs::table::value_pm;

use super::args::{default_out, optional_pixel_size, BodyArgs, OutputFolder, SolverArgs};
use indicatif::ProgressStyle;

use super::args::Quiet;
use super::common::{command_line, print_warnings, print_written, progress_bar};

default_out!(Out, "contactscope-out/fit");

#[derive(clap::Args)]
pub struct Args {
    /// Measured areas: areas.csv of `contactscope analyze` (force_mN or force_N, area_um2; the
    /// 95 % intervals area_um2_lo/_hi and pixel_size_uncertainty_pct when it has them).
    #[arg(long, alias = "experiment")]
    areas: PathBuf,
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
    /// psf.json written by `contactscope psf` (uses fwhm_nm_mean), for Dice in the sweep and
    /// --imaged-areas.
    #[arg(long, conflicts_with = "psf_fwhm")]
    psf: Option<PathBuf>,
    /// PSF full width at half maximum (e.g. 450nm), instead of --psf.
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
    #[command(flatten)]
    solver: SolverArgs,
    #[command(flatten)]
    out: OutputFolder<Out>,
    #[command(flatten)]
    quiet: Quiet,
}

/// `hardening k = 4.02 MPa/nm, load 3/8`.
fn ramp_label(event: &RampEvent) -> String {
    let parameter = match (event.family, event.parameter) {
        (Family::Hardening, Some(k)) => format!(" k = {:.3} MPa/nm", k * 1e-15),
        (Family::Hardness, Some(p)) => format!(" p_Y = {:.1} MPa", p * 1e-6),
        _ => String::new(),
    };
    format!(
        "{}{parameter}, load {}/{}",
        event.family.name(),
        event.load,
        event.loads
    )
}

fn searches(args: &Args) -> Result<Vec<(Family, Search)>> {
    let k = parse_k_range(&args.k_range).map_err(|e| anyhow::anyhow!("--k-range: {e}"))?;
    let p = parse_hardness_range(&args.hardness_range)
        .map_err(|e| anyhow::anyhow!("--hardness-range: {e}"))?;
    Ok(fit_hardening::searches(k, p))
}

fn sweep_micrographs(args: &Args) -> Result<Option<SweepMicrographs>> {
    let Some(path) = &args.micrographs else {
        return Ok(None);
    };
    let fwhm_m = psf_fwhm_m(args)?.context("--micrographs needs --psf or --psf-fwhm")?;
    Ok(Some(SweepMicrographs {
        micrographs: Micrographs::Files(SeriesSpec {
            manifest: Some(path.clone()),
            ..SeriesSpec::default()
        }),
        pixel_size_m: optional_pixel_size(&args.micrograph_pixel_size, "--micrograph-pixel-size")?,
        psf_fwhm_m: fwhm_m,
    }))
}

/// The PSF's FWHM, m, from --psf (psf.json) or --psf-fwhm.
fn psf_fwhm_m(args: &Args) -> Result<Option<f64>> {
    Ok(match (&args.psf, &args.psf_fwhm) {
        (Some(json), _) => Some(fwhm_from_psf_json(json)?),
        (None, Some(text)) => {
            Some(units::parse_positive(text, Dimension::Length).context("--psf-fwhm")?)
        }
        (None, None) => None,
    })
}

fn imaging(args: &Args) -> Result<Option<Imaging>> {
    if !args.imaged_areas {
        return Ok(None);
    }
    let (Some(fwhm_m), Some(pixel)) = (psf_fwhm_m(args)?, &args.micrograph_pixel_size) else {
        bail!("--imaged-areas needs --psf (or --psf-fwhm) and --micrograph-pixel-size");
    };
    Ok(Some(Imaging {
        fwhm_m,
        pixel_m: units::parse_pixel_size(pixel).context("--micrograph-pixel-size")?,
    }))
}

pub fn run(args: Args) -> Result<()> {
    let families =
        families_from_text(&args.models).map_err(|e| anyhow::anyhow!("--models: {e}"))?;
    let sweep = args
        .sweep
        .as_deref()
        .map(Sweep::parse)
        .transpose()
        .context("--sweep")?;
    if args.micrographs.is_some() && sweep.is_none() {
        bail!("--micrographs scores a --sweep; give one");
    }
    let body = args.body.body()?;
    let request = FitRequest {
        families,
        searches: searches(&args)?,
        sweep,
        micrographs: sweep_micrographs(&args)?,
        ..FitRequest::new(
            MeasuredInput::File(args.areas.clone()),
            BodyRequest {
                radius_m: body.radius_m,
                periodic: args.periodic,
                tolerance: args.solver.tolerance,
                max_iterations: args.solver.max_iterations,
                imaging: imaging(&args)?,
                device: args.solver.device.into(),
                ..BodyRequest::new(HeightInput::File(body.topography), body.e_star_pa)
            },
        )
    };
    let bar = progress_bar(1, 1, args.quiet.quiet);
    bar.set_style(
        ProgressStyle::with_template(
            "[{bar:30}] {pos}/~{len} loads solved ({elapsed}, about {eta} left) {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    bar.set_length(0);
    let ramps = request.expected_ramps() as u64;
    let hook_bar = bar.clone();
    let progress = Some(ProgressHook(Arc::new(move |event: &RampEvent| {
        if hook_bar.length() == Some(0) {
            hook_bar.set_length(ramps * event.loads as u64);
        }
        if hook_bar.position() + 1 >= hook_bar.length().unwrap_or(0) {
            hook_bar.inc_length(event.loads as u64);
        }
        hook_bar.inc(1);
        hook_bar.set_message(ramp_label(event));
    })));
    let outcome = run_to_folder(&request, &args.out.out, &command_line(), progress);
    bar.finish_and_clear();
    let (outcome, written) = outcome?;
    print_warnings(&outcome.warnings);
    println!(
        "{:>10} {:>22} {:>10}  95 % interval",
        "model", "parameter", "misfit"
    );
    for fit in outcome.fits() {
        let parameter = match (fit.family, fit.best.parameter) {
            (Family::Hardening, Some(k)) => match fit.parameter_se {
                Some(s) => format!("k = {} MPa/nm", value_pm(k * 1e-15, s * 1e-15)),
                None if fit.undetermined => "k undetermined".into(),
                None => format!("k = {:.3} MPa/nm (no standard error)", k * 1e-15),
            },
            (Family::Hardness, Some(p)) => match fit.parameter_se {
                Some(s) => format!("p_Y = {} MPa", value_pm(p * 1e-6, s * 1e-6)),
                None if fit.undetermined => "p_Y undetermined".into(),
                None => format!("p_Y = {:.1} MPa (no standard error)", p * 1e-6),
            },
            _ => "—".into(),
        };
        let interval = match (fit.family, fit.parameter_ci95) {
            (Family::Hardening, Some((lo, hi))) => {
                format!("{}…{} MPa/nm", short(lo * 1e-15), short(hi * 1e-15))
            }
            (Family::Hardness, Some((lo, hi))) => {
                format!("{}…{} MPa", short(lo * 1e-6), short(hi * 1e-6))
            }
            _ => "—".into(),
        };
        println!(
            "{:>10} {:>22} {:>10.4}  {interval}",
            fit.family.name(),
            parameter,
            fit.best.misfit
        );
    }
    if let Some(best) = outcome.best_model {
        println!("best model: {best}");
    }
    print_written(written.len(), &args.out.out);
    Ok(())
}
