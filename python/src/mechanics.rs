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
use contactscope::surface::fill::FillInvalid;
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::{Detrend, Topography};
use contactscope_jobs::heights::TopographySource;

use crate::{bad, compute, PixelArg};

fn detrend_of(name: &str) -> PyResult<Detrend> {
    match name {
        "none" => Ok(Detrend::None),
        "mean" => Ok(Detrend::Mean),
        "plane" => Ok(Detrend::Plane),
        other => Err(bad(format!(
            "detrend '{other}' is not one of none, mean, plane"
        ))),
    }
}

/// A height map (rows = y, columns = x; m) and its pixel size as a topography.
fn topography(heights: &PyReadonlyArray2<'_, f64>, pixel: PixelArg) -> PyResult<Topography> {
    let (dx, dy) = pixel.xy()?;
    Topography::new(heights.as_array().to_owned(), dx, dy).map_err(crate::to_py)
}

fn heights_to_py<'py>(py: Python<'py>, t: Topography) -> Bound<'py, PyAny> {
    t.heights.into_pyarray(py).into_any()
}

/// Read a height map of any format contactscope reads (npy, TIFF, GSF, text, WSxM, Nanoscope
/// and the vendor AFM and profilometer formats recognised by content), in m, with its pixel
/// size (m), then detrend it ("none", "mean" or "plane", the command line's default). `channel`
/// names the channel of a multi-channel vendor file (default: its height channel); a map with
/// invalid points is refused unless `fill_invalid` is "mean" or "nearest" (the notes say how
/// many were filled).
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
    let source = TopographySource {
        path,
        pixel_size_m: crate::pixel_opt(pixel_size)?,
        height_unit_m: height_unit,
        detrend: detrend_of(detrend)?,
        channel,
        fill_invalid: match fill_invalid {
            None => None,
            Some("mean") => Some(FillInvalid::Mean),
            Some("nearest") => Some(FillInvalid::Nearest),
            Some(other) => {
                return Err(bad(format!(
                    "fill_invalid '{other}' is not one of mean, nearest"
                )))
            }
        },
    };
    let (t, notes) = compute(py, move || source.read_with_notes())?;
    let d = PyDict::new(py);
    d.set_item("pixel_size_m", (t.dx_m, t.dy_m))?;
    d.set_item("heights", heights_to_py(py, t))?;
    d.set_item("notes", notes)?;
    Ok(d)
}

/// A seeded self-affine random surface (heights in m, rows = y): `nx` × `ny` pixels of
/// `pixel_size` m, Hurst exponent `hurst`, scaled to `rms_height` (m) or `rms_slope`, with an
/// optional roll-off and short-wavelength cutoff (m).
#[pyfunction]
#[pyo3(signature = (nx, ny, pixel_size, hurst=0.8, rms_height=None, rms_slope=None, rolloff=None, cutoff=None, seed=0))]
#[allow(clippy::too_many_arguments)]
fn surface<'py>(
    py: Python<'py>,
    nx: usize,
    ny: usize,
    pixel_size: f64,
    hurst: f64,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let target = match (rms_height, rms_slope) {
        (Some(h), None) => RmsTarget::Height(h),
        (None, Some(s)) => RmsTarget::Slope(s),
        _ => return Err(bad("give exactly one of rms_height (m) and rms_slope")),
    };
    let params = SelfAffineParams {
        nx,
        ny,
        dx_m: pixel_size,
        hurst,
        rolloff_wavelength_m: rolloff,
        short_cutoff_wavelength_m: cutoff,
        target,
        seed,
    };
    let t = compute(py, move || self_affine(&params))?;
    Ok(heights_to_py(py, t))
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
