//! The fused passes of one load-controlled iteration over the window's fields (see the module
//! docs of [`super`]): residual sums, direction, curvature, the projected step, and the
//! restoration of the load. Every sum is deterministic ([`crate::solver::cg::sums`]).

use crate::solver::cg::sums::{reduce, reduce_mut, reduce_mut2};

use super::Solver;

/// Where a pixel's pressure sits between its bounds.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Class {
    Zero,
    Free,
    Capped,
}

/// Sums of the residual pass, with g' = e − δ_prev (δ of the previous iteration): shifting by a
/// δ close to the new one keeps Σg² = Σg'² − n·m² free of cancellation (m = mean g').
#[derive(Clone, Copy)]
pub(super) struct Gaps {
    pub count: usize,
    pub sum: f64,
    pub sum_sq: f64,
    /// Σg'·t_old and Σt_old over F.
    pub sum_gt: f64,
    pub sum_t: f64,
    /// Extremes of g' on F, the smallest on p = 0, the largest on p = cap.
    pub free_min: f64,
    pub free_max: f64,
    pub zero_min: f64,
    pub capped_max: f64,
    /// E(p) + δ·ΣpΔA (the δ term is constant under load control).
    pub energy: f64,
}

impl Default for Gaps {
    fn default() -> Self {
        Gaps {
            count: 0,
            sum: 0.0,
            sum_sq: 0.0,
            sum_gt: 0.0,
            sum_t: 0.0,
            free_min: f64::INFINITY,
            free_max: f64::NEG_INFINITY,
            zero_min: f64::INFINITY,
            capped_max: f64::NEG_INFINITY,
            energy: 0.0,
        }
    }
}

impl Gaps {
    pub fn add(self, o: Gaps) -> Gaps {
        Gaps {
            count: self.count + o.count,
            sum: self.sum + o.sum,
            sum_sq: self.sum_sq + o.sum_sq,
            sum_gt: self.sum_gt + o.sum_gt,
            sum_t: self.sum_t + o.sum_t,
            free_min: self.free_min.min(o.free_min),
            free_max: self.free_max.max(o.free_max),
            zero_min: self.zero_min.min(o.zero_min),
            capped_max: self.capped_max.max(o.capped_max),
            energy: self.energy + o.energy,
        }
    }
}

/// Counts and sums of the step pass.
#[derive(Clone, Copy)]
pub(super) struct Step {
    /// Σp after the step.
    pub total: f64,
    /// After the step: pixels strictly between their bounds, pixels at the cap, and the smallest
    /// p and the smallest distance to the cap of an inside pixel. A shift μ of the inside pixels
    /// with −min_inside < μ < headroom moves no pixel across a bound.
    pub inside: usize,
    pub capped: usize,
    pub min_inside: f64,
    pub headroom: f64,
    /// Σp over the inside and over the capped pixels.
    pub inside_total: f64,
    pub capped_total: f64,
    /// Pixels that joined from p = 0, left the cap, were pushed onto the cap, or whose hardening
    /// spring switched on or off.
    pub engaged: usize,
    pub released: usize,
    pub clamped: usize,
    pub flipped: usize,
    /// The first and last window rows and columns with p > 0 (inclusive), if any.
    pub rows: (usize, usize),
    pub cols: (usize, usize),
}

impl Default for Step {
    fn default() -> Self {
        Step {
            total: 0.0,
            inside: 0,
            capped: 0,
            min_inside: f64::INFINITY,
            headroom: f64::INFINITY,
            inside_total: 0.0,
            capped_total: 0.0,
            engaged: 0,
            released: 0,
            clamped: 0,
            flipped: 0,
            rows: (usize::MAX, 0),
            cols: (usize::MAX, 0),
        }
    }
}

impl Step {
    pub fn add(self, o: Step) -> Step {
        Step {
            total: self.total + o.total,
            inside: self.inside + o.inside,
            capped: self.capped + o.capped,
            min_inside: self.min_inside.min(o.min_inside),
            headroom: self.headroom.min(o.headroom),
            inside_total: self.inside_total + o.inside_total,
            capped_total: self.capped_total + o.capped_total,
            engaged: self.engaged + o.engaged,
            released: self.released + o.released,
            clamped: self.clamped + o.clamped,
            flipped: self.flipped + o.flipped,
            rows: (self.rows.0.min(o.rows.0), self.rows.1.max(o.rows.1)),
            cols: (self.cols.0.min(o.cols.0), self.cols.1.max(o.cols.1)),
        }
    }

    /// Pixels that changed their place in the active set.
    pub fn joined(&self) -> usize {
        self.engaged + self.released + self.clamped
    }
}

/// How the load is restored after a step ([`Solver::load_shift`]): the pixels strictly inside
/// their bounds move to clip(λ·p + μ, 0, cap), the capped ones to λ_c·p.
#[derive(Clone, Copy)]
pub(super) struct Shift {
    pub inside_scale: f64,
    pub inside_add: f64,
    pub capped_scale: f64,
}

impl Solver<'_> {
    pub(super) fn class(&self, i: usize, p: f64) -> Class {
        if p <= 0.0 {
            Class::Zero
        } else if p >= self.bounds().cap(i) {
            Class::Capped
        } else {
            Class::Free
        }
    }

    /// e = s + u (+ the spring's compression) at pixel i for pressure p.
    pub(super) fn effective_gap(&self, i: usize, p: f64) -> f64 {
        self.s[i] + self.u[i] + self.bounds().spring(i, p)
    }

    /// Scale the starting pressure to the load (p ≤ cap, Σ min(λp, cap) = target; the load is
    /// below the capacity, so λ exists).
    pub(super) fn start_on_the_load(&mut self) {
        let n = self.p.len();
        let cap = |i: usize| self.bounds().cap(i);
        let mut lambda = 1.0;
        for _ in 0..200 {
            let p = &self.p;
            let (value, slope) = reduce(
                n,
                (0.0, 0.0),
                |range| {
                    range.fold((0.0, 0.0), |(v, s), i| {
                        if lambda * p[i] < cap(i) {
                            (v + lambda * p[i], s + p[i])
                        } else {
                            (v + cap(i), s)
                        }
                    })
                },
                |a, b| (a.0 + b.0, a.1 + b.1),
            );
            if !super::positive(slope) || (value - self.target).abs() <= 1e-15 * self.target {
                break;
            }
            // Σmin(λp, cap) is concave and increasing: Newton climbs to the root from below.
            lambda = (lambda + (self.target - value) / slope).max(lambda * 0.5);
        }
        let mut p = std::mem::take(&mut self.p);
        for (i, v) in p.iter_mut().enumerate() {
            *v = (*v * lambda).min(self.bounds().cap(i));
        }
        self.p = p;
    }

    /// The residual pass (reads s, u, p, t): sums and extremes of g' = e − `delta` per class,
    /// and the energy.
    pub(super) fn gaps(&self, delta: f64) -> Gaps {
        let n = self.p.len();
        reduce(
            n,
            Gaps::default(),
            |range| {
                let mut acc = Gaps::default();
                for i in range {
                    let p = self.p[i];
                    let s = self.s[i];
                    let spring = self.bounds().spring(i, p);
                    let g = s + self.u[i] + spring - delta;
                    acc.energy += p * (s + 0.5 * self.u[i]) + self.bounds().spring_energy(i, p);
                    match self.class(i, p) {
                        Class::Free => {
                            let t = self.t[i];
                            acc.count += 1;
                            acc.sum += g;
                            acc.sum_sq += g * g;
                            acc.sum_gt += g * t;
                            acc.sum_t += t;
                            acc.free_min = acc.free_min.min(g);
                            acc.free_max = acc.free_max.max(g);
                        }
                        Class::Zero => acc.zero_min = acc.zero_min.min(g),
                        Class::Capped => acc.capped_max = acc.capped_max.max(g),
                    }
                }
                acc
            },
            Gaps::add,
        )
    }

    /// Σg² over F. From the shifted sums Σg'² − n·m² when n·m² ≤ ½Σg'² (then the subtraction
    /// loses at most a bit or two; δ moved by less than the residual), else by a second, exact pass
    /// with the new δ.
    pub(super) fn residual_norm(&self, gaps: &Gaps, m: f64, delta: f64) -> f64 {
        let count = gaps.count as f64;
        let shifted = gaps.sum_sq - count * m * m;
        if count * m * m <= 0.5 * gaps.sum_sq {
            return shifted;
        }
        reduce(
            self.p.len(),
            0.0,
            |range| {
                range
                    .filter(|&i| self.class(i, self.p[i]) == Class::Free)
                    .map(|i| {
                        let g = self.effective_gap(i, self.p[i]) - delta;
                        g * g
                    })
                    .sum::<f64>()
            },
            |a, b| a + b,
        )
    }

    /// t ← (e − δ) + β·t − `mean` on F, 0 elsewhere (reads s, u, p; writes t).
    pub(super) fn direction(&mut self, delta: f64, beta: f64, mean: f64) {
        let mut t = std::mem::take(&mut self.t);
        reduce_mut(
            &mut t,
            (),
            |range, t| {
                for (k, i) in range.enumerate() {
                    let p = self.p[i];
                    t[k] = if self.class(i, p) == Class::Free {
                        self.effective_gap(i, p) - delta + beta * t[k] - mean
                    } else {
                        0.0
                    };
                }
            },
            |_, _| (),
        );
        self.t = t;
    }

    /// Σ(r + t/k where the spring acts)·t over F: the curvature of the energy along t.
    pub(super) fn curvature(&self) -> f64 {
        reduce(
            self.p.len(),
            0.0,
            |range| {
                let mut acc = 0.0;
                for i in range {
                    let p = self.p[i];
                    if self.class(i, p) == Class::Free {
                        let t = self.t[i];
                        acc += (self.r[i] + self.bounds().spring_compliance(i, p) * t) * t;
                    }
                }
                acc
            },
            |a, b| a + b,
        )
    }

    /// The projected step and the joins (reads t, s, u; writes p and previous).
    pub(super) fn step(&mut self, delta: f64, tau: f64) -> Step {
        let (mut p, mut previous) = (
            std::mem::take(&mut self.p),
            std::mem::take(&mut self.previous),
        );
        let this = &*self;
        let width = self.window.w;
        let step = reduce_mut2(
            &mut p,
            &mut previous,
            Step::default(),
            |range, p, previous| {
                let mut acc = Step::default();
                for (k, i) in range.enumerate() {
                    let (old, cap) = (p[k], this.bounds().cap(i));
                    previous[k] = old;
                    let new = match this.class(i, old) {
                        Class::Free => {
                            let stepped = old - tau * this.t[i];
                            if stepped >= cap {
                                acc.clamped += 1;
                            }
                            stepped.clamp(0.0, cap)
                        }
                        Class::Zero => {
                            let g = this.effective_gap(i, old) - delta;
                            if g < 0.0 {
                                acc.engaged += 1;
                                (-tau * g).min(cap)
                            } else {
                                old
                            }
                        }
                        Class::Capped => {
                            let g = this.effective_gap(i, old) - delta;
                            if g > 0.0 {
                                acc.released += 1;
                                (cap - tau * g).max(0.0)
                            } else {
                                old
                            }
                        }
                    };
                    let soft = |v| this.bounds().spring_compliance(i, v) > 0.0;
                    if soft(old) != soft(new) {
                        acc.flipped += 1;
                    }
                    if new > 0.0 {
                        let (row, col) = (i / width, i % width);
                        acc.rows = (acc.rows.0.min(row), acc.rows.1.max(row));
                        acc.cols = (acc.cols.0.min(col), acc.cols.1.max(col));
                    }
                    if new > 0.0 && new < cap {
                        acc.inside += 1;
                        acc.inside_total += new;
                        acc.min_inside = acc.min_inside.min(new);
                        acc.headroom = acc.headroom.min(cap - new);
                    } else if new > 0.0 {
                        acc.capped += 1;
                        acc.capped_total += new;
                    }
                    p[k] = new;
                    acc.total += new;
                }
                acc
            },
            Step::add,
        );
        self.p = p;
        self.previous = previous;
        step
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
    pub(super) fn load_shift(&self, step: &Step) -> Option<Shift> {
        if step.inside + step.capped == 0 {
            return None;
        }
        let miss = self.target - step.total;
        let keep = Shift {
            inside_scale: 1.0,
            inside_add: 0.0,
            capped_scale: 1.0,
        };
        if miss < 0.0 {
            let excess = -miss;
            return Some(if excess <= step.inside_total {
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
            });
        }
        if step.inside == 0 {
            return Some(keep);
        }
        // The usual case: μ = miss/|inside| reaches no cap and is exact without a pass.
        let mu = miss / step.inside as f64;
        if mu < step.headroom {
            return Some(Shift {
                inside_add: mu,
                ..keep
            });
        }
        let (mu, carried) = self.solve_shift(mu, |v, cap| (v > 0.0 && v < cap).then_some(cap));
        Some(Shift {
            // If the caps cannot carry it: fill them up.
            inside_add: if carried { mu } else { f64::INFINITY },
            ..keep
        })
    }

    /// μ with Σ_M clip(p + μ, 0, cap) + Σ_(not M) p = target over the pixels M that `member`
    /// selects (it returns their cap), starting from `mu`; false when no μ reaches the target
    /// (every member at 0 or at its cap). The left side is non-decreasing and piecewise linear in
    /// μ (slope: the members strictly inside their bounds after the shift), so Newton steps inside
    /// a shrinking bracket find it. A pass over the fields per step; rare.
    fn solve_shift(
        &self,
        mut mu: f64,
        member: impl Fn(f64, f64) -> Option<f64> + Sync,
    ) -> (f64, bool) {
        let value = |mu: f64| {
            reduce(
                self.p.len(),
                (0.0, 0usize, 0.0, 0.0),
                |range| {
                    let mut acc = (0.0, 0usize, 0.0, 0.0);
                    for i in range {
                        let v = self.p[i];
                        match member(v, self.bounds().cap(i)) {
                            Some(cap) => {
                                let w = (v + mu).clamp(0.0, cap);
                                acc.0 += w;
                                acc.1 += usize::from(w > 0.0 && w < cap);
                                acc.3 += cap;
                            }
                            None => {
                                acc.0 += v;
                                acc.2 += v;
                            }
                        }
                    }
                    acc
                },
                |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3),
            )
        };
        let (_, _, others, capacity) = value(0.0);
        if !(others < self.target && others + capacity > self.target) {
            return (
                if others >= self.target {
                    f64::NEG_INFINITY
                } else {
                    f64::INFINITY
                },
                false,
            );
        }
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for _ in 0..200 {
            let (f, slope, _, _) = value(mu);
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
        (mu, true)
    }

    /// Σ|p − previous| and Σp.
    pub(super) fn change(&self) -> (f64, f64) {
        reduce(
            self.p.len(),
            (0.0, 0.0),
            |range| {
                range.fold((0.0, 0.0), |(c, t), i| {
                    (c + (self.p[i] - self.previous[i]).abs(), t + self.p[i])
                })
            },
            |a, b| (a.0 + b.0, a.1 + b.1),
        )
    }

    /// The approach δ at which the pixels with e < δ, each at its cap, carry the load (the
    /// perfectly plastic contact at the current displacement): the e at which the caps of the
    /// pixels sorted by e add up to the load, halfway to the next e. A rare fallback (no free
    /// pixel), so sorting every pixel is affordable.
    pub(super) fn plastic_approach(&self) -> f64 {
        let mut order: Vec<(f64, f64)> = (0..self.p.len())
            .map(|i| (self.effective_gap(i, self.p[i]), self.bounds().cap(i)))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut carried = 0.0;
        for (k, &(e, cap)) in order.iter().enumerate() {
            carried += cap;
            if carried >= self.target {
                let next = order.get(k + 1).map_or(e + e.abs().max(1.0), |o| o.0);
                return 0.5 * (e + next);
            }
        }
        order.last().map_or(0.0, |o| o.0)
    }

    /// Apply a [`Shift`]; returns Σ|p − previous| and Σp.
    pub(super) fn apply_shift(&mut self, shift: Shift) -> (f64, f64) {
        let (mut p, mut previous) = (
            std::mem::take(&mut self.p),
            std::mem::take(&mut self.previous),
        );
        let bounds = self.bounds();
        let change = reduce_mut2(
            &mut p,
            &mut previous,
            (0.0, 0.0),
            |range, p, previous| {
                let mut acc = (0.0, 0.0);
                for (k, i) in range.enumerate() {
                    let (v, cap) = (p[k], bounds.cap(i));
                    if v > 0.0 && v < cap {
                        p[k] = (v * shift.inside_scale + shift.inside_add).clamp(0.0, cap);
                    } else if v > 0.0 {
                        p[k] = v * shift.capped_scale;
                    }
                    acc = (acc.0 + (p[k] - previous[k]).abs(), acc.1 + p[k]);
                }
                acc
            },
            |a, b| (a.0 + b.0, a.1 + b.1),
        );
        self.p = p;
        self.previous = previous;
        change
    }
}
