//! Writing results without ever leaving a partial output behind.
//!
//! Every file of one run is first written into a staging folder next to the output folder; only
//! when the whole run has succeeded are the files renamed into place, one atomic rename each. If
//! the run fails, the staging folder is removed and the output folder is untouched. Targets that
//! are input files of the run are refused, so an input is never overwritten.

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
        if let Ok(existing) = target.canonicalize() {
            if self.protected.contains(&existing) {
                return Err(Error::Output {
                    path: target,
                    reason: "it is an input file of this run; choose another --out".into(),
                });
            }
        }
        let staged = self.staging_dir.join(name);
        fs::write(&staged, bytes).map_err(|e| output_error(&staged, e))?;
        self.files.lock().expect("lock").push(name.to_string());
        Ok(target)
    }

    /// Move every staged file into the output folder.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        fs::create_dir_all(&self.out_dir).map_err(|e| output_error(&self.out_dir, e))?;
        let names = std::mem::take(&mut *self.files.lock().expect("lock"));
        let mut written = Vec::with_capacity(names.len());
        for name in names {
            let target = self.out_dir.join(&name);
            fs::rename(self.staging_dir.join(&name), &target)
                .map_err(|e| output_error(&target, e))?;
            written.push(target);
        }
        self.committed = true;
        let _ = fs::remove_dir_all(&self.staging_dir);
        Ok(written)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
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
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
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
}
