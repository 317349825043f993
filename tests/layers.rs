//! The workspace's layering (`docs/architecture.md`), held by cargo itself: a crate can only use
//! the crates it depends on, and cargo refuses dependency cycles. This test pins the allowed
//! dependencies of each layer, so that a new edge upwards (the formats using the algorithms, the
//! algorithms using the jobs) fails here, and checks what the manifests cannot: the algorithms
//! open no file, plotting and command-line crates stay out of the libraries and the wheel, and
//! no source file grows past the project's size limit.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common::root;

/// Each workspace package's dependencies on other workspace packages, and all its dependency
/// names with their `optional` flag and whether default features are on.
fn workspace() -> BTreeMap<String, Vec<(String, bool, bool)>> {
    crate::common::workspace_packages()
        .iter()
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .expect("dependencies")
                .iter()
                .filter(|d| d["kind"].is_null())
                .map(|d| {
                    (
                        d["name"].as_str().unwrap_or_default().to_string(),
                        d["optional"].as_bool().unwrap_or(false),
                        d["uses_default_features"].as_bool().unwrap_or(true),
                    )
                })
                .collect();
            (p["name"].as_str().unwrap_or_default().to_string(), deps)
        })
        .collect()
}

fn ours(deps: &[(String, bool, bool)]) -> Vec<&str> {
    let mut v: Vec<&str> = deps
        .iter()
        .map(|(n, _, _)| n.as_str())
        .filter(|n| *n == "contactscope" || n.starts_with("contactscope-"))
        .collect();
    v.sort_unstable();
    v
}

#[test]
fn each_layer_depends_only_on_the_layers_below_it() {
    let ws = workspace();
    let expect: [(&str, &[&str]); 5] = [
        ("contactscope-formats", &[]),
        ("contactscope", &["contactscope-formats"]),
        (
            "contactscope-jobs",
            &["contactscope", "contactscope-formats"],
        ),
        (
            "contactscope-cli",
            &["contactscope", "contactscope-formats", "contactscope-jobs"],
        ),
        (
            "contactscope-python",
            &["contactscope", "contactscope-formats", "contactscope-jobs"],
        ),
    ];
    assert_eq!(ws.len(), expect.len(), "packages: {:?}", ws.keys());
    for (name, allowed) in expect {
        let deps = ws.get(name).unwrap_or_else(|| panic!("no package {name}"));
        assert_eq!(ours(deps), allowed, "{name} depends on");
    }
}

#[test]
fn front_end_crates_stay_out_of_the_libraries_and_the_wheel() {
    let ws = workspace();
    for name in ["contactscope-formats", "contactscope", "contactscope-jobs"] {
        for (dep, _, _) in &ws[name] {
            assert!(
                !matches!(
                    dep.as_str(),
                    "clap" | "indicatif" | "anyhow" | "pyo3" | "signal-hook"
                ),
                "{name} depends on {dep}"
            );
        }
    }
    for name in ["contactscope-formats", "contactscope"] {
        assert!(
            ws[name].iter().all(|(d, _, _)| d != "plotters"),
            "{name} draws plots"
        );
    }
    let python = &ws["contactscope-python"];
    let jobs = python
        .iter()
        .find(|(d, _, _)| d == "contactscope-jobs")
        .expect("python uses the jobs");
    assert!(
        !jobs.2,
        "the wheel takes contactscope-jobs without default features (no plots)"
    );
    for (dep, _, _) in python {
        assert!(
            !matches!(dep.as_str(), "clap" | "indicatif" | "plotters"),
            "the wheel depends on {dep}"
        );
    }
}

/// Every `.rs` file under `dir`, recursively.
fn sources(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable").flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn the_algorithms_open_no_file() {
    let mut files = Vec::new();
    sources(&root().join("crates/algorithms/src"), &mut files);
    assert!(files.len() > 50, "found {} files", files.len());
    for file in files {
        let text = std::fs::read_to_string(&file).expect("readable");
        // Test modules may write scratch files; the library code may not.
        let library = text.split("#[cfg(test)]").next().unwrap_or_default();
        for needle in [
            "std::fs",
            "File::open",
            "File::create",
            "read_to_string(",
            "contactscope_formats::tiff",
            "contactscope_formats::microscopy",
            "read_height_map",
        ] {
            assert!(
                !library.contains(needle),
                "{} uses {needle}: the algorithms take data in memory",
                file.display()
            );
        }
    }
}

#[test]
fn no_source_file_is_over_800_lines() {
    let mut files = Vec::new();
    for dir in ["crates", "python/src", "tests", "benches"] {
        sources(&root().join(dir), &mut files);
    }
    let long: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).ok()?.lines().count();
            (n > 800).then(|| format!("{} ({n} lines)", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "split by concept: {long:?}");
}
