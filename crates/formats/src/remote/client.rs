//! Requests to object storage: which URL an object has, its size (HEAD) and a byte range of it
//! (GET with `Range`), presigned for S3 and retried when the network fails.

use std::io::{self, Read};
use std::path::Path;
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use rusty_s3::{Bucket, Credentials, S3Action, UrlStyle};
use ureq::tls::{Certificate, RootCerts, TlsConfig, TlsProvider};
use ureq::Agent;

use super::ATTEMPTS;

/// How long a presigned URL stays valid (each request is signed just before it is sent).
const SIGNED_FOR: Duration = Duration::from_secs(15 * 60);
/// The largest single response body read (a whole object asked for without a length: Zarr
/// metadata and chunks, which the formats' own limits bound further).
const MAX_BODY: u64 = 1 << 31;

/// A failure to get an object from its server (as the source of an `io::Error`), so that the
/// readers report it as such and not as a broken file.
#[derive(Debug)]
pub(crate) struct NetworkError(String);

impl std::fmt::Display for NetworkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NetworkError {}

/// An `io::Error` of `kind` carrying a [`NetworkError`].
pub(crate) fn network_error(kind: io::ErrorKind, text: impl Into<String>) -> io::Error {
    io::Error::new(kind, NetworkError(text.into()))
}

/// Whether `e` is a failure to get an object from its server.
pub(crate) fn is_network_error(e: &io::Error) -> bool {
    e.get_ref().is_some_and(|inner| inner.is::<NetworkError>())
}

/// Where an object (or the root of a store of objects) is.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Object {
    /// In an S3 bucket, under `key` (no leading `/`).
    S3 { bucket: String, key: String },
    /// At a plain HTTP(S) URL (no trailing `/`).
    Http { url: String },
}

impl Object {
    /// Parse a URL given as a path (`s3://bucket/key`, `https://host/path`).
    pub(crate) fn parse(path: &Path) -> io::Result<Object> {
        let s = path
            .to_str()
            .ok_or_else(|| io::Error::other("the URL is not valid UTF-8"))?;
        let (scheme, rest) = s
            .split_once("://")
            .ok_or_else(|| io::Error::other("not a URL (s3://, http:// or https://)"))?;
        match scheme.to_ascii_lowercase().as_str() {
            "s3" => {
                let (bucket, key) = rest.split_once('/').unwrap_or((rest, ""));
                if bucket.is_empty() {
                    return Err(io::Error::other("the s3:// URL names no bucket"));
                }
                Ok(Object::S3 {
                    bucket: bucket.to_string(),
                    key: key.trim_matches('/').to_string(),
                })
            }
            "http" | "https" => {
                if rest.is_empty() || rest.starts_with('/') {
                    return Err(io::Error::other("the URL names no host"));
                }
                Ok(Object::Http {
                    url: s.trim_end_matches('/').to_string(),
                })
            }
            other => Err(io::Error::other(format!(
                "URL scheme '{other}' is not read (s3, http, https)"
            ))),
        }
    }

    /// This object's key, or that of `child` below it (a store's `zarr.json`).
    fn key(&self, child: Option<&str>) -> String {
        let base = match self {
            Object::S3 { key, .. } => key.as_str(),
            Object::Http { url } => url.as_str(),
        };
        match child {
            Some(c) if base.is_empty() => c.to_string(),
            Some(c) => format!("{base}/{c}"),
            None => base.to_string(),
        }
    }
}

/// Check an endpoint URL: `http(s)://host[:port][/path]`.
pub(crate) fn parse_endpoint(url: &str) -> Result<url::Url, String> {
    let parsed = url::Url::parse(url).map_err(|e| {
        format!("endpoint URL '{url}': {e}; expected http://host[:port] or https://host[:port]")
    })?;
    if !matches!(parsed.scheme(), "http" | "https") || parsed.host_str().is_none() {
        return Err(format!(
            "endpoint URL '{url}': expected http://host[:port] or https://host[:port]"
        ));
    }
    Ok(parsed)
}

/// A non-empty environment variable.
fn env(name: &str) -> Option<String> {
    std::env::var(name).ok().filter(|v| !v.trim().is_empty())
}

/// The S3 settings of this moment (see the module documentation for their sources).
struct S3Settings {
    endpoint: url::Url,
    style: UrlStyle,
    region: String,
    credentials: Option<Credentials>,
}

fn s3_settings() -> io::Result<S3Settings> {
    let region = env("AWS_REGION")
        .or_else(|| env("AWS_DEFAULT_REGION"))
        .unwrap_or_else(|| "us-east-1".into());
    let custom = super::endpoint_setting()
        .lock()
        .ok()
        .and_then(|e| e.clone())
        .or_else(|| env("AWS_ENDPOINT_URL_S3"))
        .or_else(|| env("AWS_ENDPOINT_URL"));
    let (endpoint, style) = match custom {
        Some(u) => (
            parse_endpoint(&u).map_err(io::Error::other)?,
            UrlStyle::Path,
        ),
        None => (
            parse_endpoint(&format!("https://s3.{region}.amazonaws.com"))
                .map_err(io::Error::other)?,
            UrlStyle::VirtualHost,
        ),
    };
    let unsigned = env("AWS_NO_SIGN_REQUEST")
        .is_some_and(|v| matches!(v.to_ascii_lowercase().as_str(), "1" | "true" | "yes"));
    let credentials = match (
        unsigned,
        env("AWS_ACCESS_KEY_ID"),
        env("AWS_SECRET_ACCESS_KEY"),
    ) {
        (false, Some(key), Some(secret)) => Some(match env("AWS_SESSION_TOKEN") {
            Some(token) => Credentials::new_with_token(key, secret, token),
            None => Credentials::new(key, secret),
        }),
        _ => None,
    };
    Ok(S3Settings {
        endpoint,
        style,
        region,
        credentials,
    })
}

/// A byte range of an object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Range {
    /// The whole object.
    All,
    /// `len` bytes from `offset` (fewer at the end of the object).
    At { offset: u64, len: u64 },
    /// From `offset` to the end.
    From(u64),
    /// The last `len` bytes.
    Suffix(u64),
}

impl Range {
    fn header(self) -> Option<String> {
        match self {
            Range::All => None,
            Range::At { offset, len } => {
                Some(format!("bytes={offset}-{}", offset + len.max(1) - 1))
            }
            Range::From(offset) => Some(format!("bytes={offset}-")),
            Range::Suffix(len) => Some(format!("bytes=-{len}")),
        }
    }
}

/// What one try of a request gave.
enum Try<T> {
    Done(T),
    /// Worth another try (the network, or the server's load).
    Again(io::Error),
    /// Final (missing permission, a malformed request).
    Fail(io::Error),
}

/// The HTTP client, shared by every reader of the process (it pools connections).
pub(crate) struct Client {
    agent: Agent,
}

/// The process's client.
pub(crate) fn client() -> &'static Client {
    static CLIENT: OnceLock<Client> = OnceLock::new();
    CLIENT.get_or_init(Client::new)
}

impl Client {
    fn new() -> Client {
        // The system's root certificates (what curl and the AWS tools trust).
        let roots: Vec<Certificate<'static>> = rustls_native_certs::load_native_certs()
            .certs
            .iter()
            .map(|c| Certificate::from_der(c.as_ref()).to_owned())
            .collect();
        let tls = TlsConfig::builder()
            .provider(TlsProvider::Rustls)
            .unversioned_rustls_crypto_provider(Arc::new(rustls::crypto::ring::default_provider()))
            .root_certs(RootCerts::Specific(Arc::new(roots)))
            .build();
        let agent = Agent::config_builder()
            .tls_config(tls)
            .http_status_as_error(false)
            .timeout_connect(Some(Duration::from_secs(15)))
            .timeout_recv_response(Some(Duration::from_secs(60)))
            .timeout_recv_body(Some(Duration::from_secs(120)))
            // Connections kept open for the next requests: enough for every reader's read-ahead
            // (`file::READ_AHEAD` blocks at once) on a few threads, so that each block does not
            // pay a new connection (and TLS handshake).
            .max_idle_connections_per_host(4 * super::file::READ_AHEAD as usize)
            .max_idle_connections(8 * super::file::READ_AHEAD as usize)
            .build()
            .into();
        Client { agent }
    }

    /// The URL of a request (presigned for S3 with credentials).
    fn url(&self, object: &Object, child: Option<&str>, head: bool) -> io::Result<String> {
        match object {
            Object::Http { .. } => Ok(object.key(child)),
            Object::S3 { bucket, .. } => {
                let s = s3_settings()?;
                let bucket = Bucket::new(s.endpoint, s.style, bucket.clone(), s.region)
                    .map_err(|e| io::Error::other(format!("bucket name: {e}")))?;
                let key = object.key(child);
                let creds = s.credentials.as_ref();
                let url = if head {
                    rusty_s3::actions::HeadObject::new(&bucket, creds, &key).sign(SIGNED_FOR)
                } else {
                    rusty_s3::actions::GetObject::new(&bucket, creds, &key).sign(SIGNED_FOR)
                };
                Ok(url.to_string())
            }
        }
    }

    /// Retry `once` while it asks to, pausing 0.1, 0.2, 0.4, … s between tries.
    fn retried<T>(&self, mut once: impl FnMut() -> io::Result<Try<T>>) -> io::Result<T> {
        let mut last = None;
        for attempt in 0..ATTEMPTS {
            if attempt > 0 {
                std::thread::sleep(Duration::from_millis(100 << (attempt - 1)));
            }
            match once()? {
                Try::Done(v) => return Ok(v),
                Try::Fail(e) => return Err(network_error(io::ErrorKind::Other, e.to_string())),
                Try::Again(e) => last = Some(e),
            }
        }
        let e = last.unwrap_or_else(|| io::Error::other("no try made"));
        Err(network_error(
            io::ErrorKind::Other,
            format!("the server could not be read ({ATTEMPTS} tries): {e}"),
        ))
    }

    /// The size in bytes of an object (`child` below `object`), `None` when there is none.
    pub(crate) fn size(&self, object: &Object, child: Option<&str>) -> io::Result<Option<u64>> {
        Ok(self.stat(object, child)?.map(|(len, _)| len))
    }

    /// The size in bytes and the version tag (`ETag`, `Last-Modified`) of an object, `None`
    /// when there is none.
    pub(crate) fn stat(
        &self,
        object: &Object,
        child: Option<&str>,
    ) -> io::Result<Option<(u64, String)>> {
        let url = self.url(object, child, true)?;
        self.retried(|| {
            let response = match self.agent.head(&url).call() {
                Ok(r) => r,
                Err(e) => return Ok(transport(e)),
            };
            let status = response.status().as_u16();
            Ok(match status {
                200..=299 => match content_length(&response) {
                    Some(n) => {
                        let tag = ["etag", "last-modified"]
                            .iter()
                            .filter_map(|h| response.headers().get(*h)?.to_str().ok())
                            .collect::<Vec<_>>()
                            .join(" ");
                        Try::Done(Some((n, tag)))
                    }
                    None => Try::Fail(io::Error::other(
                        "the server gives no Content-Length for the object",
                    )),
                },
                404 => Try::Done(None),
                _ => refused(status),
            })
        })
    }

    /// The bytes of `range` of an object (`child` below `object`), `None` when there is none.
    /// Exactly the bytes asked for (fewer only at the end of the object), whatever the server
    /// sends: a whole object in answer to a range request is cut to the range.
    pub(crate) fn get(
        &self,
        object: &Object,
        child: Option<&str>,
        range: Range,
    ) -> io::Result<Option<Vec<u8>>> {
        if let Range::At { len: 0, .. } = range {
            return Ok(Some(Vec::new()));
        }
        let url = self.url(object, child, false)?;
        self.retried(|| {
            let mut request = self.agent.get(&url);
            if let Some(h) = range.header() {
                request = request.header("Range", h);
            }
            let response = match request.call() {
                Ok(r) => r,
                Err(e) => return Ok(transport(e)),
            };
            let status = response.status().as_u16();
            let partial = match status {
                206 => true,
                200..=299 => false,
                404 => return Ok(Try::Done(None)),
                // A range past the end: an empty object, or an offset at its end.
                416 => return Ok(Try::Done(Some(Vec::new()))),
                _ => return Ok(refused(status)),
            };
            let length = content_length(&response);
            let total = if partial { None } else { length };
            let mut reader = response.into_body().into_reader();
            // A server that ignored the range sent the whole object: skip to the range.
            let (skip, want) = match (partial, range) {
                (_, Range::All) => (0, length),
                (true, _) => (0, length),
                (false, Range::At { offset, len }) => (offset, Some(len)),
                (false, Range::From(offset)) => (offset, total.map(|t| t.saturating_sub(offset))),
                (false, Range::Suffix(len)) => match total {
                    Some(t) => (t.saturating_sub(len), Some(len.min(t))),
                    None => {
                        return Ok(Try::Fail(io::Error::other(
                            "the server ignores byte ranges and gives no Content-Length",
                        )))
                    }
                },
            };
            if skip > 0 {
                match io::copy(&mut (&mut reader).take(skip), &mut io::sink()) {
                    Ok(n) if n == skip => {}
                    Ok(_) => return Ok(Try::Done(Some(Vec::new()))),
                    Err(e) => return Ok(Try::Again(e)),
                }
            }
            let limit = want.unwrap_or(MAX_BODY).min(MAX_BODY);
            let mut body = Vec::with_capacity(limit.min(1 << 26) as usize);
            match (&mut reader).take(limit + 1).read_to_end(&mut body) {
                Ok(_) => {}
                Err(e) => return Ok(Try::Again(e)),
            }
            if body.len() as u64 > limit {
                if want.is_some() && !partial {
                    body.truncate(limit as usize);
                } else {
                    return Ok(Try::Fail(io::Error::other(format!(
                        "the server sent more than the {limit} bytes asked for"
                    ))));
                }
            }
            // A body cut short (the connection dropped before its Content-Length).
            if (partial || range == Range::All) && length.is_some_and(|n| (body.len() as u64) < n) {
                return Ok(Try::Again(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    "the connection closed before the whole response arrived",
                )));
            }
            Ok(Try::Done(Some(body)))
        })
    }
}

/// The Content-Length of a response.
fn content_length<B>(response: &ureq::http::Response<B>) -> Option<u64> {
    response
        .headers()
        .get("content-length")?
        .to_str()
        .ok()?
        .trim()
        .parse()
        .ok()
}

/// A transport failure (no HTTP status): the network (a refused, dropped or stalled connection,
/// a timeout, a response cut in its headers) is worth another try; anything else (a malformed
/// URL, a TLS handshake or certificate refused, a response too large) is final.
fn transport<T>(e: ureq::Error) -> Try<T> {
    match e {
        ureq::Error::Io(io) => Try::Again(io),
        ureq::Error::Timeout(_)
        | ureq::Error::ConnectionFailed
        | ureq::Error::HostNotFound
        | ureq::Error::Protocol(_)
        | ureq::Error::BodyStalled => Try::Again(io::Error::other(e.to_string())),
        other => Try::Fail(io::Error::other(other.to_string())),
    }
}

/// What an HTTP error status says, retried when the server may recover.
fn refused<T>(status: u16) -> Try<T> {
    let text = match status {
        403 => "access denied (HTTP 403): the credentials (AWS_ACCESS_KEY_ID, \
                AWS_SECRET_ACCESS_KEY) are missing or do not grant reading this object"
            .to_string(),
        401 => "the server asks for credentials (HTTP 401)".to_string(),
        400 => "the server refused the request (HTTP 400): check the bucket's region \
                (AWS_REGION) and the endpoint URL"
            .to_string(),
        s => format!("the server answered HTTP {s}"),
    };
    let e = io::Error::other(text);
    if matches!(status, 408 | 429 | 500..=599) {
        Try::Again(e)
    } else {
        Try::Fail(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_parse_into_objects() {
        assert_eq!(
            Object::parse(Path::new("s3://lab-data/2026/ramp.ome.zarr/")).unwrap(),
            Object::S3 {
                bucket: "lab-data".into(),
                key: "2026/ramp.ome.zarr".into()
            }
        );
        let o = Object::parse(Path::new("s3://b")).unwrap();
        assert_eq!(o.key(Some("zarr.json")), "zarr.json");
        let h = Object::parse(Path::new("https://h.org/x.zarr/")).unwrap();
        assert_eq!(h.key(Some("0/c/0")), "https://h.org/x.zarr/0/c/0");
        for bad in ["s3:///k", "https:///p", "ftp://h/x", "s3:/b"] {
            assert!(Object::parse(Path::new(bad)).is_err(), "{bad}");
        }
    }

    #[test]
    fn ranges_become_headers() {
        assert_eq!(Range::All.header(), None);
        let at = Range::At { offset: 8, len: 4 };
        assert_eq!(at.header().as_deref(), Some("bytes=8-11"));
        assert_eq!(Range::From(5).header().as_deref(), Some("bytes=5-"));
        assert_eq!(Range::Suffix(16).header().as_deref(), Some("bytes=-16"));
    }
}
