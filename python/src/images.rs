//! Micrographs: reading images and series, the global Otsu threshold, measuring, the series
//! analysis, the PSF, the autocorrelation, Newton rings, the microscope's blur and the comparison
//! of simulated maps with micrographs. Lengths in metres, forces in newtons.

use std::path::PathBuf;

use ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope::image::{Image, PixelSize, PixelSizeSource, Plane, SampleType, Samples};
use contactscope::numerics::stats::MeanSd;
use contactscope::optics::blur::{microscope_image, Grid};
use contactscope::optics::newton::{analyse, NewtonOptions};
use contactscope::optics::psf::{measure_psf, PsfOptions, FWHM_PER_SIGMA};
use contactscope::spectral::autocorrelation::AcfCurve;

use crate::{bad, compute, PixelArg};

/// Decoded planes of a stack as they came from Python, kept in their own sample type so that
/// the Otsu histogram bins exactly as the command line's (integer codes for integer data).
#[derive(FromPyObject)]
pub(crate) enum StackIn<'py> {
    U8(PyReadonlyArray3<'py, u8>),
    U16(PyReadonlyArray3<'py, u16>),
    I16(PyReadonlyArray3<'py, i16>),
    F32(PyReadonlyArray3<'py, f32>),
    F64(PyReadonlyArray3<'py, f64>),
}

impl StackIn<'_> {
    /// The planes (one copy into the library's plane type).
    pub(crate) fn planes(&self) -> PyResult<Vec<Plane>> {
        fn split<T: Copy>(
            a: ndarray::ArrayView3<'_, T>,
            f: impl Fn(Vec<T>, usize, usize) -> Plane,
        ) -> Vec<Plane> {
            let (_, h, w) = a.dim();
            a.outer_iter()
                .map(|p| f(p.iter().copied().collect(), w, h))
                .collect()
        }
        let planes = match self {
            StackIn::U8(a) => split(a.as_array(), |v, w, h| Plane {
                width: w,
                height: h,
                sample_type: SampleType::U8,
                samples: Samples::Int {
                    codes: v.into_iter().map(u16::from).collect(),
                    offset: 0,
                },
            }),
            StackIn::U16(a) => split(a.as_array(), |v, w, h| Plane::from_u16(w, h, v)),
            StackIn::I16(a) => split(a.as_array(), |v, w, h| Plane {
                width: w,
                height: h,
                sample_type: SampleType::I16,
                samples: Samples::Int {
                    codes: v
                        .into_iter()
                        .map(|x| (i32::from(x) + 32768) as u16)
                        .collect(),
                    offset: -32768,
                },
            }),
            StackIn::F32(a) => split(a.as_array(), |v, w, h| Plane {
                width: w,
                height: h,
                sample_type: SampleType::F32,
                samples: Samples::Float(v),
            }),
            StackIn::F64(a) => split(a.as_array(), |v, w, h| Plane {
                width: w,
                height: h,
                sample_type: SampleType::F64,
                samples: Samples::Float(v.into_iter().map(|x| x as f32).collect()),
            }),
        };
        if planes.is_empty() || planes[0].is_empty() {
            return Err(bad("the image stack is empty"));
        }
        Ok(planes)
    }
}

/// float64 images with a pixel size, as the optics code takes them.
fn f64_images(stack: &PyReadonlyArray3<'_, f64>, pixel: (f64, f64), label: &str) -> Vec<Image> {
    let a = stack.as_array();
    let (_, h, w) = a.dim();
    a.outer_iter()
        .enumerate()
        .map(|(page, p)| Image {
            values: p.iter().copied().collect(),
            width: w,
            height: h,
            pixel_size: Some(PixelSize {
                x_m: pixel.0,
                y_m: pixel.1,
                source: PixelSizeSource::CommandLine,
            }),
            path: PathBuf::from(label),
            page,
        })
        .collect()
}

fn mean_sd<'py>(py: Python<'py>, m: &MeanSd) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("mean", m.mean)?;
    d.set_item("sd", m.sd)?;
    Ok(d)
}

/// The PSF from sub-resolution beads: one image or a z stack (planes, rows, columns) of
/// float64, pixel size in m; σ and FWHM in m (bead-corrected with `bead_diameter`, m).
#[pyfunction]
#[pyo3(signature = (beads, pixel_size, bead_diameter=None, saturation_level=None))]
fn psf<'py>(
    py: Python<'py>,
    beads: PyReadonlyArray3<'py, f64>,
    pixel_size: PixelArg,
    bead_diameter: Option<f64>,
    saturation_level: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let images = f64_images(&beads, pixel_size.xy()?, "beads");
    let options = PsfOptions {
        bead_diameter_m: bead_diameter,
        saturation_level,
        ..PsfOptions::default()
    };
    let report = compute(py, move || measure_psf(&images, &options))?;
    let d = PyDict::new(py);
    let s = &report.summary;
    d.set_item("beads_used", s.beads_used)?;
    d.set_item("sigma_m", mean_sd(py, &s.sigma_m)?)?;
    d.set_item("fwhm_m", s.sigma_m.mean * FWHM_PER_SIGMA)?;
    d.set_item("sigma_raw_m", mean_sd(py, &s.sigma_raw_m)?)?;
    d.set_item("sigma_x_m", mean_sd(py, &s.sigma_x_m)?)?;
    d.set_item("sigma_y_m", mean_sd(py, &s.sigma_y_m)?)?;
    let beads = PyList::empty(py);
    for b in &report.beads {
        let e = PyDict::new(py);
        e.set_item("x_px", b.candidate.x)?;
        e.set_item("y_px", b.candidate.y)?;
        e.set_item("plane", b.candidate.plane)?;
        e.set_item("sigma_m", b.sigma_m)?;
        e.set_item("sigma_raw_m", b.sigma_raw_m)?;
        e.set_item("used", b.skip.is_none())?;
        e.set_item("skip_reason", b.skip.as_ref().map(|r| r.to_string()))?;
        beads.append(e)?;
    }
    d.set_item("beads", beads)?;
    Ok(d)
}

/// Radially averaged intensity autocorrelation C(r) of one image (pixel size in m) up to
/// `max_lag` (m; default half the shorter side), with the correlation lengths ξ(1/e) and the
/// first zero crossing in m.
#[pyfunction]
#[pyo3(signature = (image, pixel_size, max_lag=None))]
fn autocorrelation<'py>(
    py: Python<'py>,
    image: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    max_lag: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (dx, dy) = pixel_size.xy()?;
    let a = image.as_array();
    let (h, w) = a.dim();
    let values: Vec<f64> = a.iter().copied().collect();
    let lag = max_lag.unwrap_or(0.5 * (w as f64 * dx).min(h as f64 * dy));
    let curve = compute(py, move || {
        AcfCurve::of_grid("image", &values, (w, h), (dx, dy), lag)
    })?;
    let (r, c): (Vec<f64>, Vec<f64>) = curve.profile.iter().copied().unzip();
    let d = PyDict::new(py);
    d.set_item("lag_m", r.into_pyarray(py))?;
    d.set_item("c", c.into_pyarray(py))?;
    d.set_item("xi_1e_m", curve.xi_1e_m)?;
    d.set_item("first_zero_m", curve.first_zero_m)?;
    Ok(d)
}

/// The detection gap from Newton rings: a reflection image with rings and a fluorescence image
/// of the contact (same field, float64, pixel size in m); wavelength in m.
#[pyfunction]
#[pyo3(signature = (reflection, contact, pixel_size, wavelength=488e-9, medium_index=1.447, profiles=20))]
fn newton<'py>(
    py: Python<'py>,
    reflection: PyReadonlyArray2<'py, f64>,
    contact: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    wavelength: f64,
    medium_index: f64,
    profiles: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let px = pixel_size.xy()?;
    let one = |a: &PyReadonlyArray2<'py, f64>, label: &str| {
        let v = a.as_array();
        let (h, w) = v.dim();
        Image {
            values: v.iter().copied().collect(),
            width: w,
            height: h,
            pixel_size: Some(PixelSize {
                x_m: px.0,
                y_m: px.1,
                source: PixelSizeSource::CommandLine,
            }),
            path: PathBuf::from(label),
            page: 0,
        }
    };
    let (r, f) = (one(&reflection, "reflection"), one(&contact, "contact"));
    let options = NewtonOptions {
        wavelength_m: wavelength,
        medium_index,
        profiles,
        ..NewtonOptions::default()
    };
    let a = compute(py, move || analyse(&r, &f, &options))?;
    let d = PyDict::new(py);
    d.set_item("detection_gap_m", mean_sd(py, &a.detection_gap_m)?)?;
    d.set_item("edge_radius_m", mean_sd(py, &a.edge_radius_m)?)?;
    d.set_item("contact_radius_m", mean_sd(py, &a.contact_radius_m)?)?;
    d.set_item("sphere_radius_m", mean_sd(py, &a.sphere_radius_m)?)?;
    d.set_item("profiles_used", a.used().count())?;
    d.set_item("profiles", a.profiles.len())?;
    d.set_item("contact_threshold", a.contact.threshold)?;
    d.set_item("centre_px", a.contact.centre_px)?;
    Ok(d)
}

/// What the microscope makes of a map (e.g. a simulated contact map, 1 = contact): Gaussian
/// blur of FWHM `fwhm` (m) on the map's grid (`pixel_size`, m), then area-integrated onto image
/// pixels of `image_pixel_size` (m). A binary map's result sums to its area in image pixels.
#[pyfunction]
fn blur_and_resample<'py>(
    py: Python<'py>,
    map: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    fwhm: f64,
    image_pixel_size: PixelArg,
) -> PyResult<Bound<'py, PyAny>> {
    let (dx, dy) = pixel_size.xy()?;
    let image_px = image_pixel_size.xy()?;
    let a = map.as_array();
    let (h, w) = a.dim();
    let values: Vec<f64> = a.iter().copied().collect();
    let out = compute(py, move || {
        let grid = Grid::new(values, w, h, dx, dy)?;
        microscope_image(&grid, fwhm, image_px)
    })?;
    Ok(Array2::from_shape_vec((out.height, out.width), out.values)
        .map_err(|e| bad(format!("grid: {e}")))?
        .into_pyarray(py)
        .into_any())
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(psf, m)?)?;
    m.add_function(wrap_pyfunction!(autocorrelation, m)?)?;
    m.add_function(wrap_pyfunction!(newton, m)?)?;
    m.add_function(wrap_pyfunction!(blur_and_resample, m)?)?;
    Ok(())
}
