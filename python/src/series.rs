//! Load series from Python: reading micrographs in their stored sample type (as tifffile
//! does), the global Otsu threshold and the series analysis — the jobs
//! `contactscope_jobs::threshold` and `contactscope_jobs::analyze` with files or arrays, so that
//! Python and the command line give one threshold and one set of areas.

use std::collections::BTreeMap;
use std::path::PathBuf;

use ndarray::{Array2, Array3};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope::analysis::Pass;
use contactscope::image::{PixelSize, Plane, SampleType};
use contactscope::threshold::{Method, Threshold};
use contactscope_formats::microscopy::select::{ChannelChoice, LoadAxis, Selection};
use contactscope_formats::param::Param;
use contactscope_jobs::analyze::files::{run_to_folder, ImageOutputs};
use contactscope_jobs::analyze::{AnalyzeRequest, HertzParams};
use contactscope_jobs::series::{self, MemorySeries, Micrographs, SeriesSpec};
use contactscope_jobs::threshold::{self, ThresholdRequest};

use crate::convert::outcome_dict;
use crate::images::StackIn;
use crate::{bad, compute, pixel_opt, PixelArg};

/// Planes as one numpy array in their stored type (uint8, uint16, int16 or float32).
pub(crate) fn planes_to_py<'py>(py: Python<'py>, planes: &[Plane]) -> PyResult<Bound<'py, PyAny>> {
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

fn pixel_size_py<'py>(py: Python<'py>, p: Option<PixelSize>) -> PyResult<Bound<'py, PyAny>> {
    Ok(match p {
        Some(p) => (p.x_m, p.y_m).into_pyobject(py)?.into_any(),
        None => py.None().into_bound(py),
    })
}

/// `"t"`, `"z"` or `"series"` as the command line's `--load-axis`.
fn load_axis_of(name: Option<&str>) -> PyResult<Option<LoadAxis>> {
    match name {
        None => Ok(None),
        Some("t") => Ok(Some(LoadAxis::T)),
        Some("z") => Ok(Some(LoadAxis::Z)),
        Some("series") => Ok(Some(LoadAxis::Series)),
        Some(other) => Err(bad(format!(
            "{}'{other}' is not one of t, z, series",
            Param::LoadAxis
        ))),
    }
}

/// The files of a series as the command line's inputs, `--manifest`, selection flags,
/// `--load-axis` and `--forces`.
pub(crate) struct SpecArgs {
    inputs: Vec<PathBuf>,
    manifest: Option<PathBuf>,
    series: Option<usize>,
    channel: Option<ChannelChoice>,
    z: Option<usize>,
    t: Option<usize>,
    axes: Option<BTreeMap<String, usize>>,
    load_axis: Option<String>,
    forces: Option<Vec<f64>>,
}

impl<'a, 'py> FromPyObject<'a, 'py> for SpecArgs {
    type Error = PyErr;

    /// The dict the Python layer's `_spec` builds from the keywords; each wrong value is
    /// answered naming its keyword.
    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        use crate::extract::{index, item};
        let obj: &Bound<'py, PyAny> = &obj;
        let get = |key: &str| obj.get_item(key).ok().filter(|v| !v.is_none());
        let idx = |key: &str| match get(key) {
            Some(v) => index(&v, &format!("{key}=")),
            None => Ok(None),
        };
        Ok(SpecArgs {
            inputs: item(obj, "inputs", "a path or a list of paths")?.unwrap_or_default(),
            manifest: item(obj, "manifest", "a path")?,
            series: idx("series")?,
            channel: match get("channel") {
                Some(v) => crate::extract::channel(&v)?,
                None => None,
            },
            z: idx("z")?,
            t: idx("t")?,
            axes: item(obj, "axes", "a dict of axis names to indices ({\"H\": 0})")?,
            load_axis: item(obj, "load_axis", "\"t\", \"z\" or \"series\"")?,
            forces: item(obj, "forces", "a sequence of forces in N")?,
        })
    }
}

impl SpecArgs {
    pub(crate) fn spec(self) -> PyResult<SeriesSpec> {
        Ok(SeriesSpec {
            inputs: self.inputs,
            manifest: self.manifest,
            selection: Selection {
                series: self.series,
                channel: self.channel,
                z: self.z,
                t: self.t,
                extra: self.axes.unwrap_or_default(),
            },
            load_axis: load_axis_of(self.load_axis.as_deref())?,
            forces_n: self.forces,
        })
    }
}

/// Every image of a series of files (TIFF, CZI, ND2, LIF; folders; a manifest) in its stored
/// sample type, with forces (N), files, pages, the pixel size (m) and warnings.
#[pyfunction]
#[pyo3(signature = (spec, pixel_size=None))]
fn read_series<'py>(
    py: Python<'py>,
    spec: SpecArgs,
    pixel_size: Option<PixelArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let spec = spec.spec()?;
    let px = pixel_opt(pixel_size)?;
    let loaded = compute(py, move || series::load(&spec, px))?;
    let d = PyDict::new(py);
    d.set_item("images", planes_to_py(py, &loaded.planes)?)?;
    d.set_item(
        "forces_n",
        loaded.images.iter().map(|i| i.force_n).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "paths",
        loaded
            .images
            .iter()
            .map(|i| i.path.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "pages",
        loaded.images.iter().map(|i| i.page).collect::<Vec<_>>(),
    )?;
    d.set_item("pixel_size_m", pixel_size_py(py, loaded.pixel_size)?)?;
    d.set_item(
        "pixel_size_source",
        loaded.pixel_size.map(|p| p.source.describe()),
    )?;
    d.set_item("warnings", loaded.warnings)?;
    Ok(d)
}

/// Images handed over as arrays, or the files of a series.
pub(crate) enum ImagesArg<'py> {
    /// A dict of the file spec (`read_series`' arguments).
    Files(SpecArgs),
    /// A stack in its stored sample type.
    Arrays(StackIn<'py>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for ImagesArg<'py> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if obj.is_instance_of::<PyDict>() {
            return obj.extract::<SpecArgs>().map(ImagesArg::Files);
        }
        obj.extract::<StackIn<'py>>()
            .map(ImagesArg::Arrays)
            .map_err(|_| {
                crate::extract::wrong_type(
                    "the images",
                    "files (paths, a folder, a manifest) or a (images, rows, columns) array of uint8, uint16, int16, float32 or float64",
                    &obj,
                )
            })
    }
}

/// The micrographs of a request: the files, or the arrays (with their forces).
pub(crate) fn micrographs(
    images: ImagesArg<'_>,
    forces: Option<Vec<f64>>,
) -> PyResult<Micrographs> {
    Ok(match images {
        ImagesArg::Files(spec) => {
            let mut spec = spec.spec()?;
            if forces.is_some() {
                spec.forces_n = forces;
            }
            Micrographs::Files(spec)
        }
        ImagesArg::Arrays(stack) => Micrographs::Memory(MemorySeries {
            planes: stack.planes()?,
            forces_n: forces,
            label: "images".into(),
        }),
    })
}

/// The global Otsu threshold of a series (the command line's `threshold`).
#[pyfunction]
fn otsu_threshold<'py>(py: Python<'py>, images: ImagesArg<'py>) -> PyResult<Bound<'py, PyDict>> {
    let request = ThresholdRequest {
        micrographs: micrographs(images, None)?,
    };
    let outcome = compute(py, move || threshold::run(&request))?;
    outcome_dict(py, &outcome)
}

/// The method as the command line names it: "otsu", "per-image" or a number.
enum MethodArg {
    Manual(f64),
    Name(String),
}

impl<'a, 'py> FromPyObject<'a, 'py> for MethodArg {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Some(t) = crate::extract::real(&obj) {
            return Ok(MethodArg::Manual(t));
        }
        obj.extract::<String>().map(MethodArg::Name).map_err(|_| {
            crate::extract::wrong_type(
                "method=",
                "\"otsu\", \"per-image\" or a threshold (a number)",
                &obj,
            )
        })
    }
}

/// The series analysis (the command line's `analyze`): files or arrays, forces in N, pixel
/// size in m, Hertz reference with `radius` (m) and `modulus` (Pa). With `masks`, the contact
/// masks as a (images, rows, columns) bool array. With `out`, the folder the command line's
/// `analyze --out` writes, by the same writer (`areas.csv`, `summary.json` with `command_line`
/// as its `command_line`, `area_vs_load.png/.svg`; `overlays` and `save_masks` as its
/// `--overlays` and `--save-masks`; `zarr_out` as its `--zarr-out`), and `written`: the files'
/// paths. `progress(pass, done,
/// total)` is called as the images are read ("histogram") and measured ("measure").
#[pyfunction]
#[pyo3(signature = (images, forces=None, pixel_size=None, method=None, radius=None, modulus=None, masks=false, out=None, command_line=None, overlays=false, save_masks=false, progress=None, pixel_size_uncertainty=0.0, psf_fwhm=None, zarr_out=None))]
#[allow(clippy::too_many_arguments)]
fn analyze<'py>(
    py: Python<'py>,
    images: ImagesArg<'py>,
    forces: Option<Vec<f64>>,
    pixel_size: Option<PixelArg>,
    method: Option<MethodArg>,
    radius: Option<f64>,
    modulus: Option<f64>,
    masks: bool,
    out: Option<PathBuf>,
    command_line: Option<Vec<String>>,
    overlays: bool,
    save_masks: bool,
    progress: Option<Py<PyAny>>,
    pixel_size_uncertainty: f64,
    psf_fwhm: Option<f64>,
    zarr_out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut request = AnalyzeRequest::new(micrographs(images, forces)?);
    request.pixel_size_uncertainty = pixel_size_uncertainty;
    request.psf_fwhm_m = psf_fwhm;
    request.method = match method {
        None => Method::GlobalOtsu,
        Some(MethodArg::Manual(t)) => Method::Manual(t),
        Some(MethodArg::Name(n)) => Method::parse(&n).map_err(crate::to_py)?,
    };
    request.pixel_size_m = pixel_opt(pixel_size)?;
    request.hertz = match (radius, modulus) {
        (Some(radius_m), Some(modulus_pa)) => Some(HertzParams {
            radius_m,
            modulus_pa,
        }),
        (None, None) => None,
        _ => {
            return Err(bad(format!(
                "the Hertz columns need both {} (m) and {} (Pa)",
                Param::Radius,
                Param::Modulus
            )))
        }
    };
    if out.is_some() && masks {
        return Err(bad(
            "masks are returned by an analysis in memory; with out, ask for save_masks \
             (mask TIFFs in the folder) instead",
        ));
    }
    if out.is_none() && zarr_out.is_some() {
        return Err(bad(
            "zarr_out is written with the output folder: give out as well (the command line's \
             --out with --zarr-out)",
        ));
    }
    // Progress reported to Python from the threads the analysis runs on (the GIL taken for
    // each call; an exception in the callback is printed, not raised, and the work goes on).
    let report = move |pass: Pass, done: usize, total: usize| {
        if let Some(callback) = &progress {
            Python::attach(|py| {
                let name = match pass {
                    Pass::Histogram => "histogram",
                    Pass::Measure => "measure",
                };
                if let Err(e) = callback.call1(py, (name, done, total)) {
                    e.print(py);
                }
            });
        }
    };
    if let Some(out) = out {
        let command_line = command_line.unwrap_or_default();
        let outputs = ImageOutputs {
            overlays,
            masks: save_masks,
            zarr: zarr_out,
        };
        let (outcome, written) = compute(py, move || {
            run_to_folder(&request, &out, &command_line, outputs, &report)
        })?;
        let d = outcome_dict(py, &outcome)?;
        d.set_item("written", written)?;
        return Ok(d);
    }
    let (outcome, kept) = compute(py, move || {
        let kept = std::sync::Mutex::new(Vec::new());
        let sink = |i: usize, _: &Plane, mask: &contactscope::measure::Mask| {
            if masks {
                kept.lock().expect("lock").push((i, mask.clone()));
            }
            Ok(())
        };
        let outcome = contactscope_jobs::analyze::run(&request, &report, &sink)?;
        let mut kept = kept.into_inner().expect("lock");
        kept.sort_by_key(|(i, _)| *i);
        Ok::<_, contactscope_jobs::Error>((outcome, kept))
    })?;
    let d = outcome_dict(py, &outcome)?;
    if masks && !kept.is_empty() {
        let (h, w) = (kept[0].1.height, kept[0].1.width);
        let values: Vec<bool> = kept.iter().flat_map(|(_, m)| m.as_bools()).collect();
        let a = Array3::from_shape_vec((kept.len(), h, w), values)
            .map_err(|e| bad(format!("masks: {e}")))?;
        d.set_item("masks", a.into_pyarray(py))?;
    }
    Ok(d)
}

/// Contact (value > threshold) of one image: pixels, area (m², with a pixel size),
/// intensities, 8-connected patches and the contact mask.
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
    let pixel_m2 = px.map(|(x, y)| x * y);
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
    let mask = Array2::from_shape_vec((mask.height, mask.width), mask.as_bools())
        .map_err(|e| bad(format!("mask: {e}")))?;
    d.set_item("mask", mask.into_pyarray(py))?;
    Ok(d)
}

/// Forces as the command line's `--forces` reads them: a list with units (`4,10,20,40mN`; a 0
/// is a reference frame) or a log-spaced range (`4mN..400mN:12`); newtons.
#[pyfunction]
fn parse_forces(text: &str) -> PyResult<Vec<f64>> {
    contactscope_formats::units::parse_forces(text).map_err(crate::to_py)
}

/// A pixel size as the command line's `--pixel-size` reads it (`200nm`, `0.2um`, `200x210nm`
/// for x × y): (x, y) in metres.
#[pyfunction]
fn parse_pixel_size(text: &str) -> PyResult<(f64, f64)> {
    contactscope_formats::units::parse_pixel_size(text).map_err(crate::to_py)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(parse_forces, m)?)?;
    m.add_function(wrap_pyfunction!(parse_pixel_size, m)?)?;
    m.add_function(wrap_pyfunction!(read_series, m)?)?;
    m.add_function(wrap_pyfunction!(otsu_threshold, m)?)?;
    m.add_function(wrap_pyfunction!(analyze, m)?)?;
    m.add_function(wrap_pyfunction!(measure, m)?)?;
    Ok(())
}
