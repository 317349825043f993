//! The files this process has opened for reading. Every reader calls [`note_input`] before it
//! opens a file; the output side (`contactscope_jobs::staging`) refuses to write over any of them,
//! so that no run of any front-end overwrites one of its own inputs: the main inputs and the files
//! named inside manifests, PSF JSONs and simulation folders alike. In a long-lived process
//! (Python, napari) a file read once is never overwritten by a later call either.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// Canonical paths of every file read so far (a set: a batch reads thousands of files, and
/// every output write asks whether its target is one of them).
fn read_inputs() -> &'static Mutex<HashSet<PathBuf>> {
    static READ_INPUTS: OnceLock<Mutex<HashSet<PathBuf>>> = OnceLock::new();
    READ_INPUTS.get_or_init(|| Mutex::new(HashSet::new()))
}

/// Record that `path` is read as an input (call before opening it). A path that cannot be
/// canonicalised (it does not exist) is not recorded: opening it fails anyway.
pub fn note_input(path: &Path) {
    if let Ok(canonical) = path.canonicalize() {
        if let Ok(mut set) = read_inputs().lock() {
            set.insert(canonical);
        }
    }
}

/// Whether the file at the canonical path `canonical` has been read by this process.
pub fn was_read(canonical: &Path) -> bool {
    read_inputs()
        .lock()
        .map(|set| set.contains(canonical))
        .unwrap_or(false)
}

/// Stop treating `path` as an input of this process: for a file a job wrote and read back
/// itself (the batch's `areas.csv`, which its fit reads), which a later run of the same process
/// may replace.
pub fn forget_input(path: &Path) {
    if let Ok(canonical) = path.canonicalize() {
        if let Ok(mut set) = read_inputs().lock() {
            set.remove(&canonical);
        }
    }
}
