//! The "GT bearing-area" contact map: a measured roughness map overlaid on the GT separation
//! profile (Weber et al. 2018, Fig. 2b).

use ndarray::Array2;

use super::profile::GtProfile;
use crate::error::{Error, Result};
use crate::surface::Topography;

/// The GT bearing-area contact map (Weber et al. 2018, Fig. 2b; `docs/methods.md` §4.4).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactMap {
    /// Contact pixels, shape `(ny, nx)` like the roughness map.
    pub mask: Array2<bool>,
    /// Number of contact pixels.
    pub contact_pixels: usize,
    /// Contact pixels over all pixels.
    pub contact_fraction: f64,
    /// Contact pixels × pixel area, m² (the geometric overlap area).
    pub area_m2: f64,
    /// GT's own real-area integral 2π ∫ π·η·β·σ·F₁(u/σ) r dr of the profile, m², for
    /// comparison: it is not the overlap area (per asperity the overlap is twice the Hertz area,
    /// and the overlap fraction at separation u is about F₀(u/σ)).
    pub gt_area_m2: f64,
    /// Centre of the sphere used, (x, y) in m from the outer corner of pixel (0, 0).
    pub centre_m: (f64, f64),
}

/// Overlays a roughness map on the GT separation profile: a pixel is in contact where
/// z_rough(x, y) ≥ u_GT(r(x, y)) (`docs/methods.md` §4.4).
///
/// `roughness` is the measured **roughness** z_rough, not the sphere: heights in m with the mean
/// plane removed, positive towards the flat (the [`Topography`] convention); the caller removes
/// the sphere and the mean plane, because u_GT already contains the sphere's r²/(2R). Pixel
/// (iy, ix) sits at its centre ((ix + ½)·dx, (iy + ½)·dy); r is measured from `centre` ((x, y)
/// in m from the outer corner of pixel (0, 0); default: the middle of the map). Beyond the
/// profile's last radius u_GT continues as in [`GtProfile::separation_at`]. No elastic
/// interaction between the overlapping asperities is modelled.
pub fn gt_bearing_area(
    roughness: &Topography,
    profile: &GtProfile,
    centre: Option<(f64, f64)>,
) -> Result<ContactMap> {
    profile.check()?;
    let (dx, dy) = (roughness.dx_m, roughness.dy_m);
    let (width, height) = roughness.size_m();
    let (x0, y0) = centre.unwrap_or((0.5 * width, 0.5 * height));
    if !(x0.is_finite() && y0.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "bearing-area centre must be finite (got ({x0}, {y0}) m)"
        )));
    }
    let mask = Array2::from_shape_fn(roughness.heights.dim(), |(iy, ix)| {
        let x = (ix as f64 + 0.5) * dx - x0;
        let y = (iy as f64 + 0.5) * dy - y0;
        roughness.heights[[iy, ix]] >= profile.separation_at(x.hypot(y))
    });
    let contact_pixels = mask.iter().filter(|&&c| c).count();
    Ok(ContactMap {
        contact_fraction: contact_pixels as f64 / mask.len() as f64,
        area_m2: contact_pixels as f64 * dx * dy,
        mask,
        contact_pixels,
        gt_area_m2: profile.gt_area_m2,
        centre_m: (x0, y0),
    })
}
