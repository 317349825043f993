//! Interference orders of the ring maxima on one half-line (`docs/optics.md`, "Ring orders").
//!
//! The paper numbers the rings outward from the contact, the innermost being m = 0 (Weber et al.
//! 2018, Methods). Counting maxima fails as soon as one ring is missed or one noise maximum is
//! taken for a ring: every order beyond it is off by one and the fit fails (profiles were dropped
//! that way before). Long half-lines reach far out, where the fringes are dense and faint, so they
//! failed most. Here the order of a maximum comes from where it lies: outside the contact the
//! gap is close to a parabola, so r_m² grows almost linearly with m (for a = 20 µm,
//! R = 290 µm, extrapolating r² linearly from two rings misplaces the next by at most 0.15 of a
//! fringe spacing, from rings 0 and 1; 0.04 from rings 2 and 3). Each further order is looked
//! for near where the last two accepted rings put it.

/// A maximum is taken for the predicted order when it lies within this fraction of the local
/// fringe spacing of the predicted radius.
pub const ORDER_TOLERANCE: f64 = 0.3;

/// Orders in a row without a maximum near the prediction after which the half-line ends.
pub const MAX_MISSES: u32 = 2;

/// Orders (counted from the innermost ring, 0, 1, 2, …) of ring maxima at `candidates`
/// (radii, ascending, all outside the contact edge; any length unit). The first two candidates
/// are orders 0 and 1; each further order k is predicted from the last two accepted rings
/// (i, r_i), (j, r_j) as r_k² = r_j² + (k − j)·(r_j² − r_i²)/(j − i), and the candidate nearest
/// the prediction is accepted when it lies within [`ORDER_TOLERANCE`] of the local spacing.
/// A missed order is left out (the later ones keep their numbers). Tracking stops after
/// [`MAX_MISSES`] missed orders in a row, when the predicted spacing falls below
/// `min_spacing` (fringes blurred or aliased by the pixels), or when the prediction lies beyond
/// `max_radius` (the end of the profile).
pub fn assign_orders(candidates: &[f64], min_spacing: f64, max_radius: f64) -> Vec<(u32, f64)> {
    let mut accepted: Vec<(u32, f64)> = candidates
        .iter()
        .take(2)
        .enumerate()
        .map(|(k, &r)| (k as u32, r))
        .collect();
    if accepted.len() < 2 {
        return accepted;
    }
    let (mut order, mut misses) = (2u32, 0u32);
    loop {
        let (i, r_i) = accepted[accepted.len() - 2];
        let (j, r_j) = accepted[accepted.len() - 1];
        let per_order = (r_j * r_j - r_i * r_i) / f64::from(j - i);
        if per_order.is_nan() || per_order <= 0.0 {
            break;
        }
        let predicted = (r_j * r_j + f64::from(order - j) * per_order).sqrt();
        // Distance to the order inside it: the fringe period the image must resolve there.
        let spacing = predicted - (predicted * predicted - per_order).max(0.0).sqrt();
        if spacing < min_spacing || predicted > max_radius {
            break;
        }
        let nearest = candidates
            .iter()
            .copied()
            .filter(|&c| c > r_j)
            .min_by(|x, y| (x - predicted).abs().total_cmp(&(y - predicted).abs()));
        match nearest {
            Some(c) if (c - predicted).abs() <= ORDER_TOLERANCE * spacing => {
                accepted.push((order, c));
                misses = 0;
            }
            _ => {
                misses += 1;
                if misses >= MAX_MISSES {
                    break;
                }
            }
        }
        order += 1;
    }
    accepted
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::newton::gap::{hertz_gap, ring_gap, Phase};

    /// Radii (µm) of the Eq. 1 maxima of a = 20 µm, R = 290 µm, 488 nm, n = 1.447.
    fn ring_radii(count: u32) -> Vec<f64> {
        (0..count)
            .map(|m| {
                let d = ring_gap(m, 488e-9, 1.447, Phase::Half);
                let (mut lo, mut hi) = (20e-6, 200e-6);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if hertz_gap(mid, 20e-6, 290e-6) < d {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                lo * 1e6
            })
            .collect()
    }

    #[test]
    fn a_missed_ring_keeps_the_later_orders_and_noise_maxima_are_ignored() {
        let rings = ring_radii(16);
        let all = assign_orders(&rings, 0.0, f64::INFINITY);
        assert_eq!(all.len(), 16);
        assert!(all.iter().enumerate().all(|(k, &(m, _))| m == k as u32));

        // Ring 7 missed, a noise maximum between rings 10 and 11.
        let mut seen: Vec<f64> = rings.iter().copied().filter(|&r| r != rings[7]).collect();
        seen.push(0.5 * (rings[10] + rings[11]));
        seen.sort_by(f64::total_cmp);
        let got = assign_orders(&seen, 0.0, f64::INFINITY);
        let orders: Vec<u32> = got.iter().map(|g| g.0).collect();
        let expected: Vec<u32> = (0..16).filter(|&m| m != 7).collect();
        assert_eq!(orders, expected);
        for (m, r) in got {
            assert_eq!(r, rings[m as usize]);
        }
    }

    #[test]
    fn tracking_stops_at_dense_fringes_the_profile_end_and_two_misses() {
        let rings = ring_radii(16);
        // Spacing at ring 10 is 1.30 µm, at ring 11 1.25 µm.
        let dense = assign_orders(&rings, 1.27, f64::INFINITY);
        assert_eq!(dense.last().unwrap().0, 10);
        let short = assign_orders(&rings, 0.0, rings[5] + 0.1);
        assert_eq!(short.last().unwrap().0, 5);
        let gap: Vec<f64> = rings
            .iter()
            .enumerate()
            .filter(|(m, _)| !(6..=7).contains(m))
            .map(|(_, &r)| r)
            .collect();
        let stopped = assign_orders(&gap, 0.0, f64::INFINITY);
        assert_eq!(stopped.last().unwrap().0, 5, "two orders missed in a row");
        assert_eq!(assign_orders(&rings[..1], 0.0, 1e9), vec![(0, rings[0])]);
        assert!(assign_orders(&[], 0.0, 1e9).is_empty());
    }
}
