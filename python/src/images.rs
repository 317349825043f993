//! Micrographs: numpy stacks in their stored sample type, the microscope's blur and the
//! comparison of simulated maps with micrographs (the PSF, Newton rings and the autocorrelation
//! are in `optics.rs`). Lengths in metres, forces in newtons.

use std::path::PathBuf;

use ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope::analysis;
use contactscope::compare::{compare_maps, CompareSettings, Micrograph, Micrographs, SimulatedMap};
use contactscope::image::{Plane, SampleType, Samples};
use contactscope::optics::blur::{microscope_image, Grid};

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
    m.add_function(wrap_pyfunction!(blur_and_resample, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
