//! The `batch` job: a lab's archive in one command. A samplesheet (one row per load series:
//! an id, the input, per-series options, free metadata columns; [`sheet`]) or a folder walk
//! ([`walk`]) becomes, in one output folder:
//!
//! * `series/ID/` — the folder `analyze` writes for the series (the same files: its
//!   `summary.json` records the `analyze` command line that makes it on its own), and
//!   `fit/ID/` — `fit-hardening`'s folder for a row that names a height map;
//! * `images.parquet` / `images.csv` — one row per image of every series, `series.parquet` /
//!   `series.csv` — one row per series (fits, threshold, pixel size and its source, flags,
//!   warnings, status, error), both with the samplesheet's metadata columns ([`columns`],
//!   [`tables`]);
//! * `batch.json` — provenance: version and source revision, command line, machine, times,
//!   every input file with size and SHA-256, every series' options after defaults, decision,
//!   status and times;
//! * `index.html` with `qc/` — the QC page ([`qc`]);
//! * `records/ID.json` — each series' record ([`record`]), the state of incremental runs;
//! * `samplesheet.csv` — for a folder walk, the samplesheet it used.
//!
//! A batch runs in three steps that every front-end shares: [`plan`] (check the samplesheet
//! whole, lock the folder, decide per series whether its record still holds), [`run_series`]
//! for each series to do (in this process, or one Dask task each), [`finish`] (the tables,
//! the QC page, `batch.json`, written whole at the end of every run). A failed series has its
//! row with its error and the others complete; a batch killed at any moment keeps the series
//! it finished (each series' folders are written all or nothing, its record after them).

pub mod columns;
mod faults;
mod finish;
pub mod flags;
mod folder;
pub mod options;
pub mod outliers;
pub mod qc;
pub mod record;
mod run;
pub mod sheet;
pub mod tables;
pub mod terms;
pub mod walk;

use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use serde::Serialize;

pub use finish::{finish, BatchOutcome};
pub use options::{Opt, OutputSettings, SeriesOptions};
pub use record::{Record, Status};
pub use run::{run_series, thumbnail_path, SeriesTask, THUMBNAIL_SIDE};
pub use sheet::Sheet;
pub use walk::WalkSpec;

use crate::error::{Error, Result};
pub use folder::release_locks;
use folder::{check_inputs_outside, take_folder, walk_sheet, Lock};

/// Where the series come from.
#[derive(Debug, Clone, PartialEq)]
pub enum SheetSource {
    /// A samplesheet CSV file.
    File(PathBuf),
    /// A folder walk.
    Walk(WalkSpec),
    /// A samplesheet's text (Python hands a DataFrame over as CSV): relative inputs resolve
    /// against `base`; `label` names it in messages.
    Text {
        /// The CSV text.
        text: String,
        /// The folder of relative inputs.
        base: PathBuf,
        /// What to call it.
        label: String,
    },
}

/// Which series run again although their records still hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Rerun {
    /// Only new series and series whose inputs, options or outputs changed (the default).
    Changed,
    /// Those, and every series that failed.
    Failed,
    /// Every series.
    All,
}

impl Rerun {
    /// `changed`, `failed` or `all`.
    pub fn parse(text: &str) -> Option<Rerun> {
        match text.trim() {
            "changed" => Some(Rerun::Changed),
            "failed" => Some(Rerun::Failed),
            "all" => Some(Rerun::All),
            _ => None,
        }
    }
}

/// Everything a batch needs.
#[derive(Debug, Clone)]
pub struct BatchRequest {
    /// The samplesheet or the folder to walk.
    pub source: SheetSource,
    /// The batch's folder.
    pub out: PathBuf,
    /// Options for every series whose row leaves them empty (text, as the columns take them).
    pub defaults: SeriesOptions,
    /// Output settings of every series.
    pub settings: OutputSettings,
    /// What to run again.
    pub rerun: Rerun,
    /// The metadata column that colours the QC page's combined plot (default: the first).
    pub color_by: Option<String>,
    /// The program's name at the head of recorded command lines (`contactscope`).
    pub program: String,
    /// The command line (or call) that started the batch, for `batch.json`.
    pub command_line: Vec<String>,
}

impl BatchRequest {
    /// A request with the defaults: no per-batch options, re-run what changed.
    pub fn new(source: SheetSource, out: PathBuf) -> Self {
        BatchRequest {
            source,
            out,
            defaults: SeriesOptions::default(),
            settings: OutputSettings::default(),
            rerun: Rerun::Changed,
            color_by: None,
            program: "contactscope".into(),
            command_line: Vec::new(),
        }
    }
}

/// Whether a series runs, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Decision {
    /// It runs (false: its record is reused).
    pub run: bool,
    /// Why it runs (`new series`, `… changed (size)`, `--rerun all`, …), or `unchanged`.
    pub reason: String,
}

/// A batch ready to run: the checked samplesheet, one task per series and what to do with it.
#[derive(Debug)]
pub struct Plan {
    /// The request.
    pub request: BatchRequest,
    /// The samplesheet (read, or made by the walk).
    pub sheet: Sheet,
    /// One task per row, in samplesheet order.
    pub tasks: Vec<SeriesTask>,
    /// One decision per row.
    pub decisions: Vec<Decision>,
    /// The records that still hold, per row (`None` for series that run).
    pub reused: Vec<Option<Record>>,
    /// Bytes hashed to decide (files whose time changed).
    pub bytes_hashed: u64,
    /// When the batch started.
    pub started: SystemTime,
    /// The samplesheet a walk wrote (`samplesheet.csv`), with its SHA-256.
    pub written_sheet: Option<String>,
    clock: Instant,
    plan_seconds: f64,
    _lock: Lock,
}

impl Plan {
    /// The tasks that run, in order.
    pub fn to_run(&self) -> impl Iterator<Item = &SeriesTask> {
        self.tasks
            .iter()
            .zip(&self.decisions)
            .filter(|(_, d)| d.run)
            .map(|(t, _)| t)
    }
}

/// The file a batch keeps in its folder to mark it as a batch's.
pub const MARKER: &str = ".contactscope-batch.json";

/// Check the samplesheet, take the folder, and decide per series.
pub fn plan(request: BatchRequest) -> Result<Plan> {
    let clock = Instant::now();
    let started = SystemTime::now();
    let out = request.out.clone();
    check_defaults(&request.defaults)?;
    // A walk does not enter the batch's own folder.
    let sheet = match &request.source {
        SheetSource::File(path) => Sheet::read(path)?,
        SheetSource::Walk(spec) => walk::walk(spec, Some(&out))?,
        SheetSource::Text { text, base, label } => {
            Sheet::parse(text.as_bytes(), Path::new(label), base)?
        }
    };
    let mut tasks = Vec::with_capacity(sheet.rows.len());
    for row in &sheet.rows {
        let at = || match row.line {
            0 => format!("series {}", row.id),
            n => format!("{}: line {n}", sheet.label.display()),
        };
        // An option as the sheet's header names it (`forces_mN`), or the batch's flag.
        let column = |opt: Opt| match row.options.get(opt) {
            Some(_) => sheet
                .option_columns
                .iter()
                .find(|(o, _)| *o == opt)
                .map_or(opt.column().to_string(), |(_, h)| h.clone()),
            None => default_flag(opt),
        };
        let mut options = request.defaults.clone();
        // A manifest gives its images' forces: a default does not apply to it, and a row that
        // gives both is refused (one of the two would be ignored).
        if crate::series::is_manifest(&row.input) {
            if row.options.get(Opt::Forces).is_some() {
                return Err(Error::InvalidArgument(format!(
                    "{}, column {}: the input {} is a manifest, which gives the forces; \
                     leave the cell empty",
                    at(),
                    column(Opt::Forces),
                    row.input_text
                )));
            }
            options.0.remove(&Opt::Forces);
        }
        options.0.extend(row.options.0.clone());
        // The batch's pixel size fills only files that state none; a row's own replaces the
        // files' (and is flagged where they differ).
        if row.options.get(Opt::PixelSize).is_none() {
            if let Some(default) = options.0.remove(&Opt::PixelSize) {
                options.0.entry(Opt::PixelSizeDefault).or_insert(default);
            }
        } else {
            options.0.remove(&Opt::PixelSizeDefault);
        }
        options
            .check()
            .map_err(|(opt, m)| match row.options.get(opt) {
                Some(_) => Error::InvalidArgument(format!("{}, column {}: {m}", at(), column(opt))),
                None => Error::InvalidArgument(format!("{} ({}): {m}", at(), column(opt))),
            })?;
        let topography = options
            .get(Opt::Topography)
            .map(|t| options::resolve(&sheet.base, t));
        // A psf.json is named by its canonical path: the recorded command line finds it from
        // anywhere, and the same file is the same option whatever the working directory.
        if let Some(psf) = options.get(Opt::Psf) {
            let path = options::resolve(&sheet.base, psf);
            let path = path.canonicalize().unwrap_or(path);
            options.0.insert(Opt::Psf, path.display().to_string());
        }
        tasks.push(SeriesTask {
            id: row.id.clone(),
            input: row.input.clone(),
            topography,
            options,
            settings: request.settings,
            out: out.clone(),
            program: request.program.clone(),
        });
    }
    check_inputs_outside(&out, &tasks)?;
    let walk_sheet = match &request.source {
        SheetSource::Walk(_) => Some(walk_sheet(&out, &sheet, &tasks)?),
        _ => None,
    };
    // Everything is checked: the folder is taken (made, when new) only now; a refused or
    // failed run removes only what it made itself ([`Lock`]), so that it writes nothing.
    let mut lock = take_folder(&out)?;
    let written_sheet = match walk_sheet {
        Some((bytes, sha)) => {
            crate::staging::write_atomic(&out.join("samplesheet.csv"), &bytes)?;
            Some(sha)
        }
        None => None,
    };
    lock.keep();
    let mut decisions = Vec::with_capacity(tasks.len());
    let mut reused = Vec::with_capacity(tasks.len());
    let mut bytes_hashed = 0;
    for task in &tasks {
        let (decision, record) = decide(task, request.rerun, &mut bytes_hashed);
        decisions.push(decision);
        reused.push(record);
    }
    Ok(Plan {
        request,
        sheet,
        tasks,
        decisions,
        reused,
        bytes_hashed,
        started,
        written_sheet,
        clock,
        plan_seconds: clock.elapsed().as_secs_f64(),
        _lock: lock,
    })
}

/// The batch-wide defaults, checked as cells are (each names its flag).
fn check_defaults(defaults: &SeriesOptions) -> Result<()> {
    for (opt, text) in &defaults.0 {
        opt.parse(text)
            .map_err(|m| Error::InvalidArgument(format!("{}: {m}", default_flag(*opt))))?;
    }
    Ok(())
}

/// The batch's flag for a default option (`--pixel-size`, `--topography-pixel-size`).
pub fn default_flag(opt: Opt) -> String {
    format!("--{}", opt.column().replace('_', "-"))
}

fn decide(task: &SeriesTask, rerun: Rerun, hashed: &mut u64) -> (Decision, Option<Record>) {
    let run = |reason: String| (Decision { run: true, reason }, None);
    let Some(record) = Record::read(&task.out, &task.id) else {
        return run("new series".into());
    };
    if rerun == Rerun::All {
        return run("--rerun all".into());
    }
    let mut touched = false;
    let options = task.options.fingerprint();
    if let Some(why) = record.staleness(&options, &task.settings, &task.input, hashed, &mut touched)
    {
        return run(why);
    }
    if record.status == Status::Failed {
        if rerun == Rerun::Failed {
            return run("--rerun failed".into());
        }
    } else if let Some(missing) = missing_output(task, &record) {
        return run(match missing.contains(' ') {
            true => missing,
            false => format!("{missing} is missing"),
        });
    }
    // Files only touched (same bytes, a new time): the record takes their new times, so that
    // the next run does not hash them again.
    let record = match touched {
        true => {
            let record = record.retouched(&task.input);
            let _ = record.write(&task.out);
            record
        }
        false => record,
    };
    (
        Decision {
            run: false,
            reason: "unchanged".into(),
        },
        Some(record),
    )
}

/// An output of a finished series that is no longer there, or not the one its record describes.
fn missing_output(task: &SeriesTask, record: &Record) -> Option<String> {
    let marker = |dir: PathBuf| dir.join(crate::staging::MARKER);
    if record.result.is_some() && !marker(task.series_dir()).is_file() {
        return Some(format!("series/{}", task.id));
    }
    if record.fit.is_some() && !marker(task.fit_dir()).is_file() {
        return Some(format!("fit/{}", task.id));
    }
    if cfg!(feature = "plots") && record.result.is_some() && !task.thumbnail().is_file() {
        return Some(format!("qc/{}.png", task.id));
    }
    // A folder another run made (or a record of a batch before records named their folders).
    record
        .outputs
        .disagreement(&record::Outputs::of(task), &task.id)
        .map(|folder| format!("{folder} does not match its record (written by another run)"))
}

/// Progress of a batch in this process: told after each series with its record, how many are
/// done and how many run; called from the threads doing the work.
pub type SeriesProgress<'a> = &'a (dyn Fn(&Record, usize, usize) + Sync);

/// Every series of the plan that runs ([`run_series`]), on this process's thread pool: series
/// run side by side (rayon's work stealing also shares each series' images and hashing among
/// the threads), so that one series' serial work (opening files, plots, writing its folder)
/// overlaps another's analysis. The records in samplesheet order.
pub fn run_planned(plan: &Plan, progress: SeriesProgress) -> Vec<Record> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    let todo: Vec<&SeriesTask> = plan.to_run().collect();
    let done = AtomicUsize::new(0);
    todo.par_iter()
        .with_max_len(1)
        .map(|task| {
            let record = run_series(task);
            progress(&record, done.fetch_add(1, Ordering::SeqCst) + 1, todo.len());
            record
        })
        .collect()
}

/// A batch in this process: [`plan`], [`run_planned`], [`finish`].
pub fn run(request: BatchRequest, progress: SeriesProgress) -> Result<BatchOutcome> {
    let plan = plan(request)?;
    let fresh = run_planned(&plan, progress);
    finish(plan, fresh)
}
