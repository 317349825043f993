//! Otsu's threshold: N. Otsu, "A threshold selection method from gray-level histograms",
//! IEEE Trans. Syst. Man Cybern. 9, 62–66 (1979), doi:10.1109/TSMC.1979.4310076.
//!
//! For a split after bin k, with ω(k) the pixels in bins ≤ k, μ(k) their first moment (in bin
//! units), N the total and μ_T the total moment, the between-class variance of Otsu's Eq. (18) is
//! proportional to σ_B²(k) = (μ_T·ω − μ·N)² / (ω·(N − ω)). The numerator's difference is formed
//! exactly in 128-bit integers (counts are `u64`, moments `u128`), then squared and divided in
//! `f64`. The first maximum wins, so a plateau of empty bins resolves to its lowest bin, as in
//! scikit-image and Fiji's Auto_Threshold. The bin scale does not move the maximum, so bin
//! indices stand in for values.

/// Index k of the Otsu split: class 0 is bins `0..=k`, class 1 (contact) is bins `> k`.
/// `None` when fewer than two bins are occupied (no split exists).
pub fn otsu_split(counts: &[u64]) -> Option<usize> {
    let first = counts.iter().position(|&c| c > 0)?;
    let last = counts.iter().rposition(|&c| c > 0)?;
    if first == last {
        return None;
    }
    let total: u128 = counts.iter().map(|&c| u128::from(c)).sum();
    let total_moment: u128 = counts
        .iter()
        .enumerate()
        .map(|(i, &c)| i as u128 * u128::from(c))
        .sum();
    let (mut weight, mut moment) = (0u128, 0u128);
    let mut best = (first, f64::NEG_INFINITY);
    for (k, &c) in counts.iter().enumerate().take(last).skip(first) {
        weight += u128::from(c);
        moment += k as u128 * u128::from(c);
        let diff = (total_moment * weight) as i128 - (moment * total) as i128;
        let diff = diff as f64;
        let variance = diff * diff / (weight as f64 * (total - weight) as f64);
        if variance > best.1 {
            best = (k, variance);
        }
    }
    Some(best.0)
}

/// Between-class variance of the split after bin `k`, computed the slow and obvious way from the
/// class weights and means (Otsu 1979, Eq. 18 with σ_B² = ω₀ω₁(μ₁ − μ₀)²). Reference for tests;
/// `None` if a class is empty.
pub fn between_class_variance(counts: &[u64], k: usize) -> Option<f64> {
    let total: f64 = counts.iter().map(|&c| c as f64).sum();
    let (lower, upper) = counts.split_at(k + 1);
    let w0: f64 = lower.iter().map(|&c| c as f64).sum();
    let w1: f64 = upper.iter().map(|&c| c as f64).sum();
    if w0 == 0.0 || w1 == 0.0 {
        return None;
    }
    let m0 = lower
        .iter()
        .enumerate()
        .map(|(i, &c)| i as f64 * c as f64)
        .sum::<f64>()
        / w0;
    let m1 = upper
        .iter()
        .enumerate()
        .map(|(i, &c)| (i + k + 1) as f64 * c as f64)
        .sum::<f64>()
        / w1;
    Some(w0 / total * w1 / total * (m1 - m0) * (m1 - m0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute_force(counts: &[u64]) -> Option<(usize, f64)> {
        let mut best: Option<(usize, f64)> = None;
        for k in 0..counts.len() {
            if let Some(v) = between_class_variance(counts, k) {
                if best.is_none_or(|(_, b)| v > b) {
                    best = Some((k, v));
                }
            }
        }
        best
    }

    #[test]
    fn two_levels_give_the_lower_level() {
        let mut counts = vec![0u64; 200];
        counts[50] = 1000;
        counts[150] = 1000;
        assert_eq!(otsu_split(&counts), Some(50));
    }

    #[test]
    fn single_level_has_no_split() {
        let mut counts = vec![0u64; 10];
        counts[3] = 7;
        assert_eq!(otsu_split(&counts), None);
        assert_eq!(otsu_split(&[0, 0]), None);
    }

    #[test]
    fn large_counts_do_not_overflow() {
        // docs/validation.md B16: 10 M at 10, 1 M at 128, 20 M at 250 must give 128 (imageproc's
        // otsu_level overflows here and returns 10).
        let mut counts = vec![0u64; 256];
        counts[10] = 10_000_000;
        counts[128] = 1_000_000;
        counts[250] = 20_000_000;
        assert_eq!(otsu_split(&counts), Some(128));
        // The same shape scaled to a pooled series of ~3e11 pixels.
        let scaled: Vec<u64> = counts.iter().map(|c| c * 10_000).collect();
        assert_eq!(otsu_split(&scaled), Some(128));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]
        /// The fast split maximises the between-class variance as computed from scratch: its
        /// variance equals the brute-force maximum to 1e-12 relative, and when the brute-force
        /// maximum is unique by a clear margin, the indices agree.
        #[test]
        fn matches_brute_force(counts in prop::collection::vec(
            prop_oneof![3 => Just(0u64), 5 => 0u64..1000, 1 => 0u64..1_000_000_000_000],
            2..300,
        )) {
            let fast = otsu_split(&counts);
            let slow = brute_force(&counts);
            prop_assert_eq!(fast.is_some(), slow.is_some());
            if let (Some(k), Some((k_ref, v_ref))) = (fast, slow) {
                let v = between_class_variance(&counts, k).unwrap();
                prop_assert!((v - v_ref).abs() <= 1e-12 * v_ref, "k={} v={} k_ref={} v_ref={}", k, v, k_ref, v_ref);
                let runner_up = (0..counts.len())
                    .filter(|&j| j != k_ref)
                    .filter_map(|j| between_class_variance(&counts, j))
                    .fold(0.0f64, f64::max);
                if runner_up < v_ref * (1.0 - 1e-9) {
                    prop_assert_eq!(k, k_ref);
                }
            }
        }
    }
}
