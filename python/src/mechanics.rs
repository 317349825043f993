//! Height maps and contact mechanics: reading AFM/profilometer files, generating self-affine
//! surfaces, load ramps with the paper's contact models (elastic, penetration hardness, linear
//! hardening, Greenwood–Tripp) and the fit of the hardening coefficient. SI units: heights and
//! lengths in m, forces in N, pressures and moduli in Pa, k in Pa/m (4 MPa/nm = 4e15 Pa/m).

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope::surface::generate::RmsTarget;
use contactscope_formats::param::Param;
use contactscope_jobs::heights::TopographySource;
use contactscope_jobs::surface::SurfaceRequest;
use contactscope_jobs::topography::TopographyRequest;

use crate::convert::outcome_dict;
use crate::extract::{HeightChannel, Measurement};
use crate::heights::{detrend_of, fill_of};
use crate::{bad, compute, PixelArg};

/// Read a height map of any format contactscope reads (the job `contactscope_jobs::topography`,
/// as the command line's `topography`): the outcome in SI units (`summary`: `topography --json`;
/// `notes`) and `heights` (m, rows = y, filled as asked and detrended). A map that cannot be used
/// (invalid points without `fill_invalid`) is refused with the reason.
#[pyfunction]
#[pyo3(signature = (path, pixel_size=None, height_unit=None, detrend="plane", channel=None, fill_invalid=None, measurement=None))]
#[allow(clippy::too_many_arguments)]
fn read_topography<'py>(
    py: Python<'py>,
    path: PathBuf,
    pixel_size: Option<PixelArg>,
    height_unit: Option<f64>,
    detrend: &str,
    channel: Option<HeightChannel>,
    fill_invalid: Option<&str>,
    measurement: Option<Measurement>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = TopographyRequest {
        source: TopographySource {
            measurement: measurement.map(|m| m.0),
            pixel_size_m: crate::pixel_opt(pixel_size)?,
            height_unit_m: height_unit,
            detrend: detrend_of(detrend)?,
            channel: channel.map(|c| c.0),
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

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(surface, m)?)?;
    Ok(())
}
