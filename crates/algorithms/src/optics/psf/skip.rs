//! Why a bead candidate is not used (docs/methods.md §7.3: isolated, unsaturated, in-focus beads only).

use super::{Candidate, PlaneView, PsfOptions, SpotFit};

/// Why a candidate does not enter the summary.
#[derive(Debug, Clone, PartialEq)]
pub enum SkipReason {
    /// The window does not fit inside the image.
    AtEdge,
    /// Another candidate lies inside the window.
    Crowded {
        /// Distance to the nearest such candidate, pixels.
        distance_px: f64,
    },
    /// A plateau at the saturation level.
    Saturated {
        /// Window pixels at or above the level.
        pixels: usize,
        /// The level.
        level: f64,
    },
    /// The brightest plane is the first or last of the stack.
    FocusAtStackEnd {
        /// That plane.
        plane: usize,
    },
    /// A fit failed or did not converge.
    FitFailed(String),
    /// The fitted σ is outside the plausible range for this window.
    Implausible {
        /// Fitted σ, pixels.
        sigma_px: f64,
    },
    /// The imaged spot is narrower than the bead itself, so no correction is possible.
    SmallerThanBead {
        /// Fitted σ, pixels.
        sigma_px: f64,
    },
}

impl std::fmt::Display for SkipReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SkipReason::AtEdge => write!(f, "at the image edge (window does not fit)"),
            SkipReason::Crowded { distance_px } => {
                write!(f, "crowded (another candidate {distance_px:.1} px away)")
            }
            SkipReason::Saturated { pixels, level } => {
                write!(f, "saturated ({pixels} pixels at {level})")
            }
            SkipReason::FocusAtStackEnd { plane } => {
                write!(f, "focus at the stack end (plane {plane})")
            }
            SkipReason::FitFailed(why) => write!(f, "fit failed ({why})"),
            SkipReason::Implausible { sigma_px } => {
                write!(f, "implausible sigma ({sigma_px:.3} px)")
            }
            SkipReason::SmallerThanBead { sigma_px } => {
                write!(f, "spot narrower than the bead (sigma {sigma_px:.3} px)")
            }
        }
    }
}

impl SkipReason {
    /// A short machine-readable key (`crowded`, `saturated`, …).
    pub fn key(&self) -> &'static str {
        match self {
            SkipReason::AtEdge => "edge",
            SkipReason::Crowded { .. } => "crowded",
            SkipReason::Saturated { .. } => "saturated",
            SkipReason::FocusAtStackEnd { .. } => "focus-at-stack-end",
            SkipReason::FitFailed(_) => "fit-failed",
            SkipReason::Implausible { .. } => "implausible-sigma",
            SkipReason::SmallerThanBead { .. } => "smaller-than-bead",
        }
    }
}

/// Skips that need no fit: edge, crowding, saturation, focus outside the stack.
pub(super) fn pre_fit_skip(
    grid: PlaneView,
    c: &Candidate,
    all: &[Candidate],
    half: usize,
    planes: usize,
    opts: &PsfOptions,
) -> Option<SkipReason> {
    if c.x < half || c.y < half || c.x + half >= grid.width || c.y + half >= grid.height {
        return Some(SkipReason::AtEdge);
    }
    let nearest = all
        .iter()
        .filter(|o| {
            (o.x, o.y) != (c.x, c.y) && o.x.abs_diff(c.x) <= half && o.y.abs_diff(c.y) <= half
        })
        .map(|o| (o.x as f64 - c.x as f64).hypot(o.y as f64 - c.y as f64))
        .min_by(f64::total_cmp);
    if let Some(distance_px) = nearest {
        return Some(SkipReason::Crowded { distance_px });
    }
    if let Some(level) = opts.saturation_level {
        let pixels = window_pixels(grid, c, half).filter(|&v| v >= level).count();
        // One pixel at full scale can be a bright bead's true peak; a plateau cannot.
        if pixels >= 2 {
            return Some(SkipReason::Saturated { pixels, level });
        }
    }
    if planes >= 3 && (c.plane == 0 || c.plane == planes - 1) {
        return Some(SkipReason::FocusAtStackEnd { plane: c.plane });
    }
    None
}

fn window_pixels<'a>(
    grid: PlaneView<'a>,
    c: &Candidate,
    half: usize,
) -> impl Iterator<Item = f64> + 'a {
    let (x0, y0, side) = (c.x - half, c.y - half, 2 * half + 1);
    (y0..y0 + side).flat_map(move |y| {
        grid.values[y * grid.width + x0..y * grid.width + x0 + side]
            .iter()
            .copied()
    })
}

/// σ must be resolvable (≥ 0.3 px) and small enough that the window holds ±2.5 σ.
pub(super) fn implausible(fit: &SpotFit, half: usize) -> Option<SkipReason> {
    let upper = half as f64 / 2.5;
    let g = &fit.gauss2d;
    [fit.radial.sigma_px, g.sigma_x_px, g.sigma_y_px]
        .into_iter()
        .find(|s| !(0.3..=upper).contains(s))
        .map(|sigma_px| SkipReason::Implausible { sigma_px })
        .or_else(|| {
            let amplitudes_positive = fit.radial.amplitude > 0.0 && g.amplitude > 0.0;
            let centred =
                (g.x_px - fit.centroid_px.0).hypot(g.y_px - fit.centroid_px.1) < half as f64 / 2.0;
            (!(amplitudes_positive && centred))
                .then(|| SkipReason::FitFailed("negative amplitude or centre off the spot".into()))
        })
}
