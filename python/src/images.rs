//! Micrographs: reading images and series, the global Otsu threshold, measuring, the series
//! analysis, the PSF, the autocorrelation, Newton rings, the microscope's blur and the comparison
//! of simulated maps with micrographs. Lengths in metres, forces in newtons.

use std::collections::BTreeMap;
use std::path::PathBuf;

use ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope::analysis::fit::fit_power_law;
use contactscope::analysis::{self, AnalysisOptions, PlaneSource};
use contactscope::compare::{compare_maps, CompareSettings, Micrograph, Micrographs, SimulatedMap};
use contactscope::image::{Image, PixelSize, PixelSizeSource, Plane, SampleType, Samples};
use contactscope::numerics::stats::MeanSd;
use contactscope::optics::blur::{microscope_image, Grid};
use contactscope::optics::newton::{analyse, NewtonOptions};
use contactscope::optics::psf::{measure_psf, PsfOptions, FWHM_PER_SIGMA};
use contactscope::spectral::autocorrelation::AcfCurve;
use contactscope::threshold::{Method, Threshold};
use contactscope_formats::microscopy::select::{read_images, LoadAxis, Selection};
use contactscope_jobs::series::{self, Series};

use crate::{bad, compute, pixel_opt, PixelArg};

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

/// Planes as one numpy array in the file's own type (uint8, uint16, int16 or float32).
fn planes_to_py<'py>(py: Python<'py>, planes: &[Plane]) -> PyResult<Bound<'py, PyAny>> {
    let shape = (planes.len(), planes[0].height, planes[0].width);
    /// Every value of every plane as `T` (the values fit: `T` is the planes' own type).
    fn stack<'py, T: numpy::Element>(
        py: Python<'py>,
        planes: &[Plane],
        shape: (usize, usize, usize),
        cast: impl Fn(f64) -> T,
    ) -> PyResult<Bound<'py, PyAny>> {
        let values: Vec<T> = planes
            .iter()
            .flat_map(|p| (0..p.len()).map(|i| cast(p.value(i))))
            .collect();
        Ok(Array3::from_shape_vec(shape, values)
            .map_err(|e| bad(format!("planes of different sizes: {e}")))?
            .into_pyarray(py)
            .into_any())
    }
    match planes[0].sample_type {
        SampleType::U8 => stack(py, planes, shape, |v| v as u8),
        SampleType::U16 => stack(py, planes, shape, |v| v as u16),
        SampleType::I16 => stack(py, planes, shape, |v| v as i16),
        // The library keeps float samples as f32.
        SampleType::F32 | SampleType::F64 => stack(py, planes, shape, |v| v as f32),
    }
}

fn pixel_size_dict<'py>(py: Python<'py>, p: Option<PixelSize>) -> PyResult<Bound<'py, PyAny>> {
    Ok(match p {
        Some(p) => (p.x_m, p.y_m).into_pyobject(py)?.into_any(),
        None => py.None().into_bound(py),
    })
}

/// The selection of a CZI, ND2 or LIF file (and the channel of a TIFF), as the command line's
/// `--series`, `--channel`, `--z`, `--t` and `--axis NAME=INDEX`.
fn selection(
    series: Option<usize>,
    channel: Option<usize>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
) -> Selection {
    Selection {
        series,
        channel,
        z,
        t,
        extra: axes.unwrap_or_default(),
    }
}

/// `"t"`, `"z"` or `"series"` as the command line's `--load-axis`.
fn load_axis_of(name: Option<&str>) -> PyResult<Option<LoadAxis>> {
    match name {
        None => Ok(None),
        Some("t") => Ok(Some(LoadAxis::T)),
        Some("z") => Ok(Some(LoadAxis::Z)),
        Some("series") => Ok(Some(LoadAxis::Series)),
        Some(other) => Err(bad(format!(
            "load_axis '{other}' is not one of t, z, series"
        ))),
    }
}

/// Images of a TIFF (every page of one channel) or of a CZI, ND2 or LIF file (the plane the
/// selection names, or every plane along `load_axis`) as float64 (images, rows, columns), with
/// the pixel size (m) from the file or `pixel_size`.
#[pyfunction]
#[pyo3(signature = (path, channel=None, pixel_size=None, series=None, z=None, t=None, axes=None, load_axis=None))]
#[allow(clippy::too_many_arguments)]
fn read_image<'py>(
    py: Python<'py>,
    path: PathBuf,
    channel: Option<usize>,
    pixel_size: Option<PixelArg>,
    series: Option<usize>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
    load_axis: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let px = pixel_opt(pixel_size)?;
    let along = load_axis_of(load_axis)?;
    let chosen = selection(series, channel, z, t, axes);
    let pages = compute(py, || read_images(&path, &chosen, along, px))?;
    let (h, w) = (pages[0].height, pages[0].width);
    let values: Vec<f64> = pages
        .iter()
        .flat_map(|p| p.values.iter().copied())
        .collect();
    let array = Array3::from_shape_vec((pages.len(), h, w), values)
        .map_err(|e| bad(format!("pages of different sizes: {e}")))?;
    let d = PyDict::new(py);
    d.set_item("images", array.into_pyarray(py))?;
    d.set_item("pixel_size_m", pixel_size_dict(py, pages[0].pixel_size)?)?;
    d.set_item(
        "pixel_size_source",
        pages[0].pixel_size.map(|p| p.source.describe()),
    )?;
    d.set_item("path", path)?;
    Ok(d)
}

/// A load series from files (TIFF, CZI, ND2, LIF; folders in natural order) or a manifest CSV:
/// the planes in their own sample type, forces (N), file and page of each image and the pixel
/// size (m). A vendor file gives the plane its selection names, or every plane along
/// `load_axis` (one load each).
#[pyfunction]
#[pyo3(signature = (inputs, channel=None, forces=None, pixel_size=None, manifest=false, series=None, z=None, t=None, axes=None, load_axis=None))]
#[allow(clippy::too_many_arguments)]
fn read_series<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    channel: Option<usize>,
    forces: Option<Vec<f64>>,
    pixel_size: Option<PixelArg>,
    manifest: bool,
    series: Option<usize>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
    load_axis: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let px = pixel_opt(pixel_size)?;
    let along = load_axis_of(load_axis)?;
    let chosen = selection(series, channel, z, t, axes);
    let (series, planes, size, warnings) = compute(py, move || {
        let mut series: Series = if manifest {
            if inputs.len() != 1 {
                return Err(contactscope::error::Error::InvalidArgument(
                    "give one manifest".into(),
                ));
            }
            series::from_manifest_selected(&inputs[0], &chosen, along)?
        } else {
            series::from_files_selected(&inputs, &chosen, along)?
        };
        if let Some(f) = &forces {
            series::assign_forces(&mut series, f)?;
        }
        let mut warnings = Vec::new();
        let size = series::pixel_size(&series, px, &mut warnings)?;
        let planes = series.planes(0).scan(|_, p| Ok(p.clone()))?;
        Ok((series, planes, size, warnings))
    })?;
    let d = PyDict::new(py);
    d.set_item("images", planes_to_py(py, &planes)?)?;
    d.set_item(
        "forces_n",
        series.images.iter().map(|i| i.force_n).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "paths",
        series
            .images
            .iter()
            .map(|i| i.path.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pages",
        series.images.iter().map(|i| i.page).collect::<Vec<_>>(),
    )?;
    d.set_item("pixel_size_m", pixel_size_dict(py, size)?)?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

/// One exact Otsu threshold over the pooled histogram of all images (the paper's rule), in the
/// images' intensity units; contact is value > threshold.
#[pyfunction]
fn otsu_threshold<'py>(py: Python<'py>, images: StackIn<'py>) -> PyResult<Bound<'py, PyDict>> {
    let planes = images.planes()?;
    let (t, pixels, warnings) = compute(py, move || {
        analysis::global_threshold(planes.as_slice(), &|_, _, _| {})
    })?;
    let d = PyDict::new(py);
    d.set_item("threshold", t.value)?;
    d.set_item("pixels", pixels)?;
    d.set_item("warnings", warnings)?;
    Ok(d)
}

fn measurement_dict<'py>(
    py: Python<'py>,
    m: &contactscope::measure::Measurement,
    pixel_m2: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("contact_pixels", m.contact_pixels)?;
    d.set_item("area_m2", pixel_m2.map(|a| a * m.contact_pixels as f64))?;
    d.set_item("finite_pixels", m.finite_pixels)?;
    d.set_item("mean_intensity", m.mean_intensity)?;
    d.set_item("integrated_intensity", m.integrated_intensity)?;
    d.set_item("background_mean", m.background_mean)?;
    d.set_item("patches", m.patches)?;
    d.set_item("largest_patch_pixels", m.largest_patch_pixels)?;
    d.set_item(
        "largest_patch_m2",
        pixel_m2.map(|a| a * m.largest_patch_pixels as f64),
    )?;
    Ok(d)
}

/// Contact (value > threshold) of one image: pixels, area (m², with a pixel size), intensities,
/// 8-connected patches and the contact mask.
#[pyfunction]
#[pyo3(signature = (image, threshold, pixel_size=None))]
fn measure<'py>(
    py: Python<'py>,
    image: StackIn<'py>,
    threshold: f64,
    pixel_size: Option<PixelArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let px = pixel_opt(pixel_size)?;
    let mut planes = image.planes()?;
    if planes.len() != 1 {
        return Err(bad(format!(
            "measure takes one image (2-D array); got {} planes",
            planes.len()
        )));
    }
    let plane = planes.remove(0);
    if !threshold.is_finite() {
        return Err(bad(format!("threshold {threshold} is not a finite number")));
    }
    let t = Threshold::manual(threshold, &plane.samples);
    let (m, mask) = compute(py, move || contactscope::measure::measure(&plane, &t))?;
    let d = measurement_dict(py, &m, px.map(|(x, y)| x * y))?;
    let mask = Array2::from_shape_vec((mask.height, mask.width), mask.as_bools())
        .map_err(|e| bad(format!("mask: {e}")))?;
    d.set_item("mask", mask.into_pyarray(py))?;
    Ok(d)
}

/// The method as the command line names it: "otsu", "per-image" or a number.
#[derive(FromPyObject)]
enum MethodArg {
    Manual(f64),
    Name(String),
}

/// The two-pass series analysis (one global Otsu threshold over the pooled histogram, then every
/// image measured), with areas in m² when a pixel size (m) is given and the power-law fit
/// A = c·N^β over the images with a force (N).
#[pyfunction]
#[pyo3(signature = (images, forces=None, pixel_size=None, method=None))]
fn analyze<'py>(
    py: Python<'py>,
    images: StackIn<'py>,
    forces: Option<Vec<f64>>,
    pixel_size: Option<PixelArg>,
    method: Option<MethodArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let planes = images.planes()?;
    let method = match method {
        None => Method::GlobalOtsu,
        Some(MethodArg::Manual(t)) => Method::Manual(t),
        Some(MethodArg::Name(n)) => Method::parse(&n).map_err(crate::to_py)?,
    };
    if let Some(f) = &forces {
        if f.len() != planes.len() {
            return Err(bad(format!(
                "{} forces for {} images",
                f.len(),
                planes.len()
            )));
        }
        if let Some(bad_force) = f.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(bad(format!(
                "force {bad_force:e} N is not positive (forces are in newtons: 4 mN is 0.004)"
            )));
        }
    }
    let px = pixel_opt(pixel_size)?;
    let options = AnalysisOptions {
        method,
        pixel_size: px.map(|(x_m, y_m)| PixelSize {
            x_m,
            y_m,
            source: PixelSizeSource::CommandLine,
        }),
    };
    let result = compute(py, move || {
        analysis::analyze(
            planes.as_slice(),
            &options,
            &|_, _, _| {},
            &|_, _, _| Ok(()),
        )
    })?;
    let pixel_m2 = px.map(|(x, y)| x * y);
    let rows = PyList::empty(py);
    let (mut fx, mut fy) = (Vec::new(), Vec::new());
    for (i, r) in result.images.iter().enumerate() {
        let d = measurement_dict(py, &r.measurement, pixel_m2)?;
        let force = forces.as_ref().map(|f| f[i]);
        d.set_item("image", i)?;
        d.set_item("force_n", force)?;
        d.set_item("threshold", r.threshold.value)?;
        // As the CLI's areas.csv: force / area (Pa) and the radius of a disc of that area (m).
        let area_m2 = pixel_m2.map(|a| a * r.measurement.contact_pixels as f64);
        d.set_item(
            "mean_pressure_pa",
            match (force, area_m2) {
                (Some(f), Some(a)) if a > 0.0 => Some(f / a),
                _ => None,
            },
        )?;
        d.set_item(
            "equivalent_radius_m",
            area_m2.map(|a| (a / std::f64::consts::PI).sqrt()),
        )?;
        if let Some(f) = force {
            fx.push(f);
            fy.push(pixel_m2.unwrap_or(1.0) * r.measurement.contact_pixels as f64);
        }
        rows.append(d)?;
    }
    let d = PyDict::new(py);
    d.set_item("rows", rows)?;
    d.set_item("threshold", result.series_threshold.map(|t| t.value))?;
    d.set_item("histogram_pixels", result.histogram_pixels)?;
    d.set_item("warnings", result.warnings)?;
    let fit = fit_power_law(&fx, &fy).map(|f| {
        let p = PyDict::new(py);
        p.set_item("exponent", f.exponent)?;
        p.set_item("exponent_se", f.exponent_se)?;
        p.set_item("prefactor", f.prefactor)?;
        p.set_item("r_squared", f.r_squared)?;
        p.set_item("points", f.points)?;
        Ok::<_, PyErr>(p)
    });
    d.set_item("power_law", fit.transpose()?)?;
    Ok(d)
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

/// Simulated contact maps against micrographs: each map (1 = contact; pixel size in m) at a
/// force (N) is matched to the micrograph at the same force (within `force_tolerance`), blurred
/// with the PSF (`psf_fwhm`, m), registered and scored (Dice, Jaccard, edge distance in m).
#[pyfunction]
#[pyo3(signature = (micrographs, forces, pixel_size, maps, map_forces, map_pixel_size, psf_fwhm, dihedral=false, upsample=20, force_tolerance=0.01))]
#[allow(clippy::too_many_arguments)]
fn compare<'py>(
    py: Python<'py>,
    micrographs: StackIn<'py>,
    forces: Vec<f64>,
    pixel_size: PixelArg,
    maps: PyReadonlyArray3<'py, f64>,
    map_forces: Vec<f64>,
    map_pixel_size: PixelArg,
    psf_fwhm: f64,
    dihedral: bool,
    upsample: usize,
    force_tolerance: f64,
) -> PyResult<Bound<'py, PyList>> {
    let planes = micrographs.planes()?;
    if forces.len() != planes.len() {
        return Err(bad(format!(
            "{} forces for {} micrographs",
            forces.len(),
            planes.len()
        )));
    }
    let m = maps.as_array();
    if map_forces.len() != m.dim().0 {
        return Err(bad(format!(
            "{} map forces for {} maps",
            map_forces.len(),
            m.dim().0
        )));
    }
    if upsample == 0 {
        return Err(bad("upsample must be at least 1"));
    }
    let (mdx, mdy) = map_pixel_size.xy()?;
    let (_, mh, mw) = m.dim();
    let sim_values: Vec<Vec<f64>> = m
        .outer_iter()
        .map(|p| p.iter().copied().collect())
        .collect();
    let pixel_m = pixel_size.xy()?;
    let settings = CompareSettings {
        psf_fwhm_m: psf_fwhm,
        dihedral,
        upsample,
        force_tolerance,
    };
    let result = compute(py, move || {
        let (t, _, warnings) = analysis::global_threshold(planes.as_slice(), &|_, _, _| {})?;
        let images = planes
            .into_iter()
            .zip(&forces)
            .enumerate()
            .map(|(page, (plane, &f))| Micrograph {
                plane,
                force_n: Some(f),
                path: PathBuf::from("micrographs"),
                page,
            })
            .collect();
        let micrographs = Micrographs {
            images,
            threshold: t.value,
            pixel_m,
            warnings,
        };
        let simulated = sim_values
            .into_iter()
            .zip(&map_forces)
            .enumerate()
            .map(|(i, (v, &f))| {
                Ok(SimulatedMap {
                    force_n: f,
                    map: Grid::new(v, mw, mh, mdx, mdy)?,
                    source: format!("map {i}"),
                })
            })
            .collect::<contactscope::error::Result<Vec<_>>>()?;
        compare_maps(&micrographs, &simulated, &settings)
    })?;
    let rows = PyList::empty(py);
    for l in &result.loads {
        let d = PyDict::new(py);
        d.set_item("force_n", l.force_n)?;
        d.set_item("simulated_force_n", l.simulated_force_n)?;
        d.set_item("micrograph", l.micrograph.1)?;
        d.set_item("shift_px", l.shift_px)?;
        d.set_item("correlation_peak", l.correlation_peak)?;
        d.set_item("experiment_area_m2", l.experiment_area_m2)?;
        d.set_item("simulated_area_m2", l.simulated_area_m2)?;
        d.set_item("simulated_raw_area_m2", l.simulated_raw_area_m2)?;
        d.set_item("dice", l.dice)?;
        d.set_item("jaccard", l.jaccard)?;
        d.set_item("edge_distance_m", l.edge_distance_m)?;
        d.set_item("xi_1e_m", l.xi_1e_m)?;
        rows.append(d)?;
    }
    Ok(rows)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(read_series, m)?)?;
    m.add_function(wrap_pyfunction!(otsu_threshold, m)?)?;
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    m.add_function(wrap_pyfunction!(analyze, m)?)?;
    m.add_function(wrap_pyfunction!(psf, m)?)?;
    m.add_function(wrap_pyfunction!(autocorrelation, m)?)?;
    m.add_function(wrap_pyfunction!(newton, m)?)?;
    m.add_function(wrap_pyfunction!(blur_and_resample, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
