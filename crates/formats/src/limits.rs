//! Limits on the sizes of work: planes and maps decoded from files or asked for on the command
//! line, blur kernels, resampled grids and sampled profiles. Every reader and every algorithm
//! whose work size comes from a number it was given checks that number against [`Limits`] first,
//! with checked arithmetic, and refuses with a message naming the value instead of allocating
//! terabytes, looping for ever or wrapping a product to zero (`docs/errors.md`). The idea is
//! image-tiff's `Limits` (a decoding budget); these limits are far above any real image or
//! simulation and far below what would exhaust a workstation.

/// The article of a number as it is spoken: "an" before 8, 11, 18, 80…89, 800…, 11 000, 18 000
/// ("an 8×8 plane", "an 11×4 plane"), else "a".
pub(crate) fn article(n: usize) -> &'static str {
    let digits = n.to_string();
    let eleven_or_eighteen =
        digits.len() % 3 == 2 && (digits.starts_with("11") || digits.starts_with("18"));
    if digits.starts_with('8') || eleven_or_eighteen {
        "an"
    } else {
        "a"
    }
}

/// A work size beyond the [`Limits`], with the numbers.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LimitError {
    /// A plane with no pixels.
    #[error("{} {nx}×{ny} plane has no pixels", article(*.nx))]
    EmptyPlane {
        /// Columns.
        nx: usize,
        /// Rows.
        ny: usize,
    },
    /// A side longer than [`Limits::max_side`].
    #[error("{} {nx}×{ny} plane exceeds the limit of {limit} pixels per side", article(*.nx))]
    SideTooLong {
        /// Columns.
        nx: usize,
        /// Rows.
        ny: usize,
        /// The limit.
        limit: usize,
    },
    /// More bytes than [`Limits::max_plane_bytes`].
    #[error(
        "{} {nx}×{ny} plane of {bytes_per_value}-byte values exceeds the {limit_mib} MiB limit",
        article(*.nx)
    )]
    PlaneTooLarge {
        /// Columns.
        nx: usize,
        /// Rows.
        ny: usize,
        /// Bytes per value.
        bytes_per_value: usize,
        /// The limit, MiB.
        limit_mib: usize,
    },
    /// A Gaussian kernel wider than [`Limits::max_kernel_radius`].
    #[error("a Gaussian of σ = {sigma_px:.4e} pixels needs a kernel of ±{radius:e} pixels (limit ±{limit})")]
    KernelTooWide {
        /// σ, pixels.
        sigma_px: f64,
        /// ⌈4σ⌉.
        radius: f64,
        /// The limit, pixels.
        limit: usize,
    },
    /// Too many samples along an axis.
    #[error("{extent_m:.4e} m in pixels of {pixel_m:.4e} m is {samples:e} pixels (limit {limit})")]
    TooManySamples {
        /// Length, m.
        extent_m: f64,
        /// Pixel, m.
        pixel_m: f64,
        /// Pixels it would take.
        samples: f64,
        /// The limit.
        limit: usize,
    },
}

/// The limits in force. [`Limits::DEFAULT`] is what the command line and Python use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Largest decoded plane, height map or simulation grid, bytes (1 GiB).
    pub max_plane_bytes: usize,
    /// Longest side of a plane or grid, pixels (65 536).
    pub max_side: usize,
    /// Largest half-width of a blur kernel, pixels (1 024: ⌈4σ⌉ for a PSF about 600 pixels wide).
    pub max_kernel_radius: usize,
    /// Most samples along all line profiles of one measurement (2^24).
    pub max_profile_samples: usize,
}

impl Limits {
    /// The default limits.
    pub const DEFAULT: Limits = Limits {
        max_plane_bytes: 1 << 30,
        max_side: 1 << 16,
        max_kernel_radius: 1024,
        max_profile_samples: 1 << 24,
    };

    /// Bytes of an `nx × ny` plane of `bytes_per_value`, checked against overflow, the side
    /// limit and the byte limit. The error text names the size and the limit.
    pub fn plane_bytes(
        &self,
        nx: usize,
        ny: usize,
        bytes_per_value: usize,
    ) -> Result<usize, LimitError> {
        if nx == 0 || ny == 0 {
            return Err(LimitError::EmptyPlane { nx, ny });
        }
        if nx > self.max_side || ny > self.max_side {
            return Err(LimitError::SideTooLong {
                nx,
                ny,
                limit: self.max_side,
            });
        }
        nx.checked_mul(ny)
            .and_then(|n| n.checked_mul(bytes_per_value))
            .filter(|&b| b <= self.max_plane_bytes)
            .ok_or(LimitError::PlaneTooLarge {
                nx,
                ny,
                bytes_per_value,
                limit_mib: self.max_plane_bytes >> 20,
            })
    }

    /// The radius ⌈4σ⌉ of a Gaussian kernel of `sigma_px` pixels, if within the limit.
    pub fn kernel_radius(&self, sigma_px: f64) -> Result<usize, LimitError> {
        let radius = (4.0 * sigma_px).ceil();
        if sigma_px.is_finite() && sigma_px >= 0.0 && radius <= self.max_kernel_radius as f64 {
            Ok(radius as usize)
        } else {
            Err(LimitError::KernelTooWide {
                sigma_px,
                radius,
                limit: self.max_kernel_radius,
            })
        }
    }

    /// Pixels along an axis of `extent_m` cut into pixels of `pixel_m`, if within the side limit.
    pub fn samples(&self, extent_m: f64, pixel_m: f64) -> Result<usize, LimitError> {
        // The tolerance keeps an exact multiple (10 µm / 200 nm) from gaining a sliver pixel.
        let n = ((extent_m / pixel_m) * (1.0 - 1e-12)).ceil();
        if n.is_finite() && n >= 0.0 && n <= self.max_side as f64 {
            Ok(n as usize)
        } else {
            Err(LimitError::TooManySamples {
                extent_m,
                pixel_m,
                samples: n,
                limit: self.max_side,
            })
        }
    }
}

impl Default for Limits {
    fn default() -> Self {
        Limits::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_take_the_article_they_are_spoken_with() {
        for (n, a) in [
            (0, "a"),
            (1, "a"),
            (8, "an"),
            (11, "an"),
            (18, "an"),
            (80, "an"),
            (110, "a"),
            (181, "a"),
            (512, "a"),
            (800, "an"),
            (1100, "a"),
            (11_000, "an"),
            (18_432, "an"),
            (180_000, "a"),
        ] {
            assert_eq!(article(n), a, "{n}");
        }
        let e = LimitError::EmptyPlane { nx: 8, ny: 0 };
        assert_eq!(e.to_string(), "an 8×0 plane has no pixels");
    }

    #[test]
    fn products_that_wrap_are_refused() {
        let l = Limits::DEFAULT;
        assert_eq!(l.plane_bytes(512, 256, 2), Ok(262_144));
        // 2^58 × 2^58 × 2 wraps to 0 in unchecked arithmetic.
        assert!(l.plane_bytes(1 << 58, 1 << 58, 2).is_err());
        assert!(l.plane_bytes(1 << 16, 1 << 16, 8).is_err());
        assert!(l.plane_bytes(0, 5, 2).is_err());
        assert!(l.kernel_radius(2.0).is_ok());
        assert!(l.kernel_radius(1e13).is_err());
        assert!(l.kernel_radius(f64::NAN).is_err());
        assert!(l.samples(1e-3, 1e-300).is_err());
        assert_eq!(l.samples(10e-6, 200e-9), Ok(50));
    }
}
