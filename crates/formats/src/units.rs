//! Physical quantities on the command line and in files: `290um`, `3.7GPa`, `4,10,20,40mN`.
//!
//! Everything is converted to SI base units (m, N, Pa) on entry; output columns convert back to the
//! unit their name states (`area_um2`, `force_mN`). A number without a unit is rejected wherever a
//! unit is required, because a silently assumed unit is the most expensive mistake a lab can make.

use crate::error::{Error, Result};
use crate::ranges::Quantity;

/// The kind of quantity a string must express.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// Length, in metres.
    Length,
    /// Force, in newtons.
    Force,
    /// Pressure or modulus, in pascals.
    Pressure,
}

impl Dimension {
    fn name(self) -> &'static str {
        match self {
            Dimension::Length => "length",
            Dimension::Force => "force",
            Dimension::Pressure => "pressure",
        }
    }

    fn examples(self) -> &'static str {
        match self {
            Dimension::Length => "m, mm, um (µm, micron), nm",
            Dimension::Force => "N, mN, uN (µN), nN",
            Dimension::Pressure => "Pa, kPa, MPa, GPa",
        }
    }

    /// SI factor of a unit symbol of this dimension, `None` if the symbol is not one.
    pub(crate) fn factor(self, unit: &str) -> Option<f64> {
        // The micro sign (U+00B5), the Greek small letter mu (U+03BC) that keyboards and
        // Unicode normalisation (NFKC) give for it, or ASCII `u`.
        fn micro(u: &str) -> Option<&str> {
            u.strip_prefix('u')
                .or_else(|| u.strip_prefix('\u{b5}'))
                .or_else(|| u.strip_prefix('\u{3bc}'))
        }
        match self {
            Dimension::Length => match unit {
                "m" => Some(1.0),
                "cm" => Some(1e-2),
                "mm" => Some(1e-3),
                "micron" | "microns" => Some(1e-6),
                "nm" => Some(1e-9),
                "pm" => Some(1e-12),
                u if micro(u) == Some("m") => Some(1e-6),
                _ => None,
            },
            Dimension::Force => match unit {
                "N" => Some(1.0),
                "kN" => Some(1e3),
                "mN" => Some(1e-3),
                "nN" => Some(1e-9),
                u if micro(u) == Some("N") => Some(1e-6),
                _ => None,
            },
            Dimension::Pressure => match unit {
                "Pa" => Some(1.0),
                "kPa" => Some(1e3),
                "MPa" => Some(1e6),
                "GPa" => Some(1e9),
                _ => None,
            },
        }
    }
}

/// Split `"3.7GPa"` into `("3.7", "GPa")`; the unit part may be empty.
fn split_number(text: &str) -> (&str, &str) {
    let text = text.trim();
    let end = text
        .char_indices()
        .find(|&(i, c)| {
            !(c.is_ascii_digit()
                || c == '.'
                || c == '+'
                || c == '-'
                || ((c == 'e' || c == 'E') && exponent_follows(&text[i + 1..])))
        })
        .map_or(text.len(), |(i, _)| i);
    (&text[..end], text[end..].trim())
}

fn exponent_follows(rest: &str) -> bool {
    let rest = rest.strip_prefix(['+', '-']).unwrap_or(rest);
    rest.starts_with(|c: char| c.is_ascii_digit())
}

fn parse_number(number: &str, whole: &str) -> Result<f64> {
    let value: f64 = number
        .parse()
        .map_err(|_| Error::InvalidArgument(format!("'{whole}' is not a number with a unit")))?;
    if !value.is_finite() {
        return Err(Error::InvalidArgument(format!("'{whole}' is not finite")));
    }
    Ok(value)
}

/// `value × factor`, dividing by the exact power of ten for sub-unit factors so that `200nm`
/// gives exactly the literal `200e-9` (multiplying by the inexact `1e-9` would not).
fn scale(value: f64, factor: f64) -> f64 {
    if factor < 1.0 {
        value / (1.0 / factor).round()
    } else {
        value * factor
    }
}

fn unit_factor(dim: Dimension, unit: &str, whole: &str) -> Result<f64> {
    dim.factor(unit).ok_or_else(|| {
        if unit.is_empty() {
            Error::InvalidArgument(format!(
                "'{whole}' has no unit; give a {} unit ({})",
                dim.name(),
                dim.examples()
            ))
        } else {
            Error::InvalidArgument(format!(
                "unknown {} unit '{unit}' in '{whole}' (known: {})",
                dim.name(),
                dim.examples()
            ))
        }
    })
}

/// Parse one quantity with a mandatory unit, e.g. `parse_quantity("290um", Dimension::Length)`
/// gives `2.9e-4` (metres).
pub fn parse_quantity(text: &str, dim: Dimension) -> Result<f64> {
    let (number, unit) = split_number(text);
    let value = parse_number(number, text)?;
    Ok(scale(value, unit_factor(dim, unit, text)?))
}

/// Parse a positive quantity (pixel sizes, radii, moduli).
pub fn parse_positive(text: &str, dim: Dimension) -> Result<f64> {
    let value = parse_quantity(text, dim)?;
    if value <= 0.0 {
        return Err(Error::InvalidArgument(format!("'{text}' must be positive")));
    }
    Ok(value)
}

/// Parse a comma-separated list such as `4,10,20,40mN` or `4mN,10mN`. Items without a unit take
/// the unit of the next item that has one, so a single trailing unit serves the whole list; a list
/// with no unit at all is rejected.
pub fn parse_quantity_list(text: &str, dim: Dimension) -> Result<Vec<f64>> {
    quantity_list(text, dim, false)
}

fn quantity_list(text: &str, dim: Dimension, zero_allowed: bool) -> Result<Vec<f64>> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    if items.iter().any(|s| s.is_empty()) {
        return Err(Error::InvalidArgument(format!(
            "'{text}' has an empty item"
        )));
    }
    let mut values = vec![0.0; items.len()];
    let mut pending_unit: Option<f64> = None;
    for (i, item) in items.iter().enumerate().rev() {
        let (number, unit) = split_number(item);
        let value = parse_number(number, item)?;
        let factor = if unit.is_empty() {
            pending_unit.ok_or_else(|| {
                Error::InvalidArgument(format!(
                    "'{item}' in '{text}' has no unit; write e.g. 4,10,20mN ({})",
                    dim.examples()
                ))
            })?
        } else {
            unit_factor(dim, unit, item)?
        };
        pending_unit = Some(factor);
        values[i] = scale(value, factor);
        if dim == Dimension::Force && !(zero_allowed && values[i] == 0.0) {
            Quantity::Force.check_text(values[i], &format!("'{item}'"))?;
        }
    }
    Ok(values)
}

/// The most values a range such as `4mN..400mN:12` may ask for.
pub const MAX_RANGE_COUNT: usize = 10_000;

/// The count of a range (`…:N`), 2 ..= [`MAX_RANGE_COUNT`].
fn range_count(count: &str, text: &str) -> Result<usize> {
    let n: usize = count
        .trim()
        .parse()
        .map_err(|_| Error::InvalidArgument(format!("'{count}' in '{text}' is not a count")))?;
    if !(2..=MAX_RANGE_COUNT).contains(&n) {
        return Err(Error::InvalidArgument(format!(
            "range '{text}' asks for {n} values; give 2 to {MAX_RANGE_COUNT}"
        )));
    }
    Ok(n)
}

/// Parse loads: a list (`4,10,40mN`) or a log-spaced range `4mN..400mN:12` (12 values from 4 to
/// 400 mN, equal ratios). Returns newtons; every value must be positive (a simulated load of
/// 0 N has no contact to compute).
pub fn parse_loads(text: &str) -> Result<Vec<f64>> {
    force_values(text, false)
}

/// Parse the forces of micrographs: the syntax of [`parse_loads`], and a list may hold `0`
/// (a reference frame recorded before loading, analysed and left out of fits and log axes).
pub fn parse_forces(text: &str) -> Result<Vec<f64>> {
    force_values(text, true)
}

/// A list (each item range-checked by [`quantity_list`], 0 only if `zero_allowed`) or a
/// log-spaced range (its two ends range-checked; the values between lie within them).
fn force_values(text: &str, zero_allowed: bool) -> Result<Vec<f64>> {
    if text.contains(',') && text.contains("..") {
        return mixed_force_values(text, zero_allowed);
    }
    let Some((from, rest)) = text.split_once("..") else {
        return quantity_list(text, Dimension::Force, zero_allowed);
    };
    let (to, count) = rest.split_once(':').ok_or_else(|| {
        Error::InvalidArgument(format!(
            "force range '{text}' needs a count: e.g. 4mN..400mN:12"
        ))
    })?;
    let (a, b) = (
        parse_quantity(&with_unit_of(from, to), Dimension::Force)?,
        parse_quantity(to, Dimension::Force)?,
    );
    let n = range_count(count, text)?;
    if !(a > 0.0 && b > a) {
        return Err(Error::InvalidArgument(format!(
            "force range '{text}' needs 0 < start < end (log-spaced values)"
        )));
    }
    for end in [a, b] {
        Quantity::Force.check_text(end, &format!("'{text}'"))?;
    }
    Ok((0..n)
        .map(|i| a * (b / a).powf(i as f64 / (n - 1) as f64))
        .collect())
}

/// A list whose items are values and ranges, `0,1mN..40mN:10` (a 0 mN reference frame, then ten
/// log-spaced loads): each item as [`force_values`] reads it, bare numbers in the unit of the last
/// item (a range's end).
fn mixed_force_values(text: &str, zero_allowed: bool) -> Result<Vec<f64>> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    let last = items.last().copied().unwrap_or_default();
    let carrier = match last.split_once("..") {
        Some((_, rest)) => rest.split(':').next().unwrap_or_default(),
        None => last,
    };
    let mut values = Vec::new();
    for item in items {
        if item.contains("..") {
            values.extend(force_values(item, zero_allowed)?);
        } else {
            values.extend(quantity_list(
                &with_unit_of(item, carrier),
                Dimension::Force,
                zero_allowed,
            )?);
        }
    }
    Ok(values)
}

/// A bare number (no unit) takes the unit written after the last item, so `1..10MPa/nm:10` and
/// `1,2,4MPa/nm` mean what they say.
fn with_unit_of(item: &str, last: &str) -> String {
    let (number, unit) = split_number(item);
    if unit.is_empty() {
        format!("{number}{}", split_number(last).1)
    } else {
        item.trim().to_string()
    }
}

/// Values parsed by `parse_one`: a list `1,2,4MPa/nm` or an evenly spaced range
/// `1..10MPa/nm:10` (10 values from 1 to 10, equal steps). Bare numbers take the last item's unit.
pub fn parse_value_list(text: &str, parse_one: &dyn Fn(&str) -> Result<f64>) -> Result<Vec<f64>> {
    if let Some((from, rest)) = text.split_once("..") {
        let (to, count) = rest.split_once(':').ok_or_else(|| {
            Error::InvalidArgument(format!("range '{text}' needs a count, e.g. 1..10MPa/nm:10"))
        })?;
        let n = range_count(count, text)?;
        let (a, b) = (parse_one(&with_unit_of(from, to))?, parse_one(to)?);
        if b <= a {
            return Err(Error::InvalidArgument(format!(
                "range '{text}' needs start < end and at least 2 values"
            )));
        }
        return Ok((0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect());
    }
    let items: Vec<&str> = text.split(',').collect();
    let last = items.last().copied().unwrap_or_default();
    items
        .iter()
        .map(|item| parse_one(&with_unit_of(item, last)))
        .collect()
}

/// A range `lo..hi` of values parsed by `parse_one` (`0.1..100MPa/nm`); requires lo < hi.
pub fn parse_range(text: &str, parse_one: &dyn Fn(&str) -> Result<f64>) -> Result<(f64, f64)> {
    let (from, to) = text.split_once("..").ok_or_else(|| {
        Error::InvalidArgument(format!("'{text}' is not a range such as 0.1..100MPa/nm"))
    })?;
    let (a, b) = (parse_one(&with_unit_of(from, to))?, parse_one(to)?);
    if a < b {
        Ok((a, b))
    } else {
        Err(Error::InvalidArgument(format!(
            "range '{text}' needs start < end"
        )))
    }
}

/// Parse a ratio of two quantities, e.g. a hardening modulus `4MPa/nm` (returned in Pa/m).
pub fn parse_ratio(text: &str, numerator: Dimension, denominator: Dimension) -> Result<f64> {
    let (top, bottom) = text.split_once('/').ok_or_else(|| {
        Error::InvalidArgument(format!(
            "'{text}' must be a {} per {}, e.g. 4MPa/nm",
            numerator.name(),
            denominator.name()
        ))
    })?;
    let (number, unit) = split_number(top);
    let value = parse_number(number, text)?;
    let per = parse_positive(&format!("1{}", bottom.trim()), denominator)?;
    let ratio = scale(value, unit_factor(numerator, unit, text)?) / per;
    if !(ratio > 0.0 && ratio.is_finite()) {
        return Err(Error::InvalidArgument(format!("'{text}' must be positive")));
    }
    Ok(ratio)
}

/// Parse a pixel size: `200nm`, `0.2um`, or `200x210nm` (x by y) for non-square pixels.
/// Returns (x, y) in metres.
pub fn parse_pixel_size(text: &str) -> Result<(f64, f64)> {
    let (x_part, y_part) = match text.split_once(['x', '×']) {
        Some((x, y)) => (x, y),
        None => (text, text),
    };
    let y = parse_positive(y_part, Dimension::Length)?;
    let (x_number, x_unit) = split_number(x_part);
    let x = if x_unit.is_empty() && x_part != text {
        let (_, y_unit) = split_number(y_part);
        parse_positive(&format!("{x_number}{y_unit}"), Dimension::Length)?
    } else {
        parse_positive(x_part, Dimension::Length)?
    };
    Quantity::PixelSize.check_text(x, &format!("'{text}'"))?;
    Quantity::PixelSize.check_text(y, &format!("'{text}'"))?;
    Ok((x, y))
}

/// A pixel size with its uncertainty: `200nm±1%`, `200nm+-2nm`, `200x210nm±0.5%`, or a pixel
/// size alone ([`parse_pixel_size`]; uncertainty `None`). The uncertainty is relative (0.01 for
/// ±1 %): a percentage, or a length relative to the larger side. `+/-` and `+-` stand for `±`.
pub fn parse_pixel_size_uncertain(text: &str) -> Result<((f64, f64), Option<f64>)> {
    let split = ["±", "+/-", "+-"]
        .iter()
        .find_map(|sep| text.split_once(sep));
    let Some((size, uncertainty)) = split else {
        return Ok((parse_pixel_size(text)?, None));
    };
    let (x, y) = parse_pixel_size(size.trim())?;
    let u = parse_relative_uncertainty(uncertainty, Some(x.max(y)))
        .map_err(|e| Error::InvalidArgument(format!("'{text}': {e}")))?;
    Ok(((x, y), Some(u)))
}

/// A relative uncertainty: `1%`, `0.01`, or (when `of` is given) a length such as `2nm`
/// relative to `of` metres. Negative or non-finite values are refused.
pub fn parse_relative_uncertainty(text: &str, of: Option<f64>) -> Result<f64> {
    let t = text.trim();
    let value = if let Some(pct) = t.strip_suffix('%') {
        parse_number(pct.trim(), text)? / 100.0
    } else if let Ok(v) = t.parse::<f64>() {
        v
    } else if let Some(of) = of {
        parse_quantity(t, Dimension::Length)? / of
    } else {
        return Err(Error::InvalidArgument(format!(
            "'{text}' is not a relative uncertainty: give a percentage (1%) or a fraction (0.01)"
        )));
    };
    if !(value >= 0.0 && value.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "the uncertainty '{text}' must be 0 or positive"
        )));
    }
    Ok(value)
}

/// `value × factor` in another unit without the binary noise of the product (2e-7 m × 1e6 is
/// `0.19999999999999998`, this gives `0.2`): a product within two units in the last place of a
/// decimal of at most 12 significant digits is that decimal; any other product (a computed
/// value whose 16 or 17 digits all come from its computation) is kept exactly.
pub fn in_unit(value: f64, factor: f64) -> f64 {
    let product = value * factor;
    if !product.is_finite() || product == 0.0 {
        return product;
    }
    let rounded: f64 = format!("{product:.11e}").parse().unwrap_or(product);
    let ulp = f64::EPSILON * product.abs();
    match (rounded - product).abs() <= 2.0 * ulp {
        true => rounded,
        false => product,
    }
}

/// Format a length in metres in the most readable unit (`200 nm`, `2.49 µm`).
pub fn format_length(metres: f64) -> String {
    let abs = metres.abs();
    if abs < 1e-6 {
        format!("{:.4} nm", metres * 1e9)
    } else if abs < 1e-3 {
        format!("{:.5} µm", metres * 1e6)
    } else {
        format!("{:.5} mm", metres * 1e3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_changes_drop_binary_noise_only() {
        assert_eq!(in_unit(2e-7, 1e6), 0.2);
        assert_eq!((2e-7f64 * 1e6).to_string(), "0.19999999999999998");
        // Seventeen meaningful digits stay.
        let full = 1.234_567_890_123_456_7e-7;
        assert_eq!(in_unit(full, 1e6), full * 1e6);
        assert_eq!(in_unit(0.1 + 0.2, 1.0), 0.3);
        assert_eq!(in_unit(0.0, 1e6), 0.0);
        assert_eq!(in_unit(4.5e-7, 1e6), 0.45);
        // A computed value keeps every digit (15-digit rounding would move it by 3 ulps).
        assert_eq!(
            in_unit(0.371_919_904_654_471_17, 1.0),
            0.371_919_904_654_471_17
        );
        let x = 1.0 / 3.0;
        assert_eq!(in_unit(x, 1.0), x);
    }

    #[test]
    fn value_lists_and_ranges_carry_the_last_unit() {
        let k = |t: &str| parse_ratio(t, Dimension::Pressure, Dimension::Length);
        let v = parse_value_list("1..10MPa/nm:10", &k).unwrap();
        assert_eq!(v.len(), 10);
        assert!(
            (v[0] - 1e15).abs() < 1.0 && (v[9] - 1e16).abs() < 10.0 && (v[1] - 2e15).abs() < 1.0
        );
        let v = parse_value_list("1,2,4MPa/nm", &k).unwrap();
        assert!((v[2] - 4e15).abs() < 1.0);
        let p = |t: &str| parse_positive(t, Dimension::Pressure);
        assert_eq!(parse_range("10MPa..10GPa", &p).unwrap(), (1e7, 1e10));
        assert_eq!(parse_range("100..300MPa", &p).unwrap(), (1e8, 3e8));
        assert!(parse_range("3..1MPa", &p).is_err());
        assert!(parse_value_list("1..10MPa/nm", &k).is_err());
    }
    use approx::assert_relative_eq;

    #[test]
    fn pixel_sizes_carry_an_uncertainty_in_percent_or_length() {
        let p = parse_pixel_size_uncertain;
        assert_eq!(p("200nm").unwrap(), ((200e-9, 200e-9), None));
        let ((x, y), u) = p("200nm±1%").unwrap();
        assert_eq!((x, y), (200e-9, 200e-9));
        assert_relative_eq!(u.unwrap(), 0.01);
        assert_relative_eq!(p("200nm +- 2nm").unwrap().1.unwrap(), 0.01);
        assert_relative_eq!(p("200x250nm+/-0.5%").unwrap().1.unwrap(), 0.005);
        assert_eq!(p("200x250nm±5nm").unwrap().0, (200e-9, 250e-9));
        assert_relative_eq!(p("200x250nm±5nm").unwrap().1.unwrap(), 0.02);
        assert!(p("200nm±").is_err());
        assert!(p("200nm±-1%").is_err());
        assert!(p("200±1%").is_err());
        assert!(p("200nm±2mN").is_err());
        assert_relative_eq!(parse_relative_uncertainty("0.5 %", None).unwrap(), 0.005);
        assert_relative_eq!(parse_relative_uncertainty("0.02", None).unwrap(), 0.02);
        assert!(parse_relative_uncertainty("2nm", None).is_err());
    }

    #[test]
    fn parses_units_and_rejects_missing_or_unknown_ones() {
        assert_eq!(parse_quantity("290um", Dimension::Length).unwrap(), 290e-6);
        assert_eq!(parse_quantity("200nm", Dimension::Length).unwrap(), 200e-9);
        assert_eq!(
            parse_quantity_list("4,6mN", Dimension::Force).unwrap(),
            [4e-3, 6e-3]
        );
        assert_relative_eq!(parse_quantity("290 µm", Dimension::Length).unwrap(), 290e-6);
        // Greek mu (U+03BC) as the micro sign (U+00B5).
        assert_relative_eq!(
            parse_quantity("290 \u{3bc}m", Dimension::Length).unwrap(),
            290e-6
        );
        assert_relative_eq!(parse_quantity("5\u{3bc}N", Dimension::Force).unwrap(), 5e-6);
        assert_relative_eq!(
            parse_quantity("3.7GPa", Dimension::Pressure).unwrap(),
            3.7e9
        );
        assert_relative_eq!(parse_quantity("1e-3N", Dimension::Force).unwrap(), 1e-3);
        assert_relative_eq!(parse_quantity("2.5e2mN", Dimension::Force).unwrap(), 0.25);
        assert!(parse_quantity("290", Dimension::Length).is_err());
        assert!(parse_quantity("290furlong", Dimension::Length).is_err());
        assert!(parse_quantity("3.7GPa", Dimension::Length).is_err());
        assert!(parse_quantity("abcmN", Dimension::Force).is_err());
        assert!(parse_positive("-2nm", Dimension::Length).is_err());
    }

    #[test]
    fn lists_share_a_trailing_unit() {
        let f = parse_quantity_list("4,10,20,40mN", Dimension::Force).unwrap();
        assert_eq!(f.len(), 4);
        assert_relative_eq!(f[0], 4e-3);
        assert_relative_eq!(f[3], 40e-3);
        let g = parse_quantity_list("4mN, 1N", Dimension::Force).unwrap();
        assert_relative_eq!(g[0], 4e-3);
        assert_relative_eq!(g[1], 1.0);
        assert!(parse_quantity_list("4,10,20", Dimension::Force).is_err());
        assert!(parse_quantity_list("4mN,,5mN", Dimension::Force).is_err());
        assert!(parse_quantity_list("4mN,10", Dimension::Force).is_err());
    }

    #[test]
    fn loads_and_ratios() {
        let l = parse_loads("4mN..400mN:3").unwrap();
        assert_eq!(l.len(), 3);
        assert_relative_eq!(l[1], 0.04, max_relative = 1e-12);
        assert_relative_eq!(l[2], 0.4, max_relative = 1e-12);
        assert_eq!(parse_loads("4,10mN").unwrap(), [4e-3, 10e-3]);
        assert!(parse_loads("4mN..400mN").is_err());
        assert!(parse_loads("400mN..4mN:3").is_err());
        let e = parse_loads("4mN..400mN:1099511627776")
            .unwrap_err()
            .to_string();
        assert!(e.contains("2 to 10000"), "{e}");
        assert!(parse_value_list("1..10MPa/nm:100000", &|t| Ok(t.len() as f64)).is_err());
        assert!(parse_loads("0mN,1mN").is_err());
        // Micrograph forces: the same syntax, and a 0 mN reference frame.
        assert_eq!(parse_forces("0,4,10mN").unwrap(), [0.0, 4e-3, 10e-3]);
        let f = parse_forces("1..100mN:3").unwrap();
        assert_relative_eq!(f[1], 0.01, max_relative = 1e-12);
        assert!(parse_forces("0mN..100mN:3").is_err(), "log-spaced from 0");
        assert!(parse_forces("-1,4mN").is_err());
        assert!(parse_forces("4,400000mN").is_err(), "400 N is out of range");
        // A reference frame, then a range: each item read as alone, bare numbers in the last unit.
        let f = parse_forces("0,1mN..100mN:3").unwrap();
        assert_eq!(f.len(), 4);
        assert_eq!(f[0], 0.0);
        assert_relative_eq!(f[2], 0.01, max_relative = 1e-12);
        let f = parse_forces("0.5,1..100mN:3,200mN").unwrap();
        assert_eq!(f.len(), 5);
        assert_relative_eq!(f[0], 0.5e-3, max_relative = 1e-12);
        assert!(
            parse_loads("0,1mN..100mN:3").is_err(),
            "a simulated load of 0"
        );
        assert_relative_eq!(
            parse_ratio("4MPa/nm", Dimension::Pressure, Dimension::Length).unwrap(),
            4e15,
            max_relative = 1e-12
        );
        assert!(parse_ratio("4MPa", Dimension::Pressure, Dimension::Length).is_err());
        assert!(parse_ratio("4MPa/s", Dimension::Pressure, Dimension::Length).is_err());
    }

    #[test]
    fn pixel_sizes_square_and_rectangular() {
        let (x, y) = parse_pixel_size("200nm").unwrap();
        assert_relative_eq!(x, 200e-9);
        assert_relative_eq!(y, 200e-9);
        let (x, y) = parse_pixel_size("200x210nm").unwrap();
        assert_relative_eq!(x, 200e-9);
        assert_relative_eq!(y, 210e-9);
        let (x, y) = parse_pixel_size("0.2umx0.25um").unwrap();
        assert_relative_eq!(x, 0.2e-6);
        assert_relative_eq!(y, 0.25e-6);
        assert!(parse_pixel_size("200").is_err());
        assert!(parse_pixel_size("0nm").is_err());
    }
}
