//! `contactscope friction`: static and kinetic friction from rheometer traces; τ of F = τ·A.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};

use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::friction::files::run_to_folder;
use contactscope_jobs::friction::FrictionRequest;
use contactscope_jobs::table::value_pm_or;

use super::args::{default_out, fraction, load_forces, Forces, OutputFolder};
use super::common::{command_line, print_warnings, print_written};

default_out!(Out, "contactscope-out/friction");

#[derive(clap::Args)]
pub struct Args {
    /// Trace CSVs: time_s | displacement_um | angle_rad, friction_mN | friction_N | torque_mNm |
    /// torque_Nm, optional normal_force_mN | normal_force_N.
    #[arg(required = true)]
    traces: Vec<PathBuf>,
    /// Normal force for traces without a normal-force column (one value, e.g. 40mN).
    #[arg(long, alias = "normal-force", value_parser = load_forces)]
    forces: Option<Forces>,
    /// Rotation radius of the sphere on the rheometer plate, turns torque into force (e.g. 5mm).
    #[arg(long)]
    rotation_radius: Option<String>,
    /// areas.csv from `contactscope analyze` (force_mN, area_um2), for F = τ·A.
    #[arg(long)]
    areas: Option<PathBuf>,
    /// Largest relative difference between a trace's normal force and an area row (e.g. 2%).
    #[arg(long, default_value = "2%")]
    force_tolerance: String,
    #[command(flatten)]
    out: OutputFolder<Out>,
}

pub fn run(args: Args) -> Result<()> {
    let quantity = |text: &Option<String>, flag: &str, dim: Dimension| -> Result<Option<f64>> {
        text.as_deref()
            .map(|t| units::parse_positive(t, dim))
            .transpose()
            .with_context(|| flag.to_string())
    };
    let request = FrictionRequest {
        normal_force_n: match args.forces.as_ref().map(|f| f.0.as_slice()) {
            None => None,
            Some([one]) => Some(*one),
            Some(many) => bail!(
                "--forces: give one normal force for the traces without a normal-force column \
                 (got {})",
                many.len()
            ),
        },
        rotation_radius_m: quantity(
            &args.rotation_radius,
            "--rotation-radius",
            Dimension::Length,
        )?,
        areas: args.areas.clone(),
        force_tolerance: fraction(&args.force_tolerance, "--force-tolerance")?,
        ..FrictionRequest::new(args.traces.clone())
    };
    let (outcome, written) = run_to_folder(&request, &args.out.out, &command_line())?;
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
        let tau = value_pm_or(fit.tau_pa * 1e-6, fit.tau_se_pa.map(|s| s * 1e-6), 2);
        let r2 = fit.r_squared.map_or("—".into(), |r| format!("{r:.4}"));
        println!("F_s = τ·A: τ = {tau} MPa (R² {r2})");
    }
    if let Some(m) = &outcome.mu_trend {
        let m_exp = value_pm_or(m.exponent, m.exponent_se, 3);
        let verdict = match m.varies {
            Some(true) => "μ depends on N (not Amontons)",
            Some(false) => "μ constant within the scatter",
            None => "too few loads to judge",
        };
        println!(
            "μ_s ∝ N^m: m = {m_exp}, spread {:.1} %: {verdict}",
            m.relative_spread * 100.0
        );
    }
    print_written(written.len(), &args.out.out);
    Ok(())
}
