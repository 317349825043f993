//! Inputs on object storage: `s3://bucket/key` (Amazon S3 and S3-compatible servers: MinIO,
//! Ceph, a university's object store) and `http://` or `https://` (any web server that answers
//! byte-range requests, read-only). A URL is given wherever a micrograph path is: a single file
//! (TIFF, CZI, ND2, LIF) is read in byte ranges through a small shared block cache, never copied
//! whole to disk; an OME-Zarr store is read key by key, chunk by chunk.
//!
//! Settings follow the AWS command-line tools' environment variables:
//! - credentials `AWS_ACCESS_KEY_ID`, `AWS_SECRET_ACCESS_KEY` (and `AWS_SESSION_TOKEN`); without
//!   them, or with `AWS_NO_SIGN_REQUEST=true`, requests go unsigned (public buckets);
//! - region `AWS_REGION`, else `AWS_DEFAULT_REGION`, else `us-east-1`;
//! - endpoint [`set_endpoint_url`] (the command line's `--endpoint-url`), else
//!   `AWS_ENDPOINT_URL_S3`, else `AWS_ENDPOINT_URL`, else Amazon's
//!   `https://s3.<region>.amazonaws.com` (virtual-hosted buckets); a custom endpoint is addressed
//!   path-style (`<endpoint>/<bucket>/<key>`), as MinIO and Ceph expect.
//!
//! Requests are presigned with AWS Signature Version 4 (`rusty-s3`) and sent with `ureq`. A
//! request that fails on the way (a refused or dropped connection, a body cut short, HTTP 5xx,
//! 429 or 408) is retried up to [`ATTEMPTS`] times with a doubling pause; a missing object is an
//! error naming the URL and HTTP 404, a refused one names HTTP 403 and the credentials.

mod client;
mod file;
mod zarr_store;

use std::collections::HashMap;
use std::path::Path;
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

pub(crate) use client::is_network_error;
pub(crate) use file::{open_input, Input};
pub(crate) use zarr_store::RemoteStore;

/// How many times a request is tried before its error is reported.
pub const ATTEMPTS: u32 = 5;

/// Whether `path` names an object by URL (`s3://`, `http://`, `https://`) rather than a file.
pub fn is_url(path: &Path) -> bool {
    path.to_str().is_some_and(|s| {
        let lower = s.get(..8).unwrap_or(s).to_ascii_lowercase();
        lower.starts_with("s3://") || lower.starts_with("http://") || lower.starts_with("https://")
    })
}

/// The endpoint set by the front-end (`--endpoint-url`), which takes precedence over the
/// environment.
fn endpoint_setting() -> &'static Mutex<Option<String>> {
    static ENDPOINT: Mutex<Option<String>> = Mutex::new(None);
    &ENDPOINT
}

/// Send `s3://` requests to `url` (an S3-compatible server: `http://127.0.0.1:9000`,
/// `https://objects.example.org`) instead of the environment's or Amazon's endpoint; `None`
/// goes back to those. An endpoint that is no `http(s)://host[:port]` URL is refused with the
/// reason.
pub fn set_endpoint_url(url: Option<&str>) -> Result<(), String> {
    if let Some(u) = url {
        client::parse_endpoint(u)?;
    }
    if let Ok(mut e) = endpoint_setting().lock() {
        *e = url.map(str::to_string);
    }
    Ok(())
}

/// Whether the object store at `path` is a Zarr store (its root holds `zarr.json`, `.zgroup`,
/// `.zattrs` or `.zarray`). Asks the server, the four questions at once (each costs a round
/// trip), and takes the answer as still true for 5 s (a command asks several times); any
/// failure counts as "no" (opening it as a file then says what is wrong).
pub fn is_zarr_store(path: &Path) -> bool {
    static ANSWERS: Remembered<bool> = Remembered::new();
    let name = path.to_string_lossy();
    ANSWERS.get(&name).unwrap_or_else(|| {
        let yes = ask_is_zarr_store(path);
        ANSWERS.put(&name, yes);
        yes
    })
}

/// Answers a server gave about objects (their size, whether a store is there, a metadata
/// document), by name, each taken as still true for 5 s after it came: a command opens the
/// same object many times within seconds (one short-lived reader per page and pass), and each
/// question is a round trip. An object replaced on the server is seen afresh after that.
pub(crate) struct Remembered<T>(OnceLock<Mutex<HashMap<String, (Instant, T)>>>);

impl<T: Clone> Remembered<T> {
    /// How long an answer is taken as true.
    const VALID: Duration = Duration::from_secs(5);

    pub(crate) const fn new() -> Self {
        Remembered(OnceLock::new())
    }

    fn answers(&self) -> std::sync::MutexGuard<'_, HashMap<String, (Instant, T)>> {
        let map = self.0.get_or_init(Default::default);
        map.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The answer about `name` given within the last 5 s.
    pub(crate) fn get(&self, name: &str) -> Option<T> {
        let answers = self.answers();
        let (at, value) = answers.get(name)?;
        (at.elapsed() < Self::VALID).then(|| value.clone())
    }

    /// Keep the answer about `name` just given (answers past their time dropped).
    pub(crate) fn put(&self, name: &str, value: T) {
        let mut answers = self.answers();
        answers.retain(|_, (at, _)| at.elapsed() < Self::VALID);
        answers.insert(name.to_string(), (Instant::now(), value));
    }
}

fn ask_is_zarr_store(path: &Path) -> bool {
    let Ok(object) = client::Object::parse(path) else {
        return false;
    };
    let object = &object;
    std::thread::scope(|scope| {
        let asked: Vec<_> = ["zarr.json", ".zgroup", ".zattrs", ".zarray"]
            .into_iter()
            .map(|key| {
                scope.spawn(move || matches!(client::client().size(object, Some(key)), Ok(Some(_))))
            })
            .collect();
        // The scope waits for the answers not looked at.
        asked.into_iter().any(|h| h.join().unwrap_or(false))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_are_told_from_paths() {
        for url in [
            "s3://b/k.tif",
            "S3://b/k",
            "https://h/x.zarr",
            "http://127.0.0.1:9/b",
        ] {
            assert!(is_url(Path::new(url)), "{url}");
        }
        for path in ["s3/b/k.tif", "./s3:/x", "data/http.tif", "", "s3:/b"] {
            assert!(!is_url(Path::new(path)), "{path}");
        }
    }

    #[test]
    fn answers_are_remembered_by_name() {
        let answers: Remembered<Option<u32>> = Remembered::new();
        assert_eq!(answers.get("s3://b/k"), None);
        answers.put("s3://b/k", Some(3));
        answers.put("s3://b/gone", None);
        assert_eq!(answers.get("s3://b/k"), Some(Some(3)));
        // A missing object is an answer too.
        assert_eq!(answers.get("s3://b/gone"), Some(None));
        assert_eq!(answers.get("s3://b/other"), None);
    }

    #[test]
    fn endpoints_are_checked() {
        assert!(set_endpoint_url(Some("ftp://h")).is_err());
        assert!(set_endpoint_url(Some("not a url")).is_err());
        assert!(set_endpoint_url(Some("http://127.0.0.1:9000")).is_ok());
        assert!(set_endpoint_url(None).is_ok());
    }
}
