//! A parameter sweep of `fit-hardening` (Supplementary Fig. 8 of Weber et al. 2018): the
//! simulated area–load curve of one family at given parameter values, each value's ramp in
//! parallel, optionally scored against micrographs (Dice per load).

use rayon::prelude::*;

use contactscope::compare::{
    compare_maps, CompareSettings, Micrographs as MicrographSet, SimulatedMap,
};
use contactscope::model_fit::{Evaluation, Family, Measured, ModelBody};
use contactscope::optics::blur::Grid;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;
use contactscope_formats::units::{self, Dimension};

use super::FitRequest;
use crate::compare::CompareRequest;
use crate::error::{Error, Result};
use crate::series::Micrographs;

/// A parameter sweep: one family, explicit values (Pa or Pa/m).
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    /// Hardness or hardening.
    pub family: Family,
    /// Parameter values.
    pub values: Vec<f64>,
}

impl Sweep {
    /// Parse `k=1..10MPa/nm:10`, `k=1,2,4MPa/nm` or `hardness=100..1000MPa:10` (evenly spaced).
    pub fn parse(text: &str) -> Result<Self> {
        let (name, values) = text.split_once('=').ok_or_else(|| {
            Error::InvalidArgument(format!(
                "sweep '{text}' must read k=1..10MPa/nm:10 or hardness=100..1000MPa:10"
            ))
        })?;
        let (family, values) = match name.trim() {
            "k" => (
                Family::Hardening,
                units::parse_value_list(values, &|t| {
                    units::parse_ratio(t, Dimension::Pressure, Dimension::Length)
                })?,
            ),
            "hardness" | "pY" | "p_Y" => (
                Family::Hardness,
                units::parse_value_list(values, &|t| {
                    units::parse_positive(t, Dimension::Pressure)
                })?,
            ),
            other => {
                return Err(Error::InvalidArgument(format!(
                    "sweep parameter '{other}' is not k or hardness"
                )))
            }
        };
        if values.iter().any(|v| v.is_nan() || *v <= 0.0) {
            return Err(Error::InvalidArgument(format!(
                "sweep '{text}' needs positive values"
            )));
        }
        Ok(Sweep { family, values })
    }
}

/// Micrographs to score a sweep against.
#[derive(Debug, Clone)]
pub struct SweepMicrographs {
    /// The experiment series with its forces.
    pub micrographs: Micrographs,
    /// Pixel size override (x, y), m.
    pub pixel_size_m: Option<(f64, f64)>,
    /// PSF FWHM, m.
    pub psf_fwhm_m: f64,
}

impl SweepMicrographs {
    /// The range checks.
    pub fn check(&self) -> Result<()> {
        self.micrographs.check()?;
        Quantity::Fwhm.check(self.psf_fwhm_m, Param::PsfFwhm)?;
        if let Some((x, y)) = self.pixel_size_m {
            Quantity::PixelSize.check(x, Param::PixelSize)?;
            Quantity::PixelSize.check(y, Param::PixelSize)?;
        }
        Ok(())
    }

    /// Registration and matching as `compare` does by default.
    fn settings(&self) -> CompareSettings {
        CompareSettings {
            psf_fwhm_m: self.psf_fwhm_m,
            dihedral: false,
            upsample: CompareRequest::UPSAMPLE,
            force_tolerance: CompareRequest::FORCE_TOLERANCE,
        }
    }
}

/// One sweep value at one load.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    /// Parameter (Pa or Pa/m).
    pub parameter: f64,
    /// Normal force, N.
    pub force_n: f64,
    /// Measured area, m².
    pub measured_area_m2: f64,
    /// Simulated area, m².
    pub simulated_area_m2: f64,
    /// Dice against the micrograph of this load, when micrographs were given.
    pub dice: Option<f64>,
}

pub(super) fn run_sweep(
    request: &FitRequest,
    body: &ModelBody,
    sweep: &Sweep,
    measured: &Measured,
    micrographs: Option<&MicrographSet>,
) -> Result<Vec<SweepRow>> {
    let per_value: Vec<Vec<SweepRow>> = sweep
        .values
        .par_iter()
        .map(|&value| {
            let eval = body.score(sweep.family, Some(value), measured, micrographs.is_some())?;
            let dice = match (micrographs, &request.micrographs) {
                (Some(m), Some(settings)) => Some(dice_per_load(
                    body,
                    &eval,
                    measured,
                    m,
                    &settings.settings(),
                )?),
                _ => None,
            };
            Ok(rows_of(value, measured, &eval, dice))
        })
        .collect::<Result<_>>()?;
    Ok(per_value.into_iter().flatten().collect())
}

fn rows_of(
    value: f64,
    measured: &Measured,
    eval: &Evaluation,
    dice: Option<Vec<Option<f64>>>,
) -> Vec<SweepRow> {
    (0..measured.forces_n.len())
        .map(|i| SweepRow {
            parameter: value,
            force_n: measured.forces_n[i],
            measured_area_m2: measured.areas_m2[i],
            simulated_area_m2: eval.areas_m2[i],
            dice: dice.as_ref().and_then(|d| d[i]),
        })
        .collect()
}

/// Dice per measured load (None where no micrograph matches the force).
fn dice_per_load(
    body: &ModelBody,
    eval: &Evaluation,
    measured: &Measured,
    micrographs: &MicrographSet,
    settings: &CompareSettings,
) -> Result<Vec<Option<f64>>> {
    let maps = eval.maps.as_ref().expect("maps kept for Dice");
    let simulated: Vec<SimulatedMap> = maps
        .iter()
        .zip(&measured.forces_n)
        .map(|(m, &f)| {
            Ok(SimulatedMap {
                force_n: f,
                map: Grid::new(
                    m.clone(),
                    body.body.nx(),
                    body.body.ny(),
                    body.body.dx_m,
                    body.body.dy_m,
                )?,
                source: format!("simulated at {:.4} mN", f * 1e3),
            })
        })
        .collect::<Result<_>>()?;
    let comparison = compare_maps(micrographs, &simulated, settings)?;
    Ok(measured
        .forces_n
        .iter()
        .map(|&f| {
            comparison
                .loads
                .iter()
                .find(|l| (l.simulated_force_n - f).abs() <= 1e-12 * f)
                .map(|l| l.dice)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_parse_with_units() {
        let s = Sweep::parse("k=1..10MPa/nm:10").unwrap();
        assert_eq!(s.family, Family::Hardening);
        assert_eq!(s.values.len(), 10);
        assert!((s.values[3] - 4e15).abs() < 1.0);
        let s = Sweep::parse("hardness=100,370MPa").unwrap();
        assert_eq!(s.family, Family::Hardness);
        assert_eq!(s.values, vec![1e8, 3.7e8]);
        assert!(Sweep::parse("alpha=1..2:3").is_err());
        assert!(Sweep::parse("k=1..10MPa").is_err());
    }
}
