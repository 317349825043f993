//! The demo's synthetic load series and its comparison with each model (Weber et al. 2018,
//! Fig. 2): a seeded rough sphere pressed through the load ramp with linear hardening at the
//! true k, each load's contact map rendered as a 12-bit confocal micrograph at a known offset
//! ([`MICROGRAPH_OFFSET_PX`]), and the models' maps compared with those micrographs as
//! `compare` does. Public so that the registration of every model can be checked against the
//! offset the micrographs were made with.

use std::path::{Path, PathBuf};

use contactscope::compare::SimulatedMap;
use contactscope::compare::{
    compare_maps, CompareSettings, Comparison, Micrographs as MicrographSet,
};
use contactscope::model_fit::{Family, Imaging, ModelBody, Search};
use contactscope::optics::blur::{microscope_image, Grid};
use contactscope::solver::cg::SolverOptions;
use contactscope::solver::halfspace::Boundary;
use contactscope::solver::simulate::{sweep, Model, Setup};
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::surface::Topography;
use contactscope::synth::{render_micrograph, MicrographParams};
use contactscope_formats::tiff::write::encode_u16_stack;
use contactscope_formats::topography::encode_npy;

use super::{DemoParams, DemoProgress};
use crate::compare::load_micrographs;
use crate::error::{Error, Result};
use crate::series::{Micrographs, SeriesSpec};
use crate::staging::write_atomic;

/// Where the truth lies on the demo's micrographs: the rendered maps' corner is this far (x, y)
/// from where `compare` centres a simulated image, micrograph pixels (y down). A simulated map of
/// the same surface is therefore in place when `compare` shifts it by exactly this much.
pub const MICROGRAPH_OFFSET_PX: (i64, i64) = (3, -2);

/// The synthetic experiment: the rough sphere, the truth ramp, and its micrographs (written to
/// the data folder and read back as `compare` reads them).
#[derive(Debug, Clone)]
pub struct Experiment {
    /// The roughness (without the sphere), as written to `topography.npy`.
    pub roughness: Topography,
    /// True contact area (g = 0) per load, m².
    pub truth_areas_m2: Vec<f64>,
    /// The micrographs' manifest (`micrographs/manifest.csv` in the data folder).
    pub manifest: PathBuf,
    /// The micrographs, read and thresholded.
    pub micrographs: MicrographSet,
}

/// Generate the rough sphere and the truth ramp, render the micrographs into `data`
/// (`topography.npy`, `micrographs/series.tif` + `manifest.csv`) and read them back.
pub fn synthetic_experiment(
    p: &DemoParams,
    data: &Path,
    progress: DemoProgress,
) -> Result<Experiment> {
    std::fs::create_dir_all(data).map_err(|e| Error::io(data, e))?;
    progress("rough sphere and the hardening load ramp (truth)");
    let roughness = roughness(p)?;
    write_atomic(
        &data.join("topography.npy"),
        &encode_npy(&roughness.heights),
    )?;
    let (truth_areas_m2, maps) = truth_ramp(p, &roughness)?;
    progress("rendering the confocal stack");
    let manifest = write_micrographs(p, &maps, data)?;
    let (_, micrographs) = load_micrographs(
        &Micrographs::Files(SeriesSpec {
            manifest: Some(manifest.clone()),
            ..SeriesSpec::default()
        }),
        None,
    )?;
    Ok(Experiment {
        roughness,
        truth_areas_m2,
        manifest,
        micrographs,
    })
}

/// The solver limits of every demo simulation.
pub(super) fn solver_options(p: &DemoParams) -> Result<SolverOptions<'static>> {
    Ok(SolverOptions {
        max_iterations: 5000,
        tolerance: 1e-8,
        monitor: None,
        gpu: p.device.open()?,
        ..SolverOptions::default()
    })
}

/// The search of the demo's one-parameter fits: a log grid of `p.fit_grid` points, then Brent's
/// method to 2 % in ln(parameter).
pub fn fit_search(p: &DemoParams, family: Family) -> Search {
    Search {
        grid: p.fit_grid,
        ln_tolerance: 0.02,
        ..Search::default_for(family)
    }
}

/// How the demo's fits count simulated areas: as imaged by the micrographs' PSF and pixels.
pub fn imaging(p: &DemoParams) -> Imaging {
    Imaging {
        fwhm_m: p.psf_fwhm_m,
        pixel_m: (p.image_pixel_m, p.image_pixel_m),
    }
}

/// The models' rigid body: the experiment's roughness on the sphere.
pub fn model_body(p: &DemoParams, experiment: &Experiment) -> Result<ModelBody> {
    Ok(ModelBody::new(
        experiment.roughness.clone(),
        Some(p.radius_m),
        p.e_star_pa,
        solver_options(p)?,
    )?)
}

/// One model's maps at the demo's loads (`parameter`: the hardness in Pa or k in Pa/m, as
/// [`ModelBody::evaluate`]) compared with the micrographs, as `compare` does (no dihedral
/// search, 1/20 px, 1 % force tolerance).
pub fn compare_model(
    p: &DemoParams,
    experiment: &Experiment,
    body: &ModelBody,
    (name, family, parameter): (&str, Family, Option<f64>),
) -> Result<Comparison> {
    let settings = CompareSettings {
        psf_fwhm_m: p.psf_fwhm_m,
        dihedral: false,
        upsample: 20,
        force_tolerance: 0.01,
    };
    let (_, maps, _) = body.evaluate(family, parameter, &p.loads_n, true)?;
    let maps =
        maps.ok_or_else(|| Error::InvalidArgument(format!("{name}: the maps were not kept")))?;
    let simulated: Vec<SimulatedMap> = maps
        .into_iter()
        .zip(&p.loads_n)
        .map(|(m, &f)| {
            Ok(SimulatedMap {
                force_n: f,
                map: Grid::new(
                    m,
                    body.body.nx(),
                    body.body.ny(),
                    body.body.dx_m,
                    body.body.dy_m,
                )?,
                source: name.to_string(),
            })
        })
        .collect::<Result<_>>()?;
    Ok(compare_maps(
        &experiment.micrographs,
        &simulated,
        &settings,
    )?)
}

fn roughness(p: &DemoParams) -> Result<Topography> {
    Ok(self_affine(&SelfAffineParams {
        nx: p.size,
        ny: p.size,
        dx_m: p.sim_pixel_m,
        hurst: p.hurst,
        rolloff_wavelength_m: Some(p.rolloff_m),
        short_cutoff_wavelength_m: Some(p.cutoff_m),
        target: RmsTarget::Slope(p.rms_slope),
        seed: p.seed,
    })?)
}

/// The hardening ramp at the true k: areas (m²) and contact maps.
fn truth_ramp(p: &DemoParams, roughness: &Topography) -> Result<(Vec<f64>, Vec<Grid>)> {
    let mut body = roughness.clone();
    body.add_sphere(p.radius_m)?;
    let setup = Setup {
        topography: &body,
        e_star_pa: p.e_star_pa,
        boundary: Boundary::Free,
        model: Model::Hardening {
            modulus_pa_per_m: p.k_pa_per_m,
            initial_pa: 0.0,
        },
        options: SolverOptions {
            gap_scale_m: Some(roughness.rms_height()),
            ..solver_options(p)?
        },
    };
    let steps = sweep(&setup, &p.loads_n, &|_, _| {})?;
    if steps.iter().any(|s| s.edge_contact) {
        return Err(Error::InvalidArgument(
            "demo parameters: the contact reaches the border of the map".into(),
        ));
    }
    let maps = steps
        .iter()
        .map(|s| {
            let contact = s
                .solution
                .pressure
                .iter()
                .map(|&v| f64::from(u8::from(v > 0.0)))
                .collect();
            Grid::new(contact, body.nx(), body.ny(), body.dx_m, body.dy_m)
        })
        .collect::<contactscope::Result<_>>()?;
    Ok((steps.iter().map(|s| s.area_m2).collect(), maps))
}

/// 12-bit micrographs of the truth maps, [`MICROGRAPH_OFFSET_PX`] off the centre;
/// `series.tif` + `manifest.csv`.
fn write_micrographs(p: &DemoParams, maps: &[Grid], data: &Path) -> Result<PathBuf> {
    let dir = data.join("micrographs");
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    // The rendered map's side, as `compare` renders a simulated map of the same grid.
    let pixel = (p.image_pixel_m, p.image_pixel_m);
    let span = microscope_image(&maps[0], p.psf_fwhm_m, pixel)?.width;
    let place = |offset: i64| {
        let centred = (p.image_size.saturating_sub(span) / 2) as i64;
        usize::try_from(centred + offset).map_err(|_| {
            Error::InvalidArgument("demo parameters: the micrograph is too small".into())
        })
    };
    let corner = (
        place(MICROGRAPH_OFFSET_PX.0)?,
        place(MICROGRAPH_OFFSET_PX.1)?,
    );
    let pages: Vec<Vec<u16>> = maps
        .iter()
        .enumerate()
        .map(|(i, map)| {
            render_micrograph(
                map,
                &MicrographParams {
                    fwhm_m: p.psf_fwhm_m,
                    pixel_m: p.image_pixel_m,
                    width: p.image_size,
                    height: p.image_size,
                    corner_px: corner,
                    background: 300.0,
                    contact_level: 2400.0,
                    counts_per_photon: p.counts_per_photon,
                    seed: p.seed + i as u64,
                },
            )
        })
        .collect::<contactscope::Result<_>>()?;
    let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(
        &refs,
        p.image_size,
        p.image_size,
        Some(pixel),
        "contactscope demo: synthetic confocal load series\n",
    )?;
    write_atomic(&dir.join("series.tif"), &tiff)?;
    let mut manifest = String::from("file,page,force_mN\n");
    for (i, f) in p.loads_n.iter().enumerate() {
        manifest.push_str(&format!("series.tif,{i},{}\n", f * 1e3));
    }
    let path = dir.join("manifest.csv");
    write_atomic(&path, manifest.as_bytes())?;
    Ok(path)
}
