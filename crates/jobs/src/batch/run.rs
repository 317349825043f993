//! One series of a batch, on its own: the unit of work of the command line's loop and of a
//! Dask task. [`run_series`] writes the series' folders exactly as `contactscope analyze` (and
//! `fit-hardening`) would with the command lines it records, hashes its input files while the
//! images are analysed, draws the QC thumbnail of its highest load, and writes its record. It
//! never fails: a failure is the record's status and one-line error, and the series' outputs of
//! an earlier run are removed so that nothing stale stays beside a failed row.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Instant, SystemTime};

use serde::{Deserialize, Serialize};

use contactscope::image::Plane;
use contactscope::measure::Mask;
use contactscope::model_fit::Family;
use contactscope_formats::units::in_unit;

use super::options::{OutputSettings, SeriesOptions};
use super::record::{
    CommandLines, FileRecord, FitSummary, ImageResult, InputState, Outputs, PowerLaw, Record,
    SeriesResult, Status,
};
use crate::analyze::files::{run_open_to_folder, ImageOutputs};
use crate::analyze::{AnalyzeOutcome, AreaUnit, Row};
use crate::error::{Error, Result};
use crate::fit_hardening::FitOutcome;
use crate::provenance;
use crate::series::OpenSeries;

/// Longest side of a QC thumbnail, pixels.
pub const THUMBNAIL_SIDE: usize = 128;

/// Everything one series needs, serialisable (a Dask task carries it as JSON).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeriesTask {
    /// The series id.
    pub id: String,
    /// The input, resolved (a file, a folder or a manifest).
    pub input: PathBuf,
    /// The height map of the fit, resolved.
    pub topography: Option<PathBuf>,
    /// The options: the row's cells over the batch's defaults.
    pub options: SeriesOptions,
    /// Output settings of the whole batch.
    pub settings: OutputSettings,
    /// The batch's folder.
    pub out: PathBuf,
    /// The program's name as recorded at the head of command lines.
    pub program: String,
}

impl SeriesTask {
    /// `OUT/series/ID`: the folder `analyze` writes.
    pub fn series_dir(&self) -> PathBuf {
        self.out.join("series").join(&self.id)
    }

    /// `OUT/fit/ID`: the folder `fit-hardening` writes.
    pub fn fit_dir(&self) -> PathBuf {
        self.out.join("fit").join(&self.id)
    }

    /// `OUT/qc/ID.png`: the thumbnail of the highest load.
    pub fn thumbnail(&self) -> PathBuf {
        thumbnail_path(&self.out, &self.id)
    }

    /// The command lines that make the series' folders on their own.
    pub fn command_lines(&self) -> CommandLines {
        let with_program = |args: Vec<String>| {
            std::iter::once(self.program.clone())
                .chain(args)
                .collect::<Vec<_>>()
        };
        CommandLines {
            analyze: with_program(self.options.analyze_args(
                &self.input,
                &self.series_dir(),
                &self.settings,
            )),
            fit_hardening: self.topography.as_ref().map(|t| {
                with_program(self.options.fit_args(
                    &self.series_dir().join("areas.csv"),
                    t,
                    &self.fit_dir(),
                    &self.settings,
                ))
            }),
        }
    }
}

/// `OUT/qc/ID.png`.
pub fn thumbnail_path(out: &Path, id: &str) -> PathBuf {
    out.join("qc").join(format!("{id}.png"))
}

/// What a run of the series gathered before it ended.
struct Progress {
    files: Vec<FileRecord>,
    bytes_hashed: u64,
    result: Option<SeriesResult>,
    fit: Option<FitSummary>,
}

/// Run one series: its folders, thumbnail and record (written into `OUT/records`). The record
/// is returned too. Its folders and messages are worded as the command line words them (they
/// are what `contactscope analyze` writes), whichever front-end runs the batch.
pub fn run_series(task: &SeriesTask) -> Record {
    let _words = contactscope_formats::param::CommandLineWords::begin();
    // The old record goes before any folder of the series changes: a run killed from here on
    // leaves no record, so the next run does the series again rather than trusting a record
    // that no longer describes its folders.
    let _ = std::fs::remove_file(Record::path(&task.out, &task.id));
    super::faults::pause("record-removed");
    let started = SystemTime::now();
    let clock = Instant::now();
    let mut progress = Progress {
        files: Vec::new(),
        bytes_hashed: 0,
        result: None,
        fit: None,
    };
    let outcome = stages(task, &mut progress);
    let (status, error, failed_stage) = match outcome {
        Ok(()) => (Status::Ok, None, None),
        Err((stage, e)) => {
            remove_stale(task, stage);
            if progress.files.is_empty() {
                // Failed before its files were known and hashed: what can be seen of them, so
                // that a repair (a new size or time) makes the next run try again.
                progress.files = seen_files(&task.input);
            }
            (
                Status::Failed,
                Some(one_line(&e.to_string())),
                Some(stage.to_string()),
            )
        }
    };
    let record = Record {
        id: task.id.clone(),
        status,
        error,
        failed_stage,
        contactscope_version: provenance::version().to_string(),
        source_revision: provenance::source_revision().map(str::to_string),
        options: task.options.fingerprint(),
        settings: task.settings,
        input: InputState::of(&task.input),
        files: progress.files,
        bytes_hashed: progress.bytes_hashed,
        command_lines: task.command_lines(),
        started: provenance::rfc3339(started),
        finished: provenance::rfc3339(SystemTime::now()),
        seconds: clock.elapsed().as_secs_f64(),
        result: progress.result,
        fit: progress.fit,
        outputs: Outputs::of(task),
    };
    match record.write(&task.out) {
        Ok(()) => record,
        Err(e) => Record {
            status: Status::Failed,
            error: Some(one_line(&e.to_string())),
            failed_stage: Some("record".into()),
            ..record
        },
    }
}

type StageError = (&'static str, Error);

fn stages(task: &SeriesTask, progress: &mut Progress) -> std::result::Result<(), StageError> {
    let mut request = task.options.analyze_request(&task.input, &task.settings);
    let at = |stage: &'static str| move |e: Error| (stage, e);
    if let Some(psf) = task.options.get(super::options::Opt::Psf) {
        let fwhm = crate::results::fwhm_from_psf_json(Path::new(psf)).map_err(at("inputs"))?;
        request.psf_fwhm_m = Some(fwhm);
    }
    request.check().map_err(at("inputs"))?;
    let open = request.micrographs.open().map_err(at("inputs"))?;
    let mut to_hash: Vec<(PathBuf, &str)> = open
        .series
        .image_files()
        .into_iter()
        .map(|f| (f, "image"))
        .collect();
    to_hash.extend(open.series.manifest.clone().map(|m| (m, "manifest")));
    to_hash.extend(task.topography.clone().map(|t| (t, "topography")));
    // The PSF's file too: new contents of the same psf.json make the series stale.
    to_hash.extend(
        task.options
            .get(super::options::Opt::Psf)
            .map(|p| (PathBuf::from(p), "psf")),
    );
    let lines = task.command_lines();
    let highest = highest_load(&open);
    let thumbnail: Mutex<Option<Result<Vec<u8>>>> = Mutex::new(None);
    let observer = |i: usize, plane: &Plane, mask: &Mask| -> contactscope::Result<()> {
        if i == highest {
            *thumbnail.lock().expect("lock") = Some(draw_thumbnail(plane, mask));
        }
        Ok(())
    };
    let images = ImageOutputs {
        overlays: task.settings.overlays,
        masks: task.settings.masks,
        zarr: None,
    };
    let (hashed, analysed) = rayon::join(
        || hash_files(&to_hash),
        || {
            run_open_to_folder(
                &request,
                &open,
                &task.series_dir(),
                &lines.analyze,
                images,
                &|_, _, _| {},
                &observer,
            )
        },
    );
    let (files, bytes) = hashed.map_err(at("inputs"))?;
    progress.files = files;
    progress.bytes_hashed = bytes;
    let (outcome, _) = analysed.map_err(at("analyze"))?;
    super::faults::pause("series-committed");
    progress.result = Some(series_result(task, &open, &outcome));
    if let Some(png) = thumbnail.into_inner().expect("lock") {
        crate::staging::write_atomic(&task.thumbnail(), &png.map_err(at("qc"))?)
            .map_err(at("qc"))?;
    }
    if let (Some(topography), Some(line)) = (&task.topography, &lines.fit_hardening) {
        let areas = task.series_dir().join("areas.csv");
        let request = task
            .options
            .fit_request(&areas, topography, &task.settings)
            .map_err(|m| ("fit-hardening", Error::InvalidArgument(m)))?;
        let fitted =
            crate::fit_hardening::files::run_to_folder(&request, &task.fit_dir(), line, None);
        // The series' own areas.csv was read by the fit; it is this batch's output, which a
        // later run in this process may replace.
        contactscope_formats::inputs::forget_input(&areas);
        let (fit, _) = fitted.map_err(at("fit-hardening"))?;
        super::faults::pause("fit-committed");
        progress.fit = Some(fit_summary(&fit));
    }
    Ok(())
}

/// The files at `input` (the file, or a folder's image files and manifest) with their size and
/// time but no hash (a record of a series that failed before reading them).
fn seen_files(input: &Path) -> Vec<FileRecord> {
    let paths: Vec<PathBuf> = match InputState::of(input).listing {
        Some(names) => names.iter().map(|n| input.join(n)).collect(),
        None => vec![input.to_path_buf()],
    };
    paths
        .iter()
        .filter_map(|p| FileRecord::stat_only(p, "seen"))
        .collect()
}

/// Index of the image with the highest force (the last image without forces).
fn highest_load(open: &OpenSeries) -> usize {
    let images = &open.series.images;
    images
        .iter()
        .enumerate()
        .filter_map(|(i, im)| im.force_n.map(|f| (i, f)))
        .max_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .map_or(images.len().saturating_sub(1), |(i, _)| i)
}

#[cfg(feature = "plots")]
fn draw_thumbnail(plane: &Plane, mask: &Mask) -> Result<Vec<u8>> {
    use crate::plot::{thumbnail_png, Pixels};
    use contactscope::image::Samples;
    let pixels = match &plane.samples {
        Samples::Int { codes, offset } => Pixels::Codes(codes, *offset),
        Samples::Float(values) => Pixels::Floats(values),
    };
    thumbnail_png(
        pixels,
        plane.width,
        plane.height,
        &mask.data,
        THUMBNAIL_SIDE,
    )
}

#[cfg(not(feature = "plots"))]
fn draw_thumbnail(_: &Plane, _: &Mask) -> Result<Vec<u8>> {
    Err(Error::Plot("built without plots".into()))
}

fn hash_files(files: &[(PathBuf, &str)]) -> Result<(Vec<FileRecord>, u64)> {
    let mut records = Vec::with_capacity(files.len());
    let mut total = 0;
    for (path, role) in files {
        let (record, bytes) = FileRecord::of(path, role)?;
        records.push(record);
        total += bytes;
    }
    Ok((records, total))
}

/// Remove what an earlier run left of this series from `stage` on: a failed series has no
/// folder, fit or thumbnail beside its error (a failed fit keeps the analysis it rests on).
fn remove_stale(task: &SeriesTask, stage: &str) {
    let marked = |dir: &Path| dir.join(crate::staging::MARKER).is_file();
    if stage != "fit-hardening" {
        let series = task.series_dir();
        if marked(&series) {
            let _ = std::fs::remove_dir_all(&series);
        }
        let _ = std::fs::remove_file(task.thumbnail());
    }
    let fit = task.fit_dir();
    if marked(&fit) {
        let _ = std::fs::remove_dir_all(&fit);
    }
}

/// An error as one line: control characters as spaces, runs of spaces as one.
pub fn one_line(text: &str) -> String {
    text.split(|c: char| c.is_whitespace() || c.is_control())
        .filter(|w| !w.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

fn series_result(task: &SeriesTask, open: &OpenSeries, outcome: &AnalyzeOutcome) -> SeriesResult {
    let base = if task.input.is_dir() {
        task.input.clone()
    } else {
        task.input
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    };
    let images = outcome
        .rows
        .rows
        .iter()
        .zip(&open.series.images)
        .map(|(row, image)| ImageResult {
            row: Row {
                image: image
                    .path
                    .strip_prefix(&base)
                    .unwrap_or(&image.path)
                    .display()
                    .to_string(),
                ..row.clone()
            },
            edge_contact: row.edge_contact,
        })
        .collect();
    let first = open.series.files.first();
    let pixel = outcome.analysis.pixel_size;
    SeriesResult {
        area_unit: outcome.area_unit.area_suffix().to_string(),
        sample_type: open.sample_type().name().to_string(),
        width_px: first.map_or(0, |f| f.width),
        height_px: first.map_or(0, |f| f.height),
        threshold_method: outcome.threshold.method.to_string(),
        threshold: outcome.threshold.value,
        pixel_size_um: pixel.map(|p| (in_unit(p.x_m, 1e6), in_unit(p.y_m, 1e6))),
        pixel_size_source: pixel.map(|p| p.source.describe().to_string()),
        pixel_size_given: task.options.get(super::options::Opt::PixelSize).is_some(),
        pixel_size_from_default: pixel.is_some_and(|p| {
            p.source == contactscope::image::PixelSizeSource::DefaultForUncalibrated
        }),
        pixel_size_uncertainty: outcome.area_interval.pixel_size_uncertainty,
        metadata_pixel_size_um: first
            .and_then(|f| f.pixel_size)
            .map(|p| (in_unit(p.x_m, 1e6), in_unit(p.y_m, 1e6))),
        power_law: outcome.fits.power_law.map(|f| PowerLaw {
            prefactor: f.prefactor,
            exponent: f.exponent,
            exponent_se: f.exponent_se,
            exponent_ci95: outcome.fits.intervals.as_ref().map(|i| i.exponent),
            r_squared: f.r_squared,
            points: f.points,
        }),
        proportional_mpa: match outcome.area_unit {
            AreaUnit::SquareMicrometre => outcome.fits.proportional_mpa,
            AreaUnit::Pixel => None,
        },
        mean_pressure_range_mpa: outcome.fits.pressure_range_mpa,
        warnings: outcome.warnings.clone(),
        images,
    }
}

fn fit_summary(fit: &FitOutcome) -> FitSummary {
    let mut summary = FitSummary {
        best_model: fit.best_model.map(String::from),
        warnings: fit.warnings.clone(),
        ..FitSummary::default()
    };
    for model in fit.fits() {
        let misfit = Some(model.best.misfit);
        match model.family {
            Family::Hardening => {
                summary.k_pa_per_m = model.best.parameter;
                summary.k_se_pa_per_m = model.parameter_se;
                summary.k_ci95_pa_per_m = model.parameter_ci95;
                summary.k_misfit = misfit;
            }
            Family::Hardness => {
                summary.hardness_pa = model.best.parameter;
                summary.hardness_se_pa = model.parameter_se;
                summary.hardness_ci95_pa = model.parameter_ci95;
                summary.hardness_misfit = misfit;
            }
            Family::Elastic => summary.elastic_misfit = misfit,
            Family::GreenwoodTripp => summary.gt_misfit = misfit,
        }
    }
    summary
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_joins_words() {
        assert_eq!(one_line("a\n  b\tc "), "a b c");
    }
}
