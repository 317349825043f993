//! A row that names a height map, E* and R gets `fit-hardening` on its measured areas: the fit's
//! folder is the one its recorded command writes, and the series table carries k and p_Y with
//! their standard errors (the other rows leave those cells empty).

use serde_json::Value;

use super::{batch_ok, cells, counts, csv, files, synth};
use crate::common::{rough_surface, run_in, stderr};

#[test]
fn rows_with_a_height_map_get_k_and_p_y() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    synth(dir, "s1", 1, &[]);
    synth(dir, "s2", 2, &[]);
    // A 32 µm rough map: the contact of a 290 µm sphere at 8 mN stays well inside it.
    rough_surface(&dir.join("rough.npy"), 128, "250nm", 5, &[]);
    std::fs::write(
        dir.join("sheet.csv"),
        "id,input,topography,topography_pixel_size,radius_um,modulus,models,pixel_size_uncertainty\n\
         s1,s1,rough.npy,250nm,290,3.7GPa,\"hardness,hardening\",1%\n\
         s2,s2,,,,,,\n",
    )
    .unwrap();
    let stdout = batch_ok(dir, &["--samplesheet", "sheet.csv", "--out", "results"]);
    assert_eq!(counts(&stdout), (2, 0), "{stdout}");
    let results = dir.join("results");

    // The fit folder is what its recorded command writes.
    let fit_dir = results.join("fit/s1");
    let before = files(&fit_dir);
    let fit: Value = serde_json::from_slice(&before["fit.json"]).unwrap();
    let line: Vec<&str> = fit["command_line"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(
        line[1..].join(" "),
        "fit-hardening --areas results/series/s1/areas.csv --topography rough.npy \
         --radius 290um --modulus 3.7GPa --pixel-size 250nm --models hardness,hardening \
         --out results/fit/s1"
    );
    let o = run_in(dir, &line[1..]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(files(&fit_dir), before);
    assert!(!results.join("fit/s2").exists());

    // k and p_Y with their standard errors, as fit.json has them.
    let series = csv(&results.join("series.csv"));
    let k = cells(&series, "k_MPa_per_nm");
    let p = cells(&series, "hardness_MPa");
    assert_eq!((k[1].as_str(), p[1].as_str()), ("", ""));
    let models = fit["models"].as_array().unwrap();
    let model = |name: &str| models.iter().find(|m| m["model"] == name).unwrap();
    assert_eq!(
        k[0].parse::<f64>().unwrap(),
        model("hardening")["k_MPa_per_nm"].as_f64().unwrap()
    );
    let se = cells(&series, "k_se_MPa_per_nm");
    match model("hardening")["k_MPa_per_nm_se"].as_f64() {
        Some(v) => assert!((se[0].parse::<f64>().unwrap() - v).abs() <= 1e-12 * v.abs()),
        None => assert_eq!(se[0], ""),
    }
    // The 95 % intervals as fit.json has them; the row's pixel-size uncertainty reached the fit.
    for (column, end) in [("k_MPa_per_nm_lo", 0), ("k_MPa_per_nm_hi", 1)] {
        let cell = &cells(&series, column)[0];
        match model("hardening")["k_MPa_per_nm_ci95"][end].as_f64() {
            Some(v) => assert!((cell.parse::<f64>().unwrap() - v).abs() <= 1e-12 * v.abs()),
            None => assert_eq!(cell, ""),
        }
    }
    assert_eq!(fit["measured"]["pixel_size_uncertainty_pct"], 1.0);
    assert_eq!(cells(&series, "pixel_size_uncertainty_pct"), ["1", "0"]);
    let hardness = model("hardness")["hardness_MPa"].as_f64().unwrap();
    assert!((p[0].parse::<f64>().unwrap() - hardness).abs() <= 1e-12 * hardness);
    assert_eq!(cells(&series, "fit_folder"), ["fit/s1", ""]);
    assert_eq!(
        cells(&series, "best_model")[0],
        fit["best_model"].as_str().unwrap()
    );
    // R and E* also give analyze's Hertz columns for that series.
    let images = csv(&results.join("images.csv"));
    let hertz = cells(&images, "hertz_area_um2");
    assert!(hertz[..4].iter().all(|h| !h.is_empty()) && hertz[4..].iter().all(|h| h.is_empty()));

    // A fit option without a height map is refused before anything runs.
    std::fs::write(dir.join("bad.csv"), "id,input,models\ns1,s1,hardening\n").unwrap();
    let o = super::batch(dir, &["--samplesheet", "bad.csv", "--out", "other"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("column models"), "{}", stderr(&o));
}
