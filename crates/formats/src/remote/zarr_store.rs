//! A Zarr store on object storage, for the `zarrs` crates: each key an object below the store's
//! URL (`s3://bucket/ramp.ome.zarr/0/c/0/0/0`), each read one ranged GET. A key the server does
//! not have is a missing key (Zarr: a chunk never written holds the fill value).

use std::collections::HashSet;
use std::path::Path;
use std::sync::Mutex;

use zarrs::storage::byte_range::{ByteRange, ByteRangeIterator};
use zarrs::storage::{Bytes, MaybeBytesIterator, ReadableStorageTraits, StorageError, StoreKey};

use super::client::{client, Object, Range};
use crate::error::{Error, Result};

/// The store at a URL.
pub(crate) struct RemoteStore {
    root: Object,
    /// Keys asked for that the server does not have.
    missing: Mutex<HashSet<String>>,
}

impl RemoteStore {
    /// The store whose root is `path` (`s3://…`, `https://…`).
    pub(crate) fn new(path: &Path) -> Result<RemoteStore> {
        let root = Object::parse(path).map_err(|e| Error::io(path, e))?;
        Ok(RemoteStore {
            root,
            missing: Mutex::default(),
        })
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
        let mut parts = Vec::new();
        for r in byte_ranges {
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
