//! Height maps and contact mechanics: reading AFM/profilometer files, generating self-affine
//! surfaces, load ramps with the paper's contact models (elastic, penetration hardness, linear
//! hardening, Greenwood–Tripp) and the fit of the hardening coefficient. SI units: heights and
//! lengths in m, forces in N, pressures and moduli in Pa, k in Pa/m (4 MPa/nm = 4e15 Pa/m).

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

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

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(surface, m)?)?;
    Ok(())
}
