//! Outcomes of the jobs as Python objects: every outcome type serialises itself once
//! (`contactscope_jobs::lab`); here its SI serialisation becomes dicts, lists, floats, ints,
//! bools and `None`, with the SI keys (`force_n`, `area_m2`). Arrays travel beside it as numpy
//! arrays. No result field is named in this crate.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::Value;

use crate::bad;

/// A JSON value as the Python object it stands for.
pub(crate) fn value_to_py<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.into_pyobject(py)?.into_any(),
            (None, Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, None, Some(f)) => f.into_pyobject(py)?.into_any(),
            _ => return Err(bad(format!("number {n} has no Python form"))),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(value_to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, value_to_py(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

/// An outcome as a dict in SI units with SI keys.
pub(crate) fn device_of(name: &str) -> PyResult<contactscope_jobs::simulate::DeviceChoice> {
    contactscope_jobs::simulate::DeviceChoice::parse(name).ok_or_else(|| {
        bad(format!(
            "device '{name}': use one of {}",
            contactscope_jobs::simulate::DeviceChoice::NAMES.join(", ")
        ))
    })
}

/// The outcome of a command as a dict of SI values.
pub(crate) fn outcome_dict<'py, T: serde::Serialize>(
    py: Python<'py>,
    outcome: &T,
) -> PyResult<Bound<'py, PyDict>> {
    let value =
        contactscope_jobs::lab::to_si_value(outcome).map_err(|e| bad(format!("result: {e}")))?;
    let object = value_to_py(py, &value)?;
    Ok(object.cast_into::<PyDict>()?)
}
