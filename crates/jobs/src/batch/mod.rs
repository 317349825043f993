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
pub mod flags;
pub mod options;
pub mod qc;
pub mod record;
mod run;
pub mod sheet;
pub mod tables;
pub mod walk;

use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use serde::Serialize;
use serde_json::{json, Value};

use contactscope_formats::param::Param;

pub use options::{Opt, OutputSettings, SeriesOptions};
pub use record::{Record, Status};
pub use run::{run_series, thumbnail_path, SeriesTask, THUMBNAIL_SIDE};
pub use sheet::Sheet;
pub use walk::WalkSpec;

use crate::error::{Error, Location, Result};
use crate::provenance::{self, Machine};

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
const LOCK: &str = ".contactscope-batch.lock";

/// Check the samplesheet, take the folder, and decide per series.
pub fn plan(request: BatchRequest) -> Result<Plan> {
    let clock = Instant::now();
    let started = SystemTime::now();
    let out = request.out.clone();
    check_defaults(&request.defaults)?;
    // The walk must not see the batch's own folder; check it exists or can be made first.
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
        let mut options = request.defaults.clone();
        // A manifest gives its images' forces: a default does not apply to it, and a row that
        // gives both is refused (one of the two would be ignored).
        if crate::series::is_manifest(&row.input) {
            if row.options.get(Opt::Forces).is_some() {
                return Err(Error::InvalidArgument(format!(
                    "{}, column forces: the input {} is a manifest, which gives the forces;                      leave the cell empty",
                    at(),
                    row.input_text
                )));
            }
            options.0.remove(&Opt::Forces);
        }
        options.0.extend(row.options.0.clone());
        options.check().map_err(|(opt, m)| {
            Error::InvalidArgument(format!("{}, column {}: {m}", at(), opt.column()))
        })?;
        let topography = options
            .get(Opt::Topography)
            .map(|t| options::resolve(&sheet.base, t));
        tasks.push(SeriesTask {
            id: row.id.clone(),
            input: row.input.clone(),
            topography,
            pixel_size_from_default: row.options.get(Opt::PixelSize).is_none()
                && request.defaults.get(Opt::PixelSize).is_some(),
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
    // Everything is checked: the folder is taken (made, when new) only now, and removed again
    // if this run made it and cannot go on, so that a refused batch writes nothing.
    let existed = out.exists();
    let lock = take_folder(&out).inspect_err(|_| {
        if !existed {
            let _ = std::fs::remove_dir_all(&out);
        }
    })?;
    let written_sheet = match walk_sheet {
        Some((bytes, sha)) => {
            match crate::staging::write_atomic(&out.join("samplesheet.csv"), &bytes) {
                Ok(()) => Some(sha),
                Err(e) => {
                    drop(lock);
                    if !existed {
                        let _ = std::fs::remove_dir_all(&out);
                    }
                    return Err(e);
                }
            }
        }
        None => None,
    };
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
        return run(format!("{missing} is missing"));
    }
    // Files only touched (same bytes, a new time): the record takes their new times, so that
    // the next run does not hash them again.
    let record = match touched {
        true => {
            let record = record.retouched();
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

/// An output of a finished series that is no longer there.
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
    None
}

/// A batch's folder taken for one run: its lock file, removed when dropped.
#[derive(Debug)]
struct Lock(PathBuf);

impl Drop for Lock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Make or take the batch's folder: new, empty, or an earlier batch's (its [`MARKER`]), and not
/// in use by a running batch (its lock names a live process of this host).
fn take_folder(out: &Path) -> Result<Lock> {
    let refuse = |reason: String| Error::Output {
        path: out.to_path_buf(),
        reason: format!(
            "{reason}; nothing was written (choose another {})",
            Param::Out
        ),
    };
    match std::fs::symlink_metadata(out) {
        Ok(m) if !m.is_dir() => return Err(refuse("is in the way (not a folder)".into())),
        Ok(_) => {
            let empty = std::fs::read_dir(out)
                .map_err(|e| Error::io(out, e))?
                .next()
                .is_none();
            if !empty && !out.join(MARKER).is_file() {
                return Err(refuse(format!(
                    "is not empty and is not a batch's folder (no {MARKER})"
                )));
            }
        }
        Err(_) => {}
    }
    for dir in ["", "series", "fit", "qc", "records"] {
        let d = out.join(dir);
        std::fs::create_dir_all(&d).map_err(|e| Error::Output {
            path: d.clone(),
            reason: e.to_string(),
        })?;
    }
    let marker = json!({ "written_by": format!("contactscope {}", provenance::version()) });
    crate::staging::write_atomic(&out.join(MARKER), marker.to_string().as_bytes())?;
    let lock = out.join(LOCK);
    let me = json!({ "host": Machine::this().hostname, "pid": std::process::id() });
    if let Ok(text) = std::fs::read(&lock) {
        let holder: Value = serde_json::from_slice(&text).unwrap_or(Value::Null);
        let host = holder["host"].as_str().unwrap_or("");
        let pid = holder["pid"].as_u64().unwrap_or(0);
        if host == me["host"] && pid != u64::from(std::process::id()) && alive(pid) {
            return Err(refuse(format!(
                "is in use by another batch (process {pid}); wait for it, or remove {} if it is \
                 gone",
                lock.display()
            )));
        }
        if host != me["host"] && !host.is_empty() {
            return Err(refuse(format!(
                "is in use by a batch on host {host} (process {pid}); wait for it, or remove {} \
                 if it is gone",
                lock.display()
            )));
        }
    }
    crate::staging::write_atomic(&lock, me.to_string().as_bytes())?;
    clean_unfinished(out);
    Ok(Lock(lock))
}

/// Whether process `pid` of this host is alive (Linux: its `/proc` entry; elsewhere assumed).
fn alive(pid: u64) -> bool {
    if cfg!(target_os = "linux") {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}

/// Remove what a killed run left unfinished: staging folders of series and fits, temporary
/// files of records and thumbnails (the folder is locked: no other run writes them).
fn clean_unfinished(out: &Path) {
    for dir in ["series", "fit", "qc", "records", ""] {
        let Ok(entries) = std::fs::read_dir(out.join(dir)) else {
            continue;
        };
        for entry in entries.filter_map(|e| e.ok()) {
            let name = entry.file_name().to_string_lossy().into_owned();
            let unfinished = name.starts_with('.')
                && (name.contains(".staging-")
                    || name.contains(".tmp-")
                    || name.contains(".replaced-"));
            if unfinished {
                let path = entry.path();
                let _ = if path.is_dir() {
                    std::fs::remove_dir_all(&path)
                } else {
                    std::fs::remove_file(&path)
                };
            }
        }
    }
}

/// The walk's samplesheet (`samplesheet.csv`, inputs relative to the batch's folder) and its
/// SHA-256; refused when the one in the folder was edited by hand since the last walk.
fn walk_sheet(out: &Path, sheet: &Sheet, tasks: &[SeriesTask]) -> Result<(Vec<u8>, String)> {
    let path = out.join("samplesheet.csv");
    let inputs: Vec<String> = sheet
        .rows
        .iter()
        .map(|r| walk::relative_to(&r.input, out))
        .collect();
    let options: Vec<SeriesOptions> = tasks.iter().map(|t| t.options.clone()).collect();
    let bytes = sheet.to_csv(&options, &inputs)?;
    let sha = provenance::sha256_bytes(&bytes);
    if let Ok(existing) = std::fs::read(&path) {
        let last = std::fs::read(out.join("batch.json"))
            .ok()
            .and_then(|b| serde_json::from_slice::<Value>(&b).ok())
            .and_then(|v| {
                v["samplesheet"]["written_sha256"]
                    .as_str()
                    .map(String::from)
            });
        let existing_sha = provenance::sha256_bytes(&existing);
        if existing_sha != sha && last.as_deref() != Some(existing_sha.as_str()) {
            return Err(Error::Output {
                path,
                reason: "was edited since the last walk; run the batch on it with \
                         --samplesheet, or move it away to walk again"
                    .into(),
            });
        }
    }
    Ok((bytes, sha))
}

/// What a batch did.
#[derive(Debug, Clone, Serialize)]
pub struct BatchOutcome {
    /// Series in the samplesheet.
    pub series: usize,
    /// Series that succeeded.
    pub ok: usize,
    /// Series that failed.
    pub failed: usize,
    /// Series run in this batch.
    pub analysed: usize,
    /// Series whose records were reused.
    pub reused: usize,
    /// Rows of the image table.
    pub image_rows: usize,
    /// Files written at the end (tables, page, provenance).
    pub written: Vec<PathBuf>,
    /// Seconds to write the tables (Parquet and CSV).
    pub tables_seconds: f64,
    /// Notes (records of series no longer in the samplesheet, …).
    pub warnings: Vec<String>,
    /// The ids and errors of failed series.
    pub failures: Vec<(String, String)>,
    /// Bytes of input files hashed (new series, and files whose time changed).
    pub bytes_hashed: u64,
    /// The image table as written.
    #[serde(skip)]
    pub images: tables::Table,
    /// The series table as written.
    #[serde(skip)]
    pub series_table: tables::Table,
}

/// Write the tables, the QC page and `batch.json` from every series' record (`fresh` holds
/// those run in this batch; the others are the plan's) and release the folder.
pub fn finish(plan: Plan, fresh: Vec<Record>) -> Result<BatchOutcome> {
    let out = plan.request.out.clone();
    let mut fresh = fresh.into_iter();
    let mut records = Vec::with_capacity(plan.tasks.len());
    for ((task, decision), reused) in plan.tasks.iter().zip(&plan.decisions).zip(&plan.reused) {
        let record = match (decision.run, reused) {
            (false, Some(r)) => r.clone(),
            _ => fresh
                .next()
                .filter(|r| r.id == task.id)
                .or_else(|| Record::read(&out, &task.id))
                .ok_or_else(|| {
                    Error::InvalidArgument(format!("series {}: no record after its run", task.id))
                })?,
        };
        records.push(record);
    }
    let refs: Vec<&Record> = records.iter().collect();
    let flags = flags::flags(&refs);
    let entries: Vec<columns::Entry> = plan
        .sheet
        .rows
        .iter()
        .zip(&records)
        .zip(&flags)
        .map(|((row, record), flags)| columns::Entry { row, record, flags })
        .collect();
    let tables_clock = Instant::now();
    let images = columns::images_table(&plan.sheet.metadata, &entries);
    let series = columns::series_table(&plan.sheet.metadata, &entries);
    let meta = [("contactscope_version", provenance::version().to_string())];
    let mut written = Vec::new();
    for (name, table) in [("images", &images), ("series", &series)] {
        for (ext, bytes) in [
            ("parquet", table.to_parquet(name, &meta)?),
            ("csv", table.to_csv()?),
        ] {
            let path = out.join(format!("{name}.{ext}"));
            crate::staging::write_atomic(&path, &bytes)?;
            written.push(path);
        }
    }
    let tables_seconds = tables_clock.elapsed().as_secs_f64();
    let mut warnings = Vec::new();
    let stale = stale_records(&out, &plan);
    if !stale.is_empty() {
        warnings.push(format!(
            "{} series in {} are not in this samplesheet and are left out of the tables: {}",
            stale.len(),
            out.display(),
            stale.join(", ")
        ));
    }
    let qc_clock = Instant::now();
    written.extend(qc::write_page(
        &out,
        &plan,
        &entries,
        &images,
        &mut warnings,
    )?);
    let qc_seconds = qc_clock.elapsed().as_secs_f64();
    let failures: Vec<(String, String)> = records
        .iter()
        .filter(|r| r.status == Status::Failed)
        .map(|r| (r.id.clone(), r.error.clone().unwrap_or_default()))
        .collect();
    let bytes_hashed = plan.bytes_hashed
        + records
            .iter()
            .zip(&plan.decisions)
            .filter(|(_, d)| d.run)
            .map(|(r, _)| r.bytes_hashed)
            .sum::<u64>();
    let image_rows = images.rows;
    let outcome = BatchOutcome {
        series: records.len(),
        ok: records.len() - failures.len(),
        failed: failures.len(),
        analysed: plan.decisions.iter().filter(|d| d.run).count(),
        reused: plan.decisions.iter().filter(|d| !d.run).count(),
        image_rows,
        written,
        tables_seconds,
        warnings,
        failures,
        bytes_hashed,
        images,
        series_table: series,
    };
    let json = provenance_json(&plan, &records, &outcome, qc_seconds);
    let path = out.join("batch.json");
    crate::staging::write_atomic(&path, &serde_json::to_vec_pretty(&json).expect("JSON"))?;
    let mut outcome = outcome;
    outcome.written.push(path);
    drop(plan);
    Ok(outcome)
}

/// Ids of records in the folder whose series are not in the samplesheet.
fn stale_records(out: &Path, plan: &Plan) -> Vec<String> {
    let ids: std::collections::HashSet<&str> = plan.tasks.iter().map(|t| t.id.as_str()).collect();
    let mut stale: Vec<String> = std::fs::read_dir(out.join("records"))
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .filter_map(|e| {
                    let name = e.file_name().to_string_lossy().into_owned();
                    name.strip_suffix(".json")
                        .filter(|id| !id.starts_with('.') && !ids.contains(id))
                        .map(String::from)
                })
                .collect()
        })
        .unwrap_or_default();
    stale.sort();
    stale
}

fn provenance_json(plan: &Plan, records: &[Record], outcome: &BatchOutcome, qc_s: f64) -> Value {
    let request = &plan.request;
    let source = match &request.source {
        SheetSource::File(path) => json!({
            "path": path.display().to_string(),
            "sha256": plan.sheet.sha256,
        }),
        SheetSource::Text { label, .. } => {
            json!({ "given_as": label, "sha256": plan.sheet.sha256 })
        }
        SheetSource::Walk(spec) => json!({
            "walked": spec.root.display().to_string(),
            "patterns": if spec.patterns.is_empty() {
                walk::DEFAULT_PATTERNS.iter().map(|p| p.to_string()).collect()
            } else {
                spec.patterns.clone()
            },
            "tiff_folders": spec.tiff_folders,
            "written": "samplesheet.csv",
            "written_sha256": plan.written_sheet,
        }),
    };
    let defaults: serde_json::Map<String, Value> = request
        .defaults
        .0
        .iter()
        .map(|(o, t)| (o.column().to_string(), Value::from(t.as_str())))
        .collect();
    let series: Vec<Value> = plan
        .tasks
        .iter()
        .zip(&plan.decisions)
        .zip(records)
        .map(|((task, decision), record)| {
            json!({
                "id": task.id,
                "status": record.status.name(),
                "failed_stage": record.failed_stage,
                "error": record.error,
                "decision": if decision.run { "analysed" } else { "reused" },
                "reason": decision.reason,
                "input": task.input.display().to_string(),
                "options": task.options.0.iter().map(|(o, t)| (o.column().to_string(), Value::from(t.as_str()))).collect::<serde_json::Map<_, _>>(),
                "options_si": record.options,
                "files": record.files.iter().map(|f| json!({
                    "path": f.path, "role": f.role, "size_bytes": f.size_bytes,
                    "sha256": (!f.sha256.is_empty()).then_some(&f.sha256),
                })).collect::<Vec<_>>(),
                "command_lines": record.command_lines,
                "contactscope_version": record.contactscope_version,
                "source_revision": record.source_revision,
                "started": record.started,
                "finished": record.finished,
                "seconds": record.seconds,
            })
        })
        .collect();
    let finished = SystemTime::now();
    json!({
        "contactscope_version": provenance::version(),
        "source_revision": provenance::source_revision(),
        "command_line": request.command_line,
        "started": provenance::rfc3339(plan.started),
        "finished": provenance::rfc3339(finished),
        "seconds": plan.clock.elapsed().as_secs_f64(),
        "machine": Machine::this(),
        "samplesheet": source,
        "defaults": defaults,
        "settings": request.settings,
        "rerun": request.rerun,
        "counts": {
            "series": outcome.series,
            "ok": outcome.ok,
            "failed": outcome.failed,
            "analysed": outcome.analysed,
            "reused": outcome.reused,
            "image_rows": outcome.image_rows,
        },
        "bytes_hashed": outcome.bytes_hashed,
        "timings_s": {
            "plan": plan.plan_seconds,
            "tables": outcome.tables_seconds,
            "qc_page": qc_s,
        },
        "tables": {
            "images": ["images.parquet", "images.csv"],
            "series": ["series.parquet", "series.csv"],
        },
        "warnings": outcome.warnings,
        "series": series,
    })
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

/// Refuse a series whose input lies in the batch's own series or fit folders (a run would
/// replace it).
fn check_inputs_outside(out: &Path, tasks: &[SeriesTask]) -> Result<()> {
    let Ok(out) = out.canonicalize() else {
        return Ok(());
    };
    for task in tasks {
        if let Ok(input) = task.input.canonicalize() {
            if input.starts_with(out.join("series")) || input.starts_with(out.join("fit")) {
                return Err(Error::bad_input(
                    Location::file(&task.input),
                    format!(
                        "series {}: an input inside the batch's own output folders",
                        task.id
                    ),
                ));
            }
        }
    }
    Ok(())
}
