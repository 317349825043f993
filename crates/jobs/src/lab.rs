//! The units of the outputs. Every outcome type serialises itself once, with `serde`, in the
//! units its field names state: `force_mN`, `area_um2`, `mean_pressure_MPa`, `pixel_size_x_nm`
//! (`docs/conventions.md`, "Units"). That serialisation *is* `summary.json` and the other JSON
//! files the command line writes. The Python package shows the same outcome in SI units: it
//! serialises inside [`in_si`], where every quantity field writes its SI value, and renames each
//! key by [`si_key`] (`force_mN` → `force_n`, `area_um2` → `area_m2`, `hardening_MPa_per_nm` →
//! `hardening_pa_per_m`). One field declaration serves both: a field names its output unit and
//! the unit it is stored in with one of the functions below, e.g.
//!
//! ```ignore
//! #[serde(rename = "force_mN", serialize_with = "lab::n_as_mn")]
//! pub force_n: f64,
//! ```
//!
//! The functions multiply by the same constants the writers always used (`force_n * 1e3`), so the
//! files keep their values to the last bit. NaN and ±∞ are written as `null` (JSON has no NaN).

use std::borrow::Cow;
use std::cell::Cell;

use serde::Serializer;
use serde_json::Value;

thread_local! {
    static SI: Cell<bool> = const { Cell::new(false) };
}

/// Whether quantities are being serialised in SI units on this thread ([`in_si`]).
pub fn si() -> bool {
    SI.with(Cell::get)
}

/// Run `f` with every quantity field serialising its SI value (restored afterwards, also when
/// `f` panics).
pub fn in_si<T>(f: impl FnOnce() -> T) -> T {
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            SI.with(|c| c.set(self.0));
        }
    }
    let _restore = Restore(SI.with(|c| c.replace(true)));
    f()
}

fn scaled(v: f64, lab: f64, si_factor: f64) -> f64 {
    if si() {
        v * si_factor
    } else {
        v * lab
    }
}

macro_rules! quantities {
    ($($(#[$doc:meta])* $name:ident, $opt:ident: lab $lab:expr, si $si:expr;)*) => {$(
        $(#[$doc])*
        pub fn $name<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
            s.serialize_f64(scaled(*v, $lab, $si))
        }
        /// The same, for an optional value (`null` when absent).
        pub fn $opt<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
            match v {
                Some(v) => s.serialize_some(&scaled(*v, $lab, $si)),
                None => s.serialize_none(),
            }
        }
    )*};
}

quantities! {
    /// Stored in N, written in mN.
    n_as_mn, opt_n_as_mn: lab 1e3, si 1.0;
    /// Stored and written in mN (SI: N).
    mn, opt_mn: lab 1.0, si 1e-3;
    /// Stored in m, written in µm.
    m_as_um, opt_m_as_um: lab 1e6, si 1.0;
    /// Stored and written in µm (SI: m).
    um, opt_um: lab 1.0, si 1e-6;
    /// Stored in m, written in nm.
    m_as_nm, opt_m_as_nm: lab 1e9, si 1.0;
    /// Stored and written in nm (SI: m).
    nm, opt_nm: lab 1.0, si 1e-9;
    /// Stored in m², written in µm².
    m2_as_um2, opt_m2_as_um2: lab 1e12, si 1.0;
    /// Stored and written in µm² (SI: m²).
    um2, opt_um2: lab 1.0, si 1e-12;
    /// Stored in m³, written in µm³.
    m3_as_um3, opt_m3_as_um3: lab 1e18, si 1.0;
    /// Stored in Pa, written in MPa.
    pa_as_mpa, opt_pa_as_mpa: lab 1e-6, si 1.0;
    /// Stored and written in MPa (SI: Pa).
    mpa, opt_mpa: lab 1.0, si 1e6;
    /// Stored in Pa, written in GPa.
    pa_as_gpa, opt_pa_as_gpa: lab 1e-9, si 1.0;
    /// Stored in Pa/m, written in MPa/nm.
    pa_per_m_as_mpa_per_nm, opt_pa_per_m_as_mpa_per_nm: lab 1e-15, si 1.0;
    /// Stored in 1/m, written in 1/µm.
    per_m_as_per_um, opt_per_m_as_per_um: lab 1e-6, si 1.0;
}

/// What one unit token of a key means: (the SI token, the factor from SI to the unit).
fn unit_token(token: &str) -> Option<(&'static str, f64)> {
    Some(match token {
        "mN" => ("n", 1e3),
        "uN" => ("n", 1e6),
        "um" => ("m", 1e6),
        "nm" => ("m", 1e9),
        "um2" => ("m2", 1e12),
        "um3" => ("m3", 1e18),
        "MPa" => ("pa", 1e-6),
        "GPa" => ("pa", 1e-9),
        _ => return None,
    })
}

/// The key of a quantity in SI units: every unit token of the key (between underscores)
/// replaced by its SI token (`force_mN` → `force_n`, `fwhm_nm_mean` → `fwhm_m_mean`,
/// `hardening_MPa_per_nm` → `hardening_pa_per_m`). Keys without a unit token are unchanged.
pub fn si_key(key: &str) -> Cow<'_, str> {
    if !key.split('_').any(|t| unit_token(t).is_some()) {
        return Cow::Borrowed(key);
    }
    Cow::Owned(
        key.split('_')
            .map(|t| unit_token(t).map_or(t, |(si, _)| si))
            .collect::<Vec<_>>()
            .join("_"),
    )
}

/// The factor from SI to the units a key names (`force_mN`: 1e3; `hardening_MPa_per_nm`:
/// 1e-15), `None` for a key without a unit or with a power (`…_pow_exponent`). For checks
/// that a field's serialisation agrees with its name.
pub fn key_factor(key: &str) -> Option<f64> {
    if key.contains("_pow_") {
        return None;
    }
    let mut factor = 1.0;
    let mut any = false;
    let mut invert = false;
    for token in key.split('_') {
        if token == "per" {
            invert = true;
            continue;
        }
        if let Some((_, f)) = unit_token(token) {
            factor *= if invert { 1.0 / f } else { f };
            any = true;
        }
        invert = false;
    }
    any.then_some(factor)
}

/// `value` serialised in SI units with SI keys ([`in_si`], [`si_key`]): what the Python package
/// returns.
pub fn to_si_value<T: serde::Serialize + ?Sized>(value: &T) -> serde_json::Result<Value> {
    Ok(rename_si(in_si(|| serde_json::to_value(value))?))
}

fn rename_si(value: Value) -> Value {
    match value {
        Value::Object(map) => Value::Object(
            map.into_iter()
                .map(|(k, v)| (si_key(&k).into_owned(), rename_si(v)))
                .collect(),
        ),
        Value::Array(items) => Value::Array(items.into_iter().map(rename_si).collect()),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    #[derive(Serialize)]
    struct Load {
        #[serde(rename = "force_mN", serialize_with = "n_as_mn")]
        force_n: f64,
        #[serde(rename = "area_um2", serialize_with = "um2")]
        area_um2: f64,
        #[serde(
            rename = "hardening_MPa_per_nm",
            serialize_with = "opt_pa_per_m_as_mpa_per_nm"
        )]
        k: Option<f64>,
        patches: u64,
    }

    #[test]
    fn one_declaration_two_unit_systems() {
        let l = Load {
            force_n: 4e-3,
            area_um2: 125.5,
            k: Some(4e15),
            patches: 3,
        };
        let lab = serde_json::to_value(&l).unwrap();
        assert_eq!(lab["force_mN"], 4e-3 * 1e3);
        assert_eq!(lab["area_um2"], 125.5);
        assert_eq!(lab["hardening_MPa_per_nm"], 4e15 * 1e-15);
        let si = to_si_value(&l).unwrap();
        assert_eq!(si["force_n"], 4e-3);
        assert_eq!(si["area_m2"], 125.5 * 1e-12);
        assert_eq!(si["hardening_pa_per_m"], 4e15);
        assert_eq!(si["patches"], 3);
        // The mode is per call: a plain serialisation afterwards is in lab units again.
        assert_eq!(serde_json::to_value(&l).unwrap()["force_mN"], 4.0);
    }

    #[test]
    fn keys_and_factors() {
        assert_eq!(si_key("force_mN"), "force_n");
        assert_eq!(si_key("fwhm_nm_mean"), "fwhm_m_mean");
        assert_eq!(
            si_key("h_double_prime_rms_per_um"),
            "h_double_prime_rms_per_m"
        );
        assert_eq!(si_key("contact_fraction"), "contact_fraction");
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a / b - 1.0).abs() < 1e-12);
        assert!(close(key_factor("hardening_MPa_per_nm"), 1e-15));
        assert!(close(key_factor("h_double_prime_rms_per_um"), 1e-6));
        assert!(close(key_factor("area_um2"), 1e12));
        assert_eq!(key_factor("prefactor_um2_per_mN_pow_exponent"), None);
        assert_eq!(key_factor("patches"), None);
    }
}
