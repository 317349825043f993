//! Failures stay with their series: a missing input and a corrupt TIFF get their rows and
//! one-line errors while the other series complete, the exit status is 3, and nothing stale of
//! an earlier success stays beside a failed row. A batch killed with SIGKILL (or interrupted
//! with SIGINT) in the middle of a series keeps every series it finished, and the next run
//! does only the rest, to the same tables as an uninterrupted run.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::{batch, batch_ok, cells, counts, csv, synth};
use crate::common::stderr;

#[test]
fn a_failed_series_has_its_row_and_the_others_complete() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    synth(dir, "good", 1, &[]);
    let broken = synth(dir, "broken", 2, &[]);
    std::fs::write(
        dir.join("sheet.csv"),
        "id,input\ngood,good\nmissing,nowhere\nbroken,broken\n",
    )
    .unwrap();
    // First all good (the broken one still whole), then its TIFF cut short.
    std::fs::write(dir.join("ok.csv"), "id,input\ngood,good\nbroken,broken\n").unwrap();
    batch_ok(dir, &["--samplesheet", "ok.csv", "--out", "results"]);
    assert!(dir.join("results/series/broken/areas.csv").is_file());
    let tif = broken.join("series.tif");
    let bytes = std::fs::read(&tif).unwrap();
    std::fs::write(&tif, &bytes[..bytes.len() / 3]).unwrap();

    let o = batch(dir, &["--samplesheet", "sheet.csv", "--out", "results"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("1 ok, 2 failed"), "{stdout}");
    let series = csv(&dir.join("results/series.csv"));
    assert_eq!(cells(&series, "status"), ["ok", "failed", "failed"]);
    let errors = cells(&series, "error");
    assert!(errors[1].contains("nowhere"), "{errors:?}");
    assert!(errors[2].contains("series.tif"), "{errors:?}");
    assert!(errors.iter().all(|e| !e.contains('\n')));
    // Both fail when their files are opened, before any image is analysed.
    assert_eq!(cells(&series, "failed_stage")[1..], ["inputs", "inputs"]);
    assert!(cells(&series, "flags")[2].starts_with("failed"));
    // The good series is complete; the broken one's earlier folder and thumbnail are gone.
    assert!(dir.join("results/series/good/summary.json").is_file());
    assert!(!dir.join("results/series/broken").exists());
    assert!(!dir.join("results/qc/broken.png").exists());
    let images = csv(&dir.join("results/images.csv"));
    assert_eq!(images.1.len(), 4, "only the good series' images");
    // Unchanged, the failures stay failures without being tried again; --rerun failed tries.
    let o = batch(dir, &["--samplesheet", "sheet.csv", "--out", "results"]);
    assert_eq!(o.status.code(), Some(3));
    assert_eq!(counts(&String::from_utf8_lossy(&o.stdout)), (0, 3));
    let o = batch(
        dir,
        &[
            "--samplesheet",
            "sheet.csv",
            "--out",
            "results",
            "--rerun",
            "failed",
        ],
    );
    assert_eq!(counts(&String::from_utf8_lossy(&o.stdout)), (2, 1));
    // Repaired, the series is analysed again (its file changed).
    std::fs::write(&tif, &bytes).unwrap();
    let o = batch(dir, &["--samplesheet", "sheet.csv", "--out", "results"]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(counts(&stdout), (1, 2), "{stdout}");
    assert!(stdout.contains("2 ok, 1 failed"), "{stdout}");
}

/// Start a batch over `sheet` whose third series reads from a FIFO (it blocks there until the
/// test writes), wait until the four others are recorded (series run side by side), then send
/// `signal`.
fn interrupted(dir: &Path, signal: &str) -> (Option<i32>, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .current_dir(dir)
        .args([
            "batch",
            "--samplesheet",
            "sheet.csv",
            "--out",
            "results",
            "--quiet",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary starts");
    let records = dir.join("results/records");
    let start = Instant::now();
    let others = ["s1", "s2", "s4", "s5"];
    while !others
        .iter()
        .all(|s| records.join(format!("{s}.json")).is_file())
    {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no record written"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    // The third series is blocked on its FIFO (the process is in its staging).
    std::thread::sleep(Duration::from_millis(100));
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success());
    let out = child.wait_with_output().expect("the child ends");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[cfg(unix)]
#[test]
fn a_killed_batch_keeps_what_it_finished_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let mut sheet = String::from("id,input,forces\n");
    for i in 1..=5 {
        synth(dir, &format!("s{i}"), i, &[]);
        sheet.push_str(&format!("s{i},s{i}/series.tif,\"1,2,4,8mN\"\n"));
    }
    std::fs::write(dir.join("sheet.csv"), &sheet).unwrap();
    // The whole batch in one go, for comparison.
    let clean = batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "clean"]);
    assert_eq!(counts(&clean), (5, 0));

    let real = dir.join("s3/series.tif");
    let saved = dir.join("s3.tif");
    std::fs::rename(&real, &saved).unwrap();
    for (signal, code) in [("-KILL", None), ("-INT", Some(130))] {
        let _ = std::fs::remove_dir_all(dir.join("results"));
        let _ = std::fs::remove_file(&real);
        let fifo = Command::new("mkfifo").arg(&real).status().expect("mkfifo");
        assert!(fifo.success());
        let (status, err) = interrupted(dir, signal);
        assert_eq!(status, code, "{signal}: {err}");
        // Interrupted, the batch releases its lock (killed, the next run takes it over).
        if signal == "-INT" {
            assert!(
                !dir.join("results/.contactscope-batch.lock").exists(),
                "{err}"
            );
            assert!(err.contains("released the batch's lock"), "{err}");
        }
        std::fs::remove_file(&real).unwrap();
        std::fs::copy(&saved, &real).unwrap();
        let results = dir.join("results");
        let done: Vec<String> = std::fs::read_dir(results.join("records"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| !n.starts_with('.'))
            .collect();
        assert_eq!(done.len(), 4, "{signal}: {done:?}");
        // Resume: the four finished series are reused, the one cut off analysed.
        let resumed = batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "results"]);
        assert_eq!(counts(&resumed), (1, 4), "{signal}: {resumed}");
        for name in [
            "images.csv",
            "series.csv",
            "images.parquet",
            "series.parquet",
        ] {
            assert_eq!(
                std::fs::read(results.join(name)).unwrap(),
                std::fs::read(dir.join("clean").join(name)).unwrap(),
                "{signal}: {name}"
            );
        }
        let leftovers: Vec<String> = super::files(&results)
            .into_keys()
            .filter(|k| k.contains(".staging-") || k.contains(".tmp-") || k.ends_with(".lock"))
            .collect();
        assert!(leftovers.is_empty(), "{signal}: {leftovers:?}");
    }
}
