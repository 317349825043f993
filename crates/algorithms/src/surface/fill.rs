//! Filling the invalid (unmeasured or masked) points of a vendor height map, on request only
//! (`simulate` and `fit-hardening`, when asked to fill): a contact calculation needs every height, and
//! by default a map with invalid points is refused naming their count.
//!
//! Two rules, both documented in `docs/formats.md`:
//!
//! * [`FillInvalid::Mean`]: every invalid point gets the mean height of the valid points.
//! * [`FillInvalid::Nearest`]: every invalid point gets the height of its nearest valid point
//!   in the city-block (4-neighbour) sense, found by one breadth-first sweep from all valid
//!   points at once; a tie goes to the neighbour visited first (up, left, right, down from the
//!   point that reached it first, in row-major order). O(points).

use std::collections::VecDeque;

use serde::Serialize;

use contactscope_formats::topography::HeightMap;

/// How to fill invalid points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FillInvalid {
    /// The mean of the valid heights.
    Mean,
    /// The height of the nearest valid point (city-block distance).
    Nearest,
}

impl FillInvalid {
    /// The rule of a name ([`FillInvalid::name`]), `None` for another word.
    pub fn from_name(name: &str) -> Option<FillInvalid> {
        [FillInvalid::Mean, FillInvalid::Nearest]
            .into_iter()
            .find(|f| f.name() == name)
    }

    /// `mean` or `nearest`.
    pub fn name(self) -> &'static str {
        match self {
            FillInvalid::Mean => "mean",
            FillInvalid::Nearest => "nearest",
        }
    }
}

/// Fill every invalid (NaN) height of `map` by `how`; returns how many were filled. A map
/// without a single valid point is left as it is (the caller's refusal then names it).
pub fn fill_invalid(map: &mut HeightMap, how: FillInvalid) -> usize {
    let n_invalid = map.heights.iter().filter(|h| !h.is_finite()).count();
    if n_invalid == 0 || n_invalid == map.heights.len() {
        return 0;
    }
    match how {
        FillInvalid::Mean => {
            let (sum, n) = map
                .heights
                .iter()
                .filter(|h| h.is_finite())
                .fold((0.0, 0usize), |(s, n), h| (s + h, n + 1));
            let mean = sum / n as f64;
            map.heights
                .iter_mut()
                .filter(|h| !h.is_finite())
                .for_each(|h| *h = mean);
        }
        FillInvalid::Nearest => fill_nearest(&mut map.heights),
    }
    map.invalid_points = 0;
    n_invalid
}

/// Breadth-first from every valid point at once: each invalid point takes the value of the
/// point that reached it.
fn fill_nearest(heights: &mut ndarray::Array2<f64>) {
    let (ny, nx) = heights.dim();
    let mut queue: VecDeque<(usize, usize)> = VecDeque::new();
    let mut done = vec![false; ny * nx];
    for ((y, x), h) in heights.indexed_iter() {
        if h.is_finite() {
            done[y * nx + x] = true;
            queue.push_back((y, x));
        }
    }
    while let Some((y, x)) = queue.pop_front() {
        let value = heights[(y, x)];
        let neighbours = [
            (y.wrapping_sub(1), x),
            (y, x.wrapping_sub(1)),
            (y, x + 1),
            (y + 1, x),
        ];
        for (v, u) in neighbours {
            if v < ny && u < nx && !done[v * nx + u] {
                done[v * nx + u] = true;
                heights[(v, u)] = value;
                queue.push_back((v, u));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use contactscope_formats::topography::TopographyFormat;
    use ndarray::array;

    fn map(heights: ndarray::Array2<f64>) -> HeightMap {
        let invalid_points = heights.iter().filter(|h| h.is_nan()).count();
        HeightMap {
            format: TopographyFormat::Sdf,
            channel: "height".into(),
            channels: vec!["height".into()],
            heights,
            dx_m: 1e-6,
            dy_m: 1e-6,
            invalid_points,
            replaced_pixel_size_m: None,
        }
    }

    #[test]
    fn mean_and_nearest_fill() {
        let nan = f64::NAN;
        let heights = array![
            [1.0, nan, nan, 7.0],
            [1.0, 2.0, nan, nan],
            [nan, nan, nan, 9.0]
        ];
        let mut m = map(heights.clone());
        assert_eq!(fill_invalid(&mut m, FillInvalid::Mean), 7);
        assert_eq!(m.invalid_points, 0);
        // Valid points: 1, 7, 1, 2, 9 → mean 4.
        assert_eq!(m.heights[(0, 1)], 4.0);
        assert_eq!(m.heights[(2, 2)], 4.0);
        assert_eq!(m.heights[(1, 1)], 2.0, "valid points are kept");
        let mut m = map(heights);
        assert_eq!(fill_invalid(&mut m, FillInvalid::Nearest), 7);
        #[rustfmt::skip]
        let expected = array![
            [1.0, 1.0, 7.0, 7.0],
            [1.0, 2.0, 2.0, 7.0],
            [1.0, 2.0, 9.0, 9.0],
        ];
        // (0, 1): distance 1 to 1.0 (left) and to 2.0 (below); the left one reaches it first
        // in row-major order. (0, 2): 7.0 at distance 1. (2, 2): 9.0 at distance 1.
        assert_eq!(m.heights, expected);
        // Nothing valid: left alone.
        let mut empty = map(array![[nan, nan]]);
        assert_eq!(fill_invalid(&mut empty, FillInvalid::Mean), 0);
        assert_eq!(empty.invalid_points, 2);
    }
}
