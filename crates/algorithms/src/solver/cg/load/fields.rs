//! The fields of one load-controlled solve and the passes over them, behind one interface
//! ([`Fields`]) so that the iteration of [`super::Solver`] runs unchanged on the host
//! ([`super::passes::HostFields`]) or on a GPU (`super::device`, feature `cuda`). Every pass
//! returns the few scalars the iteration needs; the fields themselves never leave the backend
//! inside the loop.

use crate::error::Result;

use super::window::Window;

/// The fields of a solve (separation s, the per-pixel bound, pressure p, the previous pressure,
/// displacement u, direction t and r = G∗t) on the current window, row-major `h × w`, and the
/// fused passes of one iteration (see the module docs of [`super`] for the algorithm).
pub(super) trait Fields {
    /// u = G∗p on `window` (pressure outside it is zero).
    fn apply_pressure(&mut self, window: &Window) -> Result<()>;
    /// r = G∗t on `window`.
    fn apply_direction(&mut self, window: &Window) -> Result<()>;
    /// The residual pass at the previous approach `delta` (reads s, u, p, t).
    fn gaps(&mut self, delta: f64) -> Result<Gaps>;
    /// Σg² over the free pixels at approach `delta`, in one exact pass.
    fn residual_sq(&mut self, delta: f64) -> Result<f64>;
    /// t ← (e − δ) + β·t − `mean` on the free pixels, 0 elsewhere.
    fn direction(&mut self, delta: f64, beta: f64, mean: f64) -> Result<()>;
    /// Σ(r + t/k where the spring acts)·t over the free pixels.
    fn curvature(&mut self) -> Result<f64>;
    /// The projected step of length `tau` at approach `delta` (writes p and previous); `width`
    /// is the window's row length, for the loaded rows and columns.
    fn step(&mut self, delta: f64, tau: f64, width: usize) -> Result<Step>;
    /// For a shift μ of the pixels strictly inside their bounds: (Σ over them of
    /// clip(p + μ, 0, cap) plus Σp over the others, how many stay strictly inside, Σp over the
    /// others, Σcap over them).
    fn shift_sums(&mut self, mu: f64) -> Result<ShiftSums>;
    /// Apply a [`Shift`]; returns Σ|p − previous| and Σp.
    fn apply_shift(&mut self, shift: Shift) -> Result<(f64, f64)>;
    /// Σ|p − previous| and Σp.
    fn change(&mut self) -> Result<(f64, f64)>;
    /// Σmin(λp, cap) and Σp over the pixels with λp < cap.
    fn start_sums(&mut self, lambda: f64) -> Result<(f64, f64)>;
    /// p ← min(λp, cap).
    fn scale(&mut self, lambda: f64) -> Result<()>;
    /// p ← min(`value`, cap) on every pixel.
    fn fill(&mut self, value: f64) -> Result<()>;
    /// Per pixel, the effective gap e and the cap (for the rare perfectly plastic fallback).
    fn gaps_and_caps(&mut self) -> Result<Vec<(f64, f64)>>;
    /// Move to window `next` (from `current`; `whole` is the grid): the pressure is carried
    /// over, s and the bound are taken from the whole grid, previous = p, u, t, r start at 0.
    fn rewindow(&mut self, current: &Window, next: &Window, whole: &Window) -> Result<()>;
    /// The pressure on the whole grid (`window`'s embedded in `whole`, zero elsewhere) and its
    /// displacement u = G∗p on the whole grid, on the host.
    fn solution(&mut self, window: &Window, whole: &Window) -> Result<(Vec<f64>, Vec<f64>)>;
}

/// What [`Fields::shift_sums`] returns.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ShiftSums {
    pub value: f64,
    pub inside: usize,
    pub others: f64,
    pub capacity: f64,
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
