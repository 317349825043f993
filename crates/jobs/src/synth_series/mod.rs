//! The `synth-series` job: a seeded synthetic load series with known truth
//! ([`contactscope::synth::series`]), in memory. Every front-end builds a [`SynthSeriesRequest`]
//! (the command line from its flags, Python from its keywords) with the same defaults (the
//! bundled fixture's), [`SynthSeriesRequest::check`] applies the same range checks, and [`run`]
//! returns a [`SynthSeriesOutcome`]: the images and masks, and (serialised; in SI units for
//! Python, [`crate::lab`]) the forces and the true areas. [`files`] writes the TIFFs,
//! `manifest.csv` and `truth.csv`; [`read_truth`] reads the truth back.

pub mod files;

use serde::Serialize;

use contactscope::synth::series::{generate, SynthImage, SynthParams};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use crate::error::Result;
use crate::lab;
use crate::simulate::check_loads;

pub use files::{read_truth, run_to_folder, write_series, write_series_compressed, Layout};

/// Everything `synth-series` needs. SI units.
#[derive(Debug, Clone)]
pub struct SynthSeriesRequest {
    /// What to generate: size, pixel size, forces, seed and the generator's constants.
    pub params: SynthParams,
}

impl Default for SynthSeriesRequest {
    /// The bundled fixture: 256 × 256 px of 200 nm, eight loads 4…100 mN, seed 2018.
    fn default() -> Self {
        SynthSeriesRequest {
            params: SynthParams::default(),
        }
    }
}

impl SynthSeriesRequest {
    /// Every range check, the same for every front-end; each refusal names the parameter. (The
    /// generator's own checks, such as at least 8 × 8 pixels and a contact that fits the field,
    /// follow in [`run`].)
    pub fn check(&self) -> Result<()> {
        Quantity::PixelSize.check(self.params.pixel_size_m, Param::PixelSize)?;
        check_loads(&self.params.forces_n, Param::Forces)
    }
}

/// The generated series.
#[derive(Debug, Clone, Serialize)]
pub struct SynthSeriesOutcome {
    /// Normal force of each image, N.
    #[serde(rename = "forces_mN", serialize_with = "lab::each_n_as_mn")]
    pub forces_n: Vec<f64>,
    /// True contact area of each image, µm² (true contact pixels × pixel area).
    #[serde(rename = "true_area_um2", serialize_with = "lab::each_um2")]
    pub true_area_um2: Vec<f64>,
    /// True contact pixels of each image.
    pub true_contact_pixels: Vec<u64>,
    /// The images (12-bit codes) and their true contact masks, row-major.
    #[serde(skip)]
    pub images: Vec<SynthImage>,
}

/// Run `synth-series` in memory: check and generate. Nothing is written.
pub fn run(request: &SynthSeriesRequest) -> Result<SynthSeriesOutcome> {
    request.check()?;
    let images = generate(&request.params)?;
    Ok(SynthSeriesOutcome {
        forces_n: images.iter().map(|i| i.force_n).collect(),
        true_area_um2: images.iter().map(|i| i.true_area_um2).collect(),
        true_contact_pixels: images.iter().map(|i| i.true_contact_pixels).collect(),
        images,
    })
}
