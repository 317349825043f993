//! The library's seeded generators with known truth (a load series, beads, Newton rings) and a
//! TIFF writer, so that examples and tests can make inputs for both the API and the command
//! line without other packages. SI units.

use std::path::PathBuf;

use ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope::synth::beads::{synth_beads as make_beads, BeadParams};
use contactscope::synth::rings::{synth_newton as make_newton, NewtonSynthParams};
use contactscope::synth::SynthParams;
use contactscope_formats::tiff::write::{encode_f32_stack, encode_u16_stack};
use contactscope_jobs::synth_series::SynthSeriesRequest;

use crate::convert::outcome_dict;
use crate::{bad, compute, pixel_opt, PixelArg};

fn stack_u16<'py>(
    py: Python<'py>,
    planes: Vec<Vec<u16>>,
    h: usize,
    w: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let n = planes.len();
    let v: Vec<u16> = planes.into_iter().flatten().collect();
    Ok(Array3::from_shape_vec((n, h, w), v)
        .map_err(|e| bad(format!("stack: {e}")))?
        .into_pyarray(py)
        .into_any())
}

/// A synthetic confocal load series (12-bit in uint16) of a rough sphere on the rigidochromic
/// flat (the job `contactscope_jobs::synth_series`, as the command line's `synth-series`, with
/// its defaults and range checks; `None` keyword = its default): `width` × `height` pixels of
/// `pixel_size` m, one image per force (N). Returns the outcome in SI units (`forces_n`,
/// `true_area_m2`, `true_contact_pixels`) with the `images` and the true masks `truth`.
#[pyfunction]
#[pyo3(signature = (width=None, height=None, pixel_size=None, forces=None, seed=None))]
fn synth_series<'py>(
    py: Python<'py>,
    width: Option<usize>,
    height: Option<usize>,
    pixel_size: Option<f64>,
    forces: Option<Vec<f64>>,
    seed: Option<u64>,
) -> PyResult<Bound<'py, PyDict>> {
    let defaults = SynthSeriesRequest::default().params;
    let request = SynthSeriesRequest {
        params: SynthParams {
            width: width.unwrap_or(defaults.width),
            height: height.unwrap_or(defaults.height),
            pixel_size_m: pixel_size.unwrap_or(defaults.pixel_size_m),
            forces_n: forces.unwrap_or_else(|| defaults.forces_n.clone()),
            seed: seed.unwrap_or(defaults.seed),
            ..defaults
        },
    };
    let (w, h) = (request.params.width, request.params.height);
    let mut outcome = compute(py, move || contactscope_jobs::synth_series::run(&request))?;
    let images = std::mem::take(&mut outcome.images);
    let d = outcome_dict(py, &outcome)?;
    let truth: Vec<bool> = images
        .iter()
        .flat_map(|i| i.truth.iter().copied())
        .collect();
    d.set_item(
        "truth",
        Array3::from_shape_vec((images.len(), h, w), truth)
            .map_err(|e| bad(format!("truth: {e}")))?
            .into_pyarray(py),
    )?;
    let planes = images.into_iter().map(|i| i.codes).collect();
    d.set_item("images", stack_u16(py, planes, h, w)?)?;
    Ok(d)
}

/// A synthetic bead image or z stack (12-bit in uint16): `beads` Gaussian spots of σ =
/// `sigma_px` pixels on `planes` planes, seeded.
#[pyfunction]
#[pyo3(signature = (width=128, height=128, planes=1, beads=6, sigma_px=1.91, seed=7))]
fn synth_beads<'py>(
    py: Python<'py>,
    width: usize,
    height: usize,
    planes: usize,
    beads: usize,
    sigma_px: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let params = BeadParams {
        width,
        height,
        planes,
        beads,
        sigma_px,
        seed,
        ..BeadParams::default()
    };
    let b = compute(py, move || make_beads(&params))?;
    stack_u16(py, b.planes, b.height, b.width)
}

/// A synthetic Newton-ring reflection image and fluorescence image of one contact (uint16):
/// contact radius and detection gap in m, on `pixel_size` m pixels; with the true values.
#[pyfunction]
#[pyo3(signature = (width=256, height=256, pixel_size=200e-9, contact_radius=12e-6, detection_gap=9e-9, seed=7))]
fn synth_newton<'py>(
    py: Python<'py>,
    width: usize,
    height: usize,
    pixel_size: f64,
    contact_radius: f64,
    detection_gap: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyDict>> {
    // The checks every pixel size gets (positive, finite, plausible).
    let (pixel_size, _) = crate::PixelArg::Square(pixel_size).xy()?;
    let params = NewtonSynthParams {
        width,
        height,
        pixel_size_m: pixel_size,
        centre_px: (width as f64 / 2.0, height as f64 / 2.0),
        contact_radius_m: contact_radius,
        detection_gap_m: detection_gap,
        seed,
        ..NewtonSynthParams::default()
    };
    let s = compute(py, move || make_newton(&params))?;
    let as2 = |v: Vec<u16>| {
        Array2::from_shape_vec((height, width), v).map_err(|e| bad(format!("image: {e}")))
    };
    let d = PyDict::new(py);
    d.set_item("reflection", as2(s.reflection)?.into_pyarray(py))?;
    d.set_item("fluorescence", as2(s.fluorescence)?.into_pyarray(py))?;
    d.set_item("detection_gap_m", s.truth.detection_gap_m)?;
    d.set_item("contact_radius_m", s.truth.contact_radius_m)?;
    d.set_item("sphere_radius_m", s.truth.sphere_radius_m)?;
    Ok(d)
}

/// A stack for the TIFF writer: uint16 codes or float32 values.
#[derive(FromPyObject)]
enum TiffStack<'py> {
    U16(PyReadonlyArray3<'py, u16>),
    F32(PyReadonlyArray3<'py, f32>),
}

/// Write a stack (pages, rows, columns) of uint16 or float32 as a multi-page TIFF, with the pixel
/// size (m) in its metadata when given.
#[pyfunction]
#[pyo3(signature = (path, stack, pixel_size=None))]
fn write_tiff(
    py: Python<'_>,
    path: PathBuf,
    stack: TiffStack<'_>,
    pixel_size: Option<PixelArg>,
) -> PyResult<()> {
    let px = pixel_opt(pixel_size)?;
    let bytes = match stack {
        TiffStack::U16(a) => {
            let a = a.as_array();
            let (_, h, w) = a.dim();
            let pages: Vec<Vec<u16>> = a
                .outer_iter()
                .map(|p| p.iter().copied().collect())
                .collect();
            compute(py, move || {
                let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
                encode_u16_stack(&refs, w, h, px, "")
            })?
        }
        TiffStack::F32(a) => {
            let a = a.as_array();
            let (_, h, w) = a.dim();
            let pages: Vec<Vec<f32>> = a
                .outer_iter()
                .map(|p| p.iter().copied().collect())
                .collect();
            compute(py, move || {
                let refs: Vec<&[f32]> = pages.iter().map(Vec::as_slice).collect();
                encode_f32_stack(&refs, w, h, px, "")
            })?
        }
    };
    std::fs::write(&path, bytes)
        .map_err(|e| crate::FileError::new_err(format!("{}: {e}", path.display())))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(synth_series, m)?)?;
    m.add_function(wrap_pyfunction!(synth_beads, m)?)?;
    m.add_function(wrap_pyfunction!(synth_newton, m)?)?;
    m.add_function(wrap_pyfunction!(write_tiff, m)?)?;
    Ok(())
}
