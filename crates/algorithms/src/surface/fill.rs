//! Filling the invalid (unmeasured or masked) points of a vendor height map, on request only
//! (`simulate` and `fit-hardening`, when asked to fill): a contact calculation needs every height, and
//! by default a map with invalid points is refused naming their count.
//!
//! Three rules, documented in `docs/formats.md`:
//!
//! * [`FillInvalid::Mean`]: every invalid point gets the mean height of the valid points.
//! * [`FillInvalid::Nearest`]: every invalid point gets the height of its nearest valid point
//!   in the city-block (4-neighbour) sense, found by one breadth-first sweep from all valid
//!   points at once; a tie goes to the neighbour visited first (up, left, right, down from the
//!   point that reached it first, in row-major order). O(points).
//! * [`FillInvalid::Harmonic`]: the invalid heights solve the discrete Laplace equation
//!   `Σ_n (h_n − h_p) = 0` over each invalid point's four neighbours, the valid heights being
//!   fixed (Dirichlet) values; at the border of a non-periodic map the neighbours outside are
//!   left out (zero normal derivative). This is SurfaceTopography's `harmonic` rule for
//!   undefined data (the `fill_undefined_data_mode` of a contact.engineering measurement),
//!   solved here by conjugate gradients to a relative residual of 1e-14 ([`fill_harmonic`]).

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
    /// The harmonic (Laplace) interpolation from the valid points.
    Harmonic,
}

impl FillInvalid {
    /// The rule of a name ([`FillInvalid::name`]), `None` for another word.
    pub fn from_name(name: &str) -> Option<FillInvalid> {
        [
            FillInvalid::Mean,
            FillInvalid::Nearest,
            FillInvalid::Harmonic,
        ]
        .into_iter()
        .find(|f| f.name() == name)
    }

    /// `mean`, `nearest` or `harmonic`.
    pub fn name(self) -> &'static str {
        match self {
            FillInvalid::Mean => "mean",
            FillInvalid::Nearest => "nearest",
            FillInvalid::Harmonic => "harmonic",
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
        FillInvalid::Harmonic => {
            fill_harmonic(&mut map.heights, false);
        }
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

/// Fill the invalid (non-finite) heights with the harmonic interpolation of the valid ones
/// (module docs); `periodic` wraps the neighbours around the map's borders. Returns how many
/// points were filled: none when every point is valid or none is (the system has no fixed
/// value then).
///
/// Every invalid point is connected through the grid to some valid point whenever one exists,
/// so the system (the negative Laplacian restricted to the invalid points) is symmetric positive
/// definite and conjugate gradients converge; they stop at a relative residual of 1e-14 or after
/// 20 × (invalid points) + 100 iterations.
pub fn fill_harmonic(heights: &mut ndarray::Array2<f64>, periodic: bool) -> usize {
    let (ny, nx) = heights.dim();
    let unknown: Vec<usize> = (0..ny * nx)
        .filter(|&k| !heights[(k / nx, k % nx)].is_finite())
        .collect();
    if unknown.is_empty() || unknown.len() == ny * nx {
        return 0;
    }
    let mut index = vec![usize::MAX; ny * nx];
    for (u, &k) in unknown.iter().enumerate() {
        index[k] = u;
    }
    // For each unknown: its degree and its unknown neighbours; the right-hand side collects the
    // valid neighbours' heights.
    let neighbours = |k: usize| -> Vec<usize> {
        let (y, x) = (k / nx, k % nx);
        let mut out = Vec::with_capacity(4);
        for (dy, dx) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
            let (mut v, mut u) = (y as i64 + dy, x as i64 + dx);
            if periodic {
                v = v.rem_euclid(ny as i64);
                u = u.rem_euclid(nx as i64);
            } else if v < 0 || u < 0 || v >= ny as i64 || u >= nx as i64 {
                continue;
            }
            let n = v as usize * nx + u as usize;
            // A periodic axis of one point (or two) is its own neighbour: not a difference.
            if n != k {
                out.push(n);
            }
        }
        out
    };
    let n = unknown.len();
    let mut degree = vec![0.0; n];
    let mut links: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut b = vec![0.0; n];
    for (u, &k) in unknown.iter().enumerate() {
        for m in neighbours(k) {
            degree[u] += 1.0;
            match index[m] {
                usize::MAX => b[u] += heights[(m / nx, m % nx)],
                v => links[u].push(v),
            }
        }
    }
    let apply = |x: &[f64], out: &mut [f64]| {
        for u in 0..n {
            out[u] = degree[u] * x[u] - links[u].iter().map(|&v| x[v]).sum::<f64>();
        }
    };
    // Start from the mean of the valid heights.
    let (sum, count) = heights
        .iter()
        .filter(|h| h.is_finite())
        .fold((0.0, 0usize), |(s, c), h| (s + h, c + 1));
    let mut x = vec![sum / count as f64; n];
    let mut r = vec![0.0; n];
    apply(&x, &mut r);
    for u in 0..n {
        r[u] = b[u] - r[u];
    }
    let norm_b = b
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    let mut p = r.clone();
    let mut rr: f64 = r.iter().map(|v| v * v).sum();
    let mut ap = vec![0.0; n];
    for _ in 0..20 * n + 100 {
        if rr.sqrt() <= 1e-14 * norm_b {
            break;
        }
        apply(&p, &mut ap);
        let pap: f64 = p.iter().zip(&ap).map(|(a, b)| a * b).sum();
        if pap <= 0.0 {
            break;
        }
        let alpha = rr / pap;
        for u in 0..n {
            x[u] += alpha * p[u];
            r[u] -= alpha * ap[u];
        }
        let next: f64 = r.iter().map(|v| v * v).sum();
        let beta = next / rr;
        rr = next;
        for u in 0..n {
            p[u] = r[u] + beta * p[u];
        }
    }
    for (u, &k) in unknown.iter().enumerate() {
        heights[(k / nx, k % nx)] = x[u];
    }
    n
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
            height_channels: vec![true],
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

    #[test]
    fn harmonic_fill_reproduces_a_linear_field_and_the_mean_value_property() {
        // A linear field is harmonic on the grid: any hole is filled with it exactly (with the
        // border's neighbours left out, a hole at the border still sees a linear field only if
        // the field is constant across it, so the holes here are interior).
        let linear = |i: usize, j: usize| 2.0 + 0.5 * i as f64 - 0.25 * j as f64;
        let mut h = ndarray::Array2::from_shape_fn((9, 11), |(i, j)| linear(i, j));
        for (i, j) in [(2, 3), (2, 4), (3, 3), (5, 7), (6, 7), (6, 8), (4, 5)] {
            h[(i, j)] = f64::NAN;
        }
        assert_eq!(fill_harmonic(&mut h, false), 7);
        for ((i, j), v) in h.indexed_iter() {
            assert!((v - linear(i, j)).abs() < 1e-12, "({i}, {j}): {v}");
        }
        // One hole: the mean of its four neighbours; periodic wraps a corner hole.
        let mut h = array![[1.0, 2.0, 3.0], [4.0, nan(), 6.0], [7.0, 8.0, 9.0]];
        fill_harmonic(&mut h, false);
        assert!((h[(1, 1)] - 5.0).abs() < 1e-12);
        let mut h = array![[nan(), 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]];
        fill_harmonic(&mut h, true);
        // Neighbours (periodic): below 4, right 2, above (row 2) 7, left (column 2) 3.
        assert!((h[(0, 0)] - 4.0).abs() < 1e-12, "{}", h[(0, 0)]);
        let mut h = array![[nan(), 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]];
        fill_harmonic(&mut h, false);
        assert!((h[(0, 0)] - 3.0).abs() < 1e-12, "{}", h[(0, 0)]);
        let mut all = array![[nan(), nan()]];
        assert_eq!(fill_harmonic(&mut all, false), 0);
    }

    fn nan() -> f64 {
        f64::NAN
    }
}
