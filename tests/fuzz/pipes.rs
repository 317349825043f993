//! Every command with its standard output closed before it starts (a reader that is gone: `| true`,
//! `| head` after its lines): the run ends as `cat` does — killed by SIGPIPE, no message, no
//! panic — and leaves no staging folder; an output folder is complete or absent. Each fuzz
//! template is run once, unmutated and without `-q` (so that it prints), plus `info --stats` and
//! `--help`. Unix only.
#![cfg(unix)]

use std::fs;
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Stdio};

use super::{cases, copy_tree, seeds};

/// Run `args` in `dir` with stdout a pipe whose reading end is already closed; (status, stderr).
fn with_closed_stdout(dir: &Path, args: &[String]) -> (std::process::ExitStatus, String) {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "1")
        .stdin(Stdio::null())
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .expect("the binary runs");
    (
        out.status,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Names under `dir` (recursively) of staging or set-aside folders.
fn leftovers(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    for entry in fs::read_dir(dir).into_iter().flatten().flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.contains(".staging-") || name.contains(".replaced-") {
            found.push(entry.path().display().to_string());
        } else if entry.path().is_dir() {
            found.extend(leftovers(&entry.path()));
        }
    }
    found
}

#[test]
fn every_command_ends_quietly_when_its_output_is_closed() {
    let base = tempfile::tempdir().unwrap();
    let seeds_dir = base.path().join("seeds");
    fs::create_dir_all(&seeds_dir).unwrap();
    seeds::build(&seeds_dir);
    let mut runs: Vec<(String, Vec<&str>, Vec<String>)> = cases::TEMPLATES
        .iter()
        .map(|t| {
            let args = t
                .args
                .iter()
                .filter(|a| !matches!(**a, "-q" | "--quiet"))
                .map(|a| a.to_string())
                .collect();
            (t.name.to_string(), t.copies.to_vec(), args)
        })
        .collect();
    runs.push((
        "info-stats".into(),
        vec!["series"],
        vec!["info".into(), "series/series.tif".into(), "--stats".into()],
    ));
    runs.push((
        "help".into(),
        vec![],
        vec!["analyze".into(), "--help".into()],
    ));

    let mut failures = Vec::new();
    let mut ended_by_sigpipe = 0;
    for (i, (name, copies, args)) in runs.iter().enumerate() {
        let dir = base.path().join(format!("run-{i}"));
        fs::create_dir_all(&dir).unwrap();
        for c in copies {
            copy_tree(&seeds_dir.join(c), &dir.join(c));
        }
        let (status, stderr) = with_closed_stdout(&dir, args);
        let line = format!("{name}: contactscope {}", args.join(" "));
        // Some templates are refused before anything is printed (the fuzzer's templates are
        // not all valid): an ordinary error exit (1, 2; 3 for a batch) is fine there.
        if status.signal() == Some(13) {
            ended_by_sigpipe += 1;
        } else if !matches!(status.code(), Some(0..=3)) {
            failures.push(format!("{line}: {status:?}, stderr: {stderr}"));
        }
        if stderr.contains("panicked") || stderr.contains("Broken pipe") {
            failures.push(format!("{line}: stderr {stderr:?}"));
        }
        let left = leftovers(&dir);
        if !left.is_empty() {
            failures.push(format!("{line}: left {left:?}"));
        }
        // An output folder, if there is one, is whole: its completion marker is present (a
        // batch's folder: its provenance record, written last).
        if let Some(out) = args.iter().find(|a| a.starts_with("OUT")) {
            let out = dir.join(out);
            let whole = [contactscope_jobs::staging::MARKER, "batch.json"]
                .iter()
                .any(|m| out.join(m).exists());
            if out.is_dir() && !whole {
                failures.push(format!("{line}: {} is incomplete", out.display()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Most commands print something once they succeed: they must have met the closed pipe.
    assert!(
        ended_by_sigpipe >= runs.len() * 2 / 3,
        "only {ended_by_sigpipe} of {} runs met the closed pipe",
        runs.len()
    );
}
