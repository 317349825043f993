//! The outputs of `simulate` as the command line writes them, through a staging folder (nothing
//! appears on failure): `areas.csv` and `summary.json` from the [`SimulateOutcome`], per-load
//! float32 TIFF maps as the loads are solved (those [`MapChoice`] asks for), and
//! `area_vs_load.png` (feature `plots`).

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use contactscope::solver::cg::Monitor;
use contactscope_formats::tiff::write::{encode_f32_stack, quantity, values_description};

use super::export_ce::{CeExport, DeformedExport};
use super::{run, LoadMaps, LoadObserver, MapChoice, SimulateOutcome, SimulateRequest};
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
    exports: &[Export],
) -> Result<(SimulateOutcome, Vec<PathBuf>)> {
    request.check()?;
    let inputs: Vec<PathBuf> = match &request.heights {
        HeightInput::File(source) => vec![source.path.clone()],
        HeightInput::Memory { .. } => Vec::new(),
    };
    let ce = match exports.contains(&Export::ContactEngineering) {
        true => Some(CeExport::new(request)?),
        false => None,
    };
    let deformed = match exports.contains(&Export::SurfaceContainer) {
        true => Some(DeformedExport::new(request)?),
        false => None,
    };
    let staging = Staging::new(out_dir, &inputs)?;
    let mut writer = MapWriter {
        staging: &staging,
        progress,
        maps: request.maps,
        top_m: None,
        ce,
        deformed,
    };
    let outcome = run(request, &mut writer, monitor)?;
    if let Some(ce) = writer.ce.take() {
        ce.finish(&staging, request, &outcome)?;
    }
    if let Some(d) = writer.deformed.take() {
        d.finish(&staging)?;
    }
    staging.write("areas.csv", &areas_csv(&outcome)?)?;
    #[cfg(feature = "plots")]
    if outcome.loads.iter().any(|l| l.area_m2 > 0.0) {
        staging.write("area_vs_load.png", &area_plot(&outcome).to_png()?)?;
    }
    staging.write("summary.json", &summary_json(command_line, &outcome)?)?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// An export of the results in another tool's layout, beside contactscope's own files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Export {
    /// contact.engineering's contact-mechanics download (`contact_mechanics.zip`,
    /// [`super::export_ce`]).
    ContactEngineering,
    /// The plastically deformed surface and the plastic displacement of every load as a
    /// contact.engineering surface container (`deformed_surfaces.zip`,
    /// [`super::export_ce::DeformedExport`]).
    SurfaceContainer,
}

/// `areas.csv`: the `loads` of the summary, one row each; the residual with three digits.
pub fn areas_csv(outcome: &SimulateOutcome) -> Result<Vec<u8>> {
    rows_csv(&outcome.loads, &[("residual", sci3)])
}

/// Writes each load's maps into the staging folder as it is solved.
struct MapWriter<'a> {
    staging: &'a Staging,
    progress: &'a dyn Fn(usize, usize),
    maps: MapChoice,
    /// The top of the undeformed body, the same at every load (found at the first).
    top_m: Option<f64>,
    /// The contact.engineering export, when asked for.
    ce: Option<CeExport>,
    /// The deformed surfaces' container, when asked for.
    deformed: Option<DeformedExport>,
}

impl LoadObserver for MapWriter<'_> {
    fn load(&mut self, index: usize, total: usize, maps: LoadMaps<'_>) -> Result<()> {
        if let Some(ce) = &mut self.ce {
            ce.step(index, &maps)?;
        }
        if let Some(d) = &mut self.deformed {
            d.step(index, &maps)?;
        }
        if self.maps != MapChoice::None {
            self.write_maps(index, &maps)?;
        }
        (self.progress)(index + 1, total);
        Ok(())
    }
}

/// The per-load maps, in the order they are staged.
#[derive(Debug, Clone, Copy)]
enum Map {
    Contact,
    Pressure,
    Gap,
    Plastic,
    Deformed,
}

impl Map {
    /// The name in `load_NNN_{name}.tif`, with the unit.
    fn name(self) -> &'static str {
        match self {
            Map::Contact => "contact",
            Map::Pressure => "pressure_MPa",
            Map::Gap => "gap_um",
            Map::Plastic => "plastic_um",
            Map::Deformed => "deformed_um",
        }
    }

    /// What the values are and their unit, for the file's description
    /// ([`values_description`]).
    fn quantity(self) -> (&'static str, Option<&'static str>) {
        match self {
            Map::Contact => (quantity::CONTACT, None),
            Map::Pressure => (quantity::PRESSURE, Some("MPa")),
            Map::Gap => (quantity::GAP, Some("um")),
            Map::Plastic => (quantity::PLASTIC, Some("um")),
            Map::Deformed => (quantity::HEIGHT, Some("um")),
        }
    }

    /// The map's float32 values; `top_m` is the top of the undeformed body.
    fn values(self, maps: &LoadMaps<'_>, top_m: f64) -> Vec<f32> {
        let (base, step) = match maps {
            LoadMaps::BearingArea { mask, .. } => {
                return mask.iter().map(|m| f32::from(*m)).collect();
            }
            LoadMaps::HalfSpace { base, step, .. } => (base, step),
        };
        let (p, gap, plastic) = (&step.solution.pressure, &step.solution.gap, &step.plastic_m);
        match self {
            Map::Contact => p.iter().map(|p| f32::from(u8::from(*p > 0.0))).collect(),
            Map::Pressure => p.iter().map(|p| (p * 1e-6) as f32).collect(),
            Map::Gap => gap.iter().map(|g| (g * 1e6) as f32).collect(),
            Map::Plastic => plastic.iter().map(|h| (h * 1e6) as f32).collect(),
            Map::Deformed => base
                .iter()
                .zip(plastic)
                .map(|(sep, h)| ((top_m - sep - h) * 1e6) as f32)
                .collect(),
        }
    }
}

impl MapWriter<'_> {
    /// Per-load float32 maps: contact, pressure (MPa), gap (µm), plastic displacement (µm) and
    /// the deformed topography (µm, heights positive towards the flat), or the contact alone
    /// ([`MapChoice::Contact`]); Greenwood–Tripp: the contact. The maps of one load are converted
    /// and compressed in parallel, then staged in this order.
    fn write_maps(&mut self, i: usize, maps: &LoadMaps<'_>) -> Result<()> {
        let (grid, description, wanted) = match maps {
            // The GT map's description names the model.
            LoadMaps::BearingArea { roughness, .. } => (&**roughness, "gt ", &[Map::Contact][..]),
            LoadMaps::HalfSpace { body, .. } => (
                *body,
                "",
                if self.maps.all() {
                    &[
                        Map::Contact,
                        Map::Pressure,
                        Map::Gap,
                        Map::Plastic,
                        Map::Deformed,
                    ][..]
                } else {
                    &[Map::Contact][..]
                },
            ),
        };
        let top_m = match maps {
            LoadMaps::HalfSpace { body, base, .. } if self.maps.all() => {
                *self.top_m.get_or_insert_with(|| {
                    base.iter()
                        .zip(body.heights.iter())
                        .map(|(s, h)| s + h)
                        .fold(f64::NAN, f64::max)
                })
            }
            _ => f64::NAN,
        };
        let encoded: Vec<Result<Vec<u8>>> = wanted
            .par_iter()
            .map(|map| {
                Ok(encode_f32_stack(
                    &[&map.values(maps, top_m)],
                    grid.nx(),
                    grid.ny(),
                    Some((grid.dx_m, grid.dy_m)),
                    &format!(
                        "contactscope simulate {description}{}\n{}",
                        map.name(),
                        values_description(map.quantity().0, map.quantity().1)
                    ),
                )?)
            })
            .collect();
        for (map, tiff) in wanted.iter().zip(encoded) {
            self.staging
                .write(&format!("load_{:03}_{}.tif", i + 1, map.name()), &tiff?)?;
        }
        Ok(())
    }
}

#[cfg(feature = "plots")]
fn area_plot(outcome: &SimulateOutcome) -> crate::plot::Chart {
    use crate::plot::{Axes, Chart, Curve, Legend};
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
        points: crate::fits::point_sets(
            &outcome
                .loads
                .iter()
                .map(super::SimulatedLoad::load_point)
                .collect::<Vec<_>>(),
            "simulated (pixels with p > 0)",
        ),
        curves,
        ..Chart::default()
    }
}
