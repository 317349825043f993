//! The outputs of `synth-series` as the command line writes them, through a staging folder
//! (nothing appears unless everything succeeded): the TIFF(s), `manifest.csv` (file, page,
//! force_mN) and `truth.csv` (true contact pixels and area per image); and [`read_truth`] to read
//! the truth back.

use std::path::{Path, PathBuf};

use contactscope::synth::series::SynthParams;
use contactscope_formats::tiff::write::{encode_u16_stack_compressed, Compression};

use super::{run, SynthSeriesOutcome, SynthSeriesRequest};
use crate::error::{Error, Result};
use crate::staging::Staging;

/// How a generated series is laid out on disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// One multi-page TIFF `series.tif`.
    MultiPage,
    /// One file per load, `load_01.tif`, `load_02.tif`, …
    Files,
}

/// Run `synth-series` and write its folder: the outcome and the files written (final paths, in
/// order: the TIFF(s), `manifest.csv`, `truth.csv`).
pub fn run_to_folder(
    request: &SynthSeriesRequest,
    out_dir: &Path,
    layout: Layout,
    compression: Compression,
) -> Result<(SynthSeriesOutcome, Vec<PathBuf>)> {
    let outcome = run(request)?;
    let p = &request.params;
    let staging = Staging::new(out_dir, &[])?;
    let size = Some((p.pixel_size_m, p.pixel_size_m));
    let description = format!(
        "contactscope synth-series seed={} fwhm_nm={:.0}\n",
        p.seed,
        p.psf_fwhm_m * 1e9
    );
    let encode = |pages: &[&[u16]]| {
        encode_u16_stack_compressed(pages, p.width, p.height, size, &description, compression)
    };
    let images = &outcome.images;
    let mut locations = Vec::new();
    match layout {
        Layout::MultiPage => {
            let pages: Vec<&[u16]> = images.iter().map(|im| im.codes.as_slice()).collect();
            staging.write("series.tif", &encode(&pages)?)?;
            locations.extend((0..images.len()).map(|i| ("series.tif".to_string(), i)));
        }
        Layout::Files => {
            let digits = images.len().to_string().len().max(2);
            for (i, im) in images.iter().enumerate() {
                let name = format!("load_{:0digits$}.tif", i + 1);
                staging.write(&name, &encode(&[&im.codes])?)?;
                locations.push((name, 0));
            }
        }
    }
    let mut manifest = String::from("file,page,force_mN\n");
    let mut truth = String::from("file,page,force_mN,true_contact_pixels,true_area_um2\n");
    for ((file, page), im) in locations.iter().zip(images) {
        let force_mn = im.force_n * 1e3;
        manifest.push_str(&format!("{file},{page},{force_mn}\n"));
        truth.push_str(&format!(
            "{file},{page},{force_mn},{},{:.6}\n",
            im.true_contact_pixels, im.true_area_um2
        ));
    }
    staging.write("manifest.csv", manifest.as_bytes())?;
    staging.write("truth.csv", truth.as_bytes())?;
    let written = staging.commit()?;
    Ok((outcome, written))
}

/// Write a generated series into `dir`: the TIFF(s), `manifest.csv` (file, page, force_mN) and
/// `truth.csv` (true contact pixels and area per image). Returns the files written.
pub fn write_series(p: &SynthParams, dir: &Path, layout: Layout) -> Result<Vec<PathBuf>> {
    write_series_compressed(p, dir, layout, Compression::None)
}

/// [`write_series`] with a choice of TIFF compression.
pub fn write_series_compressed(
    p: &SynthParams,
    dir: &Path,
    layout: Layout,
    compression: Compression,
) -> Result<Vec<PathBuf>> {
    let request = SynthSeriesRequest { params: p.clone() };
    Ok(run_to_folder(&request, dir, layout, compression)?.1)
}

/// True areas (µm²) from a `truth.csv` written by [`write_series`], in row order.
pub fn read_truth(path: &Path) -> Result<Vec<f64>> {
    crate::staging::note_input(path);
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let bad = |reason: String| Error::bad_input(crate::error::Location::file(path), reason);
    let column = reader
        .headers()
        .map_err(|e| bad(e.to_string()))?
        .iter()
        .position(|h| h == "true_area_um2")
        .ok_or_else(|| bad("no column true_area_um2".into()))?;
    reader
        .records()
        .map(|r| {
            let r = r.map_err(|e| bad(e.to_string()))?;
            r.get(column)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| bad("true_area_um2 is not a number".into()))
        })
        .collect()
}
