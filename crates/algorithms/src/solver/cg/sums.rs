//! Deterministic parallel passes over the pixel fields.
//!
//! Each pass splits the fields into fixed chunks of [`CHUNK`] pixels, works on the chunks in
//! parallel and adds the per-chunk partial results in chunk order on the calling thread. The
//! chunking does not depend on the number of threads or on scheduling, so every sum (δ, Σg²,
//! the step length, the load) and hence every result is the same bit for bit from run to run and
//! machine to machine (rayon's own `sum`/`reduce` split adaptively and are not).

use std::ops::Range;

use rayon::prelude::*;

/// Pixels per chunk: 16 Ki f64 = 128 KiB per field, a few fields fit the L2 cache.
pub const CHUNK: usize = 1 << 14;

/// `map` over the chunks of `0..n` in parallel; the partial results combined in chunk order.
pub fn reduce<T, F, C>(n: usize, identity: T, map: F, combine: C) -> T
where
    T: Send,
    F: Fn(Range<usize>) -> T + Sync,
    C: Fn(T, T) -> T,
{
    let chunks = n.div_ceil(CHUNK);
    let partial: Vec<T> = (0..chunks)
        .into_par_iter()
        .map(|c| map(c * CHUNK..((c + 1) * CHUNK).min(n)))
        .collect();
    partial.into_iter().fold(identity, combine)
}

/// Like [`reduce`], with the chunks of two mutable fields handed to `map` as well.
pub fn reduce_mut2<T, F, C>(a: &mut [f64], b: &mut [f64], identity: T, map: F, combine: C) -> T
where
    T: Send,
    F: Fn(Range<usize>, &mut [f64], &mut [f64]) -> T + Sync,
    C: Fn(T, T) -> T,
{
    assert_eq!(a.len(), b.len(), "fields of one problem have one length");
    let partial: Vec<T> = a
        .par_chunks_mut(CHUNK)
        .zip(b.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(c, (a, b))| {
            let start = c * CHUNK;
            map(start..start + a.len(), a, b)
        })
        .collect();
    partial.into_iter().fold(identity, combine)
}

/// Like [`reduce`], with the chunks of one mutable field.
pub fn reduce_mut<T, F, C>(a: &mut [f64], identity: T, map: F, combine: C) -> T
where
    T: Send,
    F: Fn(Range<usize>, &mut [f64]) -> T + Sync,
    C: Fn(T, T) -> T,
{
    let partial: Vec<T> = a
        .par_chunks_mut(CHUNK)
        .enumerate()
        .map(|(c, a)| {
            let start = c * CHUNK;
            map(start..start + a.len(), a)
        })
        .collect();
    partial.into_iter().fold(identity, combine)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunked_sums_are_exact_and_cover_every_index_once() {
        let n = 3 * CHUNK + 17;
        let total = reduce(n, 0u64, |r| r.map(|i| i as u64).sum(), |a, b| a + b);
        assert_eq!(total, (n as u64 - 1) * n as u64 / 2);
        let mut a = vec![1.0; n];
        let mut b = vec![2.0; n];
        let count = reduce_mut2(
            &mut a,
            &mut b,
            0usize,
            |r, a, b| {
                for (k, i) in r.clone().enumerate() {
                    a[k] = i as f64;
                    b[k] += a[k];
                }
                r.len()
            },
            |x, y| x + y,
        );
        assert_eq!(count, n);
        assert!(a.iter().enumerate().all(|(i, v)| *v == i as f64));
        assert!(b.iter().enumerate().all(|(i, v)| *v == i as f64 + 2.0));
    }

    #[test]
    fn floating_sums_do_not_depend_on_the_thread_count() {
        let n = 5 * CHUNK + 3;
        let values: Vec<f64> = (0..n)
            .map(|i| ((i * 7919) % 1013) as f64 * 1.1e-3)
            .collect();
        let sum = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| reduce(n, 0.0, |r| values[r].iter().sum::<f64>(), |a, b| a + b))
        };
        assert_eq!(sum(1).to_bits(), sum(3).to_bits());
    }
}
