//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod czi;
pub mod lif;
pub mod nulls;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The project's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The bundled synthetic load series.
pub fn fixture_series() -> PathBuf {
    root().join("fixtures/synthetic-series")
}

/// `../shared/data/<sub>` if present; otherwise prints why the test is skipped.
pub fn shared_data(sub: &str) -> Option<PathBuf> {
    let path = root().join("../shared/data").join(sub);
    if path.exists() {
        Some(path)
    } else {
        eprintln!(
            "SKIPPED: {} not found (the shared test data sits beside the checkout)",
            path.display()
        );
        None
    }
}

/// Name parameters in messages as the command line does (`--channel`), for tests that call the
/// library directly and check a message the command line prints.
pub fn cli_names() {
    contactscope_formats::param::set_front_end(contactscope_formats::param::FrontEnd::CommandLine);
}

/// Run the contactscope binary.
pub fn run(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .args(args)
        .output()
        .expect("binary runs");
    if out.status.success() {
        nulls::check_run(Path::new("."), args, &out.stdout);
    }
    out
}

/// Run the binary and insist on success (stderr in the failure message).
pub fn run_ok(args: &[&str]) -> Output {
    let out = run(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    out
}

/// Run the binary and insist that it wrote its outputs: success, or exit status 4 (outputs
/// written, but no load valid: every contact touches the border or there is none), for tests of
/// other things on inputs that are not contact experiments.
pub fn run_written(args: &[&str]) -> Output {
    let out = run(args);
    assert!(
        out.status.success() || out.status.code() == Some(4),
        "{args:?}: {}",
        stderr(&out)
    );
    out
}

/// `contactscope surface`: a self-affine map (H = 0.8, h'_rms = 0.1) of `size`² pixels of `pixel`
/// written to `path`, with further options in `extra` (roll-off, cutoff).
pub fn rough_surface(path: &Path, size: usize, pixel: &str, seed: u64, extra: &[&str]) {
    let (size, seed) = (size.to_string(), seed.to_string());
    let mut args = vec![
        "surface",
        "--size",
        &size,
        "--pixel-size",
        pixel,
        "--hurst",
        "0.8",
        "--rms-slope",
        "0.1",
        "--seed",
        &seed,
        "--out",
        path.to_str().expect("UTF-8 path"),
    ];
    args.extend_from_slice(extra);
    run_ok(&args);
}

/// Run in a directory.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("binary runs");
    if out.status.success() {
        nulls::check_run(dir, args, &out.stdout);
    }
    out
}

/// Standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Standard output as text.
pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Parse a CSV file into a header and rows.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut reader = csv::Reader::from_path(path).expect("CSV opens");
    let header = reader
        .headers()
        .expect("header")
        .iter()
        .map(String::from)
        .collect();
    let rows = reader
        .records()
        .map(|r| r.expect("row").iter().map(String::from).collect())
        .collect();
    (header, rows)
}

/// Column of a CSV as numbers.
pub fn column(header: &[String], rows: &[Vec<String>], name: &str) -> Vec<f64> {
    let i = header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("column {name} in {header:?}"));
    rows.iter().map(|r| r[i].parse().expect("number")).collect()
}

/// The planes `(series, index)` of `file` as one multi-page u16 TIFF at `out`, with the given
/// pixel size.
pub fn export_tiff(
    file: &Path,
    planes: &[(usize, contactscope_formats::microscopy::PlaneIndex)],
    px: Option<(f64, f64)>,
    out: &Path,
) {
    let mut f = contactscope_formats::microscopy::MicroscopyFile::open(file).unwrap();
    let mut pages = Vec::new();
    let (mut w, mut h) = (0, 0);
    for (series, index) in planes {
        let plane = f.read_plane(*series, index).unwrap();
        (w, h) = (plane.width, plane.height);
        pages.push(
            plane
                .to_f64()
                .iter()
                .map(|&v| u16::try_from(v as i64).expect("u16 sample"))
                .collect::<Vec<u16>>(),
        );
    }
    let refs: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
    std::fs::write(
        out,
        contactscope_formats::tiff::encode_u16_stack(&refs, w, h, px, "").unwrap(),
    )
    .unwrap();
}

/// `cargo metadata --no-deps --offline`: the workspace's packages.
pub fn workspace_packages() -> Vec<serde_json::Value> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(root())
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    meta["packages"].as_array().expect("packages").clone()
}
