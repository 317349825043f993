//! Run one case under a time and memory limit and classify what happened.

use std::collections::hash_map::DefaultHasher;
use std::fs;
use std::hash::{Hash, Hasher};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// What a case did. Everything but `Ok` and `CleanError` is a failure of contactscope.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// Exit 0, outputs finite, nothing left behind.
    Ok,
    /// Exit 1 or 2 with one error line naming an input file or a flag, nothing written.
    CleanError,
    /// Exit 1 or 2 with one error line that names neither an input file nor a flag: the person
    /// cannot tell what to change.
    Unnamed,
    /// An error that is several lines, too long, or lacks the `contactscope: error:` prefix.
    Unclean,
    /// A Rust panic (exit 101).
    Panic,
    /// Killed after the time limit.
    Hang,
    /// Killed by a signal of its own (abort on a failed allocation, segfault).
    Abort,
    /// Failed after writing (part of) its output.
    Partial,
    /// An input file changed or disappeared.
    Overwritten,
    /// A staging or demo work folder left behind.
    Leftover,
    /// `inf` or `NaN` in stdout or an output CSV/JSON of a successful run.
    NonFinite,
    /// An exit code other than 0, 1, 2 (or 3 from a batch whose tables are written).
    OddExit,
}

impl Class {
    /// Whether the class is a failure the campaign reports.
    pub fn is_failure(self) -> bool {
        !matches!(
            self,
            Class::Ok | Class::CleanError | Class::Unclean | Class::Unnamed
        )
    }
}

/// The result of one case.
pub struct Outcome {
    pub class: Class,
    /// First line of stderr (or why the class was given).
    pub detail: String,
}

fn hash_file(path: &Path) -> Option<u64> {
    let bytes = fs::read(path).ok()?;
    let mut h = DefaultHasher::new();
    bytes.hash(&mut h);
    Some(h.finish())
}

/// Every file under `dir` (recursively) with its content hash, skipping `skip`.
pub fn snapshot(dir: &Path, skip: &Path) -> Vec<(PathBuf, Option<u64>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.starts_with(skip) {
                continue;
            }
            if p.is_dir() {
                stack.push(p);
            } else {
                out.push((p.clone(), hash_file(&p)));
            }
        }
    }
    out.sort();
    out
}

/// Names of staging or demo work folders anywhere under `dir`.
fn leftovers(dir: &Path) -> Vec<String> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if name.contains(".staging-") || name.contains(".demo-") || name.contains(".replaced-")
            {
                found.push(name);
            } else if e.path().is_dir() {
                stack.push(e.path());
            }
        }
    }
    found
}

/// A word `nan`, `inf` or `infinity` (any case) in `text`.
fn non_finite_word(text: &str) -> Option<String> {
    text.split(|c: char| !c.is_ascii_alphanumeric())
        .find(|w| matches!(w.to_ascii_lowercase().as_str(), "nan" | "inf" | "infinity"))
        .map(str::to_string)
}

/// The first non-finite word in stdout or in a CSV/JSON under `out`.
fn non_finite_output(stdout: &str, out: &Path) -> Option<String> {
    if let Some(w) = non_finite_word(stdout) {
        return Some(format!("stdout: {w}"));
    }
    let mut stack = vec![out.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if matches!(p.extension().and_then(|e| e.to_str()), Some("csv" | "json")) {
                let text = fs::read_to_string(&p).unwrap_or_default();
                if let Some(w) = non_finite_word(&text) {
                    return Some(format!("{}: {w}", p.display()));
                }
            }
        }
    }
    None
}

/// Whether stderr is warnings followed by exactly one `contactscope: error:` line of at most
/// 500 characters, or clap's one-line usage error (see `crates/cli/main.rs`).
fn clean_error(stderr: &str) -> Result<(), String> {
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| !l.starts_with("contactscope: warning:"))
        .collect();
    match lines.as_slice() {
        [line] if line.starts_with("contactscope: error: ") && line.len() <= 500 => Ok(()),
        [line] => Err(format!("bad line: {}", truncate(line, 200))),
        [] => Err("no error message".into()),
        many => Err(format!(
            "{} lines: {}",
            many.len(),
            truncate(&many.join(" | "), 200)
        )),
    }
}

/// The `contactscope: error:` line of stderr.
fn error_line(stderr: &str) -> &str {
    stderr
        .lines()
        .find(|l| l.starts_with("contactscope: error:"))
        .unwrap_or("")
}

fn truncate(s: &str, n: usize) -> String {
    if s.len() <= n {
        return s.to_string();
    }
    let mut end = n;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}…", &s[..end])
}

/// Limits of one run.
pub struct Limits {
    pub time: Duration,
    pub memory_kib: u64,
}

/// What an error line may name so that a person knows what to change: the name of every input
/// file of the case, every path its arguments give (a folder such as `sim`), and every flag.
fn nameable(dir: &Path, args: &[String], out: &Path) -> Vec<String> {
    let mut names: Vec<String> = snapshot(dir, out)
        .iter()
        .filter_map(|(p, _)| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    names.extend(
        args.iter()
            .filter(|a| a.starts_with("--") || dir.join(a.as_str()).exists())
            .cloned(),
    );
    names.sort();
    names.dedup();
    names
}

/// Whether `line` names `name`: a file name (`series.tif`) anywhere, a flag not as the start of a
/// longer flag, and a bare folder name (`series`, `sim`) only written as a path (`series/…`,
/// `sim:`), so that the folder `series` is not found in "the series has no images".
fn names(line: &str, name: &str) -> bool {
    let word = |c: char| c.is_alphanumeric() || c == '_' || c == '-';
    line.match_indices(name).any(|(i, _)| {
        let before = line[..i].chars().next_back();
        let after = line[i + name.len()..].chars().next();
        if name.starts_with("--") {
            !after.is_some_and(word)
        } else if name.contains('.') {
            true
        } else {
            !before.is_some_and(word) && matches!(after, Some('/' | ':')) || before == Some('/')
        }
    })
}

/// Run `args` in `dir` (which holds the case's inputs) and classify the result. `out` is the
/// output path named in the arguments.
pub fn run_case(dir: &Path, args: &[String], out: &Path, limits: &Limits) -> Outcome {
    let before = snapshot(dir, out);
    let nameable = nameable(dir, args, out);
    let stdout_path = dir.with_extension("stdout");
    let stderr_path = dir.with_extension("stderr");
    let script = format!("ulimit -v {} && exec \"$0\" \"$@\"", limits.memory_kib);
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_contactscope"))
        .args(args)
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "1")
        .stdin(Stdio::null())
        .stdout(fs::File::create(&stdout_path).unwrap())
        .stderr(fs::File::create(&stderr_path).unwrap())
        .spawn()
        .expect("sh runs");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > limits.time {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    let stdout = fs::read_to_string(&stdout_path).unwrap_or_default();
    let stderr = String::from_utf8_lossy(&fs::read(&stderr_path).unwrap_or_default()).into_owned();
    let first = truncate(stderr.lines().next().unwrap_or(""), 300);
    let outcome = |class, detail: String| Outcome { class, detail };

    let Some(status) = status else {
        return outcome(Class::Hang, format!("killed after {:?}", limits.time));
    };
    if stderr.contains("panicked at") || status.code() == Some(101) {
        let at = stderr
            .lines()
            .find(|l| l.contains("panicked at"))
            .unwrap_or(&first);
        return outcome(Class::Panic, truncate(at, 300));
    }
    if let Some(sig) = status.signal() {
        return outcome(Class::Abort, format!("signal {sig}: {first}"));
    }
    if let Some(left) = leftovers(dir).first() {
        return outcome(Class::Leftover, left.clone());
    }
    let after = snapshot(dir, out);
    if let Some((path, _)) = before.iter().find(|b| !after.contains(b)) {
        return outcome(Class::Overwritten, path.display().to_string());
    }
    match status.code() {
        Some(0) => match non_finite_output(&stdout, out) {
            Some(w) => outcome(Class::NonFinite, w),
            None => outcome(Class::Ok, String::new()),
        },
        Some(1 | 2) => {
            if out.exists() {
                return outcome(Class::Partial, format!("{} exists: {first}", out.display()));
            }
            match clean_error(&stderr) {
                Ok(()) if !nameable.iter().any(|n| names(error_line(&stderr), n)) => {
                    outcome(Class::Unnamed, first)
                }
                Ok(()) => outcome(Class::CleanError, first),
                Err(why) => outcome(Class::Unclean, why),
            }
        }
        // A batch that wrote its tables, some series failed: their rows (and stdout) quote the
        // bad input in their errors, so only the numbers of the image table are checked.
        Some(3) if out.join("series.csv").is_file() => {
            let images = fs::read_to_string(out.join("images.csv")).unwrap_or_default();
            match non_finite_word(&images) {
                Some(w) => outcome(Class::NonFinite, format!("images.csv: {w}")),
                None => outcome(Class::Ok, String::new()),
            }
        }
        // Outputs written, but no load valid (docs/errors.md): checked as a success is.
        Some(4) if out.exists() => match non_finite_output(&stdout, out) {
            Some(w) => outcome(Class::NonFinite, w),
            None => outcome(Class::Ok, String::new()),
        },
        Some(code) => outcome(Class::OddExit, format!("exit {code}: {first}")),
        None => outcome(Class::Abort, first),
    }
}

#[test]
fn an_error_names_a_file_a_flag_or_a_folder_written_as_a_path() {
    let line = "contactscope: error: the series has no images";
    assert!(!names(line, "series"));
    assert!(names(
        "contactscope: error: series/a.tif: truncated",
        "a.tif"
    ));
    assert!(names("contactscope: error: series: no manifest", "series"));
    assert!(names("contactscope: error: exp/series.tif:3: bad", "exp"));
    assert!(names("contactscope: error: --size: 0 pixels", "--size"));
    assert!(!names("contactscope: error: --size-x: 0 pixels", "--size"));
    assert!(!names("contactscope: error: simulated map empty", "sim"));
}
