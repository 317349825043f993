//! The batch's folder: taken for a run (new, empty or an earlier batch's; not in use by another
//! batch: a lock naming host and process), cleaned of what a killed run left half-done, and the
//! folder walk's samplesheet written into it (never over one edited by hand).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use contactscope_formats::param::Param;

use super::{walk, SeriesOptions, SeriesTask, Sheet, MARKER};
use crate::error::{Error, Location, Result};
use crate::provenance::{self, Machine};
use crate::staging::CreatedFolders;

const LOCK: &str = ".contactscope-batch.lock";

/// A batch's folder taken for one run: its lock file, removed when dropped. A folder this run
/// made is removed again (only what the run itself put there, only while empty) unless the run
/// [keeps](Lock::keep) it: a refused or failed batch leaves nothing, and never removes what
/// another batch made.
#[derive(Debug)]
pub(super) struct Lock {
    file: PathBuf,
    out: PathBuf,
    made: Option<CreatedFolders>,
    _held: Held,
}

impl Lock {
    /// The run goes on: the folder stays, whatever happens later.
    pub(super) fn keep(&mut self) {
        if let Some(made) = self.made.take() {
            made.keep();
        }
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        if self.made.is_some() {
            // Made by this run and not kept: only this run's own (empty) layout goes.
            let _ = std::fs::remove_file(self.out.join(MARKER));
            for dir in SUBFOLDERS {
                let _ = std::fs::remove_dir(self.out.join(dir));
            }
        }
        let _ = std::fs::remove_file(&self.file);
        // `made`, dropped after this, removes the folder and the parents it made when empty.
    }
}

/// The batch's own subfolders.
const SUBFOLDERS: [&str; 4] = ["series", "fit", "qc", "records"];

/// The lock files of the batches this process holds, for [`release_locks`].
static LOCKS: std::sync::Mutex<BTreeSet<PathBuf>> = std::sync::Mutex::new(BTreeSet::new());

/// Remove the lock files of every batch this process holds (the command line's SIGINT and
/// SIGTERM handler calls it before the process exits; the locks' owners never run again).
pub fn release_locks() -> Vec<PathBuf> {
    let locks = std::mem::take(&mut *LOCKS.lock().unwrap_or_else(|e| e.into_inner()));
    locks
        .into_iter()
        .filter(|f| std::fs::remove_file(f).is_ok())
        .collect()
}

/// The folders this process's batches hold (a Python session may plan two).
static HELD: std::sync::Mutex<BTreeSet<PathBuf>> = std::sync::Mutex::new(BTreeSet::new());

/// A folder held by a batch of this process, released when dropped.
#[derive(Debug)]
struct Held(PathBuf, Option<PathBuf>);

impl Held {
    fn take(folder: PathBuf) -> Option<Held> {
        let taken = HELD
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(folder.clone());
        // Made only when taken (and after the set's lock is released: its drop takes it).
        taken.then(|| Held(folder, None))
    }

    /// Its lock file is made: the signal handler removes it.
    fn locked(&mut self, file: &Path) {
        let file = self.0.join(file.file_name().unwrap_or_default());
        LOCKS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(file.clone());
        self.1 = Some(file);
    }
}

impl Drop for Held {
    fn drop(&mut self) {
        if let Some(file) = &self.1 {
            LOCKS.lock().unwrap_or_else(|e| e.into_inner()).remove(file);
        }
        HELD.lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&self.0);
    }
}

/// Make or take the batch's folder: new, empty, or an earlier batch's (its [`MARKER`]), and not
/// in use by a running batch (its lock, made atomically, names a live process of this host,
/// another host, or a batch of this process). Refused, it removes only folders this call made,
/// and only while they are empty: a batch that lost the race for a folder never touches the
/// winner's files.
pub(super) fn take_folder(out: &Path) -> Result<Lock> {
    let refuse = |reason: String| Error::Output {
        path: out.to_path_buf(),
        reason: format!(
            "{reason}; nothing was written (choose another {})",
            Param::Out
        ),
    };
    match std::fs::symlink_metadata(out) {
        Ok(m) if !m.is_dir() => return Err(refuse("is in the way (not a folder)".into())),
        Ok(_) => {
            let empty = std::fs::read_dir(out)
                .map_err(|e| Error::io(out, e))?
                .next()
                .is_none();
            // A batch that has just made the folder has its lock there before its marker.
            if !empty && !out.join(MARKER).is_file() && !out.join(LOCK).is_file() {
                return Err(refuse(format!(
                    "is not empty and is not a batch's folder (no {MARKER})"
                )));
            }
        }
        Err(_) => {}
    }
    super::faults::pause("folder-checked");
    let made = CreatedFolders::create(out)?;
    super::faults::pause("folder-made");
    let folder = out.canonicalize().map_err(|e| Error::io(out, e))?;
    let mut held = Held::take(folder)
        .ok_or_else(|| refuse("is in use by another batch of this process".into()))?;
    let file = out.join(LOCK);
    let host = Machine::this().hostname;
    let me = json!({ "host": host, "pid": std::process::id() });
    let output_error = |e: std::io::Error| Error::Output {
        path: file.clone(),
        reason: e.to_string(),
    };
    for attempt in 0..2 {
        let created = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&file);
        match created {
            Ok(mut f) => {
                use std::io::Write as _;
                held.locked(&file);
                let lock = Lock {
                    file: file.clone(),
                    out: out.to_path_buf(),
                    // Only a folder this call made is undone: an earlier batch's keeps its
                    // marker and layout whatever happens.
                    made: made.created_any().then_some(made),
                    _held: held,
                };
                f.write_all(me.to_string().as_bytes())
                    .map_err(output_error)?;
                super::faults::pause("folder-locked");
                for dir in SUBFOLDERS {
                    let d = out.join(dir);
                    std::fs::create_dir_all(&d).map_err(|e| Error::Output {
                        path: d.clone(),
                        reason: e.to_string(),
                    })?;
                }
                let marker =
                    json!({ "written_by": format!("contactscope {}", provenance::version()) });
                crate::staging::write_atomic(&out.join(MARKER), marker.to_string().as_bytes())?;
                clean_unfinished(out);
                return Ok(lock);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempt == 0 => {
                let holder: Value = std::fs::read(&file)
                    .ok()
                    .and_then(|t| serde_json::from_slice(&t).ok())
                    .unwrap_or(Value::Null);
                let (their_host, pid) = (
                    holder["host"].as_str().unwrap_or(""),
                    holder["pid"].as_u64().unwrap_or(0),
                );
                let ours = their_host == host;
                // A lock being written (no holder readable yet, and new) is another batch's.
                let being_written = holder.is_null()
                    && std::fs::metadata(&file)
                        .and_then(|m| m.modified())
                        .ok()
                        .and_then(|t| t.elapsed().ok())
                        .is_none_or(|age| age.as_secs() < 60);
                if (ours && pid != u64::from(std::process::id()) && alive(pid))
                    || (!ours && !their_host.is_empty())
                    || being_written
                {
                    let who = match being_written {
                        true => "another batch (its lock is being written)".to_string(),
                        false => format!("a batch on host {their_host} (process {pid})"),
                    };
                    return Err(refuse(format!(
                        "is in use by {who}; wait for it, or remove {} if that batch is gone",
                        file.display()
                    )));
                }
                // Left by a batch that is gone: taken over.
                let _ = std::fs::remove_file(&file);
            }
            Err(e) => return Err(output_error(e)),
        }
    }
    Err(refuse("its lock could not be taken".into()))
}

/// Whether process `pid` of this host is alive (Linux: its `/proc` entry; elsewhere assumed).
fn alive(pid: u64) -> bool {
    if cfg!(target_os = "linux") {
        Path::new(&format!("/proc/{pid}")).exists()
    } else {
        true
    }
}

/// Remove what a killed run left unfinished: staging folders of series and fits, temporary
/// files of records and thumbnails (the folder is locked: no other run writes them).
fn clean_unfinished(out: &Path) {
    for dir in ["series", "fit", "qc", "records", ""] {
        let Ok(entries) = std::fs::read_dir(out.join(dir)) else {
            continue;
        };
        for entry in entries.filter_map(|e| e.ok()) {
            let name = entry.file_name().to_string_lossy().into_owned();
            let unfinished = name.starts_with('.')
                && (name.contains(".staging-")
                    || name.contains(".tmp-")
                    || name.contains(".replaced-"));
            if unfinished {
                let path = entry.path();
                let _ = if path.is_dir() {
                    std::fs::remove_dir_all(&path)
                } else {
                    std::fs::remove_file(&path)
                };
            }
        }
    }
}

/// The walk's samplesheet (`samplesheet.csv`, inputs relative to the batch's folder) and its
/// SHA-256; refused when the one in the folder was edited by hand since the last walk.
pub(super) fn walk_sheet(
    out: &Path,
    sheet: &Sheet,
    tasks: &[SeriesTask],
) -> Result<(Vec<u8>, String)> {
    let path = out.join("samplesheet.csv");
    let inputs: Vec<String> = sheet
        .rows
        .iter()
        .map(|r| walk::relative_to(&r.input, out))
        .collect();
    let options: Vec<SeriesOptions> = tasks.iter().map(|t| t.options.clone()).collect();
    let bytes = sheet.to_csv(&options, &inputs)?;
    let sha = provenance::sha256_bytes(&bytes);
    if let Ok(existing) = std::fs::read(&path) {
        let last = std::fs::read(out.join("batch.json"))
            .ok()
            .and_then(|b| serde_json::from_slice::<Value>(&b).ok())
            .and_then(|v| {
                v["samplesheet"]["written_sha256"]
                    .as_str()
                    .map(String::from)
            });
        let existing_sha = provenance::sha256_bytes(&existing);
        if existing_sha != sha && last.as_deref() != Some(existing_sha.as_str()) {
            return Err(Error::Output {
                path,
                reason: "was edited since the last walk; run the batch on it with \
                         --samplesheet, or move it away to walk again"
                    .into(),
            });
        }
    }
    Ok((bytes, sha))
}

/// Refuse a series whose input lies in the batch's own series or fit folders (a run would
/// replace it).
pub(super) fn check_inputs_outside(out: &Path, tasks: &[SeriesTask]) -> Result<()> {
    let Ok(out) = out.canonicalize() else {
        return Ok(());
    };
    for task in tasks {
        if let Ok(input) = task.input.canonicalize() {
            if input.starts_with(out.join("series")) || input.starts_with(out.join("fit")) {
                return Err(Error::bad_input(
                    Location::file(&task.input),
                    format!(
                        "series {}: an input inside the batch's own output folders",
                        task.id
                    ),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_folder_is_taken_by_one_batch_at_a_time() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new/results");
        // Made and given up (a run that stops before it starts): nothing is left.
        drop(take_folder(&out).unwrap());
        assert!(
            !dir.path().join("new").exists(),
            "a folder made and not kept goes"
        );
        let mut first = take_folder(&out).unwrap();
        assert!(out.join(LOCK).is_file() && out.join(MARKER).is_file());
        first.keep();
        drop(first);
        // An earlier batch's folder taken and given up: its marker and layout stay.
        drop(take_folder(&out).unwrap());
        assert!(out.join(MARKER).is_file() && out.join("records").is_dir());
        let mut first = take_folder(&out).unwrap();
        let err = take_folder(&out).unwrap_err().to_string();
        assert!(err.contains("another batch of this process"), "{err}");
        assert!(
            out.join(LOCK).is_file(),
            "the refused run leaves the folder alone"
        );
        first.keep();
        drop(first);
        assert!(out.join(MARKER).is_file(), "kept");
        assert!(!out.join(LOCK).exists(), "released");
        let host = Machine::this().hostname;
        // A live process of this host (init) holds it: refused, its lock left alone.
        let live = json!({ "host": host, "pid": 1 }).to_string();
        std::fs::write(out.join(LOCK), &live).unwrap();
        let err = take_folder(&out).unwrap_err().to_string();
        assert!(err.contains("(process 1)"), "{err}");
        assert_eq!(std::fs::read_to_string(out.join(LOCK)).unwrap(), live);
        // A process that is gone (no pid is that large): taken over, with its leftovers.
        let gone = json!({ "host": host, "pid": u64::from(u32::MAX) + 7 }).to_string();
        std::fs::write(out.join(LOCK), gone).unwrap();
        std::fs::create_dir_all(out.join("series/.s1.staging-99")).unwrap();
        std::fs::write(out.join("records/.s2.json.tmp-99"), "").unwrap();
        let taken = take_folder(&out).unwrap();
        assert!(!out.join("series/.s1.staging-99").exists());
        assert!(!out.join("records/.s2.json.tmp-99").exists());
        drop(taken);
        // Another host's batch: refused.
        std::fs::write(
            out.join(LOCK),
            json!({ "host": "elsewhere", "pid": 5 }).to_string(),
        )
        .unwrap();
        assert!(take_folder(&out)
            .unwrap_err()
            .to_string()
            .contains("host elsewhere"));
        // A folder of one's own files is never taken.
        let mine = dir.path().join("mine");
        std::fs::create_dir_all(&mine).unwrap();
        std::fs::write(mine.join("notes.txt"), "x").unwrap();
        assert!(take_folder(&mine)
            .unwrap_err()
            .to_string()
            .contains("not a batch's folder"));
    }
}
