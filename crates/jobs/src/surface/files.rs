//! The output of `surface` as the command line writes it: the heights (m) as `.npy` or `.gsf`
//! (with the pixel size), written atomically.

use std::path::Path;

use contactscope_formats::topography::{encode_gsf, encode_npy};

use super::{run, SurfaceOutcome, SurfaceRequest};
use crate::error::{Error, Result};
use crate::staging::write_atomic;

/// Generate and write to `out`; an output name that is neither `.npy` nor `.gsf` is an error
/// (after the parameters were checked by generating).
pub fn run_to_file(request: &SurfaceRequest, out: &Path) -> Result<SurfaceOutcome> {
    let outcome = run(request)?;
    let t = &outcome.topography;
    let bytes = match out.extension().and_then(|e| e.to_str()) {
        Some("npy") => encode_npy(&t.heights),
        Some("gsf") => encode_gsf(&t.heights, (t.dx_m, t.dy_m)),
        _ => {
            return Err(Error::InvalidArgument(format!(
                "{}: the output must end in .npy or .gsf",
                out.display()
            )))
        }
    };
    write_atomic(out, &bytes)?;
    Ok(outcome)
}
