//! What a release needs, held by tests: one version everywhere (every crate of the workspace, the
//! two Python distributions, the citation file, the changelog and `contactscope --version`), the
//! licence files, and the metadata a registry asks of each library crate. The built wheels
//! themselves are checked by `scripts/test-install` (no Rust on PATH) and the licences of what
//! they ship by `scripts/licence-audit`.

use serde_json::Value;

use crate::common::{root, run};

const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The workspace's packages (`cargo metadata --no-deps`).
fn packages() -> Vec<Value> {
    crate::common::workspace_packages()
}

fn read(path: &str) -> String {
    std::fs::read_to_string(root().join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

#[test]
fn every_crate_has_the_one_version() {
    let packages = packages();
    assert_eq!(packages.len(), 5, "the workspace's five crates");
    for p in &packages {
        assert_eq!(p["version"], VERSION, "{}", p["name"]);
    }
}

#[test]
fn python_distributions_take_the_workspace_version() {
    // maturin fills `dynamic = ["version"]` from the crate; a literal version here would drift.
    for path in ["python/pyproject.toml", "pyproject.toml"] {
        let text = read(path);
        assert!(
            text.lines().any(|l| l.trim() == r#"dynamic = ["version"]"#),
            "{path}: the version must come from Cargo.toml"
        );
        assert!(
            !text
                .lines()
                .any(|l| l.trim_start().starts_with("version =")),
            "{path} states a version of its own"
        );
    }
}

#[test]
fn citation_changelog_and_version_flag_agree() {
    let cff = read("CITATION.cff");
    assert!(
        cff.lines().any(|l| l == format!("version: {VERSION}")),
        "CITATION.cff's version is not {VERSION}"
    );
    assert!(
        cff.contains("doi: \"10.1038/s41467-018-02981-y\""),
        "the paper's DOI"
    );
    let changelog = read("CHANGELOG.md");
    assert!(
        changelog.contains(&format!("\n## [{VERSION}] — ")),
        "CHANGELOG.md has no section for {VERSION}"
    );
    let out = run(&["--version"]);
    assert!(out.status.success());
    let line = String::from_utf8_lossy(&out.stdout).trim().to_string();
    if !root().join(".git").exists() {
        // Built from an sdist or a packaged crate: the version alone.
        assert_eq!(line, format!("contactscope {VERSION}"));
        return;
    }
    // Built from this checkout: the commit follows the version.
    let expected = format!("contactscope {VERSION} (source ");
    assert!(
        line.starts_with(&expected),
        "{line:?} does not start with {expected:?}"
    );
    let commit = line[expected.len()..]
        .split([' ', ')'])
        .next()
        .unwrap_or_default();
    assert_eq!(commit.len(), 40, "{line:?}: no 40-digit commit");
    assert!(commit.bytes().all(|b| b.is_ascii_hexdigit()), "{line:?}");
}

#[test]
fn library_crates_carry_what_a_registry_needs() {
    for p in packages() {
        let name = p["name"].as_str().unwrap_or_default();
        for field in ["description", "license", "repository"] {
            assert!(p[field].is_string(), "{name}: no {field}");
        }
        assert_eq!(p["license"], "MIT OR Apache-2.0", "{name}");
        if !name.starts_with("contactscope") || name == "contactscope-python" {
            continue;
        }
        let dir = std::path::Path::new(p["manifest_path"].as_str().unwrap_or_default())
            .parent()
            .expect("a crate's folder")
            .to_path_buf();
        for file in ["LICENSE-MIT", "LICENSE-APACHE", "README.md"] {
            let text = std::fs::read_to_string(dir.join(file))
                .unwrap_or_else(|e| panic!("{name}: {file}: {e}"));
            assert!(text.len() > 200, "{name}: {file} is almost empty");
        }
    }
    let apache = read("LICENSE-APACHE");
    assert!(apache.contains("Apache License") && apache.contains("Version 2.0, January 2004"));
    assert!(read("LICENSE-MIT").contains("Permission is hereby granted, free of charge"));
}

/// The path an `include_str!`/`include_bytes!` in `file` names, lexically (symbolic links are not
/// followed: a link inside the crate becomes a copy when the crate is packaged).
fn included_paths(
    crate_dir: &std::path::Path,
    file: &std::path::Path,
    text: &str,
) -> Vec<std::path::PathBuf> {
    let mut found = Vec::new();
    for (i, _) in text.match_indices("include_") {
        let rest = &text[i..];
        let Some(open) = rest.find('(') else { continue };
        if !(rest.starts_with("include_str!") || rest.starts_with("include_bytes!")) {
            continue;
        }
        let args = &rest[open + 1..rest[open..].find(';').map_or(rest.len(), |e| open + e)];
        let literal = |s: &str| s.split('"').nth(1).map(str::to_string);
        let path = if args.contains("CARGO_MANIFEST_DIR") {
            // concat!(env!("CARGO_MANIFEST_DIR"), "/assets/…")
            let after = &args[args.find("CARGO_MANIFEST_DIR").unwrap_or(0) + 19..];
            literal(after).map(|p| crate_dir.join(p.trim_start_matches('/')))
        } else {
            literal(args).map(|p| file.parent().unwrap_or(crate_dir).join(p))
        };
        found.extend(path);
    }
    found
}

#[test]
fn library_crates_include_only_their_own_files() {
    // `cargo package` and maturin's sdists hold a crate's own folder: a file included from
    // outside it (as `docs/methods.md` once was) breaks every build from a package.
    let mut outside = Vec::new();
    let mut checked = 0;
    for name in ["formats", "algorithms", "jobs"] {
        let crate_dir = root().join("crates").join(name);
        let mut stack = vec![crate_dir.join("src")];
        while let Some(dir) = stack.pop() {
            for entry in std::fs::read_dir(&dir).expect("a source folder") {
                let path = entry.expect("an entry").path();
                if path.is_dir() {
                    stack.push(path);
                    continue;
                }
                if path.extension().is_none_or(|e| e != "rs") {
                    continue;
                }
                let text = std::fs::read_to_string(&path).expect("a source file");
                for included in included_paths(&crate_dir, &path, &text) {
                    checked += 1;
                    let mut normal = std::path::PathBuf::new();
                    for part in included.components() {
                        match part {
                            std::path::Component::ParentDir => {
                                normal.pop();
                            }
                            std::path::Component::CurDir => {}
                            other => normal.push(other),
                        }
                    }
                    if !normal.starts_with(&crate_dir) || !normal.exists() {
                        outside.push(format!("{}: {}", path.display(), included.display()));
                    }
                }
            }
        }
    }
    assert!(
        checked >= 3,
        "only {checked} includes found: the scan is broken"
    );
    assert!(
        outside.is_empty(),
        "included from outside the crate: {outside:#?}"
    );
}

/// The wheel file names the docs give are the names `scripts/build-wheels` writes (maturin's
/// `--compatibility manylinux2014` gives both tags), so that a copied `pip install` line works.
#[test]
fn documented_wheel_names_are_the_built_ones() {
    let version = packages()[0]["version"].as_str().unwrap().to_string();
    let lib =
        format!("contactscope-{version}-cp39-abi3-manylinux2014_x86_64.manylinux_2_17_x86_64.whl");
    let cli = format!(
        "contactscope_cli-{version}-py3-none-manylinux2014_x86_64.manylinux_2_17_x86_64.whl"
    );
    for doc in ["README.md", "python/README.md", "docs/napari.md"] {
        let text = read(doc);
        for name in text
            .split(|c: char| c.is_whitespace() || c == '"' || c == '[' || c == '/' || c == '`')
            .filter(|w| w.ends_with(".whl") && w.starts_with("contactscope") && !w.contains('…'))
        {
            assert!(
                name == lib || name == cli,
                "{doc}: {name} is not a wheel build-wheels writes"
            );
        }
    }
}
