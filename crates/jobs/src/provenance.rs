//! What a reader of a result needs to reproduce it: the program's version and the source
//! revision it was built from, the machine, the times, and every input file with its size and
//! content hash (SHA-256, FIPS 180-4). The batch's `batch.json` and its per-series records are
//! made of these.
//!
//! The source revision is known to the front-end's build (its build script records the git
//! commit, `crates/jobs/build/revision.rs`); the front-end hands it over once at start-up with
//! [`set_source_revision`].

use std::io::Read;
use std::path::Path;
use std::sync::OnceLock;
use std::time::SystemTime;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::{Error, Result};

static SOURCE_REVISION: OnceLock<&'static str> = OnceLock::new();

/// Record the source revision the running front-end was built from (the git commit, with
/// ` (modified)` for uncommitted changes, or `unknown` when it was not built from a checkout).
/// Called once at start-up.
pub fn set_source_revision(revision: &'static str) {
    let _ = SOURCE_REVISION.set(revision);
}

/// The source revision set by the front-end; `None` when it is unknown (built from a source
/// archive or a registry's crate) or none was set. Written as JSON `null`.
pub fn source_revision() -> Option<&'static str> {
    SOURCE_REVISION
        .get()
        .copied()
        .filter(|revision| *revision != "unknown")
}

/// The version of contactscope.
pub fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// `t` as RFC 3339 in UTC, to the millisecond (`2026-11-27T07:34:17.123Z`).
pub fn rfc3339(t: SystemTime) -> String {
    humantime::format_rfc3339_millis(t).to_string()
}

/// The machine a run happened on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// Host name.
    pub hostname: String,
    /// Operating system (`linux`, `macos`, …).
    pub os: String,
    /// CPU architecture (`x86_64`, `aarch64`, …).
    pub arch: String,
    /// Logical CPUs this process may use.
    pub cpus: usize,
}

impl Machine {
    /// This machine.
    pub fn this() -> Self {
        Machine {
            hostname: gethostname::gethostname().to_string_lossy().into_owned(),
            os: std::env::consts::OS.to_string(),
            arch: std::env::consts::ARCH.to_string(),
            cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// Size and modification time of a file: what a re-run compares first (a hash only when these
/// differ).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stat {
    /// Size, bytes.
    pub size_bytes: u64,
    /// Modification time, nanoseconds since the Unix epoch (0 where the platform gives none).
    pub modified_ns: u128,
}

impl Stat {
    /// The size and modification time of `path` (following symbolic links). A folder (an
    /// OME-Zarr store) counts as the sum of its files' sizes and the latest of their times.
    pub fn of(path: &Path) -> Result<Stat> {
        let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
        if meta.is_dir() {
            let mut total = Stat {
                size_bytes: 0,
                modified_ns: 0,
            };
            for (_, file) in tree_files(path)? {
                let one = Stat::of(&file)?;
                total.size_bytes += one.size_bytes;
                total.modified_ns = total.modified_ns.max(one.modified_ns);
            }
            return Ok(total);
        }
        let modified_ns = meta
            .modified()
            .ok()
            .and_then(|t| t.duration_since(SystemTime::UNIX_EPOCH).ok())
            .map_or(0, |d| d.as_nanos());
        Ok(Stat {
            size_bytes: meta.len(),
            modified_ns,
        })
    }
}

/// The regular files below a folder (symbolic links not followed), as (path relative to the
/// folder with `/` separators, path), sorted by the relative path's bytes.
fn tree_files(dir: &Path) -> Result<Vec<(String, std::path::PathBuf)>> {
    let mut files = Vec::new();
    for entry in walkdir::WalkDir::new(dir).follow_links(false) {
        let entry = entry.map_err(|e| {
            let at = e.path().unwrap_or(dir).to_path_buf();
            Error::io(at, e.into())
        })?;
        if entry.file_type().is_file() {
            let relative = entry.path().strip_prefix(dir).unwrap_or(entry.path());
            let name: Vec<String> = relative
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            files.push((name.join("/"), entry.path().to_path_buf()));
        }
    }
    files.sort();
    Ok(files)
}

/// SHA-256 of a file's bytes, as 64 lowercase hex digits, and the number of bytes hashed.
///
/// A folder (an OME-Zarr store) has a tree hash: SHA-256 over its regular files in the byte
/// order of their relative paths, each as its relative path (`/`-separated, UTF-8), a zero
/// byte, its length as 8 little-endian bytes and its bytes, so that renaming, moving or changing
/// any file changes the hash.
pub fn sha256_file(path: &Path) -> Result<(String, u64)> {
    let mut hasher = Sha256::new();
    let mut buffer = vec![0u8; 1 << 20];
    if path.is_dir() {
        let mut total = 0u64;
        for (name, file) in tree_files(path)? {
            hasher.update(name.as_bytes());
            hasher.update([0u8]);
            let len = std::fs::metadata(&file)
                .map_err(|e| Error::io(&file, e))?
                .len();
            hasher.update(len.to_le_bytes());
            let n = hash_into(&file, &mut hasher, &mut buffer)?;
            if n != len {
                return Err(Error::io(
                    &file,
                    std::io::Error::other("the file changed while it was hashed"),
                ));
            }
            total += n;
        }
        return Ok((hex(&hasher.finalize()), total));
    }
    let total = hash_into(path, &mut hasher, &mut buffer)?;
    Ok((hex(&hasher.finalize()), total))
}

/// Feed a file's bytes to `hasher`; the number of bytes read.
fn hash_into(path: &Path, hasher: &mut Sha256, buffer: &mut [u8]) -> Result<u64> {
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut total = 0u64;
    loop {
        let n = match file.read(buffer) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(Error::io(path, e)),
        };
        hasher.update(&buffer[..n]);
        total += n as u64;
    }
    Ok(total)
}

/// SHA-256 of bytes in memory, as 64 lowercase hex digits.
pub fn sha256_bytes(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(bytes: &[u8]) -> String {
    use std::fmt::Write as _;
    bytes.iter().fold(String::with_capacity(64), |mut s, b| {
        let _ = write!(s, "{b:02x}");
        s
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_matches_the_standard_test_vectors() {
        // FIPS 180-4 examples (NIST CSRC "SHA256.pdf"): "abc" and the empty message.
        assert_eq!(
            sha256_bytes(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            sha256_bytes(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.bin");
        // More than one read buffer, not a multiple of it.
        let bytes: Vec<u8> = (0..(3 << 20) + 17).map(|i| (i % 251) as u8).collect();
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(
            sha256_file(&path).unwrap(),
            (sha256_bytes(&bytes), bytes.len() as u64)
        );
        assert!(sha256_file(&dir.path().join("missing")).is_err());
    }

    #[test]
    fn a_folder_hashes_as_its_named_files() {
        let dir = tempfile::tempdir().unwrap();
        let store = dir.path().join("s.zarr");
        std::fs::create_dir_all(store.join("0/c")).unwrap();
        std::fs::write(store.join("zarr.json"), b"{}").unwrap();
        std::fs::write(store.join("0/c/0"), b"abc").unwrap();
        // The tree hash by hand: names in byte order, each with its length and bytes.
        let mut expected = Vec::new();
        for (name, bytes) in [("0/c/0", &b"abc"[..]), ("zarr.json", &b"{}"[..])] {
            expected.extend_from_slice(name.as_bytes());
            expected.push(0);
            expected.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
            expected.extend_from_slice(bytes);
        }
        let (hash, n) = sha256_file(&store).unwrap();
        assert_eq!((hash.as_str(), n), (sha256_bytes(&expected).as_str(), 5));
        assert_eq!(Stat::of(&store).unwrap().size_bytes, 5);
        // A renamed chunk with the same bytes is another store.
        std::fs::rename(store.join("0/c/0"), store.join("0/c/1")).unwrap();
        assert_ne!(sha256_file(&store).unwrap().0, hash);
    }

    #[test]
    fn times_are_rfc3339_utc() {
        let t = SystemTime::UNIX_EPOCH + std::time::Duration::from_millis(1_795_000_000_123);
        assert_eq!(rfc3339(t), "2026-11-18T11:06:40.123Z");
    }
}
