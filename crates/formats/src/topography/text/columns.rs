//! `x y z` points: a map when they lie on a regular grid, refused otherwise.

use std::path::Path;

use crate::binary::unsupported;
use crate::error::{Error, Result};
use crate::topography::line_scan;

/// A regular axis found in a column: its first value, its step and its number of points.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Axis {
    start: f64,
    step: f64,
    count: usize,
}

/// The distinct values of a column (equal within 1e-9 of the column's span), sorted.
fn distinct(values: &[f64]) -> Vec<f64> {
    let mut v: Vec<f64> = values.to_vec();
    v.sort_by(f64::total_cmp);
    let span = v.last().copied().unwrap_or(0.0) - v.first().copied().unwrap_or(0.0);
    let tol = span.abs() * 1e-9;
    let mut out: Vec<f64> = Vec::new();
    for x in v {
        if out.last().is_none_or(|&last| x - last > tol) {
            out.push(x);
        }
    }
    out
}

/// The axis of a column's distinct values when they are evenly spaced (to 1e-6 of the step).
fn regular(values: &[f64]) -> Option<Axis> {
    let d = distinct(values);
    let (first, last) = (*d.first()?, *d.last()?);
    if d.len() < 2 {
        return None;
    }
    let step = (last - first) / (d.len() - 1) as f64;
    let even = d
        .iter()
        .enumerate()
        .all(|(i, &x)| (x - (first + step * i as f64)).abs() <= 1e-6 * step);
    (step > 0.0 && even).then_some(Axis {
        start: first,
        step,
        count: d.len(),
    })
}

/// Heights row-major, shape (ny, nx) and spacing (dx, dy).
pub(crate) type Grid = (Vec<f64>, (usize, usize), (f64, f64));

/// `x y z` rows (already in metres) as a map: rows are y, columns x, each grid point given
/// exactly once; NaN heights stay NaN (invalid points). Returns the heights row-major, the
/// shape (ny, nx) and the spacing (dx, dy). Points off a regular grid are refused.
pub(crate) fn xyz_grid(path: &Path, rows: &[[f64; 3]]) -> Result<Grid> {
    let xs: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    let ys: Vec<f64> = rows.iter().map(|r| r[1]).collect();
    let off_grid = |why: String| -> Error {
        unsupported(
            path,
            format!(
                "the file holds {} x y z points that are not on a regular grid ({why}); \
                 topography and simulate need heights on a regular grid: interpolate the points \
                 onto one first",
                rows.len()
            ),
        )
    };
    if xs.iter().chain(&ys).any(|v| !v.is_finite()) {
        return Err(off_grid("a coordinate is not a number".into()));
    }
    let (nx_distinct, ny_distinct) = (distinct(&xs).len(), distinct(&ys).len());
    if nx_distinct < 2 || ny_distinct < 2 {
        return Err(line_scan(path, rows.len(), None));
    }
    // A profile with a column of flags beside it (x, height, valid 1/0: a stylus's HFM
    // export): x runs one way through the file, every x once, and the third column holds at
    // most two values (1 and 0, in whatever unit the column was read). No spacing is said: a
    // units line such a file may have (`[mm];[mm];[1/0]`) is skipped with the titles.
    let one_way = xs.windows(2).all(|w| w[1] > w[0]) || xs.windows(2).all(|w| w[1] < w[0]);
    let third = distinct(&rows.iter().map(|r| r[2]).collect::<Vec<f64>>());
    if one_way && third.len() <= 2 {
        return Err(line_scan(path, rows.len(), None));
    }
    let (Some(ax), Some(ay)) = (regular(&xs), regular(&ys)) else {
        return Err(off_grid(format!(
            "{nx_distinct} distinct x and {ny_distinct} distinct y, unevenly spaced"
        )));
    };
    if ax.count.checked_mul(ay.count) != Some(rows.len()) {
        return Err(off_grid(format!(
            "{} distinct x × {} distinct y ≠ {} points",
            ax.count,
            ay.count,
            rows.len()
        )));
    }
    let mut heights = vec![f64::NAN; rows.len()];
    let mut seen = vec![false; rows.len()];
    for r in rows {
        let ix = ((r[0] - ax.start) / ax.step).round() as usize;
        let iy = ((r[1] - ay.start) / ay.step).round() as usize;
        let k = iy * ax.count + ix;
        if seen[k] {
            return Err(off_grid(format!(
                "point ({}, {}) is given twice",
                r[0], r[1]
            )));
        }
        seen[k] = true;
        heights[k] = r[2];
    }
    Ok((heights, (ay.count, ax.count), (ax.step, ay.step)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_on_a_grid_in_any_order_become_a_map() {
        let p = Path::new("p.xyz");
        let mut rows = Vec::new();
        for y in 0..3 {
            for x in 0..4 {
                rows.push([
                    0.5 * f64::from(x),
                    2.0 + f64::from(y),
                    f64::from(10 * y + x),
                ]);
            }
        }
        rows.reverse();
        rows[5][2] = f64::NAN;
        let (h, shape, spacing) = xyz_grid(p, &rows).unwrap();
        assert_eq!(shape, (3, 4));
        assert_eq!(spacing, (0.5, 1.0));
        assert_eq!(h[4 * 2 + 3], 23.0);
        assert_eq!(h.iter().filter(|v| v.is_nan()).count(), 1);
    }

    #[test]
    fn points_off_a_grid_and_lines_are_refused() {
        let p = Path::new("p.xyz");
        let uneven = [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [3.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0],
            [3.0, 1.0, 1.0],
        ];
        let err = xyz_grid(p, &uneven).unwrap_err().to_string();
        assert!(
            err.contains("not on a regular grid") && err.contains("p.xyz"),
            "{err}"
        );
        let missing = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let err = xyz_grid(p, &missing).unwrap_err().to_string();
        assert!(
            err.contains("2 distinct x × 2 distinct y ≠ 3 points"),
            "{err}"
        );
        let twice = [
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
            [0.0, 1.0, 2.0],
        ];
        assert!(xyz_grid(p, &twice).is_err());
        let line = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [2.0, 0.0, 1.0]];
        let err = xyz_grid(p, &line).unwrap_err().to_string();
        assert!(err.contains("line scan"), "{err}");
        // x, a height and a validity flag: a profile, not points off a grid.
        let flagged: Vec<[f64; 3]> = (0..50)
            .map(|i| {
                [
                    1e-3 * f64::from(i),
                    0.1 * f64::from(i % 7),
                    f64::from(u8::from(i != 9)),
                ]
            })
            .collect();
        let err = xyz_grid(p, &flagged).unwrap_err().to_string();
        assert!(
            err.contains("line scan (one profile of 50 points)"),
            "{err}"
        );
        // Scattered points with heights of their own stay points off a grid.
        let scattered: Vec<[f64; 3]> = (0..50)
            .map(|i| {
                [
                    1e-3 * f64::from(i),
                    0.1 * f64::from(i % 7),
                    0.5 * f64::from(i % 3),
                ]
            })
            .collect();
        let err = xyz_grid(p, &scattered).unwrap_err().to_string();
        assert!(err.contains("not on a regular grid"), "{err}");
    }
}
