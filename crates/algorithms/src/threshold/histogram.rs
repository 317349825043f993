//! Histograms that can be merged, so per-image histograms add up to the series histogram.
//!
//! Integer data: one bin per integer code (65 536 bins indexed by the `u16` code of
//! [`Samples::Int`], so uint8, uint16, 12-bit-in-16-bit, offset and int16 data all bin exactly).
//! Float data: [`FloatBinning`] with a fixed number of equal bins over a finite range that must be
//! known in advance (the series' finite min..max); non-finite values are counted apart.

use crate::error::{Error, Result};
use crate::image::{Plane, Samples};

/// Number of bins of an integer histogram: one per `u16` code.
pub const INTEGER_BINS: usize = 1 << 16;

/// Equal-width bins over `[min, max]`; the last bin includes `max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatBinning {
    /// Lower edge of bin 0.
    pub min: f64,
    /// Upper edge of the last bin.
    pub max: f64,
    /// Number of bins.
    pub bins: usize,
}

impl FloatBinning {
    /// Bins over `[min, max]`; `max > min` and both finite.
    pub fn new(min: f64, max: f64, bins: usize) -> Result<Self> {
        if !(min.is_finite() && max.is_finite() && max > min && bins >= 2) {
            return Err(Error::InvalidArgument(format!(
                "float histogram needs finite min < max and at least 2 bins (got {min}..{max}, {bins} bins)"
            )));
        }
        Ok(FloatBinning { min, max, bins })
    }

    /// Width of one bin.
    pub fn width(&self) -> f64 {
        (self.max - self.min) / self.bins as f64
    }

    /// Bin of a value; `None` for non-finite values. Values outside the range clamp to the end
    /// bins (they can only arise from a range that did not come from this data).
    #[inline]
    pub fn index(&self, value: f32) -> Option<usize> {
        if !value.is_finite() {
            return None;
        }
        let scaled = (f64::from(value) - self.min) / (self.max - self.min) * self.bins as f64;
        Some((scaled.max(0.0) as usize).min(self.bins - 1))
    }

    /// Upper edge of bin `k`.
    pub fn upper_edge(&self, k: usize) -> f64 {
        self.min + (k + 1) as f64 * self.width()
    }
}

/// How bins map to values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Binning {
    /// Bin `i` holds the integer value `i + offset`.
    Integer {
        /// Offset of the codes (−32768 for int16, else 0).
        offset: i32,
    },
    /// Equal-width float bins.
    Float(FloatBinning),
}

/// Pixel counts per bin, with `u64` counts so that any series fits.
#[derive(Debug, Clone, PartialEq)]
pub struct Histogram {
    binning: Binning,
    counts: Vec<u64>,
    non_finite: u64,
}

impl Histogram {
    /// An empty histogram with the given binning.
    pub fn new(binning: Binning) -> Self {
        let bins = match binning {
            Binning::Integer { .. } => INTEGER_BINS,
            Binning::Float(b) => b.bins,
        };
        Histogram {
            binning,
            counts: vec![0; bins],
            non_finite: 0,
        }
    }

    /// An integer histogram from explicit counts (bin `i` = value `i + offset`); used by tests
    /// and by callers that already hold counts.
    pub fn from_counts(offset: i32, counts: &[u64]) -> Result<Self> {
        if counts.len() > INTEGER_BINS {
            return Err(Error::InvalidArgument(format!(
                "{} bins given, at most {INTEGER_BINS}",
                counts.len()
            )));
        }
        let mut h = Histogram::new(Binning::Integer { offset });
        h.counts[..counts.len()].copy_from_slice(counts);
        Ok(h)
    }

    /// A float histogram from counts already binned with `binning` (one count per bin).
    pub fn from_float_counts(binning: FloatBinning, mut counts: Vec<u64>) -> Self {
        counts.resize(binning.bins, 0);
        Histogram {
            binning: Binning::Float(binning),
            counts,
            non_finite: 0,
        }
    }

    /// The binning.
    pub fn binning(&self) -> Binning {
        self.binning
    }

    /// Counts per bin.
    pub fn counts(&self) -> &[u64] {
        &self.counts
    }

    /// Pixels counted in bins (finite values).
    pub fn total(&self) -> u64 {
        self.counts.iter().sum()
    }

    /// NaN and ±∞ pixels seen (float data only).
    pub fn non_finite(&self) -> u64 {
        self.non_finite
    }

    /// Add every pixel of a plane. The plane's kind (integer with this offset, or float) must
    /// match the binning.
    pub fn add_plane(&mut self, plane: &Plane) -> Result<()> {
        match (&plane.samples, self.binning) {
            (Samples::Int { codes, offset }, Binning::Integer { offset: o }) if *offset == o => {
                add_codes(&mut self.counts, codes);
            }
            (Samples::Float(values), Binning::Float(b)) => {
                for &v in values {
                    match b.index(v) {
                        Some(i) => self.counts[i] += 1,
                        None => self.non_finite += 1,
                    }
                }
            }
            _ => {
                return Err(Error::InvalidArgument(
                    "histogram binning does not match the plane's sample type".into(),
                ))
            }
        }
        Ok(())
    }

    /// Add another histogram with the same binning.
    pub fn merge(&mut self, other: &Histogram) -> Result<()> {
        if self.binning != other.binning {
            return Err(Error::InvalidArgument(
                "cannot merge histograms with different binning".into(),
            ));
        }
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.non_finite += other.non_finite;
        Ok(())
    }

    /// Value of the lowest and highest occupied bin (bin value for integers, bin centre for
    /// floats); `None` when empty.
    pub fn occupied_range(&self) -> Option<(usize, usize)> {
        let lo = self.counts.iter().position(|&c| c > 0)?;
        let hi = self.counts.iter().rposition(|&c| c > 0)?;
        Some((lo, hi))
    }

    /// The value a bin stands for: the integer for integer data, the bin centre for floats.
    pub fn bin_value(&self, bin: usize) -> f64 {
        match self.binning {
            Binning::Integer { offset } => f64::from(bin as i32 + offset),
            Binning::Float(b) => b.min + (bin as f64 + 0.5) * b.width(),
        }
    }
}

/// Count `codes` into `counts` (one bin per code). Blocks of up to 2³² − 1 codes are counted
/// in a per-thread `u32` histogram (256 KiB, half the `u64` one, so that it stays in a core's
/// L2 cache beside the streaming plane) and then added up: the same counts.
fn add_codes(counts: &mut [u64], codes: &[u16]) {
    use std::cell::RefCell;
    thread_local! {
        static SCRATCH: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
    }
    SCRATCH.with(|scratch| {
        let mut scratch = scratch.borrow_mut();
        for block in codes.chunks(u32::MAX as usize) {
            scratch.clear();
            scratch.resize(INTEGER_BINS, 0);
            let bins = &mut scratch[..INTEGER_BINS];
            for &c in block {
                bins[usize::from(c)] += 1;
            }
            for (total, &n) in counts.iter_mut().zip(bins.iter()) {
                *total += u64::from(n);
            }
        }
    });
}

/// Finite (min, max) of a float plane, `None` if it has no finite value.
pub fn finite_range(plane: &Plane) -> Option<(f64, f64)> {
    match &plane.samples {
        Samples::Float(values) => values
            .iter()
            .filter(|v| v.is_finite())
            .fold(None, |acc, &v| {
                let v = f64::from(v);
                Some(match acc {
                    None => (v, v),
                    Some((lo, hi)) => (f64::min(lo, v), f64::max(hi, v)),
                })
            }),
        Samples::Int { codes, offset } => {
            let lo = codes.iter().min()?;
            let hi = codes.iter().max()?;
            Some((
                f64::from(i32::from(*lo) + offset),
                f64::from(i32::from(*hi) + offset),
            ))
        }
    }
}
