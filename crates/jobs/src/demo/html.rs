//! The demo's report: `index.html` (self-contained page, figures as relative PNG links, no
//! server or script needed), `demo.json` with every number, and the figures made here (Fig. 2
//! panels, the autocorrelation comparison).

use std::fmt::Write as _;
use std::path::Path;

use serde_json::json;

use super::{DemoParams, Recovered, MICROGRAPH_OFFSET_PX};
use crate::autocorr::acf_chart;
use crate::error::{Error, Result};
use crate::plot::edge_panels_png;
use crate::staging::write_atomic;
use contactscope::compare::Comparison;
use contactscope::model_fit::{Family, ModelFit};
use contactscope::spectral::autocorrelation::AcfCurve;

/// Everything the report shows.
pub(super) struct Facts<'a> {
    pub params: &'a DemoParams,
    pub recovered: &'a [Recovered],
    pub comparisons: &'a [(String, Comparison)],
    pub measured: &'a [(f64, f64)],
    /// Each measured area's 95 % interval (lo, hi), m².
    pub measured_intervals: &'a [(f64, f64, f64)],
    pub truth_areas_m2: &'a [f64],
    pub fits: &'a [ModelFit],
}

/// contactscope's own methods (`docs/methods.md`), written beside the report it cites them in.
const METHODS: &str = include_str!("../../assets/methods.md");

pub(super) fn write_report(dir: &Path, facts: &Facts) -> Result<()> {
    let panels = write_panels(dir, facts)?;
    write_acf(dir, facts)?;
    let json = demo_json(facts);
    let text = serde_json::to_string_pretty(&json)
        .map_err(|e| Error::InvalidArgument(format!("JSON: {e}")))?;
    write_atomic(&dir.join("demo.json"), text.as_bytes())?;
    // The methods the report cites travel with it (the reader of the report has no checkout).
    write_atomic(&dir.join("methods.md"), METHODS.as_bytes())?;
    write_atomic(&dir.join("index.html"), page(facts, &panels).as_bytes())
}

/// One Fig. 2 panel per load: micrograph | GT | elastic | hardness | hardening, the
/// micrograph's contact edges in green on all, cropped to a square around the micrograph's
/// contact (so the patches of the lightest load are as visible as the disc of the heaviest) and
/// magnified to about 700 pixels. Returns the file names and the crop sides in micrograph pixels.
fn write_panels(dir: &Path, facts: &Facts) -> Result<Vec<(String, usize)>> {
    let Some((_, first)) = facts.comparisons.first() else {
        return Ok(Vec::new());
    };
    let mut names = Vec::new();
    for (i, prepared) in first.prepared.iter().enumerate() {
        let (w, h) = prepared.size();
        let mut panels: Vec<Vec<f64>> = vec![prepared.micrograph().to_vec()];
        for (_, c) in facts.comparisons {
            panels.push(c.prepared[i].simulated_on_scale(&c.loads[i]));
        }
        let mask = contact_mask(facts, i);
        let crop = Crop::around(&mask, w, h);
        let panels: Vec<Vec<f64>> = panels.iter().map(|p| crop.apply(p, w)).collect();
        let mask = crop.apply(&mask, w);
        let refs: Vec<&[f64]> = panels.iter().map(Vec::as_slice).collect();
        let scale = (700 / crop.side).clamp(1, 8);
        let png = edge_panels_png(&refs, crop.side, crop.side, &mask, scale)?;
        let name = format!("fig2_load_{:02}.png", i + 1);
        write_atomic(&dir.join(&name), &png)?;
        names.push((name, crop.side));
    }
    Ok(names)
}

/// A square window of an image.
struct Crop {
    x0: usize,
    y0: usize,
    side: usize,
}

impl Crop {
    /// The smallest square holding the true pixels of `mask` with a margin of a quarter of its
    /// side (at least 16 pixels), inside the `w × h` image; the whole image's square when the
    /// mask is empty.
    fn around(mask: &[bool], w: usize, h: usize) -> Crop {
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (usize::MAX, 0, usize::MAX, 0);
        for (k, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
            let (x, y) = (k % w, k / w);
            (x_lo, x_hi, y_lo, y_hi) = (x_lo.min(x), x_hi.max(x), y_lo.min(y), y_hi.max(y));
        }
        let most = w.min(h);
        if x_lo > x_hi {
            return Crop {
                x0: 0,
                y0: 0,
                side: most,
            };
        }
        let extent = (x_hi - x_lo).max(y_hi - y_lo) + 1;
        let side = (extent + 2 * (extent / 4).max(16)).min(most);
        let place = |lo: usize, hi: usize, n: usize| {
            let centre = (lo + hi) / 2;
            centre.saturating_sub(side / 2).min(n - side)
        };
        Crop {
            x0: place(x_lo, x_hi, w),
            y0: place(y_lo, y_hi, h),
            side,
        }
    }

    fn apply<T: Copy>(&self, image: &[T], w: usize) -> Vec<T> {
        (self.y0..self.y0 + self.side)
            .flat_map(|y| {
                image[y * w + self.x0..y * w + self.x0 + self.side]
                    .iter()
                    .copied()
            })
            .collect()
    }
}

/// The micrograph's contact pixels (above the series threshold) of load `i`.
fn contact_mask(facts: &Facts, i: usize) -> Vec<bool> {
    let (_, first) = &facts.comparisons[0];
    let t = first.experiment_threshold;
    first.prepared[i]
        .micrograph()
        .iter()
        .map(|&v| v > t)
        .collect()
}

fn write_acf(dir: &Path, facts: &Facts) -> Result<()> {
    let Some((_, first)) = facts.comparisons.first() else {
        return Ok(());
    };
    let last = first.prepared.len() - 1;
    let (w, h) = first.prepared[last].size();
    let px = (facts.params.image_pixel_m, facts.params.image_pixel_m);
    let max_lag = 0.5 * w.min(h) as f64 * px.0;
    let mut curves = vec![AcfCurve::of_grid(
        "micrograph",
        &first.prepared[last].micrograph_in_region(),
        (w, h),
        px,
        max_lag,
    )?];
    for (name, c) in facts.comparisons {
        let image = c.prepared[last].simulated_on_scale(&c.loads[last]);
        if let Ok(curve) = AcfCurve::of_grid(name, &image, (w, h), px, max_lag) {
            curves.push(curve);
        }
    }
    let chart = acf_chart(
        &curves,
        &format!(
            "Intensity autocorrelation at {:.3} mN",
            facts.params.loads_n[last] * 1e3
        ),
    );
    write_atomic(&dir.join("autocorrelation.png"), &chart.to_png()?)
}

fn demo_json(facts: &Facts) -> serde_json::Value {
    let p = facts.params;
    json!({
        "contactscope_version": env!("CARGO_PKG_VERSION"),
        "inputs": p,
        "recovered": facts.recovered,
        "true_shift_x_px": MICROGRAPH_OFFSET_PX.0,
        "true_shift_y_px": MICROGRAPH_OFFSET_PX.1,
        "areas": facts.measured.iter().zip(facts.measured_intervals).zip(facts.truth_areas_m2).map(|((&(f, a), &(c, lo, hi)), t)| json!({
            "force_mN": f * 1e3,
            "measured_area_um2": a * 1e12,
            "measured_area_corrected_um2": c * 1e12,
            "measured_area_um2_lo": lo * 1e12,
            "measured_area_um2_hi": hi * 1e12,
            "true_area_um2": t * 1e12,
        })).collect::<Vec<_>>(),
        "models": facts.comparisons.iter().map(|(name, c)| json!({
            "model": name,
            "dice": c.loads.iter().map(|l| l.dice).collect::<Vec<_>>(),
            "simulated_area_um2": c.loads.iter().map(|l| l.simulated_area_m2 * 1e12).collect::<Vec<_>>(),
            "experiment_area_um2": c.loads.iter().map(|l| l.experiment_area_m2 * 1e12).collect::<Vec<_>>(),
            "series_shift_x_px": c.registration.shift_px.0,
            "series_shift_y_px": c.registration.shift_px.1,
            "series_correlation_peak": c.registration.correlation_peak,
            "shift_x_px": c.loads.iter().map(|l| l.shift_px.0).collect::<Vec<_>>(),
            "shift_y_px": c.loads.iter().map(|l| l.shift_px.1).collect::<Vec<_>>(),
            "correlation_peak": c.loads.iter().map(|l| l.correlation_peak).collect::<Vec<_>>(),
            "refinement": c.loads.iter().map(|l| l.refinement.name()).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    })
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn figure(out: &mut String, src: &str, caption: &str) {
    let _ = writeln!(
        out,
        "<figure><a href=\"{src}\"><img src=\"{src}\" alt=\"{alt}\"></a><figcaption>{caption}</figcaption></figure>",
        alt = escape(caption),
    );
}

fn page(facts: &Facts, panels: &[(String, usize)]) -> String {
    let p = facts.params;
    let mut s = String::new();
    s.push_str(HEAD);
    let _ = write!(
        s,
        "<h1>contactscope demo</h1>\n<p>The whole method of Weber et al., <i>Nat. Commun.</i> 9, 888 (2018), <a href=\"https://doi.org/10.1038/s41467-018-02981-y\">doi:10.1038/s41467-018-02981-y</a>, on a synthetic experiment with known truth, made by contactscope's own generators and solver (version {}). Inputs below are the generator's; every number under <b>Recovered</b> was measured by the analysis commands from the generated files in <a href=\"data/\">data/</a>.</p>\n",
        env!("CARGO_PKG_VERSION")
    );
    inputs_table(&mut s, p);
    recovered_table(&mut s, facts.recovered);

    s.push_str(
        "<h2>Fig. 2: micrographs and simulated contact maps</h2>\n<p>Per load: micrograph | ",
    );
    let names: Vec<String> = facts.comparisons.iter().map(|(n, _)| escape(n)).collect();
    s.push_str(&names.join(" | "));
    s.push_str(". Simulated maps are blurred with the PSF, integrated onto the micrograph pixels, registered by phase correlation (one shift per model for the whole series, each load refined within a few pixels of it) and put on the micrograph's grey scale; the micrograph's contact edges (global Otsu threshold) are green on every panel.</p>\n");
    let n = panels.len();
    let shown = if n > 3 {
        vec![0, n / 2, n - 1]
    } else {
        (0..n).collect()
    };
    for &i in &shown {
        let (name, side) = &panels[i];
        figure(
            &mut s,
            name,
            &format!(
                "N = {:.3} mN, field {:.1} µm wide",
                p.loads_n[i] * 1e3,
                *side as f64 * p.image_pixel_m * 1e6
            ),
        );
    }
    if n > shown.len() {
        s.push_str("<p>All loads: ");
        let links: Vec<String> = panels
            .iter()
            .enumerate()
            .map(|(i, (name, _))| format!("<a href=\"{name}\">{:.3} mN</a>", p.loads_n[i] * 1e3))
            .collect();
        s.push_str(&links.join(" · "));
        s.push_str("</p>\n");
    }
    dice_table(&mut s, facts);

    s.push_str("<h2>Fig. 3a: contact area vs load</h2>\n");
    figure(&mut s, "fit/fit_area_vs_load.png", "Measured areas (analyze) and the four models at their best parameters; simulated areas counted as imaged (blur, resample, Otsu). Table: fit/fit_areas.csv, fit/fit.json.");
    fits_table(&mut s, facts.fits);
    s.push_str("<p>The micrographs show more area than the simulation's g = 0 pixels (table below): the PSF merges and widens sub-resolution patches before the threshold. That is why the fit counts simulated areas as imaged, like with like (<a href=\"methods.md\">methods.md</a> §7.1, in this folder).</p>\n");
    areas_table(&mut s, facts);
    s.push_str("<h2>Fig. 3b: friction</h2>\n");
    figure(
        &mut s,
        "friction/friction_vs_area.png",
        "Static friction vs measured contact area with the fit F = τ·A (friction/summary.json).",
    );
    figure(
        &mut s,
        "friction/mu_vs_load.png",
        "Friction coefficient μ = F/N vs normal force: not constant.",
    );
    s.push_str("<h2>Autocorrelation</h2>\n");
    figure(&mut s, "autocorrelation.png", "Radially averaged intensity autocorrelation of the micrograph and of each model's imaged map at the highest load.");
    s.push_str("<h2>Newton rings: detection gap</h2>\n");
    figure(&mut s, "newton/newton_gap.png", "Gap at the ring maxima (Eq. 1), fitted Hertz exterior gap, and the fluorescent edge (newton/newton.json).");
    s.push_str("<h2>PSF and contact modulus</h2>\n");
    figure(
        &mut s,
        "psf/psf_profiles.png",
        "Radial bead profiles and Gaussian fits (psf/psf.json, psf/beads.csv).",
    );
    figure(
        &mut s,
        "hertz/squeeze_fit.png",
        "Squeeze test: force vs plate displacement 2δ and the Hertz fit (hertz/hertz.json).",
    );
    s.push_str("<h2>Files</h2>\n<ul>\n");
    for (dir, what) in [
        ("data/", "generated inputs: micrographs + manifest, topography, beads, Newton-ring pair, rheometer traces, squeeze test"),
        ("analysis/", "analyze: areas.csv, summary.json, overlays"),
        ("psf/", "psf"),
        ("newton/", "newton"),
        ("hertz/", "hertz"),
        ("friction/", "friction"),
        ("fit/", "fit-hardening"),
        ("demo.json", "every number on this page"),
    ] {
        let _ = writeln!(s, "<li><a href=\"{dir}\">{dir}</a>: {what}</li>");
    }
    s.push_str("</ul>\n</body>\n</html>\n");
    s
}

fn inputs_table(s: &mut String, p: &DemoParams) {
    s.push_str(
        "<h2>Inputs (generator truth)</h2>\n<table>\n<tr><th>quantity</th><th>value</th></tr>\n",
    );
    let rows = [
        (
            "simulation grid",
            format!("{0}×{0} px of {1:.0} nm", p.size, p.sim_pixel_m * 1e9),
        ),
        (
            "roughness",
            format!(
                "self-affine, H = {}, h'_rms = {}, roll-off {:.1} µm, cutoff {:.0} nm, seed {}",
                p.hurst,
                p.rms_slope,
                p.rolloff_m * 1e6,
                p.cutoff_m * 1e9,
                p.seed
            ),
        ),
        ("sphere radius R", format!("{:.0} µm", p.radius_m * 1e6)),
        (
            "contact modulus E*",
            format!("{:.2} GPa", p.e_star_pa * 1e-9),
        ),
        (
            "hardening k (yield pressure = k × plastic depth)",
            format!("{:.2} MPa/nm", p.k_pa_per_m * 1e-15),
        ),
        (
            "normal forces",
            p.loads_n
                .iter()
                .map(|f| format!("{:.4}", f * 1e3))
                .collect::<Vec<_>>()
                .join(", ")
                + " mN",
        ),
        (
            "micrographs",
            format!(
                "{0}×{0} px of {1:.0} nm, 12-bit, PSF FWHM {2:.0} nm, shot noise",
                p.image_size,
                p.image_pixel_m * 1e9,
                p.psf_fwhm_m * 1e9
            ),
        ),
        (
            "shear strength τ",
            format!(
                "{:.0} MPa (static friction = τ × measured area)",
                p.tau_pa * 1e-6
            ),
        ),
        (
            "detection gap",
            format!(
                "{:.1} nm (488 nm light, n = 1.447)",
                p.detection_gap_m * 1e9
            ),
        ),
    ];
    for (k, v) in rows {
        let _ = writeln!(s, "<tr><td>{}</td><td>{}</td></tr>", escape(k), escape(&v));
    }
    s.push_str("</table>\n");
}

fn recovered_table(s: &mut String, recovered: &[Recovered]) {
    s.push_str("<h2>Recovered</h2>\n<table>\n<tr><th>quantity</th><th>truth</th><th>recovered</th><th>95 % interval</th><th>error</th><th>by</th></tr>\n");
    for r in recovered {
        let recovered = crate::table::value_pm_or(r.recovered, r.uncertainty, 3);
        let interval = match r.interval {
            Some((lo, hi)) => {
                let holds = if lo <= r.truth && r.truth <= hi {
                    "holds"
                } else {
                    "misses"
                };
                format!("{lo:.3}…{hi:.3} {} ({holds} the truth)", escape(&r.unit))
            }
            None => "—".into(),
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{:.3} {u}</td><td>{recovered} {u}</td><td>{interval}</td><td>{:+.1} %</td><td><code>{}</code></td></tr>",
            escape(&r.quantity),
            r.truth,
            100.0 * r.relative_error(),
            escape(&r.by),
            u = escape(&r.unit),
        );
    }
    s.push_str("</table>\n");
}

fn dice_table(s: &mut String, facts: &Facts) {
    s.push_str("<table>\n<tr><th>force (mN)</th>");
    for (name, _) in facts.comparisons {
        let _ = write!(s, "<th>Dice, {}</th>", escape(name));
    }
    s.push_str("</tr>\n");
    let loads = facts.comparisons.first().map_or(0, |(_, c)| c.loads.len());
    let mut missed = false;
    for i in 0..loads {
        let _ = write!(
            s,
            "<tr><td>{:.4}</td>",
            facts.comparisons[0].1.loads[i].force_n * 1e3
        );
        // Every model's map belongs where the micrographs were rendered; a registration more
        // than 2 px from there has locked onto the wrong peak.
        let truth = (MICROGRAPH_OFFSET_PX.0 as f64, MICROGRAPH_OFFSET_PX.1 as f64);
        for (_, c) in facts.comparisons {
            let shift = c.loads[i].shift_px;
            let off = (shift.0 - truth.0).hypot(shift.1 - truth.1);
            if off > 2.0 {
                missed = true;
                let _ = write!(
                    s,
                    "<td>{:.3} <b>*</b> ({off:.0} px off)</td>",
                    c.loads[i].dice
                );
            } else {
                let _ = write!(s, "<td>{:.3}</td>", c.loads[i].dice);
            }
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</table>\n");
    if missed {
        s.push_str("<p><b>*</b> Registration missed: the map lies more than 2 px from where the micrographs were rendered. The Dice value of such a load measures the misregistration, not the model; its panel above shows the misplaced map.</p>\n");
    }
    for (name, c) in facts.comparisons {
        for w in &c.warnings {
            let _ = writeln!(s, "<p>{}: {}</p>", escape(name), escape(w));
        }
    }
}

fn fits_table(s: &mut String, fits: &[ModelFit]) {
    s.push_str("<table>\n<tr><th>model</th><th>fitted parameter</th><th>95 % interval</th><th>misfit (RMS of ln A<sub>sim</sub>/A<sub>exp</sub>)</th></tr>\n");
    for fit in fits {
        let parameter = match (fit.family, fit.best.parameter) {
            (Family::Hardening, Some(k)) => format!(
                "k = {} MPa/nm",
                crate::table::value_pm_or(k * 1e-15, fit.parameter_se.map(|e| e * 1e-15), 2)
            ),
            (Family::Hardness, Some(p)) => format!(
                "p<sub>Y</sub> = {} MPa",
                crate::table::value_pm_or(p * 1e-6, fit.parameter_se.map(|e| e * 1e-6), 0)
            ),
            _ => "none".into(),
        };
        let interval = match (fit.family, fit.parameter_ci95) {
            (Family::Hardening, Some((lo, hi))) => {
                format!("{:.2}…{:.2} MPa/nm", lo * 1e-15, hi * 1e-15)
            }
            (Family::Hardness, Some((lo, hi))) => format!("{:.0}…{:.0} MPa", lo * 1e-6, hi * 1e-6),
            _ => "—".into(),
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td>{interval}</td><td>{:.3}</td></tr>",
            fit.family.name(),
            parameter,
            fit.best.misfit
        );
    }
    s.push_str("</table>\n");
}

fn areas_table(s: &mut String, facts: &Facts) {
    s.push_str("<table>\n<tr><th>force (mN)</th><th>contact pixels' area (µm²)</th><th>corrected area (µm²)</th><th>95 % interval on the true area (µm²)</th><th>true area, g = 0 (µm²)</th></tr>\n");
    for ((&(f, a), &(c, lo, hi)), t) in facts
        .measured
        .iter()
        .zip(facts.measured_intervals)
        .zip(facts.truth_areas_m2)
    {
        let holds = if lo <= *t && *t <= hi {
            ""
        } else {
            " (misses the truth)"
        };
        // No corrected area where the intervals are the edge band's (a field too small).
        let corrected = if c.is_finite() {
            format!("{:.2}", c * 1e12)
        } else {
            "—".to_string()
        };
        let _ = writeln!(
            s,
            "<tr><td>{:.4}</td><td>{:.2}</td><td>{corrected}</td><td>{:.2}…{:.2}{holds}</td><td>{:.2}</td></tr>",
            f * 1e3,
            a * 1e12,
            lo * 1e12,
            hi * 1e12,
            t * 1e12
        );
    }
    s.push_str("</table>\n");
}

const HEAD: &str = r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>contactscope demo report</title>
<style>
body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #bbb; padding: 0.3em 0.7em; text-align: left; }
th { background: #eee; }
figure { margin: 1.5em 0; }
img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9em; color: #555; }
</style>
</head>
<body>
"#;
