//! Whole-series benchmark: a 40-image 1024×1024 16-bit synthetic load series (12-bit values),
//! analysed end to end (series assembly, forces, two-pass analysis with the global Otsu
//! threshold, all measurements, report, `areas.csv` in memory) in four on-disk layouts:
//!
//! | layout            | files                         |
//! |-------------------|-------------------------------|
//! | `files_raw`       | 40 single-page TIFFs, uncompressed |
//! | `multipage_raw`   | one 40-page TIFF, uncompressed |
//! | `files_lzw`       | 40 single-page TIFFs, LZW      |
//! | `multipage_lzw`   | one 40-page TIFF, LZW          |
//!
//! plus two variants with `memory_budget: 0` (no decoded planes kept between the two passes, so
//! both passes decode from disk), and a small `phases` group timing single-image stages
//! (decode, histogram, classify + measure, patch labelling) to show where the time goes.
//!
//! The data are generated once per run (fixed seed, the CLI's default 2018) into a temporary
//! folder with the same parameters as `benches/python/run_comparison.sh` uses through
//! `contactscope synth-series --size 1024 --forces <40 forces>`; set `CONTACTSCOPE_BENCH_DIR` to
//! keep them in a folder of your choice instead. Run with `cargo bench --bench series`; see
//! `docs/performance.md`.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};

use contactscope::analysis::light::light_budget;
use contactscope::measure::{measure, measure_with_tiles, patch_stats};
use contactscope::synth::{self, SynthParams};
use contactscope::threshold::{Binning, Histogram, Threshold};
use contactscope_formats::tiff::write::{encode_u16_stack_compressed, Compression};
use contactscope_formats::tiff::TiffReader;
use contactscope_formats::units::{self, Dimension};
use contactscope_jobs::analyze::files::areas_csv;
use contactscope_jobs::analyze::{run, AnalyzeRequest};
use contactscope_jobs::series::{Micrographs, SeriesSpec, DEFAULT_MEMORY_BUDGET};

const SIZE: usize = 1024;
const IMAGES: usize = 40;
const PIXEL_SIZE_M: f64 = 200e-9;
const SEED: u64 = 2018;

/// The 40 forces as the CLI receives them: log-spaced 4…400 mN, three decimals.
/// `benches/python/run_comparison.sh` builds the same string.
fn forces_text() -> String {
    let items: Vec<String> = (0..IMAGES)
        .map(|i| format!("{:.3}", 4.0 * 100f64.powf(i as f64 / (IMAGES - 1) as f64)))
        .collect();
    format!("{}mN", items.join(","))
}

/// Generated files, one folder per layout.
struct Data {
    _temp: Option<tempfile::TempDir>,
    forces_n: Vec<f64>,
    layouts: Vec<(&'static str, PathBuf)>,
    codes: Vec<Vec<u16>>,
}

impl Data {
    fn dir(&self, name: &str) -> &Path {
        &self
            .layouts
            .iter()
            .find(|(n, _)| *n == name)
            .expect("layout")
            .1
    }
}

fn write(path: &Path, bytes: &[u8]) -> u64 {
    std::fs::write(path, bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    bytes.len() as u64
}

fn generate() -> Data {
    let forces_n = units::parse_quantity_list(&forces_text(), Dimension::Force).expect("forces");
    let params = SynthParams {
        width: SIZE,
        height: SIZE,
        pixel_size_m: PIXEL_SIZE_M,
        forces_n: forces_n.clone(),
        seed: SEED,
        ..SynthParams::default()
    };
    let field_um2 = (SIZE * SIZE) as f64 * PIXEL_SIZE_M * PIXEL_SIZE_M * 1e12;
    let largest_um2 = params.true_area_m2(forces_n[IMAGES - 1]) * 1e12;
    assert!(
        largest_um2 < 0.3 * field_um2,
        "largest true contact {largest_um2:.0} µm² must stay inside the {field_um2:.0} µm² field"
    );
    let started = std::time::Instant::now();
    let images = synth::generate(&params).expect("synthetic series");
    eprintln!(
        "generated {IMAGES} × {SIZE}×{SIZE} images in {:.1} s; true area {:.0}…{largest_um2:.0} µm² \
         of a {field_um2:.0} µm² field",
        started.elapsed().as_secs_f64(),
        images[0].true_area_um2
    );
    let (temp, root) = match std::env::var_os("CONTACTSCOPE_BENCH_DIR") {
        Some(dir) => (None, PathBuf::from(dir)),
        None => {
            let t = tempfile::tempdir().expect("tempdir");
            let p = t.path().to_path_buf();
            (Some(t), p)
        }
    };
    let size = Some((PIXEL_SIZE_M, PIXEL_SIZE_M));
    let extra = format!("contactscope synth-series seed={SEED} fwhm_nm=450\n");
    let pages: Vec<&[u16]> = images.iter().map(|im| im.codes.as_slice()).collect();
    let mut layouts = Vec::new();
    for name in ["files_raw", "multipage_raw", "files_lzw", "multipage_lzw"] {
        let dir = root.join(name);
        std::fs::create_dir_all(&dir).expect("layout folder");
        let compression = if name.ends_with("lzw") {
            Compression::Lzw
        } else {
            Compression::None
        };
        let bytes: u64 = if name.starts_with("files") {
            pages
                .iter()
                .enumerate()
                .map(|(i, page)| {
                    let tiff =
                        encode_u16_stack_compressed(&[page], SIZE, SIZE, size, &extra, compression)
                            .expect("encode");
                    write(&dir.join(format!("load_{:02}.tif", i + 1)), &tiff)
                })
                .sum()
        } else {
            let tiff = encode_u16_stack_compressed(&pages, SIZE, SIZE, size, &extra, compression)
                .expect("encode");
            write(&dir.join("series.tif"), &tiff)
        };
        eprintln!(
            "{name:>14}: {:7.1} MB in {}",
            bytes as f64 / 1e6,
            dir.display()
        );
        layouts.push((name, dir));
    }
    Data {
        _temp: temp,
        forces_n,
        layouts,
        codes: images.into_iter().map(|im| im.codes).collect(),
    }
}

/// The whole job: series, forces, analysis, rows, areas.csv (in memory).
fn whole_job(dir: &Path, forces_n: &[f64], memory_budget: usize) -> (usize, Vec<u8>, f64, u64) {
    let request = AnalyzeRequest {
        memory_budget,
        ..AnalyzeRequest::new(Micrographs::Files(SeriesSpec {
            inputs: vec![dir.to_path_buf()],
            forces_n: Some(forces_n.to_vec()),
            ..SeriesSpec::default()
        }))
    };
    let outcome = run(&request, &|_, _, _| {}, &|_, _, _| Ok(())).expect("analysis");
    let csv = areas_csv(&outcome).expect("csv");
    let analysis = &outcome.analysis;
    let threshold = analysis.series_threshold.expect("global").value;
    let contact = analysis
        .images
        .iter()
        .map(|r| r.measurement.contact_pixels)
        .sum();
    (outcome.rows.rows.len(), csv, threshold, contact)
}

fn series_benches(c: &mut Criterion) {
    let data = generate();
    for (name, dir) in &data.layouts {
        let (images, csv, t, contact) = whole_job(dir, &data.forces_n, DEFAULT_MEMORY_BUDGET);
        eprintln!(
            "{name:>14}: {images} images, threshold {t}, contact pixels {contact}, areas.csv {} bytes",
            csv.len()
        );
    }
    let mut group = c.benchmark_group("series_40x1024");
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .warm_up_time(Duration::from_secs(2))
        .measurement_time(Duration::from_secs(8));
    for (name, dir) in &data.layouts {
        group.bench_function(*name, |b| {
            b.iter(|| black_box(whole_job(dir, &data.forces_n, DEFAULT_MEMORY_BUDGET).1))
        });
    }
    for name in ["files_raw", "multipage_lzw"] {
        let dir = data.dir(name);
        group.bench_function(format!("{name}_budget0"), |b| {
            b.iter(|| black_box(whole_job(dir, &data.forces_n, 0).1))
        });
    }
    group.finish();

    // Single-image stages on the largest-contact image, to see what dominates.
    let mut group = c.benchmark_group("phases_1024");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    let last = IMAGES - 1;
    let raw = data
        .dir("files_raw")
        .join(format!("load_{:02}.tif", IMAGES));
    let lzw = data
        .dir("files_lzw")
        .join(format!("load_{:02}.tif", IMAGES));
    group.bench_function("open_and_decode_raw", |b| {
        b.iter(|| black_box(TiffReader::open(&raw).unwrap().read_page(0, 0).unwrap()))
    });
    group.bench_function("open_and_decode_lzw", |b| {
        b.iter(|| black_box(TiffReader::open(&lzw).unwrap().read_page(0, 0).unwrap()))
    });
    let plane = TiffReader::open(&raw).unwrap().read_page(0, 0).unwrap();
    assert_eq!(
        plane.samples,
        contactscope::image::Samples::Int {
            codes: data.codes[last].clone(),
            offset: 0
        },
        "decoded page equals the generated one"
    );
    group.bench_function("histogram", |b| {
        b.iter(|| {
            let mut h = Histogram::new(Binning::Integer { offset: 0 });
            h.add_plane(&plane).unwrap();
            black_box(h)
        })
    });
    let mut h = Histogram::new(Binning::Integer { offset: 0 });
    h.add_plane(&plane).unwrap();
    let t: Threshold = Threshold::otsu(&h, "bench").unwrap();
    group.bench_function("measure_with_patches", |b| {
        b.iter(|| black_box(measure(&plane, &t).unwrap()))
    });
    group.bench_function("measure_with_tiles", |b| {
        b.iter(|| black_box(measure_with_tiles(&plane, &t).unwrap()))
    });
    let (_, _, tiles) = measure_with_tiles(&plane, &t).unwrap();
    group.bench_function("light_budget", |b| {
        b.iter(|| black_box(light_budget(&plane, &tiles, 1.0)))
    });
    let (_, mask) = measure(&plane, &t).unwrap();
    group.bench_function("patch_stats_only", |b| {
        b.iter(|| black_box(patch_stats(&mask)))
    });
    group.finish();
}

criterion_group!(benches, series_benches);
criterion_main!(benches);
