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
    let factor = if si() { si_factor } else { lab };
    // Without the conversion's binary noise (4.5e-7 m is 0.45 µm, not 0.44999999999999996).
    match factor == 1.0 {
        true => v,
        false => contactscope_formats::units::in_unit(v, factor),
    }
}

/// How a quantity is stored and written: the factor from the stored value to the written one,
/// and to the SI one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unit {
    /// Stored in N, written in mN.
    NAsMn,
    /// Stored and written in mN.
    Mn,
    /// Stored in m, written in µm.
    MAsUm,
    /// Stored and written in µm.
    Um,
    /// Stored in m, written in nm.
    MAsNm,
    /// Stored and written in nm.
    Nm,
    /// Stored in m², written in µm².
    M2AsUm2,
    /// Stored and written in µm².
    Um2,
    /// Stored in m³, written in µm³.
    M3AsUm3,
    /// Stored in Pa, written in MPa.
    PaAsMpa,
    /// Stored and written in MPa.
    Mpa,
    /// Stored in Pa, written in GPa.
    PaAsGpa,
    /// Stored in Pa/m, written in MPa/nm.
    PaPerMAsMpaPerNm,
    /// Stored in 1/m, written in 1/µm.
    PerMAsPerUm,
    /// A count or a ratio: no unit.
    None,
    /// Stored in m, written in mm.
    MAsMm,
    /// Stored as a fraction, written in percent (SI: the fraction).
    FractionAsPct,
}

impl Unit {
    /// (stored → written, stored → SI).
    fn factors(self) -> (f64, f64) {
        match self {
            Unit::NAsMn => (1e3, 1.0),
            Unit::Mn => (1.0, 1e-3),
            Unit::MAsUm => (1e6, 1.0),
            Unit::Um => (1.0, 1e-6),
            Unit::MAsNm => (1e9, 1.0),
            Unit::Nm => (1.0, 1e-9),
            Unit::M2AsUm2 => (1e12, 1.0),
            Unit::Um2 => (1.0, 1e-12),
            Unit::M3AsUm3 => (1e18, 1.0),
            Unit::PaAsMpa => (1e-6, 1.0),
            Unit::Mpa => (1.0, 1e6),
            Unit::PaAsGpa => (1e-9, 1.0),
            Unit::PaPerMAsMpaPerNm => (1e-15, 1.0),
            Unit::PerMAsPerUm => (1e-6, 1.0),
            Unit::None => (1.0, 1.0),
            Unit::MAsMm => (1e3, 1.0),
            Unit::FractionAsPct => (100.0, 1.0),
        }
    }

    /// The value as written (or, inside [`in_si`], in SI units).
    pub fn apply(self, v: f64) -> f64 {
        let (lab, si) = self.factors();
        scaled(v, lab, si)
    }
}

/// A quantity for hand-written `Serialize` impls: `Q(force_n, Unit::NAsMn)`.
#[derive(Debug, Clone, Copy)]
pub struct Q(pub f64, pub Unit);

impl serde::Serialize for Q {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(self.1.apply(self.0))
    }
}

/// An optional quantity (`null` when absent).
#[derive(Debug, Clone, Copy)]
pub struct OptQ(pub Option<f64>, pub Unit);

impl serde::Serialize for OptQ {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0 {
            Some(v) => s.serialize_some(&self.1.apply(v)),
            None => s.serialize_none(),
        }
    }
}

/// Quantities of one unit in a list: `Qs(&forces_n, Unit::NAsMn)`.
#[derive(Debug, Clone, Copy)]
pub struct Qs<'a>(pub &'a [f64], pub Unit);

impl serde::Serialize for Qs<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.0.iter().map(|&v| self.1.apply(v)))
    }
}

/// An interval (lo, hi) of one quantity, written as a two-element list.
#[derive(Debug, Clone, Copy)]
pub struct Interval(pub f64, pub f64, pub Unit);

impl serde::Serialize for Interval {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq([self.2.apply(self.0), self.2.apply(self.1)])
    }
}

macro_rules! quantities {
    ($($(#[$doc:meta])* $name:ident, $opt:ident, $each:ident: $unit:ident;)*) => {$(
        $(#[$doc])*
        pub fn $name<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
            s.serialize_f64(Unit::$unit.apply(*v))
        }
        /// The same, for an optional value (`null` when absent).
        pub fn $opt<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
            serde::Serialize::serialize(&OptQ(*v, Unit::$unit), s)
        }
        /// The same, for every value of a list.
        pub fn $each<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
            serde::Serialize::serialize(&Qs(v, Unit::$unit), s)
        }
    )*};
}

quantities! {
    /// Stored in N, written in mN.
    n_as_mn, opt_n_as_mn, each_n_as_mn: NAsMn;
    /// Stored and written in mN (SI: N).
    mn, opt_mn, each_mn: Mn;
    /// Stored in m, written in µm.
    m_as_um, opt_m_as_um, each_m_as_um: MAsUm;
    /// Stored and written in µm (SI: m).
    um, opt_um, each_um: Um;
    /// Stored in m, written in nm.
    m_as_nm, opt_m_as_nm, each_m_as_nm: MAsNm;
    /// Stored and written in nm (SI: m).
    nm, opt_nm, each_nm: Nm;
    /// Stored in m², written in µm².
    m2_as_um2, opt_m2_as_um2, each_m2_as_um2: M2AsUm2;
    /// Stored and written in µm² (SI: m²).
    um2, opt_um2, each_um2: Um2;
    /// Stored in m³, written in µm³.
    m3_as_um3, opt_m3_as_um3, each_m3_as_um3: M3AsUm3;
    /// Stored in Pa, written in MPa.
    pa_as_mpa, opt_pa_as_mpa, each_pa_as_mpa: PaAsMpa;
    /// Stored and written in MPa (SI: Pa).
    mpa, opt_mpa, each_mpa: Mpa;
    /// Stored in Pa, written in GPa.
    pa_as_gpa, opt_pa_as_gpa, each_pa_as_gpa: PaAsGpa;
    /// Stored in Pa/m, written in MPa/nm.
    pa_per_m_as_mpa_per_nm, opt_pa_per_m_as_mpa_per_nm, each_pa_per_m_as_mpa_per_nm: PaPerMAsMpaPerNm;
    /// Stored in 1/m, written in 1/µm.
    per_m_as_per_um, opt_per_m_as_per_um, each_per_m_as_per_um: PerMAsPerUm;
    /// Stored in m, written in mm.
    m_as_mm, opt_m_as_mm, each_m_as_mm: MAsMm;
    /// Stored as a fraction, written in percent (SI key: `…_fraction`).
    fraction_as_pct, opt_fraction_as_pct, each_fraction_as_pct: FractionAsPct;
}

/// What one unit token of a key means: (the SI token, the factor from SI to the unit).
fn unit_token(token: &str) -> Option<(&'static str, f64)> {
    Some(match token {
        "mN" => ("n", 1e3),
        "uN" => ("n", 1e6),
        "um" => ("m", 1e6),
        "nm" => ("m", 1e9),
        "mm" => ("m", 1e3),
        "um2" => ("m2", 1e12),
        "um3" => ("m3", 1e18),
        "MPa" => ("pa", 1e-6),
        "GPa" => ("pa", 1e-9),
        "pct" => ("fraction", 100.0),
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

    #[test]
    fn millimetres_and_percent() {
        #[derive(Serialize)]
        struct Inputs {
            #[serde(rename = "rotation_radius_mm", serialize_with = "opt_m_as_mm")]
            r: Option<f64>,
            #[serde(rename = "force_tolerance_pct", serialize_with = "fraction_as_pct")]
            t: f64,
        }
        let i = Inputs {
            r: Some(5e-3),
            t: 0.02,
        };
        let lab = serde_json::to_value(&i).unwrap();
        assert_eq!(lab["rotation_radius_mm"], 5e-3 * 1e3);
        assert_eq!(lab["force_tolerance_pct"], 0.02 * 100.0);
        let si = to_si_value(&i).unwrap();
        assert_eq!(si["rotation_radius_m"], 5e-3);
        assert_eq!(si["force_tolerance_fraction"], 0.02);
        assert!((key_factor("rotation_radius_mm").unwrap() - 1e3).abs() < 1e-9);
    }
}
