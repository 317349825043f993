//! A Zarr store on object storage, for the `zarrs` crates: each key an object below the store's
//! URL (`s3://bucket/ramp.ome.zarr/0/c/0/0/0`), each read one ranged GET. A key the server does
//! not have is a missing key (Zarr: a chunk never written holds the fill value).
//!
//! **Chunks fetched ahead.** A reader going through a series plane by plane names the chunks of
//! the planes it will read next ([`RemoteStore::fetch_ahead`]); they are fetched at the same
//! time, each on its own connection (at most [`AHEAD_IN_FLIGHT`] at once), into a small cache
//! the process shares (at most [`AHEAD_BYTES`], the oldest dropped first), and each is handed once to the read that asks for
//! the whole chunk (a read that asks while it is on its way waits for it). A chunk fetched ahead
//! that fails, or is missing, is simply read again when asked for, with its retries and errors.

use std::collections::{HashMap, HashSet, VecDeque};
use std::path::Path;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, OnceLock};
use std::time::Duration;

use zarrs::storage::byte_range::{ByteRange, ByteRangeIterator};
use zarrs::storage::{Bytes, MaybeBytesIterator, ReadableStorageTraits, StorageError, StoreKey};

use super::client::{client, Object, Range};
use super::Remembered;
use crate::error::{Error, Result};

/// Bytes of chunks fetched ahead and not yet read, kept at most.
const AHEAD_BYTES: usize = 64 << 20;
/// Chunks on their way at most (a plane of many small chunks names many at once: each its own
/// request and thread).
const AHEAD_IN_FLIGHT: usize = 16;

/// Chunks fetched ahead by (store URL/key), in the order they came, and those on their way.
#[derive(Default)]
struct Ahead {
    chunks: HashMap<String, Arc<Vec<u8>>>,
    order: VecDeque<String>,
    bytes: usize,
    fetching: HashSet<String>,
}

impl Ahead {
    /// Keep `chunk`, dropping the oldest beyond [`AHEAD_BYTES`].
    fn insert(&mut self, name: String, chunk: Arc<Vec<u8>>) {
        self.bytes += chunk.len();
        if let Some(old) = self.chunks.insert(name.clone(), chunk) {
            self.bytes -= old.len();
        }
        self.order.push_back(name);
        while self.bytes > AHEAD_BYTES {
            let Some(old) = self.order.pop_front() else {
                break;
            };
            if let Some(c) = self.chunks.remove(&old) {
                self.bytes -= c.len();
            }
        }
        // Names of chunks already taken.
        if self.order.len() > 4 * self.chunks.len() + 64 {
            let chunks = &self.chunks;
            self.order.retain(|n| chunks.contains_key(n));
        }
    }
}

/// Whether `key` names a metadata document (Zarr v3 `zarr.json`, v2 `.zgroup`, `.zattrs`,
/// `.zarray`) rather than a chunk.
fn is_metadata(key: &StoreKey) -> bool {
    let last = key.as_str().rsplit('/').next().unwrap_or("");
    matches!(last, "zarr.json" | ".zgroup" | ".zattrs" | ".zarray")
}

/// The chunks fetched ahead, and the signal that one has come (or failed).
fn ahead() -> &'static (Mutex<Ahead>, Condvar) {
    static AHEAD: OnceLock<(Mutex<Ahead>, Condvar)> = OnceLock::new();
    AHEAD.get_or_init(Default::default)
}

/// The chunks fetched ahead, locked (a poisoned lock is taken over: it holds whole chunks).
fn locked() -> MutexGuard<'static, Ahead> {
    ahead().0.lock().unwrap_or_else(|e| e.into_inner())
}

/// The store at a URL.
pub(crate) struct RemoteStore {
    /// The store's URL as given (names its chunks in the shared cache).
    name: String,
    root: Object,
    /// Keys asked for that the server does not have.
    missing: Mutex<HashSet<String>>,
}

impl RemoteStore {
    /// The store whose root is `path` (`s3://…`, `https://…`).
    pub(crate) fn new(path: &Path) -> Result<RemoteStore> {
        let root = Object::parse(path).map_err(|e| Error::io(path, e))?;
        Ok(RemoteStore {
            name: path.to_string_lossy().trim_end_matches('/').to_string(),
            root,
            missing: Mutex::default(),
        })
    }

    /// Fetch the whole objects at `keys` (chunks the reader will ask for next) at the same
    /// time, each on its own thread, unless kept or on their way, and no more than
    /// [`AHEAD_IN_FLIGHT`] at once (the first ones named first).
    pub(crate) fn fetch_ahead(self: &Arc<Self>, keys: &[StoreKey]) {
        let mut a = locked();
        let mut start = Vec::new();
        for key in keys {
            let name = format!("{}/{}", self.name, key.as_str());
            if a.bytes >= AHEAD_BYTES || a.fetching.len() >= AHEAD_IN_FLIGHT {
                break;
            }
            if !a.chunks.contains_key(&name) && a.fetching.insert(name.clone()) {
                start.push((name, key.clone()));
            }
        }
        drop(a);
        for (name, key) in start {
            let store = self.clone();
            let spawned = std::thread::Builder::new()
                .name("contactscope-zarr-ahead".into())
                .spawn({
                    let name = name.clone();
                    move || {
                        // A fetch that panics ends like one that failed: no reader waits on.
                        let got = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                            client().get(&store.root, Some(key.as_str()), Range::All)
                        }));
                        let mut a = locked();
                        a.fetching.remove(&name);
                        if let Ok(Ok(Some(bytes))) = got {
                            a.insert(name, Arc::new(bytes));
                        }
                        drop(a);
                        ahead().1.notify_all();
                    }
                });
            if spawned.is_err() {
                locked().fetching.remove(&name);
                ahead().1.notify_all();
            }
        }
    }

    /// The whole object at `key` if it was fetched ahead (waiting for it while it is on its
    /// way), taken out of the cache; `None` otherwise.
    fn take_ahead(&self, key: &StoreKey) -> Option<Arc<Vec<u8>>> {
        let name = format!("{}/{}", self.name, key.as_str());
        let mut a = locked();
        loop {
            if let Some(chunk) = a.chunks.remove(&name) {
                a.bytes -= chunk.len();
                return Some(chunk);
            }
            if !a.fetching.contains(&name) {
                return None;
            }
            // The timeout only bounds a wait whose wake-up was missed.
            a = ahead()
                .1
                .wait_timeout(a, Duration::from_millis(200))
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }

    /// The metadata document at `key` (`None`: the server has none), from the server or as it
    /// answered within the last few seconds ([`Remembered`]).
    fn metadata(&self, key: &StoreKey) -> std::result::Result<Option<Vec<u8>>, StorageError> {
        static DOCUMENTS: Remembered<Option<Vec<u8>>> = Remembered::new();
        let name = format!("{}/{}", self.name, key.as_str());
        let doc = match DOCUMENTS.get(&name) {
            Some(doc) => doc,
            None => {
                let doc = client().get(&self.root, Some(key.as_str()), Range::All)?;
                DOCUMENTS.put(&name, doc.clone());
                doc
            }
        };
        if doc.is_none() {
            self.note_missing(key);
        }
        Ok(doc)
    }

    fn note_missing(&self, key: &StoreKey) {
        if let Ok(mut m) = self.missing.lock() {
            m.insert(key.as_str().to_string());
        }
    }

    /// Whether `key` was asked for and found missing.
    pub(crate) fn was_missing(&self, key: &StoreKey) -> bool {
        self.missing.lock().is_ok_and(|m| m.contains(key.as_str()))
    }
}

impl ReadableStorageTraits for RemoteStore {
    fn get_partial_many<'a>(
        &'a self,
        key: &StoreKey,
        byte_ranges: ByteRangeIterator<'a>,
    ) -> std::result::Result<MaybeBytesIterator<'a>, StorageError> {
        let ranges: Vec<ByteRange> = byte_ranges.collect();
        let whole = matches!(ranges[..], [ByteRange::FromStart(0, None)]);
        if whole && is_metadata(key) {
            // Asked for by every reader the series opens: answered once per few seconds.
            let answer = self.metadata(key)?;
            return Ok(answer.map(|b| {
                Box::new(std::iter::once(Ok(Bytes::from(b)))) as Box<dyn Iterator<Item = _>>
            }));
        }
        if whole {
            if let Some(chunk) = self.take_ahead(key) {
                let whole = Bytes::from(Arc::unwrap_or_clone(chunk));
                return Ok(Some(Box::new(std::iter::once(Ok(whole)))));
            }
        }
        let mut parts = Vec::new();
        for r in ranges {
            let range = match r {
                ByteRange::FromStart(0, None) => Range::All,
                ByteRange::FromStart(offset, None) => Range::From(offset),
                ByteRange::FromStart(offset, Some(len)) => Range::At { offset, len },
                ByteRange::Suffix(len) => Range::Suffix(len),
            };
            match client().get(&self.root, Some(key.as_str()), range)? {
                Some(bytes) => parts.push(Ok(Bytes::from(bytes))),
                None => {
                    if let Ok(mut m) = self.missing.lock() {
                        m.insert(key.as_str().to_string());
                    }
                    return Ok(None);
                }
            }
        }
        Ok(Some(Box::new(parts.into_iter())))
    }

    fn size_key(&self, key: &StoreKey) -> std::result::Result<Option<u64>, StorageError> {
        Ok(client().size(&self.root, Some(key.as_str()))?)
    }

    fn supports_get_partial(&self) -> bool {
        true
    }
}
