//! Arguments that take more than one Python type (a number or a pair, a path or an array, a
//! name or a flag), extracted by hand so that a wrong type is answered in Python terms — what
//! the argument takes and what was given — rather than pyo3's text for derived enums ("failed
//! to extract enum PixelArg ('Square | Pair | List')"). Python adds the argument's name as a
//! note ("while processing 'pixel_size'"); the messages name the quantity themselves.

use std::path::PathBuf;

use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyInt, PyString};

use contactscope_formats::microscopy::select::ChannelChoice;

/// What was given, for messages: `str '200nm'`, `int 3`, `list of 3`, `NoneType`.
pub(crate) fn given(obj: &Bound<'_, PyAny>) -> String {
    let kind = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "object".into());
    if let Ok(s) = obj.cast::<PyString>() {
        let text = s.to_string();
        let short: String = text.chars().take(40).collect();
        let more = if short.len() < text.len() { "…" } else { "" };
        return format!("{kind} '{short}{more}'");
    }
    if obj.is_instance_of::<PyBool>()
        || obj.is_instance_of::<PyInt>()
        || obj.is_instance_of::<PyFloat>()
    {
        return format!("{kind} {obj}");
    }
    match obj.len() {
        Ok(n) => format!("{kind} of {n}"),
        Err(_) => kind,
    }
}

/// `TypeError("{what} must be {expected}; got {given}")`.
pub(crate) fn wrong_type(what: &str, expected: &str, obj: &Bound<'_, PyAny>) -> PyErr {
    PyTypeError::new_err(format!("{what} must be {expected}; got {}", given(obj)))
}

/// A real number (an int, a float, a numpy scalar), never a bool or a string.
pub(crate) fn real(obj: &Bound<'_, PyAny>) -> Option<f64> {
    if obj.is_instance_of::<PyBool>() || obj.is_instance_of::<PyString>() {
        return None;
    }
    obj.extract::<f64>().ok()
}

/// A path: a `str` or an `os.PathLike`.
pub(crate) fn path(obj: &Bound<'_, PyAny>) -> Option<PathBuf> {
    obj.extract::<PathBuf>().ok()
}

/// An optional non-negative index (`series=`, `z=`, `t=`): `None` or an int ≥ 0.
pub(crate) fn index(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<usize>> {
    if obj.is_none() {
        return Ok(None);
    }
    if obj.is_instance_of::<PyBool>() {
        return Err(wrong_type(what, "an int ≥ 0 or None", obj));
    }
    if !obj.is_instance_of::<PyInt>() {
        // numpy integers are not Python ints but index like them.
        if let Ok(i) = obj
            .call_method0("__index__")
            .and_then(|i| i.extract::<i64>())
        {
            return non_negative(i, what);
        }
        return Err(wrong_type(what, "an int ≥ 0 or None", obj));
    }
    non_negative(obj.extract::<i64>()?, what)
}

fn non_negative(i: i64, what: &str) -> PyResult<Option<usize>> {
    usize::try_from(i).map(Some).map_err(|_| {
        pyo3::exceptions::PyValueError::new_err(format!("{what} must be ≥ 0; got {i}"))
    })
}

/// `channel=`: `None`, an index (an int ≥ 0) or a name (a `str`) as the file's metadata gives it.
pub(crate) fn channel(obj: &Bound<'_, PyAny>) -> PyResult<Option<ChannelChoice>> {
    if let Ok(s) = obj.cast::<PyString>() {
        return s
            .to_string()
            .parse()
            .map(Some)
            .map_err(pyo3::exceptions::PyValueError::new_err);
    }
    match index(obj, "channel=") {
        Ok(i) => Ok(i.map(ChannelChoice::Index)),
        Err(e) if e.is_instance_of::<PyTypeError>(obj.py()) => Err(wrong_type(
            "channel=",
            "an index (an int ≥ 0), a channel's name (a str) or None",
            obj,
        )),
        Err(e) => Err(e),
    }
}

/// `channel=` as a function argument ([`channel`]).
pub(crate) struct ChannelArg(pub(crate) Option<ChannelChoice>);

impl<'a, 'py> FromPyObject<'a, 'py> for ChannelArg {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        channel(&obj).map(ChannelArg)
    }
}

/// `channel=` of a height map: a channel's name (a `str`) or its place in the file's list of
/// channels (an int ≥ 0), passed on as the text the readers take (`--channel`).
pub(crate) struct HeightChannel(pub(crate) String);

impl<'a, 'py> FromPyObject<'a, 'py> for HeightChannel {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        name_or_index(
            obj,
            "channel=",
            "a channel's name (a str), its index (an int ≥ 0) or None",
        )
        .map(HeightChannel)
    }
}

/// `measurement=` of a surface container: a measurement's name (a `str`) or its index in the
/// container (an int ≥ 0), passed on as the text the reader takes (`--measurement`).
pub(crate) struct Measurement(pub(crate) String);

impl<'a, 'py> FromPyObject<'a, 'py> for Measurement {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        name_or_index(
            obj,
            "measurement=",
            "a measurement's name (a str), its index (an int ≥ 0) or None",
        )
        .map(Measurement)
    }
}

/// A name (a `str`, as given) or an index (an int ≥ 0, as its digits); a message naming
/// `keyword` and what it takes (`expected`) otherwise.
fn name_or_index(obj: Borrowed<'_, '_, PyAny>, keyword: &str, expected: &str) -> PyResult<String> {
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(s.to_string());
    }
    match index(&obj, keyword) {
        Ok(Some(i)) => Ok(i.to_string()),
        // `None` never reaches here (pyo3 maps it to an absent argument).
        Ok(None) => Err(wrong_type(keyword, expected, &obj)),
        Err(e) if e.is_instance_of::<PyTypeError>(obj.py()) => {
            Err(wrong_type(keyword, expected, &obj))
        }
        Err(e) => Err(e),
    }
}

/// An optional item of a dict the Python layer built from keywords, with a message naming the
/// keyword and what it takes when the value does not fit.
pub(crate) fn item<'py, T: FromPyObjectOwned<'py>>(
    dict: &Bound<'py, PyAny>,
    key: &str,
    expected: &str,
) -> PyResult<Option<T>> {
    let value = match dict.get_item(key) {
        Ok(v) => v,
        Err(_) => return Ok(None),
    };
    if value.is_none() {
        return Ok(None);
    }
    value
        .extract::<T>()
        .map(Some)
        .map_err(|_| wrong_type(&format!("{key}="), expected, &value))
}
