//! `summary.json` and the other JSON files of the command line: the outcome of a job serialised
//! in lab units ([`crate::lab`]) with the version and the command line that made it.

use serde::Serialize;
use serde_json::{Map, Value};

use crate::error::{Error, Result};

/// The outcome as pretty JSON bytes, with `contactscope_version`, `source_revision` (the git
/// commit the program was built from, `null` when unknown: [`crate::provenance`]) and
/// `command_line` first.
pub fn summary_json<T: Serialize>(command_line: &[String], outcome: &T) -> Result<Vec<u8>> {
    summary_json_without(command_line, outcome, &[])
}

/// [`summary_json`] without the fields `leave_out` (tables written as CSV beside it).
pub fn summary_json_without<T: Serialize>(
    command_line: &[String],
    outcome: &T,
    leave_out: &[&str],
) -> Result<Vec<u8>> {
    let mut body = serde_json::to_value(outcome)
        .map_err(|e| Error::InvalidArgument(format!("summary: {e}")))?;
    if let Value::Object(fields) = &mut body {
        for key in leave_out {
            fields.shift_remove(*key);
        }
    }
    let mut map = Map::new();
    map.insert(
        "contactscope_version".into(),
        Value::from(env!("CARGO_PKG_VERSION")),
    );
    map.insert(
        "source_revision".into(),
        Value::from(crate::provenance::source_revision()),
    );
    map.insert("command_line".into(), Value::from(command_line.to_vec()));
    match body {
        Value::Object(fields) => map.extend(fields),
        other => {
            map.insert("outcome".into(), other);
        }
    }
    Ok(serde_json::to_string_pretty(&Value::Object(map))
        .expect("JSON values serialise")
        .into_bytes())
}
