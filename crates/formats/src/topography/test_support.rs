//! Checks shared by the readers' tests: statistics of a height map over its valid points, as the
//! reference table `tests/data/surface_topography_maps.csv` gives them, and the rule that a
//! truncated or corrupted file gives a result or an error, never a panic.

use std::path::Path;

use ndarray::Array2;

use crate::error::Result;

/// Minimum, maximum, mean and rms about the mean of the finite heights.
pub(crate) struct Stats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
    pub rms: f64,
}

/// [`Stats`] of the finite values of `h` (rms about their mean, as the reference table).
pub(crate) fn stats(h: &Array2<f64>) -> Stats {
    let valid: Vec<f64> = h.iter().copied().filter(|v| v.is_finite()).collect();
    let n = valid.len() as f64;
    let mean = valid.iter().sum::<f64>() / n;
    let rms = (valid.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
    Stats {
        min: valid.iter().copied().fold(f64::INFINITY, f64::min),
        max: valid.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        mean,
        rms,
    }
}

/// Asserts min, max and rms within a relative 1e-9 of the reference, the mean within 1e-9 of
/// the reference rms.
pub(crate) fn assert_stats(h: &Array2<f64>, [min, max, mean, rms]: [f64; 4]) {
    let s = stats(h);
    eprintln!(
        "min {:e} ({min:e}), max {:e} ({max:e}), mean {:e} ({mean:e}), rms {:e} ({rms:e})",
        s.min, s.max, s.mean, s.rms
    );
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * b.abs();
    assert!(close(s.min, min), "min {} vs {min}", s.min);
    assert!(close(s.max, max), "max {} vs {max}", s.max);
    assert!(close(s.rms, rms), "rms {} vs {rms}", s.rms);
    assert!(
        (s.mean - mean).abs() <= 1e-9 * rms,
        "mean {} vs {mean}",
        s.mean
    );
}

/// `a` within a relative 1e-9 of `b`.
pub(crate) fn assert_close(a: f64, b: f64) {
    assert!((a - b).abs() <= 1e-9 * b.abs(), "{a} vs {b}");
}

/// The file cut at 10 points gives an error naming it; its first 4 KiB with bytes flipped (a
/// few hundred patterns) give a result or an error, never a panic.
pub(crate) fn truncations_and_corruptions(
    path: &Path,
    data: &[u8],
    read: impl Fn(&[u8]) -> Result<()>,
) {
    let name = path.file_name().unwrap().to_string_lossy().to_string();
    for k in 0..10 {
        let cut = data.len() * k / 10 + k;
        let cut = cut.min(data.len() - 1);
        let err = read(&data[..cut])
            .expect_err(&format!("cut at {cut} of {}", data.len()))
            .to_string();
        assert!(err.contains(&name), "{err}");
    }
    let head = data.len().min(4096);
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    for trial in 0..300 {
        let mut d = data.to_vec();
        // One byte at each of the first offsets in turn, then random bytes, a few at a time.
        if trial < 128 {
            d[trial * head / 128] ^= 0xff;
        } else {
            for _ in 0..1 + trial % 8 {
                let r = next();
                d[(r % head as u64) as usize] ^= (r >> 32) as u8 | 1;
            }
        }
        let _ = read(&d);
    }
}

/// A sample file of SurfaceTopography's reader tests: from the folder named by
/// `CONTACTSCOPE_ST_EXAMPLES` when set, else from the committed `fixtures/surface-topography`
/// (a `.gz` copy decompressed once into a folder of the temporary directory that later runs
/// reuse). The path may not exist: callers skip.
pub(crate) fn sample(name: &str) -> std::path::PathBuf {
    use std::io::Read;
    if let Ok(dir) = std::env::var("CONTACTSCOPE_ST_EXAMPLES") {
        return Path::new(&dir).join(name);
    }
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/surface-topography");
    let plain = fixtures.join(name);
    if plain.exists() {
        return plain;
    }
    let out = std::env::temp_dir()
        .join("contactscope-test-samples")
        .join(name);
    if out.exists() {
        return out;
    }
    let Ok(file) = std::fs::File::open(fixtures.join(format!("{name}.gz"))) else {
        return plain;
    };
    let mut bytes = Vec::new();
    flate2::read::GzDecoder::new(file)
        .read_to_end(&mut bytes)
        .unwrap();
    let dir = out.parent().unwrap();
    std::fs::create_dir_all(dir).unwrap();
    // Written under a unique name and renamed: tests running at once may ask for the same file.
    let partial = dir.join(format!(
        "{name}.{}.{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    std::fs::write(&partial, bytes).unwrap();
    std::fs::rename(&partial, &out).unwrap();
    out
}
