//! SIGINT and SIGTERM in the middle of a long `simulate`: exit 130 / 143, a message saying what was
//! discarded, and nothing left behind (no staging folder, no output folder, no folder above it
//! that the run created). Unix only.
#![cfg(unix)]

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::rough_surface;

/// Wait (at most a minute) until `path` exists, then send `signal` to `child`.
fn signal_once_written(child: &std::process::Child, path: &Path, signal: &str) {
    let start = Instant::now();
    while !path.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "{} never appeared",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
}

/// Start a `simulate` of many loads into `dir/out`, wait until its staging folder holds a file
/// (it is inside the load ramp), send `signal`, and return (exit code, stderr).
fn interrupt(dir: &Path, out: &str, surface: &Path, signal: &str) -> (Option<i32>, String) {
    let out = dir.join(out);
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
    let staging = out
        .parent()
        .expect("a parent")
        .join(format!(".sim.staging-{}", child.id()));
    signal_once_written(&child, &staging.join("load_001_contact.tif"), signal);
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
    // The second run's `--out` names two folders that do not exist yet: it creates them, and
    // must remove them again (as `demo` once left an empty `contactscope-out/`).
    for (signal, code, name, out) in [
        ("-INT", 130, "SIGINT", "sim"),
        ("-TERM", 143, "SIGTERM", "new/deeper/sim"),
    ] {
        let (status, err) = interrupt(dir.path(), out, &surface, signal);
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

#[test]
fn an_interrupted_demo_leaves_no_folder_it_created() {
    // `demo` writes into ./contactscope-out/demo by default: interrupted, it must not leave an
    // empty contactscope-out/ behind.
    let dir = tempfile::tempdir().unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .args(["demo", "--small", "--quiet"])
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary starts");
    let work = dir
        .path()
        .join("contactscope-out")
        .join(format!(".demo.demo-{}", child.id()));
    signal_once_written(&child, &work.join("data"), "-INT");
    let output = child.wait_with_output().expect("the child ends");
    let err = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(130), "{err}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "left behind: {left:?}; {err}");
}
