//! Exact Euclidean distance transform (Felzenszwalb & Huttenlocher, "Distance transforms of sampled
//! functions", Theory of Computing 8, 415 (2012)): squared distances by two passes of the 1-D
//! lower envelope of parabolas, columns then rows, with anisotropic pixel sizes.

/// Squared distance (in the units of `dx`, `dy`) from every pixel to the nearest pixel with
/// `seeds[i] == true`; `f64::INFINITY` everywhere if there is no seed.
pub fn squared_distance(
    seeds: &[bool],
    width: usize,
    height: usize,
    (dx, dy): (f64, f64),
) -> Vec<f64> {
    assert_eq!(
        seeds.len(),
        width * height,
        "distance transform: size mismatch"
    );
    let mut grid: Vec<f64> = seeds
        .iter()
        .map(|&s| if s { 0.0 } else { f64::INFINITY })
        .collect();
    let mut line = Vec::new();
    for x in 0..width {
        line.clear();
        line.extend((0..height).map(|y| grid[y * width + x]));
        let out = lower_envelope(&line, dy);
        for (y, v) in out.into_iter().enumerate() {
            grid[y * width + x] = v;
        }
    }
    for y in 0..height {
        let out = lower_envelope(&grid[y * width..(y + 1) * width], dx);
        grid[y * width..(y + 1) * width].copy_from_slice(&out);
    }
    grid
}

/// min_q (f(q) + (step·(p − q))²) for every p: the 1-D transform of a sampled function.
fn lower_envelope(f: &[f64], step: f64) -> Vec<f64> {
    let n = f.len();
    let finite: Vec<usize> = (0..n).filter(|&q| f[q].is_finite()).collect();
    if finite.is_empty() {
        return vec![f64::INFINITY; n];
    }
    let s2 = step * step;
    // Where the parabola of q overtakes the one rooted at r (in index units).
    let cross = |q: usize, r: usize| {
        ((f[q] / s2 + (q * q) as f64) - (f[r] / s2 + (r * r) as f64))
            / (2.0 * (q as f64 - r as f64))
    };
    let mut roots: Vec<usize> = Vec::with_capacity(finite.len());
    let mut starts: Vec<f64> = Vec::with_capacity(finite.len());
    for &q in &finite {
        while let (Some(&r), Some(&z)) = (roots.last(), starts.last()) {
            if cross(q, r) <= z {
                roots.pop();
                starts.pop();
            } else {
                break;
            }
        }
        let start = roots.last().map_or(f64::NEG_INFINITY, |&r| cross(q, r));
        roots.push(q);
        starts.push(start);
    }
    let mut k = 0;
    (0..n)
        .map(|p| {
            while k + 1 < roots.len() && starts[k + 1] < p as f64 {
                k += 1;
            }
            let q = roots[k];
            f[q] + s2 * (p as f64 - q as f64).powi(2)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn equals_brute_force_on_random_seeds() {
        let (w, h) = (23, 17);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for density in [0.02, 0.2] {
            let seeds: Vec<bool> = (0..w * h).map(|_| rng.random_bool(density)).collect();
            let d = squared_distance(&seeds, w, h, (0.7, 1.3));
            for (i, &got) in d.iter().enumerate() {
                let brute = (0..w * h)
                    .filter(|&j| seeds[j])
                    .map(|j| {
                        let ddx = ((i % w) as f64 - (j % w) as f64) * 0.7;
                        let ddy = ((i / w) as f64 - (j / w) as f64) * 1.3;
                        ddx * ddx + ddy * ddy
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!((got - brute).abs() < 1e-9, "pixel {i}: {got} vs {brute}");
            }
        }
        assert!(squared_distance(&[false; 6], 3, 2, (1.0, 1.0))
            .iter()
            .all(|v| v.is_infinite()));
    }
}
