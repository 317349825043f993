//! `compare`: the job `contactscope_jobs::compare` from Python — micrographs (a Series' files or
//! arrays in their stored type) against simulated maps (a `simulate` folder or arrays), with the
//! command line's defaults and checks; the result is the outcome (`compare.json`, SI keys).

use std::path::PathBuf;

use numpy::PyReadonlyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use contactscope::compare::SimulatedMap;
use contactscope::optics::blur::Grid;
use contactscope_formats::param::Param;
use contactscope_jobs::compare::{CompareRequest, Simulation};

use crate::convert::outcome_dict;
use crate::series::ImagesArg;
use crate::{bad, compute, pixel_opt, PixelArg};

/// Simulated maps as Python gives them.
#[derive(FromPyObject)]
enum MapsArg<'py> {
    /// A folder written by `simulate`.
    Folder(PathBuf),
    /// Contact maps (loads, ny, nx), 1 = contact.
    Arrays(PyReadonlyArray3<'py, f64>),
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
#[pyfunction]
#[pyo3(signature = (micrographs, forces, pixel_size, maps, map_forces, map_pixel_size, psf_fwhm, dihedral=None, upsample=None, force_tolerance=None))]
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
    let outcome = compute(py, move || contactscope_jobs::compare::run(&request))?;
    outcome_dict(py, &outcome)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
