//! The end of a batch: the tables from every series' record ([`super::columns`]), the QC page
//! ([`super::qc`]) and `batch.json`, each written whole; the folder released.

use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use serde::Serialize;
use serde_json::{json, Value};

use super::{columns, flags, qc, tables, walk, Plan, Record, SheetSource, Status};
use crate::error::{Error, Result};
use crate::provenance::{self, Machine};

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
/// those run in this batch, in any order; the others are the plan's) and release the folder.
pub fn finish(plan: Plan, fresh: Vec<Record>) -> Result<BatchOutcome> {
    let out = plan.request.out.clone();
    let mut fresh: std::collections::HashMap<String, Record> =
        fresh.into_iter().map(|r| (r.id.clone(), r)).collect();
    let mut records = Vec::with_capacity(plan.tasks.len());
    for ((task, decision), reused) in plan.tasks.iter().zip(&plan.decisions).zip(&plan.reused) {
        let record = match (decision.run, reused) {
            (false, Some(r)) => r.clone(),
            _ => fresh
                .remove(&task.id)
                .or_else(|| Record::read(&out, &task.id))
                .ok_or_else(|| {
                    Error::InvalidArgument(format!("series {}: no record after its run", task.id))
                })?,
        };
        records.push(record);
    }
    let refs: Vec<&Record> = records.iter().collect();
    let flags = flags::flags(&refs, &sample_groups(&plan.sheet));
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
    let mut warnings: Vec<String> = plan
        .sheet
        .skipped
        .iter()
        .map(|s| format!("not a series: {s}"))
        .collect();
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

/// Each row's group for the archive-wide comparison: its value in the samplesheet's `sample`
/// column (or else `sphere`), or one group for the whole archive.
fn sample_groups(sheet: &super::Sheet) -> Vec<String> {
    let column = ["sample", "sphere"].iter().find_map(|name| {
        sheet
            .metadata
            .iter()
            .position(|m| m.name.eq_ignore_ascii_case(name))
    });
    sheet
        .rows
        .iter()
        .map(|r| column.map_or(String::new(), |k| r.metadata[k].clone()))
        .collect()
}
