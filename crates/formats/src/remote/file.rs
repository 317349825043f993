//! A file read from a path or a URL: the readers of single-file formats (TIFF, CZI, ND2, LIF)
//! take either through [`open_input`]. An object is read in blocks of [`BLOCK`] bytes kept in a
//! cache the whole process shares (at most [`CACHE_BYTES`]), so that the many short-lived readers
//! of one series (one per page decoded) fetch its headers once.

use std::collections::{HashMap, VecDeque};
use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::Path;
use std::sync::{Arc, Mutex, OnceLock};

use super::client::{client, network_error, Object, Range};
use crate::error::{Error, Result};

/// Bytes fetched per request.
const BLOCK: u64 = 4 << 20;
/// Bytes of blocks kept for later reads.
const CACHE_BYTES: usize = 96 << 20;

/// An open input: a local file or an object on a server.
pub(crate) enum Input {
    Local(File),
    Remote(RemoteFile),
}

/// Open `path` (a file, or an `s3://`/`http(s)://` URL) and return it with its length in bytes.
pub(crate) fn open_input(path: &Path) -> Result<(Input, u64)> {
    if super::is_url(path) {
        let object = Object::parse(path).map_err(|e| Error::io(path, e))?;
        let (len, tag) = client()
            .stat(&object, None)
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

/// Blocks of objects by (URL, block index), the least recently used dropped first.
#[derive(Default)]
struct Cache {
    blocks: HashMap<(String, u64), Arc<Vec<u8>>>,
    order: VecDeque<(String, u64)>,
    bytes: usize,
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
}

fn cache() -> &'static Mutex<Cache> {
    static CACHE: OnceLock<Mutex<Cache>> = OnceLock::new();
    CACHE.get_or_init(Mutex::default)
}

impl RemoteFile {
    /// Block `index` of the object, from the cache or the server.
    fn block(&self, index: u64) -> io::Result<Arc<Vec<u8>>> {
        let key = (self.object.0.clone(), index);
        if let Ok(mut c) = cache().lock() {
            if let Some(b) = c.blocks.get(&key).cloned() {
                if let Some(at) = c.order.iter().position(|k| *k == key) {
                    let k = c.order.remove(at).expect("position is in range");
                    c.order.push_back(k);
                }
                return Ok(b);
            }
        }
        let offset = index * BLOCK;
        let len = BLOCK.min(self.len - offset);
        let bytes = client()
            .get(&self.object.1, None, Range::At { offset, len })?
            .ok_or_else(|| network_error(io::ErrorKind::NotFound, "the object is gone"))?;
        if (bytes.len() as u64) < len {
            return Err(network_error(
                io::ErrorKind::Other,
                format!(
                    "the object is shorter than it was ({} bytes at {offset}, {len} expected)",
                    bytes.len()
                ),
            ));
        }
        let block = Arc::new(bytes);
        if let Ok(mut c) = cache().lock() {
            c.insert(key, block.clone(), CACHE_BYTES);
        }
        Ok(block)
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
