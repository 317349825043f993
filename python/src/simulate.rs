//! `simulate`: the job `contactscope_jobs::simulate` from Python. The request is built from the
//! keywords (SI units) with the job's own defaults and range checks; the result is the job's
//! outcome (SI keys) and, with `maps`, the per-load maps as numpy stacks.

use ndarray::Array3;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope::solver::simulate::Model;
use contactscope_formats::param::Param;
use contactscope_jobs::simulate::export_ce::{CeExport, Exporting};
use contactscope_jobs::simulate::{
    run, LoadMaps, LoadObserver, MapChoice, ModelChoice, SimulateRequest,
};

use crate::convert::outcome_dict;
use crate::extract::{HeightChannel, Measurement};
use crate::heights::{height_input, HeightsArg};
use crate::{bad, compute, PixelArg};

/// The model from its name and parameters (SI).
pub(crate) fn model_of(
    model: &str,
    hardness: Option<f64>,
    k: Option<f64>,
    initial_hardness: Option<f64>,
    alpha: Option<f64>,
) -> PyResult<ModelChoice> {
    const MODELS: [&str; 4] = ["elastic", "hardness", "hardening", "gt"];
    if !MODELS.contains(&model) {
        // The name first: a misspelt model must not be blamed on its parameters.
        let hint = MODELS
            .iter()
            .find(|m| m.eq_ignore_ascii_case(model.trim()))
            .map(|m| format!("; did you mean \"{m}\"?"))
            .unwrap_or_default();
        return Err(bad(format!(
            "{}\"{model}\" is not one of {}{hint}",
            Param::Model,
            MODELS.map(|m| format!("\"{m}\"")).join(", ")
        )));
    }
    let unused = |what: Param, value: Option<f64>, applies: &str| match value {
        Some(_) => Err(bad(format!("{what} applies to model=\"{applies}\" only"))),
        None => Ok(()),
    };
    if model != "hardness" {
        unused(Param::Hardness, hardness, "hardness")?;
        unused(Param::VolumeConserving, alpha, "hardness")?;
    }
    if model != "hardening" {
        unused(Param::Hardening, k, "hardening")?;
        unused(Param::InitialHardness, initial_hardness, "hardening")?;
    }
    Ok(match model {
        "elastic" => ModelChoice::HalfSpace(Model::Elastic),
        "gt" => ModelChoice::GreenwoodTripp,
        "hardness" => ModelChoice::HalfSpace(Model::Hardness {
            hardness_pa: hardness.ok_or_else(|| {
                bad(format!(
                    "model=\"hardness\" needs {} (Pa, e.g. 3.7e8)",
                    Param::Hardness
                ))
            })?,
            volume_conserving: alpha,
        }),
        "hardening" => ModelChoice::HalfSpace(Model::Hardening {
            modulus_pa_per_m: k.ok_or_else(|| {
                bad(format!(
                    "model=\"hardening\" needs {} (Pa/m, e.g. 4e15 for 4 MPa/nm)",
                    Param::Hardening
                ))
            })?,
            initial_pa: initial_hardness.unwrap_or(0.0),
        }),
        other => return Err(bad(format!("{}\"{other}\" is not a model", Param::Model))),
    })
}

/// `maps=`: `"none"`, `"contact"` or `"all"`; `True` and `False` (the older spelling) mean
/// `"all"` and `"none"`.
enum MapsArg {
    Flag(bool),
    Name(String),
}

impl<'a, 'py> FromPyObject<'a, 'py> for MapsArg {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Ok(flag) = obj.cast::<pyo3::types::PyBool>() {
            return Ok(MapsArg::Flag(flag.is_true()));
        }
        obj.extract::<String>().map(MapsArg::Name).map_err(|_| {
            crate::extract::wrong_type("maps=", "\"none\", \"contact\" or \"all\"", &obj)
        })
    }
}

fn maps_of(arg: MapsArg) -> PyResult<MapChoice> {
    match arg {
        MapsArg::Flag(true) => Ok(MapChoice::All),
        MapsArg::Flag(false) => Ok(MapChoice::None),
        MapsArg::Name(name) => name.parse().map_err(|_| {
            bad(format!(
                "maps={name:?} is not one of \"none\", \"contact\", \"all\""
            ))
        }),
    }
}

/// Keeps each load's maps: pressure (Pa), gap (m), plastic displacement (m), contact; or the
/// contact alone (`maps="contact"`).
#[derive(Default)]
struct KeepMaps {
    contact_only: bool,
    pressure: Vec<f64>,
    gap: Vec<f64>,
    plastic: Vec<f64>,
    contact: Vec<bool>,
    shape: (usize, usize),
}

impl LoadObserver for KeepMaps {
    fn load(
        &mut self,
        _index: usize,
        _total: usize,
        maps: LoadMaps<'_>,
    ) -> contactscope_jobs::Result<()> {
        match maps {
            LoadMaps::HalfSpace { body, step, .. } => {
                self.shape = (body.ny(), body.nx());
                self.contact
                    .extend(step.solution.pressure.iter().map(|p| *p > 0.0));
                if self.contact_only {
                    return Ok(());
                }
                // The step is ours: its fields move into the stacks.
                self.pressure.extend(step.solution.pressure);
                self.gap.extend(step.solution.gap);
                self.plastic.extend(step.plastic_m);
            }
            LoadMaps::BearingArea { roughness, mask } => {
                // Greenwood–Tripp gives the bearing-area contact only: no pressure, gap or
                // plastic fields.
                let n = mask.len();
                self.shape = (roughness.ny(), roughness.nx());
                self.contact.extend(mask.iter().map(|m| *m > 0));
                if self.contact_only {
                    return Ok(());
                }
                self.pressure.extend(std::iter::repeat_n(f64::NAN, n));
                self.gap.extend(std::iter::repeat_n(f64::NAN, n));
                self.plastic.extend(std::iter::repeat_n(0.0, n));
            }
        }
        Ok(())
    }
}

/// A load ramp with one contact model (the command line's `simulate`); see the package's
/// docstring. Returns the outcome (SI) and the stacks (loads, ny, nx) `maps` asks for.
#[pyfunction]
#[pyo3(signature = (heights, pixel_size, modulus, loads, model="elastic", hardness=None, k=None, initial_hardness=None, alpha=None, radius=None, periodic=false, tolerance=None, max_iterations=None, maps=MapsArg::Name("all".into()), detrend="plane", height_unit=None, channel=None, fill_invalid=None, device="cpu", measurement=None, contact_engineering=None))]
// The signature as Python's `help` and `inspect` show it: `maps`' default is a Rust value, which
// PyO3 would print as `...`.
#[pyo3(
    text_signature = "(heights, pixel_size, modulus, loads, model='elastic', hardness=None, k=None, initial_hardness=None, alpha=None, radius=None, periodic=False, tolerance=None, max_iterations=None, maps='all', detrend='plane', height_unit=None, channel=None, fill_invalid=None, device='cpu', measurement=None, contact_engineering=None)"
)]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    heights: HeightsArg<'py>,
    pixel_size: Option<PixelArg>,
    modulus: f64,
    loads: Vec<f64>,
    model: &str,
    hardness: Option<f64>,
    k: Option<f64>,
    initial_hardness: Option<f64>,
    alpha: Option<f64>,
    radius: Option<f64>,
    periodic: bool,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    maps: MapsArg,
    detrend: &str,
    height_unit: Option<f64>,
    channel: Option<HeightChannel>,
    fill_invalid: Option<&str>,
    device: &str,
    measurement: Option<Measurement>,
    contact_engineering: Option<std::path::PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let device = crate::convert::device_of(device)?;
    let input = height_input(
        heights,
        pixel_size,
        detrend,
        height_unit,
        channel.map(|c| c.0),
        fill_invalid,
        measurement.map(|m| m.0),
    )?;
    let model = model_of(model, hardness, k, initial_hardness, alpha)?;
    let maps = maps_of(maps)?;
    let mut request = SimulateRequest::new(input, modulus, model, loads);
    request.radius_m = radius;
    request.periodic = periodic;
    request.tolerance = tolerance.unwrap_or(request.tolerance);
    request.max_iterations = max_iterations.unwrap_or(request.max_iterations);
    request.device = device;
    request.maps = maps;
    let (outcome, kept) = compute(py, move || {
        let mut kept = KeepMaps {
            contact_only: maps == MapChoice::Contact,
            ..KeepMaps::default()
        };
        let mut none = contactscope_jobs::simulate::NoMaps;
        let inner: &mut dyn LoadObserver = if maps == MapChoice::None {
            &mut none
        } else {
            &mut kept
        };
        let outcome = match &contact_engineering {
            // The export hears of every load beside the maps kept; the archive is written
            // (atomically) only when every load is solved.
            Some(path) => {
                let mut export = CeExport::new(&request)?;
                let outcome = run(
                    &request,
                    &mut Exporting {
                        inner,
                        export: &mut export,
                    },
                    None,
                )?;
                export.finish_to(path, &request, &outcome)?;
                outcome
            }
            None => run(&request, inner, None)?,
        };
        Ok::<_, contactscope_jobs::Error>((outcome, kept))
    })?;
    let d = outcome_dict(py, &outcome)?;
    let shape = (outcome.loads.len(), kept.shape.0, kept.shape.1);
    let err = |e: ndarray::ShapeError| bad(format!("maps: {e}"));
    if maps.all() {
        for (name, values) in [
            ("pressure", kept.pressure),
            ("gap", kept.gap),
            ("plastic", kept.plastic),
        ] {
            let a = Array3::from_shape_vec(shape, values).map_err(err)?;
            d.set_item(name, a.into_pyarray(py))?;
        }
    }
    if maps != MapChoice::None {
        let a = Array3::from_shape_vec(shape, kept.contact).map_err(err)?;
        d.set_item("contact", a.into_pyarray(py))?;
    }
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    Ok(())
}
