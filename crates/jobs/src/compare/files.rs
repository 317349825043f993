//! The outputs of `compare` as the command line writes them, through a staging folder (all or
//! nothing): `compare.csv` (every score per load), `compare.json` (the outcome) and one
//! `panel_NNN.png` per matched load (feature `plots`: the micrograph and the simulation on its
//! grey scale, the experiment's contact edges in green on both, as Fig. 2a).

use std::path::{Path, PathBuf};

use contactscope::compare::LoadComparison;
#[cfg(feature = "plots")]
use contactscope::compare::Prepared;

use super::{load_micrographs, run_with, CompareOutcome, CompareRequest, Simulation};
use crate::error::Result;
use crate::series::Series;
use crate::staging::Staging;
use crate::summary::summary_json;
use crate::table::csv_text;

/// Run `compare` and write its folder: the outcome and the files written (final paths).
pub fn run_to_folder(
    request: &CompareRequest,
    out_dir: &Path,
    command_line: &[String],
) -> Result<(CompareOutcome, Vec<PathBuf>)> {
    request.check()?;
    let (series, micrographs) = load_micrographs(&request.micrographs, request.pixel_size_m)?;
    let outcome = run_with(request, &micrographs)?;
    let staging = Staging::new(out_dir, &input_files(request, &series))?;
    staging.write("compare.csv", compare_csv(&outcome.loads)?.as_bytes())?;
    #[cfg(feature = "plots")]
    for (i, p) in outcome.prepared.iter().enumerate() {
        staging.write(
            &format!("panel_{:03}.png", i + 1),
            &panel(p, &outcome.loads[i], outcome.experiment_threshold)?,
        )?;
    }
    staging.write("compare.json", &summary_json(command_line, &outcome)?)?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// Micrograph | simulated image on the micrograph's grey scale, the experiment's contact edges
/// in green on both (Fig. 2a style).
#[cfg(feature = "plots")]
fn panel(p: &Prepared, load: &LoadComparison, t_exp: f64) -> Result<Vec<u8>> {
    let (w, h) = p.size();
    let mask: Vec<bool> = p.micrograph().iter().map(|&v| v > t_exp).collect();
    let simulated = p.simulated_on_scale(load);
    let scale = (512 / w.max(h)).clamp(1, 4);
    crate::plot::edge_panels_png(&[p.micrograph(), &simulated], w, h, &mask, scale)
}

fn compare_csv(loads: &[LoadComparison]) -> Result<String> {
    csv_text(|w| {
        w.write_record([
            "force_mN",
            "simulated_force_mN",
            "transform",
            "shift_x_px",
            "shift_y_px",
            "shift_x_um",
            "shift_y_um",
            "correlation_peak",
            "refinement",
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
        ])?;
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
        for l in loads {
            w.write_record([
                format!("{:.6}", l.force_n * 1e3),
                format!("{:.6}", l.simulated_force_n * 1e3),
                l.transform.name(),
                format!("{:.3}", l.shift_px.0),
                format!("{:.3}", l.shift_px.1),
                format!("{:.4}", l.shift_m.0 * 1e6),
                format!("{:.4}", l.shift_m.1 * 1e6),
                format!("{:.4}", l.correlation_peak),
                l.refinement.name().to_string(),
                format!("{:.4}", l.experiment_area_m2 * 1e12),
                format!("{:.4}", l.simulated_area_m2 * 1e12),
                format!("{:.4}", l.simulated_raw_area_m2 * 1e12),
                opt((l.experiment_area_m2 > 0.0)
                    .then(|| l.simulated_area_m2 / l.experiment_area_m2)),
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
            ])?;
        }
        Ok(())
    })
}

fn input_files(request: &CompareRequest, series: &Series) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = series.files.iter().map(|f| f.path.clone()).collect();
    if let Some(m) = &series.manifest {
        files.push(m.clone());
    }
    if let Simulation::Folder(dir) = &request.simulation {
        files.push(dir.join("areas.csv"));
    }
    files
}
