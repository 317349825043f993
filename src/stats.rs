//! Summary statistics shared by the commands.

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
}
