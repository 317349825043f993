//! The mechanics tests from their CSV files (the formats of `contactscope_jobs::mechanics_csv`):
//! rheometer friction traces (the job `contactscope_jobs::friction`) and squeeze tests (the job
//! `contactscope_jobs::hertz`), as the command line's `friction` and `hertz`. The requests are
//! built from the keywords (SI units) with the jobs' own defaults and range checks; the results
//! are the jobs' outcomes in SI units with SI keys.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope_jobs::friction::FrictionRequest;
use contactscope_jobs::hertz::HertzRequest;

use crate::compute;
use crate::convert::outcome_dict;

/// Static and kinetic friction of each trace, μ, and τ of F_s = τ·A with `areas` (an
/// `areas.csv`); see the package's docstring.
#[pyfunction]
#[pyo3(signature = (traces, normal_force=None, rotation_radius=None, areas=None, force_tolerance=None))]
fn friction<'py>(
    py: Python<'py>,
    traces: Vec<PathBuf>,
    normal_force: Option<f64>,
    rotation_radius: Option<f64>,
    areas: Option<PathBuf>,
    force_tolerance: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let defaults = FrictionRequest::new(traces);
    let request = FrictionRequest {
        normal_force_n: normal_force,
        rotation_radius_m: rotation_radius,
        areas,
        force_tolerance: force_tolerance.unwrap_or(defaults.force_tolerance),
        ..defaults
    };
    let outcome = compute(py, move || contactscope_jobs::friction::run(&request))?;
    outcome_dict(py, &outcome)
}

/// The contact modulus E* from a squeeze test and the Hertz contact at `loads`; see the
/// package's docstring.
#[pyfunction]
#[pyo3(signature = (squeeze, radius, loads=None))]
fn hertz<'py>(
    py: Python<'py>,
    squeeze: PathBuf,
    radius: f64,
    loads: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = HertzRequest {
        loads_n: loads,
        ..HertzRequest::new(squeeze, radius)
    };
    let outcome = compute(py, move || contactscope_jobs::hertz::run(&request))?;
    outcome_dict(py, &outcome)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(friction, m)?)?;
    m.add_function(wrap_pyfunction!(hertz, m)?)?;
    Ok(())
}
