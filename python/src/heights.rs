//! Height maps from Python: a path (read as the command line reads `--topography`) or an array
//! of heights in metres with its pixel size, as the jobs' [`HeightInput`].

use std::path::PathBuf;

use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use contactscope::surface::fill::FillInvalid;
use contactscope::surface::{Detrend, Topography};
use contactscope_formats::param::Param;
use contactscope_jobs::heights::{HeightInput, TopographySource};

use crate::{bad, PixelArg};

/// Heights as Python gives them.
pub(crate) enum HeightsArg<'py> {
    /// A file of any height-map format.
    Path(PathBuf),
    /// Heights in m, rows = y.
    Array(PyReadonlyArray2<'py, f64>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for HeightsArg<'py> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Some(p) = crate::extract::path(&obj) {
            return Ok(HeightsArg::Path(p));
        }
        obj.extract::<PyReadonlyArray2<'py, f64>>()
            .map(HeightsArg::Array)
            .map_err(|_| {
                crate::extract::wrong_type(
                    "heights",
                    "a height-map file or a 2-D float64 array of heights in m",
                    &obj,
                )
            })
    }
}

/// `"none"`, `"mean"` or `"plane"`.
pub(crate) fn detrend_of(name: &str) -> PyResult<Detrend> {
    Detrend::from_name(name).ok_or_else(|| {
        bad(format!(
            "{}'{name}' is not one of none, mean, plane",
            Param::Detrend
        ))
    })
}

/// `"mean"` or `"nearest"`.
pub(crate) fn fill_of(name: Option<&str>) -> PyResult<Option<FillInvalid>> {
    name.map(|n| {
        FillInvalid::from_name(n).ok_or_else(|| {
            bad(format!(
                "{}'{n}' is not one of mean, nearest",
                Param::FillInvalid
            ))
        })
    })
    .transpose()
}

/// How to read a file, or the array as a topography (`pixel_size` needed for an array).
pub(crate) fn height_input(
    heights: HeightsArg<'_>,
    pixel_size: Option<PixelArg>,
    detrend: &str,
    height_unit: Option<f64>,
    channel: Option<String>,
    fill_invalid: Option<&str>,
    measurement: Option<String>,
) -> PyResult<HeightInput> {
    let detrend = detrend_of(detrend)?;
    let pixel = pixel_size.map(PixelArg::xy).transpose()?;
    match heights {
        HeightsArg::Path(path) => Ok(HeightInput::File(TopographySource {
            path,
            pixel_size_m: pixel,
            height_unit_m: height_unit,
            detrend,
            channel,
            fill_invalid: fill_of(fill_invalid)?,
            measurement,
        })),
        HeightsArg::Array(a) => {
            if height_unit.is_some()
                || channel.is_some()
                || fill_invalid.is_some()
                || measurement.is_some()
            {
                return Err(bad(format!(
                    "{}, {}, {} and {} apply to a file; an array holds heights in metres",
                    Param::HeightUnit,
                    Param::Channel,
                    Param::FillInvalid,
                    Param::Measurement
                )));
            }
            let (dx, dy) = pixel.ok_or_else(|| {
                bad(format!(
                    "{}: an array of heights needs its pixel size (m)",
                    Param::PixelSize
                ))
            })?;
            let topography =
                Topography::new(a.as_array().to_owned(), dx, dy).map_err(crate::to_py)?;
            Ok(HeightInput::Memory {
                topography,
                detrend,
                label: "heights (array)".into(),
            })
        }
    }
}
