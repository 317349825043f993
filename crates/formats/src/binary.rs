//! Bounds-checked little- and big-endian reads from a byte slice, shared by the binary format
//! readers. Every read past the end is an error naming the file, never a panic.

use std::path::Path;

use crate::error::{Error, Location, Result};

/// Largest decoded plane or height map any reader allocates (bytes), as
/// [`crate::tiff::read::MAX_PAGE_BYTES`]: a header promising more is refused before allocating.
pub const MAX_PLANE_BYTES: usize = crate::limits::Limits::DEFAULT.max_plane_bytes;

/// A bad-input error naming the file.
pub(crate) fn bad(path: &Path, reason: impl Into<String>) -> Error {
    Error::bad_input(Location::file(path), reason)
}

/// An "unsupported" error naming the file.
pub(crate) fn unsupported(path: &Path, reason: impl Into<String>) -> Error {
    Error::Unsupported {
        at: Location::file(path),
        reason: reason.into(),
    }
}

/// `count · size` bytes, checked against [`MAX_PLANE_BYTES`] (and overflow).
pub(crate) fn checked_bytes(path: &Path, what: &str, dims: &[usize], size: usize) -> Result<usize> {
    let mut total = size;
    for &d in dims {
        total = total.saturating_mul(d);
    }
    if total > MAX_PLANE_BYTES {
        return Err(unsupported(
            path,
            format!(
                "{what} of {dims:?} × {size} bytes exceeds the {} MiB limit (header corrupt?)",
                MAX_PLANE_BYTES >> 20
            ),
        ));
    }
    Ok(total)
}

/// Bytes `offset..offset + len` of `data`, or a "truncated" error.
pub(crate) fn slice<'a>(
    path: &Path,
    data: &'a [u8],
    offset: usize,
    len: usize,
    what: &str,
) -> Result<&'a [u8]> {
    offset
        .checked_add(len)
        .and_then(|end| data.get(offset..end))
        .ok_or_else(|| {
            bad(
                path,
                format!(
                    "file is truncated: {what} needs {len} bytes at offset {offset}, the file has {}",
                    data.len()
                ),
            )
        })
}

/// A cursor over a byte slice with typed, bounds-checked reads.
pub(crate) struct Reader<'a> {
    path: &'a Path,
    data: &'a [u8],
    /// Current position.
    pub pos: usize,
    big_endian: bool,
}

macro_rules! read_num {
    ($name:ident, $t:ty, $n:expr) => {
        pub(crate) fn $name(&mut self) -> Result<$t> {
            let b = self.take($n)?;
            let mut a = [0u8; $n];
            a.copy_from_slice(b);
            Ok(if self.big_endian {
                <$t>::from_be_bytes(a)
            } else {
                <$t>::from_le_bytes(a)
            })
        }
    };
}

impl<'a> Reader<'a> {
    /// A little-endian cursor at `pos`.
    pub(crate) fn new(path: &'a Path, data: &'a [u8], pos: usize) -> Self {
        Reader {
            path,
            data,
            pos,
            big_endian: false,
        }
    }

    /// Switch to big-endian reads.
    pub(crate) fn big_endian(mut self, big: bool) -> Self {
        self.big_endian = big;
        self
    }

    /// The next `n` bytes.
    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        let s = slice(self.path, self.data, self.pos, n, "a header field")?;
        self.pos += n;
        Ok(s)
    }

    read_num!(u8, u8, 1);
    read_num!(u16, u16, 2);
    read_num!(i16, i16, 2);
    read_num!(u32, u32, 4);
    read_num!(i32, i32, 4);
    read_num!(u64, u64, 8);
    read_num!(i64, i64, 8);
    read_num!(f32, f32, 4);
    read_num!(f64, f64, 8);

    /// Bytes left after the cursor.
    pub(crate) fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    /// A count or offset read as u32/u64, as `usize`.
    pub(crate) fn usize_u32(&mut self) -> Result<usize> {
        Ok(self.u32()? as usize)
    }

    /// An i64 size or offset that must be non-negative.
    pub(crate) fn usize_i64(&mut self, what: &str) -> Result<usize> {
        let v = self.i64()?;
        usize::try_from(v).map_err(|_| bad(self.path, format!("negative {what} ({v})")))
    }

    /// A u64 size or offset as usize.
    pub(crate) fn usize_u64(&mut self) -> Result<usize> {
        let v = self.u64()?;
        usize::try_from(v).map_err(|_| bad(self.path, format!("offset {v} too large")))
    }
}

/// Decode `n` UTF-16LE code units.
pub(crate) fn utf16le(bytes: &[u8]) -> String {
    let units: Vec<u16> = bytes
        .chunks_exact(2)
        .map(|c| u16::from_le_bytes([c[0], c[1]]))
        .collect();
    String::from_utf16_lossy(&units)
}

/// Little-endian samples of `width` bytes to f64 (`float` marks IEEE floats, `signed` two's
/// complement integers).
pub(crate) fn decode_values(
    bytes: &[u8],
    width: usize,
    float: bool,
    signed: bool,
    big: bool,
) -> Vec<f64> {
    bytes
        .chunks_exact(width)
        .map(|c| {
            let mut a = [0u8; 8];
            if big {
                a[8 - width..].copy_from_slice(c);
                a.reverse();
            } else {
                a[..width].copy_from_slice(c);
            }
            let u = u64::from_le_bytes(a);
            match (width, float, signed) {
                (4, true, _) => f64::from(f32::from_bits(u as u32)),
                (8, true, _) => f64::from_bits(u),
                (1, false, true) => f64::from(u as u8 as i8),
                (2, false, true) => f64::from(u as u16 as i16),
                (4, false, true) => f64::from(u as u32 as i32),
                (8, false, true) => u as i64 as f64,
                _ => u as f64,
            }
        })
        .collect()
}

/// An open file read in pieces: every piece is checked against the file length before a buffer
/// is allocated for it, so a corrupt offset or size gives an error, not a huge allocation.
pub(crate) struct FileSource {
    /// The file as named.
    pub path: std::path::PathBuf,
    file: crate::remote::Input,
    /// File length in bytes.
    pub len: u64,
}

impl FileSource {
    /// Open `path`.
    pub(crate) fn open(path: &Path) -> Result<Self> {
        crate::inputs::note_input(path);
        let (file, len) = crate::remote::open_input(path)?;
        Ok(FileSource {
            path: path.to_path_buf(),
            file,
            len,
        })
    }

    /// `len` bytes at `offset`; an error naming `what` if they are not all in the file.
    pub(crate) fn read_at(&mut self, offset: u64, len: usize, what: &str) -> Result<Vec<u8>> {
        use std::io::{Read, Seek, SeekFrom};
        let end = offset.checked_add(len as u64);
        if end.is_none_or(|e| e > self.len) {
            return Err(bad(
                &self.path,
                format!(
                    "file is truncated or corrupt: {what} needs {len} bytes at offset {offset}, the file has {}",
                    self.len
                ),
            ));
        }
        let mut buf = vec![0u8; len];
        self.file
            .seek(SeekFrom::Start(offset))
            .and_then(|_| self.file.read_exact(&mut buf))
            .map_err(|e| Error::io(&self.path, e))?;
        Ok(buf)
    }

    /// Up to `len` bytes at `offset` (fewer at the end of the file).
    pub(crate) fn read_up_to(&mut self, offset: u64, len: usize) -> Result<Vec<u8>> {
        let available = self.len.saturating_sub(offset).min(len as u64) as usize;
        self.read_at(offset, available, "header")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_are_bounds_checked() {
        let p = Path::new("f.bin");
        let data = [1u8, 0, 0, 0, 0xff];
        let mut r = Reader::new(p, &data, 0);
        assert_eq!(r.u32().unwrap(), 1);
        assert!(r.u32().unwrap_err().to_string().contains("truncated"));
        let mut r = Reader::new(p, &data, 0).big_endian(true);
        assert_eq!(r.u16().unwrap(), 256);
        assert!(checked_bytes(p, "plane", &[1 << 20, 1 << 20], 2).is_err());
        assert_eq!(checked_bytes(p, "plane", &[3, 4], 2).unwrap(), 24);
        assert_eq!(
            decode_values(&[0xff, 0xff], 2, false, true, false),
            vec![-1.0]
        );
        assert_eq!(
            decode_values(&[0x01, 0x00], 2, false, false, true),
            vec![256.0]
        );
    }
}
