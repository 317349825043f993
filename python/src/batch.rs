//! The batch (`contactscope_jobs::batch`) from Python: [`batch_plan`], then either
//! [`BatchPlan::run`] (every series in this process, as the command line's `batch` does) or
//! [`batch_series`] per task and [`BatchPlan::finish`], which `contactscope.distributed.batch`
//! spreads over Dask (one series per task; tasks and records travel as JSON).
//!
//! Options for every series come as text, the samplesheet's own vocabulary (`"200nm"`,
//! `"4,10,40mN"`); the Python package turns SI numbers into such text.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use contactscope_jobs::batch::tables::{Table, Values};
use contactscope_jobs::batch::{
    self as jobs, BatchOutcome, BatchRequest, Opt, OutputSettings, Plan, Record, Rerun,
    SeriesOptions, SeriesTask, SheetSource, WalkSpec,
};

use crate::convert::{device_of, value_to_py};
use crate::{bad, compute};

/// The per-series options of the keyword arguments (`{"pixel_size": "200nm", …}`).
fn defaults(options: HashMap<String, String>) -> PyResult<SeriesOptions> {
    let mut out = SeriesOptions::default();
    for (name, text) in options {
        let Some((opt, unit)) = Opt::of_column(&name) else {
            let known: Vec<&str> = Opt::ALL.iter().map(|o| o.column()).collect();
            return Err(bad(format!(
                "batch: '{name}' is not a per-series option (known: {})",
                known.join(", ")
            )));
        };
        let text = Opt::with_unit(&text, unit.as_deref());
        opt.parse(&text)
            .map_err(|m| bad(format!("batch: {}={text:?}: {m}", opt.column())))?;
        out.0.insert(opt, text);
    }
    Ok(out)
}

/// A batch's request from the keyword arguments.
#[allow(clippy::too_many_arguments)]
fn request(
    kind: &str,
    source: String,
    out: PathBuf,
    base: Option<PathBuf>,
    patterns: Vec<String>,
    tiff_folders: bool,
    options: HashMap<String, String>,
    overlays: bool,
    save_masks: bool,
    memory_mib: usize,
    device: &str,
    rerun: &str,
    color_by: Option<String>,
    command_line: Vec<String>,
) -> PyResult<BatchRequest> {
    let source = match kind {
        "file" => SheetSource::File(PathBuf::from(source)),
        "walk" => SheetSource::Walk(WalkSpec {
            root: PathBuf::from(source),
            patterns,
            tiff_folders,
        }),
        "text" => SheetSource::Text {
            text: source,
            base: base.unwrap_or_default(),
            label: "the samplesheet (DataFrame)".into(),
        },
        other => return Err(bad(format!("batch: unknown source kind '{other}'"))),
    };
    let rerun = Rerun::parse(rerun)
        .ok_or_else(|| bad(format!("rerun='{rerun}': use changed, failed or all")))?;
    Ok(BatchRequest {
        defaults: defaults(options)?,
        settings: OutputSettings {
            overlays,
            masks: save_masks,
            memory_mib,
            device: device_of(device)?,
        },
        rerun,
        color_by,
        command_line,
        ..BatchRequest::new(source, out)
    })
}

/// A column of a table as (name, kind, values) with `None` for nulls.
fn table_to_py<'py>(py: Python<'py>, table: &Table) -> PyResult<Bound<'py, PyList>> {
    let columns = PyList::empty(py);
    for c in &table.columns {
        let (kind, values): (&str, Bound<'py, PyAny>) = match &c.values {
            Values::Float(v) => ("float", v.clone().into_pyobject(py)?.into_any()),
            Values::Int(v) => ("int", v.clone().into_pyobject(py)?.into_any()),
            Values::Text(v) => ("text", v.clone().into_pyobject(py)?.into_any()),
            Values::Bool(v) => ("bool", v.clone().into_pyobject(py)?.into_any()),
        };
        columns.append((c.name.as_str(), kind, values))?;
    }
    Ok(columns)
}

/// The outcome as a dict with the two tables' columns under `images_table` and
/// `series_table` (a list of (name, kind, values) each).
fn outcome_to_py<'py>(py: Python<'py>, outcome: &BatchOutcome) -> PyResult<Bound<'py, PyDict>> {
    let value = serde_json::to_value(outcome).map_err(|e| bad(format!("batch: {e}")))?;
    let dict = value_to_py(py, &value)?.cast_into::<PyDict>()?;
    dict.set_item("images_table", table_to_py(py, &outcome.images)?)?;
    dict.set_item("series_table", table_to_py(py, &outcome.series_table)?)?;
    Ok(dict)
}

/// A planned batch: the tasks to run (JSON), and [`BatchPlan::finish`] once their records are
/// back. The batch's folder stays locked until then.
#[pyclass(module = "contactscope._contactscope")]
struct BatchPlan {
    plan: Mutex<Option<Plan>>,
}

#[pymethods]
impl BatchPlan {
    /// The series to run, each as the JSON of its task (in samplesheet order).
    fn tasks(&self) -> PyResult<Vec<String>> {
        let plan = self.plan.lock().expect("lock");
        let plan = plan
            .as_ref()
            .ok_or_else(|| bad("batch: this plan is finished"))?;
        plan.to_run()
            .map(|t| serde_json::to_string(t).map_err(|e| bad(format!("batch: {e}"))))
            .collect()
    }

    /// Series in the samplesheet, and how many are re-used unchanged.
    fn counts(&self) -> PyResult<(usize, usize)> {
        let plan = self.plan.lock().expect("lock");
        let plan = plan
            .as_ref()
            .ok_or_else(|| bad("batch: this plan is finished"))?;
        let reused = plan.decisions.iter().filter(|d| !d.run).count();
        Ok((plan.tasks.len(), reused))
    }

    /// Run every series of the plan in this process (side by side on its thread pool), then
    /// [`BatchPlan::finish`]: the command line's `batch`. `progress(id, done, total)` is
    /// called after each series, from the threads doing the work.
    #[pyo3(signature = (progress=None))]
    fn run<'py>(
        &self,
        py: Python<'py>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let plan = self
            .plan
            .lock()
            .expect("lock")
            .take()
            .ok_or_else(|| bad("batch: this plan is finished"))?;
        let callback_error: Arc<Mutex<Option<PyErr>>> = Arc::new(Mutex::new(None));
        let error = callback_error.clone();
        let outcome = compute(py, move || {
            let report = move |record: &Record, done: usize, total: usize| {
                if let Some(f) = &progress {
                    Python::attach(|py| {
                        if let Err(e) = f.call1(py, (record.id.as_str(), done, total)) {
                            error.lock().expect("lock").get_or_insert(e);
                        }
                    });
                }
            };
            let fresh = jobs::run_planned(&plan, &report);
            jobs::finish(plan, fresh)
        })?;
        if let Some(e) = callback_error.lock().expect("lock").take() {
            return Err(e);
        }
        outcome_to_py(py, &outcome)
    }

    /// Write the tables, page and provenance from the records (JSON, one per task, in order).
    fn finish<'py>(&self, py: Python<'py>, records: Vec<String>) -> PyResult<Bound<'py, PyDict>> {
        let plan = self
            .plan
            .lock()
            .expect("lock")
            .take()
            .ok_or_else(|| bad("batch: this plan is finished"))?;
        let records = records
            .iter()
            .map(|r| serde_json::from_str::<Record>(r))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| bad(format!("batch: a record: {e}")))?;
        let outcome = compute(py, move || jobs::finish(plan, records))?;
        outcome_to_py(py, &outcome)
    }
}

/// Plan a batch (check the samplesheet, take the folder, decide per series).
#[pyfunction]
#[pyo3(signature = (kind, source, out, base=None, patterns=Vec::new(), tiff_folders=false,
    options=HashMap::new(), overlays=false, save_masks=false, memory_mib=128, device="cpu",
    rerun="changed", color_by=None, command_line=Vec::new()))]
#[allow(clippy::too_many_arguments)]
fn batch_plan(
    py: Python<'_>,
    kind: &str,
    source: String,
    out: PathBuf,
    base: Option<PathBuf>,
    patterns: Vec<String>,
    tiff_folders: bool,
    options: HashMap<String, String>,
    overlays: bool,
    save_masks: bool,
    memory_mib: usize,
    device: &str,
    rerun: &str,
    color_by: Option<String>,
    command_line: Vec<String>,
) -> PyResult<BatchPlan> {
    let request = request(
        kind,
        source,
        out,
        base,
        patterns,
        tiff_folders,
        options,
        overlays,
        save_masks,
        memory_mib,
        device,
        rerun,
        color_by,
        command_line,
    )?;
    let plan = compute(py, move || jobs::plan(request))?;
    Ok(BatchPlan {
        plan: Mutex::new(Some(plan)),
    })
}

/// Run one series of a plan (its task's JSON); its record as JSON. Never raises for a failed
/// series: the record says why.
#[pyfunction]
fn batch_series(py: Python<'_>, task: String) -> PyResult<String> {
    let task: SeriesTask =
        serde_json::from_str(&task).map_err(|e| bad(format!("batch: a task: {e}")))?;
    let record = compute(py, move || -> contactscope_jobs::Result<Record> {
        Ok(jobs::run_series(&task))
    })?;
    serde_json::to_string(&record).map_err(|e| bad(format!("batch: {e}")))
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(batch_plan, m)?)?;
    m.add_function(wrap_pyfunction!(batch_series, m)?)?;
    m.add_class::<BatchPlan>()?;
    Ok(())
}
