//! Newton rings and the detection gap (Weber et al. 2018, Methods, "Newton rings", Eq. 1;
//! `docs/methods.md` §7.5; `docs/optics.md`).
//!
//! A reflection image shows Newton rings around the contact: intensity maxima where the gap is
//! d_m = (m + ½)·λ/(2n). A fluorescence image of the same field shows the contact where the
//! rigidochromic molecules light up. Along line profiles through the contact centre, the ring
//! radii r_m give gap points (r_m, d_m); a Hertz exterior gap fitted to them and evaluated at the
//! fluorescent edge r_f gives the gap at which the molecules light up: the detection gap (the
//! paper: 9 nm, averaged over 20 profiles). The edge is where the fluorescence profile crosses
//! half-way between its plateaus ([`profile::half_level_edge`]); ring orders come from where the
//! maxima lie, not from counting them ([`rings::assign_orders`]).
//!
//! [`analyse`] does the measurement on two images in memory; `contactscope_jobs::newton` reads the files and
//! writes `newton.json`, `newton_rings.csv`, `newton_profiles.csv` and `newton_gap.png`.

pub mod gap;
pub mod profile;
pub mod rings;

pub use crate::numerics::stats::MeanSd;
pub use gap::{fit_hertz_gap, hertz_gap, ring_gap, GapFit, Phase};

use crate::error::{Error, Location, Result};
use crate::image::Image;
use crate::limits::Limits;
use profile::{
    edge_crossing, find_contact, half_level_edge, noise_sd, peaks, smooth, Contact, HalfLine,
};
use rings::assign_orders;

/// Choices of the analysis. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonOptions {
    /// Illumination wavelength λ, m (the paper: 488 nm).
    pub wavelength_m: f64,
    /// Refractive index n of the medium in the gap (formamide: 1.447).
    pub medium_index: f64,
    /// Number of lines through the centre, at angles k·180°/N (the paper: 20).
    pub profiles: usize,
    /// Where the maxima lie (Eq. 1's +½, or none for n_sphere < n_medium).
    pub phase: Phase,
    /// Width of each line, pixels, averaged across (bilinear samples one pixel apart).
    pub line_width_px: usize,
    /// σ of the Gaussian smoothing along a profile, pixels.
    pub smoothing_px: f64,
    /// A ring must stand out of its surroundings by this many noise deviations of its profile
    /// (robust deviation of the raw profile about the smoothed one)…
    pub min_prominence_noise: f64,
    /// …and by this fraction of the most prominent ring on the same half-line.
    pub min_prominence_fraction: f64,
    /// Profiles whose rms gap residual exceeds this are skipped, m.
    pub max_rms_residual_m: f64,
    /// Distance from the fluorescent edge at which its inside and outside plateaus begin, m
    /// (each plateau is twice as long). It must exceed the edge's blurred half-width: 3σ of the
    /// PSF and the smoothing together.
    pub edge_margin_m: f64,
    /// Fewest usable profiles for a result (or all of them when fewer are asked for); with
    /// fewer, [`analyse`] fails with [`Error::TooFewProfiles`].
    pub min_profiles: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            wavelength_m: 488e-9,
            medium_index: 1.447,
            profiles: 20,
            phase: Phase::Half,
            line_width_px: 5,
            smoothing_px: 1.0,
            min_prominence_noise: 5.0,
            min_prominence_fraction: 0.2,
            // A tenth of the fringe spacing λ/(2n) = 168.6 nm: a correct order assignment on
            // clean rings fits to a few nm, a shifted one by tens of nm.
            max_rms_residual_m: 17e-9,
            // 3.2σ of a 450 nm PSF with σ = 1 px smoothing at 250 nm pixels, 4.7σ at 100 nm.
            edge_margin_m: 1e-6,
            // A mean and a spread with two degrees of freedom.
            min_profiles: 3,
        }
    }
}

/// Points needed for a fit of a and R that leaves a residual.
pub const MIN_RINGS: usize = 3;

/// Sampling step along a profile, in (smaller) pixels.
const STEP_PX: f64 = 0.25;

/// Ring tracking ends where the fringes come closer than this, pixels: below it the pixels
/// alias them and the PSF washes them out (see [`rings`]).
const MIN_FRINGE_SPACING_PX: f64 = 3.0;

/// One ring maximum on one half-line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ring {
    /// +1 for the half-line at the profile's angle, −1 for the opposite one.
    pub side: i8,
    /// Interference order m.
    pub order: u32,
    /// Distance from the centre, m.
    pub radius_m: f64,
    /// Gap d_m of its order, m.
    pub gap_m: f64,
}

/// Result of one line profile.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileResult {
    /// Profile index, 0-based.
    pub index: usize,
    /// Angle of the line, degrees from +x towards +y (rows grow downward).
    pub angle_deg: f64,
    /// Fluorescent edge radius on each side, m (`None` where no edge was found).
    pub edge_radius_sides_m: [Option<f64>; 2],
    /// Rings on both sides, ordered outward per side.
    pub rings: Vec<Ring>,
    /// The fit with the paper's order rule, if there were enough rings.
    pub fit: Option<GapFit>,
    /// The fit with every order one higher (the innermost ring assumed missed), for comparison.
    pub shifted_fit: Option<GapFit>,
    /// Fitted gap at the mean edge radius, m.
    pub detection_gap_m: Option<f64>,
    /// Why the profile is not used; `None` when it is.
    pub skipped: Option<String>,
}

impl ProfileResult {
    /// Which half-lines (+, −) the profile uses: those with a fluorescent edge and at least one
    /// ring. A half-line cut short by the image border is left out, the other one still counts.
    pub fn sides_used(&self) -> [bool; 2] {
        [1i8, -1].map(|side| {
            let slot = usize::from(side < 0);
            self.edge_radius_sides_m[slot].is_some() && self.rings.iter().any(|r| r.side == side)
        })
    }

    /// Mean edge radius of the half-lines used, m; with both, a centre error along the line
    /// cancels to first order.
    pub fn edge_radius_m(&self) -> Option<f64> {
        let used: Vec<f64> = self
            .sides_used()
            .iter()
            .zip(self.edge_radius_sides_m)
            .filter_map(|(&used, edge)| edge.filter(|_| used))
            .collect();
        (!used.is_empty()).then(|| used.iter().sum::<f64>() / used.len() as f64)
    }

    /// rms residual with orders shifted by +1 over that with the paper's orders: well above 1
    /// when the paper's assignment is right.
    pub fn shifted_residual_ratio(&self) -> Option<f64> {
        Some(self.shifted_fit?.rms_residual_m / self.fit?.rms_residual_m)
    }
}

/// Everything measured by [`analyse`].
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonAnalysis {
    /// The fluorescent contact (threshold, centre).
    pub contact: Contact,
    /// Pixel size (x, y) used, m.
    pub pixel_m: (f64, f64),
    /// All profiles, used and skipped.
    pub profiles: Vec<ProfileResult>,
    /// Detection gap over the profiles used, m.
    pub detection_gap_m: MeanSd,
    /// Edge radius over the profiles used, m.
    pub edge_radius_m: MeanSd,
    /// Fitted contact radius a over the profiles used, m.
    pub contact_radius_m: MeanSd,
    /// Fitted sphere radius R over the profiles used, m.
    pub sphere_radius_m: MeanSd,
}

impl NewtonAnalysis {
    /// Profiles used for the averages.
    pub fn used(&self) -> impl Iterator<Item = &ProfileResult> {
        self.profiles.iter().filter(|p| p.skipped.is_none())
    }
}

/// Measure the detection gap from a reflection image with Newton rings and a fluorescence image
/// of the same field (same size; the pixel size comes from the reflection image, else from the
/// fluorescence image).
pub fn analyse(
    reflection: &Image,
    fluorescence: &Image,
    options: &NewtonOptions,
) -> Result<NewtonAnalysis> {
    check_options(options)?;
    let pixel_m = pixel_size(reflection, fluorescence)?;
    if (reflection.width, reflection.height) != (fluorescence.width, fluorescence.height) {
        return Err(Error::bad_input(
            Location::file(&fluorescence.path),
            format!(
                "fluorescence image is {}×{} px but the reflection image {} is {}×{} px; both must show the same field",
                fluorescence.width,
                fluorescence.height,
                reflection.path.display(),
                reflection.width,
                reflection.height
            ),
        ));
    }
    // Every profile samples at most the image diagonal in steps of the smaller pixel: bound the
    // whole measurement before starting (a pixel of 200 nm × 1e-6 nm once sampled for ever).
    let diagonal_m =
        (reflection.width as f64 * pixel_m.0).hypot(reflection.height as f64 * pixel_m.1);
    let per_line = diagonal_m / (STEP_PX * pixel_m.0.min(pixel_m.1)) + 2.0;
    let total = per_line * 2.0 * (options.profiles * options.line_width_px.max(1)) as f64;
    if total > Limits::DEFAULT.max_profile_samples as f64 {
        return Err(Error::bad_input(
            Location::file(&reflection.path),
            format!(
                "pixel size {:.4e} × {:.4e} m: {} profiles of {:.3e} samples each exceed the limit \
                 of {} samples (pixels far from square?)",
                pixel_m.0,
                pixel_m.1,
                2 * options.profiles,
                per_line,
                Limits::DEFAULT.max_profile_samples
            ),
        ));
    }
    let contact = find_contact(fluorescence)?;
    let profiles: Vec<ProfileResult> = (0..options.profiles)
        .map(|k| measure_profile(k, reflection, fluorescence, &contact, pixel_m, options))
        .collect();
    let needed = options.min_profiles.min(options.profiles);
    summarise(reflection, contact, pixel_m, profiles, needed)
}

fn check_options(o: &NewtonOptions) -> Result<()> {
    let finite_positive = [o.wavelength_m, o.medium_index, o.max_rms_residual_m];
    if finite_positive.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return Err(Error::InvalidArgument(
            "wavelength, medium index and residual limit must be positive".into(),
        ));
    }
    if !(1..=3600).contains(&o.profiles) {
        return Err(Error::InvalidArgument(format!(
            "{} is out of range 1..=3600",
            contactscope_formats::param::Param::Profiles.with_value(o.profiles)
        )));
    }
    if o.line_width_px == 0 || o.smoothing_px.is_nan() || o.smoothing_px < 0.0 {
        return Err(Error::InvalidArgument(
            "line width must be at least 1 px and smoothing not negative".into(),
        ));
    }
    if !(o.edge_margin_m.is_finite() && o.edge_margin_m > 0.0) || o.min_profiles == 0 {
        return Err(Error::InvalidArgument(
            "the edge margin must be positive and at least one profile must be required".into(),
        ));
    }
    Ok(())
}

/// Pixel size of the pair: the reflection image's, else the fluorescence image's.
fn pixel_size(reflection: &Image, fluorescence: &Image) -> Result<(f64, f64)> {
    let px = match (reflection.pixel_size, fluorescence.pixel_size) {
        (Some(px), _) | (None, Some(px)) => px,
        (None, None) => reflection.require_pixel_size()?,
    };
    Ok((px.x_m, px.y_m))
}

/// Rings, edge and fit of the line at angle k·180°/N.
fn measure_profile(
    index: usize,
    reflection: &Image,
    fluorescence: &Image,
    contact: &Contact,
    pixel_m: (f64, f64),
    o: &NewtonOptions,
) -> ProfileResult {
    let angle = std::f64::consts::PI * index as f64 / o.profiles as f64;
    let step_m = STEP_PX * pixel_m.0.min(pixel_m.1);
    let mut edges = [None, None];
    let mut rings = Vec::new();
    for (slot, side) in [1i8, -1].into_iter().enumerate() {
        let line = HalfLine {
            centre_px: contact.centre_px,
            angle_rad: if side > 0 {
                angle
            } else {
                angle + std::f64::consts::PI
            },
            pixel_m,
            width_samples: o.line_width_px,
            step_m,
        };
        let sigma = o.smoothing_px / STEP_PX;
        let fluo = smooth(&line.sample(fluorescence), sigma);
        // The Otsu crossing only seeds the search: its level sits anywhere between the
        // plateaus, which moves the crossing by up to the blur width.
        let margin = (o.edge_margin_m / step_m).ceil() as usize;
        let Some(edge) = edge_crossing(&fluo, contact.threshold)
            .and_then(|guess| half_level_edge(&fluo, guess, margin, 2 * margin))
        else {
            continue;
        };
        edges[slot] = Some(edge.position * step_m);
        let raw = line.sample(reflection);
        let min_spacing = MIN_FRINGE_SPACING_PX / STEP_PX;
        let tracked = assign_orders(
            &ring_candidates(&raw, sigma, edge.position, o),
            min_spacing,
            raw.len().saturating_sub(1) as f64,
        );
        rings.extend(tracked.iter().map(|&(k, s)| {
            let order = o.phase.first_order() + k;
            Ring {
                side,
                order,
                radius_m: s * step_m,
                gap_m: ring_gap(order, o.wavelength_m, o.medium_index, o.phase),
            }
        }));
    }
    let mut result = ProfileResult {
        index,
        angle_deg: angle.to_degrees(),
        edge_radius_sides_m: edges,
        rings,
        fit: None,
        shifted_fit: None,
        detection_gap_m: None,
        skipped: None,
    };
    fit_profile(&mut result, o);
    result
}

/// Positions (samples) of the maxima on one half-line that stand out enough to be rings,
/// outward, outside the fluorescent edge; [`assign_orders`] numbers them.
fn ring_candidates(raw: &[f64], sigma: f64, edge: f64, o: &NewtonOptions) -> Vec<f64> {
    let smoothed = smooth(raw, sigma);
    // The residual raw − smoothed carries most of the profile's noise; peaks of smoothed noise
    // reach about twice its deviation, real rings stand far above that.
    let noise = noise_sd(raw, &smoothed);
    let found = peaks(&smoothed, edge.ceil() as usize);
    let strongest = found.iter().map(|p| p.prominence).fold(0.0, f64::max);
    let floor = (o.min_prominence_noise * noise).max(o.min_prominence_fraction * strongest);
    found
        .iter()
        .filter(|p| p.prominence > floor && p.prominence > 0.0)
        .map(|p| p.position)
        .collect()
}

/// Fit the profile's rings (paper orders and orders + 1) and decide whether it is used.
fn fit_profile(result: &mut ProfileResult, o: &NewtonOptions) {
    let Some(edge) = result.edge_radius_m() else {
        result.skipped = Some(if result.edge_radius_sides_m.iter().all(Option::is_none) {
            "no fluorescent edge on either half-line".into()
        } else {
            "0 ring(s) outside the contact edge on the half-lines with an edge".into()
        });
        return;
    };
    // Rings are only looked for beyond an edge, so every ring lies on a half-line used.
    if result.rings.len() < MIN_RINGS {
        result.skipped = Some(format!(
            "{} ring(s) outside the contact edge; {MIN_RINGS} needed to fit a and R",
            result.rings.len()
        ));
        return;
    }
    let points = |shift: u32| -> Vec<(f64, f64)> {
        result
            .rings
            .iter()
            .map(|r| {
                (
                    r.radius_m,
                    ring_gap(r.order + shift, o.wavelength_m, o.medium_index, o.phase),
                )
            })
            .collect()
    };
    result.fit = fit_hertz_gap(&points(0), edge);
    result.shifted_fit = fit_hertz_gap(&points(1), edge);
    let Some(fit) = result.fit else {
        result.skipped = Some("the Hertz gap fit found no positive sphere radius".into());
        return;
    };
    result.detection_gap_m = Some(fit.gap_at(edge));
    // a may not exceed the fluorescent edge; a fit that ends on that bound says nothing about
    // the gap there (it would read 0 nm by construction).
    if fit.contact_radius_m >= edge * (1.0 - 1e-3) {
        result.skipped = Some(format!(
            "the fitted contact radius {:.3} µm runs into the fluorescent edge {:.3} µm: the rings do not fix the gap at the edge",
            fit.contact_radius_m * 1e6,
            edge * 1e6
        ));
    } else if fit.rms_residual_m > o.max_rms_residual_m {
        result.skipped = Some(format!(
            "rms gap residual {:.1} nm exceeds {:.1} nm",
            fit.rms_residual_m * 1e9,
            o.max_rms_residual_m * 1e9
        ));
    }
}

/// Averages over the profiles used, or [`Error::TooFewProfiles`] when fewer than `needed` are.
fn summarise(
    reflection: &Image,
    contact: Contact,
    pixel_m: (f64, f64),
    profiles: Vec<ProfileResult>,
    needed: usize,
) -> Result<NewtonAnalysis> {
    let used: Vec<&ProfileResult> = profiles.iter().filter(|p| p.skipped.is_none()).collect();
    if used.len() < needed {
        return Err(too_few_profiles(reflection, &profiles, needed));
    }
    let spread = |f: &dyn Fn(&ProfileResult) -> Option<f64>| {
        MeanSd::of(&used.iter().filter_map(|p| f(p)).collect::<Vec<_>>())
    };
    let (Some(gap), Some(edge), Some(a), Some(r)) = (
        spread(&|p| p.detection_gap_m),
        spread(&|p| p.edge_radius_m()),
        spread(&|p| p.fit.map(|f| f.contact_radius_m)),
        spread(&|p| p.fit.map(|f| f.sphere_radius_m)),
    ) else {
        return Err(too_few_profiles(reflection, &profiles, needed));
    };
    Ok(NewtonAnalysis {
        contact,
        pixel_m,
        profiles,
        detection_gap_m: gap,
        edge_radius_m: edge,
        contact_radius_m: a,
        sphere_radius_m: r,
    })
}

fn too_few_profiles(reflection: &Image, profiles: &[ProfileResult], needed: usize) -> Error {
    let usable = profiles.iter().filter(|p| p.skipped.is_none()).count();
    let most = profiles.iter().map(|p| p.rings.len()).max().unwrap_or(0);
    let reason = if most == 0 {
        "no Newton rings found outside the fluorescent contact on any line profile".to_string()
    } else if most < MIN_RINGS {
        format!("at most {most} Newton ring(s) on any line profile; {MIN_RINGS} are needed to fit the gap profile")
    } else {
        let first = profiles
            .iter()
            .find_map(|p| {
                p.skipped
                    .as_ref()
                    .map(|why| format!("profile {} ({:.1}°): {why}", p.index, p.angle_deg))
            })
            .unwrap_or_default();
        format!("the first skipped is {first}")
    };
    Error::TooFewProfiles {
        at: Location::file(&reflection.path),
        usable,
        total: profiles.len(),
        needed,
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rings where the Hertz gap of a = 12 µm, R = 290 µm reaches the Eq. 1 gaps, both sides.
    fn profile(edge_m: f64) -> ProfileResult {
        let o = NewtonOptions::default();
        let (a, big_r) = (12e-6, 290e-6);
        let rings = (0..4u32)
            .flat_map(|m| {
                let d = ring_gap(m, o.wavelength_m, o.medium_index, o.phase);
                let (mut lo, mut hi) = (a, 5.0 * a);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if hertz_gap(mid, a, big_r) < d {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                [1i8, -1].map(|side| Ring {
                    side,
                    order: m,
                    radius_m: lo,
                    gap_m: d,
                })
            })
            .collect();
        ProfileResult {
            index: 0,
            angle_deg: 0.0,
            edge_radius_sides_m: [Some(edge_m); 2],
            rings,
            fit: None,
            shifted_fit: None,
            detection_gap_m: None,
            skipped: None,
        }
    }

    #[test]
    fn fit_recovers_the_gap_and_refuses_a_contact_radius_at_the_edge() {
        let o = NewtonOptions::default();
        let mut good = profile(12.7e-6);
        fit_profile(&mut good, &o);
        assert_eq!(good.skipped, None);
        let expected = hertz_gap(12.7e-6, 12e-6, 290e-6);
        let got = good.detection_gap_m.unwrap();
        assert!((got - expected).abs() < 0.05e-9, "{got} vs {expected}");
        assert!(good.shifted_residual_ratio().unwrap() > 5.0);

        // An edge inside the true contact: a is bounded by the edge and the gap there is 0 by
        // construction, so the profile must not be used.
        let mut bounded = profile(10e-6);
        fit_profile(&mut bounded, &o);
        let reason = bounded.skipped.expect("skipped");
        assert!(
            reason.contains("runs into the fluorescent edge"),
            "{reason}"
        );
    }
}
