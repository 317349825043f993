//! 2-D real FFTs with plans built once and reused (RustFFT + realfft).
//!
//! # Conventions
//! * Arrays are row-major `(y, x)`: `ny` rows of `nx` values (see `docs/conventions.md`).
//! * [`RealFft2::forward`] computes the unnormalised DFT
//!   `F(kx, ky) = Σ_x Σ_y f(x, y) · exp(−2πi (kx·x/nx + ky·y/ny))` for `kx = 0..=nx/2` (the other half
//!   follows from Hermitian symmetry) and every `ky`.
//! * **Spectrum layout is transposed**: element `kx * ny + ky`. Keeping the column transform's
//!   natural layout saves two transposes per round trip; element-wise products (kernels,
//!   multipliers) do not care, and [`RealFft2::wavenumbers`] maps an index to signed indices.
//! * [`RealFft2::inverse`] is the unnormalised inverse: `inverse(forward(f)) = nx·ny·f`. Divide by
//!   [`RealFft2::len`] once per round trip (Parseval: Σ|f|² = Σ_full |F|² / (nx·ny)).
//! * Rows and columns are transformed in parallel (rayon); each call allocates only the scratch it
//!   needs per thread.

pub mod autocorrelation;
pub mod register;

use std::sync::Arc;

use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};

pub use rustfft::num_complex::Complex64;

/// A planned 2-D real-to-complex FFT of an `ny × nx` array.
pub struct RealFft2 {
    nx: usize,
    ny: usize,
    row_forward: Arc<dyn RealToComplex<f64>>,
    row_inverse: Arc<dyn ComplexToReal<f64>>,
    col_forward: Arc<dyn Fft<f64>>,
    col_inverse: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for RealFft2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RealFft2({}×{})", self.ny, self.nx)
    }
}

impl RealFft2 {
    /// Plan transforms for `ny` rows of `nx` values (both ≥ 1; `nx` even is fastest).
    pub fn new(ny: usize, nx: usize) -> Self {
        assert!(nx >= 1 && ny >= 1, "FFT size must be positive");
        let mut real = RealFftPlanner::<f64>::new();
        let mut complex = FftPlanner::<f64>::new();
        RealFft2 {
            nx,
            ny,
            row_forward: real.plan_fft_forward(nx),
            row_inverse: real.plan_fft_inverse(nx),
            col_forward: complex.plan_fft_forward(ny),
            col_inverse: complex.plan_fft_inverse(ny),
        }
    }

    /// Columns `nx` of the real array.
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// Rows `ny` of the real array.
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Number of real values, `nx·ny` (the round-trip normalisation).
    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    /// Always false (sizes are positive).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Length of the half spectrum, `(nx/2 + 1)·ny`.
    pub fn spectrum_len(&self) -> usize {
        (self.nx / 2 + 1) * self.ny
    }

    /// A zeroed spectrum buffer.
    pub fn make_spectrum(&self) -> Vec<Complex64> {
        vec![Complex::new(0.0, 0.0); self.spectrum_len()]
    }

    /// Signed wavenumber indices `(mx, my)` of spectrum element `index`: `mx ∈ 0..=nx/2`,
    /// `my ∈ (−ny/2, ny/2]`.
    pub fn wavenumbers(&self, index: usize) -> (i64, i64) {
        let (kx, ky) = (index / self.ny, index % self.ny);
        let my = if ky > self.ny / 2 {
            ky as i64 - self.ny as i64
        } else {
            ky as i64
        };
        (kx as i64, my)
    }

    /// Forward transform of `input` (`ny·nx` values, row-major) into `output` (transposed half
    /// spectrum). `input` is used as scratch and left unspecified.
    pub fn forward(&self, input: &mut [f64], output: &mut [Complex64]) {
        let mut scratch = Vec::new();
        self.forward_rows(input, self.ny, output, &mut scratch);
    }

    /// Forward transform when only the first `live_rows` rows can be non-zero (zero padding):
    /// `input` holds just those rows (`live_rows·nx` values); the zero rows' transforms are
    /// skipped. `scratch` is reused between calls.
    pub fn forward_rows(
        &self,
        input: &mut [f64],
        live_rows: usize,
        output: &mut [Complex64],
        scratch: &mut Vec<Complex64>,
    ) {
        assert!(live_rows <= self.ny, "forward: live rows");
        assert_eq!(input.len(), live_rows * self.nx, "forward: input length");
        assert_eq!(output.len(), self.spectrum_len(), "forward: output length");
        let half = self.nx / 2 + 1;
        scratch.resize(self.ny * half, Complex::new(0.0, 0.0));
        let (live, dead) = scratch.split_at_mut(live_rows * half);
        dead.fill(Complex::new(0.0, 0.0));
        input
            .par_chunks_mut(self.nx)
            .zip(live.par_chunks_mut(half))
            .for_each_init(
                || self.row_forward.make_scratch_vec(),
                |work, (row, out)| {
                    self.row_forward
                        .process_with_scratch(row, out, work)
                        .expect("row lengths match the plan");
                },
            );
        transpose(scratch, output, self.ny, half);
        self.columns(output, &self.col_forward);
    }

    /// Inverse transform of a transposed half spectrum (destroyed) into `output` (`ny·nx`
    /// values), unnormalised. The imaginary parts of the self-conjugate bins are ignored.
    pub fn inverse(&self, input: &mut [Complex64], output: &mut [f64]) {
        let mut scratch = Vec::new();
        self.inverse_rows(input, self.ny, output, &mut scratch);
    }

    /// Inverse transform computing only the first `live_rows` output rows (`output` holds
    /// `live_rows·nx` values); the other rows' transforms are skipped.
    pub fn inverse_rows(
        &self,
        input: &mut [Complex64],
        live_rows: usize,
        output: &mut [f64],
        scratch: &mut Vec<Complex64>,
    ) {
        assert!(live_rows <= self.ny, "inverse: live rows");
        assert_eq!(input.len(), self.spectrum_len(), "inverse: input length");
        assert_eq!(output.len(), live_rows * self.nx, "inverse: output length");
        let half = self.nx / 2 + 1;
        self.columns(input, &self.col_inverse);
        scratch.resize(self.ny * half, Complex::new(0.0, 0.0));
        transpose(input, scratch, half, self.ny);
        let nx_even = self.nx % 2 == 0;
        scratch[..live_rows * half]
            .par_chunks_mut(half)
            .zip(output.par_chunks_mut(self.nx))
            .for_each_init(
                || self.row_inverse.make_scratch_vec(),
                |work, (row, out)| {
                    // realfft insists on real DC (and Nyquist) bins; rounding leaves tiny
                    // imaginary parts there after the column pass.
                    row[0].im = 0.0;
                    if nx_even {
                        row[half - 1].im = 0.0;
                    }
                    self.row_inverse
                        .process_with_scratch(row, out, work)
                        .expect("row lengths match the plan");
                },
            );
    }

    /// Buffers for [`RealFft2::convolve`] with `live_rows` live rows.
    pub fn convolve_work(&self, live_rows: usize) -> ConvolveWork {
        let len = live_rows * (self.nx / 2 + 1);
        ConvolveWork {
            rows: vec![Complex::new(0.0, 0.0); len],
            blocks: vec![Complex::new(0.0, 0.0); len],
        }
    }

    /// `output = inverse(multiplier · forward(input))` (unnormalised, as [`RealFft2::inverse`])
    /// when only the first `live_rows` rows of the input can be non-zero and only the first
    /// `live_rows` rows of the output are wanted; `input` and `output` hold `live_rows` rows of
    /// `width ≤ nx` values (the input is zero beyond `width`, the output is cut at `width`), and
    /// `multiplier` is in the transposed spectrum layout.
    ///
    /// The arithmetic is that of [`RealFft2::forward_rows`], an element-wise product and
    /// [`RealFft2::inverse_rows`], bit for bit, but no whole spectrum is transposed: the columns
    /// are gathered [`COLUMN_BLOCK`] at a time from the row transforms, transformed, multiplied,
    /// transformed back while in cache, and left in blocks that the inverse row pass reads.
    pub fn convolve(
        &self,
        input: &[f64],
        width: usize,
        multiplier: &[f64],
        output: &mut [f64],
        work: &mut ConvolveWork,
    ) {
        let (nx, ny, half) = (self.nx, self.ny, self.nx / 2 + 1);
        let live = input.len() / width.max(1);
        assert!(width <= nx && live <= ny, "convolve: shape");
        assert_eq!(input.len(), live * width, "convolve: input length");
        assert_eq!(output.len(), live * width, "convolve: output length");
        assert_eq!(
            multiplier.len(),
            self.spectrum_len(),
            "convolve: multiplier"
        );
        assert_eq!(work.rows.len(), live * half, "convolve: work buffers");
        let zero = Complex::new(0.0, 0.0);
        // Forward row transforms of the zero-padded rows.
        input
            .par_chunks(width)
            .zip(work.rows.par_chunks_mut(half))
            .for_each_init(
                || (vec![0.0; nx], self.row_forward.make_scratch_vec()),
                |(padded, scratch), (row, out)| {
                    padded[..width].copy_from_slice(row);
                    padded[width..].fill(0.0);
                    self.row_forward
                        .process_with_scratch(padded, out, scratch)
                        .expect("row lengths match the plan");
                },
            );
        // Columns, a block at a time: forward, multiply, inverse; keep the live rows. Block b
        // holds columns b·COLUMN_BLOCK.. as `live` rows of its width.
        let rows = &work.rows;
        let scratch_len = self
            .col_forward
            .get_inplace_scratch_len()
            .max(self.col_inverse.get_inplace_scratch_len());
        work.blocks
            .par_chunks_mut(live * COLUMN_BLOCK)
            .enumerate()
            .for_each_init(
                || (vec![zero; COLUMN_BLOCK * ny], vec![zero; scratch_len]),
                |(columns, scratch), (b, block)| {
                    let (c0, w) = (b * COLUMN_BLOCK, block.len() / live);
                    for (r, row) in rows.chunks(half).enumerate() {
                        for (j, value) in row[c0..c0 + w].iter().enumerate() {
                            columns[j * ny + r] = *value;
                        }
                    }
                    for (j, column) in columns.chunks_mut(ny).take(w).enumerate() {
                        column[live..].fill(zero);
                        self.col_forward.process_with_scratch(column, scratch);
                        let m = &multiplier[(c0 + j) * ny..(c0 + j + 1) * ny];
                        for (c, t) in column.iter_mut().zip(m) {
                            *c *= *t;
                        }
                        self.col_inverse.process_with_scratch(column, scratch);
                    }
                    for (r, out) in block.chunks_mut(w).enumerate() {
                        for (j, value) in out.iter_mut().enumerate() {
                            *value = columns[j * ny + r];
                        }
                    }
                },
            );
        // Inverse row transforms of the live rows.
        let blocks = &work.blocks;
        let nx_even = nx % 2 == 0;
        output.par_chunks_mut(width).enumerate().for_each_init(
            || {
                let scratch = self.row_inverse.make_scratch_vec();
                (vec![zero; half], vec![0.0; nx], scratch)
            },
            |(row, full, scratch), (r, out)| {
                for (b, block) in blocks.chunks(live * COLUMN_BLOCK).enumerate() {
                    let w = block.len() / live;
                    row[b * COLUMN_BLOCK..b * COLUMN_BLOCK + w]
                        .copy_from_slice(&block[r * w..(r + 1) * w]);
                }
                // As in `inverse_rows`: realfft insists on real DC (and Nyquist) bins.
                row[0].im = 0.0;
                if nx_even {
                    row[half - 1].im = 0.0;
                }
                self.row_inverse
                    .process_with_scratch(row, full, scratch)
                    .expect("row lengths match the plan");
                out.copy_from_slice(&full[..width]);
            },
        );
    }

    fn columns(&self, data: &mut [Complex64], plan: &Arc<dyn Fft<f64>>) {
        data.par_chunks_mut(self.ny).for_each_init(
            || vec![Complex::new(0.0, 0.0); plan.get_inplace_scratch_len()],
            |scratch, column| plan.process_with_scratch(column, scratch),
        );
    }
}

/// Columns gathered per block by [`RealFft2::convolve`] (eight complex values: two cache lines
/// of each row; 4 and 16 measured the same within noise).
pub const COLUMN_BLOCK: usize = 8;

/// Buffers of [`RealFft2::convolve`]: the row transforms and the column blocks.
#[derive(Debug, Clone)]
pub struct ConvolveWork {
    rows: Vec<Complex64>,
    blocks: Vec<Complex64>,
}

/// `out[c * rows + r] = input[r * cols + c]`, blocked for cache reuse, in parallel over blocks
/// of output rows.
fn transpose(input: &[Complex64], out: &mut [Complex64], rows: usize, cols: usize) {
    const BLOCK: usize = 32;
    out.par_chunks_mut(rows * BLOCK)
        .enumerate()
        .for_each(|(block, chunk)| {
            let c0 = block * BLOCK;
            for r0 in (0..rows).step_by(BLOCK) {
                for c in c0..(c0 + BLOCK).min(cols) {
                    let dst = &mut chunk[(c - c0) * rows..];
                    for r in r0..(r0 + BLOCK).min(rows) {
                        dst[r] = input[r * cols + c];
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn naive_dft(f: &[f64], ny: usize, nx: usize, mx: i64, my: i64) -> Complex64 {
        let mut sum = Complex::new(0.0, 0.0);
        for y in 0..ny {
            for x in 0..nx {
                let phase = -2.0
                    * std::f64::consts::PI
                    * (mx as f64 * x as f64 / nx as f64 + my as f64 * y as f64 / ny as f64);
                sum += f[y * nx + x] * Complex::new(phase.cos(), phase.sin());
            }
        }
        sum
    }

    #[test]
    fn convolve_is_forward_product_inverse_bit_for_bit() {
        // (ny, nx, live rows, width): zero-padded (free) and full (periodic) shapes, odd and even
        // lengths, several column blocks with a partial last one.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for (ny, nx, live, width) in [(12, 40, 6, 20), (9, 7, 9, 7), (16, 34, 8, 17), (5, 4, 2, 1)]
        {
            let fft = RealFft2::new(ny, nx);
            let input: Vec<f64> = (0..live * width)
                .map(|_| rng.random_range(-1.0..1.0))
                .collect();
            let multiplier: Vec<f64> = (0..fft.spectrum_len())
                .map(|_| rng.random_range(0.0..2.0))
                .collect();
            // Reference: the separate passes.
            let mut padded = vec![0.0; live * nx];
            for (row, src) in padded.chunks_mut(nx).zip(input.chunks(width)) {
                row[..width].copy_from_slice(src);
            }
            let (mut spectrum, mut scratch) = (fft.make_spectrum(), Vec::new());
            fft.forward_rows(&mut padded, live, &mut spectrum, &mut scratch);
            for (c, m) in spectrum.iter_mut().zip(&multiplier) {
                *c *= *m;
            }
            let mut full = vec![0.0; live * nx];
            fft.inverse_rows(&mut spectrum, live, &mut full, &mut scratch);
            let mut output = vec![0.0; live * width];
            let mut work = fft.convolve_work(live);
            fft.convolve(&input, width, &multiplier, &mut output, &mut work);
            for (out, reference) in output.chunks(width).zip(full.chunks(nx)) {
                for (a, b) in out.iter().zip(reference) {
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "{ny}×{nx}, {live} rows of {width}"
                    );
                }
            }
        }
    }

    #[test]
    fn forward_matches_naive_dft_and_round_trips() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        for (ny, nx) in [(6, 8), (5, 7), (1, 4), (9, 1), (12, 10)] {
            let f: Vec<f64> = (0..nx * ny).map(|_| rng.random_range(-1.0..1.0)).collect();
            let fft = RealFft2::new(ny, nx);
            let mut spectrum = fft.make_spectrum();
            fft.forward(&mut f.clone(), &mut spectrum);
            for (i, value) in spectrum.iter().enumerate() {
                let (mx, my) = fft.wavenumbers(i);
                let expected = naive_dft(&f, ny, nx, mx, my);
                assert!((value - expected).norm() < 1e-12, "{ny}×{nx} ({mx},{my})");
            }
            let mut back = vec![0.0; nx * ny];
            fft.inverse(&mut spectrum, &mut back);
            for (a, b) in back.iter().zip(&f) {
                assert!((a / fft.len() as f64 - b).abs() < 1e-13);
            }
        }
    }
}
