//! Keeping the load (see the module docs of [`super`]): the starting pressure scaled onto it,
//! the shift that restores it after a step, and the perfectly plastic approach of the rare
//! iteration with no free pixel. Scalar logic on the host over the passes of [`Fields`].

use crate::error::Result;

use super::fields::{Fields, Shift, ShiftSums, Step};
use super::Solver;

impl<F: Fields> Solver<'_, F> {
    /// Scale the starting pressure to the load (p ≤ cap, Σ min(λp, cap) = target; the load is
    /// below the capacity, so λ exists).
    pub(super) fn start_on_the_load(&mut self) -> Result<()> {
        let mut lambda = 1.0;
        for _ in 0..200 {
            let (value, slope) = self.fields.start_sums(lambda)?;
            if !super::positive(slope) || (value - self.target).abs() <= 1e-15 * self.target {
                break;
            }
            // Σmin(λp, cap) is concave and increasing: Newton climbs to the root from below.
            lambda = (lambda + (self.target - value) / slope).max(lambda * 0.5);
        }
        self.fields.scale(lambda)
    }

    /// How the load is restored after a step. A deficit (clamps at the cap took load off) is
    /// spread over the pixels strictly inside their bounds by a common shift μ,
    /// p ← clip(p + μ, 0, cap): the Euclidean projection onto the load restricted to them, which
    /// leaves the bounds alone whenever it can, so an active set, once found, stays found. If
    /// even their caps cannot carry it they are filled to the cap, and the next iteration's
    /// approach engages more pixels. An excess (clipping at 0 and joining pixels added load) is
    /// taken off the inside pixels in proportion, p ← λp with λ < 1 (exact in one pass, nothing
    /// crosses 0; an additive shift would push the pixels that just joined below 0 and need a
    /// search on most iterations), and off the capped ones only when the inside ones cannot
    /// absorb it (projecting onto every loaded pixel at once takes a sliver off each capped pixel
    /// and cycles). Pixels at p = 0 never move. `None` when no pixel is loaded.
    pub(super) fn load_shift(&mut self, step: &Step) -> Result<Option<Shift>> {
        if step.inside + step.capped == 0 {
            return Ok(None);
        }
        let miss = self.target - step.total;
        let keep = Shift {
            inside_scale: 1.0,
            inside_add: 0.0,
            capped_scale: 1.0,
        };
        if miss < 0.0 {
            let excess = -miss;
            return Ok(Some(if excess <= step.inside_total {
                Shift {
                    inside_scale: 1.0 - excess / step.inside_total,
                    ..keep
                }
            } else {
                Shift {
                    inside_scale: 0.0,
                    capped_scale: 1.0 - (excess - step.inside_total) / step.capped_total,
                    ..keep
                }
            }));
        }
        if step.inside == 0 {
            return Ok(Some(keep));
        }
        // The usual case: μ = miss/|inside| reaches no cap and is exact without a pass.
        let mu = miss / step.inside as f64;
        if mu < step.headroom {
            return Ok(Some(Shift {
                inside_add: mu,
                ..keep
            }));
        }
        let (mu, carried) = self.solve_shift(mu)?;
        Ok(Some(Shift {
            // If the caps cannot carry it: fill them up.
            inside_add: if carried { mu } else { f64::INFINITY },
            ..keep
        }))
    }

    /// μ with Σ_M clip(p + μ, 0, cap) + Σ_(not M) p = target over the pixels M strictly inside
    /// their bounds, starting from `mu`; false when no μ reaches the target
    /// (every member at 0 or at its cap). The left side is non-decreasing and piecewise linear in
    /// μ (slope: the members strictly inside their bounds after the shift), so Newton steps inside
    /// a shrinking bracket find it. A pass over the fields per step; rare.
    fn solve_shift(&mut self, mut mu: f64) -> Result<(f64, bool)> {
        let ShiftSums {
            others, capacity, ..
        } = self.fields.shift_sums(0.0)?;
        if !(others < self.target && others + capacity > self.target) {
            return Ok((
                if others >= self.target {
                    f64::NEG_INFINITY
                } else {
                    f64::INFINITY
                },
                false,
            ));
        }
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for _ in 0..200 {
            let ShiftSums {
                value: f,
                inside: slope,
                ..
            } = self.fields.shift_sums(mu)?;
            let miss = self.target - f;
            if miss.abs() <= 1e-15 * self.target {
                break;
            }
            if miss > 0.0 {
                lo = mu;
            } else {
                hi = mu;
            }
            let newton = mu + miss / slope as f64;
            mu = if slope > 0 && newton > lo && newton < hi {
                newton
            } else if lo.is_finite() && hi.is_finite() {
                0.5 * (lo + hi)
            } else {
                // Widen the bracket.
                mu + miss.signum() * (miss.abs() + mu.abs())
            };
        }
        Ok((mu, true))
    }

    /// The approach δ at which the pixels with e < δ, each at its cap, carry the load (the
    /// perfectly plastic contact at the current displacement): the e at which the caps of the
    /// pixels sorted by e add up to the load, halfway to the next e. A rare fallback (no free
    /// pixel), so sorting every pixel is affordable.
    pub(super) fn plastic_approach(&mut self) -> Result<f64> {
        let mut order = self.fields.gaps_and_caps()?;
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut carried = 0.0;
        for (k, &(e, cap)) in order.iter().enumerate() {
            carried += cap;
            if carried >= self.target {
                let next = order.get(k + 1).map_or(e + e.abs().max(1.0), |o| o.0);
                return Ok(0.5 * (e + next));
            }
        }
        Ok(order.last().map_or(0.0, |o| o.0))
    }
}
