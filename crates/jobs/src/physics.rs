//! Physics checks on results: one table of the ranges a measured number can take in any contact
//! experiment ([`PLAUSIBLE`], `docs/conventions.md`, "Plausible results"), shared by every
//! command and front-end. A result outside its range is kept and reported with a warning that
//! names the likely cause, almost always a unit (a force column in mN headed `_N`, heights in µm
//! read as metres) or an order (forces listed from the largest load).
//!
//! These are checks on what a command *computed*; the ranges of what it *accepts* are
//! [`contactscope_formats::ranges`].

use contactscope_formats::ranges::short;

/// A result with a plausible range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Checked {
    /// Contact modulus E*, Pa (`hertz`, `fit-hardening`).
    ContactModulus,
    /// Friction coefficient μ (static or kinetic), dimensionless (`friction`).
    FrictionCoefficient,
    /// Mean contact pressure N/A, Pa (`analyze`, `simulate`).
    MeanPressure,
    /// rms height of a surface, m (`topography`, `read_topography`).
    HeightRms,
    /// rms slope of a surface, dimensionless (`topography`, `read_topography`).
    SlopeRms,
}

/// One row of the table: what, its range in SI, the unit it is printed in, and the likely cause
/// of a value below and above the range.
#[derive(Debug, Clone, Copy)]
pub struct Plausible {
    /// The result.
    pub what: Checked,
    /// Its name in warnings.
    pub name: &'static str,
    /// Lowest plausible value, SI.
    pub lo: f64,
    /// Highest plausible value, SI.
    pub hi: f64,
    /// Factor from SI to the unit of `unit`.
    pub factor: f64,
    /// The unit the warning prints.
    pub unit: &'static str,
    /// What a value below `lo` most likely means.
    pub low_cause: &'static str,
    /// What a value above `hi` most likely means.
    pub high_cause: &'static str,
}

/// The plausible results (`docs/conventions.md` prints this table).
pub const PLAUSIBLE: &[Plausible] = &[
    Plausible {
        what: Checked::ContactModulus,
        name: "contact modulus E*",
        lo: 1e3,
        hi: 1.2e12,
        factor: 1e-9,
        unit: "GPa",
        low_cause: "softer than any gel: forces in N read as mN, or displacements in µm read as mm?",
        high_cause: "stiffer than diamond (E* ≤ 1.2 TPa): forces in mN under a column headed _N, or displacements in nm read as µm?",
    },
    Plausible {
        what: Checked::FrictionCoefficient,
        name: "friction coefficient μ",
        lo: 1e-3,
        hi: 10.0,
        factor: 1.0,
        unit: "",
        low_cause: "below any dry contact: the friction force in N and the normal force in mN?",
        high_cause: "above any dry contact: the friction force in mN under a column headed _N, or the normal force in N given as mN?",
    },
    Plausible {
        what: Checked::MeanPressure,
        name: "mean pressure",
        lo: crate::fits::LOWEST_PLAUSIBLE_PRESSURE_PA,
        hi: crate::fits::IMPLAUSIBLE_PRESSURE_PA,
        factor: 1e-6,
        unit: "MPa",
        low_cause: "below any contact that bears a load: the pixel size too large, or the forces too small (mN given as N?)",
        high_cause: "beyond any solid contact (the hardest solids yield below 20 GPa): the forces in another unit, or the areas too small?",
    },
    Plausible {
        what: Checked::HeightRms,
        name: "rms height",
        lo: 0.0,
        hi: 1e-3,
        factor: 1e6,
        unit: "µm",
        low_cause: "",
        high_cause: "over 1 mm, no rough surface in a contact: heights in µm or nm read as metres? (give --height-unit)",
    },
    Plausible {
        what: Checked::SlopeRms,
        name: "rms slope",
        lo: 0.0,
        hi: 10.0,
        factor: 1.0,
        unit: "",
        low_cause: "",
        high_cause: "over 10 (steeper than 84°): heights in µm or nm read as metres, or the pixel size too small? (give --height-unit or --pixel-size)",
    },
];

/// The row of `what`.
pub fn range_of(what: Checked) -> &'static Plausible {
    PLAUSIBLE
        .iter()
        .find(|p| p.what == what)
        .expect("every checked result has a row")
}

/// A warning when `value` (SI) lies outside the plausible range of `what` (`None` inside it, and
/// for values that are not finite, which other checks report): "contact modulus E* = 3692.7 GPa
/// is outside 1e-6…1200 GPa: stiffer than diamond …".
pub fn check(what: Checked, value: f64) -> Option<String> {
    let p = range_of(what);
    if !value.is_finite() || (p.lo..=p.hi).contains(&value) {
        return None;
    }
    let cause = if value < p.lo {
        p.low_cause
    } else {
        p.high_cause
    };
    let unit = |v: f64| match p.unit {
        "" => short(v * p.factor),
        u => format!("{} {u}", short(v * p.factor)),
    };
    Some(format!(
        "{} = {} is outside the plausible {}…{}: {cause}",
        p.name,
        unit(value),
        short(p.lo * p.factor),
        unit(p.hi)
    ))
}

/// The warning for an area that falls as the load rises (`analyze`, `simulate`, and the batch's
/// `physics` flag): the fitted exponent β is negative. `significant`: β lies more than two
/// standard errors below 0.
pub fn falling_area(beta: f64, significant: bool) -> Option<String> {
    (beta.is_finite() && beta < 0.0).then(|| {
        format!(
            "the contact area falls as the load rises (β = {}{}): impossible for a sphere pressed \
             on a flat; forces in the wrong order, or the images in another order than the forces?",
            short(beta),
            if significant {
                ", more than two standard errors below 0"
            } else {
                ""
            }
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_outside_their_ranges_are_named_with_a_cause() {
        let w = check(Checked::ContactModulus, 3692.7e9).unwrap();
        assert!(w.contains("3692.7 GPa") && w.contains("_N"), "{w}");
        assert!(check(Checked::ContactModulus, 3.7e9).is_none());
        assert!(check(Checked::ContactModulus, 100.0)
            .unwrap()
            .contains("softer"));
        let w = check(Checked::FrictionCoefficient, 1881.0).unwrap();
        assert!(w.contains("1881") && w.contains("mN"), "{w}");
        assert!(check(Checked::FrictionCoefficient, 0.4).is_none());
        let w = check(Checked::HeightRms, 0.095).unwrap();
        assert!(w.contains("95000 µm") && w.contains("--height-unit"), "{w}");
        assert!(check(Checked::SlopeRms, 226_745.0)
            .unwrap()
            .contains("rms slope"));
        assert!(check(Checked::SlopeRms, 0.3).is_none());
        assert!(check(Checked::MeanPressure, f64::NAN).is_none());
        assert!(falling_area(-1.09, true).unwrap().contains("wrong order"));
        assert!(falling_area(0.9, false).is_none());
    }

    #[test]
    fn every_result_has_one_row() {
        for what in [
            Checked::ContactModulus,
            Checked::FrictionCoefficient,
            Checked::MeanPressure,
            Checked::HeightRms,
            Checked::SlopeRms,
        ] {
            assert_eq!(PLAUSIBLE.iter().filter(|p| p.what == what).count(), 1);
            let p = range_of(what);
            assert!(p.lo < p.hi);
        }
    }
}
