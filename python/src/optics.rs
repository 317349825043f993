//! The optics jobs from Python: `psf`, `newton` and `autocorrelation` are the jobs
//! `contactscope_jobs::psf`, `::newton` and `::autocorr` with files (read as the command line
//! reads them, with its selection flags) or arrays in their stored sample type. The request is
//! built from the keywords (SI units; `None` = the request's default), the result is the job's
//! outcome in SI units (the command line's JSON file, SI keys), with the autocorrelation curves
//! as numpy arrays.

use std::collections::BTreeMap;
use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope::image::SampleType;
use contactscope::optics::newton::Phase;
use contactscope_formats::microscopy::select::Selection;
use contactscope_formats::param::Param;
use contactscope_jobs::autocorr::{self, AutocorrRequest};
use contactscope_jobs::images::{ImageInput, MemoryImages};
use contactscope_jobs::newton::NewtonRequest;
use contactscope_jobs::psf::PsfRequest;

use crate::convert::outcome_dict;
use crate::extract::ChannelArg;
use crate::images::StackIn;
use crate::{bad, compute, pixel_opt, PixelArg};

/// An image file, or a stack in its stored sample type.
enum ImageArg<'py> {
    /// A stack (planes, rows, columns).
    Stack(StackIn<'py>),
    /// A file (TIFF, CZI, ND2, LIF, OME-Zarr).
    File(PathBuf),
}

impl<'a, 'py> FromPyObject<'a, 'py> for ImageArg<'py> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Some(p) = crate::extract::path(&obj) {
            return Ok(ImageArg::File(p));
        }
        obj.extract::<StackIn<'py>>()
            .map(ImageArg::Stack)
            .map_err(|_| {
                crate::extract::wrong_type(
                    "an image",
                    "a file (TIFF, CZI, ND2, LIF, OME-Zarr) or a (planes, rows, columns) array of uint8, uint16, int16, float32 or float64",
                    &obj,
                )
            })
    }
}

impl ImageArg<'_> {
    /// The job's input; planes in memory are called `label`.
    fn input(self, label: &str) -> ImageInput {
        match self {
            ImageArg::File(path) => ImageInput::File(path),
            ImageArg::Stack(stack) => ImageInput::Memory(memory_images(&stack, label)),
        }
    }
}

/// The planes of a stack as `f64` values (exact for every stored type), with their type.
fn memory_images(stack: &StackIn<'_>, label: &str) -> MemoryImages {
    fn split<T: Copy>(
        a: ndarray::ArrayView3<'_, T>,
        f: impl Fn(T) -> f64,
    ) -> (Vec<Vec<f64>>, usize, usize) {
        let (_, h, w) = a.dim();
        let planes = a
            .outer_iter()
            .map(|p| p.iter().map(|&v| f(v)).collect())
            .collect();
        (planes, w, h)
    }
    let ((planes, width, height), sample_type) = match stack {
        StackIn::U8(a) => (split(a.as_array(), f64::from), SampleType::U8),
        StackIn::U16(a) => (split(a.as_array(), f64::from), SampleType::U16),
        StackIn::I16(a) => (split(a.as_array(), f64::from), SampleType::I16),
        StackIn::F32(a) => (split(a.as_array(), f64::from), SampleType::F32),
        StackIn::F64(a) => (split(a.as_array(), |v| v), SampleType::F64),
    };
    MemoryImages {
        label: label.into(),
        width,
        height,
        planes,
        sample_type,
    }
}

/// The selection keywords as the command line's `--series`, `--channel`, `--z`, `--t`,
/// `--axis`.
fn selection(
    series: Option<usize>,
    channel: Option<ChannelArg>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
) -> Selection {
    Selection {
        series,
        channel: channel.and_then(|c| c.0),
        z,
        t,
        extra: axes.unwrap_or_default(),
    }
}

/// The PSF from sub-resolution beads (the command line's `psf`): a bead image or z stack, as a
/// file or an array in its stored sample type. Returns the outcome (`psf.json` and the rows of
/// `beads.csv`) in SI units.
#[pyfunction]
#[pyo3(signature = (beads, pixel_size=None, bead_diameter=None, saturation_level=None, series=None, channel=None, z=None, t=None, axes=None))]
#[allow(clippy::too_many_arguments)]
fn psf<'py>(
    py: Python<'py>,
    beads: ImageArg<'py>,
    pixel_size: Option<PixelArg>,
    bead_diameter: Option<f64>,
    saturation_level: Option<f64>,
    series: Option<usize>,
    channel: Option<ChannelArg>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = PsfRequest {
        selection: selection(series, channel, z, t, axes),
        pixel_size_m: pixel_opt(pixel_size)?,
        bead_diameter_m: bead_diameter,
        saturation_level,
        ..PsfRequest::new(beads.input("beads"))
    };
    let outcome = compute(py, move || contactscope_jobs::psf::run(&request))?;
    outcome_dict(py, &outcome)
}

/// The detection gap from Newton rings (the command line's `newton`): the reflection image and
/// the fluorescence image of the contact, as files or arrays. Returns the outcome
/// (`newton.json` and the rows of `newton_rings.csv`) in SI units.
#[pyfunction]
#[pyo3(signature = (reflection, contact, pixel_size=None, wavelength=None, medium_index=None, profiles=None, phase=None, contact_channel=None, series=None, channel=None, z=None, t=None, axes=None))]
#[allow(clippy::too_many_arguments)]
fn newton<'py>(
    py: Python<'py>,
    reflection: ImageArg<'py>,
    contact: ImageArg<'py>,
    pixel_size: Option<PixelArg>,
    wavelength: Option<f64>,
    medium_index: Option<f64>,
    profiles: Option<usize>,
    phase: Option<&str>,
    contact_channel: Option<usize>,
    series: Option<usize>,
    channel: Option<ChannelArg>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut request = NewtonRequest::new(reflection.input("reflection"), contact.input("contact"));
    request.selection = selection(series, channel, z, t, axes);
    request.contact_channel = contact_channel;
    request.pixel_size_m = pixel_opt(pixel_size)?;
    let o = &mut request.options;
    o.wavelength_m = wavelength.unwrap_or(o.wavelength_m);
    o.medium_index = medium_index.unwrap_or(o.medium_index);
    o.profiles = profiles.unwrap_or(o.profiles);
    o.phase = match phase {
        None => o.phase,
        Some("half") => Phase::Half,
        Some("zero") => Phase::Zero,
        Some(other) => {
            return Err(bad(format!(
                "{}\"{other}\" is not one of half, zero",
                Param::Phase
            )))
        }
    };
    let outcome = compute(py, move || contactscope_jobs::newton::run(&request))?;
    outcome_dict(py, &outcome)
}

/// Radially averaged intensity autocorrelations (the command line's `autocorr`): image files
/// (every page of a multi-page TIFF is one image) or a stack (each plane one image). Returns
/// the outcome (`autocorr.json`) in SI units; each entry of its images gets its curve as
/// numpy arrays of lags (m) and C.
#[pyfunction]
#[pyo3(signature = (images, pixel_size=None, max_lag=None, series=None, channel=None, z=None, t=None, axes=None))]
#[allow(clippy::too_many_arguments)]
fn autocorrelation<'py>(
    py: Python<'py>,
    images: Vec<ImageArg<'py>>,
    pixel_size: Option<PixelArg>,
    max_lag: Option<f64>,
    series: Option<usize>,
    channel: Option<ChannelArg>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = AutocorrRequest {
        selection: selection(series, channel, z, t, axes),
        pixel_size_m: pixel_opt(pixel_size)?,
        max_lag_m: max_lag,
        ..AutocorrRequest::new(images.into_iter().map(|i| i.input("images")).collect())
    };
    let outcome = compute(py, move || autocorr::run(&request))?;
    let d = outcome_dict(py, &outcome)?;
    let rows = d
        .get_item("images")?
        .ok_or_else(|| bad("result: no images"))?
        .cast_into::<PyList>()?;
    for (row, curve) in rows.iter().zip(&outcome.curves) {
        let (lag, c): (Vec<f64>, Vec<f64>) = curve.profile.iter().copied().unzip();
        row.set_item("lag_m", lag.into_pyarray(py))?;
        row.set_item("acf", c.into_pyarray(py))?;
    }
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(psf, m)?)?;
    m.add_function(wrap_pyfunction!(newton, m)?)?;
    m.add_function(wrap_pyfunction!(autocorrelation, m)?)?;
    Ok(())
}
