//! The samplesheet: one row per load series, as CellProfiler's LoadData and nf-core's
//! samplesheets have it. Columns:
//!
//! * `id` (required): the series' name, which names its output folders: letters, digits, `.`,
//!   `_` and `-`, unique (also ignoring case);
//! * `input` (required): a TIFF, CZI, ND2 or LIF file, a folder of TIFFs, a manifest CSV or a
//!   folder holding `manifest.csv`, relative to the samplesheet's folder;
//! * the per-series options ([`Opt`]): `analyze`'s (`forces`, `channel`, `load_axis`,
//!   `pixel_size`, `threshold`, …) and `fit-hardening`'s (`topography`, `modulus`, …), with a
//!   unit in the column name allowed (`pixel_size_nm`); an empty cell takes the batch's default;
//! * every other column is metadata (sample, lubricant, date, operator, …), carried into every
//!   output table: a column whose every value is a plain decimal number is a number column,
//!   any other a text column.
//!
//! The whole sheet is checked before anything runs (nf-core's rule): a bad cell is an error
//! naming the file, line and column. A metadata column named like an option (`pixelsize`,
//! `load_axes`) is refused with the option it resembles, since its values would otherwise be
//! silently ignored.

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};

use contactscope_formats::inputs::note_input;

use super::options::{resolve, Opt, SeriesOptions};
use crate::error::{Error, Location, Result};

/// The kind of a metadata column's values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum MetaKind {
    /// Every non-empty value is a plain decimal number (typed as a float in the tables).
    Number,
    /// Anything else (typed as text).
    Text,
}

/// A metadata column.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct MetaColumn {
    /// As written in the header.
    pub name: String,
    /// Its values' kind.
    pub kind: MetaKind,
}

/// One row: a load series.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Line of the samplesheet (the header is line 1); 0 for a row of a folder walk.
    pub line: usize,
    /// The series id.
    pub id: String,
    /// The input as written.
    pub input_text: String,
    /// The input resolved against the samplesheet's folder.
    pub input: PathBuf,
    /// The options its cells give (empty cells left out).
    pub options: SeriesOptions,
    /// Its metadata values, one per metadata column (empty string: no value).
    pub metadata: Vec<String>,
}

/// A samplesheet, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct Sheet {
    /// The file (or what to call a samplesheet given as text).
    pub label: PathBuf,
    /// The folder relative inputs are resolved against.
    pub base: PathBuf,
    /// The metadata columns, in header order.
    pub metadata: Vec<MetaColumn>,
    /// The option columns present, in header order (for writing the sheet back).
    pub option_columns: Vec<(Opt, String)>,
    /// The rows, in file order.
    pub rows: Vec<Row>,
    /// SHA-256 of the samplesheet's bytes.
    pub sha256: String,
    /// What a folder walk found and did not take as a series, each "PATH: why" (empty for a
    /// samplesheet read from a file).
    pub skipped: Vec<String>,
}

/// Names the batch's tables use for their own columns: a metadata column may not take one.
pub const RESERVED_COLUMNS: &[&str] = &[
    "series_id",
    "status",
    "error",
    "input",
    "image",
    "image_index",
    "page",
    "flags",
    "warnings",
    "folder",
];

impl Sheet {
    /// Read and check a samplesheet file.
    pub fn read(path: &Path) -> Result<Sheet> {
        note_input(path);
        let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Sheet::parse(&bytes, path, &base)
    }

    /// Check a samplesheet's text; `label` names it in messages, `base` resolves its inputs.
    pub fn parse(bytes: &[u8], label: &Path, base: &Path) -> Result<Sheet> {
        let at = || Location::file(label);
        if let Some(kind) = spreadsheet_kind(bytes) {
            return Err(Error::bad_input(
                at(),
                format!(
                    "{kind}, not CSV text: save the sheet as CSV (Excel: File → Save As →                      \"CSV UTF-8\"; LibreOffice: File → Save As → \"Text CSV\") and give that file"
                ),
            ));
        }
        let text = std::str::from_utf8(bytes).map_err(|_| {
            Error::bad_input(at(), "not UTF-8 text (save the samplesheet as CSV UTF-8)")
        })?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let delimiter = crate::table::sniff_delimiter(text);
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| Error::bad_input(at(), format!("not a readable CSV: {e}")))?
            .iter()
            .map(String::from)
            .collect();
        let columns = classify(&header).map_err(|m| Error::bad_input(at(), m))?;
        let mut rows = Vec::new();
        let mut ids: HashSet<String> = HashSet::new();
        for record in reader.records() {
            let record =
                record.map_err(|e| Error::bad_input(at(), format!("not a readable CSV: {e}")))?;
            let line = crate::table::line_of(text, &record) as usize;
            // A row with no value at all (a spreadsheet's trailing `,,,,`) is no row.
            if record.iter().all(str::is_empty) {
                continue;
            }
            let cell = |i: usize| record.get(i).unwrap_or("").to_string();
            let bad = |column: &str, m: String| {
                Error::bad_input(at(), format!("line {line}, column {column}: {m}"))
            };
            let id = cell(columns.id);
            check_id(&id).map_err(|m| bad("id", m))?;
            if !ids.insert(id.to_ascii_lowercase()) {
                return Err(bad("id", format!("'{id}' is used by an earlier row (ids name folders, so they must differ also ignoring case)")));
            }
            let input_text = cell(columns.input);
            if input_text.is_empty() {
                return Err(bad(
                    "input",
                    "empty: give a file, a folder or a manifest".into(),
                ));
            }
            // The batch's records stat and hash local files to tell what changed.
            if contactscope_formats::remote::is_url(Path::new(&input_text)) {
                return Err(bad(
                    "input",
                    format!(
                        "'{input_text}' is a URL: the batch reads local files (its records \
                         hash them to redo only what changed); analyze a URL with \
                         `contactscope analyze`, or copy the objects to a folder"
                    ),
                ));
            }
            let mut options = SeriesOptions::default();
            for (i, opt, unit) in &columns.options {
                let value = cell(*i);
                if value.is_empty() {
                    continue;
                }
                // In a `;`- or tab-separated sheet a single number may have a decimal comma.
                let value = match delimiter != b',' && opt.single_number() {
                    true => decimal_point(&value),
                    false => value,
                };
                let value = Opt::with_unit(&value, unit.as_deref());
                opt.parse(&value).map_err(|m| bad(&header[*i], m))?;
                options.0.insert(*opt, value);
            }
            options.check().map_err(|(opt, m)| {
                let name = columns
                    .options
                    .iter()
                    .find(|(_, o, _)| *o == opt)
                    .map_or(opt.column(), |(i, _, _)| header[*i].as_str());
                bad(name, m)
            })?;
            rows.push(Row {
                line,
                id,
                input: resolve(base, &input_text),
                input_text,
                options,
                metadata: columns.metadata.iter().map(|&i| cell(i)).collect(),
            });
        }
        if rows.is_empty() {
            return Err(Error::bad_input(
                at(),
                "no rows: one row per load series (id, input, …)",
            ));
        }
        let metadata = columns
            .metadata
            .iter()
            .enumerate()
            .map(|(k, &i)| MetaColumn {
                name: header[i].clone(),
                kind: kind_of(rows.iter().map(|r| r.metadata[k].as_str())),
            })
            .collect();
        Ok(Sheet {
            label: label.to_path_buf(),
            base: base.to_path_buf(),
            metadata,
            option_columns: columns
                .options
                .iter()
                .map(|(i, o, _)| (*o, header[*i].clone()))
                .collect(),
            rows,
            sha256: crate::provenance::sha256_bytes(bytes),
            skipped: Vec::new(),
        })
    }

    /// The samplesheet as CSV: `id`, `input`, the options of every row (defaults filled in, so
    /// that the file alone repeats the run) and the metadata columns.
    pub fn to_csv(&self, options: &[SeriesOptions], inputs: &[String]) -> Result<Vec<u8>> {
        let used: Vec<Opt> = Opt::ALL
            .iter()
            .copied()
            .filter(|o| options.iter().any(|s| s.get(*o).is_some()))
            .collect();
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header = vec!["id".to_string(), "input".to_string()];
        header.extend(used.iter().map(|o| o.column().to_string()));
        header.extend(self.metadata.iter().map(|m| m.name.clone()));
        w.write_record(&header).map_err(csv_err)?;
        for ((row, opts), input) in self.rows.iter().zip(options).zip(inputs) {
            let mut record = vec![row.id.clone(), input.clone()];
            record.extend(used.iter().map(|o| opts.get(*o).unwrap_or("").to_string()));
            record.extend(row.metadata.iter().cloned());
            w.write_record(&record).map_err(csv_err)?;
        }
        w.into_inner()
            .map_err(|e| Error::InvalidArgument(format!("samplesheet: {e}")))
    }
}

/// What kind of spreadsheet file `bytes` is, when it is one rather than text: a ZIP (`.xlsx`,
/// `.ods`) or an OLE compound file (`.xls`).
fn spreadsheet_kind(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"PK\x03\x04") {
        let head = &bytes[..bytes.len().min(4096)];
        let has = |needle: &[u8]| head.windows(needle.len()).any(|w| w == needle);
        return Some(if has(b"opendocument") {
            "an OpenDocument spreadsheet (.ods)"
        } else {
            "an Excel workbook (.xlsx, a ZIP file)"
        });
    }
    bytes
        .starts_with(&[0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1])
        .then_some("an old Excel workbook (.xls)")
}

/// `0,2um` → `0.2um`: one comma between digits and no point is a decimal comma.
fn decimal_point(cell: &str) -> String {
    let b = cell.as_bytes();
    let commas: Vec<usize> = (0..b.len()).filter(|&i| b[i] == b',').collect();
    match commas[..] {
        [i] if !cell.contains('.')
            && i > 0
            && b[i - 1].is_ascii_digit()
            && b.get(i + 1).is_some_and(u8::is_ascii_digit) =>
        {
            cell.replacen(',', ".", 1)
        }
        _ => cell.to_string(),
    }
}

fn csv_err(e: csv::Error) -> Error {
    Error::InvalidArgument(format!("samplesheet: {e}"))
}

/// Where each kind of column is.
struct Columns {
    id: usize,
    input: usize,
    options: Vec<(usize, Opt, Option<String>)>,
    metadata: Vec<usize>,
}

fn classify(header: &[String]) -> std::result::Result<Columns, String> {
    let position = |name: &str| header.iter().position(|h| h.eq_ignore_ascii_case(name));
    let (Some(id), Some(input)) = (position("id"), position("input")) else {
        return Err(format!(
            "the header needs the columns id and input (found: {})",
            header.join(", ")
        ));
    };
    let mut seen: BTreeMap<String, &str> = BTreeMap::new();
    let mut options = Vec::new();
    let mut metadata = Vec::new();
    for (i, name) in header.iter().enumerate() {
        if name.is_empty() {
            return Err(format!("column {} has no name", i + 1));
        }
        let key = match Opt::of_column(name) {
            Some((opt, _)) => opt.column().to_string(),
            None => name.to_ascii_lowercase(),
        };
        if let Some(earlier) = seen.insert(key, name) {
            return Err(format!(
                "columns '{earlier}' and '{name}' say the same thing; keep one"
            ));
        }
        if i == id || i == input {
            continue;
        }
        match Opt::of_column(name) {
            Some((opt, unit)) => options.push((i, opt, unit)),
            None => {
                check_metadata_name(name)?;
                metadata.push(i);
            }
        }
    }
    Ok(Columns {
        id,
        input,
        options,
        metadata,
    })
}

/// A metadata column may not take a table's own column name, nor look like a misspelt option.
fn check_metadata_name(name: &str) -> std::result::Result<(), String> {
    let lower = name.to_ascii_lowercase();
    if RESERVED_COLUMNS.contains(&lower.as_str()) || lower == "id" {
        return Err(format!(
            "column '{name}': the output tables use this name themselves; rename the column"
        ));
    }
    let squash = |s: &str| -> String {
        s.chars()
            .filter(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase()
    };
    let squashed = squash(name);
    for opt in Opt::ALL {
        let option = squash(opt.column());
        let close = squashed == option
            || (option.len() >= 5
                && squashed.len() >= 5
                && strsim::damerau_levenshtein(&squashed, &option) <= 2);
        if close {
            return Err(format!(
                "column '{name}' looks like the option '{}' but is not spelt as one; rename it \
                 to '{}' (or, if it is metadata, to a name that is not so close)",
                opt.column(),
                opt.column()
            ));
        }
    }
    Ok(())
}

fn check_id(id: &str) -> std::result::Result<(), String> {
    if id.is_empty() {
        return Err("empty: every series needs an id".into());
    }
    if id.len() > 100 {
        return Err(format!("'{id}' is longer than 100 characters"));
    }
    if id.starts_with(['.', '-']) {
        return Err(format!("'{id}' may not start with '.' or '-'"));
    }
    if let Some(c) = id
        .chars()
        .find(|c| !(c.is_ascii_alphanumeric() || "._-".contains(*c)))
    {
        return Err(format!(
            "'{id}' holds {c:?}; ids name folders: use letters, digits, '.', '_' and '-'"
        ));
    }
    Ok(())
}

/// Number when every non-empty value is a plain decimal number (no leading zero before a digit,
/// so that codes such as `007` stay text), text otherwise.
fn kind_of<'a>(values: impl Iterator<Item = &'a str>) -> MetaKind {
    let plain = |v: &str| {
        let digits = v.trim_start_matches(['-', '+']);
        let leading_zero =
            digits.starts_with('0') && digits[1..].starts_with(|c: char| c.is_ascii_digit());
        !leading_zero
            && v.chars().all(|c| c.is_ascii_digit() || ".-+eE".contains(c))
            && v.parse::<f64>().is_ok_and(f64::is_finite)
    };
    let mut any = false;
    for v in values.filter(|v| !v.is_empty()) {
        if !plain(v) {
            return MetaKind::Text;
        }
        any = true;
    }
    if any {
        MetaKind::Number
    } else {
        MetaKind::Text
    }
}

/// A series id made from a path's text: characters ids do not allow become `_`.
pub fn id_from(text: &str) -> String {
    let id: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    id.trim_start_matches(['.', '-'])
        .chars()
        .take(100)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Sheet> {
        Sheet::parse(
            text.as_bytes(),
            Path::new("sheet.csv"),
            Path::new("archive"),
        )
    }

    #[test]
    fn options_metadata_and_units_are_told_apart() {
        let sheet = parse(
            "id,input,pixel_size_nm,Forces,sample,radius_um,date,load\n\
             s1,a/s1,200,\"4,10,40mN\",glass,290,2026-11-01,1.5\n\
             s2,/abs/s2.czi,,,steel,,2026-11-02,2\n",
        )
        .unwrap();
        assert_eq!(sheet.rows.len(), 2);
        let s1 = &sheet.rows[0];
        assert_eq!(s1.input, Path::new("archive/a/s1"));
        assert_eq!(sheet.rows[1].input, Path::new("/abs/s2.czi"));
        assert_eq!(s1.options.get(Opt::PixelSize), Some("200nm"));
        assert_eq!(s1.options.get(Opt::Forces), Some("4,10,40mN"));
        assert_eq!(s1.options.get(Opt::Radius), Some("290um"));
        assert!(sheet.rows[1].options.0.is_empty());
        let names: Vec<(&str, MetaKind)> = sheet
            .metadata
            .iter()
            .map(|m| (m.name.as_str(), m.kind))
            .collect();
        assert_eq!(
            names,
            [
                ("sample", MetaKind::Text),
                ("date", MetaKind::Text),
                ("load", MetaKind::Number)
            ]
        );
        assert_eq!(s1.metadata, ["glass", "2026-11-01", "1.5"]);
        assert_eq!(s1.line, 2);
    }

    #[test]
    fn semicolons_bom_and_comments_are_read() {
        let sheet = parse("\u{feff}# an archive\nid;input;code\ns1;a;007\ns2;b;12\n").unwrap();
        assert_eq!(sheet.rows[1].id, "s2");
        assert_eq!(sheet.metadata[0].kind, MetaKind::Text, "007 stays text");
    }

    #[test]
    fn every_problem_names_line_and_column() {
        let err = |text: &str| parse(text).unwrap_err().to_string();
        assert!(err("id,file\ns1,a\n").contains("needs the columns id and input"));
        let e = err("id,input,pixel_size\ns1,a,200nm\ns2,b,200\n");
        assert!(
            e.contains("sheet.csv: line 3, column pixel_size") && e.contains("no unit"),
            "{e}"
        );
        let e = err("id,input\ns1,s3://lab/a.tif\n");
        assert!(
            e.contains("line 2, column input") && e.contains("is a URL"),
            "{e}"
        );
        let e = err("id,input\ns1,a\nS1,b\n");
        assert!(
            e.contains("line 3, column id") && e.contains("earlier row"),
            "{e}"
        );
        let e = err("id,input\na/b,a\n");
        assert!(e.contains("ids name folders"), "{e}");
        let e = err("id,input,pixelsize\ns1,a,200nm\n");
        assert!(e.contains("looks like the option 'pixel_size'"), "{e}");
        let e = err("id,input,load_axes\ns1,a,t\n");
        assert!(e.contains("'load_axis'"), "{e}");
        let e = err("id,input,status\ns1,a,x\n");
        assert!(e.contains("tables use this name"), "{e}");
        let e = err("id,input,pixel_size,pixel-size\ns1,a,1um,1um\n");
        assert!(e.contains("say the same thing"), "{e}");
        let e = err("id,input,models\ns1,a,hardening\n");
        assert!(e.contains("without a height map"), "{e}");
        assert!(err("id,input\n").contains("no rows"));
        let e = err("id,input\ns1,a,extra\n");
        assert!(e.contains("not a readable CSV"), "{e}");
        assert!(err("id,input\ns1,\n").contains("column input: empty"));
    }

    #[test]
    fn sheets_as_excel_and_libreoffice_write_them() {
        // CRLF line ends: line numbers stay exact.
        let e = parse("id,input,pixel_size\r\ns1,a,200nm\r\ns2,b,200\r\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 3, column pixel_size"), "{e}");
        let e = parse("\u{feff}# notes\r\nid,input\r\n\r\ns1,a\r\n,\r\ns 2,b\r\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 6, column id"), "{e}");
        // Empty trailing rows (and empty rows between) are no rows.
        let sheet = parse("id,input,sample,pixel_size_nm\r\ns1,a,x,200\r\n,,,\r\n,,,\r\n").unwrap();
        assert_eq!(sheet.rows.len(), 1);
        // Semicolons with decimal commas; a list keeps its commas.
        let sheet =
            parse("id;input;pixel_size_um;radius;forces\ns1;a;0,2;290,5um;4,10,40mN\n").unwrap();
        let o = &sheet.rows[0].options;
        assert_eq!(o.get(Opt::PixelSize), Some("0.2um"));
        assert_eq!(o.get(Opt::Radius), Some("290.5um"));
        assert_eq!(o.get(Opt::Forces), Some("4,10,40mN"));
        // A workbook is refused naming CSV export.
        let e = Sheet::parse(
            b"PK\x03\x04\x14\x00[Content_Types].xml xl/workbook.xml",
            Path::new("sheet.xlsx"),
            Path::new("."),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("sheet.xlsx: an Excel workbook") && e.contains("CSV UTF-8"),
            "{e}"
        );
    }

    #[test]
    fn the_sheet_is_written_back_with_its_options_and_metadata() {
        let sheet = parse("id,input,sample\ns1,a,glass\n").unwrap();
        let options = vec![SeriesOptions([(Opt::LoadAxis, "t".to_string())].into())];
        let csv = sheet.to_csv(&options, &["../a".to_string()]).unwrap();
        assert_eq!(
            String::from_utf8(csv).unwrap(),
            "id,input,load_axis,sample\ns1,../a,t,glass\n"
        );
        assert_eq!(id_from("sample A/run 1"), "sample_A_run_1");
    }
}
