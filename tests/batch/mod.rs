//! `contactscope batch`: an archive (a samplesheet or a folder walk) → the folders `analyze`
//! writes, the tables `images` and `series` (Parquet and CSV), `batch.json`, the QC page;
//! failures isolated, killed batches resumed, re-runs that redo only what changed.

mod failures;
mod faults;
mod fit;
mod outliers;
mod reruns;
mod sheet;
mod walk;

use std::path::{Path, PathBuf};
use std::process::Output;

use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;

use crate::common::{run, stderr};

/// `contactscope synth-series` into `dir/name` (a manifest folder): 192² pixels, 1–8 mN (the
/// contact stays off the image border).
pub fn synth(dir: &Path, name: &str, seed: u64, extra: &[&str]) -> PathBuf {
    let out = dir.join(name);
    let seed = seed.to_string();
    let mut args = vec![
        "synth-series",
        "--out",
        out.to_str().unwrap(),
        "--size",
        "192",
        "--forces",
        "1,2,4,8mN",
        "--seed",
        &seed,
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

/// Run `contactscope batch ARGS` in `dir` (relative paths as a user in that folder gives them).
pub fn batch(dir: &Path, args: &[&str]) -> Output {
    let mut all = vec!["batch", "--quiet"];
    all.extend_from_slice(args);
    crate::common::run_in(dir, &all)
}

/// `batch` that must succeed; its stdout.
pub fn batch_ok(dir: &Path, args: &[&str]) -> String {
    let o = batch(dir, args);
    assert!(o.status.success(), "batch {args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// (analysed, reused) from the summary line a batch prints.
pub fn counts(stdout: &str) -> (usize, usize) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("batch:"))
        .unwrap_or_else(|| panic!("no summary line: {stdout}"));
    let number_before = |word: &str| -> usize {
        let end = line
            .find(word)
            .unwrap_or_else(|| panic!("{word} in {line}"));
        line[..end]
            .trim_end()
            .rsplit(' ')
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    (number_before(" analysed"), number_before(" reused"))
}

/// A CSV as (header, rows of cells).
pub fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    crate::common::read_csv(path)
}

/// The cells of column `name`.
pub fn cells(table: &(Vec<String>, Vec<Vec<String>>), name: &str) -> Vec<String> {
    let i = table
        .0
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", table.0));
    table.1.iter().map(|r| r[i].clone()).collect()
}

/// A Parquet file as (column names, rows of fields).
pub fn parquet(path: &Path) -> (Vec<String>, Vec<Vec<Field>>) {
    let reader = SerializedFileReader::new(std::fs::File::open(path).unwrap()).unwrap();
    let names = reader
        .metadata()
        .file_metadata()
        .schema_descr()
        .columns()
        .iter()
        .map(|c| c.name().to_string())
        .collect();
    let rows = reader
        .get_row_iter(None)
        .unwrap()
        .map(|r| {
            r.unwrap()
                .get_column_iter()
                .map(|(_, f)| f.clone())
                .collect()
        })
        .collect();
    (names, rows)
}

/// A Parquet field as the CSV writes it (nulls empty, floats in their shortest form).
pub fn field_text(field: &Field) -> String {
    match field {
        Field::Null => String::new(),
        Field::Bool(b) => b.to_string(),
        Field::Long(v) => v.to_string(),
        Field::Double(v) => format!("{v}"),
        Field::Str(s) => s.clone(),
        other => panic!("unexpected Parquet field {other:?}"),
    }
}

/// Every file under `dir` (relative path → bytes), for comparing folders.
pub fn files(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let rel = path.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    out
}
