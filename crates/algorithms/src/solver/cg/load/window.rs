//! The window a load-controlled solve keeps its fields on (see the module docs of
//! [`super`]): where the separation comes within reach of an approach δ.

use rayon::prelude::*;

use crate::solver::halfspace::{window_length, Boundary};

/// A rectangle of the grid: rows `y0..y0 + h`, columns `x0..x0 + w`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Window {
    pub y0: usize,
    pub x0: usize,
    pub h: usize,
    pub w: usize,
}

impl Window {
    pub fn len(&self) -> usize {
        self.h * self.w
    }

    fn contains(&self, o: &Window) -> bool {
        o.y0 >= self.y0
            && o.x0 >= self.x0
            && o.y0 + o.h <= self.y0 + self.h
            && o.x0 + o.w <= self.x0 + self.w
    }

    pub fn union(&self, o: &Window) -> Window {
        let (y0, x0) = (self.y0.min(o.y0), self.x0.min(o.x0));
        let (y1, x1) = (
            (self.y0 + self.h).max(o.y0 + o.h),
            (self.x0 + self.w).max(o.x0 + o.w),
        );
        Window {
            y0,
            x0,
            h: y1 - y0,
            w: x1 - x0,
        }
    }

    /// Padded transform area of the window's operator (what an application costs).
    fn cost(&self) -> usize {
        window_length(self.h) * window_length(self.w)
    }

    /// Copy the part of `field` (on `from`) that lies in `self` into a new field on `self`,
    /// zero elsewhere.
    pub fn embed(&self, from: &Window, field: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; self.len()];
        let (y_lo, y_hi) = (
            self.y0.max(from.y0),
            (self.y0 + self.h).min(from.y0 + from.h),
        );
        let (x_lo, x_hi) = (
            self.x0.max(from.x0),
            (self.x0 + self.w).min(from.x0 + from.w),
        );
        if x_lo >= x_hi {
            return out;
        }
        for y in y_lo..y_hi {
            let src = (y - from.y0) * from.w + (x_lo - from.x0);
            let dst = (y - self.y0) * self.w + (x_lo - self.x0);
            out[dst..dst + x_hi - x_lo].copy_from_slice(&field[src..src + x_hi - x_lo]);
        }
        out
    }
}

/// Where the separation s lies below a level: per-row and per-column minima of s, so that the
/// bounding box of {s < level} costs O(N_x + N_y).
#[derive(Debug)]
pub(super) struct Reach {
    nx: usize,
    ny: usize,
    row_min: Vec<f64>,
    col_min: Vec<f64>,
    s_min: f64,
    free: bool,
}

impl Reach {
    pub fn new(separation: &[f64], nx: usize, ny: usize, boundary: Boundary) -> Self {
        // Bands of rows in parallel, each with its own column minima, folded in band order.
        const BAND: usize = 64;
        let bands: Vec<(Vec<f64>, Vec<f64>)> = separation
            .par_chunks(nx * BAND)
            .map(|band| {
                let mut cols = vec![f64::INFINITY; nx];
                let rows = band
                    .chunks(nx)
                    .map(|row| {
                        let mut least = f64::INFINITY;
                        for (c, &s) in cols.iter_mut().zip(row) {
                            least = least.min(s);
                            *c = c.min(s);
                        }
                        least
                    })
                    .collect();
                (rows, cols)
            })
            .collect();
        let mut row_min = Vec::with_capacity(ny);
        let mut col_min = vec![f64::INFINITY; nx];
        for (rows, cols) in bands {
            row_min.extend(rows);
            for (c, b) in col_min.iter_mut().zip(cols) {
                *c = c.min(b);
            }
        }
        let s_min = row_min.iter().copied().fold(f64::INFINITY, f64::min);
        Reach {
            nx,
            ny,
            row_min,
            col_min,
            s_min,
            free: boundary == Boundary::Free,
        }
    }

    /// The whole grid.
    pub fn whole(&self) -> Window {
        Window {
            y0: 0,
            x0: 0,
            h: self.ny,
            w: self.nx,
        }
    }

    /// The bounding box of {s < level}, if any pixel is below it.
    fn below(&self, level: f64) -> Option<Window> {
        let first_last = |m: &[f64]| {
            let first = m.iter().position(|v| *v < level)?;
            let last = m.iter().rposition(|v| *v < level)?;
            Some((first, last + 1))
        };
        let (y0, y1) = first_last(&self.row_min)?;
        let (x0, x1) = first_last(&self.col_min)?;
        Some(Window {
            y0,
            x0,
            h: y1 - y0,
            w: x1 - x0,
        })
    }

    /// The window to move to, if the current one must grow or may shrink, at approach `delta`
    /// with the loaded pixels inside `loaded` (grid coordinates): the bounding box of the loaded
    /// pixels and of {s < δ − c·(δ − min s)}, grown by a few pixels for pixels about to engage
    /// at the contact's edge. c = [`REACH`] = ½ reaches about the Hertz radius and leaves out the
    /// rest of the geometric overlap {s < δ}, which is twice the contact's area (Hertz:
    /// s = r²/2R < δ = a²/R reaches r = √2·a; with it the 40 mN window of a 512² map needs the
    /// next transform size up and runs 3× slower): a pixel there is lifted by the displacement u
    /// of the load around it, and any that is not (a distant asperity) is caught when the
    /// converged solution is checked on the whole grid ([`super::Solver`]). It grows whenever it must; it shrinks when that halves the transform,
    /// and not within three iterations of the last move. Periodic maps keep the whole grid.
    pub fn next_window(
        &self,
        current: &Window,
        loaded: Option<Window>,
        delta: f64,
        since_move: usize,
    ) -> Option<Window> {
        if !self.free {
            return None;
        }
        let level = delta - REACH * (delta - self.s_min).max(0.0);
        let needed = super::union(self.below(level), loaded)?;
        let padded = self.pad(&needed, PAD);
        if !current.contains(&needed) {
            return Some(padded);
        }
        const SETTLE: usize = 3;
        (since_move >= SETTLE && 2 * padded.cost() <= current.cost()).then_some(padded)
    }

    /// `window` grown by `k` pixels on every side, within the grid.
    pub fn pad(&self, window: &Window, k: usize) -> Window {
        let (y0, x0) = (window.y0.saturating_sub(k), window.x0.saturating_sub(k));
        let (y1, x1) = (
            (window.y0 + window.h + k).min(self.ny),
            (window.x0 + window.w + k).min(self.nx),
        );
        Window {
            y0,
            x0,
            h: y1 - y0,
            w: x1 - x0,
        }
    }

    /// The window holding `current` and the pixels outside it where `gap` (on the whole grid)
    /// is below −`tolerance`, or `None` when there are none.
    pub fn violations(&self, current: &Window, gap: &[f64], tolerance: f64) -> Option<Window> {
        let mut found: Option<Window> = None;
        for (i, g) in gap.iter().enumerate() {
            let (y, x) = (i / self.nx, i % self.nx);
            let inside = y >= current.y0
                && y < current.y0 + current.h
                && x >= current.x0
                && x < current.x0 + current.w;
            if !inside && *g < -tolerance {
                let pixel = Window {
                    y0: y,
                    x0: x,
                    h: 1,
                    w: 1,
                };
                found = Some(found.map_or(pixel, |f| f.union(&pixel)));
            }
        }
        found.map(|f| self.pad(&f.union(current), PAD))
    }
}

/// Share of the penetration δ − min s by which the window's reach falls short of the geometric
/// overlap (see [`Reach::next_window`]).
pub(super) const REACH: f64 = 0.5;
/// Pixels added around the needed box.
const PAD: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_embed_and_reach() {
        // A bowl on a 12 × 10 grid: s = (x − 4)² + (y − 6)².
        let (nx, ny) = (10, 12);
        let s: Vec<f64> = (0..nx * ny)
            .map(|i| {
                let (x, y) = ((i % nx) as f64, (i / nx) as f64);
                (x - 4.0).powi(2) + (y - 6.0).powi(2)
            })
            .collect();
        let reach = Reach::new(&s, nx, ny, Boundary::Free);
        // s < 4.5: |x − 4| ≤ 2 and |y − 6| ≤ 2.
        let b = reach.below(4.5).unwrap();
        assert_eq!(
            b,
            Window {
                y0: 4,
                x0: 2,
                h: 5,
                w: 5
            }
        );
        assert!(reach.below(0.0).is_none());
        // At δ = 9 the window reaches s < 9 − ½·9 = 4.5, padded by 4 within the grid.
        assert_eq!(REACH, 0.5);
        // On this small grid the padded reach is the whole grid: nothing to gain from the whole
        // grid, and a window too small for it must grow to it.
        let whole = reach.whole();
        assert_eq!(reach.pad(&b, PAD), whole);
        assert!(reach.next_window(&whole, None, 9.0, 10).is_none());
        let tiny = Window {
            y0: 5,
            x0: 3,
            h: 2,
            w: 2,
        };
        assert_eq!(reach.next_window(&tiny, None, 9.0, 0), Some(whole));
        // On a larger grid the same bowl shrinks the window ...
        let (nx, ny) = (40, 40);
        let s: Vec<f64> = (0..nx * ny)
            .map(|i| ((i % nx) as f64 - 20.0).powi(2) + ((i / nx) as f64 - 20.0).powi(2))
            .collect();
        let reach = Reach::new(&s, nx, ny, Boundary::Free);
        let whole = reach.whole();
        let small = reach.next_window(&whole, None, 9.0, 10).unwrap();
        assert_eq!(
            small,
            Window {
                y0: 14,
                x0: 14,
                h: 13,
                w: 13
            }
        );
        // ... but not right after a move, and grows again when δ moves out of it.
        assert!(reach.next_window(&whole, None, 9.0, 1).is_none());
        let grown = reach.next_window(&small, None, 100.0, 0).unwrap();
        assert!(grown.contains(&small) && grown != small);
        // Loaded pixels outside the reach stay in the window.
        let loaded = Window {
            y0: 0,
            x0: 39,
            h: 1,
            w: 1,
        };
        let with_loaded = reach.next_window(&small, Some(loaded), 9.0, 10).unwrap();
        assert!(with_loaded.contains(&loaded) && with_loaded.contains(&small));
        // A penetrating pixel outside the window is found on the whole grid.
        let mut gap = vec![1.0; nx * ny];
        gap[2 * nx + 30] = -1.0;
        let v = reach.violations(&small, &gap, 1e-9).unwrap();
        assert!(
            v.contains(&small)
                && v.contains(&Window {
                    y0: 2,
                    x0: 30,
                    h: 1,
                    w: 1
                })
        );
        gap[2 * nx + 30] = -1e-12;
        assert!(reach.violations(&small, &gap, 1e-9).is_none());
        // Embedding copies the overlap and zeroes the rest.
        let b = Window {
            y0: 4,
            x0: 2,
            h: 5,
            w: 5,
        };
        let field: Vec<f64> = (0..b.len()).map(|k| k as f64 + 1.0).collect();
        let inner = Window {
            y0: 5,
            x0: 3,
            h: 2,
            w: 2,
        };
        assert_eq!(inner.embed(&b, &field), vec![7.0, 8.0, 12.0, 13.0]);
        let back = b.embed(&inner, &inner.embed(&b, &field));
        assert_eq!(back.iter().filter(|v| **v != 0.0).count(), 4);
        assert_eq!(back[6], 7.0);
        // Periodic maps never leave the whole grid.
        let periodic = Reach::new(&s, nx, ny, Boundary::Periodic);
        assert!(periodic.next_window(&whole, None, 9.0, 10).is_none());
    }
}
