//! Vendor formats in the fuzz campaign (issue 14: "broken and truncated files of each new format
//! give one clean error"). A CZI load series is made fresh by the test writer in
//! `tests/common/czi.rs`; the real samples of every other format (CZI, ND2, LIF, and the AFM and
//! profilometer formats) are copied from `../shared/data` when it sits beside the checkout, and
//! their templates are left out of the campaign (with a message) when it does not. The samples
//! are only read into a temporary folder, never copied into the repository.

use std::fs;
use std::path::{Path, PathBuf};

use super::cases::Template;
use crate::common::czi::{czi, Tile};

/// A 48×40 CZI with three time points (one load each): a bright disc that grows with t on a
/// dark background, 12-bit values in Gray16, no metadata (so `--pixel-size` is needed).
fn czi_series(dir: &Path) {
    let (w, h) = (48i32, 40i32);
    let tiles: Vec<Tile> = (0..3)
        .map(|t| {
            let r = 6.0 + 4.0 * t as f64;
            let values = (0..w * h)
                .map(|k| {
                    let (x, y) = ((k % w) as f64 - 23.5, (k / w) as f64 - 19.5);
                    let inside = x * x + y * y < r * r;
                    (if inside { 2400 } else { 300 }) + ((k * 37) % 97) as u16
                })
                .collect();
            Tile {
                s: 0,
                t,
                z: 0,
                c: 0,
                m: 0,
                x: 0,
                y: 0,
                w,
                h,
                values,
            }
        })
        .collect();
    fs::create_dir_all(dir.join("vendor")).unwrap();
    fs::write(dir.join("vendor/t.czi"), czi(&tiles)).unwrap();
}

/// The real samples used as seeds: (folder under `../shared/data`, file name).
const REAL: &[(&str, &str)] = &[
    ("real-formats/czi", "newCZI_compressed.czi"),
    ("real-formats/nd2", "cluster.nd2"),
    ("real-formats/lif", "LeicaLASX_wavelength-sweep_example.lif"),
    ("real-formats/sdf", "sdf-1.sdf"),
    ("real-formats/gwy", "test.gwy"),
    ("real-formats/frt", "frt-2.frt"),
    ("real-formats/mi", "mi-1.mi"),
    ("real-formats/sur", "sur-2.sur"),
    ("real-formats/nid", "nid-1.nid"),
    ("real-formats/ibw", "spot_1-1000nm.ibw"),
    ("real-formats/plu", "plu-1.plu"),
    ("real-formats/x3p", "x3p-2.x3p"),
    ("real-formats/opd", "opd-1.opd"),
    ("real-formats/park-tiff", "example_ps.tiff"),
    ("real-afm", "di-3.di"),
    ("real-afm", "top-1.top"),
];

/// SurfaceTopography's reader test files committed as fixtures (`fixtures/surface-topography`;
/// binary ones stored gzip-compressed), used as seeds whatever is beside the checkout.
const PEER: &[&str] = &[
    "al3d-1.al3d",
    "tmd-1.tmd",
    "stp-1.stp",
    "metropro-1.dat",
    "nms-1.nms",
    "di-2.di",
    "nc-1.nc",
    "opdx-3.opdx",
    "matrix-4.txt.gz",
    "gwyddion-export-german.txt",
    "xyz-2.txt",
];

fn shared_data() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/data")
}

/// The vendor seeds, in `dir`: the CZI series always, the real samples when present.
pub fn build(dir: &Path) {
    czi_series(dir);
    let peer = dir.join("peer");
    fs::create_dir_all(&peer).unwrap();
    let fixtures = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fixtures/surface-topography");
    for name in PEER {
        let plain = fixtures.join(name);
        let bytes = if plain.is_file() {
            fs::read(&plain).unwrap()
        } else {
            let mut out = Vec::new();
            let zipped = fs::File::open(fixtures.join(format!("{name}.gz"))).unwrap();
            std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(zipped), &mut out)
                .unwrap();
            out
        };
        fs::write(peer.join(name), bytes).unwrap();
    }
    let real = dir.join("real");
    fs::create_dir_all(&real).unwrap();
    let mut missing = 0;
    for (folder, name) in REAL {
        let from = shared_data().join(folder).join(name);
        if from.is_file() {
            fs::copy(&from, real.join(name)).unwrap();
        } else {
            missing += 1;
        }
    }
    if missing > 0 {
        eprintln!(
            "fuzz: {missing} real vendor samples not found under {} (their templates are skipped)",
            shared_data().display()
        );
    }
}

macro_rules! info {
    ($name:expr, $file:expr) => {
        Template {
            name: $name,
            copies: &[$file],
            mutable: &[$file],
            args: &["info", $file, "--json", "--stats"],
        }
    };
}

macro_rules! topo {
    ($name:expr, $file:expr) => {
        Template {
            name: $name,
            copies: &[$file],
            mutable: &[$file],
            args: &["topography", $file, "--json"],
        }
    };
}

/// Templates over the vendor seeds.
pub const TEMPLATES: &[Template] = &[
    Template {
        name: "czi-analyze",
        copies: &["vendor"],
        mutable: &["vendor/t.czi"],
        args: &[
            "analyze",
            "vendor/t.czi",
            "--load-axis",
            "t",
            "--forces",
            "1,2,4mN",
            "--pixel-size",
            "200nm",
            "--out",
            "OUT",
            "-q",
        ],
    },
    info!("czi-info", "vendor/t.czi"),
    info!("real-czi-info", "real/newCZI_compressed.czi"),
    info!("real-nd2-info", "real/cluster.nd2"),
    info!(
        "real-lif-info",
        "real/LeicaLASX_wavelength-sweep_example.lif"
    ),
    topo!("real-sdf", "real/sdf-1.sdf"),
    topo!("real-gwy", "real/test.gwy"),
    topo!("real-frt", "real/frt-2.frt"),
    topo!("real-mi", "real/mi-1.mi"),
    topo!("real-sur", "real/sur-2.sur"),
    topo!("real-nid", "real/nid-1.nid"),
    topo!("real-ibw", "real/spot_1-1000nm.ibw"),
    topo!("real-plu", "real/plu-1.plu"),
    topo!("real-x3p", "real/x3p-2.x3p"),
    topo!("real-opd", "real/opd-1.opd"),
    topo!("real-park-tiff", "real/example_ps.tiff"),
    topo!("real-di", "real/di-3.di"),
    topo!("real-top", "real/top-1.top"),
    topo!("peer-al3d", "peer/al3d-1.al3d"),
    topo!("peer-tmd", "peer/tmd-1.tmd"),
    topo!("peer-stp", "peer/stp-1.stp"),
    topo!("peer-metropro", "peer/metropro-1.dat"),
    topo!("peer-nms", "peer/nms-1.nms"),
    topo!("peer-di", "peer/di-2.di"),
    topo!("peer-nc", "peer/nc-1.nc"),
    topo!("peer-opdx", "peer/opdx-3.opdx"),
    topo!("peer-gz", "peer/matrix-4.txt.gz"),
    topo!("peer-gwyddion-text", "peer/gwyddion-export-german.txt"),
    topo!("peer-xyz", "peer/xyz-2.txt"),
];

#[test]
fn every_peer_template_names_a_listed_fixture() {
    for t in TEMPLATES.iter().filter(|t| t.name.starts_with("peer-")) {
        let file = t.copies[0].trim_start_matches("peer/");
        assert!(PEER.contains(&file), "{}", t.name);
    }
}

#[test]
fn every_real_template_names_a_listed_sample() {
    for t in TEMPLATES.iter().filter(|t| t.name.starts_with("real-")) {
        let file = t.copies[0].trim_start_matches("real/");
        assert!(REAL.iter().any(|(_, n)| *n == file), "{}", t.name);
    }
}
