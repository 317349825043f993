//! The `compare` job: simulated contact maps against micrographs, load by load (Weber et al.
//! 2018, Fig. 2; `docs/methods.md` §7.4 and §8). Every front-end builds a [`CompareRequest`]:
//! the micrographs (files or planes in memory, [`Micrographs`]) and the simulated maps (a
//! `simulate` output folder or maps in memory); [`CompareRequest::check`] applies the range
//! checks; [`run`] returns a [`CompareOutcome`], which is `compare.json` (lab units) and the
//! Python result (SI units). [`files`] writes `compare.csv`, `compare.json` and the panels.

pub mod files;

use std::path::PathBuf;

use serde::ser::SerializeSeq;
use serde::{Serialize, Serializer};

use contactscope::analysis::{global_threshold, PlaneSource};
use contactscope::compare::{
    compare_maps, CompareSettings, Comparison, LoadComparison, Micrograph,
    Micrographs as MicrographSet, Prepared, SeriesShift, SimulatedMap,
};
use contactscope::image::pixel_size_or;
use contactscope::spectral::register::MAX_UPSAMPLE;
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::{Error, Location, Result};
use crate::lab::{self, OptQ, Unit, Q};
use crate::results::simulated_maps;
use crate::series::{Micrographs, Series};

/// The simulated maps: a `simulate` output folder, or maps in memory.
#[derive(Debug, Clone)]
pub enum Simulation {
    /// A folder written by `simulate` (`areas.csv`, `load_NNN_contact.tif`).
    Folder(PathBuf),
    /// Contact maps (1 = contact) at forces, with their pixel size.
    Memory {
        /// The maps.
        maps: Vec<SimulatedMap>,
        /// What to call them in outputs.
        label: String,
    },
}

impl Simulation {
    fn label(&self) -> String {
        match self {
            Simulation::Folder(p) => p.display().to_string(),
            Simulation::Memory { label, .. } => label.clone(),
        }
    }
}

/// Everything `compare` needs. SI units.
#[derive(Debug, Clone)]
pub struct CompareRequest {
    /// The experiment series with its forces.
    pub micrographs: Micrographs,
    /// Micrograph pixel size (x, y), m, overriding the files' metadata.
    pub pixel_size_m: Option<(f64, f64)>,
    /// The simulated maps.
    pub simulation: Simulation,
    /// PSF FWHM, m.
    pub psf_fwhm_m: f64,
    /// Also try mirror images and 90° rotations when registering.
    pub dihedral: bool,
    /// Sub-pixel registration resolution, 1/`upsample` px.
    pub upsample: usize,
    /// Largest relative force difference for two loads to match.
    pub force_tolerance: f64,
}

impl CompareRequest {
    /// Default registration upsampling.
    pub const UPSAMPLE: usize = 20;
    /// Default force tolerance (1 %).
    pub const FORCE_TOLERANCE: f64 = 0.01;

    /// A request with the defaults: no dihedral search, 1/20 px, 1 % force tolerance.
    pub fn new(micrographs: Micrographs, simulation: Simulation, psf_fwhm_m: f64) -> Self {
        CompareRequest {
            micrographs,
            pixel_size_m: None,
            simulation,
            psf_fwhm_m,
            dihedral: false,
            upsample: Self::UPSAMPLE,
            force_tolerance: Self::FORCE_TOLERANCE,
        }
    }

    /// Every range check, the same for every front-end.
    pub fn check(&self) -> Result<()> {
        self.micrographs.check()?;
        if let Some((x, y)) = self.pixel_size_m {
            Quantity::PixelSize.check(x, Param::PixelSize)?;
            Quantity::PixelSize.check(y, Param::PixelSize)?;
        }
        Quantity::Fwhm.check(self.psf_fwhm_m, Param::PsfFwhm)?;
        if !(1..=MAX_UPSAMPLE).contains(&self.upsample) {
            return Err(Error::InvalidArgument(format!(
                "{} {}: give 1 to {MAX_UPSAMPLE} (a sub-pixel resolution of 1/N pixel)",
                Param::Upsample,
                self.upsample
            )));
        }
        if !(0.0..1.0).contains(&self.force_tolerance) {
            return Err(Error::InvalidArgument(format!(
                "{} {}: give a fraction in [0, 1) such as 0.01 (1 %)",
                Param::ForceTolerance,
                self.force_tolerance
            )));
        }
        Ok(())
    }

    fn settings(&self) -> CompareSettings {
        CompareSettings {
            psf_fwhm_m: self.psf_fwhm_m,
            dihedral: self.dihedral,
            upsample: self.upsample,
            force_tolerance: self.force_tolerance,
        }
    }
}

/// How the comparison is made, in words (`compare.json` `method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MethodWords {
    /// The simulated image.
    pub simulated_image: &'static str,
    /// The registration.
    pub registration: &'static str,
    /// The thresholds.
    pub thresholds: &'static str,
    /// Where the scores are computed.
    pub scores: &'static str,
    /// The edge distance.
    pub edge_distance_um: &'static str,
    /// The autocorrelation distance.
    pub acf_rms_distance: &'static str,
}

const METHOD: MethodWords = MethodWords {
    simulated_image: "contact map (g = 0) blurred by a Gaussian PSF on the simulation grid, integrated over micrograph pixels (area fraction), centred on a micrograph-sized canvas",
    registration: "one shift for the series: the highest peak of the mean normalised cross-power spectrum of all matched loads (Hann window, upsampled-DFT sub-pixel refinement); each load refined within the window around it, keeping the series shift where its own peak is weak or on the window's edge",
    thresholds: "experiment: exact Otsu over all micrographs of the series; simulation: Otsu over all blurred simulated images (4096 bins)",
    scores: "on the region covered by the simulation after registration",
    edge_distance_um: "mean of the two mean distances from each contact-edge pixel to the other map's nearest edge pixel (exact Euclidean distance transform)",
    acf_rms_distance: "RMS difference of the radially averaged intensity autocorrelations, lags up to half the smaller micrograph side",
};

/// What `compare` found: `compare.json` without the command line.
#[derive(Debug, Clone, Serialize)]
pub struct CompareOutcome {
    /// The simulation folder (or the label of maps in memory).
    pub simulation: String,
    /// PSF FWHM, m.
    #[serde(rename = "psf_fwhm_nm", serialize_with = "lab::m_as_nm")]
    pub psf_fwhm_m: f64,
    /// The experiment's global Otsu threshold (grey levels).
    pub experiment_threshold: f64,
    /// The simulated images' threshold (blurred contact fraction, 0..1).
    pub simulated_threshold: f64,
    /// Whether the dihedral transforms were tried.
    pub dihedral_search: bool,
    /// Sub-pixel resolution, 1/N px.
    pub upsample: usize,
    /// Force tolerance (a fraction; written in %).
    #[serde(
        rename = "force_tolerance_pct",
        serialize_with = "lab::fraction_as_pct"
    )]
    pub force_tolerance: f64,
    /// Loads present in both.
    pub loads_matched: usize,
    /// Mean Dice over the matched loads.
    pub dice_mean: f64,
    /// Mean Jaccard index.
    pub jaccard_mean: f64,
    /// The registration of the whole series.
    #[serde(serialize_with = "series_json")]
    pub series_registration: SeriesShift,
    /// How it was done.
    pub method: MethodWords,
    /// One entry per matched load, in experiment order.
    #[serde(serialize_with = "loads_json")]
    pub loads: Vec<LoadComparison>,
    /// Notes for the user.
    pub warnings: Vec<String>,
    /// Micrograph pixel size (x, y), m.
    #[serde(skip)]
    pub pixel_m: (f64, f64),
    /// Each matched pair, registered, for the panels.
    #[serde(skip)]
    pub prepared: Vec<Prepared>,
}

/// The series registration as `compare.json` writes it.
fn series_json<S: Serializer>(r: &SeriesShift, s: S) -> std::result::Result<S::Ok, S::Error> {
    use serde::ser::SerializeMap;
    let mut m = s.serialize_map(None)?;
    m.serialize_entry("transform", &r.transform.name())?;
    m.serialize_entry("shift_x_px", &r.shift_px.0)?;
    m.serialize_entry("shift_y_px", &r.shift_px.1)?;
    m.serialize_entry("shift_x_um", &Q(r.shift_m.0, Unit::MAsUm))?;
    m.serialize_entry("shift_y_um", &Q(r.shift_m.1, Unit::MAsUm))?;
    m.serialize_entry("correlation_peak", &r.correlation_peak)?;
    m.serialize_entry("window_px", &r.window_px)?;
    m.end()
}

/// The loads as `compare.json` lists them.
fn loads_json<S: Serializer>(
    loads: &[LoadComparison],
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    struct One<'a>(&'a LoadComparison);
    impl Serialize for One<'_> {
        fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
            use serde::ser::SerializeMap;
            let l = self.0;
            let mut m = s.serialize_map(None)?;
            m.serialize_entry("force_mN", &Q(l.force_n, Unit::NAsMn))?;
            m.serialize_entry("simulated_force_mN", &Q(l.simulated_force_n, Unit::NAsMn))?;
            m.serialize_entry("transform", &l.transform.name())?;
            m.serialize_entry("shift_x_px", &l.shift_px.0)?;
            m.serialize_entry("shift_y_px", &l.shift_px.1)?;
            m.serialize_entry("shift_x_um", &Q(l.shift_m.0, Unit::MAsUm))?;
            m.serialize_entry("shift_y_um", &Q(l.shift_m.1, Unit::MAsUm))?;
            m.serialize_entry("correlation_peak", &l.correlation_peak)?;
            m.serialize_entry("refinement", l.refinement.name())?;
            m.serialize_entry(
                "experiment_area_um2",
                &Q(l.experiment_area_m2, Unit::M2AsUm2),
            )?;
            m.serialize_entry("simulated_area_um2", &Q(l.simulated_area_m2, Unit::M2AsUm2))?;
            m.serialize_entry(
                "simulated_raw_area_um2",
                &Q(l.simulated_raw_area_m2, Unit::M2AsUm2),
            )?;
            m.serialize_entry("dice", &l.dice)?;
            m.serialize_entry("jaccard", &l.jaccard)?;
            m.serialize_entry("edge_distance_um", &OptQ(l.edge_distance_m, Unit::MAsUm))?;
            m.serialize_entry("acf_rms_distance", &l.acf_rms_distance)?;
            m.end()
        }
    }
    let mut seq = s.serialize_seq(Some(loads.len()))?;
    for l in loads {
        seq.serialize_element(&One(l))?;
    }
    seq.end()
}

/// Run `compare` in memory: match loads, render, register, threshold, score.
pub fn run(request: &CompareRequest) -> Result<CompareOutcome> {
    request.check()?;
    let (_, micrographs) = load_micrographs(&request.micrographs, request.pixel_size_m)?;
    run_with(request, &micrographs)
}

/// [`run`] on micrographs already read (the folder writer needs their files first).
pub fn run_with(request: &CompareRequest, micrographs: &MicrographSet) -> Result<CompareOutcome> {
    let simulated = match &request.simulation {
        Simulation::Folder(dir) => simulated_maps(dir)?,
        Simulation::Memory { maps, .. } => maps.clone(),
    };
    let Comparison {
        loads,
        prepared,
        registration,
        simulated_threshold,
        warnings,
        ..
    } = compare_maps(micrographs, &simulated, &request.settings())?;
    let mean = |f: &dyn Fn(&LoadComparison) -> f64| {
        loads.iter().map(f).sum::<f64>() / loads.len().max(1) as f64
    };
    Ok(CompareOutcome {
        simulation: request.simulation.label(),
        psf_fwhm_m: request.psf_fwhm_m,
        experiment_threshold: micrographs.threshold,
        simulated_threshold,
        dihedral_search: request.dihedral,
        upsample: request.upsample,
        force_tolerance: request.force_tolerance,
        loads_matched: loads.len(),
        dice_mean: mean(&|l| l.dice),
        jaccard_mean: mean(&|l| l.jaccard),
        series_registration: registration,
        method: METHOD,
        warnings,
        pixel_m: micrographs.pixel_m,
        prepared,
        loads,
    })
}

/// Read the experiment series, its forces and pixel size, decode its micrographs and threshold
/// them (one exact Otsu threshold over the series, as `analyze`).
pub fn load_micrographs(
    input: &Micrographs,
    pixel_size_m: Option<(f64, f64)>,
) -> Result<(Series, MicrographSet)> {
    let open = input.open()?;
    crate::series::refuse_maps(&open.series)?;
    let planes = match &open.planes {
        Some(planes) => planes.clone(),
        None => open.series.planes(0).scan(|_, plane| Ok(plane.clone()))?,
    };
    let (threshold, _, warnings) = global_threshold(planes.as_slice(), &|_, _, _| {})?;
    let series = open.series;
    let pixel_m = experiment_pixel(&series, pixel_size_m)?;
    let mut warnings = warnings;
    warnings.extend(crate::series::pixel_size_warnings(
        &series,
        pixel_m,
        pixel_size_m.is_some(),
    ));
    let images = series
        .images
        .iter()
        .zip(planes)
        .map(|(image, plane)| Micrograph {
            plane,
            force_n: image.force_n,
            path: image.path.clone(),
            page: image.page,
        })
        .collect();
    let micrographs = MicrographSet {
        images,
        threshold: threshold.value,
        pixel_m,
        warnings,
    };
    Ok((series, micrographs))
}

fn experiment_pixel(series: &Series, pixel_size_m: Option<(f64, f64)>) -> Result<(f64, f64)> {
    let file = series.files.first();
    pixel_size_or(file.and_then(|f| f.pixel_size), pixel_size_m)
        .map(|p| (p.x_m, p.y_m))
        .ok_or_else(|| {
            let at = file.map_or_else(
                || Location::file(series.images[0].path.clone()),
                |f| Location::file(&f.path),
            );
            Error::bad_input(
                at,
                format!(
                    "no pixel size in the file's metadata; give one with {} (e.g. 200nm)",
                    Param::PixelSize
                ),
            )
        })
}
