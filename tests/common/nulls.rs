//! Every `null` a JSON output can hold is documented in `docs/outputs.md`: after each successful
//! run of the binary in these tests, the JSON files of its `--out` folder (and the `--json`
//! output on stdout) are walked, and each `null` must appear in that page's table as the file
//! and its JSON pointer (array indices written `*`).

use std::collections::BTreeSet;
use std::path::Path;
use std::sync::OnceLock;

use serde_json::Value;

/// (file, pointer) pairs of the table in `docs/outputs.md`.
fn documented() -> &'static BTreeSet<(String, String)> {
    static DOC: OnceLock<BTreeSet<(String, String)>> = OnceLock::new();
    DOC.get_or_init(|| {
        let text = std::fs::read_to_string(super::root().join("docs/outputs.md"))
            .expect("docs/outputs.md");
        text.lines()
            .filter(|l| l.starts_with("| `"))
            .filter_map(|l| {
                let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                let ticked = |c: &str| c.split('`').nth(1).map(String::from);
                Some((ticked(cells.get(1)?)?, ticked(cells.get(2)?)?))
            })
            .collect()
    })
}

fn nulls(value: &Value, pointer: String, found: &mut Vec<String>) {
    match value {
        Value::Null => found.push(pointer),
        Value::Array(items) => items
            .iter()
            .for_each(|v| nulls(v, format!("{pointer}/*"), found)),
        Value::Object(map) => map
            .iter()
            .for_each(|(k, v)| nulls(v, format!("{pointer}/{k}"), found)),
        _ => {}
    }
}

/// The undocumented nulls of one JSON text written as `file`.
pub fn undocumented(file: &str, text: &str) -> Vec<String> {
    let Ok(value) = serde_json::from_str::<Value>(text) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    nulls(&value, String::new(), &mut found);
    found.sort();
    found.dedup();
    found
        .into_iter()
        .filter(|p| !documented().contains(&(file.to_string(), p.clone())))
        .map(|p| format!("{file} {p}"))
        .collect()
}

/// Check the outputs of a successful run of `args` in `dir`.
pub fn check_run(dir: &Path, args: &[&str], stdout: &[u8]) {
    let mut missing = Vec::new();
    let command = args.first().copied().unwrap_or_default();
    if args.contains(&"--json") {
        missing.extend(undocumented(
            &format!("{command} --json"),
            &String::from_utf8_lossy(stdout),
        ));
    }
    if let Some(k) = args.iter().position(|a| *a == "--out") {
        let out = dir.join(args.get(k + 1).copied().unwrap_or_default());
        for entry in std::fs::read_dir(&out).into_iter().flatten().flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.ends_with(".json") && !name.starts_with('.') {
                let text = std::fs::read_to_string(entry.path()).unwrap_or_default();
                missing.extend(undocumented(&name, &text));
            }
        }
    }
    if missing.is_empty() {
        return;
    }
    if let Ok(report) = std::env::var("NULLS_REPORT") {
        use std::io::Write;
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(report)
            .unwrap();
        for m in &missing {
            let _ = writeln!(f, "{command}\t{m}");
        }
        return;
    }
    panic!(
        "`contactscope {}` wrote nulls that docs/outputs.md does not explain: {missing:?}",
        args.join(" ")
    );
}
