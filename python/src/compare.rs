//! `compare`: the job `contactscope_jobs::compare` from Python — micrographs (a Series' files or
//! arrays in their stored type) against simulated maps (a `simulate` folder or arrays), with the
//! command line's defaults and checks; the result is the outcome (`compare.json`, SI keys).

use std::path::PathBuf;

use ndarray::Array3;
use numpy::{IntoPyArray, PyReadonlyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope_jobs::compare::files::run_to_folder;

use contactscope::compare::SimulatedMap;
use contactscope::optics::blur::Grid;
use contactscope_formats::param::Param;
use contactscope_jobs::compare::{CompareRequest, Simulation};

use crate::convert::outcome_dict;
use crate::series::ImagesArg;
use crate::{bad, compute, pixel_opt, PixelArg};

/// Simulated maps as Python gives them.
enum MapsArg<'py> {
    /// A folder written by `simulate`.
    Folder(PathBuf),
    /// Contact maps (loads, ny, nx), 1 = contact.
    Arrays(PyReadonlyArray3<'py, f64>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for MapsArg<'py> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        if let Some(dir) = crate::extract::path(&obj) {
            return Ok(MapsArg::Folder(dir));
        }
        obj.extract::<PyReadonlyArray3<'py, f64>>()
            .map(MapsArg::Arrays)
            .map_err(|_| {
                crate::extract::wrong_type(
                    "the simulated maps",
                    "a folder written by simulate or a (loads, rows, columns) float64 array",
                    &obj,
                )
            })
    }
}

fn simulation(
    maps: MapsArg<'_>,
    map_forces: Option<Vec<f64>>,
    map_pixel_size: Option<PixelArg>,
) -> PyResult<Simulation> {
    match maps {
        MapsArg::Folder(dir) => {
            if map_forces.is_some() || map_pixel_size.is_some() {
                return Err(bad(
                    "a simulate folder gives its maps' forces and pixel size; give them only \
                     with arrays",
                ));
            }
            Ok(Simulation::Folder(dir))
        }
        MapsArg::Arrays(a) => {
            let a = a.as_array();
            let (n, ny, nx) = a.dim();
            let forces = map_forces.ok_or_else(|| bad("maps as arrays need map_forces (N)"))?;
            if forces.len() != n {
                return Err(bad(format!("{} map forces for {n} maps", forces.len())));
            }
            let (dx, dy) = map_pixel_size
                .ok_or_else(|| {
                    bad(format!(
                        "maps as arrays need map_pixel_size (m), as {} for the micrographs",
                        Param::PixelSize
                    ))
                })?
                .xy()?;
            let maps = a
                .outer_iter()
                .zip(forces)
                .enumerate()
                .map(|(i, (m, f))| {
                    Ok(SimulatedMap {
                        force_n: f,
                        map: Grid::new(m.iter().copied().collect(), nx, ny, dx, dy)
                            .map_err(crate::to_py)?,
                        source: format!("map {i}"),
                    })
                })
                .collect::<PyResult<_>>()?;
            Ok(Simulation::Memory {
                maps,
                label: "maps (arrays)".into(),
            })
        }
    }
}

/// Simulated contact maps against micrographs, load by load (the command line's `compare`).
/// With `images`, also the registered pairs the scores are computed on (the panels of
/// `panel_NNN.png`), each a (loads, rows, columns) stack on the micrograph's grid:
/// `micrographs` (grey levels), `simulated_images` (the blurred, resampled and registered
/// contact map on the micrograph's grey scale, NaN outside the simulated region),
/// `experiment_contact` and `simulated_contact` (bool: contact as the Dice counts it, inside
/// the compared region). With `out`, the folder the command line's `compare --out` writes, by
/// the same writer (`compare.csv`, `compare.json` with `command_line` as its `command_line`,
/// `panel_NNN.png`), and `written`: the files' paths.
#[pyfunction]
#[pyo3(signature = (micrographs, forces, pixel_size, maps, map_forces, map_pixel_size, psf_fwhm, dihedral=None, upsample=None, force_tolerance=None, images=false, out=None, command_line=None))]
#[allow(clippy::too_many_arguments)]
fn compare<'py>(
    py: Python<'py>,
    micrographs: ImagesArg<'py>,
    forces: Option<Vec<f64>>,
    pixel_size: Option<PixelArg>,
    maps: MapsArg<'py>,
    map_forces: Option<Vec<f64>>,
    map_pixel_size: Option<PixelArg>,
    psf_fwhm: f64,
    dihedral: Option<bool>,
    upsample: Option<usize>,
    force_tolerance: Option<f64>,
    images: bool,
    out: Option<PathBuf>,
    command_line: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut request = CompareRequest::new(
        crate::series::micrographs(micrographs, forces)?,
        simulation(maps, map_forces, map_pixel_size)?,
        psf_fwhm,
    );
    request.pixel_size_m = pixel_opt(pixel_size)?;
    request.dihedral = dihedral.unwrap_or(request.dihedral);
    request.upsample = upsample.unwrap_or(request.upsample);
    request.force_tolerance = force_tolerance.unwrap_or(request.force_tolerance);
    let (outcome, written) = match out {
        Some(out) => {
            let command_line = command_line.unwrap_or_default();
            let (outcome, written) =
                compute(py, move || run_to_folder(&request, &out, &command_line))?;
            (outcome, Some(written))
        }
        None => (
            compute(py, move || contactscope_jobs::compare::run(&request))?,
            None,
        ),
    };
    let d = outcome_dict(py, &outcome)?;
    if let Some(written) = written {
        d.set_item("written", written)?;
    }
    if images && !outcome.prepared.is_empty() {
        let (w, h) = outcome.prepared[0].size();
        let n = outcome.prepared.len();
        let pairs = || outcome.prepared.iter().zip(&outcome.loads);
        let f64_stack = |values: Vec<f64>| {
            Array3::from_shape_vec((n, h, w), values).map_err(|e| bad(format!("images: {e}")))
        };
        let bool_stack = |values: Vec<bool>| {
            Array3::from_shape_vec((n, h, w), values).map_err(|e| bad(format!("images: {e}")))
        };
        let micrographs: Vec<f64> = pairs().flat_map(|(p, _)| p.micrograph().to_vec()).collect();
        let simulated: Vec<f64> = pairs().flat_map(|(p, l)| p.simulated_on_scale(l)).collect();
        let experiment: Vec<bool> = pairs()
            .flat_map(|(p, _)| p.experiment_contact(outcome.experiment_threshold))
            .collect();
        let simulated_contact: Vec<bool> = pairs()
            .flat_map(|(p, _)| p.simulated_contact(outcome.simulated_threshold))
            .collect();
        d.set_item("micrographs", f64_stack(micrographs)?.into_pyarray(py))?;
        d.set_item("simulated_images", f64_stack(simulated)?.into_pyarray(py))?;
        d.set_item(
            "experiment_contact",
            bool_stack(experiment)?.into_pyarray(py),
        )?;
        d.set_item(
            "simulated_contact",
            bool_stack(simulated_contact)?.into_pyarray(py),
        )?;
    }
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
