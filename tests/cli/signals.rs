//! SIGINT and SIGTERM in the middle of a long `simulate`: exit 130 / 143, a message saying what was
//! discarded, and nothing left behind (no staging folder, no output folder). Unix only.
#![cfg(unix)]

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::rough_surface;

/// Start a `simulate` of many loads, wait until its staging folder holds a file (it is inside
/// the load ramp), send `signal`, and return (exit code, stderr).
fn interrupt(dir: &Path, surface: &Path, signal: &str) -> (Option<i32>, String) {
    let out = dir.join("sim");
    let child = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .args([
            "simulate",
            "--topography",
            surface.to_str().unwrap(),
            "--pixel-size",
            "128nm",
            "--radius",
            "290um",
            "--modulus",
            "3.7GPa",
            "--model",
            "hardening",
            "--hardening",
            "4MPa/nm",
            "--forces",
            "4mN..400mN:200",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary starts");
    let staging = dir.join(format!(".sim.staging-{}", child.id()));
    let start = Instant::now();
    while !staging.join("load_001_contact.tif").exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the first load was never written"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
    let output = child.wait_with_output().expect("the child ends");
    assert!(!staging.exists(), "{signal}: staging folder left behind");
    assert!(!out.exists(), "{signal}: partial output folder");
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

#[test]
fn interrupted_simulations_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let surface = dir.path().join("surface.npy");
    rough_surface(&surface, 256, "128nm", 3, &[]);
    for (signal, code, name) in [("-INT", 130, "SIGINT"), ("-TERM", 143, "SIGTERM")] {
        let (status, err) = interrupt(dir.path(), &surface, signal);
        assert_eq!(status, Some(code), "{name}: {err}");
        assert!(
            err.contains(&format!("interrupted by {name}")) && err.contains("discarded"),
            "{name}: {err}"
        );
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, vec![std::ffi::OsString::from("surface.npy")]);
}
