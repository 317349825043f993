//! `contactscope autocorr`: known correlation lengths, a direct O(N²) reference, several images on
//! one plot, bad input.

use std::fs;
use std::path::{Path, PathBuf};

use crate::common::{column, read_csv, run, stderr};
use contactscope::optics::blur::isotropic_blur;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// White noise blurred by a Gaussian of `sigma_px`, as a 12-bit-range u16 TIFF.
fn blurred_noise(dir: &Path, name: &str, n: usize, sigma_px: f64, pixel_m: f64) -> PathBuf {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(n as u64 + sigma_px as u64);
    let noise: Vec<f64> = (0..n * n)
        .map(|_| StandardNormal.sample(&mut rng))
        .collect();
    let field = isotropic_blur(&noise, n, n, sigma_px);
    let sd = (field.iter().map(|v| v * v).sum::<f64>() / field.len() as f64).sqrt();
    let codes: Vec<u16> = field
        .iter()
        .map(|v| (2000.0 + 300.0 * v / sd).round().clamp(0.0, 4095.0) as u16)
        .collect();
    write_u16(dir, name, &codes, n, n, Some(pixel_m))
}

fn write_u16(
    dir: &Path,
    name: &str,
    codes: &[u16],
    w: usize,
    h: usize,
    pixel_m: Option<f64>,
) -> PathBuf {
    let path = dir.join(name);
    let bytes = contactscope_formats::tiff::write::encode_u16_stack(
        &[codes],
        w,
        h,
        pixel_m.map(|p| (p, p)),
        "",
    )
    .unwrap();
    fs::write(&path, bytes).unwrap();
    path
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&fs::read_to_string(path).unwrap()).unwrap()
}

/// docs/validation.md B17 through the command: blurred noise has ξ_1/e = 2σ_g; two images with
/// different pixel sizes share one CSV, JSON and plot.
#[test]
fn known_correlation_lengths_of_two_images() {
    let dir = tempfile::tempdir().unwrap();
    let fine = blurred_noise(dir.path(), "fine.tif", 512, 4.0, 100e-9);
    let coarse = blurred_noise(dir.path(), "coarse.tif", 256, 3.0, 200e-9);
    let out = dir.path().join("acf");
    let o = run(&[
        "autocorr",
        s(&fine),
        s(&coarse),
        "--max-lag",
        "5um",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = json(&out.join("autocorr.json"));
    let images = summary["images"].as_array().unwrap();
    assert_eq!(images.len(), 2);
    for (image, expected_um) in images.iter().zip([0.8, 1.2]) {
        let xi = image["correlation_length_um_1e"].as_f64().unwrap();
        assert!(
            (xi / expected_um - 1.0).abs() < 0.04,
            "{}: ξ = {xi} µm, expected {expected_um}",
            image["image"]
        );
        // A Gaussian ACF never crosses zero in theory; C(2ξ) = e⁻⁴, so noise and
        // the subtracted sample mean may make it cross, but only in the tail.
        if let Some(zero) = image["first_zero_um"].as_f64() {
            assert!(zero > 1.5 * expected_um, "first zero {zero}");
        }
    }
    let (header, rows) = read_csv(&out.join("autocorr.csv"));
    assert_eq!(header, ["image", "lag_um", "acf"]);
    let labels: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert!(labels.contains(&"fine.tif") && labels.contains(&"coarse.tif"));
    let lags = column(&header, &rows, "lag_um");
    assert!(lags.iter().all(|&l| (0.0..=5.0 + 0.2).contains(&l)));
    let png = image::open(out.join("autocorr.png")).unwrap();
    assert_eq!((png.width(), png.height()), (900, 650));
}

/// The radially averaged curve in the CSV equals a direct O(N²) computation: mean-subtracted
/// products summed over all pixel pairs, binned by rounded distance, pair-weighted.
#[test]
fn csv_matches_a_direct_computation_on_a_small_image() {
    let (w, h) = (11, 8);
    let codes: Vec<u16> = (0..w * h)
        .map(|i| ((i * 7919) % 97 + (i % w) * 3) as u16)
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = write_u16(dir.path(), "small.tif", &codes, w, h, Some(1e-6));
    let out = dir.path().join("acf");
    let o = run(&["autocorr", s(&path), "--max-lag", "3um", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&out.join("autocorr.csv"));
    let acf = column(&header, &rows, "acf");

    let v: Vec<f64> = codes.iter().map(|&c| f64::from(c)).collect();
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let (wi, hi) = (w as i64, h as i64);
    let lag_sum = |lx: i64, ly: i64| {
        let (mut sum, mut n) = (0.0, 0.0);
        for y in 0..hi {
            for x in 0..wi {
                let (x2, y2) = (x + lx, y + ly);
                if (0..wi).contains(&x2) && (0..hi).contains(&y2) {
                    sum += (v[(y * wi + x) as usize] - mean) * (v[(y2 * wi + x2) as usize] - mean);
                    n += 1.0;
                }
            }
        }
        (sum / n, n)
    };
    let (c0, n0) = lag_sum(0, 0);
    let mut bins = vec![(0.0, 0.0); 4];
    for ly in -(hi - 1)..hi {
        for lx in -(wi - 1)..wi {
            let (c, n) = lag_sum(lx, ly);
            let bin = ((lx * lx + ly * ly) as f64).sqrt().round() as usize;
            if bin < bins.len() && n >= 0.25 * n0 {
                bins[bin].0 += n * c / c0;
                bins[bin].1 += n;
            }
        }
    }
    assert_eq!(acf.len(), 4);
    for (got, (sum, n)) in acf.iter().zip(bins) {
        assert!((got - sum / n).abs() < 1e-7, "{got} vs {}", sum / n);
    }
}

#[test]
fn bad_inputs_name_the_file_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("acf");
    let no_px = write_u16(dir.path(), "nopx.tif", &[1, 2, 3, 4], 2, 2, None);
    let o = run(&["autocorr", s(&no_px), "--out", s(&out)]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("nopx.tif") && stderr(&o).contains("--pixel-size"));

    let flat = write_u16(dir.path(), "flat.tif", &[7; 16], 4, 4, Some(2e-7));
    let o = run(&["autocorr", s(&flat), "--out", s(&out)]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("flat.tif"), "{}", stderr(&o));

    let o = run(&[
        "autocorr",
        s(&dir.path().join("missing.tif")),
        "--out",
        s(&out),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("missing.tif"));
    assert!(!out.exists(), "no output folder after a failure");
}
