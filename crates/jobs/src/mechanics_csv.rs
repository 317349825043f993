//! The CSV inputs of the mechanics commands, read into the in-memory types of
//! [`contactscope::mechanics`]: rheometer friction traces ([`read_trace`]) and squeeze tests
//! ([`read_squeeze`]). Column names carry the unit; values are converted to SI here.
//!
//! # Friction traces ([`read_trace`])
//! One row per sample, in recording order; column names carry the unit and are the contract:
//!
//! * **x** (one of, first found wins in this order): `displacement_um`, `angle_rad`, `time_s`.
//!   Values must increase from row to row.
//! * **friction** (exactly one of): `friction_mN`, `friction_N`, or the rheometer's torque
//!   `torque_mNm`, `torque_Nm`. Torque T becomes force F = T / r with the sphere's rotation
//!   radius r (`rotation_radius_m`), as in the paper's Methods; torque without r is an error.
//! * **normal force** (optional): `normal_force_mN` or `normal_force_N`; its median is the
//!   trace's N. Without it the caller's N (`--forces`) is used; neither is an error.
//!
//! Values beyond plausible bounds (forces ±100 N, torques ±100 N·m, displacements ±1 m, angles
//! ±10⁶ rad, times ±10⁹ s) are refused with their line: they are unit mistakes or corruption,
//! and would overflow what is computed from them.
//!
//! Other columns are ignored, except names that start like a known quantity (`friction_`,
//! `torque_`, `normal_force_`, `time_`, `displacement_`, `angle_`) with an unknown unit, which
//! are refused rather than silently skipped. Lines starting with `#` are comments.
//!
//! # Squeeze tests ([`read_squeeze`])
//! `force_mN` (or `force_N`) and `displacement_um`, the total plate displacement 2δ measured
//! from first contact, one row per sample of the loading curve. Rows with P ≤ 0 (before contact)
//! are ignored; among the rest, force must not decrease and displacement must increase from row
//! to row (an unloading branch is refused, naming the row).

use std::path::Path;

use super::table::Table;
use crate::error::{Error, Location, Result};
use contactscope::mechanics::friction::{Trace, XAxis, MIN_SAMPLES};
use contactscope::mechanics::squeeze::{check_points, SqueezePoint};
use contactscope::numerics::stats::median;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

const FRICTION_COLUMNS: [(&str, f64); 2] = [("friction_mN", 1e-3), ("friction_N", 1.0)];
const TORQUE_COLUMNS: [(&str, f64); 2] = [("torque_mNm", 1e-3), ("torque_Nm", 1.0)];
const NORMAL_COLUMNS: [(&str, f64); 2] = [("normal_force_mN", 1e-3), ("normal_force_N", 1.0)];
/// Largest |force| read, N (the plausible force range of `contactscope_formats::ranges`).
const MAX_FORCE_N: f64 = Quantity::Force.range().1;
/// Largest |torque| read, N·m.
const MAX_TORQUE_NM: f64 = 100.0;
/// Largest |displacement| read, m.
const MAX_DISPLACEMENT_M: f64 = 1.0;

/// Largest |x| of a trace, SI.
fn max_x(axis: XAxis) -> f64 {
    match axis {
        XAxis::Displacement => MAX_DISPLACEMENT_M,
        XAxis::Angle => 1e6,
        XAxis::Time => 1e9,
    }
}

const QUANTITY_STEMS: [&str; 6] = [
    "friction_",
    "torque_",
    "normal_force_",
    "time_",
    "displacement_",
    "angle_",
];

/// Read a trace CSV (format in the module documentation). `rotation_radius_m` converts torque to
/// force and is required when the file has a torque column.
pub fn read_trace(path: &Path, rotation_radius_m: Option<f64>) -> Result<Trace> {
    let table = Table::read(path)?;
    refuse_unknown_units(&table)?;
    let x_axis = XAxis::ALL
        .into_iter()
        .find(|a| table.header().iter().any(|h| h == a.column()))
        .ok_or_else(|| table.missing("x", &XAxis::ALL.map(XAxis::column)))?;
    let x = table.numbers_within(x_axis.column(), x_axis.si_per_unit(), max_x(x_axis))?;
    let friction_n = friction_column(&table, rotation_radius_m)?;
    let normal_force_n = match pick(&table, &NORMAL_COLUMNS)? {
        Some((name, factor)) => Some(median(&table.numbers_within(name, factor, MAX_FORCE_N)?)),
        None => None,
    };
    if table.len() < MIN_SAMPLES {
        return Err(Error::bad_input(
            table.location(),
            format!(
                "{} samples; a trace needs at least {MIN_SAMPLES}",
                table.len()
            ),
        ));
    }
    if let Some(k) = (1..x.len()).find(|&k| x[k] <= x[k - 1]) {
        return Err(Error::bad_input(
            table.location(),
            format!(
                "line {}: {} does not increase ({} after {})",
                table.line(k),
                x_axis.column(),
                x_axis.to_column_unit(x[k]),
                x_axis.to_column_unit(x[k - 1])
            ),
        ));
    }
    Ok(Trace {
        x_axis,
        x,
        friction_n,
        normal_force_n,
    })
}

/// A column such as `friction_lbf` is almost certainly a unit mistake: refuse it.
fn refuse_unknown_units(table: &Table) -> Result<()> {
    let known: Vec<&str> = FRICTION_COLUMNS
        .iter()
        .chain(&TORQUE_COLUMNS)
        .chain(&NORMAL_COLUMNS)
        .map(|c| c.0)
        .chain(XAxis::ALL.map(XAxis::column))
        .collect();
    let unknown = table
        .header()
        .iter()
        .find(|h| QUANTITY_STEMS.iter().any(|s| h.starts_with(s)) && !known.contains(&h.as_str()));
    match unknown {
        Some(h) => Err(Error::bad_input(
            table.location(),
            format!(
                "column {h:?} has a unit contactscope does not read (known: {}); columns found: {}",
                known.join(", "),
                table.found()
            ),
        )),
        None => Ok(()),
    }
}

fn pick(table: &Table, columns: &[(&'static str, f64)]) -> Result<Option<(&'static str, f64)>> {
    let names: Vec<&str> = columns.iter().map(|c| c.0).collect();
    Ok(table
        .one_of(&names)?
        .and_then(|n| columns.iter().copied().find(|c| c.0 == n)))
}

fn friction_column(table: &Table, rotation_radius_m: Option<f64>) -> Result<Vec<f64>> {
    let force = pick(table, &FRICTION_COLUMNS)?;
    let torque = pick(table, &TORQUE_COLUMNS)?;
    match (force, torque) {
        (Some((f, _)), Some((t, _))) => Err(Error::bad_input(
            table.location(),
            format!("both {f} and {t}; keep one friction column"),
        )),
        (Some((name, factor)), None) => table.numbers_within(name, factor, MAX_FORCE_N),
        (None, Some((name, factor))) => {
            let r = rotation_radius_m.ok_or_else(|| {
                Error::bad_input(
                    table.location(),
                    format!(
                        "{name} is a torque; give the sphere's rotation radius ({}, e.g. 5mm) to turn it into a force",
                        Param::RotationRadius
                    ),
                )
            })?;
            if !(r.is_finite() && r > 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "rotation radius {r:e} m must be positive"
                )));
            }
            // F = T / r: the sphere sits at distance r from the rheometer axis (paper, Methods).
            Ok(table
                .numbers_within(name, factor, MAX_TORQUE_NM)?
                .iter()
                .map(|t| t / r)
                .collect())
        }
        (None, None) => {
            let accepted: Vec<&str> = FRICTION_COLUMNS
                .iter()
                .chain(&TORQUE_COLUMNS)
                .map(|c| c.0)
                .collect();
            Err(table.missing("friction or torque", &accepted))
        }
    }
}

/// Read a squeeze CSV: the loaded rows (P > 0), checked for order (see the module docs).
pub fn read_squeeze(path: &Path) -> Result<Vec<SqueezePoint>> {
    let table = Table::read(path)?;
    let force_column = table
        .one_of(&["force_mN", "force_N"])?
        .ok_or_else(|| table.missing("force", &["force_mN", "force_N"]))?;
    let factor = if force_column == "force_mN" {
        1e-3
    } else {
        1.0
    };
    if table.one_of(&["displacement_um"])?.is_none() {
        return Err(table.missing("displacement", &["displacement_um"]));
    }
    let forces = table.numbers_within(force_column, factor, MAX_FORCE_N)?;
    let displacements = table.numbers_within("displacement_um", 1e-6, MAX_DISPLACEMENT_M)?;
    let points: Vec<SqueezePoint> = forces
        .iter()
        .zip(&displacements)
        .enumerate()
        .filter(|(_, (f, _))| **f > 0.0)
        .map(|(k, (&force_n, &displacement_m))| SqueezePoint {
            force_n,
            displacement_m,
            line: table.line(k),
        })
        .collect();
    check_points(&points).map_err(|reason| Error::bad_input(Location::file(path), reason))?;
    Ok(points)
}
