//! Pressure → displacement operators on a grid, by FFT convolution.
//!
//! * [`Boundary::Free`]: zero padding to a 2N_y × 2N_x grid (Hockney 1970; Liu, Wang & Liu 2000,
//!   "DC-FFT"): circular convolution of length 2N is exact linear convolution of N-point supports.
//!   The kernel spectrum of the Love pixel response is computed once, and the round-trip
//!   normalisation 1/(4N_xN_y) is folded into it.
//! * [`Boundary::Periodic`]: the continuum multiplier 2/(E*|q|) on the N_y × N_x grid, q = 0 set
//!   to zero (docs/methods.md §1.4).
//!
//! Both are symmetric positive (semi-)definite, as conjugate gradients need.
//!
//! **Windows.** The free operator is translation-invariant, so the displacement on an `h × w`
//! window caused by pressure inside the same window only needs a zero-padded transform of
//! 2h' × 2w' with h' ≥ h, w' ≥ w ([`ElasticOperator::window`]): exact, and 16 times cheaper
//! for a window of a quarter of the map. The load solver keeps its fields on the window that can
//! carry load (`solver::cg::load`). Window operators are planned on first use and cached, and
//! take their kernel values from the whole operator's (the Love pixel responses at the offsets
//! the window spans are a corner of the whole grid's, the same numbers), so that planning one
//! costs its transform only.

use std::sync::{Arc, Mutex, OnceLock};

use rayon::prelude::*;

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
    /// Transfer function per spectrum element, normalisation included: computed on the first
    /// application (a solve on the GPU never needs it, and at 2048² it is most of the set-up).
    transfer: OnceLock<Vec<f64>>,
    self_coefficient: f64,
    /// Pixel size and modulus, to plan window operators.
    dx: f64,
    dy: f64,
    e_star: f64,
    /// Free boundaries: the Love pixel responses of the transfer function, computed on first
    /// use and shared with the window operators.
    quadrant: OnceLock<Quadrant>,
    /// Window operators planned so far.
    windows: Mutex<Vec<Arc<ElasticOperator>>>,
}

/// An operator for a window of an [`ElasticOperator`]'s grid: the operator itself or a smaller one.
#[derive(Debug, Clone)]
pub enum WindowOperator<'a> {
    /// The window needs the whole padded grid.
    Whole(&'a ElasticOperator),
    /// A smaller planned operator.
    Part(Arc<ElasticOperator>),
}

impl std::ops::Deref for WindowOperator<'_> {
    type Target = ElasticOperator;

    fn deref(&self) -> &ElasticOperator {
        match self {
            WindowOperator::Whole(op) => op,
            WindowOperator::Part(op) => op,
        }
    }
}

/// The smallest grid length on the ladder 1, 2, 3, 4, 6, 8, 12, 16, … (2^a and 3·2^a, sizes
/// whose doubled length RustFFT transforms fastest) that is at least `n`.
pub fn window_length(n: usize) -> usize {
    let mut power = 1usize;
    loop {
        if power >= n {
            return power;
        }
        if power >= 2 && power / 2 * 3 >= n {
            return power / 2 * 3;
        }
        power *= 2;
    }
}

impl ElasticOperator {
    /// Plan the operator for `ny × nx` pixels of `dx × dy` and contact modulus `e_star`.
    pub fn new(ny: usize, nx: usize, dx: f64, dy: f64, e_star: f64, boundary: Boundary) -> Self {
        let fft = match boundary {
            Boundary::Free => RealFft2::new(2 * ny, 2 * nx),
            Boundary::Periodic => RealFft2::new(ny, nx),
        };
        Self::planned(ny, nx, dx, dy, e_star, boundary, fft, OnceLock::new())
    }

    /// The free operator of `ny × nx` pixels whose kernel values come from `quadrant` (at least
    /// (ny + 1) × (nx + 1) offsets); it keeps no quadrant of its own.
    fn free(ny: usize, nx: usize, dx: f64, dy: f64, e_star: f64, quadrant: &Quadrant) -> Self {
        let fft = RealFft2::new(2 * ny, 2 * nx);
        let transfer = free_transfer(&fft, quadrant);
        Self::planned(ny, nx, dx, dy, e_star, Boundary::Free, fft, transfer.into())
    }

    #[allow(clippy::too_many_arguments)]
    fn planned(
        ny: usize,
        nx: usize,
        dx: f64,
        dy: f64,
        e_star: f64,
        boundary: Boundary,
        fft: RealFft2,
        transfer: OnceLock<Vec<f64>>,
    ) -> Self {
        ElasticOperator {
            nx,
            ny,
            boundary,
            fft,
            transfer,
            self_coefficient: love_pixel(0.0, 0.0, dx, dy, e_star),
            dx,
            dy,
            e_star,
            quadrant: OnceLock::new(),
            windows: Mutex::new(Vec::new()),
        }
    }

    /// The operator for fields on an `h × w` window of this grid (pressure inside the window,
    /// displacement wanted inside it): with free boundaries the smallest planned operator of at
    /// least `h × w` on the [`window_length`] ladder, else (or when that is not smaller) this
    /// one. Apply it with [`ElasticOperator::apply_window`].
    pub fn window(&self, h: usize, w: usize) -> WindowOperator<'_> {
        assert!(h <= self.ny && w <= self.nx, "window larger than the grid");
        let (wy, wx) = (window_length(h), window_length(w));
        if self.boundary == Boundary::Periodic || (wy >= self.ny && wx >= self.nx) {
            return WindowOperator::Whole(self);
        }
        let (wy, wx) = (wy.min(self.ny), wx.min(self.nx));
        let mut cache = self.windows.lock().expect("window cache lock");
        if let Some(op) = cache.iter().find(|op| op.ny == wy && op.nx == wx) {
            return WindowOperator::Part(Arc::clone(op));
        }
        let op = Arc::new(ElasticOperator::free(
            wy,
            wx,
            self.dx,
            self.dy,
            self.e_star,
            self.quadrant(),
        ));
        cache.push(Arc::clone(&op));
        WindowOperator::Part(op)
    }

    /// The Love pixel responses at offsets up to the grid's size, computed on first use.
    fn quadrant(&self) -> &Quadrant {
        self.quadrant
            .get_or_init(|| Quadrant::new(self.ny + 1, self.nx + 1, self.dx, self.dy, self.e_star))
    }

    /// The transfer function, computed on first use.
    fn transfer(&self) -> &[f64] {
        self.transfer.get_or_init(|| match self.boundary {
            Boundary::Free => free_transfer(&self.fft, self.quadrant()),
            Boundary::Periodic => periodic_transfer(&self.fft, self.dx, self.dy, self.e_star),
        })
    }

    /// The pixel size (Δx, Δy).
    pub fn pixel_size(&self) -> (f64, f64) {
        (self.dx, self.dy)
    }

    /// The contact modulus E*.
    pub fn modulus(&self) -> f64 {
        self.e_star
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
        self.window_workspace(self.ny)
    }

    /// A scratch buffer set for [`ElasticOperator::apply_window`] on windows of `h` rows.
    pub fn window_workspace(&self, h: usize) -> Workspace {
        Workspace {
            convolve: self.fft.convolve_work(h),
        }
    }

    /// u = G∗p for `p` and `u` of `ny·nx` values (row-major). With free boundaries only the
    /// physical rows are transformed forward and back: the padding rows are known zeros on the
    /// way in and discarded on the way out ([`RealFft2::convolve`]).
    pub fn apply(&self, p: &[f64], u: &mut [f64], work: &mut Workspace) {
        let n = self.nx * self.ny;
        assert!(p.len() == n && u.len() == n, "operator: field lengths");
        self.fft
            .convolve(p, self.nx, self.transfer(), u, &mut work.convolve);
    }

    /// u = G∗p on a window of `h` rows of `w` values (row-major; `h ≤ ny`, `w ≤ nx`) when the
    /// pressure outside the window is zero. Free boundaries only (a periodic operator wraps).
    pub fn apply_window(&self, p: &[f64], h: usize, w: usize, u: &mut [f64], work: &mut Workspace) {
        if h == self.ny && w == self.nx {
            return self.apply(p, u, work);
        }
        assert!(
            self.boundary == Boundary::Free && h <= self.ny && w <= self.nx,
            "operator: window"
        );
        assert!(
            p.len() == h * w && u.len() == h * w,
            "operator: field lengths"
        );
        self.fft
            .convolve(p, w, self.transfer(), u, &mut work.convolve);
    }
}

/// Scratch buffers of one operator application.
#[derive(Debug, Clone)]
pub struct Workspace {
    convolve: ConvolveWork,
}

/// The Love pixel responses G(i·dx, j·dy) for 0 ≤ i < qx, 0 ≤ j < qy (row-major, qx a row).
/// G is even in x and y, so these fill any kernel whose offsets stay within them.
#[derive(Debug)]
struct Quadrant {
    qx: usize,
    values: Vec<f64>,
}

impl Quadrant {
    fn new(qy: usize, qx: usize, dx: f64, dy: f64, e_star: f64) -> Self {
        let values = (0..qy * qx)
            .into_par_iter()
            .map(|k| love_pixel((k % qx) as f64 * dx, (k / qx) as f64 * dy, dx, dy, e_star))
            .collect();
        Quadrant { qx, values }
    }

    /// G at offsets (|x|, |y|) in pixels.
    fn at(&self, y: usize, x: usize) -> f64 {
        self.values[y * self.qx + x]
    }
}

fn free_transfer(fft: &RealFft2, quadrant: &Quadrant) -> Vec<f64> {
    let (fy, fx) = (fft.ny(), fft.nx());
    // Offsets wrap at half the padded length; G is even in x and y, so one quadrant of values
    // (|offset| ≤ half the length) fills the whole kernel.
    let fold = |i: usize, n: usize| if i <= n / 2 { i } else { n - i };
    let mut kernel = vec![0.0; fy * fx];
    kernel.par_chunks_mut(fx).enumerate().for_each(|(y, row)| {
        let oy = fold(y, fy);
        for (x, value) in row.iter_mut().enumerate() {
            *value = quadrant.at(oy, fold(x, fx));
        }
    });
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
        // docs/validation.md B1: zero-padded FFT product = direct O(N⁴) sum on a small grid, 1e-12.
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
    fn window_operator_equals_the_whole_one_inside_the_window() {
        // A pressure patch inside a 9 × 14 window of a 40 × 36 grid: the window operator (padded
        // 2·12 × 2·16) gives the whole operator's displacement on the window, to round-off.
        let (ny, nx, dx, dy, e) = (40, 36, 0.7, 0.9, 2.5);
        let (y0, x0, h, w) = (13, 5, 9, 14);
        let op = ElasticOperator::new(ny, nx, dx, dy, e, Boundary::Free);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let mut p = vec![0.0; nx * ny];
        let mut window_p = vec![0.0; h * w];
        for yy in 0..h {
            for xx in 0..w {
                let v = rng.random_range(0.0..1.0);
                p[(y0 + yy) * nx + x0 + xx] = v;
                window_p[yy * w + xx] = v;
            }
        }
        let mut u = vec![0.0; nx * ny];
        op.apply(&p, &mut u, &mut op.workspace());
        let part = op.window(h, w);
        assert_eq!((part.ny(), part.nx()), (12, 16), "ladder sizes");
        let mut window_u = vec![0.0; h * w];
        part.apply_window(
            &window_p,
            h,
            w,
            &mut window_u,
            &mut part.window_workspace(h),
        );
        let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for yy in 0..h {
            for xx in 0..w {
                let (a, b) = (u[(y0 + yy) * nx + x0 + xx], window_u[yy * w + xx]);
                assert!((a - b).abs() < 1e-13 * scale, "({yy}, {xx}): {a} vs {b}");
            }
        }
        // A window as large as the grid is the operator itself.
        assert!(matches!(op.window(ny, nx), WindowOperator::Whole(_)));
        // Its kernel values come from the whole operator's: the same transfer function, bit for
        // bit, as an operator planned on its own.
        let own = ElasticOperator::new(12, 16, dx, dy, e, Boundary::Free);
        assert_eq!(part.transfer().len(), own.transfer().len());
        assert!(part
            .transfer()
            .iter()
            .zip(own.transfer())
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn window_lengths_climb_the_ladder() {
        let ladder: Vec<usize> = (1..=25).map(window_length).collect();
        assert_eq!(
            ladder,
            [
                1, 2, 3, 4, 6, 6, 8, 8, 12, 12, 12, 12, 16, 16, 16, 16, 24, 24, 24, 24, 24, 24, 24,
                24, 32
            ]
        );
        assert_eq!(window_length(1025), 1536);
    }

    #[test]
    fn periodic_single_mode() {
        // docs/validation.md B2: p = p₀ cos(q·x) gives u = 2p₀/(E*|q|) cos(q·x); mean pressure gives 0.
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
