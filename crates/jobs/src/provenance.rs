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
    /// The size and modification time of `path` (following symbolic links).
    pub fn of(path: &Path) -> Result<Stat> {
        let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
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

/// SHA-256 of a file's bytes, as 64 lowercase hex digits, and the number of bytes hashed.
pub fn sha256_file(path: &Path) -> Result<(String, u64)> {
    let mut file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut hasher = Sha256::new();
    let mut buffer = vec![0u8; 1 << 20];
    let mut total = 0u64;
    loop {
        let n = match file.read(&mut buffer) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(Error::io(path, e)),
        };
        hasher.update(&buffer[..n]);
        total += n as u64;
    }
    Ok((hex(&hasher.finalize()), total))
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
    fn times_are_rfc3339_utc() {
        let t = SystemTime::UNIX_EPOCH + std::time::Duration::from_millis(1_795_000_000_123);
        assert_eq!(rfc3339(t), "2026-11-18T11:06:40.123Z");
    }
}
