//! Small numeric CSV tables whose column names carry the unit (`force_mN`, `torque_Nm`): the one
//! reader shared by the mechanics inputs, so that every missing or misspelt column is reported
//! the same way, naming the file and the columns it does have.

use std::path::{Path, PathBuf};

use crate::error::{Error, Location, Result};

/// A CSV file read into memory: trimmed header names and raw records.
pub(crate) struct Table {
    path: PathBuf,
    header: Vec<String>,
    rows: Vec<csv::StringRecord>,
    /// The line each row starts on.
    lines: Vec<u64>,
    delimiter: u8,
}

/// The field delimiter of a CSV text: `;` when its first line that is not a `#` comment has
/// semicolons and no commas (the CSV a spreadsheet writes in locales whose decimal mark is the
/// comma), else `,`.
pub(crate) fn sniff_delimiter(text: &str) -> u8 {
    let first = text
        .trim_start_matches('\u{feff}')
        .lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    match first {
        Some(l) if l.contains(';') && !l.contains(',') => b';',
        // Tab-separated (spreadsheets' "Text (Tab delimited)").
        Some(l) if l.contains('\t') && !l.contains(',') && !l.contains(';') => b'\t',
        _ => b',',
    }
}

/// A number cell of a CSV with `delimiter`: in a semicolon- or tab-separated file a decimal
/// comma (`4,5`) is the decimal point.
pub(crate) fn parse_number(cell: &str, delimiter: u8) -> Option<f64> {
    let cell = cell.trim();
    match cell.parse::<f64>() {
        Ok(v) => Some(v),
        Err(_) if delimiter != b',' && cell.matches(',').count() == 1 && !cell.contains('.') => {
            cell.replace(',', ".").parse().ok()
        }
        Err(_) => None,
    }
}

impl Table {
    /// Read `path`; an unreadable file or a malformed CSV is an error naming the file.
    pub(crate) fn read(path: &Path) -> Result<Table> {
        crate::staging::note_input(path);
        let at = || Location::file(path);
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let text = std::str::from_utf8(&bytes)
            .map_err(|_| Error::bad_input(at(), "not UTF-8 text (save the table as CSV UTF-8)"))?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let delimiter = sniff_delimiter(text);
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let header = reader
            .headers()
            .map_err(|e| csv_error(path, e))?
            .iter()
            .map(String::from)
            .collect();
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        for record in reader.records() {
            let record =
                record.map_err(|e| Error::bad_input(at(), format!("not a readable CSV: {e}")))?;
            // A row with no value at all (a spreadsheet's trailing `,,,`) is no row.
            if record.iter().all(str::is_empty) {
                continue;
            }
            lines.push(line_of(text, &record));
            rows.push(record);
        }
        Ok(Table {
            path: path.to_path_buf(),
            header,
            rows,
            lines,
            delimiter,
        })
    }

    /// The file, for error messages.
    pub(crate) fn location(&self) -> Location {
        Location::file(&self.path)
    }

    /// Column names as found.
    pub(crate) fn header(&self) -> &[String] {
        &self.header
    }

    /// Number of data rows.
    pub(crate) fn len(&self) -> usize {
        self.rows.len()
    }

    /// The one column among `candidates` that is present, `None` if none is. Two of them at once
    /// (`friction_mN` and `friction_N`) are ambiguous and an error.
    pub(crate) fn one_of<'a>(&self, candidates: &[&'a str]) -> Result<Option<&'a str>> {
        let present: Vec<&'a str> = candidates
            .iter()
            .copied()
            .filter(|c| self.header.iter().any(|h| h == c))
            .collect();
        match present.as_slice() {
            [] => Ok(None),
            [one] => Ok(Some(one)),
            many => Err(Error::bad_input(
                self.location(),
                format!(
                    "columns {} say the same thing; keep one",
                    many.join(" and ")
                ),
            )),
        }
    }

    /// The error for a required column that is not there.
    pub(crate) fn missing(&self, what: &str, accepted: &[&str]) -> Error {
        Error::bad_input(
            self.location(),
            format!(
                "no {what} column (accepted: {}); columns found: {}",
                accepted.join(", "),
                self.found()
            ),
        )
    }

    /// The header as a readable list.
    pub(crate) fn found(&self) -> String {
        if self.header.is_empty() {
            "none".into()
        } else {
            self.header.join(", ")
        }
    }

    /// Column `name` as finite numbers times `factor`; an empty or non-numeric cell is an error
    /// naming its line (the header is line 1).
    pub(crate) fn numbers(&self, name: &str, factor: f64) -> Result<Vec<f64>> {
        let i = self
            .header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| self.missing(name, &[name]))?;
        self.rows
            .iter()
            .enumerate()
            .map(|(k, row)| {
                let cell = row.get(i).unwrap_or("");
                match parse_number(cell, self.delimiter) {
                    Some(v) if v.is_finite() => Ok(v * factor),
                    _ => Err(Error::bad_input(
                        self.location(),
                        format!(
                            "line {}, column {name}: {cell:?} is not a finite number",
                            self.line(k)
                        ),
                    )),
                }
            })
            .collect()
    }

    /// [`Self::numbers`], each also within ±`max_abs` (SI, after `factor`): a plausibility
    /// bound that keeps absurd values (1e308 mN) from overflowing what is computed from them.
    pub(crate) fn numbers_within(&self, name: &str, factor: f64, max_abs: f64) -> Result<Vec<f64>> {
        let values = self.numbers(name, factor)?;
        if let Some(k) = values.iter().position(|v| v.abs() > max_abs) {
            return Err(Error::bad_input(
                self.location(),
                format!(
                    "line {}, column {name}: {:e} is beyond ±{:e} (a wrong unit?)",
                    self.line(k),
                    values[k] / factor,
                    max_abs / factor
                ),
            ));
        }
        Ok(values)
    }

    /// File line of data row `k` (for messages).
    pub(crate) fn line(&self, k: usize) -> u64 {
        self.lines.get(k).copied().unwrap_or(k as u64 + 2)
    }
}

/// The line (from 1) a record of `text` starts on, counted from its byte offset: the CSV
/// reader's own line count is one off after CRLF line ends (Excel's).
pub(crate) fn line_of(text: &str, record: &csv::StringRecord) -> u64 {
    let Some(position) = record.position() else {
        return 0;
    };
    let bytes = text.as_bytes();
    let mut start = usize::try_from(position.byte())
        .unwrap_or(usize::MAX)
        .min(bytes.len());
    // (The offset may point at the line end before the record.)
    while bytes.get(start).is_some_and(|b| b"\r\n".contains(b)) {
        start += 1;
    }
    1 + bytes[..start].iter().filter(|&&b| b == b'\n').count() as u64
}

fn csv_error(path: &Path, e: csv::Error) -> Error {
    match e.into_kind() {
        csv::ErrorKind::Io(source) => Error::io(path, source),
        other => Error::bad_input(
            Location::file(path),
            format!("not a readable CSV: {other:?}"),
        ),
    }
}

/// A number as the tables write it: Rust's shortest round-trip form (`4`, `0.0125`, `1e-7`), as
/// `f64::to_string`; an empty cell for `null` (an undefined number).
fn cell(value: &serde_json::Value) -> String {
    match value {
        serde_json::Value::Null => String::new(),
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.to_string(),
            (None, Some(i), _) => i.to_string(),
            (None, None, Some(f)) => f.to_string(),
            _ => n.to_string(),
        },
        other => other.to_string(),
    }
}

/// A column's own cell format.
pub type CellFormat = fn(&serde_json::Value) -> String;

/// A CSV of `rows` (anything serialised as a list of records), one line per item, whose columns are the item's serialised fields in order (the
/// same names and units as in the JSON outputs: one declaration serves both). `formats` gives a
/// column its own cell format (e.g. three significant digits for a residual). The header comes
/// from the first row; an empty table is an error.
pub fn rows_csv<T: serde::Serialize + ?Sized>(
    rows: &T,
    formats: &[(&str, CellFormat)],
) -> Result<Vec<u8>> {
    let values = match serde_json::to_value(rows) {
        Ok(serde_json::Value::Array(values)) => values,
        Ok(_) => return Err(Error::InvalidArgument("CSV: not a list of rows".into())),
        Err(e) => return Err(Error::InvalidArgument(format!("CSV: {e}"))),
    };
    let header: Vec<String> = match values.first() {
        Some(serde_json::Value::Object(first)) => first.keys().cloned().collect(),
        _ => return Err(Error::InvalidArgument("CSV: no rows to write".into())),
    };
    let mut writer = csv::Writer::from_writer(Vec::new());
    let csv_err = |e: csv::Error| Error::InvalidArgument(format!("CSV: {e}"));
    writer.write_record(&header).map_err(csv_err)?;
    for row in &values {
        let record: Vec<String> = header
            .iter()
            .map(|k| {
                let v = row.get(k).unwrap_or(&serde_json::Value::Null);
                match formats.iter().find(|(name, _)| name == k) {
                    Some((_, f)) if !v.is_null() => f(v),
                    _ => cell(v),
                }
            })
            .collect();
        writer.write_record(&record).map_err(csv_err)?;
    }
    writer
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

/// A CSV written in memory by `write` (header first), as UTF-8 text.
pub(crate) fn csv_text(
    write: impl FnOnce(&mut csv::Writer<Vec<u8>>) -> std::result::Result<(), csv::Error>,
) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    write(&mut w).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    let bytes = w
        .into_inner()
        .map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| Error::InvalidArgument(format!("CSV: {e}")))
}

/// `value ± se` as a measurement is written: the uncertainty to two significant digits and the
/// value to the same decimal place (`0.8712 ± 0.00043` → `0.87120 ± 0.00043`, `153.6 ± 12.3` →
/// `154 ± 12`, `15360 ± 1234` → `15400 ± 1200`); far from 1 (a value or uncertainty past
/// 10⁹ or below 10⁻⁸) in scientific notation (`1.500e-12 ± 3.0e-14`). An uncertainty that is
/// zero or not finite cannot set the digits: the value keeps four significant digits then; one
/// below the value's eighth significant digit neither: the value keeps eight
/// (`3.6999999999999966 ± 1.7e-16` → `3.7000000 ± 1.7e-16`).
pub fn value_pm(value: f64, se: f64) -> String {
    if !value.is_finite() {
        return format!("{value} ± {se}");
    }
    if !(se.is_finite() && se > 0.0) {
        return format!("{} ± {se}", significant(value, 4));
    }
    // The last digit of the rounded uncertainty (0.0996 rounds to 0.10: two digits, not three).
    let exponent = |v: f64| v.abs().log10().floor() as i32;
    let last = exponent(se) - 1;
    let se = round_at(se, last);
    let last = exponent(se) - 1;
    let magnitude = exponent(value.abs().max(se));
    if magnitude - last >= MAX_DIGITS {
        // An uncertainty below the value's eighth digit (an exact fit, rounding noise) does
        // not set the digits: the value to eight significant digits.
        let value = if (-8..9).contains(&magnitude) {
            significant(value, MAX_DIGITS)
        } else {
            format!("{value:.*e}", (MAX_DIGITS - 1) as usize)
        };
        return format!("{value} ± {se:.1e}");
    }
    if !(-8..9).contains(&magnitude) || !(-9..9).contains(&last) {
        let digits = (exponent(value.abs().max(se)) - last).max(1) as usize;
        return format!("{value:.digits$e} ± {se:.1e}");
    }
    let decimals = (-last).max(0) as usize;
    // `+ 0.0` turns a value rounded to −0 into 0.
    let value = round_at(value, last) + 0.0;
    format!("{value:.decimals$} ± {se:.decimals$}")
}

/// The most significant digits [`value_pm`] writes of a value.
const MAX_DIGITS: i32 = 8;

/// [`value_pm`] when there is an uncertainty, else the value alone to `decimals` places.
pub fn value_pm_or(value: f64, se: Option<f64>, decimals: usize) -> String {
    match se {
        Some(se) => value_pm(value, se),
        None => format!("{value:.decimals$}"),
    }
}

/// `v` rounded to the digit of 10^`at`.
fn round_at(v: f64, at: i32) -> f64 {
    if at >= 0 {
        let unit = 10f64.powi(at);
        (v / unit).round() * unit
    } else {
        let scale = 10f64.powi(-at);
        (v * scale).round() / scale
    }
}

/// `v` to `digits` significant digits, in plain decimals.
fn significant(v: f64, digits: i32) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let last = v.abs().log10().floor() as i32 - (digits - 1);
    format!("{:.*}", (-last).max(0) as usize, round_at(v, last) + 0.0)
}

/// A number in scientific notation with three significant digits (`1.234e-9`), for residuals.
pub fn sci3(value: &serde_json::Value) -> String {
    value
        .as_f64()
        .map_or_else(String::new, |v| format!("{v:.3e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn delimiters_are_sniffed_from_the_header() {
        assert_eq!(sniff_delimiter("file,force_mN\na.tif,4\n"), b',');
        assert_eq!(sniff_delimiter("file;force_mN\na.tif;4,5\n"), b';');
        assert_eq!(
            sniff_delimiter("\u{feff}file\tforce_mN\na.tif\t4,5\n"),
            b'\t'
        );
        assert_eq!(parse_number("4,5", b'\t'), Some(4.5));
        assert_eq!(parse_number("4,5", b','), None);
    }

    #[test]
    fn excel_line_ends_and_empty_rows_keep_line_numbers_exact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("manifest.csv");
        std::fs::write(
            &path,
            "file,force_mN\r\na.tif,4\r\n\r\nb.tif,x\r\n,\r\n,\r\n",
        )
        .unwrap();
        let table = Table::read(&path).unwrap();
        assert_eq!(table.len(), 2, "empty rows are no rows");
        let e = table.numbers("force_mN", 1e-3).unwrap_err().to_string();
        assert!(e.contains("line 4, column force_mN"), "{e}");
    }

    #[test]
    fn uncertainties_keep_two_significant_digits_and_values_their_decimal_place() {
        assert_eq!(value_pm(0.8712, 0.00043), "0.87120 ± 0.00043");
        assert_eq!(value_pm(153.6, 12.3), "154 ± 12");
        assert_eq!(value_pm(0.871, 0.004), "0.8710 ± 0.0040");
        assert_eq!(value_pm(15360.0, 1234.0), "15400 ± 1200");
        assert_eq!(value_pm(-2.3456, 0.012), "-2.346 ± 0.012");
        // 0.0996 rounds to 0.10: two digits after rounding, not three.
        assert_eq!(value_pm(0.871, 0.0996), "0.87 ± 0.10");
        assert_eq!(value_pm(3.997, 0.005), "3.9970 ± 0.0050");
        // A value that rounds to zero is not written −0.
        assert_eq!(value_pm(-0.0001, 0.012), "0.000 ± 0.012");
        // Far from 1: scientific notation.
        assert_eq!(value_pm(1.5e-12, 3e-14), "1.500e-12 ± 3.0e-14");
        assert_eq!(value_pm(2.5e10, 1.2e8), "2.500e10 ± 1.2e8");
        // No usable uncertainty: four significant digits and the uncertainty as it is.
        assert_eq!(value_pm(0.87123, 0.0), "0.8712 ± 0");
        assert_eq!(value_pm(3.6999999999999966, 1.7e-16), "3.7000000 ± 1.7e-16");
        assert_eq!(value_pm(-123.456789012, 1e-9), "-123.45679 ± 1.0e-9");
        assert_eq!(value_pm(1.5e-12, 1e-30), "1.5000000e-12 ± 1.0e-30");
        assert_eq!(value_pm(1.23456789, 1.2e-7), "1.2345679 ± 1.2e-7");
        assert_eq!(value_pm(1.23456789, 1.2e-6), "1.2345679 ± 0.0000012");
        assert_eq!(value_pm(153.64, f64::NAN), "153.6 ± NaN");
        assert_eq!(value_pm(f64::INFINITY, 1.0), "inf ± 1");
        assert_eq!(value_pm_or(0.87123, None, 3), "0.871");
        assert_eq!(value_pm_or(0.87123, Some(0.00043), 3), "0.87123 ± 0.00043");
    }
}
