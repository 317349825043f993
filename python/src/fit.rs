//! `fit_hardening`, `ramp` and `misfit`: the job `contactscope_jobs::fit_hardening` from Python
//! (the same request, defaults and checks as the command line's `fit-hardening`), one load ramp
//! as the unit of a distributed fit, and the fit's misfit.

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope::model_fit::{Family, Imaging, Search};
use contactscope_formats::param::Param;
use contactscope_jobs::fit_hardening::{BodyRequest, FitRequest, MeasuredInput};

use crate::convert::outcome_dict;
use crate::extract::HeightChannel;
use crate::heights::{height_input, HeightsArg};
use crate::{bad, compute, PixelArg};

/// The measured curve: an `areas.csv` path, (forces N, areas m²), or (forces N, areas m², lower
/// ends m², upper ends m²) with each area's interval.
enum MeasuredArg {
    Path(PathBuf),
    Pairs((Vec<f64>, Vec<f64>)),
    Intervals((Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)),
}

impl<'a, 'py> FromPyObject<'a, 'py> for MeasuredArg {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Some(p) = crate::extract::path(&obj) {
            return Ok(MeasuredArg::Path(p));
        }
        if let Ok(pairs) = obj.extract::<(Vec<f64>, Vec<f64>)>() {
            return Ok(MeasuredArg::Pairs(pairs));
        }
        obj.extract::<(Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)>()
            .map(MeasuredArg::Intervals)
            .map_err(|_| {
                crate::extract::wrong_type(
                    "the measured curve",
                    "an areas.csv path, (forces in N, areas in m²) or (forces, areas, lower \
                     ends, upper ends of the areas' intervals)",
                    &obj,
                )
            })
    }
}

fn measured_input(measured: MeasuredArg) -> PyResult<MeasuredInput> {
    Ok(match measured {
        MeasuredArg::Path(p) => MeasuredInput::File(p),
        MeasuredArg::Pairs((forces, areas)) => {
            if forces.len() != areas.len() {
                return Err(bad(format!(
                    "{} forces for {} areas",
                    forces.len(),
                    areas.len()
                )));
            }
            MeasuredInput::Memory(forces.into_iter().zip(areas).collect())
        }
        MeasuredArg::Intervals((forces, areas, lo, hi)) => {
            if [areas.len(), lo.len(), hi.len()] != [forces.len(); 3] {
                return Err(bad(format!(
                    "{} forces for {} areas, {} lower and {} upper ends",
                    forces.len(),
                    areas.len(),
                    lo.len(),
                    hi.len()
                )));
            }
            MeasuredInput::Intervals(
                (0..forces.len())
                    .map(|i| (forces[i], areas[i], lo[i], hi[i]))
                    .collect(),
            )
        }
    })
}

/// The body of a fit or ramp from the keywords (SI; `None` = the request's default).
#[allow(clippy::too_many_arguments)]
fn body_request(
    heights: HeightsArg<'_>,
    pixel_size: Option<PixelArg>,
    modulus: f64,
    radius: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
    detrend: &str,
    periodic: bool,
    file: (Option<f64>, Option<String>, Option<&str>),
    device: &str,
) -> PyResult<BodyRequest> {
    let device = crate::convert::device_of(device)?;
    let (height_unit, channel, fill_invalid) = file;
    let input = height_input(
        heights,
        pixel_size,
        detrend,
        height_unit,
        channel,
        fill_invalid,
        None,
    )?;
    let mut body = BodyRequest::new(input, modulus);
    body.radius_m = radius;
    body.periodic = periodic;
    body.tolerance = tolerance.unwrap_or(body.tolerance);
    body.max_iterations = max_iterations.unwrap_or(body.max_iterations);
    body.device = device;
    body.imaging = match (imaging_fwhm, imaging_pixel_size) {
        (Some(fwhm_m), Some(p)) => Some(Imaging {
            fwhm_m,
            pixel_m: p.xy()?,
        }),
        (None, None) => None,
        _ => {
            return Err(bad(
                "imaging needs both imaging_fwhm (m) and imaging_pixel_size (m)",
            ))
        }
    };
    Ok(body)
}

fn family_of(name: &str) -> PyResult<Family> {
    Family::parse(name).map_err(crate::to_py)
}

/// Fit contact models to a measured area–load curve (the command line's `fit-hardening`).
/// Returns the outcome (SI keys) with each model's search `trace` [(parameter, misfit)].
#[pyfunction]
#[pyo3(signature = (measured, heights, pixel_size, modulus, radius=None, families=None, range=None, grid=None, ln_tolerance=None, tolerance=None, max_iterations=None, imaging_fwhm=None, imaging_pixel_size=None, detrend="plane", periodic=false, height_unit=None, channel=None, fill_invalid=None, device="cpu"))]
#[allow(clippy::too_many_arguments)]
fn fit_hardening<'py>(
    py: Python<'py>,
    measured: MeasuredArg,
    heights: HeightsArg<'py>,
    pixel_size: Option<PixelArg>,
    modulus: f64,
    radius: Option<f64>,
    families: Option<Vec<String>>,
    range: Option<(f64, f64)>,
    grid: Option<usize>,
    ln_tolerance: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
    detrend: &str,
    periodic: bool,
    height_unit: Option<f64>,
    channel: Option<HeightChannel>,
    fill_invalid: Option<&str>,
    device: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let body = body_request(
        heights,
        pixel_size,
        modulus,
        radius,
        tolerance,
        max_iterations,
        imaging_fwhm,
        imaging_pixel_size,
        detrend,
        periodic,
        (height_unit, channel.map(|c| c.0), fill_invalid),
        device,
    )?;
    let mut request = FitRequest::new(measured_input(measured)?, body);
    if let Some(names) = families {
        request.families = names
            .iter()
            .map(|n| family_of(n))
            .collect::<PyResult<_>>()?;
    }
    // range, grid and ln_tolerance apply to every fitted family with a parameter.
    let fitted: Vec<Family> = request
        .families
        .iter()
        .copied()
        .filter(|f| f.has_parameter())
        .collect();
    if range.is_some() && fitted.len() > 1 {
        return Err(bad(format!(
            "{} is one search range: fit one model with a parameter at a time",
            Param::Hardening
        )));
    }
    for family in fitted {
        let mut search = Search::default_for(family);
        if let Some(r) = range {
            search.range = r;
        }
        search.grid = grid.unwrap_or(search.grid);
        search.ln_tolerance = ln_tolerance.unwrap_or(search.ln_tolerance);
        request.searches.push((family, search));
    }
    let outcome = compute(py, move || {
        contactscope_jobs::fit_hardening::run(&request, None)
    })?;
    let d = outcome_dict(py, &outcome)?;
    // Each model's search trace: (parameter, misfit) per evaluation (not part of fit.json).
    let models = d
        .get_item("models")?
        .ok_or_else(|| bad("result without models"))?
        .cast_into::<PyList>()?;
    for (model, fit) in models.iter().zip(outcome.fits()) {
        model.set_item("trace", fit.trace.clone())?;
    }
    Ok(d)
}

/// One load ramp (loads in N, increasing) of `family` at `parameter` on the rough sphere: the
/// contact areas (m²) as `fit_hardening` counts them, and whether the contact reached the
/// border.
#[pyfunction]
#[pyo3(signature = (heights, pixel_size, modulus, family, parameter, loads, radius=None, tolerance=None, max_iterations=None, imaging_fwhm=None, imaging_pixel_size=None, detrend="plane", periodic=false, device="cpu"))]
#[allow(clippy::too_many_arguments)]
fn ramp<'py>(
    py: Python<'py>,
    heights: HeightsArg<'py>,
    pixel_size: Option<PixelArg>,
    modulus: f64,
    family: &str,
    parameter: Option<f64>,
    loads: Vec<f64>,
    radius: Option<f64>,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
    detrend: &str,
    periodic: bool,
    device: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let family = family_of(family)?;
    let body = body_request(
        heights,
        pixel_size,
        modulus,
        radius,
        tolerance,
        max_iterations,
        imaging_fwhm,
        imaging_pixel_size,
        detrend,
        periodic,
        (None, None, None),
        device,
    )?;
    let outcome = compute(py, move || {
        contactscope_jobs::fit_hardening::ramp(&body, family, parameter, &loads)
    })?;
    let d = PyDict::new(py);
    d.set_item("areas_m2", outcome.areas_m2.into_pyarray(py))?;
    d.set_item("edge_contact", outcome.edge_contact)?;
    Ok(d)
}

/// The fit's misfit: RMS over the measured loads of ln(A_sim/A_exp) (forces in N, areas and
/// simulated areas in m², in the order of the forces).
#[pyfunction]
fn misfit(forces: Vec<f64>, areas: Vec<f64>, simulated: Vec<f64>) -> PyResult<f64> {
    if simulated.len() != forces.len() || areas.len() != forces.len() {
        return Err(bad(format!(
            "{} forces, {} areas and {} simulated areas: give one of each per load",
            forces.len(),
            areas.len(),
            simulated.len()
        )));
    }
    let mut order: Vec<usize> = (0..forces.len()).collect();
    order.sort_by(|&a, &b| forces[a].total_cmp(&forces[b]));
    let measured = MeasuredInput::Memory(forces.iter().copied().zip(areas).collect())
        .read()
        .map_err(crate::to_py)?;
    let sorted: Vec<f64> = order.iter().map(|&i| simulated[i]).collect();
    Ok(measured.misfit(&sorted))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(fit_hardening, m)?)?;
    m.add_function(wrap_pyfunction!(ramp, m)?)?;
    m.add_function(wrap_pyfunction!(misfit, m)?)?;
    Ok(())
}
