//! The microscope's point-spread function measured on sub-resolution fluorescent beads.
//!
//! Weber et al. 2018, Methods (Microscopy): 100 nm beads imaged under the contact experiments'
//! conditions, "radially averaged around the center of intensity to obtain a Gaussian profile"
//! of FWHM 450 nm. The procedure is `docs/methods.md` §7.3; the choices made here are
//! written down in `docs/optics.md` ("PSF from beads"):
//!
//! 1. Candidates ([`detect()`]): local maxima of the image (or of the maximum projection of a
//!    stack's planes), smoothed with σ = 1 px, above median + max(10·noise, 2 % of the brightest
//!    spot), noise = 1.4826·MAD. A stack bead's best-focus plane is the plane whose smoothed
//!    value at the bead is highest. The median half-maximum area of the candidates gives a first
//!    σ, which sets the window: 9 σ wide (at least 9 px).
//! 2. Skips, in this order: window off the image, another candidate inside the window
//!    (crowded), ≥ 2 window pixels at the saturation level, focus on the first or last plane of
//!    a stack (the true focus may lie outside it), failed or implausible fits.
//! 3. Per bead ([`fit_spot`]): border-median background, centre of intensity over pixels above
//!    0.2 of the peak with three re-centring passes, radial profile in 0.5 px bins fitted with
//!    I0·exp(−r²/2σ²) + c (the paper's method; it feeds the summary), and a 2-D axis-aligned
//!    Gaussian with a free centre (the reported bead position, σx, σy).
//! 4. Optional finite-bead correction σ² − a²/5 (a = bead radius; a uniform sphere seen in
//!    projection has a per-axis variance a²/5). FWHM = 2√(2 ln 2)·σ.

mod detect;
mod fit;
mod lm;
mod skip;

pub use detect::{detect, Candidate, DetectOptions, Detection};
pub use fit::{fit_spot, Gauss2dFit, PlaneView, RadialFit, SpotFailure, SpotFit, SpotOptions};
pub use skip::SkipReason;

pub use crate::numerics::stats::MeanSd;
use skip::{implausible, pre_fit_skip};

use crate::error::{Error, Location, Result};
use crate::image::Image;
use crate::image::PixelSize;

/// FWHM / σ of a Gaussian, 2√(2 ln 2).
pub const FWHM_PER_SIGMA: f64 = 2.354_820_045_030_949;

/// Choices of the PSF measurement (defaults as in the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct PsfOptions {
    /// Candidate detection.
    pub detect: DetectOptions,
    /// Window width in units of the detected σ.
    pub window_sigmas: f64,
    /// Smallest window half-width, pixels.
    pub min_half_window_px: usize,
    /// Centre of intensity over pixels above this fraction of the peak.
    pub centroid_fraction: f64,
    /// Re-centring passes.
    pub centroid_iterations: usize,
    /// Radial bin width, pixels.
    pub bin_px: f64,
    /// Bead diameter for the finite-size correction; `None`: no correction.
    pub bead_diameter_m: Option<f64>,
    /// Value at which the detector saturates; `None`: no saturation check.
    pub saturation_level: Option<f64>,
}

impl Default for PsfOptions {
    fn default() -> Self {
        PsfOptions {
            detect: DetectOptions::default(),
            window_sigmas: 9.0,
            min_half_window_px: 4,
            centroid_fraction: 0.2,
            centroid_iterations: 3,
            bin_px: 0.5,
            bead_diameter_m: None,
            saturation_level: None,
        }
    }
}

/// One candidate and what became of it.
#[derive(Debug, Clone, PartialEq)]
pub struct BeadMeasurement {
    /// Where it was detected.
    pub candidate: Candidate,
    /// TIFF page of its best-focus plane.
    pub page: usize,
    /// Highest raw value in the 3 × 3 pixels around the candidate on its plane.
    pub raw_peak: f64,
    /// The fits, if they ran and succeeded.
    pub fit: Option<SpotFit>,
    /// Radial σ of the image spot, metres.
    pub sigma_raw_m: Option<f64>,
    /// Reported σ (bead-corrected when a diameter was given), metres.
    pub sigma_m: Option<f64>,
    /// Why it is not used; `None` for used beads.
    pub skip: Option<SkipReason>,
}

/// Over the used beads, metres.
#[derive(Debug, Clone, PartialEq)]
pub struct PsfSummary {
    /// Beads used.
    pub beads_used: usize,
    /// Reported σ (bead-corrected when asked).
    pub sigma_m: MeanSd,
    /// σ of the image spots (no correction).
    pub sigma_raw_m: MeanSd,
    /// 2-D fit σ along x.
    pub sigma_x_m: MeanSd,
    /// 2-D fit σ along y.
    pub sigma_y_m: MeanSd,
}

/// The whole measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct PsfReport {
    /// Every candidate, brightest first.
    pub beads: Vec<BeadMeasurement>,
    /// Detection statistics.
    pub detection: Detection,
    /// Window half-width used, pixels.
    pub half_window_px: usize,
    /// Pixel size (square).
    pub pixel_size: PixelSize,
    /// Planes analysed.
    pub planes: usize,
    /// Bead diameter given for the correction.
    pub bead_diameter_m: Option<f64>,
    /// Saturation level checked against.
    pub saturation_level: Option<f64>,
    /// Summary over used beads.
    pub summary: PsfSummary,
}

/// Measure the PSF on one image or on the planes of one stack (all of one file and channel).
pub fn measure_psf(images: &[Image], opts: &PsfOptions) -> Result<PsfReport> {
    let first = images
        .first()
        .ok_or_else(|| Error::InvalidArgument("no image to measure a PSF on".into()))?;
    let at = || Location::file(&first.path);
    let pixel_size = square_pixel_size(first)?;
    check_planes(images)?;
    let planes: Vec<&[f64]> = images.iter().map(|im| im.values.as_slice()).collect();
    let (width, height) = (first.width, first.height);
    let detection = detect(&planes, width, height, &opts.detect);
    if detection.candidates.is_empty() {
        return Err(Error::bad_input(
            at(),
            format!(
                "no beads found (background {:.1}, noise {:.2}, detection level {:.1})",
                detection.background, detection.noise, detection.threshold
            ),
        ));
    }
    let half = half_window(&detection, opts);
    if 2 * half + 1 > width.min(height) {
        return Err(Error::bad_input(
            at(),
            format!(
                "the bead window ({} px = {} σ, σ ≈ {:.2} px) is wider than the image ({width}×{height} px)",
                2 * half + 1,
                opts.window_sigmas,
                detection.sigma_guess_px
            ),
        ));
    }
    let beads: Vec<BeadMeasurement> = detection
        .candidates
        .iter()
        .map(|c| measure_bead(images, c, &detection.candidates, half, pixel_size.x_m, opts))
        .collect();
    let summary = summarise(&beads, pixel_size.x_m).ok_or_else(|| all_skipped(at(), &beads))?;
    Ok(PsfReport {
        beads,
        detection,
        half_window_px: half,
        pixel_size,
        planes: images.len(),
        bead_diameter_m: opts.bead_diameter_m,
        saturation_level: opts.saturation_level,
        summary,
    })
}

fn square_pixel_size(image: &Image) -> Result<PixelSize> {
    let px = image.require_pixel_size()?;
    if (px.x_m - px.y_m).abs() > 1e-3 * px.x_m {
        return Err(Error::bad_input(
            Location::file(&image.path),
            format!(
                "psf needs square pixels; this file has {} × {} nm (give {} to override)",
                px.x_m * 1e9,
                px.y_m * 1e9,
                contactscope_formats::param::Param::PixelSize
            ),
        ));
    }
    Ok(px)
}

/// Planes must share one shape and hold finite values (the smoothing and the fits need both).
fn check_planes(images: &[Image]) -> Result<()> {
    let first = &images[0];
    for im in images {
        let at = || Location::page(&im.path, im.page);
        if (im.width, im.height) != (first.width, first.height)
            || im.values.len() != im.width * im.height
        {
            return Err(Error::bad_input(
                at(),
                format!(
                    "plane is {}×{} px but the first is {}×{}; psf needs one shape per stack",
                    im.width, im.height, first.width, first.height
                ),
            ));
        }
        if im.values.iter().any(|v| !v.is_finite()) {
            return Err(Error::bad_input(
                at(),
                "NaN or infinite values; psf needs finite data",
            ));
        }
    }
    Ok(())
}

fn half_window(detection: &Detection, opts: &PsfOptions) -> usize {
    let half = (0.5 * opts.window_sigmas * detection.sigma_guess_px).ceil();
    (half as usize).max(opts.min_half_window_px)
}

fn all_skipped(at: Location, beads: &[BeadMeasurement]) -> Error {
    let reasons: Vec<String> = beads
        .iter()
        .take(10)
        .map(|b| {
            let why = b.skip.as_ref().map_or(String::new(), |s| s.to_string());
            format!("({}, {}): {why}", b.candidate.x, b.candidate.y)
        })
        .collect();
    let more = if beads.len() > 10 {
        format!("; and {} more", beads.len() - 10)
    } else {
        String::new()
    };
    Error::bad_input(
        at,
        format!(
            "all {} bead candidates were skipped: {}{more}",
            beads.len(),
            reasons.join("; ")
        ),
    )
}

fn measure_bead(
    images: &[Image],
    c: &Candidate,
    all: &[Candidate],
    half: usize,
    pixel_m: f64,
    opts: &PsfOptions,
) -> BeadMeasurement {
    let image = &images[c.plane];
    let grid = PlaneView {
        values: &image.values,
        width: image.width,
        height: image.height,
    };
    let mut bead = BeadMeasurement {
        candidate: *c,
        page: image.page,
        raw_peak: raw_peak(grid, c.x, c.y),
        fit: None,
        sigma_raw_m: None,
        sigma_m: None,
        skip: None,
    };
    if let Some(skip) = pre_fit_skip(grid, c, all, half, images.len(), opts) {
        bead.skip = Some(skip);
        return bead;
    }
    let spot_opts = SpotOptions {
        half_window_px: half,
        centroid_fraction: opts.centroid_fraction,
        centroid_iterations: opts.centroid_iterations,
        bin_px: opts.bin_px,
    };
    match fit_spot(grid, c.x, c.y, &spot_opts) {
        Err(SpotFailure::AtEdge) => bead.skip = Some(SkipReason::AtEdge),
        Err(SpotFailure::NoSignal) => {
            bead.skip = Some(SkipReason::FitFailed(
                "no signal above the window border".into(),
            ))
        }
        Err(SpotFailure::NotConverged(which)) => {
            bead.skip = Some(SkipReason::FitFailed(format!("{which} did not converge")))
        }
        Ok(fit) => {
            bead.skip = implausible(&fit, half);
            let sigma_px = fit.radial.sigma_px;
            bead.sigma_raw_m = Some(sigma_px * pixel_m);
            bead.sigma_m = corrected_sigma(sigma_px * pixel_m, opts.bead_diameter_m);
            if bead.skip.is_none() && bead.sigma_m.is_none() {
                bead.skip = Some(SkipReason::SmallerThanBead { sigma_px });
            }
            bead.fit = Some(fit);
        }
    }
    bead
}

fn raw_peak(grid: PlaneView, x: usize, y: usize) -> f64 {
    let mut best = f64::NEG_INFINITY;
    for yy in y.saturating_sub(1)..=(y + 1).min(grid.height - 1) {
        for xx in x.saturating_sub(1)..=(x + 1).min(grid.width - 1) {
            best = best.max(grid.values[yy * grid.width + xx]);
        }
    }
    best
}

/// σ_psf = √(σ_img² − a²/5), a = D/2; `None` if the spot is narrower than the bead.
pub fn corrected_sigma(sigma_img_m: f64, bead_diameter_m: Option<f64>) -> Option<f64> {
    match bead_diameter_m {
        None => Some(sigma_img_m),
        Some(d) => {
            let v = sigma_img_m * sigma_img_m - (0.5 * d).powi(2) / 5.0;
            (v > 0.0).then(|| v.sqrt())
        }
    }
}

fn summarise(beads: &[BeadMeasurement], pixel_m: f64) -> Option<PsfSummary> {
    let used: Vec<&BeadMeasurement> = beads.iter().filter(|b| b.skip.is_none()).collect();
    if used.is_empty() {
        return None;
    }
    let stats = |f: &dyn Fn(&BeadMeasurement) -> Option<f64>| {
        MeanSd::of(&used.iter().filter_map(|b| f(b)).collect::<Vec<_>>())
            .unwrap_or(MeanSd::UNDEFINED)
    };
    Some(PsfSummary {
        beads_used: used.len(),
        sigma_m: stats(&|b| b.sigma_m),
        sigma_raw_m: stats(&|b| b.sigma_raw_m),
        sigma_x_m: stats(&|b| Some(b.fit.as_ref()?.gauss2d.sigma_x_px * pixel_m)),
        sigma_y_m: stats(&|b| Some(b.fit.as_ref()?.gauss2d.sigma_y_px * pixel_m)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::PixelSizeSource;

    fn image(width: usize, height: usize, value: f64, page: usize) -> Image {
        Image {
            values: vec![value; width * height],
            width,
            height,
            pixel_size: Some(PixelSize {
                x_m: 1e-7,
                y_m: 1e-7,
                source: PixelSizeSource::CommandLine,
            }),
            path: "s.tif".into(),
            page,
        }
    }

    #[test]
    fn mixed_shapes_and_nan_are_refused() {
        let opts = PsfOptions::default();
        let err = measure_psf(&[image(8, 8, 1.0, 0), image(9, 8, 1.0, 1)], &opts).unwrap_err();
        assert!(
            err.to_string().contains("page 1") && err.to_string().contains("9×8"),
            "{err}"
        );
        let err = measure_psf(&[image(8, 8, f64::NAN, 0)], &opts).unwrap_err();
        assert!(err.to_string().contains("NaN"), "{err}");
        let mut wide = image(8, 8, 1.0, 0);
        wide.pixel_size.as_mut().unwrap().y_m = 2e-7;
        assert!(measure_psf(&[wide], &opts)
            .unwrap_err()
            .to_string()
            .contains("square"));
    }

    #[test]
    fn correction_and_mean_sd() {
        let s = corrected_sigma(191e-9, Some(100e-9)).unwrap();
        assert!((s * s - (191e-9f64.powi(2) - 500e-18)).abs() < 1e-24);
        assert_eq!(corrected_sigma(10e-9, Some(100e-9)), None);
        assert_eq!(corrected_sigma(5.0, None), Some(5.0));
    }
}
