//! Writing results without ever leaving a partial output behind.
//!
//! Every file of one run is first written into a staging folder next to the output folder; only
//! when the whole run has succeeded are the files renamed into place. The commit is all or
//! nothing: every target is checked before the first rename (a directory or other non-file in
//! the way, or an input of the run, refuses the commit with nothing moved), a file it replaces
//! is first moved aside, and if a rename still fails the files already moved are taken back and
//! the replaced ones restored. If the run fails, the staging folder is removed and the output
//! folder is untouched. Targets that are input files of the run are refused, so an input is
//! never overwritten.
//!
//! Staging folders alive in the process are registered, so that a signal handler
//! ([`discard_unfinished`], called by the command line on SIGINT and SIGTERM) can remove them.

use std::fs;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Files of one run, staged until [`Staging::commit`].
#[derive(Debug)]
pub struct Staging {
    out_dir: PathBuf,
    staging_dir: PathBuf,
    files: std::sync::Mutex<Vec<String>>,
    protected: Vec<PathBuf>,
    committed: bool,
}

impl Staging {
    /// Prepare to write into `out_dir`. `inputs` are files the run reads; writing over any of
    /// them is refused.
    pub fn new(out_dir: &Path, inputs: &[PathBuf]) -> Result<Self> {
        let name = out_dir
            .file_name()
            .map_or("out".into(), |n| n.to_string_lossy().into_owned());
        let parent = match out_dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        fs::create_dir_all(&parent).map_err(|e| output_error(&parent, e))?;
        let staging_dir = parent.join(format!(".{name}.staging-{}", std::process::id()));
        fs::create_dir_all(&staging_dir).map_err(|e| output_error(&staging_dir, e))?;
        register(&staging_dir);
        Ok(Staging {
            out_dir: out_dir.to_path_buf(),
            staging_dir,
            files: std::sync::Mutex::new(Vec::new()),
            protected: inputs
                .iter()
                .filter_map(|p| p.canonicalize().ok())
                .collect(),
            committed: false,
        })
    }

    /// Final path of an output file.
    pub fn final_path(&self, name: &str) -> PathBuf {
        self.out_dir.join(name)
    }

    /// Stage `bytes` as output file `name` (a plain file name).
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<PathBuf> {
        let target = self.final_path(name);
        if is_input(&target, &self.protected) {
            return Err(input_refusal(target));
        }
        let staged = self.staging_dir.join(name);
        let _open = open_gate(&staged)?;
        fs::write(&staged, bytes).map_err(|e| output_error(&staged, e))?;
        self.files.lock().expect("lock").push(name.to_string());
        Ok(target)
    }

    /// Move every staged file into the output folder: all of them, or none (module docs).
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        fs::create_dir_all(&self.out_dir).map_err(|e| output_error(&self.out_dir, e))?;
        let names = std::mem::take(&mut *self.files.lock().expect("lock"));
        // Every target first: nothing is moved unless every one can take its file.
        for name in &names {
            let target = self.out_dir.join(name);
            match fs::symlink_metadata(&target) {
                Ok(meta) if !meta.is_file() => {
                    return Err(Error::Output {
                        path: target,
                        reason: "is in the way (not a regular file); nothing was written".into(),
                    });
                }
                Ok(_) => {
                    if is_input(&target, &self.protected) {
                        return Err(input_refusal(target));
                    }
                }
                Err(_) => {}
            }
        }
        // A signal handler ([`discard_unfinished`]) waits until the renames are done.
        let mut unfinished = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        let aside = self.staging_dir.join(".replaced");
        let mut moved: Vec<(PathBuf, PathBuf, Option<PathBuf>)> = Vec::new();
        for name in &names {
            let (staged, target) = (self.staging_dir.join(name), self.out_dir.join(name));
            let step = || -> std::io::Result<Option<PathBuf>> {
                let replaced = if target.exists() {
                    fs::create_dir_all(&aside)?;
                    let old = aside.join(name);
                    fs::rename(&target, &old)?;
                    Some(old)
                } else {
                    None
                };
                if let Err(e) = fs::rename(&staged, &target) {
                    if let Some(old) = &replaced {
                        let _ = fs::rename(old, &target);
                    }
                    return Err(e);
                }
                Ok(replaced)
            };
            match step() {
                Ok(replaced) => moved.push((staged, target, replaced)),
                Err(e) => {
                    // Take back what was moved, newest first, and restore what it replaced.
                    for (staged, target, replaced) in moved.iter().rev() {
                        let _ = fs::rename(target, staged);
                        if let Some(old) = replaced {
                            let _ = fs::rename(old, target);
                        }
                    }
                    return Err(Error::Output {
                        path: target,
                        reason: format!("{e}; nothing was written"),
                    });
                }
            }
        }
        self.committed = true;
        unfinished.retain(|d| d != &self.staging_dir);
        drop(unfinished);
        let _ = fs::remove_dir_all(&self.staging_dir);
        Ok(moved.into_iter().map(|(_, target, _)| target).collect())
    }
}

pub use contactscope_formats::inputs::note_input;

/// Whether `target` (an existing file) is an input: named to [`Staging::new`] or read by the
/// process.
fn is_input(target: &Path, protected: &[PathBuf]) -> bool {
    let Ok(existing) = target.canonicalize() else {
        return false;
    };
    protected.contains(&existing) || contactscope_formats::inputs::was_read(&existing)
}

fn input_refusal(target: PathBuf) -> Error {
    Error::Output {
        path: target,
        reason: format!(
            "it is an input file of this run; choose another {}",
            contactscope_formats::param::Param::Out
        ),
    }
}

/// Staging (and other unfinished output) folders of this process.
static UNFINISHED: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Register an unfinished output folder for [`discard_unfinished`].
pub fn register(dir: &Path) {
    if let Ok(mut list) = UNFINISHED.lock() {
        list.push(dir.to_path_buf());
    }
}

/// The folder is finished (committed or removed).
pub fn unregister(dir: &Path) {
    if let Ok(mut list) = UNFINISHED.lock() {
        list.retain(|d| d != dir);
    }
}

/// Closed (true) once [`discard_unfinished`] has begun: writes in flight finish first, later ones
/// are refused, so that no file appears in a folder while it is being removed.
static WRITE_GATE: std::sync::RwLock<bool> = std::sync::RwLock::new(false);

/// Hold the gate open for one write, or refuse it after an interruption.
fn open_gate(path: &Path) -> Result<std::sync::RwLockReadGuard<'static, bool>> {
    let gate = WRITE_GATE.read().unwrap_or_else(|e| e.into_inner());
    if *gate {
        return Err(Error::Output {
            path: path.to_path_buf(),
            reason: "interrupted; not written".into(),
        });
    }
    Ok(gate)
}

/// Remove every registered unfinished folder (for a signal handler: the process is about to
/// exit); returns the folders removed. Writes through [`Staging::write`] and [`write_atomic`]
/// are refused from now on.
pub fn discard_unfinished() -> Vec<PathBuf> {
    *WRITE_GATE.write().unwrap_or_else(|e| e.into_inner()) = true;
    let dirs = match UNFINISHED.lock() {
        Ok(mut list) => std::mem::take(&mut *list),
        Err(_) => return Vec::new(),
    };
    dirs.into_iter()
        .filter(|d| fs::remove_dir_all(d).is_ok())
        .collect()
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            unregister(&self.staging_dir);
            let _ = fs::remove_dir_all(&self.staging_dir);
        }
    }
}

fn output_error(path: &Path, e: std::io::Error) -> Error {
    Error::Output {
        path: path.to_path_buf(),
        reason: e.to_string(),
    }
}

/// Write one file atomically: a temporary file in the same folder, then a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&dir).map_err(|e| output_error(&dir, e))?;
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy().into_owned());
    if is_input(path, &[]) {
        return Err(input_refusal(path.to_path_buf()));
    }
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let _open = open_gate(&tmp)?;
    fs::write(&tmp, bytes).map_err(|e| output_error(&tmp, e))?;
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        output_error(path, e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_files_appear_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        let staging = Staging::new(&out, &[]).unwrap();
        staging.write("a.csv", b"x").unwrap();
        assert!(!out.join("a.csv").exists());
        staging.commit().unwrap();
        assert_eq!(fs::read(out.join("a.csv")).unwrap(), b"x");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "staging folder removed"
        );
    }

    #[test]
    fn dropped_staging_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        {
            let staging = Staging::new(&out, &[]).unwrap();
            staging.write("a.csv", b"x").unwrap();
        }
        assert!(!out.exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn refuses_to_overwrite_inputs() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("areas.csv");
        fs::write(&input, b"precious").unwrap();
        let staging = Staging::new(dir.path(), std::slice::from_ref(&input)).unwrap();
        assert!(staging.write("areas.csv", b"y").is_err());
        drop(staging);
        assert_eq!(fs::read(&input).unwrap(), b"precious");
    }

    #[test]
    fn a_directory_in_the_way_refuses_the_whole_commit() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        fs::create_dir_all(out.join("summary.json")).unwrap();
        fs::write(out.join("areas.csv"), b"old").unwrap();
        let staging = Staging::new(&out, &[]).unwrap();
        staging.write("areas.csv", b"new").unwrap();
        staging.write("summary.json", b"{}").unwrap();
        let err = staging.commit().unwrap_err().to_string();
        assert!(
            err.contains("summary.json") && err.contains("nothing was written"),
            "{err}"
        );
        assert_eq!(fs::read(out.join("areas.csv")).unwrap(), b"old");
        let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "only the output folder, no staging folder");
    }

    #[test]
    fn a_failed_rename_takes_back_what_was_moved() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        fs::create_dir_all(&out).unwrap();
        fs::write(out.join("a.csv"), b"old").unwrap();
        let staging = Staging::new(&out, &[]).unwrap();
        staging.write("a.csv", b"new").unwrap();
        staging.write("b.csv", b"new").unwrap();
        // The second rename fails after the first has happened.
        fs::remove_file(staging.staging_dir.join("b.csv")).unwrap();
        assert!(staging.commit().is_err());
        assert_eq!(fs::read(out.join("a.csv")).unwrap(), b"old", "restored");
        assert!(!out.join("b.csv").exists());
        assert_eq!(fs::read_dir(&out).unwrap().count(), 1);
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "staging removed"
        );
    }
}
