//! The `hertz` job: a squeeze-test CSV in; E* from [`contactscope::mechanics::squeeze`] and the
//! predicted Hertz contact radii out. Every front-end builds a [`HertzRequest`],
//! [`HertzRequest::check`] applies the same range checks, and [`run`] returns a
//! [`HertzOutcome`], whose serialisation is `hertz.json` (lab units; without `points`, which is
//! `hertz_fit.csv`) and the Python result (SI units, [`crate::lab`]). [`files`] writes the folder.

pub mod files;

use std::path::PathBuf;

use serde::ser::SerializeMap;
use serde::{Serialize, Serializer};

use contactscope::mechanics::hertz;
use contactscope::mechanics::squeeze::{
    check_radius, fit_hertz, fit_hertz_with_offset, HertzFit, SqueezePoint,
};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::Result;
use crate::lab::{self, Unit, Q};
use crate::mechanics_csv::read_squeeze;
use crate::simulate::check_loads;

/// Everything `hertz` needs. SI units.
#[derive(Debug, Clone)]
pub struct HertzRequest {
    /// The squeeze CSV (format in [`crate::mechanics_csv`]).
    pub input: PathBuf,
    /// Sphere radius R, m.
    pub radius_m: f64,
    /// Loads at which to predict the contact radius, N; the measured forces when `None`.
    pub loads_n: Option<Vec<f64>>,
}

impl HertzRequest {
    /// A request with the defaults: predictions at the measured forces.
    pub fn new(input: PathBuf, radius_m: f64) -> Self {
        HertzRequest {
            input,
            radius_m,
            loads_n: None,
        }
    }

    /// Every range check, the same for every front-end; each refusal names the parameter.
    pub fn check(&self) -> Result<()> {
        Quantity::Radius.check(self.radius_m, Param::Radius)?;
        if let Some(loads) = &self.loads_n {
            check_loads(loads, Param::Loads)?;
        }
        Ok(())
    }
}

/// The Hertz contact at one load (`hertz.json` `predicted`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HertzPrediction {
    /// Load P, N.
    #[serde(rename = "force_mN", serialize_with = "lab::n_as_mn")]
    pub force_n: f64,
    /// Contact radius a = (3PR/4E*)^(1/3) (paper Eq. 3), m.
    #[serde(rename = "contact_radius_um", serialize_with = "lab::m_as_um")]
    pub contact_radius_m: f64,
    /// Contact area πa², m².
    #[serde(rename = "contact_area_um2", serialize_with = "lab::m2_as_um2")]
    pub contact_area_m2: f64,
}

/// One fitted point (a row of `hertz_fit.csv`; `points` of the Python result).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FitPoint {
    /// Measured force P, N.
    #[serde(rename = "force_mN", serialize_with = "lab::n_as_mn")]
    pub force_n: f64,
    /// Total plate displacement 2δ, m.
    #[serde(rename = "displacement_um", serialize_with = "lab::m_as_um")]
    pub displacement_m: f64,
    /// Approach of one contact δ, m.
    #[serde(rename = "delta_um", serialize_with = "lab::m_as_um")]
    pub delta_m: f64,
    /// Force of the fit through the origin, N.
    #[serde(rename = "fitted_force_mN", serialize_with = "lab::n_as_mn")]
    pub fitted_force_n: f64,
    /// P − P_fit, N.
    #[serde(rename = "residual_mN", serialize_with = "lab::n_as_mn")]
    pub residual_n: f64,
}

/// What `hertz` found: `hertz.json` (without the version and the command line) and `points`.
#[derive(Debug, Clone)]
pub struct HertzOutcome {
    /// The squeeze CSV.
    pub input: PathBuf,
    /// Sphere radius R, m.
    pub radius_m: f64,
    /// Points used (P > 0).
    pub points: Vec<SqueezePoint>,
    /// Fit through the origin (the main result).
    pub fit: HertzFit,
    /// Fit with a free contact offset, when there are enough points.
    pub offset_fit: Option<HertzFit>,
    /// The Hertz contact at each load asked for.
    pub predicted: Vec<HertzPrediction>,
    /// Physics checks that failed ([`crate::physics`]): E* outside any solid's range.
    pub warnings: Vec<String>,
}

impl HertzOutcome {
    /// The points with the fit through the origin (`hertz_fit.csv`).
    pub fn fit_points(&self) -> Vec<FitPoint> {
        self.points
            .iter()
            .zip(&self.fit.fitted_n)
            .zip(self.fit.residuals(&self.points))
            .map(|((p, f), r)| FitPoint {
                force_n: p.force_n,
                displacement_m: p.displacement_m,
                delta_m: p.delta_m(),
                fitted_force_n: *f,
                residual_n: r,
            })
            .collect()
    }
}

/// The fit with a free contact point: E*, its standard error, R² and the contact offset.
struct OffsetFitJson<'a>(&'a HertzFit);

impl Serialize for OffsetFitJson<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let fit = self.0;
        let mut m = s.serialize_map(Some(4))?;
        m.serialize_entry("contact_modulus_GPa", &Q(fit.e_star_pa, Unit::PaAsGpa))?;
        m.serialize_entry(
            "contact_modulus_se_GPa",
            &Q(fit.e_star_se_pa, Unit::PaAsGpa),
        )?;
        m.serialize_entry("r2", &fit.r_squared)?;
        m.serialize_entry(
            "contact_offset_displacement_um",
            &Q(2.0 * fit.offset_m, Unit::MAsUm),
        )?;
        m.end()
    }
}

/// The law and the fits, in words (`method`).
struct MethodJson;

impl Serialize for MethodJson {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(4))?;
        m.serialize_entry("law", "P = (4/3) E* R^(1/2) delta^(3/2), delta = displacement/2 (two contacts in series); Johnson 1985 eq. 4.23. The paper's printed Eq. 2 lacks the square on E* and is not dimensionally consistent.")?;
        m.serialize_entry("fit", "least squares in P of P on delta^(3/2) through the origin (unweighted); se from sqrt(SS_res/(n-1)/sum x^2); r2 about the mean")?;
        m.serialize_entry("offset_fit", "same, with P = (4/3) E* R^(1/2) (delta - delta0)^(3/2) and delta0 minimising the residual (reported separately)")?;
        m.serialize_entry("contact_radius", "a = (3PR/4E*)^(1/3) (paper Eq. 3)")?;
        m.end()
    }
}

impl Serialize for HertzOutcome {
    /// `hertz.json` with `points` (lab units), or the Python result inside [`lab::in_si`].
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        let fit = &self.fit;
        let max_abs_residual_n = fit
            .residuals(&self.points)
            .iter()
            .fold(0.0f64, |m, r| m.max(r.abs()));
        let mut m = s.serialize_map(None)?;
        m.serialize_entry("input", &self.input.display().to_string())?;
        m.serialize_entry("radius_um", &Q(self.radius_m, Unit::MAsUm))?;
        m.serialize_entry("method", &MethodJson)?;
        m.serialize_entry("points_used", &self.points.len())?;
        m.serialize_entry("contact_modulus_GPa", &Q(fit.e_star_pa, Unit::PaAsGpa))?;
        m.serialize_entry(
            "contact_modulus_se_GPa",
            &Q(fit.e_star_se_pa, Unit::PaAsGpa),
        )?;
        m.serialize_entry("r2", &fit.r_squared)?;
        m.serialize_entry("max_abs_residual_mN", &Q(max_abs_residual_n, Unit::NAsMn))?;
        m.serialize_entry("offset_fit", &self.offset_fit.as_ref().map(OffsetFitJson))?;
        m.serialize_entry("predicted", &self.predicted)?;
        m.serialize_entry("points", &self.fit_points())?;
        m.serialize_entry("warnings", &self.warnings)?;
        m.end()
    }
}

/// Run `hertz` in memory: check, read, fit, predict a = (3PR/4E*)^(1/3) (paper Eq. 3). Nothing
/// is written.
pub fn run(request: &HertzRequest) -> Result<HertzOutcome> {
    request.check()?;
    check_radius(request.radius_m)?;
    let points = read_squeeze(&request.input)?;
    let fit = fit_hertz(&points, request.radius_m)?;
    let offset_fit = fit_hertz_with_offset(&points, request.radius_m).ok();
    let loads = match &request.loads_n {
        Some(l) => l.clone(),
        None => points.iter().map(|p| p.force_n).collect(),
    };
    let predicted = loads
        .iter()
        .map(|&p| {
            let a = hertz::contact_radius(p, request.radius_m, fit.e_star_pa);
            HertzPrediction {
                force_n: p,
                contact_radius_m: a,
                contact_area_m2: std::f64::consts::PI * a * a,
            }
        })
        .collect();
    let warnings = crate::physics::check(crate::physics::Checked::ContactModulus, fit.e_star_pa)
        .map(|w| format!("{}: {w}", request.input.display()))
        .into_iter()
        .collect();
    Ok(HertzOutcome {
        input: request.input.clone(),
        radius_m: request.radius_m,
        points,
        fit,
        offset_fit,
        predicted,
        warnings,
    })
}
