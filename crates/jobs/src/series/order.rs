//! The natural order of file names: numbers compared as numbers, so that a folder of load steps
//! reads in load order. `img2` comes before `img10`, `load_1.25mN` before `load_1.5mN` (a decimal
//! point is part of the number), `f_1e-3N` before `f_2e-3N` (so is an exponent). Names that
//! differ only in zero padding (`img2`, `img02`) keep one stable order: fewer digits first.

use std::cmp::Ordering;

/// One piece of a name: a run of text, or a number.
#[derive(Debug, PartialEq)]
enum Piece<'a> {
    Text(char),
    Number(Number<'a>),
}

/// A number as written: integer digits, fraction digits (after a '.'), an exponent.
#[derive(Debug, PartialEq)]
struct Number<'a> {
    integer: &'a str,
    fraction: &'a str,
    exponent: Option<i32>,
    written: &'a str,
}

impl Number<'_> {
    /// Exact comparison of two decimals without exponents (any length); through f64 when
    /// either has an exponent.
    fn cmp(&self, other: &Self) -> Ordering {
        if self.exponent.is_some() || other.exponent.is_some() {
            let (a, b) = (self.value(), other.value());
            return a.partial_cmp(&b).unwrap_or(Ordering::Equal);
        }
        let (ia, ib) = (
            self.integer.trim_start_matches('0'),
            other.integer.trim_start_matches('0'),
        );
        let (fa, fb) = (
            self.fraction.trim_end_matches('0'),
            other.fraction.trim_end_matches('0'),
        );
        ia.len().cmp(&ib.len()).then(ia.cmp(ib)).then(fa.cmp(fb))
    }

    fn value(&self) -> f64 {
        let mantissa: f64 = format!("{}.{}0", self.integer, self.fraction)
            .parse()
            .unwrap_or(f64::INFINITY);
        mantissa * 10f64.powi(self.exponent.unwrap_or(0))
    }
}

/// The number at the start of `s` (which starts with a digit), and the rest.
fn number(s: &str) -> (Number<'_>, &str) {
    let digits = |t: &str| t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let int_end = digits(s);
    let mut end = int_end;
    let mut fraction = "";
    // A '.' followed by a digit continues the number (`1.25`); `img1.tif` does not.
    if s[end..].starts_with('.') && s[end + 1..].starts_with(|c: char| c.is_ascii_digit()) {
        let n = digits(&s[end + 1..]);
        fraction = &s[end + 1..end + 1 + n];
        end += 1 + n;
    }
    // An exponent: e or E, an optional sign, digits (`1e-3`); `2em` is no exponent.
    let mut exponent = None;
    let rest = &s[end..];
    if rest.starts_with(['e', 'E']) {
        let signed = &rest[1..];
        let (sign, unsigned) = match signed.chars().next() {
            Some('-') => (-1, &signed[1..]),
            Some('+') => (1, &signed[1..]),
            _ => (1, signed),
        };
        let n = digits(unsigned);
        if n > 0 && n <= 4 {
            exponent = unsigned[..n].parse::<i32>().ok().map(|e| sign * e);
            end += rest.len() - unsigned.len() + n;
        }
    }
    (
        Number {
            integer: &s[..int_end],
            fraction,
            exponent,
            written: &s[..end],
        },
        &s[end..],
    )
}

fn pieces(mut s: &str) -> Vec<Piece<'_>> {
    let mut out = Vec::new();
    while let Some(c) = s.chars().next() {
        if c.is_ascii_digit() {
            let (n, rest) = number(s);
            out.push(Piece::Number(n));
            s = rest;
        } else {
            out.push(Piece::Text(c));
            s = &s[c.len_utf8()..];
        }
    }
    out
}

/// Compare names in natural order (module docs). Equal only for equal names.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (pa, pb) = (pieces(a), pieces(b));
    let mut padding = Ordering::Equal;
    for (x, y) in pa.iter().zip(&pb) {
        let ord = match (x, y) {
            (Piece::Number(m), Piece::Number(n)) => {
                let ord = m.cmp(n);
                if ord == Ordering::Equal && padding == Ordering::Equal {
                    padding = m.written.len().cmp(&n.written.len());
                }
                ord
            }
            // Numbers before text, as digits sort before letters.
            (Piece::Number(_), Piece::Text(_)) => Ordering::Less,
            (Piece::Text(_), Piece::Number(_)) => Ordering::Greater,
            (Piece::Text(c), Piece::Text(d)) => c.cmp(d),
        };
        if ord != Ordering::Equal {
            return ord;
        }
    }
    pa.len().cmp(&pb.len()).then(padding).then_with(|| a.cmp(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut names: Vec<&str>) -> Vec<&str> {
        names.sort_by(|a, b| natural_cmp(a, b));
        names
    }

    #[test]
    fn integers_by_value_and_padding_stable() {
        assert_eq!(
            sorted(vec![
                "img10.tif",
                "img2.tif",
                "img1.tif",
                "img02.tif",
                "a.tif"
            ]),
            ["a.tif", "img1.tif", "img2.tif", "img02.tif", "img10.tif"]
        );
        assert_eq!(natural_cmp("T00009", "T00010"), Ordering::Less);
        assert_eq!(natural_cmp("x", "x"), Ordering::Equal);
        // Longer than any integer type.
        assert_eq!(
            natural_cmp("t123456789012345678901", "t123456789012345678902"),
            Ordering::Less
        );
    }

    #[test]
    fn decimals_and_exponents_by_value() {
        assert_eq!(
            sorted(vec![
                "load_10mN.tif",
                "load_1.5mN.tif",
                "load_1.25mN.tif",
                "load_1.0mN.tif"
            ]),
            [
                "load_1.0mN.tif",
                "load_1.25mN.tif",
                "load_1.5mN.tif",
                "load_10mN.tif"
            ]
        );
        assert_eq!(
            sorted(vec!["f_2e-3N.tif", "f_5e-4N.tif", "f_1e-2N.tif"]),
            ["f_5e-4N.tif", "f_2e-3N.tif", "f_1e-2N.tif"]
        );
        // 1.0 and 1 are the same number: the shorter first, stably.
        assert_eq!(sorted(vec!["p1.0", "p1"]), ["p1", "p1.0"]);
        // A dot before letters is no decimal point; "2em" no exponent.
        assert_eq!(
            sorted(vec!["img2.tif", "img1.tif"]),
            ["img1.tif", "img2.tif"]
        );
        assert_eq!(sorted(vec!["w3em", "w2em"]), ["w2em", "w3em"]);
    }

    #[test]
    fn a_total_order() {
        let names = [
            "a", "a1", "a01", "a1.0", "a1.5", "a1e1", "a10", "b", "a.1", "a-1", "1", "01",
        ];
        for x in names {
            for y in names {
                let (xy, yx) = (natural_cmp(x, y), natural_cmp(y, x));
                assert_eq!(xy, yx.reverse(), "{x} {y}");
                assert_eq!(xy == Ordering::Equal, x == y, "{x} {y}");
                for z in names {
                    if xy == Ordering::Less && natural_cmp(y, z) == Ordering::Less {
                        assert_eq!(natural_cmp(x, z), Ordering::Less, "{x} {y} {z}");
                    }
                }
            }
        }
    }
}
