//! Mutations of seed files and option values: byte flips, header numbers replaced by extreme
//! values (as text and as 2/4/8-byte integers), truncation, inserted and deleted bytes, and line
//! edits of text files. Biased toward the first kilobyte, where the headers are.

use rand::seq::IndexedRandom;
use rand::Rng;

/// Extreme numbers as text: zero, negative, powers of two around integer widths, float limits,
/// non-finite spellings and a number too large for f64.
pub const EXTREME_TEXT: &[&str] = &[
    "0",
    "-1",
    "1",
    "-0",
    "65535",
    "2147483647",
    "4294967295",
    "4294967296",
    "288230376151711744",
    "9223372036854775808",
    "18446744073709551615",
    "18446744073709551616",
    "1e308",
    "-1e308",
    "1e-300",
    "1e-308",
    "1e999",
    "nan",
    "inf",
    "-inf",
    "0.0000001",
    "",
];

/// Extreme integers for binary header fields.
const EXTREME_INT: &[u64] = &[
    0,
    1,
    0x7f,
    0xff,
    0x7fff,
    0xffff,
    0x7fff_ffff,
    0xffff_ffff,
    1 << 32,
    1 << 58,
    1 << 63,
    u64::MAX,
];

/// A position: in the first kilobyte half the time.
fn position(rng: &mut impl Rng, len: usize) -> usize {
    if len == 0 {
        return 0;
    }
    if rng.random_bool(0.5) {
        rng.random_range(0..len.min(1024))
    } else {
        rng.random_range(0..len)
    }
}

/// Byte ranges of ASCII numbers (digits with sign, point and exponent) in `data`.
fn number_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if data[i].is_ascii_digit() {
            let mut start = i;
            if start > 0 && (data[start - 1] == b'-' || data[start - 1] == b'.') {
                start -= 1;
            }
            let mut end = i;
            while end < data.len()
                && (data[end].is_ascii_digit()
                    || matches!(data[end], b'.' | b'e' | b'E' | b'-' | b'+'))
            {
                end += 1;
            }
            spans.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    spans
}

/// Replace one ASCII number of `data` by an extreme value; false if there is none.
fn replace_number(rng: &mut impl Rng, data: &mut Vec<u8>) -> bool {
    let spans = number_spans(data);
    // Header numbers first: a number among the first 64 found, usually.
    let pool = if rng.random_bool(0.7) {
        &spans[..spans.len().min(64)]
    } else {
        &spans[..]
    };
    let Some(&(start, end)) = pool.choose(rng) else {
        return false;
    };
    let new = EXTREME_TEXT.choose(rng).unwrap().as_bytes();
    data.splice(start..end, new.iter().copied());
    true
}

/// Overwrite 2, 4 or 8 bytes with an extreme integer, little- or big-endian.
fn overwrite_int(rng: &mut impl Rng, data: &mut [u8]) {
    let width = *[2usize, 4, 8].choose(rng).unwrap();
    if data.len() < width {
        return;
    }
    let at = position(rng, data.len() - width + 1);
    let v = *EXTREME_INT.choose(rng).unwrap();
    let bytes = if rng.random_bool(0.5) {
        v.to_le_bytes()
    } else {
        v.to_be_bytes()
    };
    let src = if rng.random_bool(0.5) {
        &bytes[..width]
    } else {
        &bytes[8 - width..]
    };
    data[at..at + width].copy_from_slice(src);
}

/// Line edits: delete, duplicate, swap or blank a line, or add a very long one.
fn edit_lines(rng: &mut impl Rng, data: &mut Vec<u8>) {
    let mut lines: Vec<Vec<u8>> = data.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    if lines.is_empty() {
        return;
    }
    let i = rng.random_range(0..lines.len());
    match rng.random_range(0..5) {
        0 => {
            lines.remove(i);
        }
        1 => {
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        2 => {
            let j = rng.random_range(0..lines.len());
            lines.swap(i, j);
        }
        3 => lines[i].clear(),
        _ => lines.insert(i, vec![b'9'; rng.random_range(1..200_000)]),
    }
    *data = lines.join(&b'\n');
}

/// Apply one to three mutations to a file's bytes; returns what was done, for the report.
pub fn mutate_file(rng: &mut impl Rng, data: &mut Vec<u8>) -> String {
    let mut done = Vec::new();
    for _ in 0..rng.random_range(1..=3) {
        let kind = rng.random_range(0..8);
        match kind {
            0 | 1 => {
                if replace_number(rng, data) {
                    done.push("number");
                }
            }
            2 => {
                overwrite_int(rng, data);
                done.push("int");
            }
            3 => {
                for _ in 0..rng.random_range(1..=8) {
                    if !data.is_empty() {
                        let at = position(rng, data.len());
                        data[at] ^= 1 << rng.random_range(0..8);
                    }
                }
                done.push("flip");
            }
            4 => {
                let len = if rng.random_bool(0.5) {
                    position(rng, data.len())
                } else {
                    data.len().saturating_sub(rng.random_range(1..64))
                };
                data.truncate(len);
                done.push("truncate");
            }
            5 => {
                let at = position(rng, data.len());
                let n = rng.random_range(1..64);
                let mut block = vec![0u8; n];
                rng.fill_bytes(&mut block);
                data.splice(at..at, block);
                done.push("insert");
            }
            6 => {
                if !data.is_empty() {
                    let at = position(rng, data.len());
                    let end = (at + rng.random_range(1..64)).min(data.len());
                    data.drain(at..end);
                }
                done.push("delete");
            }
            _ => {
                edit_lines(rng, data);
                done.push("lines");
            }
        }
    }
    done.join("+")
}

/// Replace the number in an option value (`290um`, `0.05,0.1mN`, `k=1..10MPa/nm:10`) by an
/// extreme one, keeping the unit; sometimes the whole value by an odd word.
pub fn mutate_value(rng: &mut impl Rng, value: &str) -> String {
    if rng.random_bool(0.1) {
        return ["", "-", "x", "1e308x1e-300nm", "200x1e-6nm", "nan", "0"]
            .choose(rng)
            .unwrap()
            .to_string();
    }
    let mut bytes = value.as_bytes().to_vec();
    if !replace_number(rng, &mut bytes) {
        return value.to_string();
    }
    String::from_utf8_lossy(&bytes).into_owned()
}
