//! Micrographs: numpy stacks in their stored sample type, the microscope's blur and the
//! comparison of simulated maps with micrographs (the PSF, Newton rings and the autocorrelation
//! are in `optics.rs`). Lengths in metres, forces in newtons.

use ndarray::Array2;
use numpy::{IntoPyArray, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;

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

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(blur_and_resample, m)?)?;
    Ok(())
}
