//! The `compare` job: micrographs (a manifest, or TIFFs with forces) and a `simulate` output
//! folder in; `compare.csv`, `compare.json` and one `panel_NNN.png` per matched load out. The
//! comparison itself is [`contactscope::compare`].

use std::path::PathBuf;

use serde_json::{json, Value};

use crate::error::{Error, Location, Result};
use crate::plot::edge_panels_png;
use crate::results::simulated_maps;
use crate::series::{self, Series};
use crate::staging::Staging;
use contactscope::analysis::{global_threshold, PlaneSource};
use contactscope::compare::{
    compare_maps, CompareSettings, Comparison, LoadComparison, Micrograph, Micrographs, Prepared,
};
use contactscope::image::{pixel_size_or, Plane};
use contactscope_formats::microscopy::select::{LoadAxis, Selection};

/// Where the micrographs come from.
#[derive(Debug, Clone)]
pub enum ExperimentInput {
    /// A manifest CSV (`file, page, force_mN`), or a folder holding `manifest.csv`.
    Manifest(PathBuf),
    /// TIFF, CZI, ND2 or LIF files or folders with one force per image, N.
    Files {
        /// Files or folders, in natural order.
        inputs: Vec<PathBuf>,
        /// Normal force per image, N.
        forces_n: Vec<f64>,
    },
}

/// Everything `compare` needs, already parsed.
#[derive(Debug, Clone)]
pub struct CompareRequest {
    /// The experiment series.
    pub experiment: ExperimentInput,
    /// Which planes of confocal micrograph files (and the channel of TIFFs).
    pub selection: Selection,
    /// Axis of a CZI, ND2 or LIF micrograph file whose planes are the loads.
    pub load_axis: Option<LoadAxis>,
    /// Micrograph pixel size override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// Output folder of `contactscope simulate` (areas.csv + load_NNN_contact.tif).
    pub simulation: PathBuf,
    /// PSF, registration and load matching.
    pub settings: CompareSettings,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line, for the JSON.
    pub command_line: Vec<String>,
}

/// What `compare` computed and wrote.
#[derive(Debug, Clone)]
pub struct CompareOutcome {
    /// One entry per matched load, in experiment order.
    pub loads: Vec<LoadComparison>,
    /// Experiment threshold (grey levels) and simulated threshold (blurred intensity, 0..1).
    pub thresholds: (f64, f64),
    /// Files written.
    pub written: Vec<PathBuf>,
    /// Notes for the user.
    pub warnings: Vec<String>,
}

/// Run `compare`: match loads, render, register, threshold, score, and write `compare.csv`,
/// `compare.json` and one `panel_NNN.png` per matched load (all or nothing).
pub fn run_compare(request: &CompareRequest) -> Result<CompareOutcome> {
    let (series, micrographs) = load_micrographs(
        &request.experiment,
        &request.selection,
        request.load_axis,
        request.pixel_size_m,
    )?;
    let simulated = simulated_maps(&request.simulation)?;
    let Comparison {
        loads,
        prepared,
        simulated_threshold: sim_threshold,
        warnings,
        ..
    } = compare_maps(&micrographs, &simulated, &request.settings)?;
    let threshold = micrographs.threshold;
    let pixel = micrographs.pixel_m;
    let staging = Staging::new(&request.out_dir, &input_files(request, &series))?;
    staging.write("compare.csv", compare_csv(&loads, pixel)?.as_bytes())?;
    for (i, p) in prepared.iter().enumerate() {
        staging.write(
            &format!("panel_{:03}.png", i + 1),
            &panel(p, &loads[i], threshold)?,
        )?;
    }
    let summary = summary_json(request, &loads, (threshold, sim_threshold), &warnings);
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    staging.write("compare.json", text.as_bytes())?;
    Ok(CompareOutcome {
        loads,
        thresholds: (threshold, sim_threshold),
        written: staging.commit()?,
        warnings,
    })
}

/// Read the experiment series, its forces and pixel size, decode its micrographs and threshold
/// them (one exact Otsu threshold over the series, as `analyze`).
pub fn load_micrographs(
    experiment: &ExperimentInput,
    selection: &Selection,
    load_axis: Option<LoadAxis>,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<(Series, Micrographs)> {
    let series = experiment_series(experiment, selection, load_axis)?;
    let planes: Vec<Plane> = series.planes(0).scan(|_, plane| Ok(plane.clone()))?;
    let (threshold, _, warnings) = global_threshold(planes.as_slice(), &|_, _, _| {})?;
    let pixel_m = experiment_pixel(&series, pixel_size_m)?;
    let images = series
        .images
        .iter()
        .zip(planes)
        .map(|(image, plane)| Micrograph {
            plane,
            force_n: image.force_n,
            path: image.path.clone(),
            page: image.page,
        })
        .collect();
    let micrographs = Micrographs {
        images,
        threshold: threshold.value,
        pixel_m,
        warnings,
    };
    Ok((series, micrographs))
}

fn experiment_series(
    experiment: &ExperimentInput,
    selection: &Selection,
    load_axis: Option<LoadAxis>,
) -> Result<Series> {
    match experiment {
        ExperimentInput::Manifest(path) => {
            let manifest = if path.is_dir() {
                path.join("manifest.csv")
            } else {
                path.clone()
            };
            if !manifest.is_file() {
                return Err(Error::bad_input(
                    Location::file(path),
                    "no manifest: give a manifest CSV (file, page, force_mN) or a folder holding manifest.csv, or TIFF files with --forces",
                ));
            }
            series::from_manifest_selected(&manifest, selection, load_axis)
        }
        ExperimentInput::Files { inputs, forces_n } => {
            let mut s = series::from_files_selected(inputs, selection, load_axis)?;
            series::assign_forces(&mut s, forces_n)?;
            Ok(s)
        }
    }
}

fn experiment_pixel(series: &Series, pixel_size_m: Option<(f64, f64)>) -> Result<(f64, f64)> {
    let first = &series.files[0];
    pixel_size_or(first.pixel_size, pixel_size_m)
        .map(|p| (p.x_m, p.y_m))
        .ok_or_else(|| {
            Error::bad_input(
                Location::file(&first.path),
                "no pixel size in the file's metadata; give one with --pixel-size (e.g. 200nm)",
            )
        })
}

/// Micrograph | simulated image on the micrograph's grey scale, the experiment's contact edges
/// in green on both (Fig. 2a style).
fn panel(p: &Prepared, load: &LoadComparison, t_exp: f64) -> Result<Vec<u8>> {
    let (w, h) = p.size();
    let mask: Vec<bool> = p.micrograph().iter().map(|&v| v > t_exp).collect();
    let simulated = p.simulated_on_scale(load);
    let scale = (512 / w.max(h)).clamp(1, 4);
    edge_panels_png(&[p.micrograph(), &simulated], w, h, &mask, scale)
}

fn compare_csv(loads: &[LoadComparison], pixel: (f64, f64)) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    w.write_record([
        "force_mN",
        "simulated_force_mN",
        "transform",
        "shift_x_px",
        "shift_y_px",
        "shift_x_um",
        "shift_y_um",
        "correlation_peak",
        "experiment_area_um2",
        "simulated_area_um2",
        "simulated_raw_area_um2",
        "area_ratio",
        "dice",
        "jaccard",
        "dice_threshold_minus10pct",
        "dice_threshold_plus10pct",
        "edge_distance_um",
        "acf_rms_distance",
        "experiment_xi_1e_um",
        "simulated_xi_1e_um",
        "intensity_gain",
        "intensity_offset",
        "micrograph",
        "simulated_map",
    ])
    .map_err(csv_err)?;
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
    for l in loads {
        w.write_record([
            format!("{:.6}", l.force_n * 1e3),
            format!("{:.6}", l.simulated_force_n * 1e3),
            l.transform.name(),
            format!("{:.3}", l.shift_px.0),
            format!("{:.3}", l.shift_px.1),
            format!("{:.4}", l.shift_px.0 * pixel.0 * 1e6),
            format!("{:.4}", l.shift_px.1 * pixel.1 * 1e6),
            format!("{:.4}", l.correlation_peak),
            format!("{:.4}", l.experiment_area_m2 * 1e12),
            format!("{:.4}", l.simulated_area_m2 * 1e12),
            format!("{:.4}", l.simulated_raw_area_m2 * 1e12),
            opt((l.experiment_area_m2 > 0.0).then(|| l.simulated_area_m2 / l.experiment_area_m2)),
            format!("{:.5}", l.dice),
            format!("{:.5}", l.jaccard),
            format!("{:.5}", l.dice_threshold_pm10.0),
            format!("{:.5}", l.dice_threshold_pm10.1),
            opt(l.edge_distance_m.map(|d| d * 1e6)),
            opt(l.acf_rms_distance),
            opt(l.xi_1e_m.0.map(|v| v * 1e6)),
            opt(l.xi_1e_m.1.map(|v| v * 1e6)),
            format!("{:.4}", l.intensity.gain),
            format!("{:.4}", l.intensity.offset),
            format!("{}:page {}", l.micrograph.0.display(), l.micrograph.1),
            l.simulated_map.clone(),
        ])
        .map_err(csv_err)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

fn input_files(request: &CompareRequest, series: &Series) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = series.files.iter().map(|f| f.path.clone()).collect();
    if let Some(m) = &series.manifest {
        files.push(m.clone());
    }
    files.push(request.simulation.join("areas.csv"));
    files
}

fn summary_json(
    request: &CompareRequest,
    loads: &[LoadComparison],
    (t_exp, t_sim): (f64, f64),
    warnings: &[String],
) -> Value {
    let per_load: Vec<Value> = loads
        .iter()
        .map(|l| {
            json!({
                "force_mN": l.force_n * 1e3,
                "simulated_force_mN": l.simulated_force_n * 1e3,
                "transform": l.transform.name(),
                "shift_x_px": l.shift_px.0,
                "shift_y_px": l.shift_px.1,
                "correlation_peak": l.correlation_peak,
                "experiment_area_um2": l.experiment_area_m2 * 1e12,
                "simulated_area_um2": l.simulated_area_m2 * 1e12,
                "simulated_raw_area_um2": l.simulated_raw_area_m2 * 1e12,
                "dice": l.dice,
                "jaccard": l.jaccard,
                "edge_distance_um": l.edge_distance_m.map(|d| d * 1e6),
                "acf_rms_distance": l.acf_rms_distance,
            })
        })
        .collect();
    let mean = |f: &dyn Fn(&LoadComparison) -> f64| {
        loads.iter().map(f).sum::<f64>() / loads.len().max(1) as f64
    };
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "simulation": request.simulation.display().to_string(),
        "psf_fwhm_nm": request.settings.psf_fwhm_m * 1e9,
        "experiment_threshold": t_exp,
        "simulated_threshold": t_sim,
        "dihedral_search": request.settings.dihedral,
        "upsample": request.settings.upsample,
        "force_tolerance_pct": request.settings.force_tolerance * 100.0,
        "loads_matched": loads.len(),
        "dice_mean": mean(&|l| l.dice),
        "jaccard_mean": mean(&|l| l.jaccard),
        "method": {
            "simulated_image": "contact map (g = 0) blurred by a Gaussian PSF on the simulation grid, integrated over micrograph pixels (area fraction), centred on a micrograph-sized canvas",
            "registration": "phase correlation with Hann window, upsampled-DFT sub-pixel refinement",
            "thresholds": "experiment: exact Otsu over all micrographs of the series; simulation: Otsu over all blurred simulated images (4096 bins)",
            "scores": "on the region covered by the simulation after registration",
            "edge_distance_um": "mean of the two mean distances from each contact-edge pixel to the other map's nearest edge pixel (exact Euclidean distance transform)",
            "acf_rms_distance": "RMS difference of the radially averaged intensity autocorrelations, lags up to half the smaller micrograph side",
        },
        "loads": per_load,
        "warnings": warnings,
    })
}
