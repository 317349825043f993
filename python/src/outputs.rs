//! Output folders written from Python as the command line writes its own: every file staged
//! beside the folder, then renamed into place when all are written (`contactscope_jobs::staging`).

use std::path::PathBuf;

use pyo3::prelude::*;

use crate::{bad, compute};
use contactscope_jobs::staging::{check_out_dir, Staging};

/// Write `files` (pairs of a plain file name and its bytes) as the output folder `out`: all of
/// them or none, replacing a folder an earlier contactscope run wrote as a whole and refusing any
/// other non-empty folder (the command line's `--out` rules). Returns the paths written.
#[pyfunction]
#[pyo3(signature = (out, files))]
fn write_folder(
    py: Python<'_>,
    out: PathBuf,
    files: Vec<(String, Vec<u8>)>,
) -> PyResult<Vec<PathBuf>> {
    for (name, _) in &files {
        let plain = !name.is_empty()
            && !name.starts_with('.')
            && !name.contains(['/', '\\'])
            && name != "..";
        if !plain {
            return Err(bad(format!(
                "output file name '{name}' is not a plain file name"
            )));
        }
    }
    compute(py, move || -> contactscope_jobs::Result<Vec<PathBuf>> {
        let staging = Staging::new(&out, &[])?;
        for (name, bytes) in &files {
            staging.write(name, bytes)?;
        }
        staging.commit()
    })
}

/// Refuse, before any work, an output folder `write_folder` would refuse (in the way, or
/// holding files no contactscope run wrote): the command line's `--out` rules, checked early.
#[pyfunction]
fn check_out_folder(out: PathBuf) -> PyResult<()> {
    check_out_dir(&out, &[]).map_err(crate::to_py)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(write_folder, m)?)?;
    m.add_function(wrap_pyfunction!(check_out_folder, m)?)?;
    Ok(())
}
