//! Plausible ranges of the physical numbers contactscope accepts, from the command line, from
//! manifests and from file metadata (`docs/errors.md`, "Accepted ranges"). A value outside its range is almost
//! always a typo or a wrong unit (`1e-300nm`, `400N` for 400 mN) or a corrupt header, and would
//! otherwise make a kernel, a grid or a plot axis absurdly large; it is refused with a message
//! naming the value, its source and the range. The ranges are wide: they bound what any contact
//! experiment or simulation could use, not what is typical. `docs/errors.md` lists them.

use crate::error::{Error, Location, Result};
use crate::param::Param;

/// A physical quantity with a plausible range (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Normal or friction force, N: [1 nN, 100 N].
    Force,
    /// Image or map pixel size, m: [0.1 nm, 1 mm].
    PixelSize,
    /// Sphere radius, m: [1 µm, 1 m].
    Radius,
    /// Contact modulus E*, Pa: [1 kPa, 10 TPa].
    Modulus,
    /// Penetration hardness or initial yield pressure, Pa: [1 kPa, 1 TPa].
    Hardness,
    /// Hardening coefficient k, Pa/m: [1 Pa/nm, 1 TPa/nm] = [1e9, 1e21].
    Hardening,
    /// Light wavelength, m: [100 nm, 10 µm].
    Wavelength,
    /// PSF FWHM, m: [1 nm, 100 µm].
    Fwhm,
    /// A lateral length (roll-off and cutoff wavelengths, lags, bead diameters, lever arms), m:
    /// [0.1 nm, 1 m].
    Length,
    /// A height (rms roughness, metres per stored height unit), m: [1 fm, 1 m].
    Height,
}

impl Quantity {
    /// (lowest, highest), SI, both included.
    pub const fn range(self) -> (f64, f64) {
        match self {
            Quantity::Force => (1e-9, 100.0),
            Quantity::PixelSize => (1e-10, 1e-3),
            Quantity::Radius => (1e-6, 1.0),
            Quantity::Modulus => (1e3, 1e13),
            Quantity::Hardness => (1e3, 1e12),
            Quantity::Hardening => (1e9, 1e21),
            Quantity::Wavelength => (1e-7, 1e-5),
            Quantity::Fwhm => (1e-9, 1e-4),
            Quantity::Length => (1e-10, 1.0),
            Quantity::Height => (1e-15, 1.0),
        }
    }

    /// What it is, in words, with the factor from SI to the unit its range is written in and
    /// that unit.
    pub fn describe(self) -> (&'static str, f64, &'static str) {
        match self {
            Quantity::Force => ("force", 1e3, "mN"),
            Quantity::PixelSize => ("pixel size", 1e9, "nm"),
            Quantity::Radius => ("radius", 1e6, "µm"),
            Quantity::Modulus => ("contact modulus", 1e-6, "MPa"),
            Quantity::Hardness => ("hardness", 1e-6, "MPa"),
            Quantity::Hardening => ("hardening coefficient", 1e-15, "MPa/nm"),
            Quantity::Wavelength => ("wavelength", 1e9, "nm"),
            Quantity::Fwhm => ("PSF FWHM", 1e9, "nm"),
            Quantity::Length => ("length", 1e6, "µm"),
            Quantity::Height => ("height", 1e9, "nm"),
        }
    }

    /// Whether `value` (SI) lies in the range; NaN and infinities never do. The bounds are
    /// widened by 1e-12 relative, so that a bound written in another unit (`1e-6mN` for 1 nN)
    /// is not refused for the rounding of its conversion.
    pub fn contains(self, value: f64) -> bool {
        let (lo, hi) = self.range();
        value.is_finite() && (lo * (1.0 - 1e-12)..=hi * (1.0 + 1e-12)).contains(&value)
    }

    /// The message for a value outside the range.
    pub fn refusal(self, value: f64) -> String {
        let (name, to_unit, unit) = self.describe();
        let (lo, hi) = self.range();
        let what = if value <= 0.0 {
            "is negative or zero; it must lie in"
        } else {
            "is outside the plausible range"
        };
        // A finite value whose conversion overflows is written in SI units (never "inf").
        let shown = if (value * to_unit).is_finite() || !value.is_finite() {
            format!("{} {unit}", short(value * to_unit))
        } else {
            format!("{} (SI)", short(value))
        };
        format!(
            "{name} {shown} {what} {} … {} {unit} (a typo or a wrong unit?)",
            short(lo * to_unit),
            short(hi * to_unit)
        )
    }

    /// `value` if it lies in the range, else an [`Error::OutOfRange`] naming the parameter it
    /// was given as.
    pub fn check(self, value: f64, param: Param) -> Result<f64> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(Error::OutOfRange {
                param,
                quantity: self,
                value,
            })
        }
    }

    /// `value` if it lies in the range, else an invalid-argument error naming the `text` it was
    /// read from (`'400N'`).
    pub fn check_text(self, value: f64, text: &str) -> Result<f64> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(Error::InvalidArgument(format!(
                "{text}: {}",
                self.refusal(value)
            )))
        }
    }

    /// `value` if it lies in the range, else a bad-input error at `at` (a file, line or page).
    pub fn check_at(self, value: f64, at: &Location) -> Result<f64> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(Error::bad_input(at.clone(), self.refusal(value)))
        }
    }

    /// A value of this quantity in SI units, for messages to a caller who gives SI numbers
    /// (Python): `200 nm is 2e-7`.
    pub fn si_example(self) -> &'static str {
        match self {
            Quantity::Force => "4 mN is 4e-3",
            Quantity::PixelSize => "200 nm is 2e-7",
            Quantity::Radius => "290 µm is 2.9e-4",
            Quantity::Modulus => "3.7 GPa is 3.7e9",
            Quantity::Hardness => "370 MPa is 3.7e8",
            Quantity::Hardening => "4 MPa/nm is 4e15",
            Quantity::Wavelength => "488 nm is 4.88e-7",
            Quantity::Fwhm => "450 nm is 4.5e-7",
            Quantity::Length => "20 µm is 2e-5",
            Quantity::Height => "1 nm is 1e-9",
        }
    }
}

/// `x` to 7 significant digits without rounding noise, in exponent notation beyond 10⁶ or below
/// 10⁻⁴ (`2e11`, not `199999999999.99997`; `0.1`, not `0.10000000000000002`).
pub fn short(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let rounded: f64 = format!("{x:.6e}").parse().unwrap_or(x);
    let magnitude = rounded.abs().log10().floor();
    if !(-4.0..=6.0).contains(&magnitude) {
        format!("{rounded:e}")
    } else {
        format!("{rounded}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_refusals_are_short() {
        assert_eq!(short(199999999999.99997), "2e11");
        assert_eq!(short(0.1), "0.1");
        assert_eq!(short(1e6), "1000000");
        assert_eq!(short(-3.7), "-3.7");
        assert_eq!(short(1.23456789e-5), "1.234568e-5");
        assert_eq!(short(2.5e-3), "0.0025");
        // A size whose conversion to nm overflows is given in SI units, never as "inf".
        let m = Quantity::PixelSize.refusal(3.3e307);
        assert!(m.contains("3.3e307 (SI)") && !m.contains("inf"), "{m}");
    }

    #[test]
    fn ranges_refuse_absurd_and_non_finite_values() {
        assert!(Quantity::Force.contains(4e-3));
        assert!(Quantity::Force.contains(100.0));
        assert!(!Quantity::Force.contains(0.0));
        assert!(!Quantity::Force.contains(1e-311));
        assert!(!Quantity::Force.contains(1e305));
        assert!(!Quantity::Force.contains(f64::NAN));
        assert!(Quantity::PixelSize.contains(200e-9));
        assert!(!Quantity::PixelSize.contains(1e-309));
        assert!(!Quantity::PixelSize.contains(f64::INFINITY));
        assert!(Quantity::Hardening.contains(4e15));
        // A bound written in another unit survives the rounding of its conversion.
        assert!(Quantity::Force.contains(1e-6 * 1e-3));
        assert!(!Quantity::Force.contains(0.999e-9));
        let err = Quantity::PixelSize
            .check(1e-300, Param::PixelSize)
            .unwrap_err();
        assert!(matches!(
            err,
            Error::OutOfRange {
                param: Param::PixelSize,
                quantity: Quantity::PixelSize,
                ..
            }
        ));
        let text = err.to_string();
        assert!(text.contains("0.1 … 1000000 nm"), "{text}");
    }
}
