//! Height maps and contact mechanics: reading AFM/profilometer files, generating self-affine
//! surfaces, load ramps with the paper's contact models (elastic, penetration hardness, linear
//! hardening, Greenwood–Tripp) and the fit of the hardening coefficient. SI units: heights and
//! lengths in m, forces in N, pressures and moduli in Pa, k in Pa/m (4 MPa/nm = 4e15 Pa/m).

use std::path::PathBuf;

use ndarray::Array3;
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope::error::{Error, Result};
use contactscope::io::topography::{FillInvalid, TopographySource};
use contactscope::measure::patches::count_patches;
use contactscope::model_fit::{fit_parameter, Family, Imaging, Measured, ModelBody, Search};
use contactscope::solver::cg::SolverOptions;
use contactscope::solver::gt::{gt_bearing_area, gt_profile, GtParams};
use contactscope::solver::halfspace::Boundary;
use contactscope::solver::simulate::{sweep_each, Model, Setup};
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::stats::SurfaceStats;
use contactscope::surface::{Detrend, Topography};

use crate::{bad, compute, PixelArg};

fn detrend_of(name: &str) -> PyResult<Detrend> {
    match name {
        "none" => Ok(Detrend::None),
        "mean" => Ok(Detrend::Mean),
        "plane" => Ok(Detrend::Plane),
        other => Err(bad(format!(
            "detrend '{other}' is not one of none, mean, plane"
        ))),
    }
}

/// A height map (rows = y, columns = x; m) and its pixel size as a topography.
fn topography(heights: &PyReadonlyArray2<'_, f64>, pixel: PixelArg) -> PyResult<Topography> {
    let (dx, dy) = pixel.xy()?;
    Topography::new(heights.as_array().to_owned(), dx, dy).map_err(crate::to_py)
}

fn heights_to_py<'py>(py: Python<'py>, t: Topography) -> Bound<'py, PyAny> {
    t.heights.into_pyarray(py).into_any()
}

/// Read a height map of any format contactscope reads (npy, TIFF, GSF, text, WSxM, Nanoscope
/// and the vendor AFM and profilometer formats recognised by content), in m, with its pixel
/// size (m), then detrend it ("none", "mean" or "plane", the command line's default). `channel`
/// names the channel of a multi-channel vendor file (default: its height channel); a map with
/// invalid points is refused unless `fill_invalid` is "mean" or "nearest" (the notes say how
/// many were filled).
#[pyfunction]
#[pyo3(signature = (path, pixel_size=None, height_unit=None, detrend="plane", channel=None, fill_invalid=None))]
fn read_topography<'py>(
    py: Python<'py>,
    path: PathBuf,
    pixel_size: Option<PixelArg>,
    height_unit: Option<f64>,
    detrend: &str,
    channel: Option<String>,
    fill_invalid: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let source = TopographySource {
        path,
        pixel_size_m: crate::pixel_opt(pixel_size)?,
        height_unit_m: height_unit,
        detrend: detrend_of(detrend)?,
        channel,
        fill_invalid: match fill_invalid {
            None => None,
            Some("mean") => Some(FillInvalid::Mean),
            Some("nearest") => Some(FillInvalid::Nearest),
            Some(other) => {
                return Err(bad(format!(
                    "fill_invalid '{other}' is not one of mean, nearest"
                )))
            }
        },
    };
    let (t, notes) = compute(py, move || source.read_with_notes())?;
    let d = PyDict::new(py);
    d.set_item("pixel_size_m", (t.dx_m, t.dy_m))?;
    d.set_item("heights", heights_to_py(py, t))?;
    d.set_item("notes", notes)?;
    Ok(d)
}

/// A seeded self-affine random surface (heights in m, rows = y): `nx` × `ny` pixels of
/// `pixel_size` m, Hurst exponent `hurst`, scaled to `rms_height` (m) or `rms_slope`, with an
/// optional roll-off and short-wavelength cutoff (m).
#[pyfunction]
#[pyo3(signature = (nx, ny, pixel_size, hurst=0.8, rms_height=None, rms_slope=None, rolloff=None, cutoff=None, seed=0))]
#[allow(clippy::too_many_arguments)]
fn surface<'py>(
    py: Python<'py>,
    nx: usize,
    ny: usize,
    pixel_size: f64,
    hurst: f64,
    rms_height: Option<f64>,
    rms_slope: Option<f64>,
    rolloff: Option<f64>,
    cutoff: Option<f64>,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let target = match (rms_height, rms_slope) {
        (Some(h), None) => RmsTarget::Height(h),
        (None, Some(s)) => RmsTarget::Slope(s),
        _ => return Err(bad("give exactly one of rms_height (m) and rms_slope")),
    };
    let params = SelfAffineParams {
        nx,
        ny,
        dx_m: pixel_size,
        hurst,
        rolloff_wavelength_m: rolloff,
        short_cutoff_wavelength_m: cutoff,
        target,
        seed,
    };
    let t = compute(py, move || self_affine(&params))?;
    Ok(heights_to_py(py, t))
}

/// Solver limits as given from Python.
fn solver_options(tolerance: f64, max_iterations: usize) -> PyResult<SolverOptions<'static>> {
    if !(tolerance.is_finite() && tolerance > 0.0) || max_iterations == 0 {
        return Err(bad(format!(
            "tolerance {tolerance:e} must be positive and max_iterations at least 1"
        )));
    }
    Ok(SolverOptions {
        tolerance,
        max_iterations,
        ..SolverOptions::default()
    })
}

/// The half-space model from its name and parameters.
fn model_of(
    model: &str,
    hardness: Option<f64>,
    k: Option<f64>,
    initial_hardness: f64,
    alpha: Option<f64>,
) -> PyResult<Option<Model>> {
    Ok(Some(match model {
        "elastic" => Model::Elastic,
        "hardness" => Model::Hardness {
            hardness_pa: hardness.ok_or_else(|| bad("the hardness model needs hardness (Pa)"))?,
            volume_conserving: alpha,
        },
        "hardening" => Model::Hardening {
            modulus_pa_per_m: k.ok_or_else(|| bad("the hardening model needs k (Pa/m)"))?,
            initial_pa: initial_hardness,
        },
        "gt" => return Ok(None),
        other => {
            return Err(bad(format!(
                "model '{other}' is not one of elastic, hardness, hardening, gt"
            )))
        }
    }))
}

/// One load of a simulated ramp, SI units, with its maps when kept.
struct Step {
    force_n: f64,
    area_m2: f64,
    contact_fraction: f64,
    mean_pressure_pa: f64,
    max_pressure_pa: f64,
    approach_m: f64,
    patches: u64,
    iterations: usize,
    residual: f64,
    plastic_volume_m3: f64,
    edge_contact: bool,
    /// pressure (Pa), gap (m), plastic displacement (m); contact is p > 0.
    maps: Option<[Vec<f64>; 3]>,
}

/// A load ramp with one contact model on a rough body: heights (m, rows = y; positive towards
/// the flat) of pixel size `pixel_size` (m), a sphere of `radius` (m) added when given, contact
/// modulus E* `modulus` (Pa), normal forces `loads` (N, in order; the plastic state carries from
/// load to load). Models: "elastic", "hardness" (p_Y = `hardness`, Pa; `alpha` for the
/// volume-conserving Eq. 5), "hardening" (p_Y = `initial_hardness` + `k`·h_pl, k in Pa/m),
/// "gt" (Greenwood–Tripp bearing area; needs `radius`). Per load: the summary and, with
/// `maps`, pressure (Pa), gap (m), contact (bool) and plastic displacement (m) maps.
#[pyfunction]
#[pyo3(signature = (heights, pixel_size, modulus, loads, model="elastic", hardness=None, k=None, initial_hardness=0.0, alpha=None, radius=None, periodic=false, tolerance=1e-8, max_iterations=5000, maps=true))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    heights: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    loads: Vec<f64>,
    model: &str,
    hardness: Option<f64>,
    k: Option<f64>,
    initial_hardness: f64,
    alpha: Option<f64>,
    radius: Option<f64>,
    periodic: bool,
    tolerance: f64,
    max_iterations: usize,
    maps: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let roughness = topography(&heights, pixel_size)?;
    let model = model_of(model, hardness, k, initial_hardness, alpha)?;
    let options = solver_options(tolerance, max_iterations)?;
    if loads.is_empty() {
        return Err(bad("no loads given (newtons)"));
    }
    let (nx, ny) = (roughness.nx(), roughness.ny());
    let (steps, stacks) = compute(py, move || {
        let stats = SurfaceStats::finite_differences(&roughness)?;
        let mut steps = match model {
            Some(model) => run_halfspace(
                roughness, &stats, radius, modulus, model, periodic, options, &loads, maps,
            ),
            None => run_gt(&roughness, &stats, radius, modulus, &loads, maps),
        }?;
        // The per-load maps into (loads, ny, nx) stacks, still without the GIL.
        let stacks = maps.then(|| {
            let cells = steps.len() * nx * ny;
            let mut stacks: [Vec<f64>; 3] = std::array::from_fn(|_| Vec::with_capacity(cells));
            let mut contact: Vec<bool> = Vec::with_capacity(cells);
            for s in &mut steps {
                if let Some([mut pressure, gap, plastic]) = s.maps.take() {
                    contact.extend(pressure.iter().map(|p| *p > 0.0));
                    if model.is_none() {
                        pressure.fill(f64::NAN);
                    }
                    for (stack, map) in stacks.iter_mut().zip([pressure, gap, plastic]) {
                        stack.extend(map);
                    }
                }
            }
            (stacks, contact)
        });
        Ok((steps, stacks))
    })?;
    let d = PyDict::new(py);
    let rows = PyList::empty(py);
    for s in &steps {
        let r = PyDict::new(py);
        r.set_item("force_n", s.force_n)?;
        r.set_item("area_m2", s.area_m2)?;
        r.set_item("contact_fraction", s.contact_fraction)?;
        r.set_item("mean_pressure_pa", s.mean_pressure_pa)?;
        r.set_item("max_pressure_pa", s.max_pressure_pa)?;
        r.set_item("approach_m", s.approach_m)?;
        r.set_item("patches", s.patches)?;
        r.set_item("iterations", s.iterations)?;
        r.set_item("residual", s.residual)?;
        r.set_item("plastic_volume_m3", s.plastic_volume_m3)?;
        r.set_item("edge_contact", s.edge_contact)?;
        rows.append(r)?;
    }
    d.set_item("rows", rows)?;
    if let Some(([pressure, gap, plastic], contact)) = stacks {
        // The stacks become numpy arrays without another copy.
        let shape = (steps.len(), ny, nx);
        let err = |e: ndarray::ShapeError| bad(format!("maps: {e}"));
        for (name, values) in [("pressure", pressure), ("gap", gap), ("plastic", plastic)] {
            let a = Array3::from_shape_vec(shape, values).map_err(err)?;
            d.set_item(name, a.into_pyarray(py))?;
        }
        let a = Array3::from_shape_vec(shape, contact).map_err(err)?;
        d.set_item("contact", a.into_pyarray(py))?;
    }
    Ok(d)
}

#[allow(clippy::too_many_arguments)]
fn run_halfspace(
    roughness: Topography,
    stats: &SurfaceStats,
    radius: Option<f64>,
    modulus: f64,
    model: Model,
    periodic: bool,
    options: SolverOptions<'static>,
    loads: &[f64],
    keep_maps: bool,
) -> Result<Vec<Step>> {
    let mut body = roughness;
    if let Some(r) = radius {
        body.add_sphere(r)?;
    }
    // As the `simulate` job: gap residuals relative to the roughness.
    let options = SolverOptions {
        gap_scale_m: options.gap_scale_m.or(Some(stats.h_rms_m)),
        ..options
    };
    let setup = Setup {
        topography: &body,
        e_star_pa: modulus,
        boundary: if periodic {
            Boundary::Periodic
        } else {
            Boundary::Free
        },
        model,
        options,
    };
    let cell = body.dx_m * body.dy_m;
    let mut steps = Vec::with_capacity(loads.len());
    sweep_each(&setup, loads, &mut |_, s| {
        let plastic_volume_m3 = s.plastic_m.iter().sum::<f64>() * cell;
        let mut step = Step {
            force_n: s.force_n,
            area_m2: s.area_m2,
            contact_fraction: s.contact_fraction,
            mean_pressure_pa: s.mean_pressure_pa,
            max_pressure_pa: s.max_pressure_pa,
            approach_m: s.solution.approach,
            patches: s.patches,
            iterations: s.solution.iterations,
            residual: s.solution.gap_residual.max(s.solution.pressure_change),
            plastic_volume_m3,
            edge_contact: s.edge_contact,
            maps: None,
        };
        if keep_maps {
            // The step is ours: its fields move into the result without a copy.
            step.maps = Some([s.solution.pressure, s.solution.gap, s.plastic_m]);
        }
        steps.push(step);
        Ok(())
    })?;
    Ok(steps)
}

fn run_gt(
    roughness: &Topography,
    stats: &SurfaceStats,
    radius: Option<f64>,
    modulus: f64,
    loads: &[f64],
    keep_maps: bool,
) -> Result<Vec<Step>> {
    let radius = radius.ok_or_else(|| {
        Error::InvalidArgument("the Greenwood–Tripp model needs the sphere radius (m)".into())
    })?;
    let params = GtParams::new(
        radius,
        modulus,
        stats.h_rms_m,
        stats.h_double_prime_rms_per_m,
    );
    params.validate()?;
    let n = roughness.nx() * roughness.ny();
    loads
        .iter()
        .map(|&force| {
            let profile = gt_profile(&params, force)?;
            let map = gt_bearing_area(roughness, &profile, None)?;
            let mask: Vec<u8> = map.mask.iter().map(|m| u8::from(*m)).collect();
            // No pressure field: the first map carries the bearing-area contact (1) instead, and
            // `simulate` returns NaN pressures for GT.
            let contact: Vec<f64> = mask.iter().map(|m| f64::from(*m)).collect();
            Ok(Step {
                force_n: force,
                area_m2: map.area_m2,
                contact_fraction: map.contact_fraction,
                mean_pressure_pa: if map.area_m2 > 0.0 {
                    force / map.area_m2
                } else {
                    f64::NAN
                },
                max_pressure_pa: profile.pressure_pa.first().copied().unwrap_or(f64::NAN),
                approach_m: profile.approach_m,
                patches: count_patches(&mask, roughness.nx()).0,
                iterations: profile.iterations,
                residual: (profile.load_n - force).abs() / force,
                plastic_volume_m3: 0.0,
                edge_contact: false,
                // GT gives the bearing-area contact map only: no pressure, gap or plastic maps.
                maps: keep_maps.then(|| [contact, vec![f64::NAN; n], vec![0.0; n]]),
            })
        })
        .collect()
}

fn family_of(name: &str) -> PyResult<Family> {
    Family::parse(name).map_err(crate::to_py)
}

/// The model body of a fit: roughness (m) with the sphere, E* (Pa), solver limits and the
/// optional imaging of simulated maps (PSF FWHM in m, micrograph pixel in m).
#[allow(clippy::too_many_arguments)]
fn model_body(
    heights: &PyReadonlyArray2<'_, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    radius: Option<f64>,
    tolerance: f64,
    max_iterations: usize,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
) -> PyResult<ModelBody> {
    let roughness = topography(heights, pixel_size)?;
    let options = solver_options(tolerance, max_iterations)?;
    let mut body = ModelBody::new(roughness, radius, modulus, options).map_err(crate::to_py)?;
    body.imaging = match (imaging_fwhm, imaging_pixel_size) {
        (Some(fwhm_m), Some(p)) => Some(Imaging {
            fwhm_m,
            pixel_m: p.xy()?,
        }),
        (None, None) => None,
        _ => {
            return Err(bad(
                "imaging needs both imaging_fwhm (m) and imaging_pixel_size (m)",
            ))
        }
    };
    Ok(body)
}

/// One model evaluation, the unit of work of a fit or a sweep: the contact areas (m²) of one load
/// ramp (`loads`, N, increasing) for `family` ("elastic", "gt", "hardness" with p_Y in Pa,
/// "hardening" with k in Pa/m) on the rough sphere, as `fit_hardening` counts them (raw p > 0
/// pixels, or imaged like micrographs with `imaging_fwhm` and `imaging_pixel_size`).
#[pyfunction]
#[pyo3(signature = (heights, pixel_size, modulus, family, parameter, loads, radius=None, tolerance=1e-8, max_iterations=5000, imaging_fwhm=None, imaging_pixel_size=None))]
#[allow(clippy::too_many_arguments)]
fn ramp<'py>(
    py: Python<'py>,
    heights: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    family: &str,
    parameter: Option<f64>,
    loads: Vec<f64>,
    radius: Option<f64>,
    tolerance: f64,
    max_iterations: usize,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let family = family_of(family)?;
    let body = model_body(
        &heights,
        pixel_size,
        modulus,
        radius,
        tolerance,
        max_iterations,
        imaging_fwhm,
        imaging_pixel_size,
    )?;
    let (areas, _, edge) = compute(py, move || body.evaluate(family, parameter, &loads, false))?;
    let d = PyDict::new(py);
    d.set_item("areas_m2", areas.into_pyarray(py))?;
    d.set_item("edge_contact", edge)?;
    Ok(d)
}

/// The fit's misfit: RMS over the measured loads of ln(A_sim/A_exp) (areas in m², forces in N).
#[pyfunction]
fn misfit(forces: Vec<f64>, areas: Vec<f64>, simulated: Vec<f64>) -> PyResult<f64> {
    if simulated.len() != forces.len() {
        return Err(bad(format!(
            "{} simulated areas for {} measured loads",
            simulated.len(),
            forces.len()
        )));
    }
    let mut order: Vec<usize> = (0..forces.len()).collect();
    order.sort_by(|&a, &b| forces[a].total_cmp(&forces[b]));
    let measured =
        Measured::new(forces.iter().copied().zip(areas).collect()).map_err(crate::to_py)?;
    let sorted: Vec<f64> = order.iter().map(|&i| simulated[i]).collect();
    Ok(measured.misfit(&sorted))
}

/// Fit one contact model to a measured area–load curve (forces in N, areas in m²) on the rough
/// sphere (heights in m, pixel size in m, sphere `radius` in m, E* `modulus` in Pa): for
/// "hardening" (k in Pa/m) or "hardness" (p_Y in Pa) a log grid over `range` then Brent's method
/// on ln(parameter), with the Gauss–Newton standard error; "elastic" and "gt" are evaluated once.
#[pyfunction]
#[pyo3(signature = (forces, areas, heights, pixel_size, modulus, radius=None, family="hardening", range=None, grid=7, ln_tolerance=0.01, tolerance=1e-8, max_iterations=5000, imaging_fwhm=None, imaging_pixel_size=None))]
#[allow(clippy::too_many_arguments)]
fn fit_hardening<'py>(
    py: Python<'py>,
    forces: Vec<f64>,
    areas: Vec<f64>,
    heights: PyReadonlyArray2<'py, f64>,
    pixel_size: PixelArg,
    modulus: f64,
    radius: Option<f64>,
    family: &str,
    range: Option<(f64, f64)>,
    grid: usize,
    ln_tolerance: f64,
    tolerance: f64,
    max_iterations: usize,
    imaging_fwhm: Option<f64>,
    imaging_pixel_size: Option<PixelArg>,
) -> PyResult<Bound<'py, PyDict>> {
    let family = family_of(family)?;
    if forces.len() != areas.len() {
        return Err(bad(format!(
            "{} forces for {} areas",
            forces.len(),
            areas.len()
        )));
    }
    let measured = Measured::new(forces.into_iter().zip(areas).collect()).map_err(crate::to_py)?;
    let body = model_body(
        &heights,
        pixel_size,
        modulus,
        radius,
        tolerance,
        max_iterations,
        imaging_fwhm,
        imaging_pixel_size,
    )?;
    let mut search = Search::default_for(family);
    if let Some(r) = range {
        search.range = r;
    }
    search.grid = grid;
    search.ln_tolerance = ln_tolerance;
    let fit = compute(py, move || {
        if family.has_parameter() {
            fit_parameter(&body, family, &measured, search).map(Some)
        } else {
            Ok(None)
        }
        .and_then(|fit| match fit {
            Some(f) => Ok((f.best, f.parameter_se, f.trace, f.at_range_edge)),
            None => Ok((
                body.score(family, None, &measured, false)?,
                None,
                vec![],
                false,
            )),
        })
    })?;
    let (best, se, trace, edge) = fit;
    let d = PyDict::new(py);
    d.set_item("family", family.name())?;
    d.set_item("parameter", best.parameter)?;
    d.set_item("parameter_se", se)?;
    d.set_item("misfit", best.misfit)?;
    d.set_item("areas_m2", best.areas_m2.into_pyarray(py))?;
    d.set_item("edge_contact", best.edge_contact)?;
    d.set_item("trace", trace)?;
    d.set_item("at_range_edge", edge)?;
    Ok(d)
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_topography, m)?)?;
    m.add_function(wrap_pyfunction!(surface, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(ramp, m)?)?;
    m.add_function(wrap_pyfunction!(misfit, m)?)?;
    m.add_function(wrap_pyfunction!(fit_hardening, m)?)?;
    Ok(())
}
