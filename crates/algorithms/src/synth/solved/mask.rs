//! The truth kept per load: bit-packed contact masks and their patch statistics.

use crate::error::{Error, Result};
use crate::measure::patches::patch_sizes;

/// One row-major bit-packed binary mask: pixel i is bit `i % 64` of word `i / 64`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitMask {
    width: usize,
    height: usize,
    words: Vec<u64>,
}

impl BitMask {
    /// A mask from one byte per pixel (non-zero = set).
    pub fn from_bytes(bytes: &[u8], width: usize, height: usize) -> Result<Self> {
        if Some(bytes.len()) != width.checked_mul(height) {
            return Err(Error::SizeMismatch {
                what: "mask bytes",
                expected: width.saturating_mul(height),
                got: bytes.len(),
            });
        }
        let mut words = vec![0u64; bytes.len().div_ceil(64)];
        for (i, _) in bytes.iter().enumerate().filter(|(_, b)| **b != 0) {
            words[i / 64] |= 1 << (i % 64);
        }
        Ok(BitMask {
            width,
            height,
            words,
        })
    }

    /// A mask from its words; errors if the count does not fit the size or a bit past the last
    /// pixel is set.
    pub fn from_words(words: Vec<u64>, width: usize, height: usize) -> Result<Self> {
        let pixels = width.saturating_mul(height);
        if words.len() != pixels.div_ceil(64) {
            return Err(Error::SizeMismatch {
                what: "mask words",
                expected: pixels.div_ceil(64),
                got: words.len(),
            });
        }
        if pixels % 64 != 0 && words.last().is_some_and(|w| w >> (pixels % 64) != 0) {
            return Err(Error::InvalidArgument(
                "mask: a bit past the last pixel is set".into(),
            ));
        }
        Ok(BitMask {
            width,
            height,
            words,
        })
    }

    /// Columns.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Rows.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The packed words.
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// Whether pixel (x, y) is set.
    pub fn get(&self, x: usize, y: usize) -> bool {
        let i = y * self.width + x;
        self.words[i / 64] >> (i % 64) & 1 == 1
    }

    /// Set pixels.
    pub fn count(&self) -> u64 {
        self.words.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// One byte per pixel, 1 where set.
    pub fn to_bytes(&self) -> Vec<u8> {
        (0..self.width * self.height)
            .map(|i| (self.words[i / 64] >> (i % 64) & 1) as u8)
            .collect()
    }
}

/// Patch statistics of one contact mask (8-connected patches).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchStats {
    /// Number of 8-connected patches.
    pub patches: u64,
    /// Area-weighted mean equivalent diameter Σ aᵢ·2√(aᵢ/π) / Σ aᵢ, m (0 without contact).
    pub mean_diameter_m: f64,
    /// Number-weighted mean equivalent diameter, m (0 without contact).
    pub number_mean_diameter_m: f64,
    /// Area of the largest patch, m².
    pub largest_m2: f64,
}

impl PatchStats {
    /// The statistics of a mask of `pixel_m` square pixels.
    pub fn of(mask: &[u8], width: usize, pixel_m: f64) -> Self {
        let sizes = patch_sizes(mask, width);
        let pixel_area = pixel_m * pixel_m;
        let diameter = |px: u64| 2.0 * (px as f64 * pixel_area / std::f64::consts::PI).sqrt();
        let total: u64 = sizes.iter().sum();
        let (weighted, plain) = sizes.iter().fold((0.0, 0.0), |(w, p), &s| {
            (w + s as f64 * diameter(s), p + diameter(s))
        });
        PatchStats {
            patches: sizes.len() as u64,
            mean_diameter_m: if total > 0 {
                weighted / total as f64
            } else {
                0.0
            },
            number_mean_diameter_m: if sizes.is_empty() {
                0.0
            } else {
                plain / sizes.len() as f64
            },
            largest_m2: sizes.iter().copied().max().unwrap_or(0) as f64 * pixel_area,
        }
    }
}
