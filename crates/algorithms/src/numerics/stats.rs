//! Summary statistics shared by the commands: mean ± sample sd and the median. Kept here rather
//! than taken from a crate: each is a few lines, exact, and needs no conversion of our slices
//! (`statrs`' `Data` would copy every slice into its own container first).

/// Mean and sample standard deviation (n − 1; `None` for a single value).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeanSd {
    /// Mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub sd: Option<f64>,
}

impl MeanSd {
    /// No values: mean NaN, no spread.
    pub const UNDEFINED: MeanSd = MeanSd {
        mean: f64::NAN,
        sd: None,
    };

    /// Of `values`; `None` when empty.
    pub fn of(values: &[f64]) -> Option<MeanSd> {
        if values.is_empty() {
            return None;
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let sd = (values.len() >= 2)
            .then(|| (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt());
        Some(MeanSd { mean, sd })
    }

    /// Both scaled (unit conversion).
    pub fn scaled(self, k: f64) -> MeanSd {
        MeanSd {
            mean: self.mean * k,
            sd: self.sd.map(|s| s * k),
        }
    }
}

/// Median (mean of the middle two for an even count); NaN for an empty slice. Sorts `values`.
pub fn median_in_place(values: &mut [f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

/// [`median_in_place`] of a copy.
pub fn median(values: &[f64]) -> f64 {
    median_in_place(&mut values.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_sample_sd() {
        let m = MeanSd::of(&[1.0, 2.0, 3.0]).unwrap();
        assert_eq!((m.mean, m.sd), (2.0, Some(1.0)));
        assert_eq!(MeanSd::of(&[4.0]).unwrap().sd, None);
        assert_eq!(MeanSd::of(&[]), None);
        assert_eq!(m.scaled(2.0).sd, Some(2.0));
    }

    #[test]
    fn median_of_even_and_odd() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
        let mut v = [3.0, 1.0, 2.0];
        assert_eq!(median_in_place(&mut v), 2.0);
        assert_eq!(v, [1.0, 2.0, 3.0], "sorted in place");
    }
}
