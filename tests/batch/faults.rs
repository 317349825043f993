//! The batch under faults: batches started side by side with delays injected at every step of
//! taking the output folder (`CONTACTSCOPE_TEST_PAUSE`, the batch's test hook), kills between a
//! series' folder and its record, folders that another run replaced, and the same archive read
//! from another working directory or moved. After each, one plain run gives the tables of a
//! clean run, and no `ok` row is without its folder.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use super::{batch_ok, cells, counts, csv, synth};

const TABLES: [&str; 4] = [
    "images.csv",
    "series.csv",
    "images.parquet",
    "series.parquet",
];

/// `contactscope batch --quiet ARGS` started in `dir` with the test hook's pauses.
fn start(dir: &Path, args: &[&str], pauses: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_contactscope"))
        .current_dir(dir)
        .arg("batch")
        .arg("--quiet")
        .args(args)
        .env("CONTACTSCOPE_TEST_PAUSE", pauses)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary starts")
}

/// Exit code and stderr of a child.
fn finish(child: Child) -> (Option<i32>, String) {
    let out = child.wait_with_output().expect("the child ends");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Three series of 192² images and a samplesheet naming them.
fn archive(dir: &Path) {
    let mut sheet = String::from("id,input,sample\n");
    for i in 1..=3 {
        synth(dir, &format!("s{i}"), i, &[]);
        sheet.push_str(&format!("s{i},s{i},glass\n"));
    }
    std::fs::write(dir.join("sheet.csv"), sheet).unwrap();
}

/// Every table of `results` equals the clean run's, and every `ok` row has its folder.
fn same_as_clean(dir: &Path, results: &str, what: &str) {
    for name in TABLES {
        assert_eq!(
            std::fs::read(dir.join(results).join(name)).unwrap(),
            std::fs::read(dir.join("clean").join(name)).unwrap(),
            "{what}: {name}"
        );
    }
    let series = csv(&dir.join(results).join("series.csv"));
    for (id, status) in cells(&series, "series_id")
        .iter()
        .zip(cells(&series, "status"))
    {
        if status == "ok" {
            let summary = dir
                .join(results)
                .join("series")
                .join(id)
                .join("summary.json");
            assert!(summary.is_file(), "{what}: {id} is ok without its folder");
        }
    }
}

const ARGS: [&str; 4] = ["--samplesheet", "sheet.csv", "--out", "results"];

#[cfg(unix)]
#[test]
fn batches_side_by_side_never_remove_each_others_folder() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    archive(dir);
    assert_eq!(
        counts(&batch_ok(
            dir,
            &["--samplesheet", "sheet.csv", "--out", "clean"]
        )),
        (3, 0)
    );
    // The second batch looks at the folder (not there yet), then waits at the named step while
    // the first takes it and runs; its refusal must not remove what the first made. The first
    // is slowed after its first series so that it is still running then.
    for late_step in ["folder-checked", "folder-made"] {
        let _ = std::fs::remove_dir_all(dir.join("results"));
        let late = start(dir, &ARGS, &format!("{late_step}=1500"));
        std::thread::sleep(Duration::from_millis(300));
        let first = start(dir, &ARGS, "series-committed=2500");
        let (code, err) = finish(late);
        assert_eq!(code, Some(1), "{late_step}: {err}");
        assert!(err.contains("is in use by"), "{late_step}: {err}");
        let (code, err) = finish(first);
        assert_eq!(code, Some(0), "{late_step}: {err}");
        same_as_clean(dir, "results", late_step);
        assert!(dir.join("results/.contactscope-batch.json").is_file());
        assert!(!dir.join("results/.contactscope-batch.lock").exists());
    }
    // Three at once, each delayed at every step by a different amount, twice over: whichever
    // win run, the others are refused (or run after); one plain run then gives the clean tables.
    let steps = [
        "folder-checked",
        "folder-made",
        "folder-locked",
        "record-removed",
    ];
    for round in 0..2u64 {
        let _ = std::fs::remove_dir_all(dir.join("results"));
        let children: Vec<Child> = (0..3u64)
            .map(|k| {
                let pauses: Vec<String> = steps
                    .iter()
                    .enumerate()
                    .map(|(i, s)| format!("{s}={}", (k * 7 + i as u64 * 13 + round * 29) % 40 * 10))
                    .collect();
                start(dir, &ARGS, &pauses.join(","))
            })
            .collect();
        let ends: Vec<(Option<i32>, String)> = children.into_iter().map(finish).collect();
        for (code, err) in &ends {
            assert!(
                *code == Some(0) || (*code == Some(1) && err.contains("is in use by")),
                "round {round}: {code:?} {err}"
            );
        }
        assert!(
            ends.iter().any(|(c, _)| *c == Some(0)),
            "round {round}: {ends:?}"
        );
        same_as_clean(dir, "results", &format!("round {round}"));
        assert_eq!(counts(&batch_ok(dir, &ARGS)), (0, 3), "round {round}");
        same_as_clean(dir, "results", &format!("round {round}, re-run"));
    }
}

/// The `threshold` of `results/series/ID/summary.json`.
fn folder_threshold(dir: &Path, id: &str) -> Value {
    let path = dir.join("results/series").join(id).join("summary.json");
    let summary: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    summary["threshold"].clone()
}

/// Each series' decision reason in `results/batch.json`.
fn reasons(dir: &Path) -> Vec<String> {
    let record: Value =
        serde_json::from_slice(&std::fs::read(dir.join("results/batch.json")).unwrap()).unwrap();
    record["series"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["reason"].as_str().unwrap_or_default().to_string())
        .collect()
}

#[cfg(unix)]
#[test]
fn a_folder_is_never_trusted_under_a_record_that_does_not_describe_it() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    archive(dir);
    batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "clean"]);
    batch_ok(dir, &ARGS);
    let global: Vec<Value> = (1..=3)
        .map(|i| folder_threshold(dir, &format!("s{i}")))
        .collect();
    // A run with other options, killed once a new series folder is in place and before its
    // record is written.
    let mut child = start(
        dir,
        &[&ARGS[..], &["--threshold", "per-image"]].concat(),
        "series-committed=20000",
    );
    let start_time = Instant::now();
    let changed = |dir: &Path| {
        (1..=3).any(|i| {
            let id = format!("s{i}");
            std::fs::read(dir.join("results/series").join(&id).join("summary.json"))
                .is_ok_and(|_| folder_threshold(dir, &id) != global[i - 1])
        })
    };
    while !changed(dir) {
        assert!(
            start_time.elapsed() < Duration::from_secs(60),
            "no folder replaced"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // The plain run redoes the series whose folder changed; the tables and folders agree.
    let resumed = batch_ok(dir, &ARGS);
    assert!(counts(&resumed).0 >= 1, "{resumed}");
    same_as_clean(dir, "results", "after the kill");
    for i in 1..=3 {
        assert_eq!(
            folder_threshold(dir, &format!("s{i}")),
            global[i - 1],
            "s{i}"
        );
    }
    // A folder replaced by another run (here `analyze` with other options) no longer matches
    // its record: the batch makes it again.
    let o = crate::common::run_in(
        dir,
        &[
            "analyze",
            "s2",
            "--out",
            "results/series/s2",
            "--threshold",
            "per-image",
            "--quiet",
        ],
    );
    assert!(o.status.success(), "{}", crate::common::stderr(&o));
    assert_eq!(counts(&batch_ok(dir, &ARGS)), (1, 2));
    let why = reasons(dir);
    assert!(
        why[1].contains("series/s2 does not match its record"),
        "{why:?}"
    );
    assert_eq!(folder_threshold(dir, "s2"), global[1]);
    same_as_clean(dir, "results", "after another run's folder");
}

#[test]
fn the_same_archive_from_another_folder_or_moved_is_reused() {
    let top = tempfile::tempdir().unwrap();
    let dir = top.path().join("lab");
    std::fs::create_dir_all(&dir).unwrap();
    archive(&dir);
    assert_eq!(counts(&batch_ok(&dir, &ARGS)), (3, 0));
    // From the folder above, with absolute paths.
    let sheet = dir.join("sheet.csv").display().to_string();
    let results = dir.join("results").display().to_string();
    let from_above = ["--samplesheet", &sheet, "--out", &results];
    assert_eq!(counts(&batch_ok(top.path(), &from_above)), (0, 3));
    // The whole archive moved (inputs and results together).
    let moved = top.path().join("moved");
    std::fs::rename(&dir, &moved).unwrap();
    assert_eq!(counts(&batch_ok(&moved, &ARGS)), (0, 3));
    // The records now name the new place: reused again without a look at the old one.
    let record: Value =
        serde_json::from_slice(&std::fs::read(moved.join("results/records/s1.json")).unwrap())
            .unwrap();
    let file = record["files"][0]["canonical"].as_str().unwrap();
    assert!(file.contains("/moved/"), "{file}");
    assert_eq!(counts(&batch_ok(&moved, &ARGS)), (0, 3));
}
