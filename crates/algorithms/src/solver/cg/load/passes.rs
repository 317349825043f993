//! The fused passes of one load-controlled iteration on the host (see the module docs of
//! [`super`]): residual sums, direction, curvature, the projected step, and the restoration of
//! the load, over the window's fields in parallel. Every sum is deterministic
//! ([`crate::solver::cg::sums`]).

use crate::error::Result;
use crate::solver::cg::sums::{reduce, reduce_mut, reduce_mut2};
use crate::solver::cg::{Plasticity, Problem};
use crate::solver::halfspace::{WindowOperator, Workspace};

use super::fields::{Fields, Gaps, Shift, ShiftSums, Step};
use super::window::Window;

/// Where a pixel's pressure sits between its bounds.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Class {
    Zero,
    Free,
    Capped,
}

/// The fields on the host, `h × w` on the window.
pub(super) struct HostFields<'a> {
    problem: &'a Problem<'a>,
    plasticity: Plasticity<'a>,
    op: WindowOperator<'a>,
    work: Workspace,
    /// The window's rows and columns.
    shape: (usize, usize),
    /// Separation and, for bounded models, the per-pixel cap or p_Y,prev, on the window.
    s: Vec<f64>,
    bound: Vec<f64>,
    p: Vec<f64>,
    previous: Vec<f64>,
    u: Vec<f64>,
    t: Vec<f64>,
    r: Vec<f64>,
}

impl<'a> HostFields<'a> {
    /// The fields on the whole grid with starting pressure `p`.
    pub fn new(problem: &'a Problem<'a>, plasticity: Plasticity<'a>, p: Vec<f64>) -> Self {
        let op = problem.operator;
        let n = problem.len();
        let bound = match plasticity {
            Plasticity::Elastic => Vec::new(),
            Plasticity::Cap(c) => c.to_vec(),
            Plasticity::Hardening { yield_pressure, .. } => yield_pressure.to_vec(),
        };
        HostFields {
            problem,
            plasticity,
            op: op.window(op.ny(), op.nx()),
            work: op.workspace(),
            shape: (op.ny(), op.nx()),
            s: problem.separation.to_vec(),
            bound,
            p,
            previous: vec![0.0; n],
            u: vec![0.0; n],
            t: vec![0.0; n],
            r: vec![0.0; n],
        }
    }

    /// The plasticity on the window's pixels.
    fn bounds(&self) -> Plasticity<'_> {
        match self.plasticity {
            Plasticity::Elastic => Plasticity::Elastic,
            Plasticity::Cap(_) => Plasticity::Cap(&self.bound),
            Plasticity::Hardening { compliance, .. } => Plasticity::Hardening {
                yield_pressure: &self.bound,
                compliance,
            },
        }
    }

    fn class(&self, i: usize, p: f64) -> Class {
        if p <= 0.0 {
            Class::Zero
        } else if p >= self.bounds().cap(i) {
            Class::Capped
        } else {
            Class::Free
        }
    }

    /// e = s + u (+ the spring's compression) at pixel i for pressure p.
    fn effective_gap(&self, i: usize, p: f64) -> f64 {
        self.s[i] + self.u[i] + self.bounds().spring(i, p)
    }
}

impl Fields for HostFields<'_> {
    fn apply_pressure(&mut self, window: &Window) -> Result<()> {
        self.op
            .apply_window(&self.p, window.h, window.w, &mut self.u, &mut self.work);
        Ok(())
    }

    fn apply_direction(&mut self, window: &Window) -> Result<()> {
        self.op
            .apply_window(&self.t, window.h, window.w, &mut self.r, &mut self.work);
        Ok(())
    }

    /// The residual pass (reads s, u, p, t): sums and extremes of g' = e − `delta` per class,
    /// and the energy.
    fn gaps(&mut self, delta: f64) -> Result<Gaps> {
        let n = self.p.len();
        Ok(reduce(
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
        ))
    }

    /// t ← (e − δ) + β·t − `mean` on F, 0 elsewhere (reads s, u, p; writes t).
    fn direction(&mut self, delta: f64, beta: f64, mean: f64) -> Result<()> {
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
        Ok(())
    }

    /// Σ(r + t/k where the spring acts)·t over F: the curvature of the energy along t.
    fn curvature(&mut self) -> Result<f64> {
        Ok(reduce(
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
        ))
    }

    /// The projected step and the joins (reads t, s, u; writes p and previous).
    fn step(&mut self, delta: f64, tau: f64, width: usize) -> Result<Step> {
        let (mut p, mut previous) = (
            std::mem::take(&mut self.p),
            std::mem::take(&mut self.previous),
        );
        let this = &*self;
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
        Ok(step)
    }

    /// Σ|p − previous| and Σp.
    fn change(&mut self) -> Result<(f64, f64)> {
        Ok(reduce(
            self.p.len(),
            (0.0, 0.0),
            |range| {
                range.fold((0.0, 0.0), |(c, t), i| {
                    (c + (self.p[i] - self.previous[i]).abs(), t + self.p[i])
                })
            },
            |a, b| (a.0 + b.0, a.1 + b.1),
        ))
    }

    /// Apply a [`Shift`]; returns Σ|p − previous| and Σp.
    fn apply_shift(&mut self, shift: Shift) -> Result<(f64, f64)> {
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
        Ok(change)
    }

    fn residual_sq(&mut self, delta: f64) -> Result<f64> {
        Ok(reduce(
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
        ))
    }

    fn shift_sums(&mut self, mu: f64) -> Result<ShiftSums> {
        let (value, inside, others, capacity) = reduce(
            self.p.len(),
            (0.0, 0usize, 0.0, 0.0),
            |range| {
                let mut acc = (0.0, 0usize, 0.0, 0.0);
                for i in range {
                    let (v, cap) = (self.p[i], self.bounds().cap(i));
                    if v > 0.0 && v < cap {
                        let w = (v + mu).clamp(0.0, cap);
                        acc.0 += w;
                        acc.1 += usize::from(w > 0.0 && w < cap);
                        acc.3 += cap;
                    } else {
                        acc.0 += v;
                        acc.2 += v;
                    }
                }
                acc
            },
            |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2, a.3 + b.3),
        );
        Ok(ShiftSums {
            value,
            inside,
            others,
            capacity,
        })
    }

    fn start_sums(&mut self, lambda: f64) -> Result<(f64, f64)> {
        let p = &self.p;
        Ok(reduce(
            p.len(),
            (0.0, 0.0),
            |range| {
                range.fold((0.0, 0.0), |(v, s), i| {
                    let cap = self.bounds().cap(i);
                    if lambda * p[i] < cap {
                        (v + lambda * p[i], s + p[i])
                    } else {
                        (v + cap, s)
                    }
                })
            },
            |a, b| (a.0 + b.0, a.1 + b.1),
        ))
    }

    fn scale(&mut self, lambda: f64) -> Result<()> {
        let mut p = std::mem::take(&mut self.p);
        for (i, v) in p.iter_mut().enumerate() {
            *v = (*v * lambda).min(self.bounds().cap(i));
        }
        self.p = p;
        Ok(())
    }

    fn fill(&mut self, value: f64) -> Result<()> {
        let mut p = std::mem::take(&mut self.p);
        for (i, v) in p.iter_mut().enumerate() {
            *v = value.min(self.bounds().cap(i));
        }
        self.p = p;
        Ok(())
    }

    fn gaps_and_caps(&mut self) -> Result<Vec<(f64, f64)>> {
        Ok((0..self.p.len())
            .map(|i| (self.effective_gap(i, self.p[i]), self.bounds().cap(i)))
            .collect())
    }

    fn rewindow(&mut self, current: &Window, next: &Window, whole: &Window) -> Result<()> {
        self.p = next.embed(current, &self.p);
        self.s = next.embed(whole, self.problem.separation);
        self.bound = match self.plasticity {
            Plasticity::Elastic => Vec::new(),
            Plasticity::Cap(c) => next.embed(whole, c),
            Plasticity::Hardening { yield_pressure, .. } => next.embed(whole, yield_pressure),
        };
        let n = next.len();
        self.previous = self.p.clone();
        (self.u, self.t, self.r) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        self.op = self.problem.operator.window(next.h, next.w);
        self.work = self.op.window_workspace(next.h);
        self.shape = (next.h, next.w);
        Ok(())
    }

    /// The iteration's buffers are freed first, and a whole-grid window lends its workspace,
    /// so that the whole-grid application does not add a second set of buffers to the peak
    /// memory (134 MB at 2048²).
    fn solution(&mut self, window: &Window, whole: &Window) -> Result<(Vec<f64>, Vec<f64>)> {
        let pressure = whole.embed(window, &self.p);
        let n = self.p.len();
        for field in [&mut self.u, &mut self.t, &mut self.r, &mut self.previous] {
            *field = Vec::new();
        }
        let operator = self.problem.operator;
        let whole = self.shape == (operator.ny(), operator.nx());
        let mut own;
        let work = if whole {
            &mut self.work
        } else {
            own = operator.workspace();
            &mut own
        };
        let mut displacement = vec![0.0; pressure.len()];
        operator.apply(&pressure, &mut displacement, work);
        (self.u, self.t, self.r, self.previous) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        Ok((pressure, displacement))
    }
}
