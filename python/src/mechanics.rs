//! Height maps and contact mechanics: reading AFM/profilometer files, generating self-affine
//! surfaces, load ramps with the paper's contact models (elastic, penetration hardness, linear
//! hardening, Greenwood–Tripp) and the fit of the hardening coefficient. SI units: heights and
//! lengths in m, forces in N, pressures and moduli in Pa, k in Pa/m (4 MPa/nm = 4e15 Pa/m).

use std::path::PathBuf;

use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope::model_fit::{fit_parameter, Family, Imaging, Measured, ModelBody, Search};
use contactscope::solver::cg::SolverOptions;
use contactscope::surface::generate::RmsTarget;
use contactscope::surface::Topography;
use contactscope_formats::param::Param;
use contactscope_jobs::heights::TopographySource;
use contactscope_jobs::surface::SurfaceRequest;
use contactscope_jobs::topography::TopographyRequest;

use crate::convert::outcome_dict;
use crate::heights::{detrend_of, fill_of};
use crate::{bad, compute, PixelArg};

/// A height map (rows = y, columns = x; m) and its pixel size as a topography.
fn topography(heights: &PyReadonlyArray2<'_, f64>, pixel: PixelArg) -> PyResult<Topography> {
    let (dx, dy) = pixel.xy()?;
    Topography::new(heights.as_array().to_owned(), dx, dy).map_err(crate::to_py)
}

/// Read a height map of any format contactscope reads (the job `contactscope_jobs::topography`,
/// as the command line's `topography`): the outcome in SI units (`summary`: `topography --json`;
/// `notes`) and `heights` (m, rows = y, filled as asked and detrended). A map that cannot be used
/// (invalid points without `fill_invalid`) is refused with the reason.
#[pyfunction]
#[pyo3(signature = (path, pixel_size=None, height_unit=None, detrend="plane", channel=None, fill_invalid=None))]
fn read_topography<'py>(
    py: Python<'py>,
    path: PathBuf,
    pixel_size: Option<PixelArg>,
    height_unit: Option<f64>,
    detrend: &str,
    channel: Option<String>,
    fill_invalid: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = TopographyRequest {
        source: TopographySource {
            pixel_size_m: crate::pixel_opt(pixel_size)?,
            height_unit_m: height_unit,
            detrend: detrend_of(detrend)?,
            channel,
            fill_invalid: fill_of(fill_invalid)?,
            ..TopographyRequest::new(path).source
        },
    };
    let mut outcome = compute(py, move || {
        let outcome = contactscope_jobs::topography::run(&request)?;
        outcome.usable_heights()?;
        Ok::<_, contactscope_jobs::Error>(outcome)
    })?;
    let heights = outcome.heights.take();
    let d = outcome_dict(py, &outcome)?;
    if let Some(t) = heights {
        d.set_item("heights", t.heights.into_pyarray(py))?;
    }
    Ok(d)
}

/// A seeded self-affine random surface (the job `contactscope_jobs::surface`, as the command
/// line's `surface`, with its defaults and range checks): the outcome in SI units (`nx`, `ny`,
/// `pixel_size_m`, `h_rms_m`, `h_prime_rms`, `h_double_prime_rms_per_m`) and `heights` (m,
/// rows = y).
#[pyfunction]
#[pyo3(signature = (nx, ny, pixel_size, hurst=None, rms_height=None, rms_slope=None, rolloff=None, cutoff=None, seed=None))]
#[allow(clippy::too_many_arguments)]
fn surface<'py>(
    py: Python<'py>,
    nx: usize,
    ny: usize,
    pixel_size: f64,
    hurst: Option<f64>,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let target = match (rms_height, rms_slope) {
        (Some(h), None) => RmsTarget::Height(h),
        (None, Some(s)) => RmsTarget::Slope(s),
        _ => {
            return Err(bad(format!(
                "give exactly one of {} (m) and {}",
                Param::RmsHeight,
                Param::RmsSlope
            )))
        }
    };
    let defaults = SurfaceRequest::new(pixel_size, target);
    let request = SurfaceRequest {
        nx,
        ny,
        hurst: hurst.unwrap_or(defaults.hurst),
        rolloff_m: rolloff,
        cutoff_m: cutoff,
        seed: seed.unwrap_or(defaults.seed),
        ..defaults
    };
    let mut outcome = compute(py, move || contactscope_jobs::surface::run(&request))?;
    let heights = std::mem::take(&mut outcome.topography.heights);
    let d = outcome_dict(py, &outcome)?;
    d.set_item("heights", heights.into_pyarray(py))?;
    Ok(d)
}

/// Solver limits as given from Python.
fn solver_options(tolerance: f64, max_iterations: usize) -> PyResult<SolverOptions<'static>> {
    if !(tolerance.is_finite() && tolerance > 0.0) || max_iterations == 0 {
        return Err(bad(format!(
            "tolerance {tolerance:e} must be positive and max_iterations at least 1"
        )));
    }
    Ok(SolverOptions {
        tolerance,
        max_iterations,
        ..SolverOptions::default()
    })
}

fn family_of(name: &str) -> PyResult<Family> {
    Family::parse(name).map_err(crate::to_py)
}

/// The model body of a fit: roughness (m) with the sphere, E* (Pa), solver limits and the
/// optional imaging of simulated maps (PSF FWHM in m, micrograph pixel in m).
#[allow(clippy::too_many_arguments)]
fn model_body(
    heights: &PyReadonlyArray2<'_, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    radius: Option<f64>,
    tolerance: f64,
    max_iterations: usize,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
) -> PyResult<ModelBody> {
    let roughness = topography(heights, pixel_size)?;
    let options = solver_options(tolerance, max_iterations)?;
    let mut body = ModelBody::new(roughness, radius, modulus, options).map_err(crate::to_py)?;
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

/// One model evaluation, the unit of work of a fit or a sweep: the contact areas (m²) of one load
/// ramp (`loads`, N, increasing) for `family` ("elastic", "gt", "hardness" with p_Y in Pa,
/// "hardening" with k in Pa/m) on the rough sphere, as `fit_hardening` counts them (raw p > 0
/// pixels, or imaged like micrographs with `imaging_fwhm` and `imaging_pixel_size`).
#[pyfunction]
#[pyo3(signature = (heights, pixel_size, modulus, family, parameter, loads, radius=None, tolerance=1e-8, max_iterations=5000, imaging_fwhm=None, imaging_pixel_size=None))]
#[allow(clippy::too_many_arguments)]
fn ramp<'py>(
    py: Python<'py>,
    heights: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    family: &str,
    parameter: Option<f64>,
    loads: Vec<f64>,
    radius: Option<f64>,
    tolerance: f64,
    max_iterations: usize,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let family = family_of(family)?;
    let body = model_body(
        &heights,
        pixel_size,
        modulus,
        radius,
        tolerance,
        max_iterations,
        imaging_fwhm,
        imaging_pixel_size,
    )?;
    let (areas, _, edge) = compute(py, move || body.evaluate(family, parameter, &loads, false))?;
    let d = PyDict::new(py);
    d.set_item("areas_m2", areas.into_pyarray(py))?;
    d.set_item("edge_contact", edge)?;
    Ok(d)
}

/// The fit's misfit: RMS over the measured loads of ln(A_sim/A_exp) (areas in m², forces in N).
#[pyfunction]
fn misfit(forces: Vec<f64>, areas: Vec<f64>, simulated: Vec<f64>) -> PyResult<f64> {
    if simulated.len() != forces.len() {
        return Err(bad(format!(
            "{} simulated areas for {} measured loads",
            simulated.len(),
            forces.len()
        )));
    }
    let mut order: Vec<usize> = (0..forces.len()).collect();
    order.sort_by(|&a, &b| forces[a].total_cmp(&forces[b]));
    let measured =
        Measured::new(forces.iter().copied().zip(areas).collect()).map_err(crate::to_py)?;
    let sorted: Vec<f64> = order.iter().map(|&i| simulated[i]).collect();
    Ok(measured.misfit(&sorted))
}

/// Fit one contact model to a measured area–load curve (forces in N, areas in m²) on the rough
/// sphere (heights in m, pixel size in m, sphere `radius` in m, E* `modulus` in Pa): for
/// "hardening" (k in Pa/m) or "hardness" (p_Y in Pa) a log grid over `range` then Brent's method
/// on ln(parameter), with the Gauss–Newton standard error; "elastic" and "gt" are evaluated once.
#[pyfunction]
#[pyo3(signature = (forces, areas, heights, pixel_size, modulus, radius=None, family="hardening", range=None, grid=7, ln_tolerance=0.01, tolerance=1e-8, max_iterations=5000, imaging_fwhm=None, imaging_pixel_size=None))]
#[allow(clippy::too_many_arguments)]
fn fit_hardening<'py>(
    py: Python<'py>,
    forces: Vec<f64>,
    areas: Vec<f64>,
    heights: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    radius: Option<f64>,
    family: &str,
    range: Option<(f64, f64)>,
    grid: usize,
    ln_tolerance: f64,
    tolerance: f64,
    max_iterations: usize,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let family = family_of(family)?;
    if forces.len() != areas.len() {
        return Err(bad(format!(
            "{} forces for {} areas",
            forces.len(),
            areas.len()
        )));
    }
    let measured = Measured::new(forces.into_iter().zip(areas).collect()).map_err(crate::to_py)?;
    let body = model_body(
        &heights,
        pixel_size,
        modulus,
        radius,
        tolerance,
        max_iterations,
        imaging_fwhm,
        imaging_pixel_size,
    )?;
    let mut search = Search::default_for(family);
    if let Some(r) = range {
        search.range = r;
    }
    search.grid = grid;
    search.ln_tolerance = ln_tolerance;
    let fit = compute(py, move || {
        if family.has_parameter() {
            fit_parameter(&body, family, &measured, search).map(Some)
        } else {
            Ok(None)
        }
        .and_then(|fit| match fit {
            Some(f) => Ok((f.best, f.parameter_se, f.trace, f.at_range_edge)),
            None => Ok((
                body.score(family, None, &measured, false)?,
                None,
                vec![],
                false,
            )),
        })
    })?;
    let (best, se, trace, edge) = fit;
    let d = PyDict::new(py);
    d.set_item("family", family.name())?;
    d.set_item("parameter", best.parameter)?;
    d.set_item("parameter_se", se)?;
    d.set_item("misfit", best.misfit)?;
    d.set_item("areas_m2", best.areas_m2.into_pyarray(py))?;
    d.set_item("edge_contact", best.edge_contact)?;
    d.set_item("trace", trace)?;
    d.set_item("at_range_edge", edge)?;
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(surface, m)?)?;
    m.add_function(wrap_pyfunction!(ramp, m)?)?;
    m.add_function(wrap_pyfunction!(misfit, m)?)?;
    m.add_function(wrap_pyfunction!(fit_hardening, m)?)?;
    Ok(())
}
