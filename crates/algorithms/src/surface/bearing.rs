//! The bearing area (Abbott–Firestone) curve of a height map's piecewise-linear surface, and
//! the median height it defines — the `median` detrend mode of SurfaceTopography and
//! contact.engineering.
//!
//! The surface between the grid points is the linear interpolation: along a line scan, one
//! segment between neighbouring points; on a map, each grid cell cut into two triangles. The
//! fractional bearing area at height `t` is the fraction of the projected area where that
//! surface lies above `t`, computed exactly per element (every element has the same projected
//! area). Elements that touch an invalid point (NaN) are left out. The median height is the `t`
//! at which the fraction is ½: not the median of the points.
//!
//! The triangles of a cell at row `r`, column `c` (rows = y) are (r, c)–(r, c+1)–(r+1, c) and
//! (r+1, c+1)–(r, c+1)–(r+1, c): both share the diagonal from (r, c+1) to (r+1, c). That is
//! SurfaceTopography's cut for its `heights(x, y)` arrays read as rows = y (its NetCDF files
//! and containers); for a reader that stores the lines in the opposite order the cut is the
//! other diagonal, which moves the bearing area by a little (`docs/formats.md`).

use ndarray::Array2;

/// Relative width, to the height range, at which the median's bisection stops: the tolerance
/// SurfaceTopography's `median` uses (its result lies within this of the exact median).
pub const MEDIAN_RTOL: f64 = 1e-6;

/// Fraction of a segment with end heights `a`, `b` that lies above `t`.
fn segment_above(a: f64, b: f64, t: f64) -> f64 {
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    if t >= hi {
        0.0
    } else if t <= lo {
        1.0
    } else {
        (hi - t) / (hi - lo)
    }
}

/// Fraction of a triangle's projected area where the linear interpolant of its corner heights
/// lies above `t`.
fn triangle_above(p: f64, q: f64, r: f64, t: f64) -> f64 {
    let mut v = [p, q, r];
    v.sort_by(f64::total_cmp);
    let [lo, mid, hi] = v;
    if t >= hi {
        0.0
    } else if t <= lo {
        1.0
    } else if t < mid {
        // Below t: the corner of the lowest vertex, similar to the whole triangle.
        1.0 - (t - lo) * (t - lo) / ((mid - lo) * (hi - lo))
    } else {
        // Above t: the corner of the highest vertex.
        (hi - t) * (hi - t) / ((hi - lo) * (hi - mid))
    }
}

/// The fractional bearing area of `heights` (rows = y) at `t` and the number of elements it
/// averages; periodic maps close each line (and each column) onto itself. `None` without an
/// element free of invalid points.
pub fn bearing_area(heights: &Array2<f64>, periodic: bool, t: f64) -> Option<f64> {
    let (ny, nx) = heights.dim();
    let mut sum = 0.0;
    let mut elements = 0usize;
    let spans = |n: usize| if periodic { n } else { n.saturating_sub(1) };
    if ny == 1 || nx == 1 {
        // A line scan: segments.
        let line: Vec<f64> = heights.iter().copied().collect();
        let n = line.len();
        for k in 0..spans(n) {
            let (a, b) = (line[k], line[(k + 1) % n]);
            if a.is_finite() && b.is_finite() {
                sum += segment_above(a, b, t);
                elements += 1;
            }
        }
    } else {
        for r in 0..spans(ny) {
            let r1 = (r + 1) % ny;
            for c in 0..spans(nx) {
                let c1 = (c + 1) % nx;
                let (p00, p01) = (heights[[r, c]], heights[[r, c1]]);
                let (p10, p11) = (heights[[r1, c]], heights[[r1, c1]]);
                if p01.is_finite() && p10.is_finite() {
                    if p00.is_finite() {
                        sum += triangle_above(p00, p01, p10, t);
                        elements += 1;
                    }
                    if p11.is_finite() {
                        sum += triangle_above(p11, p01, p10, t);
                        elements += 1;
                    }
                }
            }
        }
    }
    (elements > 0).then(|| sum / elements as f64)
}

/// The median height of the piecewise-linear surface: where the bearing area is ½, by
/// bisection between the lowest and the highest valid height until the bracket is
/// [`MEDIAN_RTOL`] of that range (its midpoint returned). `None` without a valid element.
pub fn median_height(heights: &Array2<f64>, periodic: bool) -> Option<f64> {
    let (lo, hi) = heights
        .iter()
        .filter(|h| h.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| {
            (lo.min(h), hi.max(h))
        });
    bearing_area(heights, periodic, lo)?;
    let (mut a, mut b) = (lo, hi);
    let stop = (hi - lo) * MEDIAN_RTOL;
    // Bounded: each step halves the bracket, so about log2(1/MEDIAN_RTOL) ≈ 20 steps.
    while b - a > stop {
        let c = 0.5 * (a + b);
        let above = bearing_area(heights, periodic, c)?;
        if above < 0.5 {
            b = c;
        } else if above > 0.5 {
            a = c;
        } else {
            return Some(c);
        }
    }
    Some(0.5 * (a + b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_s_bearing_area_is_exact() {
        // Heights 0, 0, 1: the part above t is a similar triangle scaled by (1 − t).
        for t in [0.1, 0.5, 0.9] {
            let got = triangle_above(0.0, 1.0, 0.0, t);
            assert!((got - (1.0 - t) * (1.0 - t)).abs() < 1e-15, "{t}: {got}");
        }
        // Heights 0, 1, 1: the part below t is the corner at 0, scaled by t.
        assert!((triangle_above(1.0, 0.0, 1.0, 0.25) - (1.0 - 0.0625)).abs() < 1e-15);
        // Heights 0, 1, 2 at t = 1: the two pieces meet at the middle vertex (½ each side
        // by symmetry of the linear interpolant).
        assert!((triangle_above(0.0, 1.0, 2.0, 1.0) - 0.5).abs() < 1e-15);
        assert_eq!(triangle_above(0.0, 1.0, 2.0, 2.0), 0.0);
        assert_eq!(triangle_above(0.0, 1.0, 2.0, 0.0), 1.0);
        assert!((segment_above(2.0, 0.0, 0.5) - 0.75).abs() < 1e-15);
    }

    #[test]
    fn a_plane_s_median_is_its_middle_height() {
        // A tilted plane's bearing area falls linearly from its top to its bottom: the median is
        // the height halfway, within the bisection's tolerance of the range.
        let h = Array2::from_shape_fn((7, 11), |(r, c)| 3.0 + 0.5 * c as f64 - 0.25 * r as f64);
        let (lo, hi) = (3.0 - 0.25 * 6.0, 3.0 + 0.5 * 10.0);
        let m = median_height(&h, false).unwrap();
        assert!(
            (m - 0.5 * (lo + hi)).abs() <= (hi - lo) * MEDIAN_RTOL,
            "{m}"
        );
        // Not the median of the points: along 0, 10, 0, 1, 2 (points' median 1) the surface
        // is above t in (1, 2) on (10 − t)/10 of each of the first two segments and 2 − t of
        // the last: ½ at t = 5/3.
        let line = Array2::from_shape_vec((1, 5), vec![0.0, 10.0, 0.0, 1.0, 2.0]).unwrap();
        let m = median_height(&line, false).unwrap();
        assert!((m - 5.0 / 3.0).abs() <= 10.0 * MEDIAN_RTOL, "{m}");
    }

    #[test]
    fn invalid_points_leave_their_elements_out_and_periodic_maps_wrap() {
        let mut h = Array2::from_shape_fn((5, 5), |(r, c)| (r * 5 + c) as f64);
        let full = bearing_area(&h, false, 12.0).unwrap();
        h[[2, 2]] = f64::NAN;
        // The six triangles around the centre point are left out, not counted as low or high.
        let holed = bearing_area(&h, false, 12.0).unwrap();
        assert!((full - 0.5).abs() < 1e-12 && (holed - 0.5).abs() < 1e-12);
        let line = Array2::from_shape_vec((1, 4), vec![0.0, 1.0, 2.0, 3.0]).unwrap();
        // Open: three rising segments, a third of them above 2 … ; periodic: one more segment
        // falling from 3 to 0.
        assert!((bearing_area(&line, false, 2.5).unwrap() - 0.5 / 3.0).abs() < 1e-12);
        assert!((bearing_area(&line, true, 2.5).unwrap() - (0.5 + 1.0 / 6.0) / 4.0).abs() < 1e-12);
        assert_eq!(
            median_height(&Array2::from_elem((3, 3), f64::NAN), false),
            None
        );
    }
}
