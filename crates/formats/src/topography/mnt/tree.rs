//! The entry tree of a MountainsMap `ScopedContents` stream and its zlib-block arrays (the
//! layout is described in the [parent module](super)).

use std::io::Read;
use std::path::Path;

use crate::binary::{bad, unsupported, utf16le, Reader, MAX_PLANE_BYTES};
use crate::error::Result;

/// Largest ratio of decompressed to compressed bytes zlib can reach (deflate's limit is 1032):
/// an array header promising more than this is corrupt, refused before allocating.
const MAX_ZLIB_RATIO: usize = 1100;

/// The entries of one container: `(tag, value)` in file order.
pub(super) struct Entries<'a> {
    path: &'a Path,
    what: &'static str,
    pub(super) list: Vec<(u16, &'a [u8])>,
}

impl<'a> Entries<'a> {
    /// Split `data` into entries (with an extra `u64` before each one when `prefixed`); an entry
    /// that overruns the container is an error naming `what`.
    pub(super) fn parse(
        path: &'a Path,
        data: &'a [u8],
        what: &'static str,
        prefixed: bool,
    ) -> Result<Self> {
        let mut r = Reader::new(path, data, 0);
        let mut list = Vec::new();
        while r.remaining() > 0 {
            let at = r.pos;
            let header = if prefixed { 18 } else { 10 };
            let corrupt = |reason: String| {
                bad(
                    path,
                    format!("MNT {what} is corrupt: the entry at byte {at} {reason}"),
                )
            };
            if r.remaining() < header {
                return Err(corrupt(format!(
                    "needs {header} header bytes, {} are left",
                    r.remaining()
                )));
            }
            if prefixed {
                r.u64()?;
            }
            let tag = r.u16()?;
            let size = r.u64()?;
            if size > r.remaining() as u64 {
                return Err(corrupt(format!(
                    "(tag {tag:#06x}) claims {size} bytes, {} are left",
                    r.remaining()
                )));
            }
            list.push((tag, r.take(size as usize)?));
        }
        Ok(Entries { path, what, list })
    }

    /// The first entry with `tag`.
    pub(super) fn get(&self, tag: u16) -> Option<&'a [u8]> {
        self.list.iter().find(|(t, _)| *t == tag).map(|(_, v)| *v)
    }

    /// The first entry with `tag`, or an error naming `what`.
    pub(super) fn need(&self, tag: u16, what: &str) -> Result<&'a [u8]> {
        self.get(tag).ok_or_else(|| {
            bad(
                self.path,
                format!("MNT {} has no {what} (tag {tag:#06x})", self.what),
            )
        })
    }

    /// The entries of the container at `tag`.
    pub(super) fn child(&self, tag: u16, what: &'static str) -> Result<Entries<'a>> {
        Entries::parse(self.path, self.need(tag, what)?, what, false)
    }

    /// A value of exactly `N` bytes at `tag`.
    fn fixed<const N: usize>(&self, tag: u16, what: &str) -> Result<[u8; N]> {
        let v = self.need(tag, what)?;
        v.try_into().map_err(|_| {
            bad(
                self.path,
                format!(
                    "MNT {what} has {} bytes, {N} expected (in {})",
                    v.len(),
                    self.what
                ),
            )
        })
    }

    pub(super) fn u32(&self, tag: u16, what: &str) -> Result<u32> {
        self.fixed::<4>(tag, what).map(u32::from_le_bytes)
    }

    pub(super) fn f64(&self, tag: u16, what: &str) -> Result<f64> {
        self.fixed::<8>(tag, what).map(f64::from_le_bytes)
    }

    /// A text entry (marker `0x04`, UTF-16LE), or `None` when absent or not text.
    pub(super) fn text(&self, tag: u16) -> Option<String> {
        let v = self.get(tag)?;
        match v.split_first() {
            Some((&0x04, rest)) if rest.len() % 2 == 0 => {
                Some(utf16le(rest).trim_end_matches('\0').trim().to_string())
            }
            _ => None,
        }
    }
}

/// A document object: its class number and body (empty when it has none, as the class-0
/// placeholder of an absent mask).
pub(super) fn object<'a>(
    path: &'a Path,
    data: &'a [u8],
    what: &'static str,
) -> Result<(u32, &'a [u8])> {
    let e = Entries::parse(path, data, what, false)?;
    let class = e
        .child(0x0001, "object class")?
        .u32(0x0001, "class number")?;
    Ok((class, e.get(0x0002).unwrap_or_default()))
}

/// An array object's element count and compressed data.
#[derive(Debug, Clone, Copy)]
pub(super) struct ArrayData<'a> {
    pub(super) count: usize,
    pub(super) data: &'a [u8],
}

pub(super) fn array<'a>(
    path: &'a Path,
    body: &'a [u8],
    what: &'static str,
) -> Result<ArrayData<'a>> {
    let e = Entries::parse(path, body, what, false)?;
    Ok(ArrayData {
        count: e.u32(0x0001, "array length")? as usize,
        data: e.need(0x0002, "array data")?,
    })
}

/// Decompress an array stored in zlib blocks; returns the bytes and the element width, which
/// must be one of `widths`. The blocks must tile the array exactly.
pub(super) fn block_array(
    path: &Path,
    a: ArrayData<'_>,
    widths: &[usize],
    what: &str,
) -> Result<(Vec<u8>, usize)> {
    let mut r = Reader::new(path, a.data, 0);
    let total = r.usize_u64()?;
    if a.count == 0 || total % a.count != 0 || !widths.contains(&(total / a.count)) {
        return Err(bad(
            path,
            format!(
                "MNT {what}: {total} bytes for {} elements (elements of {widths:?} bytes expected)",
                a.count
            ),
        ));
    }
    let width = total / a.count;
    if total > MAX_PLANE_BYTES || total > a.data.len().saturating_mul(MAX_ZLIB_RATIO) {
        return Err(unsupported(
            path,
            format!(
                "MNT {what} of {total} bytes from {} compressed bytes (header corrupt?)",
                a.data.len()
            ),
        ));
    }
    let mut out = vec![0u8; total];
    let mut spans = Vec::new();
    while r.remaining() > 0 {
        let offset = r.usize_u64()?;
        let n = r.usize_u32()?;
        let size = r.usize_u32()?;
        let compressed = r.take(size)?;
        let start = offset.checked_mul(width);
        let end = n.checked_mul(width).and_then(|len| start?.checked_add(len));
        let (Some(start), Some(end)) = (start, end.filter(|&e| e <= total)) else {
            return Err(bad(
                path,
                format!(
                    "MNT {what}: a block of {n} elements at element {offset} lies outside the \
                     {} elements",
                    a.count
                ),
            ));
        };
        let mut z = flate2::read::ZlibDecoder::new(compressed);
        let mut extra = [0u8; 1];
        let filled = z.read_exact(&mut out[start..end]).is_ok();
        if !filled || !matches!(z.read(&mut extra), Ok(0)) {
            return Err(bad(
                path,
                format!(
                    "MNT {what}: the block at element {offset} does not decompress to {n} \
                     elements"
                ),
            ));
        }
        spans.push((start, end));
    }
    spans.sort_unstable();
    let mut next = 0;
    for (start, end) in spans {
        if start != next {
            break;
        }
        next = end;
    }
    if next != total {
        return Err(bad(
            path,
            format!(
                "MNT {what}: the blocks do not cover the {} elements exactly (truncated or \
                 corrupt)",
                a.count
            ),
        ));
    }
    Ok((out, width))
}
