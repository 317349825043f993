//! Height maps: the rigid rough body of a contact calculation.
//!
//! A [`Topography`] holds heights in metres on a regular grid, row-major `(y, x)`, with heights
//! **positive towards the counter-surface** (the apex of a sphere is the maximum), as measured on
//! a sphere's top by AFM. The solver converts to the undeformed separation
//! `s = max(h) − h` (`docs/conventions.md`, methods.md §0).

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

impl Topography {
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
}
