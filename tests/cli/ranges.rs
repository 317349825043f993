//! Absurd physical numbers (issue 12, class 4) from the command line and from a manifest are
//! refused with one line naming the value, its source and the plausible range, before any work;
//! nothing is written.

use crate::common::{fixture_series, run, stderr};

fn refused(args: &[&str], needles: &[&str]) {
    let o = run(args);
    assert!(!o.status.success(), "{args:?} succeeded");
    let err = stderr(&o);
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' not in {err}");
    }
}

#[test]
fn absurd_numbers_are_refused_with_their_source() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let out = out.to_str().unwrap();
    let series = fixture_series().join("series.tif");
    let series = series.to_str().unwrap();
    let forces = "4,6,9,13,20,30,45,68mN";
    refused(
        &[
            "analyze",
            series,
            "--forces",
            "4,6,9,13,20,30,45,1e308mN",
            "--out",
            out,
        ],
        &["1e308mN", "force", "plausible range"],
    );
    refused(
        &[
            "analyze",
            series,
            "--forces",
            "1e-308mN,6,9,13,20,30,45,68mN",
            "--out",
            out,
        ],
        &["1e-308mN", "force"],
    );
    refused(
        &[
            "analyze",
            series,
            "--forces",
            forces,
            "--pixel-size",
            "1e-300nm",
            "--out",
            out,
        ],
        &["1e-300nm", "pixel size", "0.1"],
    );
    refused(
        &[
            "analyze",
            series,
            "--forces",
            forces,
            "--radius",
            "1e9m",
            "--modulus",
            "3.7GPa",
            "--out",
            out,
        ],
        &["--radius", "radius"],
    );
    // A manifest row with an absurd force names the file and line.
    let manifest = dir.path().join("manifest.csv");
    std::fs::copy(
        fixture_series().join("series.tif"),
        dir.path().join("series.tif"),
    )
    .unwrap();
    std::fs::write(
        &manifest,
        "file,page,force_mN\nseries.tif,0,4\nseries.tif,1,1e308\n",
    )
    .unwrap();
    refused(
        &[
            "analyze",
            "--manifest",
            manifest.to_str().unwrap(),
            "--out",
            out,
        ],
        &["manifest.csv:3", "force"],
    );
    assert!(!dir.path().join("out").exists(), "nothing written");
}
