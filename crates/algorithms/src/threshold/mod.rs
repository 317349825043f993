//! Choosing the contact threshold. Histogram accumulation ([`histogram`]) is kept apart from the
//! choice ([`otsu`]), so one Otsu threshold over a whole load series is the Otsu threshold of the
//! merged per-image histograms (Weber et al. 2018, Methods: "we define a single threshold value
//! based on all images in the load series").
//!
//! Convention: contact is value > t. For integer data t is an integer level (the highest level
//! of the background class). For float data the series range is cut into [`FLOAT_BINS`] equal
//! bins and t is the upper edge of the highest background bin; a pixel is contact when its bin
//! lies above the threshold bin, which is value ≥ t up to the rounding of the bin computation.

pub mod histogram;
pub mod otsu;

pub use histogram::{Binning, FloatBinning, Histogram};

use serde::Serialize;

use crate::error::{Error, Result};
use crate::image::Samples;

/// Number of equal bins for float data over the series' finite min..max.
pub const FLOAT_BINS: usize = 4096;

/// How the threshold is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Method {
    /// One exact Otsu threshold over the pooled histogram of all images (the paper's rule).
    #[default]
    GlobalOtsu,
    /// Each image its own Otsu threshold (for comparison).
    PerImageOtsu,
    /// A fixed value; contact is value > t.
    Manual(f64),
}

impl Method {
    /// Parse `otsu`, `per-image` or a number.
    pub fn parse(text: &str) -> Result<Self> {
        match text.trim() {
            "otsu" | "global" | "global-otsu" => Ok(Method::GlobalOtsu),
            "per-image" | "per-image-otsu" => Ok(Method::PerImageOtsu),
            other => other
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite())
                .map(Method::Manual)
                .ok_or_else(|| {
                    Error::InvalidArgument(format!(
                        "{}: '{other}' is neither 'otsu', 'per-image' nor a finite number",
                        contactscope_formats::param::Param::Threshold
                    ))
                }),
        }
    }

    /// Name used in outputs.
    pub fn name(&self) -> &'static str {
        match self {
            Method::GlobalOtsu => "otsu-global",
            Method::PerImageOtsu => "otsu-per-image",
            Method::Manual(_) => "manual",
        }
    }
}

/// Which pixels are contact, in the terms of the stored samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "rule", rename_all = "kebab-case")]
pub enum ContactRule {
    /// Integer data: contact when `code > code_threshold` (`value = code + offset`).
    CodeAbove {
        /// Threshold in code units; may lie outside 0..65535.
        code_threshold: i64,
    },
    /// Float data: contact when the value's bin index exceeds `bin`.
    BinAbove {
        /// Binning of the histogram the threshold came from.
        #[serde(skip)]
        binning: FloatBinning,
        /// Highest background bin.
        bin: usize,
    },
    /// Float data with a manual threshold: contact when value > `value`.
    ValueAbove {
        /// The threshold.
        value: f64,
    },
}

/// A threshold: its value in the data's units and the rule that applies it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Threshold {
    /// Threshold value t in the image's intensity units; contact is value > t.
    pub value: f64,
    /// How pixels are classified.
    pub rule: ContactRule,
}

impl Threshold {
    /// A manual threshold for data stored as `samples` (only their kind and offset matter).
    pub fn manual(value: f64, samples: &Samples) -> Self {
        let rule = match samples {
            Samples::Int { offset, .. } => ContactRule::CodeAbove {
                code_threshold: (value - f64::from(*offset)).floor() as i64,
            },
            Samples::Float(_) => ContactRule::ValueAbove { value },
        };
        Threshold { value, rule }
    }

    /// The Otsu threshold of a histogram; `what` names the data in the error when every pixel has
    /// one value (a constant image or series has no threshold).
    pub fn otsu(hist: &Histogram, what: &str) -> Result<Self> {
        let Some(k) = otsu::otsu_split(hist.counts()) else {
            let value = hist
                .occupied_range()
                .map_or(f64::NAN, |(lo, _)| hist.bin_value(lo));
            return Err(Error::ConstantData {
                what: what.to_string(),
                value,
            });
        };
        Ok(match hist.binning() {
            Binning::Integer { offset } => Threshold {
                value: f64::from(k as i32 + offset),
                rule: ContactRule::CodeAbove {
                    code_threshold: k as i64,
                },
            },
            Binning::Float(binning) => Threshold {
                value: binning.upper_edge(k),
                rule: ContactRule::BinAbove { binning, bin: k },
            },
        })
    }

    /// Whether this rule can classify `samples` (integer rules for integer data and so on).
    pub fn fits(&self, samples: &Samples) -> bool {
        matches!(
            (self.rule, samples),
            (ContactRule::CodeAbove { .. }, Samples::Int { .. })
                | (ContactRule::BinAbove { .. }, Samples::Float(_))
                | (ContactRule::ValueAbove { .. }, Samples::Float(_))
        )
    }
}

/// Exact Otsu threshold of values pooled from several images; contact is value > t. Whole
/// numbers within a 16-bit span get one bin per level (as integer images in `analyze`), other
/// data [`FLOAT_BINS`] equal bins over the finite range. `what` names the data in the error for
/// constant values.
pub fn otsu_of_values(images: &[&[f64]], what: &str) -> Result<f64> {
    let finite = || {
        images
            .iter()
            .flat_map(|v| v.iter())
            .copied()
            .filter(|v| v.is_finite())
    };
    let (lo, hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    // hi ≤ lo also covers data without finite values (±∞ from the fold).
    if hi <= lo {
        return Err(Error::ConstantData {
            what: what.to_string(),
            value: lo,
        });
    }
    let integer = finite().all(|v| v.fract() == 0.0) && hi - lo < 65536.0 && lo >= -32768.0;
    let hist = if integer {
        let mut counts = vec![0u64; (hi - lo) as usize + 1];
        for v in finite() {
            counts[(v - lo) as usize] += 1;
        }
        Histogram::from_counts(lo as i32, &counts)?
    } else {
        let binning = FloatBinning::new(lo, hi, FLOAT_BINS)?;
        let mut counts = vec![0u64; FLOAT_BINS];
        for v in finite() {
            if let Some(i) = binning.index(v as f32) {
                counts[i] += 1;
            }
        }
        Histogram::from_float_counts(binning, counts)
    };
    Threshold::otsu(&hist, what).map(|t| t.value)
}

#[cfg(test)]
mod tests {

    #[test]
    fn otsu_of_values_splits_two_levels() {
        let a = [0.1, 0.1, 0.12, 0.9];
        let b = [0.88, 0.9, 0.11];
        let t = otsu_of_values(&[&a, &b], "test").unwrap();
        assert!(t > 0.12 && t < 0.88, "{t}");
        assert!(otsu_of_values(&[&[0.5, 0.5, f64::NAN]], "flat").is_err());
        // Whole numbers: one bin per level, t is a level of the lower class.
        let t = otsu_of_values(&[&[100.0, 101.0, 100.0, 900.0, 901.0]], "levels").unwrap();
        assert!((101.0..900.0).contains(&t) && t.fract() == 0.0, "{t}");
    }
    use super::*;
    use crate::image::Plane;

    #[test]
    fn per_image_histograms_merge_to_the_series_histogram() {
        let a = Plane::from_u16(2, 2, vec![1, 2, 3, 4000]);
        let b = Plane::from_u16(2, 2, vec![5, 4001, 4002, 4003]);
        let mut ha = Histogram::new(Binning::Integer { offset: 0 });
        ha.add_plane(&a).unwrap();
        let mut hb = Histogram::new(Binning::Integer { offset: 0 });
        hb.add_plane(&b).unwrap();
        let mut pooled = Histogram::new(Binning::Integer { offset: 0 });
        pooled.add_plane(&a).unwrap();
        pooled.add_plane(&b).unwrap();
        ha.merge(&hb).unwrap();
        assert_eq!(ha, pooled);
        assert_eq!(ha.total(), 8);
        let t = Threshold::otsu(&ha, "series").unwrap();
        assert_eq!(t.value, 5.0);
    }

    #[test]
    fn gaussian_mixture_threshold_near_midpoint() {
        // docs/validation.md B16 asks for t ≈ 100 ± 1 for equal-weight Gaussians at 50 and 150. That
        // holds when the classes overlap (σ = 15 here). With σ = 5 the valley between the peaks
        // is empty, σ_B² is flat across it, and the first-maximum rule returns the valley's
        // lowest bin: the last occupied level of the lower peak.
        let mixture = |sigma: f64| {
            let counts: Vec<u64> = (0..256)
                .map(|i| {
                    let g = |m: f64| (-(i as f64 - m).powi(2) / (2.0 * sigma * sigma)).exp();
                    (1e6 * (g(50.0) + g(150.0))).round() as u64
                })
                .collect();
            let t = Threshold::otsu(&Histogram::from_counts(0, &counts).unwrap(), "mix");
            (t.unwrap().value, counts)
        };
        let (t, _) = mixture(15.0);
        assert!((t - 100.0).abs() <= 1.0, "t = {t}");
        let (t, counts) = mixture(5.0);
        let last_low = (0..100).rev().find(|&i| counts[i] > 0).unwrap();
        assert_eq!(t, last_low as f64);
    }

    #[test]
    fn constant_data_is_an_error() {
        let h = Histogram::from_counts(-32768, &[0, 0, 9]).unwrap();
        match Threshold::otsu(&h, "series") {
            Err(Error::ConstantData { value, .. }) => assert_eq!(value, -32766.0),
            other => panic!("expected ConstantData, got {other:?}"),
        }
    }

    #[test]
    fn parses_methods() {
        assert_eq!(Method::parse("otsu").unwrap(), Method::GlobalOtsu);
        assert_eq!(Method::parse("per-image").unwrap(), Method::PerImageOtsu);
        assert_eq!(Method::parse("1234").unwrap(), Method::Manual(1234.0));
        assert!(Method::parse("auto").is_err());
        assert!(Method::parse("nan").is_err());
    }

    #[test]
    fn manual_thresholds_respect_offsets() {
        let samples = Samples::Int {
            codes: vec![],
            offset: -32768,
        };
        let t = Threshold::manual(10.5, &samples);
        assert_eq!(
            t.rule,
            ContactRule::CodeAbove {
                code_threshold: 32778
            }
        );
    }
}
