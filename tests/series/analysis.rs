//! The streaming analysis: results do not depend on the memory budget, the layout or the
//! parallel split; float data and per-image thresholds behave as documented.

use std::io::Cursor;
use std::path::Path;

use contactscope::analysis::Analysis;
use contactscope::synth::{self, SynthParams};
use contactscope::threshold::Method;
use contactscope_formats::tiff::write::{encode_u16_stack_compressed, Compression};
use contactscope_jobs::analyze::AnalyzeRequest;
use contactscope_jobs::series::{Micrographs, SeriesSpec, DEFAULT_MEMORY_BUDGET};
use tiff::encoder::{colortype, TiffEncoder};

fn params() -> SynthParams {
    SynthParams {
        width: 128,
        height: 96,
        forces_n: (0..9).map(|i| 4e-3 * 1.3f64.powi(i)).collect(),
        ..SynthParams::default()
    }
}

/// Write the pages as one Deflate-compressed multi-page TIFF (no calibration).
fn write_deflate(path: &Path, pages: &[Vec<u16>], width: usize, height: usize) {
    let pages: Vec<&[u16]> = pages.iter().map(Vec::as_slice).collect();
    let bytes =
        encode_u16_stack_compressed(&pages, width, height, None, "", Compression::Deflate).unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// The analysis of `analyze` on the files, with `method` and a memory budget.
fn run(paths: &[std::path::PathBuf], method: Method, memory_budget: usize) -> Analysis {
    let request = AnalyzeRequest {
        method,
        memory_budget,
        ..AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
            inputs: paths.to_vec(),
            ..SeriesSpec::default()
        }))
    };
    contactscope_jobs::analyze::run(&request, &|_, _, _| {}, &|_, _, _| Ok(()))
        .unwrap()
        .analysis
}

fn pixels(a: &Analysis) -> Vec<(u64, u64, u64)> {
    a.images
        .iter()
        .map(|r| {
            let m = &r.measurement;
            (m.contact_pixels, m.patches, m.largest_patch_pixels)
        })
        .collect()
}

#[test]
fn results_do_not_depend_on_cache_or_layout() {
    let p = params();
    let images = synth::generate(&p).unwrap();
    let pages: Vec<Vec<u16>> = images.iter().map(|i| i.codes.clone()).collect();
    let dir = tempfile::tempdir().unwrap();
    let stack = dir.path().join("stack.tif");
    write_deflate(&stack, &pages, p.width, p.height);
    let mut singles = Vec::new();
    for (i, page) in pages.iter().enumerate() {
        let path = dir.path().join(format!("img{i}.tif"));
        write_deflate(&path, std::slice::from_ref(page), p.width, p.height);
        singles.push(path);
    }
    let cached = run(
        std::slice::from_ref(&stack),
        Method::GlobalOtsu,
        DEFAULT_MEMORY_BUDGET,
    );
    let uncached = run(std::slice::from_ref(&stack), Method::GlobalOtsu, 0);
    let tiny_cache = run(
        std::slice::from_ref(&stack),
        Method::GlobalOtsu,
        3 * p.width * p.height * 2,
    );
    let files = run(&singles, Method::GlobalOtsu, DEFAULT_MEMORY_BUDGET);
    assert_eq!(pixels(&cached), pixels(&uncached));
    assert_eq!(pixels(&cached), pixels(&tiny_cache));
    assert_eq!(pixels(&cached), pixels(&files));
    assert_eq!(cached.series_threshold, files.series_threshold);
    // Every image got its own result, in input order: areas grow with load.
    let areas: Vec<u64> = pixels(&cached).iter().map(|p| p.0).collect();
    assert!(areas.windows(2).all(|w| w[1] > w[0]), "{areas:?}");
}

#[test]
fn float_data_threshold_and_per_image_method() {
    let p = params();
    let images = synth::generate(&p).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("float.tif");
    let mut bytes = Cursor::new(Vec::new());
    {
        let mut enc = TiffEncoder::new(&mut bytes).unwrap();
        for im in &images {
            let mut v: Vec<f32> = im.codes.iter().map(|&c| f32::from(c) / 4095.0).collect();
            v[0] = f32::NAN;
            enc.write_image::<colortype::Gray32Float>(p.width as u32, p.height as u32, &v)
                .unwrap();
        }
    }
    std::fs::write(&path, bytes.into_inner()).unwrap();
    let float = run(
        std::slice::from_ref(&path),
        Method::GlobalOtsu,
        DEFAULT_MEMORY_BUDGET,
    );
    assert!(
        float.warnings.iter().any(|w| w.contains("NaN")),
        "{:?}",
        float.warnings
    );
    assert_eq!(
        float.histogram_pixels as usize,
        images.len() * (p.width * p.height - 1)
    );
    // The same data as integers: 4096 float bins over the range resolve the same split to
    // within a bin, so contact counts agree closely.
    let ints: Vec<Vec<u16>> = images.iter().map(|i| i.codes.clone()).collect();
    let int_path = dir.path().join("int.tif");
    write_deflate(&int_path, &ints, p.width, p.height);
    let int = run(
        std::slice::from_ref(&int_path),
        Method::GlobalOtsu,
        DEFAULT_MEMORY_BUDGET,
    );
    for (f, i) in float.images.iter().zip(&int.images) {
        let (a, b) = (
            f.measurement.contact_pixels as f64,
            i.measurement.contact_pixels as f64,
        );
        assert!((a - b).abs() <= 0.01 * b + 2.0, "float {a} vs int {b}");
    }
    let per_image = run(
        std::slice::from_ref(&path),
        Method::PerImageOtsu,
        DEFAULT_MEMORY_BUDGET,
    );
    assert!(per_image.series_threshold.is_none());
    let t: Vec<f64> = per_image.images.iter().map(|r| r.threshold.value).collect();
    assert!(t.iter().any(|v| (v - t[0]).abs() > 1e-6), "{t:?}");
}
