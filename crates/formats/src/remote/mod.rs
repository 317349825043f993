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
    type Answers = Mutex<HashMap<String, (Instant, bool)>>;
    static ANSWERS: OnceLock<Answers> = OnceLock::new();
    let answers = ANSWERS.get_or_init(Default::default);
    let name = path.to_string_lossy().to_string();
    if let Some((at, yes)) = answers.lock().ok().and_then(|a| a.get(&name).copied()) {
        if at.elapsed() < ANSWER_VALID {
            return yes;
        }
    }
    let yes = ask_is_zarr_store(path);
    if let Ok(mut a) = answers.lock() {
        a.retain(|_, (at, _)| at.elapsed() < ANSWER_VALID);
        a.insert(name, (Instant::now(), yes));
    }
    yes
}

/// How long an answer about an object (its size, whether a store is there) is taken as true.
pub(crate) const ANSWER_VALID: Duration = Duration::from_secs(5);

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
    fn endpoints_are_checked() {
        assert!(set_endpoint_url(Some("ftp://h")).is_err());
        assert!(set_endpoint_url(Some("not a url")).is_err());
        assert!(set_endpoint_url(Some("http://127.0.0.1:9000")).is_ok());
        assert!(set_endpoint_url(None).is_ok());
    }
}
