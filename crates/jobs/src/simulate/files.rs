//! The outputs of `simulate` as the command line writes them, through a staging folder (nothing
//! appears on failure): `areas.csv` and `summary.json` from the [`SimulateOutcome`], per-load
//! float32 TIFF maps as the loads are solved, and `area_vs_load.png` (feature `plots`).

use std::path::{Path, PathBuf};

use contactscope::solver::cg::Monitor;
use contactscope_formats::tiff::write::encode_f32_stack;

use super::{run, LoadMaps, LoadObserver, SimulateOutcome, SimulateRequest};
use crate::error::Result;
use crate::heights::HeightInput;
use crate::staging::Staging;
use crate::summary::summary_json;
use crate::table::{rows_csv, sci3};

/// Run `simulate` and write its folder: the outcome and the files written (final paths).
/// `progress` hears of finished loads (done, total), `monitor` of every CG iteration.
pub fn run_to_folder(
    request: &SimulateRequest,
    out_dir: &Path,
    command_line: &[String],
    progress: &dyn Fn(usize, usize),
    monitor: Option<Monitor>,
) -> Result<(SimulateOutcome, Vec<PathBuf>)> {
    request.check()?;
    let inputs: Vec<PathBuf> = match &request.heights {
        HeightInput::File(source) => vec![source.path.clone()],
        HeightInput::Memory { .. } => Vec::new(),
    };
    let staging = Staging::new(out_dir, &inputs)?;
    let mut writer = MapWriter {
        staging: &staging,
        progress,
    };
    let outcome = run(request, &mut writer, monitor)?;
    staging.write("areas.csv", &areas_csv(&outcome)?)?;
    #[cfg(feature = "plots")]
    if outcome.loads.iter().any(|l| l.area_m2 > 0.0) {
        staging.write("area_vs_load.png", &area_plot(&outcome).to_png()?)?;
    }
    staging.write("summary.json", &summary_json(command_line, &outcome)?)?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// `areas.csv`: the `loads` of the summary, one row each; the residual with three digits.
pub fn areas_csv(outcome: &SimulateOutcome) -> Result<Vec<u8>> {
    rows_csv(&outcome.loads, &[("residual", sci3)])
}

/// Writes each load's maps into the staging folder as it is solved.
struct MapWriter<'a> {
    staging: &'a Staging,
    progress: &'a dyn Fn(usize, usize),
}

impl LoadObserver for MapWriter<'_> {
    fn load(&mut self, index: usize, total: usize, maps: LoadMaps<'_>) -> Result<()> {
        write_maps(self.staging, index, &maps)?;
        (self.progress)(index + 1, total);
        Ok(())
    }
}

/// Per-load float32 maps: contact, pressure (MPa), gap (µm), plastic displacement (µm) and the
/// deformed topography (µm, heights positive towards the flat); Greenwood–Tripp: the contact.
fn write_maps(staging: &Staging, i: usize, maps: &LoadMaps<'_>) -> Result<()> {
    let map = |grid: (usize, usize, f64, f64), name: &str, values: Vec<f32>| -> Result<()> {
        let (nx, ny, dx, dy) = grid;
        let tiff = encode_f32_stack(
            &[&values],
            nx,
            ny,
            Some((dx, dy)),
            &format!("contactscope simulate {name}\n"),
        )?;
        staging.write(&format!("load_{:03}_{name}.tif", i + 1), &tiff)?;
        Ok(())
    };
    match maps {
        LoadMaps::BearingArea { roughness, mask } => {
            let grid = (
                roughness.nx(),
                roughness.ny(),
                roughness.dx_m,
                roughness.dy_m,
            );
            let contact: Vec<f32> = mask.iter().map(|m| f32::from(*m)).collect();
            // The GT map's description names the model.
            let (nx, ny, dx, dy) = grid;
            let tiff = encode_f32_stack(
                &[&contact],
                nx,
                ny,
                Some((dx, dy)),
                "contactscope simulate gt contact\n",
            )?;
            staging.write(&format!("load_{:03}_contact.tif", i + 1), &tiff)?;
            Ok(())
        }
        LoadMaps::HalfSpace { body, base, step } => {
            let grid = (body.nx(), body.ny(), body.dx_m, body.dy_m);
            let s = step;
            map(
                grid,
                "contact",
                s.solution
                    .pressure
                    .iter()
                    .map(|p| f32::from(u8::from(*p > 0.0)))
                    .collect(),
            )?;
            map(
                grid,
                "pressure_MPa",
                s.solution
                    .pressure
                    .iter()
                    .map(|p| (p * 1e-6) as f32)
                    .collect(),
            )?;
            map(
                grid,
                "gap_um",
                s.solution.gap.iter().map(|g| (g * 1e6) as f32).collect(),
            )?;
            map(
                grid,
                "plastic_um",
                s.plastic_m.iter().map(|h| (h * 1e6) as f32).collect(),
            )?;
            let top = base
                .iter()
                .zip(body.heights.iter())
                .map(|(s, h)| s + h)
                .fold(f64::NAN, f64::max);
            map(
                grid,
                "deformed_um",
                base.iter()
                    .zip(&s.plastic_m)
                    .map(|(sep, h)| ((top - sep - h) * 1e6) as f32)
                    .collect(),
            )
        }
    }
}

#[cfg(feature = "plots")]
fn area_plot(outcome: &SimulateOutcome) -> crate::plot::Chart {
    use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
    let xy: Vec<(f64, f64)> = outcome
        .loads
        .iter()
        .map(|l| (l.force_n * 1e3, l.area_m2 * 1e12))
        .collect();
    let curves = outcome
        .power_law
        .map(|fit| Curve {
            label: format!("power law A ∝ N^β, β = {:.3}", fit.exponent),
            xy: xy
                .iter()
                .map(|&(n, _)| (n, fit.prefactor_um2 * n.powf(fit.exponent)))
                .collect(),
        })
        .into_iter()
        .collect();
    Chart {
        title: format!("Simulated contact area ({} model)", outcome.model.name()),
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
