//! `contactscope demo`: the whole method of Weber et al. 2018 on a synthetic experiment made by
//! the project's own generators and solver, with known truth.
//!
//! The experiment: a self-affine rough sphere (seeded) is pressed through a load ramp with linear
//! contact hardening at a known k; each load's contact map is rendered as a 12-bit confocal image
//! (PSF blur, background, shot noise, ImageJ calibration). Beside it: a bead z stack (known PSF),
//! a reflection/fluorescence pair with Newton rings (known detection gap), rheometer traces with
//! static friction τ·A (known τ) and a squeeze test (known E*). The demo then analyses it all
//! with the same library calls as the commands (`analyze`, `psf`, `newton`, `friction`, `hertz`,
//! `fit-hardening`, `compare`, `autocorr`), simulates all four models, and writes a report folder
//! with `index.html`. Every recovered number is listed next to its truth.
//!
//! The standard demo is in the paper's regime ([`DemoParams::standard`]: R = 290 µm, 4–400 mN,
//! a patchy contact at the lightest load and a near-Hertzian disc ~55 µm across at the heaviest,
//! 200 nm micrographs); it takes one to two minutes on 2 cores, most of it in `fit-hardening`
//! (about 30 load ramps). [`DemoParams::reduced`] (`--small`) is a 10 µm toy for the tests.

mod experiment;
mod html;

pub use experiment::{
    compare_model, fit_search, imaging, model_body, synthetic_experiment, Experiment,
    MICROGRAPH_OFFSET_PX,
};

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::analyze::files::{run_to_folder as analyze_to_folder, ImageOutputs};
use crate::analyze::AnalyzeRequest;
use crate::error::{Error, Result};
use crate::fit_hardening::files::run_to_folder as fit_to_folder;
use crate::fit_hardening::{BodyRequest, FitRequest, MeasuredInput};
use crate::friction::{files::run_to_folder as friction_to_folder, FrictionRequest};
use crate::heights::HeightInput;
use crate::heights::TopographySource;
use crate::hertz::{files::run_to_folder as hertz_to_folder, HertzRequest};
use crate::images::ImageInput;
use crate::newton::{files::run_to_folder as newton_to_folder, NewtonRequest};
use crate::psf::{files::run_to_folder as psf_to_folder, PsfRequest};
use crate::series::{Micrographs, SeriesSpec};
use crate::simulate::DeviceChoice;
use crate::staging::write_atomic;
use contactscope::compare::Comparison;
use contactscope::mechanics::friction::{SlipOptions, XAxis};
use contactscope::model_fit::Family;
use contactscope::synth::beads::{synth_beads, BeadParams};
use contactscope::synth::rings::{synth_newton, NewtonSynthParams};
use contactscope::synth::traces::{synthetic_trace, trace_csv, CsvLayout, TraceParams};
use contactscope_formats::tiff::write::encode_u16_stack;

/// The synthetic experiment's truth and sizes. SI units.
#[derive(Debug, Clone, Serialize)]
pub struct DemoParams {
    /// Simulation grid, pixels per side.
    pub size: usize,
    /// Simulation pixel, m.
    pub sim_pixel_m: f64,
    /// Hurst exponent of the roughness.
    pub hurst: f64,
    /// RMS slope of the roughness.
    pub rms_slope: f64,
    /// Roll-off wavelength, m.
    pub rolloff_m: f64,
    /// Short-wavelength cutoff, m.
    pub cutoff_m: f64,
    /// Sphere radius, m.
    pub radius_m: f64,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// Hardening coefficient k, Pa/m (p_Y = k·h_pl).
    pub k_pa_per_m: f64,
    /// Normal forces of the ramp, N.
    pub loads_n: Vec<f64>,
    /// Micrograph pixel, m.
    pub image_pixel_m: f64,
    /// Micrograph side, pixels.
    pub image_size: usize,
    /// PSF FWHM, m.
    pub psf_fwhm_m: f64,
    /// Detector grey levels per photon of the micrographs (their shot noise: 4 gives a standard
    /// deviation of about 2·√I grey levels).
    pub counts_per_photon: f64,
    /// Interfacial shear strength τ, Pa.
    pub tau_pa: f64,
    /// Detection gap of the rigidochromic layer, m.
    pub detection_gap_m: f64,
    /// Grid points of each one-parameter fit.
    pub fit_grid: usize,
    /// Seed of everything random.
    pub seed: u64,
    /// Where the contact solver runs.
    pub device: DeviceChoice,
}

impl DemoParams {
    /// The default demo, in the paper's regime: an 81.9 µm map (512² at 160 nm) of a rough
    /// R = 290 µm sphere, E* = 3.7 GPa, k = 4 MPa/nm, 8 loads log-spaced over 4–400 mN,
    /// 432² micrographs at 200 nm with a 450 nm PSF. The map holds the 400 mN contact of every
    /// model the fit tries (the penetration hardness's is the widest, ~70 µm across).
    pub fn standard() -> Self {
        DemoParams {
            size: 512,
            sim_pixel_m: 160e-9,
            hurst: 0.8,
            rms_slope: 0.1,
            rolloff_m: 8e-6,
            cutoff_m: 384e-9,
            radius_m: 290e-6,
            e_star_pa: 3.7e9,
            k_pa_per_m: 4e15,
            loads_n: log_spaced(4e-3, 400e-3, 8),
            image_pixel_m: 200e-9,
            image_size: 432,
            psf_fwhm_m: 450e-9,
            counts_per_photon: 4.0,
            tau_pa: 50e6,
            detection_gap_m: 9e-9,
            fit_grid: 5,
            seed: 2018,
            device: DeviceChoice::Cpu,
        }
    }

    /// The reduced demo of the test suite (`--small`): the same pipeline on a 7.7 µm map
    /// (96² at 80 nm) of an R = 50 µm sphere at 4 loads of 0.05–0.35 mN, 48² micrographs; it runs
    /// in seconds.
    pub fn reduced() -> Self {
        DemoParams {
            size: 96,
            sim_pixel_m: 80e-9,
            rolloff_m: 2e-6,
            cutoff_m: 240e-9,
            radius_m: 50e-6,
            loads_n: vec![0.05e-3, 0.1e-3, 0.2e-3, 0.35e-3],
            image_size: 48,
            ..DemoParams::standard()
        }
    }
}

/// `n` forces from `first` to `last` evenly spaced in log, N.
fn log_spaced(first: f64, last: f64, n: usize) -> Vec<f64> {
    let ratio = (last / first).ln() / (n - 1) as f64;
    (0..n).map(|i| first * (ratio * i as f64).exp()).collect()
}

/// One recovered number beside its truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Recovered {
    /// What it is.
    pub quantity: String,
    /// Unit of `truth` and `recovered`.
    pub unit: String,
    /// The generator's value.
    pub truth: f64,
    /// What the analysis found.
    pub recovered: f64,
    /// Its uncertainty (standard error or spread), when known.
    pub uncertainty: Option<f64>,
    /// Its 95 % interval (lo, hi), in `unit`, when the command gives one.
    pub interval: Option<(f64, f64)>,
    /// Which command recovered it.
    pub by: String,
}

impl Recovered {
    /// recovered / truth − 1.
    pub fn relative_error(&self) -> f64 {
        self.recovered / self.truth - 1.0
    }
}

/// What the demo did.
#[derive(Debug, Clone)]
pub struct DemoOutcome {
    /// Recovered numbers with their truth.
    pub recovered: Vec<Recovered>,
    /// Mean Dice per model against the micrographs.
    pub dice: Vec<(String, f64)>,
    /// The report folder.
    pub out_dir: PathBuf,
    /// The report page.
    pub index: PathBuf,
}

/// Progress messages (one line per stage).
pub type DemoProgress<'a> = &'a dyn Fn(&str);

/// Run the demo into `out_dir` (created; a previous demo report there is replaced, any other
/// non-empty folder is refused).
pub fn run_demo(out_dir: &Path, p: &DemoParams, progress: DemoProgress) -> Result<DemoOutcome> {
    let (work, created) = prepare_folder(out_dir)?;
    let result = build(&work, p, progress);
    crate::staging::unregister(&work);
    match result {
        Ok(mut outcome) => {
            replace_folder(&work, out_dir)?;
            created.keep();
            outcome.out_dir = out_dir.to_path_buf();
            outcome.index = out_dir.join("index.html");
            Ok(outcome)
        }
        Err(e) => {
            let _ = std::fs::remove_dir_all(&work);
            Err(e)
        }
    }
}

/// A fresh work folder beside `out_dir`; checks that `out_dir` may be replaced.
fn prepare_folder(out_dir: &Path) -> Result<(PathBuf, crate::staging::CreatedFolders)> {
    if out_dir.exists() {
        let previous_demo = out_dir.join("demo.json").is_file();
        let empty = std::fs::read_dir(out_dir)
            .map(|mut d| d.next().is_none())
            .unwrap_or(false);
        if !(previous_demo || empty) {
            return Err(Error::Output {
                path: out_dir.to_path_buf(),
                reason: "exists and is not an earlier demo report; choose another --out".into(),
            });
        }
    }
    let name = out_dir
        .file_name()
        .map_or("demo".into(), |n| n.to_string_lossy().into_owned());
    let parent = match out_dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    // `contactscope-out/` and any other folder created here go again if the demo ends without
    // a report (an error, Ctrl-C).
    let created = crate::staging::CreatedFolders::create(&parent)?;
    let work = parent.join(format!(".{name}.demo-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).map_err(|e| Error::io(&work, e))?;
    // Removed by the command line's signal handler if the demo is interrupted.
    crate::staging::register(&work);
    Ok((work, created))
}

fn replace_folder(work: &Path, out_dir: &Path) -> Result<()> {
    if out_dir.exists() {
        std::fs::remove_dir_all(out_dir).map_err(|e| Error::io(out_dir, e))?;
    }
    std::fs::rename(work, out_dir).map_err(|e| Error::io(out_dir, e))
}

fn build(work: &Path, p: &DemoParams, progress: DemoProgress) -> Result<DemoOutcome> {
    let data = work.join("data");
    let experiment = synthetic_experiment(p, &data, progress)?;
    let mut recovered = Vec::new();

    // The PSF first: the area intervals take the width the beads give.
    progress("psf: beads");
    recovered.push(psf(work, &data, p)?);
    let fwhm_m = recovered[0].recovered * 1e-9;

    progress("analyze: global Otsu threshold, contact areas");
    let (measured, measured_intervals) = analyze(work, &experiment.manifest, fwhm_m)?;
    progress("newton: detection gap");
    recovered.extend(newton(work, &data, p)?);
    progress("hertz: squeeze test");
    recovered.push(hertz(work, &data, p)?);
    progress("friction: rheometer traces");
    recovered.push(friction(work, &data, p, &measured)?);

    progress("fit-hardening: all four models against the measured curve");
    let fit = fit(work, &data, p)?;
    recovered.push(fit.k.clone());

    progress("compare: simulated maps against the micrographs");
    let comparisons = compare_models(p, &experiment, &fit)?;
    let dice = comparisons
        .iter()
        .map(|(name, c)| {
            let mean = c.loads.iter().map(|l| l.dice).sum::<f64>() / c.loads.len().max(1) as f64;
            (name.clone(), mean)
        })
        .collect();
    let facts = html::Facts {
        params: p,
        recovered: &recovered,
        comparisons: &comparisons,
        measured: &measured,
        measured_intervals: &measured_intervals,
        truth_areas_m2: &experiment.truth_areas_m2,
        fits: &fit.fits,
    };
    html::write_report(work, &facts)?;
    Ok(DemoOutcome {
        recovered,
        dice,
        out_dir: work.to_path_buf(),
        index: work.join("index.html"),
    })
}

/// Measured (force N, contact pixels' area m²) from `analyze`, and each image's corrected area
/// and 95 % interval on the true area (corrected, lo, hi), m².
type MeasuredCurve = (Vec<(f64, f64)>, Vec<(f64, f64, f64)>);

fn analyze(work: &Path, manifest: &Path, psf_fwhm_m: f64) -> Result<MeasuredCurve> {
    let request = AnalyzeRequest {
        memory_budget: 64 << 20,
        psf_fwhm_m: Some(psf_fwhm_m),
        ..AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
            manifest: Some(manifest.to_path_buf()),
            ..SeriesSpec::default()
        }))
    };
    let (outcome, _) = analyze_to_folder(
        &request,
        &work.join("analysis"),
        &["contactscope demo".into()],
        ImageOutputs {
            overlays: true,
            ..ImageOutputs::default()
        },
        &|_, _, _| {},
    )?;
    let rows = &outcome.rows.rows;
    Ok((
        rows.iter()
            .map(|r| (r.force_mn.unwrap_or(f64::NAN) * 1e-3, r.area * 1e-12))
            .collect(),
        rows.iter()
            .map(|r| {
                (
                    r.area_corrected * 1e-12,
                    r.area_lo * 1e-12,
                    r.area_hi * 1e-12,
                )
            })
            .collect(),
    ))
}

fn psf(work: &Path, data: &Path, p: &DemoParams) -> Result<Recovered> {
    let pixel = 100e-9;
    let sigma_m = p.psf_fwhm_m / contactscope::optics::blur::FWHM_PER_SIGMA;
    let beads = synth_beads(&BeadParams {
        planes: 9,
        sigma_px: sigma_m / pixel,
        seed: p.seed,
        ..BeadParams::default()
    })?;
    let path = data.join("beads.tif");
    let pages: Vec<&[u16]> = beads.planes.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(&pages, beads.width, beads.height, Some((pixel, pixel)), "")?;
    write_atomic(&path, &tiff)?;
    let (outcome, _) = psf_to_folder(
        &PsfRequest::new(ImageInput::File(path)),
        &work.join("psf"),
        &["contactscope demo".into()],
    )?;
    let s = &outcome.report.summary;
    Ok(Recovered {
        quantity: "PSF FWHM".into(),
        unit: "nm".into(),
        truth: p.psf_fwhm_m * 1e9,
        recovered: s.sigma_m.mean * contactscope::optics::blur::FWHM_PER_SIGMA * 1e9,
        uncertainty: s
            .sigma_m
            .sd
            .map(|sd| sd * contactscope::optics::blur::FWHM_PER_SIGMA * 1e9),
        interval: None,
        by: "psf".into(),
    })
}

fn newton(work: &Path, data: &Path, p: &DemoParams) -> Result<Vec<Recovered>> {
    let synth = synth_newton(&NewtonSynthParams {
        width: 192,
        height: 192,
        centre_px: (95.37, 97.62),
        contact_radius_m: 9e-6,
        detection_gap_m: p.detection_gap_m,
        psf_fwhm_m: p.psf_fwhm_m,
        counts_per_photon: Some(4.0),
        seed: p.seed,
        ..NewtonSynthParams::default()
    })?;
    let size = Some((200e-9, 200e-9));
    let write = |name: &str, codes: &[u16]| -> Result<PathBuf> {
        let path = data.join(name);
        write_atomic(&path, &encode_u16_stack(&[codes], 192, 192, size, "")?)?;
        Ok(path)
    };
    let reflection = write("reflection.tif", &synth.reflection)?;
    let fluorescence = write("fluorescence.tif", &synth.fluorescence)?;
    let (outcome, _) = newton_to_folder(
        &NewtonRequest::new(ImageInput::File(reflection), ImageInput::File(fluorescence)),
        &work.join("newton"),
        &["contactscope demo".into()],
    )?;
    let a = &outcome.analysis;
    Ok(vec![Recovered {
        quantity: "detection gap".into(),
        unit: "nm".into(),
        truth: p.detection_gap_m * 1e9,
        recovered: a.detection_gap_m.mean * 1e9,
        uncertainty: a.detection_gap_m.sd.map(|s| s * 1e9),
        interval: None,
        by: "newton".into(),
    }])
}

fn hertz(work: &Path, data: &Path, p: &DemoParams) -> Result<Recovered> {
    // A 290 µm sphere squeezed between plates, 2–50 mN, 5 nm displacement noise.
    let radius = 290e-6;
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(p.seed);
    let mut text = String::from("force_mN,displacement_um\n");
    for i in 0..25 {
        let force = 2e-3 + 48e-3 * f64::from(i) / 24.0;
        let delta = contactscope::mechanics::hertz::approach(force, radius, p.e_star_pa);
        let noise: f64 = rand_distr::Distribution::sample(&rand_distr::StandardNormal, &mut rng);
        text.push_str(&format!(
            "{},{}\n",
            force * 1e3,
            (2.0 * delta + 5e-9 * noise) * 1e6
        ));
    }
    let path = data.join("squeeze.csv");
    write_atomic(&path, text.as_bytes())?;
    let (outcome, _) = hertz_to_folder(
        &HertzRequest {
            input: path,
            radius_m: radius,
            loads_n: Some(p.loads_n.clone()),
        },
        &work.join("hertz"),
        &["contactscope demo".into()],
    )?;
    Ok(Recovered {
        quantity: "contact modulus E*".into(),
        unit: "GPa".into(),
        truth: p.e_star_pa * 1e-9,
        recovered: outcome.fit.e_star_pa * 1e-9,
        uncertainty: Some(outcome.fit.e_star_se_pa * 1e-9),
        interval: None,
        by: "hertz".into(),
    })
}

/// Traces whose static friction is τ times the contact area the microscope measures (the
/// paper's F = τ·A relation is between friction and the measured area).
fn friction(
    work: &Path,
    data: &Path,
    p: &DemoParams,
    measured: &[(f64, f64)],
) -> Result<Recovered> {
    let dir = data.join("friction");
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let mut traces = Vec::new();
    for (i, &(force, area)) in measured.iter().enumerate() {
        let f_s = p.tau_pa * area;
        let trace = synthetic_trace(&TraceParams {
            static_friction_n: f_s,
            kinetic_friction_n: 0.8 * f_s,
            // Loading over 20 µm of drive, as the generator's default trace.
            stiffness_n_per_m: f_s / 20e-6,
            wiggle_n: 0.01 * f_s,
            noise_n: 0.003 * f_s,
            seed: p.seed + i as u64,
            ..TraceParams::default()
        });
        let text = trace_csv(
            &trace,
            &CsvLayout {
                x_axis: XAxis::Displacement,
                torque: false,
                rotation_radius_m: 5e-3,
                normal_force_n: Some(force),
            },
        );
        let path = dir.join(format!("trace_{:02}.csv", i + 1));
        write_atomic(&path, text.as_bytes())?;
        traces.push(path);
    }
    let (outcome, _) = friction_to_folder(
        &FrictionRequest {
            traces,
            normal_force_n: None,
            rotation_radius_m: None,
            areas: Some(work.join("analysis").join("areas.csv")),
            force_tolerance: 0.02,
            slip: SlipOptions::default(),
        },
        &work.join("friction"),
        &["contactscope demo".into()],
    )?;
    let shear = outcome
        .shear
        .ok_or_else(|| Error::InvalidArgument("no τ fit".into()))?;
    Ok(Recovered {
        quantity: "interfacial shear strength τ".into(),
        unit: "MPa".into(),
        truth: p.tau_pa * 1e-6,
        recovered: shear.tau_pa * 1e-6,
        uncertainty: shear.tau_se_pa.map(|s| s * 1e-6),
        interval: None,
        by: "friction".into(),
    })
}

/// The fitted parameters of the demo's model fit.
struct FitResult {
    k: Recovered,
    fits: Vec<contactscope::model_fit::ModelFit>,
    k_pa_per_m: f64,
    hardness_pa: f64,
}

fn fit(work: &Path, data: &Path, p: &DemoParams) -> Result<FitResult> {
    let search = |family| fit_search(p, family);
    let body = BodyRequest {
        radius_m: Some(p.radius_m),
        imaging: Some(imaging(p)),
        device: p.device,
        ..BodyRequest::new(
            HeightInput::File(TopographySource {
                path: data.join("topography.npy"),
                pixel_size_m: Some((p.sim_pixel_m, p.sim_pixel_m)),
                height_unit_m: None,
                detrend: contactscope::surface::Detrend::None,
                channel: None,
                fill_invalid: None,
                measurement: None,
            }),
            p.e_star_pa,
        )
    };
    let request = FitRequest {
        families: Family::ALL.to_vec(),
        searches: vec![
            (Family::Hardening, search(Family::Hardening)),
            (Family::Hardness, search(Family::Hardness)),
        ],
        ..FitRequest::new(
            MeasuredInput::File(work.join("analysis").join("areas.csv")),
            body,
        )
    };
    let (outcome, _) = fit_to_folder(
        &request,
        &work.join("fit"),
        &["contactscope demo".into()],
        None,
    )?;
    let parameter = |family: Family| {
        outcome
            .fits()
            .find(|f| f.family == family)
            .and_then(|f| {
                f.best
                    .parameter
                    .map(|v| (v, f.parameter_se, f.parameter_ci95))
            })
            .ok_or_else(|| Error::InvalidArgument(format!("no {} fit", family.name())))
    };
    let (k, k_se, k_ci) = parameter(Family::Hardening)?;
    let (hardness, _, _) = parameter(Family::Hardness)?;
    Ok(FitResult {
        k: Recovered {
            quantity: "hardening coefficient k".into(),
            unit: "MPa/nm".into(),
            truth: p.k_pa_per_m * 1e-15,
            recovered: k * 1e-15,
            uncertainty: k_se.map(|s| s * 1e-15),
            interval: k_ci.map(|(lo, hi)| (lo * 1e-15, hi * 1e-15)),
            by: "fit-hardening".into(),
        },
        k_pa_per_m: k,
        hardness_pa: hardness,
        fits: outcome.fits().cloned().collect(),
    })
}

/// Each model's maps at the loads (fitted parameters), compared with the micrographs.
fn compare_models(
    p: &DemoParams,
    experiment: &Experiment,
    fit: &FitResult,
) -> Result<Vec<(String, Comparison)>> {
    let body = model_body(p, experiment)?;
    let models = [
        ("Greenwood–Tripp", Family::GreenwoodTripp, None),
        ("elastic", Family::Elastic, None),
        (
            "penetration hardness",
            Family::Hardness,
            Some(fit.hardness_pa),
        ),
        ("linear hardening", Family::Hardening, Some(fit.k_pa_per_m)),
    ];
    models
        .iter()
        .map(|&model| {
            Ok((
                model.0.to_string(),
                compare_model(p, experiment, &body, model)?,
            ))
        })
        .collect()
}
