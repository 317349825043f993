//! Writing results without ever leaving a partial output behind, and without mixing two runs.
//!
//! Every file of one run is first written into a staging folder next to the output folder; only
//! when the whole run has succeeded does the staging folder become the output folder. A run
//! replaces its output folder as a whole: nothing of an earlier run survives beside the new
//! files (overlays of other images, maps of other loads). To keep that from ever deleting a
//! person's own files, the folder is replaced only when it is new, empty, or was written by an
//! earlier run — recorded in the [`MARKER`] file each run leaves in its folder, which lists the
//! files it wrote — and holds nothing else. Any other folder, or one that holds an input of the
//! run, is refused with nothing written. The replacement is two renames (the old folder aside,
//! the staging folder into place; the old folder is restored if the second fails). If the run
//! fails, the staging folder is removed and the output folder is untouched. An input file is
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
    /// Folders above `out_dir` this run created: removed again, when empty, if the run does
    /// not commit (dropped after `staging_dir` is removed).
    created_parents: Option<CreatedFolders>,
    files: std::sync::Mutex<Vec<String>>,
    protected: Vec<PathBuf>,
    committed: bool,
}

impl Staging {
    /// Prepare to write into `out_dir`. `inputs` are files the run reads; writing over any of
    /// them is refused.
    pub fn new(out_dir: &Path, inputs: &[PathBuf]) -> Result<Self> {
        local_only(out_dir)?;
        let name = out_dir
            .file_name()
            .map_or("out".into(), |n| n.to_string_lossy().into_owned());
        let parent = match out_dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let created_parents = CreatedFolders::create(&parent)?;
        let staging_dir = parent.join(format!(".{name}.staging-{}", std::process::id()));
        fs::create_dir_all(&staging_dir).map_err(|e| output_error(&staging_dir, e))?;
        register(&staging_dir);
        Ok(Staging {
            out_dir: out_dir.to_path_buf(),
            staging_dir,
            created_parents: Some(created_parents),
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

    /// Stage output file `name` written by `write` (for a file too large to hold in memory):
    /// `write` gets the open staged file.
    pub fn write_with(
        &self,
        name: &str,
        write: impl FnOnce(&mut fs::File) -> Result<()>,
    ) -> Result<PathBuf> {
        let target = self.final_path(name);
        if is_input(&target, &self.protected) {
            return Err(input_refusal(target));
        }
        let staged = self.staging_dir.join(name);
        let _open = open_gate(&staged)?;
        let mut file = fs::File::create(&staged).map_err(|e| output_error(&staged, e))?;
        write(&mut file)?;
        self.files.lock().expect("lock").push(name.to_string());
        Ok(target)
    }

    /// Make the staged files the output folder, replacing an earlier run's folder as a whole
    /// (module docs): all of them, or nothing.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        // In the order written (a name written twice counts once).
        let mut names = std::mem::take(&mut *self.files.lock().expect("lock"));
        let mut seen = std::collections::HashSet::new();
        names.retain(|n| seen.insert(n.clone()));
        let marker = serde_json::json!({
            "written_by": format!("contactscope {}", env!("CARGO_PKG_VERSION")),
            "files": names,
        });
        let marker = serde_json::to_vec_pretty(&marker).expect("a list of names serialises");
        let marker_path = self.staging_dir.join(MARKER);
        fs::write(&marker_path, marker).map_err(|e| output_error(&marker_path, e))?;
        let replaced = self.check_replaceable()?;
        // A signal handler ([`discard_unfinished`]) waits until the renames are done.
        let mut unfinished = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        let aside = replaced.then(|| {
            let name = self
                .out_dir
                .file_name()
                .map_or("out".into(), |n| n.to_string_lossy().into_owned());
            self.staging_dir
                .with_file_name(format!(".{name}.replaced-{}", std::process::id()))
        });
        if let Some(aside) = &aside {
            let _ = fs::remove_dir_all(aside);
            fs::rename(&self.out_dir, aside).map_err(|e| Error::Output {
                path: self.out_dir.clone(),
                reason: format!("{e}; nothing was written"),
            })?;
        }
        if let Err(e) = fs::rename(&self.staging_dir, &self.out_dir) {
            if let Some(aside) = &aside {
                let _ = fs::rename(aside, &self.out_dir);
            }
            return Err(Error::Output {
                path: self.out_dir.clone(),
                reason: format!("{e}; nothing was written"),
            });
        }
        self.committed = true;
        unfinished.retain(|d| d != &self.staging_dir);
        if let Some(created) = self.created_parents.take() {
            created.keep();
        }
        // The earlier run's folder, set aside, goes too if a signal comes while it is removed.
        unfinished.extend(aside.clone());
        drop(unfinished);
        if let Some(aside) = &aside {
            let _ = fs::remove_dir_all(aside);
            unregister(aside);
        }
        Ok(names.iter().map(|n| self.out_dir.join(n)).collect())
    }

    /// Whether the output folder exists and may be replaced (true), does not exist (false), or
    /// must not be touched (an error naming what is in the way).
    fn check_replaceable(&self) -> Result<bool> {
        replaceable(&self.out_dir, &self.protected)
    }
}

/// Outputs are written to local folders only: a URL (`s3://…`) would otherwise become a folder
/// named `s3:` here.
fn local_only(path: &Path) -> Result<()> {
    if contactscope_formats::remote::is_url(path) {
        return Err(Error::Output {
            path: path.to_path_buf(),
            reason: "outputs are written to a local folder, not to object storage (inputs \
                     may be s3:// or https:// URLs); nothing was written"
                .into(),
        });
    }
    Ok(())
}

/// Refuse, before any work, an output folder a run's commit would refuse (in the way, holding
/// files no contactscope run wrote, or holding one of `inputs`); the commit checks again.
pub fn check_out_dir(out_dir: &Path, inputs: &[PathBuf]) -> Result<()> {
    let protected: Vec<PathBuf> = inputs
        .iter()
        .filter_map(|p| p.canonicalize().ok())
        .collect();
    replaceable(out_dir, &protected).map(|_| ())
}

/// Whether `out_dir` exists and may be replaced (true), does not exist (false), or must not be
/// touched (an error naming what is in the way).
fn replaceable(out_dir: &Path, protected: &[PathBuf]) -> Result<bool> {
    let refuse = |reason: String| Error::Output {
        path: out_dir.to_path_buf(),
        reason: format!(
            "{reason}; nothing was written (choose another {} or remove it)",
            contactscope_formats::param::Param::Out
        ),
    };
    local_only(out_dir)?;
    match fs::symlink_metadata(out_dir) {
        Err(_) => return Ok(false),
        Ok(meta) if !meta.is_dir() => {
            return Err(refuse("is in the way (not a folder)".into()));
        }
        Ok(_) => {}
    }
    let entries: Vec<(String, PathBuf)> = fs::read_dir(out_dir)
        .map_err(|e| output_error(out_dir, e))?
        .filter_map(|e| e.ok())
        .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
        .collect();
    if entries.is_empty() {
        return Ok(true);
    }
    let earlier = earlier_run_files(out_dir).ok_or_else(|| {
        refuse(format!(
            "is not empty and was not written by contactscope (no {MARKER})"
        ))
    })?;
    for (name, path) in &entries {
        if is_input(path, protected) {
            return Err(input_refusal(path.clone()));
        }
        let is_file = fs::symlink_metadata(path).is_ok_and(|m| m.is_file());
        if name != MARKER && !(is_file && earlier.contains(name)) {
            return Err(refuse(format!(
                "holds '{name}', which no earlier contactscope run wrote there"
            )));
        }
    }
    Ok(true)
}

/// The file a run leaves in its output folder: JSON with the names of the files it wrote, so
/// that the next run into the folder knows it may replace them (module docs).
pub const MARKER: &str = ".contactscope-run.json";

/// The files an earlier run recorded in `dir`'s [`MARKER`], if it has a readable one.
fn earlier_run_files(dir: &Path) -> Option<Vec<String>> {
    let text = fs::read(dir.join(MARKER)).ok()?;
    let value: serde_json::Value = serde_json::from_slice(&text).ok()?;
    value
        .get("files")?
        .as_array()?
        .iter()
        .map(|v| v.as_str().map(String::from))
        .collect()
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
/// exit), then the folders above them that this process created and that are now empty (`--out
/// new/deeper/run` interrupted leaves no `new/`); returns the folders removed. Writes through
/// [`Staging::write`] and [`write_atomic`] are refused from now on.
pub fn discard_unfinished() -> Vec<PathBuf> {
    *WRITE_GATE.write().unwrap_or_else(|e| e.into_inner()) = true;
    let dirs = match UNFINISHED.lock() {
        Ok(mut list) => std::mem::take(&mut *list),
        Err(_) => return Vec::new(),
    };
    let mut removed: Vec<PathBuf> = dirs
        .into_iter()
        .filter(|d| fs::remove_dir_all(d).is_ok())
        .collect();
    let mut parents = match CREATED_PARENTS.lock() {
        Ok(mut list) => std::mem::take(&mut *list),
        Err(_) => Vec::new(),
    };
    // Deepest first, so that a folder is empty once its own created children are gone.
    parents.sort_by_key(|p| std::cmp::Reverse(p.components().count()));
    parents.dedup();
    removed.extend(remove_empty(&parents));
    removed
}

/// Folders above an output folder that runs of this process created and have not committed into.
static CREATED_PARENTS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn register_parents(dirs: &[PathBuf]) {
    if let Ok(mut list) = CREATED_PARENTS.lock() {
        list.extend(dirs.iter().cloned());
    }
}

fn unregister_parents(dirs: &[PathBuf]) {
    if let Ok(mut list) = CREATED_PARENTS.lock() {
        list.retain(|d| !dirs.contains(d));
    }
}

/// The folders a run created to hold its output folder (`--out new/deeper/run` creates `new` and
/// `new/deeper`): unless [`kept`](Self::keep), they are removed again when empty, on drop and
/// by [`discard_unfinished`] — a run that ends without output leaves no folder it created.
#[derive(Debug)]
pub struct CreatedFolders {
    /// Deepest first.
    dirs: Vec<PathBuf>,
    kept: bool,
}

impl CreatedFolders {
    /// Create `dir` and its missing ancestors, remembering those created.
    pub fn create(dir: &Path) -> Result<Self> {
        local_only(dir)?;
        let mut dirs = Vec::new();
        let mut at = Some(dir);
        while let Some(d) = at.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            dirs.push(d.to_path_buf());
            at = d.parent();
        }
        let created = CreatedFolders { dirs, kept: false };
        fs::create_dir_all(dir).map_err(|e| output_error(dir, e))?;
        register_parents(&created.dirs);
        Ok(created)
    }

    /// Whether any folder was created (`dir` did not exist).
    pub fn created_any(&self) -> bool {
        !self.dirs.is_empty()
    }

    /// The output was committed into them: they stay.
    pub fn keep(mut self) {
        unregister_parents(&self.dirs);
        self.kept = true;
    }
}

impl Drop for CreatedFolders {
    fn drop(&mut self) {
        if !self.kept {
            unregister_parents(&self.dirs);
            remove_empty(&self.dirs);
        }
    }
}

/// Remove each folder of `dirs` (deepest first) that is empty; returns those removed.
fn remove_empty(dirs: &[PathBuf]) -> Vec<PathBuf> {
    dirs.iter()
        .filter(|d| fs::remove_dir(d).is_ok())
        .cloned()
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

/// Write one file atomically by `write` (given the open temporary file): a temporary file in
/// the same folder, then a rename; an input of the run (`inputs`) is never overwritten.
pub fn write_atomic_with(
    path: &Path,
    inputs: &[PathBuf],
    write: impl FnOnce(&mut fs::File) -> Result<()>,
) -> Result<()> {
    local_only(path)?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    fs::create_dir_all(&dir).map_err(|e| output_error(&dir, e))?;
    let name = path
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy().into_owned());
    let protected: Vec<PathBuf> = inputs
        .iter()
        .filter_map(|p| p.canonicalize().ok())
        .collect();
    if is_input(path, &protected) {
        return Err(input_refusal(path.to_path_buf()));
    }
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let _open = open_gate(&tmp)?;
    let written = fs::File::create(&tmp)
        .map_err(|e| output_error(&tmp, e))
        .and_then(|mut f| write(&mut f));
    if let Err(e) = written {
        let _ = fs::remove_file(&tmp);
        return Err(e);
    }
    fs::rename(&tmp, path).map_err(|e| {
        let _ = fs::remove_file(&tmp);
        output_error(path, e)
    })
}

/// Write one file atomically: a temporary file in the same folder, then a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    write_atomic_with(path, &[], |f| {
        f.write_all(bytes).map_err(|e| output_error(path, e))
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
    fn folders_created_above_the_output_go_unless_committed_into() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("new/deeper/results");
        drop(Staging::new(&out, &[]).unwrap());
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            0,
            "new/ left behind"
        );
        // Committed: the folders hold the output and stay.
        let staging = Staging::new(&out, &[]).unwrap();
        staging.write("a.csv", b"x").unwrap();
        staging.commit().unwrap();
        assert!(out.join("a.csv").exists());
        // A folder that existed before is never removed, even when empty.
        let kept = dir.path().join("kept");
        fs::create_dir(&kept).unwrap();
        drop(Staging::new(&kept.join("run"), &[]).unwrap());
        assert!(kept.exists());
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
    fn staged_files_appear_only_on_commit_and_are_listed() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        let staging = Staging::new(&out, &[]).unwrap();
        staging.write("a.csv", b"x").unwrap();
        let written = staging.commit().unwrap();
        assert_eq!(written, [out.join("a.csv")]);
        assert_eq!(earlier_run_files(&out).unwrap(), ["a.csv"]);
    }

    #[test]
    fn a_rerun_replaces_the_earlier_folder_as_a_whole() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        let first = Staging::new(&out, &[]).unwrap();
        first.write("areas.csv", b"old").unwrap();
        first.write("overlay_001_a.png", b"old").unwrap();
        first.commit().unwrap();
        let second = Staging::new(&out, &[]).unwrap();
        second.write("areas.csv", b"new").unwrap();
        second.write("overlay_001_b.png", b"new").unwrap();
        second.commit().unwrap();
        let mut names: Vec<String> = fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, [MARKER, "areas.csv", "overlay_001_b.png"]);
        assert_eq!(fs::read(out.join("areas.csv")).unwrap(), b"new");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "nothing aside"
        );
    }

    #[test]
    fn a_folder_with_files_no_run_wrote_is_refused_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        // A folder of the person's own files, without a marker.
        fs::create_dir_all(&out).unwrap();
        fs::write(out.join("notes.txt"), b"mine").unwrap();
        let staging = Staging::new(&out, &[]).unwrap();
        staging.write("areas.csv", b"new").unwrap();
        let err = staging.commit().unwrap_err().to_string();
        assert!(err.contains("not written by contactscope"), "{err}");
        assert!(err.contains("nothing was written"), "{err}");
        // An earlier run's folder to which the person added a file.
        let staging = Staging::new(&out, &[]).unwrap();
        fs::write(out.join(MARKER), br#"{"files": ["areas.csv"]}"#).unwrap();
        fs::write(out.join("areas.csv"), b"old").unwrap();
        staging.write("areas.csv", b"new").unwrap();
        let err = staging.commit().unwrap_err().to_string();
        assert!(err.contains("'notes.txt'"), "{err}");
        assert_eq!(fs::read(out.join("notes.txt")).unwrap(), b"mine");
        assert_eq!(fs::read(out.join("areas.csv")).unwrap(), b"old");
        let left: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "only the output folder, no staging folder");
    }

    #[test]
    fn the_early_check_refuses_what_the_commit_would() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        check_out_dir(&out, &[]).unwrap(); // new
        fs::create_dir_all(&out).unwrap();
        check_out_dir(&out, &[]).unwrap(); // empty
        fs::write(out.join("notes.txt"), b"mine").unwrap();
        let err = check_out_dir(&out, &[]).unwrap_err().to_string();
        assert!(err.contains("not written by contactscope"), "{err}");
        fs::write(out.join(MARKER), br#"{"files": ["notes.txt"]}"#).unwrap();
        check_out_dir(&out, &[]).unwrap(); // an earlier run's
        let input = out.join("notes.txt");
        assert!(check_out_dir(&out, std::slice::from_ref(&input)).is_err());
        fs::remove_dir_all(&out).unwrap();
        fs::write(&out, b"a file").unwrap();
        let err = check_out_dir(&out, &[]).unwrap_err().to_string();
        assert!(err.contains("in the way"), "{err}");
        assert_eq!(
            fs::read_dir(dir.path()).unwrap().count(),
            1,
            "nothing written"
        );
    }

    #[test]
    fn a_folder_holding_an_input_is_never_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("results");
        fs::create_dir_all(&out).unwrap();
        let input = out.join("series.tif");
        fs::write(&input, b"data").unwrap();
        fs::write(out.join(MARKER), br#"{"files": ["series.tif"]}"#).unwrap();
        let staging = Staging::new(&out, std::slice::from_ref(&input)).unwrap();
        staging.write("areas.csv", b"new").unwrap();
        let err = staging.commit().unwrap_err().to_string();
        assert!(err.contains("input file"), "{err}");
        assert_eq!(fs::read(&input).unwrap(), b"data");
    }
}
