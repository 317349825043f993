//! The `fit-hardening` job: read the measured curve and the topography, fit every requested model,
//! optionally sweep one parameter (Supplementary Fig. 8) with Dice against the micrographs, and
//! write the tables, JSON and plots through a staging folder.

use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde_json::{json, Value};

use crate::compare::{load_micrographs, ExperimentInput};
use crate::error::{Error, Location, Result};
use crate::heights::TopographySource;
use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
use crate::results::read_areas_csv;
use crate::staging::Staging;
use contactscope::compare::{compare_maps, CompareSettings, Micrographs, SimulatedMap};
use contactscope::model_fit::{
    fit_parameter, Evaluation, Family, Imaging, Measured, ModelBody, ModelFit, ProgressHook, Search,
};
use contactscope::optics::blur::Grid;
use contactscope::solver::cg::SolverOptions;
use contactscope::surface::stats::SurfaceStats;
use contactscope_formats::units::{self, Dimension};

/// A parameter sweep: one family, explicit values (Pa or Pa/m).
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// Hardness or hardening.
    pub family: Family,
    /// Parameter values.
    pub values: Vec<f64>,
}

impl Sweep {
    /// Parse `k=1..10MPa/nm:10`, `k=1,2,4MPa/nm` or `hardness=100..1000MPa:10` (evenly spaced).
    pub fn parse(text: &str) -> Result<Self> {
        let (name, values) = text.split_once('=').ok_or_else(|| {
            Error::InvalidArgument(format!(
                "sweep '{text}' must read k=1..10MPa/nm:10 or hardness=100..1000MPa:10"
            ))
        })?;
        let (family, values) = match name.trim() {
            "k" => (
                Family::Hardening,
                units::parse_value_list(values, &|t| {
                    units::parse_ratio(t, Dimension::Pressure, Dimension::Length)
                })?,
            ),
            "hardness" | "pY" | "p_Y" => (
                Family::Hardness,
                units::parse_value_list(values, &|t| {
                    units::parse_positive(t, Dimension::Pressure)
                })?,
            ),
            other => {
                return Err(Error::InvalidArgument(format!(
                    "sweep parameter '{other}' is not k or hardness"
                )))
            }
        };
        if values.iter().any(|v| v.is_nan() || *v <= 0.0) {
            return Err(Error::InvalidArgument(format!(
                "sweep '{text}' needs positive values"
            )));
        }
        Ok(Sweep { family, values })
    }
}

/// Micrographs to score sweeps against.
#[derive(Debug, Clone)]
pub struct SweepMicrographs {
    /// The experiment series (with forces).
    pub experiment: ExperimentInput,
    /// Channel of multi-channel files.
    pub channel: Option<usize>,
    /// Pixel size override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// PSF, registration and matching.
    pub settings: CompareSettings,
}

/// Everything `fit-hardening` needs, already parsed.
#[derive(Debug, Clone)]
pub struct FitRequest {
    /// `areas.csv` of `analyze` (columns `force_mN`, `area_um2`).
    pub experiment: PathBuf,
    /// Height map, read and detrended as stated.
    pub topography: TopographySource,
    /// Sphere radius added to the map (and the GT sphere), m.
    pub radius_m: Option<f64>,
    /// Contact modulus E*, Pa.
    pub e_star_pa: f64,
    /// Periodic boundaries.
    pub periodic: bool,
    /// Models to fit.
    pub families: Vec<Family>,
    /// Search settings per fitted family (defaults from [`Search::default_for`]).
    pub searches: Vec<(Family, Search)>,
    /// Optional sweep.
    pub sweep: Option<Sweep>,
    /// Optional micrographs for Dice in the sweep.
    pub micrographs: Option<SweepMicrographs>,
    /// Solver limits.
    pub options: SolverOptions<'static>,
    /// Count simulated areas as imaged (blur, resample, Otsu) instead of raw g = 0 pixels.
    pub imaging: Option<Imaging>,
    /// Output folder.
    pub out_dir: PathBuf,
    /// The command line.
    pub command_line: Vec<String>,
    /// Told of every load solved by every ramp ([`FitRequest::expected_ramps`] estimates how
    /// many ramps there will be).
    pub progress: Option<ProgressHook>,
}

impl FitRequest {
    /// About how many load ramps the fit will run: for progress bars and their time
    /// estimates; the true count differs by a few.
    pub fn expected_ramps(&self) -> usize {
        let ramps: usize = self
            .families
            .iter()
            .map(|&family| match family.has_parameter() {
                true => self
                    .searches
                    .iter()
                    .find(|(f, _)| *f == family)
                    .map_or_else(|| Search::default_for(family), |(_, s)| *s)
                    .expected_ramps(),
                false => 1,
            })
            .sum::<usize>()
            + self.sweep.as_ref().map_or(0, |s| s.values.len());
        ramps
    }
}

/// One sweep value at one load.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    /// Parameter (Pa or Pa/m).
    pub parameter: f64,
    /// Normal force, N.
    pub force_n: f64,
    /// Measured area, m².
    pub measured_area_m2: f64,
    /// Simulated area, m².
    pub simulated_area_m2: f64,
    /// Dice against the micrograph of this load, when micrographs were given.
    pub dice: Option<f64>,
}

/// What `fit-hardening` found and wrote.
#[derive(Debug, Clone)]
pub struct FitOutcome {
    /// The measured curve.
    pub measured: Measured,
    /// One fit per family, in request order.
    pub fits: Vec<ModelFit>,
    /// Sweep rows (empty without a sweep).
    pub sweep: Vec<SweepRow>,
    /// Roughness statistics.
    pub stats: SurfaceStats,
    /// Files written.
    pub written: Vec<PathBuf>,
    /// Notes.
    pub warnings: Vec<String>,
}

impl FitOutcome {
    /// The fit with the lowest misfit.
    pub fn best(&self) -> Option<&ModelFit> {
        self.fits
            .iter()
            .min_by(|a, b| a.best.misfit.total_cmp(&b.best.misfit))
    }
}

/// Run `fit-hardening`.
pub fn run_fit(request: &FitRequest) -> Result<FitOutcome> {
    let measured = read_measured(&request.experiment)?;
    let (body, notes) = model_body(request)?;
    let micrographs = request
        .micrographs
        .as_ref()
        .map(|m| {
            load_micrographs(
                &m.experiment,
                &contactscope_formats::microscopy::select::Selection::channel(m.channel),
                None,
                m.pixel_size_m,
            )
            .map(|(_, micrographs)| micrographs)
        })
        .transpose()?;
    let mut warnings = notes;
    let mut fits = Vec::new();
    for &family in &request.families {
        let fit = fit_family(request, &body, family, &measured)?;
        if fit.best.edge_contact {
            warnings.push(format!(
                "{}: the contact reaches the border of the map; the free-boundary areas are not valid (use a larger map or smaller loads)",
                family.name()
            ));
        }
        if fit.at_range_edge {
            warnings.push(format!(
                "{}: the best value lies at the end of the search range; widen it",
                family.name()
            ));
        }
        fits.push(fit);
    }
    let sweep = match &request.sweep {
        Some(s) => run_sweep(request, &body, s, &measured, micrographs.as_ref())?,
        None => Vec::new(),
    };
    let staging = Staging::new(&request.out_dir, &inputs(request))?;
    staging.write("fit_areas.csv", fit_csv(&measured, &fits)?.as_bytes())?;
    staging.write(
        "fit_area_vs_load.png",
        &fit_chart(&measured, &fits).to_png()?,
    )?;
    if let Some(chart) = misfit_chart(&fits) {
        staging.write("misfit.png", &chart.to_png()?)?;
    }
    if let Some(s) = &request.sweep {
        staging.write("sweep.csv", sweep_csv(s.family, &sweep)?.as_bytes())?;
        staging.write(
            "sweep_area_vs_load.png",
            &sweep_chart(s.family, &measured, &sweep).to_png()?,
        )?;
    }
    let summary = summary_json(request, &measured, &fits, &sweep, &body.stats, &warnings);
    let text = serde_json::to_string_pretty(&summary)
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    staging.write("fit.json", text.as_bytes())?;
    Ok(FitOutcome {
        measured,
        fits,
        sweep,
        stats: body.stats,
        written: staging.commit()?,
        warnings,
    })
}

/// `force_mN` and `area_um2` of an `analyze` table (or any CSV with those columns).
pub fn read_measured(path: &Path) -> Result<Measured> {
    Measured::new(read_areas_csv(path)?)
        .map_err(|e| Error::bad_input(Location::file(path), e.to_string()))
}

fn model_body(request: &FitRequest) -> Result<(ModelBody, Vec<String>)> {
    let (topography, notes) = request.topography.read_with_notes()?;
    let mut body = ModelBody::new(
        topography,
        request.radius_m,
        request.e_star_pa,
        request.options,
    )?;
    body.periodic = request.periodic;
    body.imaging = request.imaging;
    body.progress = request.progress.clone();
    Ok((body, notes))
}

fn fit_family(
    request: &FitRequest,
    body: &ModelBody,
    family: Family,
    measured: &Measured,
) -> Result<ModelFit> {
    if !family.has_parameter() {
        let best = body.score(family, None, measured, false)?;
        return Ok(ModelFit {
            family,
            trace: Vec::new(),
            best,
            parameter_se: None,
            at_range_edge: false,
        });
    }
    let search = request
        .searches
        .iter()
        .find(|(f, _)| *f == family)
        .map_or_else(|| Search::default_for(family), |(_, s)| *s);
    Ok(fit_parameter(body, family, measured, search)?)
}

fn run_sweep(
    request: &FitRequest,
    body: &ModelBody,
    sweep: &Sweep,
    measured: &Measured,
    micrographs: Option<&Micrographs>,
) -> Result<Vec<SweepRow>> {
    let per_value: Vec<Vec<SweepRow>> = sweep
        .values
        .par_iter()
        .map(|&value| {
            let eval = body.score(sweep.family, Some(value), measured, micrographs.is_some())?;
            let dice = match (micrographs, &request.micrographs) {
                (Some(m), Some(settings)) => {
                    Some(dice_per_load(body, &eval, measured, m, &settings.settings)?)
                }
                _ => None,
            };
            Ok(rows_of(value, measured, &eval, dice))
        })
        .collect::<Result<_>>()?;
    Ok(per_value.into_iter().flatten().collect())
}

fn rows_of(
    value: f64,
    measured: &Measured,
    eval: &Evaluation,
    dice: Option<Vec<Option<f64>>>,
) -> Vec<SweepRow> {
    (0..measured.forces_n.len())
        .map(|i| SweepRow {
            parameter: value,
            force_n: measured.forces_n[i],
            measured_area_m2: measured.areas_m2[i],
            simulated_area_m2: eval.areas_m2[i],
            dice: dice.as_ref().and_then(|d| d[i]),
        })
        .collect()
}

/// Dice per measured load (None where no micrograph matches the force).
fn dice_per_load(
    body: &ModelBody,
    eval: &Evaluation,
    measured: &Measured,
    micrographs: &Micrographs,
    settings: &CompareSettings,
) -> Result<Vec<Option<f64>>> {
    let maps = eval.maps.as_ref().expect("maps kept for Dice");
    let simulated: Vec<SimulatedMap> = maps
        .iter()
        .zip(&measured.forces_n)
        .map(|(m, &f)| {
            Ok(SimulatedMap {
                force_n: f,
                map: Grid::new(
                    m.clone(),
                    body.body.nx(),
                    body.body.ny(),
                    body.body.dx_m,
                    body.body.dy_m,
                )?,
                source: format!("simulated at {:.4} mN", f * 1e3),
            })
        })
        .collect::<Result<_>>()?;
    let comparison = compare_maps(micrographs, &simulated, settings)?;
    Ok(measured
        .forces_n
        .iter()
        .map(|&f| {
            comparison
                .loads
                .iter()
                .find(|l| (l.simulated_force_n - f).abs() <= 1e-12 * f)
                .map(|l| l.dice)
        })
        .collect())
}

fn inputs(request: &FitRequest) -> Vec<PathBuf> {
    vec![request.experiment.clone(), request.topography.path.clone()]
}

/// Parameter in display units: MPa for hardness, MPa/nm for hardening.
fn display(family: Family, value: f64) -> f64 {
    match family {
        Family::Hardness => value * 1e-6,
        _ => value * 1e-15,
    }
}

fn unit(family: Family) -> &'static str {
    match family {
        Family::Hardness => "MPa",
        _ => "MPa_per_nm",
    }
}

fn model_label(fit: &ModelFit) -> String {
    let name = match fit.family {
        Family::Elastic => "elastic".to_string(),
        Family::GreenwoodTripp => "Greenwood–Tripp".to_string(),
        Family::Hardness => format!(
            "hardness {:.0} MPa",
            display(Family::Hardness, fit.best.parameter.unwrap_or(f64::NAN))
        ),
        Family::Hardening => format!(
            "hardening k = {:.2} MPa/nm",
            display(Family::Hardening, fit.best.parameter.unwrap_or(f64::NAN))
        ),
    };
    format!("{name} (misfit {:.3})", fit.best.misfit)
}

fn csv_text(
    write: impl FnOnce(&mut csv::Writer<Vec<u8>>) -> std::result::Result<(), csv::Error>,
) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    write(&mut w).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

fn fit_csv(measured: &Measured, fits: &[ModelFit]) -> Result<String> {
    csv_text(|w| {
        let mut header = vec!["force_mN".to_string(), "measured_area_um2".to_string()];
        header.extend(fits.iter().map(|f| format!("{}_area_um2", f.family.name())));
        w.write_record(&header)?;
        for (i, (&f, &a)) in measured.forces_n.iter().zip(&measured.areas_m2).enumerate() {
            let mut row = vec![format!("{:.6}", f * 1e3), format!("{:.6}", a * 1e12)];
            row.extend(
                fits.iter()
                    .map(|fit| format!("{:.6}", fit.best.areas_m2[i] * 1e12)),
            );
            w.write_record(&row)?;
        }
        Ok(())
    })
}

fn sweep_csv(family: Family, rows: &[SweepRow]) -> Result<String> {
    csv_text(|w| {
        w.write_record([
            format!(
                "{}_{}",
                if family == Family::Hardness {
                    "hardness"
                } else {
                    "k"
                },
                unit(family)
            ),
            "force_mN".into(),
            "measured_area_um2".into(),
            "simulated_area_um2".into(),
            "dice".into(),
        ])?;
        for r in rows {
            w.write_record([
                format!("{:.6}", display(family, r.parameter)),
                format!("{:.6}", r.force_n * 1e3),
                format!("{:.6}", r.measured_area_m2 * 1e12),
                format!("{:.6}", r.simulated_area_m2 * 1e12),
                r.dice.map_or(String::new(), |d| format!("{d:.5}")),
            ])?;
        }
        Ok(())
    })
}

fn measured_points(measured: &Measured) -> PointSet {
    PointSet {
        label: "measured".into(),
        xy: measured
            .forces_n
            .iter()
            .zip(&measured.areas_m2)
            .map(|(f, a)| (f * 1e3, a * 1e12))
            .collect(),
    }
}

/// Fig. 3a: measured areas and every model's best curve, log-log.
pub fn fit_chart(measured: &Measured, fits: &[ModelFit]) -> Chart {
    Chart {
        title: "Contact area vs load: experiment and models".into(),
        x_label: "normal force N (mN)".into(),
        y_label: "contact area A (µm²)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points: vec![measured_points(measured)],
        curves: fits
            .iter()
            .map(|fit| Curve {
                label: model_label(fit),
                xy: measured
                    .forces_n
                    .iter()
                    .zip(&fit.best.areas_m2)
                    .map(|(f, a)| (f * 1e3, a * 1e12))
                    .collect(),
            })
            .collect(),
    }
}

fn misfit_chart(fits: &[ModelFit]) -> Option<Chart> {
    let fit = fits
        .iter()
        .find(|f| f.family == Family::Hardening && !f.trace.is_empty())?;
    let mut trace = fit.trace.clone();
    trace.sort_by(|a, b| a.0.total_cmp(&b.0));
    Some(Chart {
        title: "Hardening fit: misfit vs k".into(),
        x_label: "hardening coefficient k (MPa/nm)".into(),
        y_label: "misfit: RMS of ln(simulated / measured area)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperRight,
        points: vec![PointSet {
            label: "evaluated".into(),
            xy: trace
                .iter()
                .map(|&(k, m)| (display(Family::Hardening, k), m))
                .collect(),
        }],
        curves: Vec::new(),
    })
}

fn sweep_chart(family: Family, measured: &Measured, rows: &[SweepRow]) -> Chart {
    let mut values: Vec<f64> = rows.iter().map(|r| r.parameter).collect();
    values.dedup();
    let curves = values
        .iter()
        .map(|&v| Curve {
            label: format!(
                "{} = {:.3} {}",
                if family == Family::Hardness {
                    "hardness"
                } else {
                    "k"
                },
                display(family, v),
                unit(family).replace("_per_", "/")
            ),
            xy: rows
                .iter()
                .filter(|r| r.parameter == v)
                .map(|r| (r.force_n * 1e3, r.simulated_area_m2 * 1e12))
                .collect(),
        })
        .collect();
    Chart {
        title: format!("Parameter sweep ({} model)", family.name()),
        x_label: "normal force N (mN)".into(),
        y_label: "contact area A (µm²)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points: vec![measured_points(measured)],
        curves,
    }
}

fn summary_json(
    request: &FitRequest,
    measured: &Measured,
    fits: &[ModelFit],
    sweep: &[SweepRow],
    stats: &SurfaceStats,
    warnings: &[String],
) -> Value {
    let models: Vec<Value> = fits
        .iter()
        .map(|fit| {
            let mut entry = json!({
                "model": fit.family.name(),
                "misfit_rms_ln_area": fit.best.misfit,
                "areas_um2": fit.best.areas_m2.iter().map(|a| a * 1e12).collect::<Vec<_>>(),
                "evaluations": fit.trace.len(),
                "at_range_edge": fit.at_range_edge,
            });
            if let Some(p) = fit.best.parameter {
                let key = match fit.family {
                    Family::Hardness => "hardness_MPa",
                    _ => "k_MPa_per_nm",
                };
                entry[key] = json!(display(fit.family, p));
                entry[format!("{key}_se")] =
                    json!(fit.parameter_se.map(|s| display(fit.family, s)));
            }
            entry
        })
        .collect();
    let best = fits
        .iter()
        .min_by(|a, b| a.best.misfit.total_cmp(&b.best.misfit))
        .map(|f| f.family.name());
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "command_line": request.command_line,
        "experiment": request.experiment.display().to_string(),
        "topography": request.topography.path.display().to_string(),
        "topography_channel": request.topography.channel,
        "fill_invalid": request.topography.fill_invalid,
        "radius_um": request.radius_m.map(|r| r * 1e6),
        "contact_modulus_GPa": request.e_star_pa * 1e-9,
        "roughness": {
            "h_rms_nm": stats.h_rms_m * 1e9,
            "h_prime_rms": stats.h_prime_rms,
            "h_double_prime_rms_per_um": stats.h_double_prime_rms_per_m * 1e-6,
        },
        "measured": {
            "force_mN": measured.forces_n.iter().map(|f| f * 1e3).collect::<Vec<_>>(),
            "area_um2": measured.areas_m2.iter().map(|a| a * 1e12).collect::<Vec<_>>(),
        },
        "simulated_areas": match &request.imaging {
            Some(i) => json!({
                "counted": "as imaged: blurred by the PSF, integrated onto micrograph pixels, one Otsu threshold per simulated series",
                "psf_fwhm_nm": i.fwhm_m * 1e9,
                "pixel_size_nm": [i.pixel_m.0 * 1e9, i.pixel_m.1 * 1e9],
            }),
            None => json!({ "counted": "raw: simulation pixels with g = 0 (p > 0)" }),
        },
        "method": "least squares in log area: misfit = RMS of ln(A_sim/A_exp) over the measured loads; one-parameter models by a parallel log grid then Brent's method on ln(parameter); SE by Gauss-Newton at the optimum; hardening has p_Y0 = 0 as in the paper",
        "models": models,
        "best_model": best,
        "sweep_rows": sweep.len(),
        "warnings": warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_parse_with_units() {
        let s = Sweep::parse("k=1..10MPa/nm:10").unwrap();
        assert_eq!(s.family, Family::Hardening);
        assert_eq!(s.values.len(), 10);
        assert!((s.values[3] - 4e15).abs() < 1.0);
        let s = Sweep::parse("hardness=100,370MPa").unwrap();
        assert_eq!(s.family, Family::Hardness);
        assert_eq!(s.values, vec![1e8, 3.7e8]);
        assert!(Sweep::parse("alpha=1..2:3").is_err());
        assert!(Sweep::parse("k=1..10MPa").is_err());
    }
}
