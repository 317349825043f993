//! Python bindings of contactscope: a thin layer over the jobs crate (one request → outcome per
//! command, as the command line uses them) and the in-memory algorithms. numpy arrays in and out, SI units
//! everywhere (metres, pascals, newtons), the GIL released while Rust computes, and library
//! errors raised as Python exceptions that subclass `ValueError` (bad input) or `OSError`
//! (files) and carry the library's message. A panic never reaches Python as a panic: it becomes
//! a [`InternalError`] (a `RuntimeError`).
//!
//! The pure-Python package `contactscope` (python/python/contactscope) wraps these functions
//! with result classes, `to_pandas()` and the Dask helpers (`contactscope.distributed`).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex};

use pyo3::create_exception;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use contactscope_jobs::Error;

mod batch;
mod compare;
mod convert;
mod extract;
mod fit;
mod heights;
mod images;
mod info;
mod mechanics;
mod mechanics_csv;
mod optics;
mod outputs;
mod series;
mod simulate;
mod synth;

create_exception!(
    contactscope,
    InputError,
    PyValueError,
    "Bad input: a value, an array or a file's content that contactscope refuses (the message says why)."
);
create_exception!(
    contactscope,
    FileError,
    PyOSError,
    "A file could not be opened, read or written."
);
create_exception!(
    contactscope,
    ConvergenceError,
    PyValueError,
    "An iterative solver stopped at its iteration limit without meeting its tolerance."
);
create_exception!(
    contactscope,
    InternalError,
    PyRuntimeError,
    "A bug in contactscope (a Rust panic caught at the boundary); please report it."
);

/// The library's error as the matching Python exception, with the library's message.
pub(crate) fn to_py(e: impl Into<Error>) -> PyErr {
    use contactscope_formats::Error as FormatError;
    let e = e.into();
    let message = e.to_string();
    match e {
        Error::Output { .. }
        | Error::Format(FormatError::Io { .. } | FormatError::Output { .. }) => {
            FileError::new_err(message)
        }
        Error::Algorithm(contactscope::Error::NotConverged { .. }) => {
            ConvergenceError::new_err(message)
        }
        _ => InputError::new_err(message),
    }
}

/// A bad argument found here (before the library sees it).
pub(crate) fn bad(message: impl Into<String>) -> PyErr {
    InputError::new_err(message.into())
}

/// The thread pool Rust's parallel code runs on; `None`: rayon's global pool (all cores).
static POOL: Mutex<Option<Arc<rayon::ThreadPool>>> = Mutex::new(None);

/// Run `f` with the GIL released, on the configured thread pool, with panics caught.
pub(crate) fn compute<T: Send, E: Into<Error> + Send>(
    py: Python<'_>,
    f: impl FnOnce() -> Result<T, E> + Send,
) -> PyResult<T> {
    let pool = POOL.lock().map(|p| p.clone()).unwrap_or(None);
    let outcome = py.detach(move || {
        catch_unwind(AssertUnwindSafe(move || match pool {
            Some(pool) => pool.install(f),
            None => f(),
        }))
    });
    match outcome {
        Ok(result) => result.map_err(to_py),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            Err(InternalError::new_err(format!(
                "internal error in contactscope: {what}"
            )))
        }
    }
}

/// Use `n` threads for contactscope's parallel loops in this process (0: all cores). Dask
/// workers call this with their share of the cores so that workers do not oversubscribe them.
#[pyfunction]
fn set_num_threads(n: usize) -> PyResult<()> {
    let pool = if n == 0 {
        None
    } else {
        Some(Arc::new(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map_err(|e| bad(format!("cannot build a pool of {n} threads: {e}")))?,
        ))
    };
    *POOL.lock().map_err(|_| bad("thread pool lock poisoned"))? = pool;
    Ok(())
}

/// Every parameter a person sets, as the front-ends name it, with its plausible range: for the
/// test that walks both front-ends' checks. Each entry: `flag` (command line), `keyword`
/// (Python; empty where Python has none), `words`, and for physical quantities `quantity`,
/// `lowest` and `highest` (SI) and the `unit` and `factor` (SI to that unit) of the messages.
#[pyfunction]
fn _params(py: Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyList>> {
    use contactscope_formats::param::Param;
    let list = pyo3::types::PyList::empty(py);
    for &p in Param::ALL {
        let d = pyo3::types::PyDict::new(py);
        d.set_item("flag", p.flag())?;
        d.set_item("keyword", p.keyword())?;
        d.set_item("words", p.words())?;
        if let Some(q) = p.quantity() {
            let (name, factor, unit) = q.describe();
            let (lo, hi) = q.range();
            d.set_item("quantity", name)?;
            d.set_item("lowest", lo)?;
            d.set_item("highest", hi)?;
            d.set_item("factor", factor)?;
            d.set_item("unit", unit)?;
        }
        list.append(d)?;
    }
    Ok(list)
}

/// Threads contactscope's parallel loops use in this process.
#[pyfunction]
fn get_num_threads() -> usize {
    match POOL.lock().ok().and_then(|p| p.clone()) {
        Some(pool) => pool.current_num_threads(),
        None => rayon::current_num_threads(),
    }
}

/// A pixel size given as one number (square pixels) or an (x, y) pair, metres.
#[derive(Clone)]
pub(crate) enum PixelArg {
    /// Square pixels.
    Square(f64),
    /// [x, y] (a list or an array).
    List(Vec<f64>),
}

impl<'a, 'py> FromPyObject<'a, 'py> for PixelArg {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let obj: &Bound<'py, PyAny> = &obj;
        if let Some(v) = extract::real(obj) {
            return Ok(PixelArg::Square(v));
        }
        if !obj.is_instance_of::<pyo3::types::PyString>() {
            if let Ok(v) = obj.extract::<Vec<f64>>() {
                return Ok(PixelArg::List(v));
            }
        }
        let hint = match obj.cast::<pyo3::types::PyString>() {
            Ok(s) => format!(
                " (parse_pixel_size('{}') converts a length with its unit)",
                s.to_string().replace('\'', "\\'")
            ),
            Err(_) => String::new(),
        };
        Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "a pixel size must be a number of metres (2e-7 for 200 nm) or an (x, y) pair; got {}{hint}",
            extract::given(obj)
        )))
    }
}

impl PixelArg {
    /// (x, y) in metres after checking both are finite and positive.
    pub(crate) fn xy(self) -> PyResult<(f64, f64)> {
        let (x, y) = match self {
            PixelArg::Square(s) => (s, s),
            PixelArg::List(v) if v.len() == 2 => (v[0], v[1]),
            PixelArg::List(v) => {
                return Err(bad(format!(
                    "pixel size needs one number or two (x, y); got {}",
                    v.len()
                )))
            }
        };
        if !(x.is_finite() && x > 0.0 && y.is_finite() && y > 0.0) {
            return Err(bad(format!(
                "pixel size ({x:e}, {y:e}) m must be positive and finite (metres: 200 nm is 2e-7)"
            )));
        }
        // The plausible range, for every function taking a pixel size (the jobs check it again
        // where they use it; measure and write_tiff have no job of their own).
        for v in [x, y] {
            contactscope_formats::ranges::Quantity::PixelSize
                .check(v, contactscope_formats::param::Param::PixelSize)
                .map_err(to_py)?;
        }
        Ok((x, y))
    }
}

/// Optional pixel size → optional (x, y).
pub(crate) fn pixel_opt(p: Option<PixelArg>) -> PyResult<Option<(f64, f64)>> {
    p.map(PixelArg::xy).transpose()
}

#[pymodule]
fn _contactscope(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // Messages name parameters as keywords (`pixel_size=`).
    contactscope_formats::param::set_front_end(contactscope_formats::param::FrontEnd::Python);
    contactscope_jobs::provenance::set_source_revision(env!("CONTACTSCOPE_SOURCE_REVISION"));
    m.add_function(wrap_pyfunction!(_params, m)?)?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("FileError", py.get_type::<FileError>())?;
    m.add("ConvergenceError", py.get_type::<ConvergenceError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The git commit the extension was built from, None outside a checkout (as summary.json's
    // `source_revision`).
    m.add(
        "__source_revision__",
        contactscope_jobs::provenance::source_revision(),
    )?;
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(get_num_threads, m)?)?;
    images::register(m)?;
    batch::register(m)?;
    compare::register(m)?;
    fit::register(m)?;
    info::register(m)?;
    mechanics::register(m)?;
    mechanics_csv::register(m)?;
    optics::register(m)?;
    outputs::register(m)?;
    series::register(m)?;
    simulate::register(m)?;
    synth::register(m)?;
    Ok(())
}
