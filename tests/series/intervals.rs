//! The per-image area intervals of `analyze` against the generator's truth, through the command
//! line: a smaller version of `cargo bench --bench intervals` (`docs/validation.md` B25).

use crate::common::{column, read_csv, run_ok};

#[test]
fn area_intervals_hold_the_true_area_of_synthetic_series() {
    let tmp = tempfile::tempdir().unwrap();
    let (mut covered, mut total, mut beta_covered) = (0usize, 0usize, 0usize);
    let mut widths = Vec::new();
    for seed in ["3", "5", "8"] {
        let series = tmp.path().join(format!("s{seed}"));
        let out = tmp.path().join(format!("a{seed}"));
        let s = |p: &std::path::Path| p.to_str().unwrap().to_string();
        run_ok(&["synth-series", "--seed", seed, "--out", &s(&series)]);
        run_ok(&["analyze", &s(&series), "--out", &s(&out), "-q"]);
        let (h, r) = read_csv(&out.join("areas.csv"));
        let (area, lo, hi) = (
            column(&h, &r, "area_um2"),
            column(&h, &r, "area_um2_lo"),
            column(&h, &r, "area_um2_hi"),
        );
        let (th, tr) = read_csv(&series.join("truth.csv"));
        let truth = column(&th, &tr, "true_area_um2");
        assert_eq!(truth.len(), area.len());
        for i in 0..area.len() {
            assert!(
                lo[i] <= area[i] && area[i] <= hi[i],
                "the interval holds the measurement"
            );
            total += 1;
            // The truth file rounds to 1e-6 µm².
            if lo[i] <= truth[i] + 1e-6 && truth[i] - 1e-6 <= hi[i] {
                covered += 1;
            }
            widths.push((hi[i] - lo[i]) / truth[i]);
        }
        // The pressures' interval is the force over the areas' ends.
        let (f, p_lo, p_hi) = (
            column(&h, &r, "force_mN"),
            column(&h, &r, "mean_pressure_MPa_lo"),
            column(&h, &r, "mean_pressure_MPa_hi"),
        );
        for i in 0..f.len() {
            assert!((p_lo[i] - f[i] / hi[i] * 1e3).abs() < 1e-9 * p_lo[i]);
            assert!((p_hi[i] - f[i] / lo[i] * 1e3).abs() < 1e-9 * p_hi[i]);
        }
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(summary["area_interval"]["level_pct"], 95.0);
        assert_eq!(summary["area_interval"]["band_half_width"], 0.05);
        // The exponent's bootstrap interval against the exponent of the true areas.
        let law = &summary["fits"]["power_law"];
        let ci: Vec<f64> = law["exponent_ci95"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(ci[0] < ci[1] && ci[1] - ci[0] < 0.1, "{ci:?}");
        let (n, a): (Vec<f64>, Vec<f64>) = column(&th, &tr, "force_mN")
            .into_iter()
            .zip(truth.iter().copied())
            .map(|(f, a)| (f.ln(), a.ln()))
            .unzip();
        let (mn, ma) = (n.iter().sum::<f64>() / 8.0, a.iter().sum::<f64>() / 8.0);
        let true_beta = n
            .iter()
            .zip(&a)
            .map(|(x, y)| (x - mn) * (y - ma))
            .sum::<f64>()
            / n.iter().map(|x| (x - mn).powi(2)).sum::<f64>();
        if ci[0] <= true_beta && true_beta <= ci[1] {
            beta_covered += 1;
        }
        let p = &summary["fits"]["proportional"]["pressure_MPa_ci95"];
        assert!(p[0].as_f64().unwrap() < p[1].as_f64().unwrap());
    }
    widths.sort_by(f64::total_cmp);
    let median_width = widths[widths.len() / 2];
    assert_eq!(total, 24);
    assert!(
        covered * 10 >= total * 9,
        "{covered} of {total} intervals hold the truth"
    );
    assert!(median_width <= 0.10, "median relative width {median_width}");
    assert!(
        beta_covered >= 2,
        "the true exponent in {beta_covered} of 3 intervals"
    );
}
