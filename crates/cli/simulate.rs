//! `contactscope simulate`: contact of a rough topography under a load sweep.

use anyhow::{bail, Context, Result};
use clap::ValueEnum;
use indicatif::ProgressStyle;

use contactscope::solver::simulate::Model;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::heights::HeightInput;
use contactscope_jobs::simulate::files::{run_to_folder, Export};
use contactscope_jobs::simulate::{MapChoice, ModelChoice, SimulateRequest};

use super::args::{default_out, load_forces, BodyArgs, Forces, OutputFolder, Quiet, SolverArgs};
use super::common::{command_line, print_warnings, print_written, progress_bar, Finished};

default_out!(Out, "contactscope-out/simulate");

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

/// `--maps`: which per-load TIFF maps to write.
#[derive(Clone, Copy, ValueEnum)]
enum MapsArg {
    /// No maps: areas.csv, summary.json and the plot only.
    None,
    /// The contact map of each load only.
    Contact,
    /// Contact, pressure, gap, plastic displacement and deformed surface of each load.
    All,
}

/// `--export`: another tool's layout.
#[derive(Clone, Copy, ValueEnum)]
enum ExportArg {
    /// contact.engineering's contact-mechanics download (contact_mechanics.zip).
    ContactEngineering,
    /// The deformed surfaces as a surface container (deformed_surfaces.zip).
    SurfaceContainer,
}

#[derive(clap::Args)]
pub struct Args {
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
    /// Normal forces of the ramp: 4,10,40mN or 4mN..400mN:12 (log-spaced).
    #[arg(long, alias = "loads", value_parser = load_forces)]
    forces: Forces,
    #[command(flatten)]
    solver: SolverArgs,
    /// Per-load float32 TIFF maps to write: all, contact (the contact map only) or none.
    #[arg(long, value_enum, default_value = "all")]
    maps: MapsArg,
    /// Also write the results in other tools' layouts (comma-separated): contact-engineering
    /// writes contact_mechanics.zip as contact.engineering's contact-mechanics download
    /// (plot.csv, result-step-N.nc, info.txt); surface-container writes deformed_surfaces.zip,
    /// the plastically deformed surface and plastic displacement of every load as a surface
    /// container (docs/outputs.md).
    #[arg(long, value_enum, value_delimiter = ',')]
    export: Vec<ExportArg>,
    #[command(flatten)]
    out: OutputFolder<Out>,
    #[command(flatten)]
    quiet: Quiet,
}

fn model_of(args: &Args) -> Result<ModelChoice> {
    let pressure = |t: &str, flag: &str| -> Result<f64> {
        let p = units::parse_positive(t, Dimension::Pressure).with_context(|| flag.to_string())?;
        Ok(contactscope_formats::ranges::Quantity::Hardness.check_text(p, flag)?)
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
            .context("--hardening")
            .and_then(|k| {
                Ok(contactscope_formats::ranges::Quantity::Hardening
                    .check_text(k, "--hardening")?)
            })?,
            initial_pa: units::parse_quantity(&args.initial_hardness, Dimension::Pressure)
                .context("--initial-hardness")?,
        }),
    })
}

pub fn run(args: Args) -> Result<Finished> {
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
    let body = args.body.body()?;
    let mut request = SimulateRequest::new(
        HeightInput::File(body.topography),
        body.e_star_pa,
        model_of(&args)?,
        args.forces.0.clone(),
    );
    request.radius_m = body.radius_m;
    request.periodic = args.periodic;
    request.tolerance = args.solver.tolerance;
    request.max_iterations = args.solver.max_iterations;
    request.device = args.solver.device.into();
    request.maps = match args.maps {
        MapsArg::None => MapChoice::None,
        MapsArg::Contact => MapChoice::Contact,
        MapsArg::All => MapChoice::All,
    };
    let bar = progress_bar(request.loads_n.len(), 1, args.quiet.quiet);
    bar.set_style(
        ProgressStyle::with_template(
            "[{bar:30}] {pos}/{len} loads ({elapsed}, about {eta} left) {msg}",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let monitor = |iteration: usize, residual: f64| {
        bar.set_message(format!("CG iteration {iteration}, residual {residual:.2e}"));
    };
    let outcome = run_to_folder(
        &request,
        &args.out.out,
        &command_line(),
        &|done, _| bar.set_position(done as u64),
        Some(&monitor),
        &args
            .export
            .iter()
            .map(|e| match e {
                ExportArg::ContactEngineering => Export::ContactEngineering,
                ExportArg::SurfaceContainer => Export::SurfaceContainer,
            })
            .collect::<Vec<_>>(),
    );
    bar.finish_and_clear();
    let (outcome, written) = outcome?;
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
        let p_mean = if l.mean_pressure_pa.is_finite() {
            format!("{:.2}", l.mean_pressure_pa * 1e-6)
        } else {
            "—".to_string()
        };
        let note = match l.load_point().excluded {
            Some(why) => format!("  ({}: left out of the fit)", why.legend()),
            None => String::new(),
        };
        println!(
            "{:>10.4} {:>12.4} {:>9.5} {:>10} {:>8} {:>6}{note}",
            l.force_n * 1e3,
            l.area_m2 * 1e12,
            l.contact_fraction,
            p_mean,
            l.patches,
            l.iterations
        );
    }
    if let Some(fit) = outcome.power_law {
        let beta = contactscope_jobs::table::value_pm_or(fit.exponent, fit.exponent_se, 3);
        let r2 = fit
            .r_squared
            .map_or("— (fewer than 3 distinct forces)".into(), |r| {
                format!("{r:.4}")
            });
        println!(
            "power law over {} loads: A ∝ N^β, β = {beta}, R² = {r2}",
            fit.points
        );
    }
    print_written(written.len(), &args.out.out);
    Ok(Finished::unless_nothing_valid(outcome.nothing_valid()))
}
