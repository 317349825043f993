//! The `newton` job: the detection gap from Newton rings around the fluorescent contact (Weber
//! et al. 2018, Methods, "Newton rings", Eq. 1; docs/methods.md §7.5; the measurement is
//! [`contactscope::optics::newton`]). Every front-end builds a [`NewtonRequest`] (the command
//! line from two files and the selection flags, Python from files or arrays),
//! [`NewtonRequest::check`] applies the same range checks, and [`run`] returns a
//! [`NewtonOutcome`]: its serialisation is `newton.json` with the ring points of
//! `newton_rings.csv` (`rings`), in lab units, and the Python result in SI units. [`files`]
//! writes the folder.

pub mod files;

use serde::Serialize;

use contactscope::optics::newton::{analyse, ring_gap, NewtonAnalysis, NewtonOptions};
use contactscope_formats::microscopy::select::{ChannelChoice, Selection};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::{Error, Result};
use crate::images::ImageInput;
use crate::lab;

/// Everything `newton` needs. SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct NewtonRequest {
    /// Reflection image with Newton rings (a single-page TIFF, one plane of a CZI, ND2 or LIF
    /// file, or one image in memory).
    pub reflection: ImageInput,
    /// Fluorescence image of the contact: same field and size.
    pub fluorescence: ImageInput,
    /// The plane of each file (the same selection for both, except the channel below).
    pub selection: Selection,
    /// Channel of the fluorescence image when it differs from the reflection's (both images
    /// as two channels of one file).
    pub contact_channel: Option<usize>,
    /// Pixel size (x, y), m, overriding the files' metadata (needed for images in memory).
    pub pixel_size_m: Option<(f64, f64)>,
    /// Wavelength, medium index, profiles, phase and the analysis' other choices.
    pub options: NewtonOptions,
}

impl NewtonRequest {
    /// Most line profiles.
    pub const MAX_PROFILES: usize = 3600;

    /// A request with the defaults: the files' pixel size, λ = 488 nm, n = 1.447 (formamide),
    /// 20 profiles, maxima at (m + ½)λ/(2n) ([`NewtonOptions::default`]).
    pub fn new(reflection: ImageInput, fluorescence: ImageInput) -> Self {
        NewtonRequest {
            reflection,
            fluorescence,
            selection: Selection::default(),
            contact_channel: None,
            pixel_size_m: None,
            options: NewtonOptions::default(),
        }
    }

    /// Every range check, the same for every front-end.
    pub fn check(&self) -> Result<()> {
        self.reflection.check(&self.selection, self.pixel_size_m)?;
        self.fluorescence
            .check(&self.fluorescence_selection(), self.pixel_size_m)?;
        if let Some((x, y)) = self.pixel_size_m {
            Quantity::PixelSize.check(x, Param::PixelSize)?;
            Quantity::PixelSize.check(y, Param::PixelSize)?;
        }
        let o = &self.options;
        Quantity::Wavelength.check(o.wavelength_m, Param::Wavelength)?;
        if !(o.medium_index.is_finite() && o.medium_index > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "{}: the refractive index {} must be a positive number",
                Param::MediumIndex,
                o.medium_index
            )));
        }
        if !(1..=Self::MAX_PROFILES).contains(&o.profiles) {
            return Err(Error::InvalidArgument(format!(
                "{}: {} profiles is out of range 1..={}",
                Param::Profiles,
                o.profiles,
                Self::MAX_PROFILES
            )));
        }
        Ok(())
    }

    /// The selection of the fluorescence image: the reflection's, with the contact channel.
    fn fluorescence_selection(&self) -> Selection {
        Selection {
            channel: self
                .contact_channel
                .map(ChannelChoice::Index)
                .or_else(|| self.selection.channel.clone()),
            ..self.selection.clone()
        }
    }
}

/// The two inputs and the pixel size used (`inputs` of `newton.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NewtonInputs {
    /// The reflection image's file (or label).
    pub reflection: String,
    /// The fluorescence image's file (or label).
    pub fluorescence: String,
    /// Pixel size along x, m.
    #[serde(rename = "pixel_size_x_um", serialize_with = "lab::m_as_um")]
    pub pixel_size_x_m: f64,
    /// Pixel size along y, m.
    #[serde(rename = "pixel_size_y_um", serialize_with = "lab::m_as_um")]
    pub pixel_size_y_m: f64,
}

/// The gap d_m of one ring order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RingGap {
    /// Interference order m.
    pub order: u32,
    /// d_m, m.
    #[serde(rename = "gap_nm", serialize_with = "lab::m_as_nm")]
    pub gap_m: f64,
}

/// The method as `newton.json` records it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NewtonMethod {
    /// How the contact centre is found.
    pub centre: &'static str,
    /// Width of each line, pixels.
    pub line_width_px: usize,
    /// Smoothing along a profile, pixels.
    pub smoothing_sigma_px: f64,
    /// How the fluorescent edge is found.
    pub edge: &'static str,
    /// Distance from the edge to its plateaus, m.
    #[serde(rename = "edge_margin_um", serialize_with = "lab::m_as_um")]
    pub edge_margin_m: f64,
    /// How ring orders are assigned.
    pub ring_orders: String,
    /// The gap model fitted.
    pub gap_model: &'static str,
    /// Profiles with a larger rms residual are skipped, m.
    #[serde(rename = "max_rms_residual_nm", serialize_with = "lab::m_as_nm")]
    pub max_rms_residual_m: f64,
}

/// One line profile: an entry of `profiles` in `newton.json` (`newton_profiles.csv` has most
/// of its columns).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfileRow {
    /// Profile index.
    pub profile: usize,
    /// Angle of the line, degrees.
    pub angle_deg: f64,
    /// Rings found.
    pub rings: usize,
    /// Mean edge radius of the half-lines used, m.
    #[serde(rename = "edge_radius_um", serialize_with = "lab::opt_m_as_um")]
    pub edge_radius_m: Option<f64>,
    /// Half-lines used (0–2).
    pub half_lines_used: usize,
    /// Fitted contact radius a, m.
    #[serde(rename = "a_um", serialize_with = "lab::opt_m_as_um")]
    pub a_m: Option<f64>,
    /// Fitted sphere radius R, m.
    #[serde(rename = "R_mm", serialize_with = "opt_m_as_mm")]
    pub r_m: Option<f64>,
    /// rms gap residual of the fit, m.
    #[serde(rename = "rms_residual_nm", serialize_with = "lab::opt_m_as_nm")]
    pub rms_residual_m: Option<f64>,
    /// The same with every order one higher, m.
    #[serde(
        rename = "shifted_rms_residual_nm",
        serialize_with = "lab::opt_m_as_nm"
    )]
    pub shifted_rms_residual_m: Option<f64>,
    /// Ratio of the two.
    pub shifted_residual_ratio: Option<f64>,
    /// Fitted gap at the edge, m.
    #[serde(rename = "detection_gap_nm", serialize_with = "lab::opt_m_as_nm")]
    pub detection_gap_m: Option<f64>,
    /// Whether it enters the averages.
    pub used: bool,
    /// Why not.
    pub skipped_reason: Option<String>,
}

/// A profile left out of the averages.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkippedProfile {
    /// Profile index.
    pub profile: usize,
    /// Angle, degrees.
    pub angle_deg: f64,
    /// Why.
    pub reason: String,
}

/// One ring maximum: a row of `newton_rings.csv` (`rings` of the outcome).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RingRow {
    /// Profile index.
    pub profile: usize,
    /// Angle of the profile, degrees.
    pub angle_deg: f64,
    /// `+` for the half-line at the angle, `-` for the opposite one.
    pub side: &'static str,
    /// Interference order m.
    pub order: u32,
    /// Distance from the centre, m.
    #[serde(rename = "r_um", serialize_with = "lab::m_as_um")]
    pub r_m: f64,
    /// Gap d_m of its order, m.
    #[serde(rename = "gap_nm", serialize_with = "lab::m_as_nm")]
    pub gap_m: f64,
    /// The profile's fitted gap at r, m.
    #[serde(rename = "fit_gap_nm", serialize_with = "lab::opt_m_as_nm")]
    pub fit_gap_m: Option<f64>,
    /// Whether the profile is used.
    pub used: bool,
}

/// What `newton` found: `newton.json` (without `rings`, which is `newton_rings.csv`).
#[derive(Debug, Clone, Serialize)]
pub struct NewtonOutcome {
    /// The inputs and the pixel size.
    pub inputs: NewtonInputs,
    /// Detection gap over the profiles used: mean, m.
    #[serde(rename = "detection_gap_nm_mean", serialize_with = "lab::m_as_nm")]
    pub detection_gap_m_mean: f64,
    /// Its sd, m.
    #[serde(rename = "detection_gap_nm_sd", serialize_with = "lab::opt_m_as_nm")]
    pub detection_gap_m_sd: Option<f64>,
    /// Edge radius: mean, m.
    #[serde(rename = "edge_radius_um", serialize_with = "lab::m_as_um")]
    pub edge_radius_m: f64,
    /// Its sd, m.
    #[serde(rename = "edge_radius_um_sd", serialize_with = "lab::opt_m_as_um")]
    pub edge_radius_m_sd: Option<f64>,
    /// Fitted contact radius a: mean, m.
    #[serde(rename = "contact_radius_a_um_mean", serialize_with = "lab::m_as_um")]
    pub contact_radius_a_m_mean: f64,
    /// Its sd, m.
    #[serde(rename = "contact_radius_a_um_sd", serialize_with = "lab::opt_m_as_um")]
    pub contact_radius_a_m_sd: Option<f64>,
    /// Fitted sphere radius R: mean, m.
    #[serde(rename = "sphere_radius_R_mm_mean", serialize_with = "m_as_mm")]
    pub sphere_radius_r_m_mean: f64,
    /// Its sd, m.
    #[serde(rename = "sphere_radius_R_mm_sd", serialize_with = "opt_m_as_mm")]
    pub sphere_radius_r_m_sd: Option<f64>,
    /// Profiles used.
    pub profiles_used: usize,
    /// Profiles measured.
    pub profiles_total: usize,
    /// Fewest usable profiles for a result.
    pub profiles_needed: usize,
    /// Contact centre, column.
    pub centre_x_px: f64,
    /// Contact centre, row.
    pub centre_y_px: f64,
    /// Contact centre x, m.
    #[serde(rename = "centre_x_um", serialize_with = "lab::m_as_um")]
    pub centre_x_m: f64,
    /// Contact centre y, m.
    #[serde(rename = "centre_y_um", serialize_with = "lab::m_as_um")]
    pub centre_y_m: f64,
    /// Otsu threshold of the fluorescence image.
    pub fluorescence_threshold: f64,
    /// Pixels of the largest contact region.
    pub fluorescence_contact_pixels: usize,
    /// Wavelength, m.
    #[serde(rename = "wavelength_nm", serialize_with = "lab::m_as_nm")]
    pub wavelength_m: f64,
    /// Refractive index of the medium.
    pub medium_index: f64,
    /// Phase of the maxima: `half` or `zero`.
    pub phase: &'static str,
    /// The gaps of the first six orders.
    #[serde(rename = "ring_gaps_nm")]
    pub ring_gaps: Vec<RingGap>,
    /// The method.
    pub method: NewtonMethod,
    /// Every profile.
    pub profiles: Vec<ProfileRow>,
    /// The profiles left out, and why.
    pub skipped_profiles: Vec<SkippedProfile>,
    /// Every ring maximum: `newton_rings.csv`.
    pub rings: Vec<RingRow>,
    /// The measurement itself, for printing and plotting.
    #[serde(skip)]
    pub analysis: NewtonAnalysis,
}

/// Run `newton` in memory: check the request, read the two images, analyse.
pub fn run(request: &NewtonRequest) -> Result<NewtonOutcome> {
    request.check()?;
    let (sel, px) = (&request.selection, request.pixel_size_m);
    let reflection = request.reflection.read_one(sel, px)?;
    let fluorescence = request
        .fluorescence
        .read_one(&request.fluorescence_selection(), px)?;
    let analysis = analyse(&reflection, &fluorescence, &request.options)?;
    Ok(outcome(request, analysis))
}

/// Stored in m, written in mm (in SI, [`lab::in_si`]: m).
fn m_as_mm<S: serde::Serializer>(v: &f64, s: S) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_f64(if lab::si() { *v } else { v * 1e3 })
}

/// The same, for an optional value (`null` when absent).
fn opt_m_as_mm<S: serde::Serializer>(
    v: &Option<f64>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    match v {
        Some(v) => m_as_mm(v, s),
        None => s.serialize_none(),
    }
}

fn outcome(request: &NewtonRequest, a: NewtonAnalysis) -> NewtonOutcome {
    let o = &request.options;
    let (cx, cy) = a.contact.centre_px;
    let profiles = a
        .profiles
        .iter()
        .map(|p| ProfileRow {
            profile: p.index,
            angle_deg: p.angle_deg,
            rings: p.rings.len(),
            edge_radius_m: p.edge_radius_m(),
            half_lines_used: p.sides_used().iter().filter(|&&u| u).count(),
            a_m: p.fit.map(|f| f.contact_radius_m),
            r_m: p.fit.map(|f| f.sphere_radius_m),
            rms_residual_m: p.fit.map(|f| f.rms_residual_m),
            shifted_rms_residual_m: p.shifted_fit.map(|f| f.rms_residual_m),
            shifted_residual_ratio: p.shifted_residual_ratio(),
            detection_gap_m: p.detection_gap_m,
            used: p.skipped.is_none(),
            skipped_reason: p.skipped.clone(),
        })
        .collect();
    let skipped_profiles = a
        .profiles
        .iter()
        .filter_map(|p| {
            Some(SkippedProfile {
                profile: p.index,
                angle_deg: p.angle_deg,
                reason: p.skipped.clone()?,
            })
        })
        .collect();
    let rings = a
        .profiles
        .iter()
        .flat_map(|p| {
            p.rings.iter().map(move |ring| RingRow {
                profile: p.index,
                angle_deg: p.angle_deg,
                side: if ring.side > 0 { "+" } else { "-" },
                order: ring.order,
                r_m: ring.radius_m,
                gap_m: ring.gap_m,
                fit_gap_m: p.fit.map(|f| f.gap_at(ring.radius_m)),
                used: p.skipped.is_none(),
            })
        })
        .collect();
    NewtonOutcome {
        inputs: NewtonInputs {
            reflection: request.reflection.label(),
            fluorescence: request.fluorescence.label(),
            pixel_size_x_m: a.pixel_m.0,
            pixel_size_y_m: a.pixel_m.1,
        },
        detection_gap_m_mean: a.detection_gap_m.mean,
        detection_gap_m_sd: a.detection_gap_m.sd,
        edge_radius_m: a.edge_radius_m.mean,
        edge_radius_m_sd: a.edge_radius_m.sd,
        contact_radius_a_m_mean: a.contact_radius_m.mean,
        contact_radius_a_m_sd: a.contact_radius_m.sd,
        sphere_radius_r_m_mean: a.sphere_radius_m.mean,
        sphere_radius_r_m_sd: a.sphere_radius_m.sd,
        profiles_used: a.used().count(),
        profiles_total: a.profiles.len(),
        profiles_needed: o.min_profiles.min(o.profiles),
        centre_x_px: cx,
        centre_y_px: cy,
        centre_x_m: cx * a.pixel_m.0,
        centre_y_m: cy * a.pixel_m.1,
        fluorescence_threshold: a.contact.threshold,
        fluorescence_contact_pixels: a.contact.pixels,
        wavelength_m: o.wavelength_m,
        medium_index: o.medium_index,
        phase: o.phase.name(),
        ring_gaps: (0..6)
            .map(|m| m + o.phase.first_order())
            .map(|m| RingGap {
                order: m,
                gap_m: ring_gap(m, o.wavelength_m, o.medium_index, o.phase),
            })
            .collect(),
        method: NewtonMethod {
            centre: "centroid of the largest 8-connected region above the exact Otsu threshold of the fluorescence image",
            line_width_px: o.line_width_px,
            smoothing_sigma_px: o.smoothing_px,
            edge: "half-way between the inside and outside plateaus (medians beyond the margin), linearly interpolated",
            edge_margin_m: o.edge_margin_m,
            ring_orders: format!(
                "innermost ring outside the fluorescent edge is m = {}; further orders where r² extrapolated from the last two rings puts them",
                o.phase.first_order()
            ),
            gap_model: "Hertz exterior gap (Johnson 1985), a and R free, a ≤ edge radius",
            max_rms_residual_m: o.max_rms_residual_m,
        },
        profiles,
        skipped_profiles,
        rings,
        analysis: a,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn millimetres_in_the_file_metres_in_si() {
        #[derive(Serialize)]
        struct Radius {
            #[serde(rename = "R_mm", serialize_with = "opt_m_as_mm")]
            r_m: Option<f64>,
            #[serde(rename = "sphere_radius_R_mm_mean", serialize_with = "m_as_mm")]
            mean_m: f64,
        }
        let r = Radius {
            r_m: Some(2.9e-4),
            mean_m: 2.9e-4,
        };
        let lab = serde_json::to_value(&r).unwrap();
        assert_eq!(lab["R_mm"], 2.9e-4 * 1e3);
        let si = lab::to_si_value(&r).unwrap();
        assert_eq!(si["R_m"], 2.9e-4);
        assert_eq!(si["sphere_radius_R_m_mean"], 2.9e-4);
    }

    #[test]
    fn the_request_checks_the_options() {
        let file = |p: &str| ImageInput::File(p.into());
        let ok = NewtonRequest::new(file("r.tif"), file("f.tif"));
        assert!(ok.check().is_ok());
        let mut bad = ok.clone();
        bad.options.wavelength_m = 488.0;
        assert!(bad.check().is_err());
        let mut bad = ok.clone();
        bad.options.profiles = 0;
        assert!(bad.check().is_err());
        let mut bad = ok;
        bad.options.medium_index = f64::NAN;
        assert!(bad.check().is_err());
    }
}
