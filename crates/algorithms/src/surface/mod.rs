//! Height maps: the rigid rough body of a contact calculation.
//!
//! A [`Topography`] holds heights in metres on a regular grid, row-major `(y, x)`, with heights
//! **positive towards the counter-surface** (the apex of a sphere is the maximum), as measured on
//! a sphere's top by AFM. The solver converts to the undeformed separation
//! `s = max(h) − h` (`docs/conventions.md`, docs/methods.md §0).
//!
//! * [`stats`] — rms height, slope and curvature (finite-difference and spectral estimators) and
//!   the radially averaged power spectral density (Jacobs, Junge, Pastewka 2017).
//! * [`generate`] — seeded self-affine random surfaces by Fourier filtering (Ramisetti et al.
//!   2011; docs/methods.md §5.2).
//! * [`masked`] — the same statistics over the valid points of a map as an instrument stored it
//!   (invalid points NaN); [`fill`] — filling those points on request.
//! * Reading and writing height maps (`.npy`, float TIFF, Gwyddion `.gsf`, text matrices, WSxM
//!   `.top`, Bruker/Nanoscope, vendor AFM formats) is `contactscope_formats::topography`, which
//!   returns a [`HeightMap`]; [`Topography::from_height_map`] takes it.

pub mod bearing;
pub mod fill;
pub mod generate;
pub mod masked;
pub mod stats;
pub mod trend;

pub use contactscope_formats::topography::HeightMap;

use ndarray::Array2;

use crate::error::{Error, Result};

/// Heights on a regular grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Topography {
    /// Heights in metres, shape `(ny, nx)`, positive towards the counter-surface.
    pub heights: Array2<f64>,
    /// Pixel size along x (columns), metres.
    pub dx_m: f64,
    /// Pixel size along y (rows), metres.
    pub dy_m: f64,
}

/// Largest height magnitude a topography may hold, m: low enough that sums of squares of heights
/// can never overflow (a finite height of 1e154 m once gave h_rms = ∞). Height maps read from
/// files are held to a much tighter, physical bound
/// (`contactscope_formats::topography::MAX_FILE_HEIGHT_M`).
pub const MAX_ABS_HEIGHT_M: f64 = 1e100;

impl Topography {
    /// The heights and pixel size of a map read from a file (every point must be valid: fill
    /// invalid points first, [`fill::fill_invalid`]).
    pub fn from_height_map(map: HeightMap) -> Result<Self> {
        Topography::new(map.heights, map.dx_m, map.dy_m)
    }

    /// A topography; heights must be finite and the pixel size positive.
    pub fn new(heights: Array2<f64>, dx_m: f64, dy_m: f64) -> Result<Self> {
        if !(dx_m.is_finite() && dy_m.is_finite() && dx_m > 0.0 && dy_m > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "pixel size must be positive and finite (got {dx_m} × {dy_m} m)"
            )));
        }
        if heights.is_empty() {
            return Err(Error::InvalidArgument("topography has no pixels".into()));
        }
        if let Some(bad) = heights.iter().position(|h| !h.is_finite()) {
            let nx = heights.ncols();
            return Err(Error::InvalidArgument(format!(
                "height at row {}, column {} is not finite (NaN or ∞)",
                bad / nx,
                bad % nx
            )));
        }
        if let Some(bad) = heights.iter().position(|h| h.abs() > MAX_ABS_HEIGHT_M) {
            let nx = heights.ncols();
            return Err(Error::InvalidArgument(format!(
                "height at row {}, column {} is {:e} m, beyond ±{MAX_ABS_HEIGHT_M:e} m",
                bad / nx,
                bad % nx,
                heights.iter().nth(bad).copied().unwrap_or(f64::NAN)
            )));
        }
        Ok(Topography {
            heights,
            dx_m,
            dy_m,
        })
    }

    /// Columns.
    pub fn nx(&self) -> usize {
        self.heights.ncols()
    }

    /// Rows.
    pub fn ny(&self) -> usize {
        self.heights.nrows()
    }

    /// Physical size (x, y) in metres.
    pub fn size_m(&self) -> (f64, f64) {
        (self.nx() as f64 * self.dx_m, self.ny() as f64 * self.dy_m)
    }

    /// Nominal area `A₀ = nx·dx · ny·dy` in m².
    pub fn area_m2(&self) -> f64 {
        let (lx, ly) = self.size_m();
        lx * ly
    }

    /// Mean height in metres.
    pub fn mean(&self) -> f64 {
        self.heights.sum() / self.heights.len() as f64
    }

    /// Root-mean-square height about the mean, `sqrt(⟨(h − ⟨h⟩)²⟩)`, in metres, over every pixel.
    /// No detrending beyond the mean: call [`Topography::remove_plane`] (or
    /// [`Topography::detrend`]) first where a tilt should not count as roughness
    /// (docs/methods.md §5.4).
    pub fn rms_height(&self) -> f64 {
        let mean = self.mean();
        let sum: f64 = self.heights.iter().map(|h| (h - mean) * (h - mean)).sum();
        (sum / self.heights.len() as f64).sqrt()
    }

    /// Subtract the mean height, so that `⟨h⟩ = 0`.
    pub fn remove_mean(&mut self) {
        let mean = self.mean();
        self.heights.mapv_inplace(|h| h - mean);
    }

    /// Subtract the least-squares plane `a + b·x + c·y` (also removes the mean).
    ///
    /// On a full regular grid the centred pixel coordinates are orthogonal to each other and to
    /// the constant, so the normal equations decouple: `a = ⟨h⟩`, `b = Σ x̃·h / Σ x̃²`,
    /// `c = Σ ỹ·h / Σ ỹ²` with `x̃ = j − (nx − 1)/2`, `ỹ = i − (ny − 1)/2`. An exact plane is
    /// removed to rounding error.
    pub fn remove_plane(&mut self) {
        let (cx, cy) = centre_index(self.nx(), self.ny());
        let (mut sxh, mut sxx, mut syh, mut syy) = (0.0, 0.0, 0.0, 0.0);
        for ((i, j), &h) in self.heights.indexed_iter() {
            let (x, y) = (j as f64 - cx, i as f64 - cy);
            sxh += x * h;
            sxx += x * x;
            syh += y * h;
            syy += y * y;
        }
        let b = if sxx > 0.0 { sxh / sxx } else { 0.0 };
        let c = if syy > 0.0 { syh / syy } else { 0.0 };
        let a = self.mean();
        for ((i, j), h) in self.heights.indexed_iter_mut() {
            *h -= a + b * (j as f64 - cx) + c * (i as f64 - cy);
        }
    }

    /// Apply a [`Detrend`].
    pub fn detrend(&mut self, detrend: Detrend) {
        match detrend {
            Detrend::None => {}
            Detrend::Mean => self.remove_mean(),
            Detrend::Plane => self.remove_plane(),
        }
    }

    /// Add a spherical cap of radius `radius_m` in its small-slope (paraboloid) form
    /// `−r²/(2R)`, centred on the map centre (pixel centres `(nx − 1)/2`, `(ny − 1)/2`), so
    /// that the apex is the highest point: heights are positive towards the counter-surface
    /// (docs/methods.md §0, `s = r²/(2R) − z_rough`).
    pub fn add_sphere(&mut self, radius_m: f64) -> Result<()> {
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "sphere radius must be positive and finite (got {radius_m} m)"
            )));
        }
        let (cx, cy) = centre_index(self.nx(), self.ny());
        let (dx, dy) = (self.dx_m, self.dy_m);
        for ((i, j), h) in self.heights.indexed_iter_mut() {
            let (x, y) = ((j as f64 - cx) * dx, (i as f64 - cy) * dy);
            *h -= (x * x + y * y) / (2.0 * radius_m);
        }
        Ok(())
    }
}

/// Detrending applied to a measured map before statistics (docs/methods.md §5.4: "record which").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detrend {
    /// Heights as read.
    None,
    /// Subtract the mean height.
    #[default]
    Mean,
    /// Subtract the least-squares plane (tilt of the sample or scanner).
    Plane,
}

impl Detrend {
    /// Every detrending.
    pub const ALL: [Detrend; 3] = [Detrend::None, Detrend::Mean, Detrend::Plane];

    /// The detrending of a name ([`Detrend::name`]), `None` for another word.
    pub fn from_name(name: &str) -> Option<Detrend> {
        Self::ALL.into_iter().find(|d| d.name() == name)
    }

    /// Lowercase name for outputs (`none`, `mean`, `plane`).
    pub fn name(self) -> &'static str {
        match self {
            Detrend::None => "none",
            Detrend::Mean => "mean",
            Detrend::Plane => "plane",
        }
    }
}

/// Centre of the pixel grid in index units.
fn centre_index(nx: usize, ny: usize) -> (f64, f64) {
    ((nx as f64 - 1.0) / 2.0, (ny as f64 - 1.0) / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(ny: usize, nx: usize) -> Topography {
        let h = Array2::from_shape_fn((ny, nx), |(i, j)| 1e-6 + 3e-8 * j as f64 - 2e-8 * i as f64);
        Topography::new(h, 1e-7, 2e-7).unwrap()
    }

    #[test]
    fn rejects_bad_pixel_sizes_and_non_finite_heights() {
        let h = Array2::zeros((4, 4));
        assert!(Topography::new(h.clone(), 0.0, 1.0).is_err());
        assert!(Topography::new(h.clone(), 1.0, -1.0).is_err());
        assert!(Topography::new(h.clone(), f64::NAN, 1.0).is_err());
        let mut bad = h;
        bad[[2, 1]] = f64::NAN;
        let err = Topography::new(bad, 1.0, 1.0).unwrap_err().to_string();
        assert!(err.contains("row 2, column 1"), "{err}");
        assert!(Topography::new(Array2::zeros((0, 3)), 1.0, 1.0).is_err());
    }

    #[test]
    fn removes_an_exact_plane() {
        for (ny, nx) in [(7, 9), (8, 8), (1, 5), (5, 1)] {
            let mut t = plane(ny, nx);
            t.remove_plane();
            let worst = t.heights.iter().fold(0.0f64, |m, h| m.max(h.abs()));
            assert!(worst < 1e-12 * 1e-6, "{ny}×{nx}: {worst}");
        }
    }

    #[test]
    fn mean_and_rms() {
        let h = Array2::from_shape_vec((2, 2), vec![0.25, 0.75, 0.25, 0.75]).unwrap();
        let mut t = Topography::new(h, 1.0, 1.0).unwrap();
        assert_eq!(t.mean(), 0.5);
        assert_eq!(t.rms_height(), 0.25);
        t.detrend(Detrend::Mean);
        assert_eq!(t.mean(), 0.0);
        assert_eq!(t.area_m2(), 4.0);
    }

    #[test]
    fn sphere_apex_is_the_maximum_at_the_centre() {
        let mut t = Topography::new(Array2::zeros((5, 7)), 1e-6, 1e-6).unwrap();
        t.add_sphere(1e-3).unwrap();
        assert_eq!(t.heights[[2, 3]], 0.0);
        let corner = -((3e-6f64).powi(2) + (2e-6f64).powi(2)) / 2e-3;
        assert!((t.heights[[0, 0]] - corner).abs() < 1e-24);
        assert!(t.heights.iter().all(|&h| h <= 0.0));
        assert!(t.add_sphere(0.0).is_err());
    }
}
