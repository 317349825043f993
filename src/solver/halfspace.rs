//! Pressure → displacement operators on a grid, by FFT convolution.
//!
//! * [`Boundary::Free`]: zero padding to a 2N_y × 2N_x grid (Hockney 1970; Liu, Wang & Liu 2000,
//!   "DC-FFT"): circular convolution of length 2N is exact linear convolution of N-point supports.
//!   The kernel spectrum of the Love pixel response is computed once, and the round-trip
//!   normalisation 1/(4N_xN_y) is folded into it.
//! * [`Boundary::Periodic`]: the continuum multiplier 2/(E*|q|) on the N_y × N_x grid, q = 0 set
//!   to zero (methods.md §1.4).
//!
//! Both are symmetric positive (semi-)definite, as conjugate gradients need.

use crate::spectral::{ConvolveWork, RealFft2};

use super::greens::{love_pixel, periodic_compliance};

/// Boundary conditions of the half-space.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// An isolated contact: the map is surrounded by unloaded surface (zero padding).
    Free,
    /// The map is one period of an infinite surface.
    Periodic,
}

/// A planned operator u = G∗p for one grid and modulus.
#[derive(Debug)]
pub struct ElasticOperator {
    nx: usize,
    ny: usize,
    boundary: Boundary,
    fft: RealFft2,
    /// Transfer function per spectrum element, normalisation included.
    transfer: Vec<f64>,
    self_coefficient: f64,
}

impl ElasticOperator {
    /// Plan the operator for `ny × nx` pixels of `dx × dy` and contact modulus `e_star`.
    pub fn new(ny: usize, nx: usize, dx: f64, dy: f64, e_star: f64, boundary: Boundary) -> Self {
        let (fy, fx) = match boundary {
            Boundary::Free => (2 * ny, 2 * nx),
            Boundary::Periodic => (ny, nx),
        };
        let fft = RealFft2::new(fy, fx);
        let transfer = match boundary {
            Boundary::Free => free_transfer(&fft, dx, dy, e_star),
            Boundary::Periodic => periodic_transfer(&fft, dx, dy, e_star),
        };
        ElasticOperator {
            nx,
            ny,
            boundary,
            fft,
            transfer,
            self_coefficient: love_pixel(0.0, 0.0, dx, dy, e_star),
        }
    }

    /// Grid rows.
    pub fn ny(&self) -> usize {
        self.ny
    }

    /// Grid columns.
    pub fn nx(&self) -> usize {
        self.nx
    }

    /// The boundary conditions.
    pub fn boundary(&self) -> Boundary {
        self.boundary
    }

    /// Displacement at a loaded pixel's centre per unit pressure on that pixel (1.12·Δ/E* for
    /// square pixels): the local compliance, used for first steps.
    pub fn self_coefficient(&self) -> f64 {
        self.self_coefficient
    }

    /// A scratch buffer set for [`ElasticOperator::apply`].
    pub fn workspace(&self) -> Workspace {
        Workspace {
            convolve: self.fft.convolve_work(self.ny),
        }
    }

    /// u = G∗p for `p` and `u` of `ny·nx` values (row-major). With free boundaries only the
    /// physical rows are transformed forward and back: the padding rows are known zeros on the
    /// way in and discarded on the way out ([`RealFft2::convolve`]).
    pub fn apply(&self, p: &[f64], u: &mut [f64], work: &mut Workspace) {
        let n = self.nx * self.ny;
        assert!(p.len() == n && u.len() == n, "operator: field lengths");
        self.fft
            .convolve(p, self.nx, &self.transfer, u, &mut work.convolve);
    }
}

/// Scratch buffers of one operator application.
#[derive(Debug, Clone)]
pub struct Workspace {
    convolve: ConvolveWork,
}

fn free_transfer(fft: &RealFft2, dx: f64, dy: f64, e_star: f64) -> Vec<f64> {
    let (fy, fx) = (fft.ny(), fft.nx());
    let wrap = |i: usize, n: usize| {
        if i <= n / 2 {
            i as f64
        } else {
            i as f64 - n as f64
        }
    };
    let mut kernel: Vec<f64> = (0..fy * fx)
        .map(|k| {
            let (y, x) = (wrap(k / fx, fy) * dy, wrap(k % fx, fx) * dx);
            love_pixel(x, y, dx, dy, e_star)
        })
        .collect();
    let mut spectrum = fft.make_spectrum();
    fft.forward(&mut kernel, &mut spectrum);
    // The kernel is real and even, so its spectrum is real.
    let scale = 1.0 / fft.len() as f64;
    spectrum.iter().map(|c| c.re * scale).collect()
}

fn periodic_transfer(fft: &RealFft2, dx: f64, dy: f64, e_star: f64) -> Vec<f64> {
    let (lx, ly) = (fft.nx() as f64 * dx, fft.ny() as f64 * dy);
    let scale = 1.0 / fft.len() as f64;
    (0..fft.spectrum_len())
        .map(|i| {
            let (mx, my) = fft.wavenumbers(i);
            let qx = 2.0 * std::f64::consts::PI * mx as f64 / lx;
            let qy = 2.0 * std::f64::consts::PI * my as f64 / ly;
            periodic_compliance(qx.hypot(qy), e_star) * scale
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn free_operator_equals_direct_summation() {
        // validation.md B1: zero-padded FFT product = direct O(N⁴) sum on a small grid, 1e-12.
        let (ny, nx, dx, dy, e) = (16, 13, 0.7, 0.9, 2.5);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let p: Vec<f64> = (0..nx * ny).map(|_| rng.random_range(0.0..1.0)).collect();
        let op = ElasticOperator::new(ny, nx, dx, dy, e, Boundary::Free);
        let mut u = vec![0.0; nx * ny];
        op.apply(&p, &mut u, &mut op.workspace());
        let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (i, ui) in u.iter().enumerate() {
            let (yi, xi) = ((i / nx) as f64, (i % nx) as f64);
            let direct: f64 = (0..nx * ny)
                .map(|j| {
                    let (yj, xj) = ((j / nx) as f64, (j % nx) as f64);
                    love_pixel((xi - xj) * dx, (yi - yj) * dy, dx, dy, e) * p[j]
                })
                .sum();
            assert!((ui - direct).abs() < 1e-12 * scale, "pixel {i}");
        }
    }

    #[test]
    fn periodic_single_mode() {
        // validation.md B2: p = p₀ cos(q·x) gives u = 2p₀/(E*|q|) cos(q·x); mean pressure gives 0.
        let (ny, nx, dx, dy, e) = (8, 32, 0.5, 0.25, 3.0);
        let op = ElasticOperator::new(ny, nx, dx, dy, e, Boundary::Periodic);
        let (lx, ly) = (nx as f64 * dx, ny as f64 * dy);
        let (qx, qy) = (
            2.0 * std::f64::consts::PI * 3.0 / lx,
            2.0 * std::f64::consts::PI / ly,
        );
        let q = qx.hypot(qy);
        let p: Vec<f64> = (0..nx * ny)
            .map(|i| 5.0 + 0.7 * (qx * (i % nx) as f64 * dx + qy * (i / nx) as f64 * dy).cos())
            .collect();
        let mut u = vec![0.0; nx * ny];
        op.apply(&p, &mut u, &mut op.workspace());
        for (i, ui) in u.iter().enumerate() {
            let expected =
                2.0 * 0.7 / (e * q) * (qx * (i % nx) as f64 * dx + qy * (i / nx) as f64 * dy).cos();
            assert!((ui - expected).abs() < 1e-12 * 2.0 * 0.7 / (e * q), "{i}");
        }
    }
}
