//! The files this process has opened for reading. Every reader calls [`note_input`] before it
//! opens a file; the output side (`contactscope_jobs::staging`) refuses to write over any of them,
//! so that no run of any front-end overwrites one of its own inputs: the main inputs and the files
//! named inside manifests, PSF JSONs and simulation folders alike. In a long-lived process
//! (Python, napari) a file read once is never overwritten by a later call either.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Canonical paths of every file read so far.
static READ_INPUTS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Record that `path` is read as an input (call before opening it). A path that cannot be
/// canonicalised (it does not exist) is not recorded: opening it fails anyway.
pub fn note_input(path: &Path) {
    if let Ok(canonical) = path.canonicalize() {
        if let Ok(mut list) = READ_INPUTS.lock() {
            if !list.contains(&canonical) {
                list.push(canonical);
            }
        }
    }
}

/// Whether the file at the canonical path `canonical` has been read by this process.
pub fn was_read(canonical: &Path) -> bool {
    READ_INPUTS
        .lock()
        .map(|list| list.iter().any(|p| p == canonical))
        .unwrap_or(false)
}
