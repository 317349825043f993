//! A file read from a path or a URL: the readers of single-file formats (TIFF, CZI, ND2, LIF)
//! take either through [`open_input`]. An object is read in blocks of [`BLOCK`] bytes kept in a
//! cache the whole process shares (at most [`CACHE_BYTES`]), so that the many short-lived readers
//! of one series (one per page decoded) fetch its headers once.
//!
//! **Read-ahead.** A server far away answers each request after a round trip and sends one
//! response no faster than one connection carries (tens of milliseconds and about 100 MB/s
//! for a cloud bucket); a reader that asked for one block at a time would wait for both on
//! every block. A block missed right after the one before it (a reader going through the file
//! in order: a TIFF's pages, one after another) is therefore fetched together with the next
//! [`READ_AHEAD`] − 1 blocks, each on its own connection at the same time; the reader goes on
//! as soon as its own block is in, and a reader that needs a block still on its way waits for
//! it rather than asking again. A block missed out of order (a header at the end of a file) is
//! fetched alone. A block fetched ahead that fails is simply fetched again when it is read (with
//! its retries and, if it keeps failing, its error).

use std::collections::{HashMap, HashSet, VecDeque};
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::{Arc, Condvar, Mutex, MutexGuard, OnceLock};
use std::time::Duration;

use super::client::{client, network_error, Object, Range};
use super::Remembered;
use crate::error::{Error, Result};

/// Bytes fetched per request.
const BLOCK: u64 = 4 << 20;
/// Bytes of blocks kept for later reads.
const CACHE_BYTES: usize = 96 << 20;
/// Blocks fetched at once when a reader goes through an object in order (module docs): its own
/// and the next ones, at most 24 MiB on the way per reader.
pub(crate) const READ_AHEAD: u64 = 8;

/// An open input: a local file or an object on a server.
pub(crate) enum Input {
    Local(File),
    Remote(RemoteFile),
}

/// The length and version tag of `object` (named `url`): asked of the server, or as it answered
/// within the last few seconds ([`Remembered`]).
fn stat(url: &str, object: &Object) -> io::Result<Option<(u64, String)>> {
    static STATS: Remembered<(u64, String)> = Remembered::new();
    if let Some(known) = STATS.get(url) {
        return Ok(Some(known));
    }
    let answer = client().stat(object, None)?;
    if let Some(known) = &answer {
        STATS.put(url, known.clone());
    }
    Ok(answer)
}

/// Open `path` (a file, or an `s3://`/`http(s)://` URL) and return it with its length in bytes.
pub(crate) fn open_input(path: &Path) -> Result<(Input, u64)> {
    if super::is_url(path) {
        let object = Object::parse(path).map_err(|e| Error::io(path, e))?;
        let (len, tag) = stat(&path.to_string_lossy(), &object)
            .map_err(|e| Error::io(path, e))?
            .ok_or_else(|| {
                Error::io(
                    path,
                    io::Error::new(io::ErrorKind::NotFound, "no such object (HTTP 404)"),
                )
            })?;
        // Cached blocks belong to this version of the object: one replaced on the server since
        // (another ETag or length) is read afresh.
        let name = format!("{} {len} {tag}", path.to_string_lossy());
        return Ok((
            Input::Remote(RemoteFile {
                object: Arc::new((name, object)),
                len,
                pos: 0,
            }),
            len,
        ));
    }
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    Ok((Input::Local(file), len))
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self {
            Input::Local(f) => f.read(buf),
            Input::Remote(r) => r.read(buf),
        }
    }
}

impl Seek for Input {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        match self {
            Input::Local(f) => f.seek(to),
            Input::Remote(r) => r.seek(to),
        }
    }
}

/// An object read as a file.
pub(crate) struct RemoteFile {
    /// (URL as given with the object's length and version tag, where it is).
    object: Arc<(String, Object)>,
    len: u64,
    pos: u64,
}

/// Blocks of objects by (URL, block index), the least recently used dropped first, and the
/// blocks being fetched.
#[derive(Default)]
struct Cache {
    blocks: HashMap<(String, u64), Arc<Vec<u8>>>,
    order: VecDeque<(String, u64)>,
    bytes: usize,
    fetching: HashSet<(String, u64)>,
}

impl Cache {
    /// Keep `block`, dropping the least recently used ones beyond `capacity` bytes. Another
    /// reader may have fetched the same block meanwhile: one copy is kept.
    fn insert(&mut self, key: (String, u64), block: Arc<Vec<u8>>, capacity: usize) {
        self.bytes += block.len();
        match self.blocks.insert(key.clone(), block) {
            Some(old) => self.bytes -= old.len(),
            None => self.order.push_back(key),
        }
        while self.bytes > capacity {
            let Some(old) = self.order.pop_front() else {
                break;
            };
            if let Some(b) = self.blocks.remove(&old) {
                self.bytes -= b.len();
            }
        }
    }

    /// Block `key`, marked as used most recently.
    fn take(&mut self, key: &(String, u64)) -> Option<Arc<Vec<u8>>> {
        let block = self.blocks.get(key).cloned()?;
        if let Some(at) = self.order.iter().position(|k| k == key) {
            let k = self.order.remove(at).expect("position is in range");
            self.order.push_back(k);
        }
        Some(block)
    }

    /// The blocks after block `index` of `name` (of `blocks` in all) to fetch ahead: where the
    /// block before it has been read or is on its way (a reader going through the object in
    /// order), those of the next [`READ_AHEAD`] − 1 that are neither kept nor on their way;
    /// else none.
    fn ahead(&self, name: &str, index: u64, blocks: u64) -> Vec<u64> {
        let known = |i: u64| {
            let key = (name.to_string(), i);
            self.blocks.contains_key(&key) || self.fetching.contains(&key)
        };
        if index > 0 && !known(index - 1) {
            return Vec::new();
        }
        (index + 1..blocks.min(index + READ_AHEAD))
            .filter(|&i| !known(i))
            .collect()
    }
}

/// The shared cache, and the signal that a block fetched by one reader has come (or failed).
fn cache() -> &'static (Mutex<Cache>, Condvar) {
    static CACHE: OnceLock<(Mutex<Cache>, Condvar)> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// The cache, locked (a poisoned lock is taken over: the cache holds only whole blocks).
fn locked() -> MutexGuard<'static, Cache> {
    cache().0.lock().unwrap_or_else(|e| e.into_inner())
}

/// Fetch block `index` (of `len` bytes of the object) from the server.
fn fetch(object: &Object, len: u64, index: u64) -> io::Result<Arc<Vec<u8>>> {
    let offset = index * BLOCK;
    let want = BLOCK.min(len - offset);
    let bytes = client()
        .get(object, None, Range::At { offset, len: want })?
        .ok_or_else(|| network_error(io::ErrorKind::NotFound, "the object is gone"))?;
    if (bytes.len() as u64) < want {
        return Err(network_error(
            io::ErrorKind::Other,
            format!(
                "the object is shorter than it was ({} bytes at {offset}, {want} expected)",
                bytes.len()
            ),
        ));
    }
    Ok(Arc::new(bytes))
}

/// Fetch block `index` of `object` (named `name`, `len` bytes) and hand it to the cache
/// ([`arrived`]). A fetch that panics ends as an error, so that no reader waits for a block that
/// will never come.
fn fetch_and_keep(name: &str, object: &Object, len: u64, index: u64) -> io::Result<Arc<Vec<u8>>> {
    let fetched =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| fetch(object, len, index)))
            .unwrap_or_else(|_| Err(io::Error::other("fetching the block failed")));
    arrived((name.to_string(), index), &fetched);
    fetched
}

/// Keep what fetching `key` gave (nothing after a failure), end its fetching and wake the
/// readers waiting for it.
fn arrived(key: (String, u64), fetched: &io::Result<Arc<Vec<u8>>>) {
    let mut c = locked();
    c.fetching.remove(&key);
    if let Ok(block) = fetched {
        c.insert(key, block.clone(), CACHE_BYTES);
    }
    drop(c);
    cache().1.notify_all();
}

impl RemoteFile {
    /// Block `index` of the object, from the cache, from another reader's fetch, or from the
    /// server; read in order, the blocks after it are fetched meanwhile (module docs).
    fn block(&self, index: u64) -> io::Result<Arc<Vec<u8>>> {
        let name = &self.object.0;
        let key = (name.clone(), index);
        let mut c = locked();
        let ahead = c.ahead(name, index, self.len.div_ceil(BLOCK));
        for &i in &ahead {
            c.fetching.insert((name.clone(), i));
        }
        drop(c);
        for i in ahead {
            let (object, len) = (self.object.clone(), self.len);
            let spawned = std::thread::Builder::new()
                .name("contactscope-read-ahead".into())
                .spawn(move || {
                    let _ = fetch_and_keep(&object.0, &object.1, len, i);
                });
            if spawned.is_err() {
                // No thread to be had: the block is fetched when it is read.
                arrived((name.clone(), i), &Err(io::Error::other("no thread")));
            }
        }
        let mut c = locked();
        loop {
            if let Some(b) = c.take(&key) {
                return Ok(b);
            }
            if !c.fetching.contains(&key) {
                break;
            }
            // On its way: wait for it (or for its fetch to fail, then fetch it here). The
            // timeout only bounds a wait whose wake-up was missed.
            c = cache()
                .1
                .wait_timeout(c, Duration::from_millis(200))
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
        c.fetching.insert(key.clone());
        drop(c);
        fetch_and_keep(name, &self.object.1, self.len, index)
    }
}

impl Read for RemoteFile {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.pos >= self.len || buf.is_empty() {
            return Ok(0);
        }
        let block = self.block(self.pos / BLOCK)?;
        let start = (self.pos % BLOCK) as usize;
        let n = buf.len().min(block.len() - start);
        buf[..n].copy_from_slice(&block[start..start + n]);
        self.pos += n as u64;
        Ok(n)
    }
}

impl Seek for RemoteFile {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let target = match to {
            SeekFrom::Start(n) => Some(n),
            SeekFrom::End(d) => self.len.checked_add_signed(d),
            SeekFrom::Current(d) => self.pos.checked_add_signed(d),
        };
        self.pos = target
            .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "seek before the start"))?;
        Ok(self.pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_fetched_ahead_only_for_a_reader_going_in_order() {
        let mut c = Cache::default();
        let a = |i: u64| ("a".to_string(), i);
        // The first block of an object: the next READ_AHEAD − 1 with it.
        assert_eq!(c.ahead("a", 0, 100), (1..READ_AHEAD).collect::<Vec<_>>());
        // A block whose predecessor is neither kept nor on its way (a header at the end of the
        // file): alone.
        assert!(c.ahead("a", 50, 100).is_empty());
        // In order: the blocks after it, less those kept or on their way, not past the end.
        c.insert(a(49), Arc::new(vec![0; 4]), 1 << 20);
        c.fetching.insert(a(51));
        c.insert(a(53), Arc::new(vec![0; 4]), 1 << 20);
        let ahead = c.ahead("a", 50, 100);
        assert_eq!(ahead[..3], [52, 54, 55]);
        assert_eq!(ahead.len() as u64, READ_AHEAD - 1 - 2);
        assert_eq!(c.ahead("a", 50, 53), vec![52]);
        // Another object's blocks say nothing about this one's order.
        assert!(c.ahead("b", 50, 100).is_empty());
        // A block on its way counts as read for the order.
        c.fetching.insert(a(70));
        assert_eq!(c.ahead("a", 71, 100).len() as u64, READ_AHEAD - 1);
    }

    #[test]
    fn the_cache_counts_each_block_once_and_keeps_to_its_capacity() {
        let mut c = Cache::default();
        let block = |n: usize| Arc::new(vec![0u8; n]);
        c.insert(("a".into(), 0), block(10), 25);
        c.insert(("a".into(), 0), block(10), 25);
        assert_eq!((c.bytes, c.blocks.len(), c.order.len()), (10, 1, 1));
        c.insert(("a".into(), 1), block(10), 25);
        c.insert(("b".into(), 0), block(10), 25);
        // Over 25 bytes: the oldest block goes.
        assert_eq!(c.bytes, 20);
        assert!(!c.blocks.contains_key(&("a".into(), 0)));
        assert_eq!(c.order.len(), c.blocks.len());
    }
}
