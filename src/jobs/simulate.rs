//! The `simulate` job end to end: read and prepare the topography, run the load sweep with the
//! chosen model, and write the table, the maps, the summary and the plot through a staging
//! folder (nothing appears on failure). The command line only builds a [`SimulateRequest`].

use std::path::PathBuf;

use serde_json::{json, Value};

use crate::analysis::fit::fit_power_law;
use crate::error::{Error, Result};
use crate::io::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::io::staging::Staging;
use crate::io::tiff::write::encode_f32_stack;
use crate::io::topography::TopographySource;
use crate::measure::patches::count_patches;
use crate::surface::stats::SurfaceStats;
use crate::surface::Topography;

use crate::solver::cg::{Monitor, SolverOptions};
use crate::solver::gt::{gt_bearing_area, gt_profile, GtParams};
use crate::solver::halfspace::Boundary;
use crate::solver::simulate::{separation, sweep_each, LoadStep, Model, Setup};

/// Which model to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelChoice {
    /// One of the half-space models.
    HalfSpace(Model),
    /// Greenwood–Tripp with the bearing-area map (needs the sphere radius).
    GreenwoodTripp,
}

impl ModelChoice {
    /// Name used in outputs.
    pub fn name(&self) -> &'static str {
        match self {
            ModelChoice::HalfSpace(m) => m.name(),
            ModelChoice::GreenwoodTripp => "gt",
        }
    }
}

/// Everything `simulate` needs, already validated by the caller.
#[derive(Debug, Clone)]
pub struct SimulateRequest {
    /// Height map, read and detrended as stated.
    pub topography: TopographySource,
    /// Sphere radius to add to a flattened map (and the GT sphere), m.
    pub radius_m: Option<f64>,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// The model.
    pub model: ModelChoice,
    /// Periodic boundaries (free otherwise).
    pub periodic: bool,
    /// Normal forces, N, in order.
    pub loads_n: Vec<f64>,
    /// Solver limits (the progress monitor is passed to [`run_simulate`] separately).
    pub options: SolverOptions<'static>,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the summary.
    pub command_line: Vec<String>,
}

/// One row of the simulated area–load table, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct SimulatedLoad {
    /// Normal force, N.
    pub force_n: f64,
    /// Contact area, m².
    pub area_m2: f64,
    /// Contact fraction of the map.
    pub contact_fraction: f64,
    /// Force / area, Pa; NaN where the area is zero (a Greenwood–Tripp load whose bearing
    /// area covers no pixel): an empty cell in `areas.csv`, `null` in `summary.json`.
    pub mean_pressure_pa: f64,
    /// Largest pressure, Pa.
    pub max_pressure_pa: f64,
    /// Rigid approach, m.
    pub approach_m: f64,
    /// 8-connected contact patches.
    pub patches: u64,
    /// Solver iterations.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Plastic volume, m³.
    pub plastic_volume_m3: f64,
    /// Contact reaches the border of a free map.
    pub edge_contact: bool,
}

/// What `simulate` produced.
#[derive(Debug, Clone)]
pub struct SimulateOutcome {
    /// The rows.
    pub loads: Vec<SimulatedLoad>,
    /// Statistics of the roughness (after detrending, before adding a sphere).
    pub stats: SurfaceStats,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Files written.
    pub written: Vec<PathBuf>,
}

/// Progress callback: (loads done, loads in all).
pub type SimulateProgress<'a> = &'a dyn Fn(usize, usize);

/// Run `simulate`. `progress` hears of finished loads, `monitor` of every CG iteration.
pub fn run_simulate(
    request: &SimulateRequest,
    progress: SimulateProgress,
    monitor: Option<Monitor>,
) -> Result<SimulateOutcome> {
    let (roughness, notes) = request.topography.read_with_notes()?;
    let stats = SurfaceStats::finite_differences(&roughness)?;
    let staging = Staging::new(
        &request.out_dir,
        std::slice::from_ref(&request.topography.path),
    )?;
    let (loads, mut warnings) = match request.model {
        ModelChoice::GreenwoodTripp => run_gt(request, &roughness, &stats, &staging, progress)?,
        ModelChoice::HalfSpace(model) => {
            let mut body = roughness.clone();
            if let Some(r) = request.radius_m {
                body.add_sphere(r)?;
            }
            // Gap residuals relative to the roughness (SolverOptions::gap_scale_m).
            let options = SolverOptions {
                monitor,
                gap_scale_m: request.options.gap_scale_m.or(Some(stats.h_rms_m)),
                ..request.options
            };
            run_halfspace(request, model, &body, options, &staging, progress)?
        }
    };
    warnings.splice(0..0, notes);
    for l in loads.iter().filter(|l| l.area_m2 <= 0.0) {
        warnings.push(format!(
            "{:.6} mN: no pixel in contact (the contact is smaller than a pixel); mean pressure left empty",
            l.force_n * 1e3
        ));
    }
    staging.write("areas.csv", &areas_csv(&loads)?)?;
    staging.write("area_vs_load.png", &area_plot(request, &loads).to_png()?)?;
    let summary = summary_json(request, &roughness, &stats, &loads, &warnings);
    let text = serde_json::to_string_pretty(&summary).expect("JSON values serialise");
    staging.write("summary.json", text.as_bytes())?;
    let written = staging.commit()?;
    Ok(SimulateOutcome {
        loads,
        stats,
        warnings,
        written,
    })
}

type Rows = (Vec<SimulatedLoad>, Vec<String>);

fn run_halfspace(
    request: &SimulateRequest,
    model: Model,
    body: &Topography,
    options: SolverOptions,
    staging: &Staging,
    progress: SimulateProgress,
) -> Result<Rows> {
    let setup = Setup {
        topography: body,
        e_star_pa: request.e_star_pa,
        boundary: if request.periodic {
            Boundary::Periodic
        } else {
            Boundary::Free
        },
        model,
        options,
    };
    let base = separation(body);
    let total = request.loads_n.len();
    let mut warnings = Vec::new();
    let mut rows = Vec::with_capacity(total);
    // Each load's maps are written and its fields dropped before the next load is solved.
    sweep_each(&setup, &request.loads_n, &mut |i, step| {
        write_maps(staging, body, &base, i, &step)?;
        if step.edge_contact {
            warnings.push(format!(
                "at {:.4} mN the contact reaches the border of the map: the free-boundary result is not valid; use a larger map or smaller loads",
                step.force_n * 1e3
            ));
        }
        rows.push(row_of(body, &step));
        progress(i + 1, total);
        Ok(())
    })?;
    Ok((rows, warnings))
}

fn row_of(body: &Topography, s: &LoadStep) -> SimulatedLoad {
    SimulatedLoad {
        force_n: s.force_n,
        area_m2: s.area_m2,
        contact_fraction: s.contact_fraction,
        mean_pressure_pa: s.mean_pressure_pa,
        max_pressure_pa: s.max_pressure_pa,
        approach_m: s.solution.approach,
        patches: s.patches,
        iterations: s.solution.iterations,
        residual: s.solution.gap_residual.max(s.solution.pressure_change),
        plastic_volume_m3: s.plastic_m.iter().sum::<f64>() * body.dx_m * body.dy_m,
        edge_contact: s.edge_contact,
    }
}

/// Per-load float32 maps: contact, pressure (MPa), gap (µm), plastic displacement (µm) and the
/// deformed topography (µm, heights positive towards the flat).
fn write_maps(
    staging: &Staging,
    body: &Topography,
    base: &[f64],
    i: usize,
    s: &LoadStep,
) -> Result<()> {
    let (nx, ny) = (body.nx(), body.ny());
    let size = Some((body.dx_m, body.dy_m));
    let map = |name: &str, values: Vec<f32>| -> Result<()> {
        let tiff = encode_f32_stack(
            &[&values],
            nx,
            ny,
            size,
            &format!("contactscope simulate {name}\n"),
        )?;
        staging.write(&format!("load_{:03}_{name}.tif", i + 1), &tiff)?;
        Ok(())
    };
    map(
        "contact",
        s.solution
            .pressure
            .iter()
            .map(|p| f32::from(u8::from(*p > 0.0)))
            .collect(),
    )?;
    map(
        "pressure_MPa",
        s.solution
            .pressure
            .iter()
            .map(|p| (p * 1e-6) as f32)
            .collect(),
    )?;
    map(
        "gap_um",
        s.solution.gap.iter().map(|g| (g * 1e6) as f32).collect(),
    )?;
    map(
        "plastic_um",
        s.plastic_m.iter().map(|h| (h * 1e6) as f32).collect(),
    )?;
    let top = base
        .iter()
        .zip(body.heights.iter())
        .map(|(s, h)| s + h)
        .fold(f64::NAN, f64::max);
    map(
        "deformed_um",
        base.iter()
            .zip(&s.plastic_m)
            .map(|(sep, h)| ((top - sep - h) * 1e6) as f32)
            .collect(),
    )
}

fn run_gt(
    request: &SimulateRequest,
    roughness: &Topography,
    stats: &SurfaceStats,
    staging: &Staging,
    progress: SimulateProgress,
) -> Result<Rows> {
    let radius = request.radius_m.ok_or_else(|| {
        Error::InvalidArgument(
            "the Greenwood–Tripp model needs the sphere radius (--radius)".into(),
        )
    })?;
    let params = GtParams::new(
        radius,
        request.e_star_pa,
        stats.h_rms_m,
        stats.h_double_prime_rms_per_m,
    );
    params.validate()?;
    let (nx, ny) = (roughness.nx(), roughness.ny());
    let size = Some((roughness.dx_m, roughness.dy_m));
    let mut rows = Vec::new();
    for (i, &force) in request.loads_n.iter().enumerate() {
        let profile = gt_profile(&params, force)?;
        let map = gt_bearing_area(roughness, &profile, None)?;
        let mask: Vec<u8> = map.mask.iter().map(|m| u8::from(*m)).collect();
        let contact: Vec<f32> = mask.iter().map(|m| f32::from(*m)).collect();
        let tiff = encode_f32_stack(
            &[&contact],
            nx,
            ny,
            size,
            "contactscope simulate gt contact\n",
        )?;
        staging.write(&format!("load_{:03}_contact.tif", i + 1), &tiff)?;
        rows.push(SimulatedLoad {
            force_n: force,
            area_m2: map.area_m2,
            contact_fraction: map.contact_fraction,
            mean_pressure_pa: if map.area_m2 > 0.0 {
                force / map.area_m2
            } else {
                f64::NAN
            },
            max_pressure_pa: profile.pressure_pa.first().copied().unwrap_or(f64::NAN),
            approach_m: profile.approach_m,
            patches: count_patches(&mask, nx).0,
            iterations: profile.iterations,
            residual: (profile.load_n - force).abs() / force,
            plastic_volume_m3: 0.0,
            edge_contact: false,
        });
        progress(i + 1, request.loads_n.len());
    }
    Ok((rows, Vec::new()))
}

/// A number for a CSV cell; an empty cell for an undefined (non-finite) one.
fn finite_cell(v: f64) -> String {
    if v.is_finite() {
        v.to_string()
    } else {
        String::new()
    }
}

fn areas_csv(loads: &[SimulatedLoad]) -> Result<Vec<u8>> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    w.write_record([
        "force_mN",
        "area_um2",
        "contact_fraction",
        "mean_pressure_MPa",
        "max_pressure_MPa",
        "approach_um",
        "patches",
        "iterations",
        "residual",
        "plastic_volume_um3",
        "edge_contact",
    ])
    .map_err(csv_err)?;
    for l in loads {
        w.write_record([
            (l.force_n * 1e3).to_string(),
            (l.area_m2 * 1e12).to_string(),
            l.contact_fraction.to_string(),
            finite_cell(l.mean_pressure_pa * 1e-6),
            finite_cell(l.max_pressure_pa * 1e-6),
            (l.approach_m * 1e6).to_string(),
            l.patches.to_string(),
            l.iterations.to_string(),
            format!("{:.3e}", l.residual),
            (l.plastic_volume_m3 * 1e18).to_string(),
            l.edge_contact.to_string(),
        ])
        .map_err(csv_err)?;
    }
    w.into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

fn area_plot(request: &SimulateRequest, loads: &[SimulatedLoad]) -> Chart {
    let xy: Vec<(f64, f64)> = loads
        .iter()
        .map(|l| (l.force_n * 1e3, l.area_m2 * 1e12))
        .collect();
    let (f, a): (Vec<f64>, Vec<f64>) = xy.iter().copied().unzip();
    let curves = fit_power_law(&f, &a)
        .map(|fit| Curve {
            label: format!("power law A ∝ N^β, β = {:.3}", fit.exponent),
            xy: f.iter().map(|&n| (n, fit.eval(n))).collect(),
        })
        .into_iter()
        .collect();
    Chart {
        title: format!("Simulated contact area ({} model)", request.model.name()),
        x_label: "normal force N (mN)".into(),
        y_label: "contact area A (µm²)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points: vec![PointSet {
            label: "simulated (pixels with p > 0)".into(),
            xy,
        }],
        curves,
    }
}

fn model_json(model: &ModelChoice) -> Value {
    match model {
        ModelChoice::GreenwoodTripp => {
            json!({ "name": "gt", "eta_h_rms_beta": GtParams::DEFAULT_ETA_H_BETA, "sigma": "h_rms" })
        }
        ModelChoice::HalfSpace(Model::Elastic) => json!({ "name": "elastic" }),
        ModelChoice::HalfSpace(Model::Hardness {
            hardness_pa,
            volume_conserving,
        }) => json!({
            "name": "hardness",
            "hardness_MPa": hardness_pa * 1e-6,
            "plastic_increment": if volume_conserving.is_some() { "volume-conserving (Eq. 5)" } else { "local (Eq. 4)" },
            "relaxation_alpha": volume_conserving,
        }),
        ModelChoice::HalfSpace(Model::Hardening {
            modulus_pa_per_m,
            initial_pa,
        }) => json!({
            "name": "hardening",
            "hardening_MPa_per_nm": modulus_pa_per_m * 1e-15,
            "initial_hardness_MPa": initial_pa * 1e-6,
            "solve": "implicit series compliance per load step (methods.md §3.4)",
        }),
    }
}

fn summary_json(
    request: &SimulateRequest,
    roughness: &Topography,
    stats: &SurfaceStats,
    loads: &[SimulatedLoad],
    warnings: &[String],
) -> Value {
    let (f, a): (Vec<f64>, Vec<f64>) = loads
        .iter()
        .map(|l| (l.force_n * 1e3, l.area_m2 * 1e12))
        .unzip();
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "topography": {
            "path": request.topography.path.display().to_string(),
            "nx": roughness.nx(),
            "ny": roughness.ny(),
            "pixel_size_x_nm": roughness.dx_m * 1e9,
            "pixel_size_y_nm": roughness.dy_m * 1e9,
            "detrend": request.topography.detrend.name(),
            "channel": request.topography.channel,
            "fill_invalid": request.topography.fill_invalid,
            "h_rms_nm": stats.h_rms_m * 1e9,
            "h_prime_rms": stats.h_prime_rms,
            "h_double_prime_rms_per_um": stats.h_double_prime_rms_per_m * 1e-6,
            "sphere_radius_um": request.radius_m.map(|r| r * 1e6),
        },
        "contact_modulus_GPa": request.e_star_pa * 1e-9,
        "model": model_json(&request.model),
        "boundary": if request.periodic { "periodic (q = 0 mode zero: mean pressure imposed, approach is the multiplier)" } else { "free (2N zero padding, Love pixel kernel)" },
        "solver": {
            "method": "Polonsky–Keer constrained conjugate gradients, f64",
            "tolerance": request.options.tolerance,
            "max_iterations": request.options.max_iterations,
        },
        "loads": loads.iter().map(|l| json!({
            "force_mN": l.force_n * 1e3,
            "area_um2": l.area_m2 * 1e12,
            "contact_fraction": l.contact_fraction,
            "mean_pressure_MPa": l.mean_pressure_pa * 1e-6,
            "max_pressure_MPa": l.max_pressure_pa * 1e-6,
            "approach_um": l.approach_m * 1e6,
            "patches": l.patches,
            "iterations": l.iterations,
            "residual": l.residual,
            "plastic_volume_um3": l.plastic_volume_m3 * 1e18,
            "edge_contact": l.edge_contact,
        })).collect::<Vec<_>>(),
        "power_law": fit_power_law(&f, &a).map(|fit| json!({
            "exponent": fit.exponent,
            "exponent_se": fit.exponent_se,
            "prefactor_um2_per_mN_pow_exponent": fit.prefactor,
            "r_squared": fit.r_squared,
        })),
        "warnings": warnings,
    })
}
