//! `info`: what a micrograph file holds (the job `contactscope_jobs::info`, as the command
//! line's `info --json`), in SI units with SI keys.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope_jobs::info::InfoRequest;

use crate::compute;
use crate::convert::outcome_dict;

/// The series, axes, sample type and voxel size (m) of a TIFF, CZI, ND2, LIF or OME-Zarr file and, with
/// `stats`, every plane's min, max, mean and sum.
#[pyfunction]
#[pyo3(signature = (path, stats=false))]
fn info<'py>(py: Python<'py>, path: PathBuf, stats: bool) -> PyResult<Bound<'py, PyDict>> {
    let request = InfoRequest {
        stats,
        ..InfoRequest::new(path)
    };
    let outcome = compute(py, move || contactscope_jobs::info::run(&request))?;
    outcome_dict(py, &outcome)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(info, m)?)?;
    Ok(())
}
