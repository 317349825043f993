//! The numerics taken from crates or kept (issue 11 item 4), timed through the public API so the
//! same bench runs on either implementation (`harness = false`, criterion):
//!
//! | name | what |
//! |---|---|
//! | `special/gt_f0` | F₀(t) = ½·erfc(t/√2) at 1000 points, t ∈ [−6, 9] (erfc) |
//! | `special/ring_kernel_antiderivative` | S(ξ) at 1000 points, ξ ∈ (0, 4] (complete elliptic K, E) |
//! | `gt/kernel256` | [`RadialKernel::uniform`] on 256 points (O(n²) evaluations of S) |
//! | `gt/profile` | [`gt_profile`] of Weber et al.'s sphere at 4 mN (kernel, load search, Newton with dense solves) |
//! | `psf/measure` | [`measure_psf`] on nine 128² planes with six beads (Levenberg–Marquardt fits) |
//! | `squeeze/offset_fit` | [`fit_hertz_with_offset`] on 40 points (grid + golden section) |
//! | `npy/read1024` | [`read_npy`] of a 1024² float64 file (page cache warm) |
//!
//! Run with `cargo bench --bench numerics`; see `docs/performance.md`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};

use contactscope::mechanics::hertz;
use contactscope::mechanics::squeeze::{fit_hertz_with_offset, SqueezePoint};
use contactscope::optics::psf::{measure_psf, PsfOptions};
use contactscope::solver::gt::{
    gt_f, gt_profile, ring_kernel_antiderivative, GtParams, RadialKernel,
};
use contactscope::surface::generate::{self_affine, RmsTarget, SelfAffineParams};
use contactscope::synth::beads::{synth_beads, BeadParams};
use contactscope_formats::tiff::{encode_u16_stack, read_pages};
use contactscope_formats::topography::read_npy;
use contactscope_jobs::heights::write_npy;

fn special(c: &mut Criterion) {
    let mut g = c.benchmark_group("special");
    g.sample_size(20).measurement_time(Duration::from_secs(2));
    let t: Vec<f64> = (0..1000).map(|i| -6.0 + 15.0 * i as f64 / 999.0).collect();
    g.bench_function("gt_f0", |b| {
        b.iter(|| t.iter().map(|&t| gt_f(0.0, black_box(t))).sum::<f64>())
    });
    let xi: Vec<f64> = (1..=1000).map(|i| 4.0 * i as f64 / 1000.0).collect();
    g.bench_function("ring_kernel_antiderivative", |b| {
        b.iter(|| {
            xi.iter()
                .map(|&x| ring_kernel_antiderivative(black_box(x)))
                .sum::<f64>()
        })
    });
    g.finish();
}

fn gt(c: &mut Criterion) {
    let mut g = c.benchmark_group("gt");
    g.sample_size(10).measurement_time(Duration::from_secs(4));
    g.bench_function("kernel256", |b| {
        b.iter(|| RadialKernel::uniform(black_box(8.0), 256).expect("kernel"))
    });
    let params = GtParams::new(290e-6, 3.7e9, 50e-9, 1e6);
    g.bench_function("profile", |b| {
        b.iter(|| gt_profile(&params, black_box(4e-3)).expect("profile"))
    });
    g.finish();
}

fn psf(c: &mut Criterion) {
    let beads = synth_beads(&BeadParams {
        planes: 9,
        ..BeadParams::default()
    })
    .expect("beads");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("beads.tif");
    let pages: Vec<&[u16]> = beads.planes.iter().map(Vec::as_slice).collect();
    let tiff = encode_u16_stack(
        &pages,
        beads.width,
        beads.height,
        Some((100e-9, 100e-9)),
        "",
    )
    .expect("tiff");
    std::fs::write(&path, tiff).expect("write");
    let images = read_pages(&path, None, None).expect("read");
    let mut g = c.benchmark_group("psf");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    g.bench_function("measure", |b| {
        b.iter(|| measure_psf(black_box(&images), &PsfOptions::default()).expect("psf"))
    });
    g.finish();
}

fn squeeze(c: &mut Criterion) {
    let (r, e_star) = (290e-6, 3.7e9);
    let points: Vec<SqueezePoint> = (1..=40)
        .map(|i| {
            let p = 1e-3 * i as f64;
            let wobble = 1.0 + 0.002 * ((i * 7919) % 13) as f64 / 13.0;
            SqueezePoint {
                force_n: p,
                displacement_m: 2.0 * (hertz::approach(p, r, e_star) * wobble + 20e-9),
                line: 0,
            }
        })
        .collect();
    let mut g = c.benchmark_group("squeeze");
    g.sample_size(20).measurement_time(Duration::from_secs(2));
    g.bench_function("offset_fit", |b| {
        b.iter(|| fit_hertz_with_offset(black_box(&points), r).expect("fit"))
    });
    g.finish();
}

fn npy(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("surface.npy");
    let topography = self_affine(&SelfAffineParams {
        nx: 1024,
        ny: 1024,
        dx_m: 32e-9,
        hurst: 0.8,
        rolloff_wavelength_m: None,
        short_cutoff_wavelength_m: None,
        target: RmsTarget::Slope(0.1),
        seed: 2018,
    })
    .expect("surface");
    write_npy(&path, &topography).expect("write");
    let mut g = c.benchmark_group("npy");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.bench_function("read1024", |b| {
        b.iter(|| read_npy(black_box(&path), Some((32e-9, 32e-9)), None).expect("read"))
    });
    g.finish();
}

criterion_group!(benches, special, gt, psf, squeeze, npy);
criterion_main!(benches);
