//! The QC page (`index.html` beside the tables): the whole archive at a glance. One row per
//! series with the thumbnail of its highest load (contact edges in green), a small area–load
//! plot (log–log, its power law; points whose contact touches the border in orange), the fit
//! values, the flags and warnings, and links to its folders; above the table, one combined
//! area–load plot of every series coloured by a metadata column (`qc/area_vs_load.png/.svg`).
//! The page is static HTML with a few lines of script to sort, filter and show flagged series
//! only; it references only files of the batch's folder, by relative paths, so the folder can be
//! moved or shared whole.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::columns::Entry;
use super::record::{SeriesResult, Status};
use super::tables::Table;
use super::Plan;
use crate::error::Result;
use crate::provenance;

/// Escape text for HTML.
fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// A path segment (a series id: letters, digits, `.`, `_`, `-`) as a URL.
fn url(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            'A'..='Z' | 'a'..='z' | '0'..='9' | '.' | '_' | '-' | '/' => c.to_string(),
            c => {
                let mut buf = [0u8; 4];
                c.encode_utf8(&mut buf)
                    .bytes()
                    .map(|b| format!("%{b:02X}"))
                    .collect()
            }
        })
        .collect()
}

/// The metadata column that colours the combined plot: the one asked for, else the first.
fn colour_column(plan: &Plan, warnings: &mut Vec<String>) -> Option<usize> {
    let metadata = &plan.sheet.metadata;
    match &plan.request.color_by {
        Some(name) => {
            let found = metadata.iter().position(|m| m.name == *name);
            if found.is_none() {
                warnings.push(format!(
                    "--color-by {name}: no such metadata column (have: {}); the combined plot \
                     is coloured by series",
                    if metadata.is_empty() {
                        "none".to_string()
                    } else {
                        metadata
                            .iter()
                            .map(|m| m.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ));
            }
            found
        }
        None => (!metadata.is_empty()).then_some(0),
    }
}

/// Write `qc/area_vs_load.png/.svg` and `index.html`; the paths written.
pub fn write_page(
    out: &Path,
    plan: &Plan,
    entries: &[Entry],
    images: &Table,
    warnings: &mut Vec<String>,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    let colour = colour_column(plan, warnings);
    let label = |e: &Entry| match colour {
        Some(k) if !e.row.metadata[k].is_empty() => e.row.metadata[k].clone(),
        Some(_) => "(none)".to_string(),
        None => e.row.id.clone(),
    };
    let combined = combined_plot(entries, &label);
    #[cfg(feature = "plots")]
    if let Some(chart) = &combined {
        let qc = out.join("qc");
        let (png, svg, digest) = (
            qc.join("area_vs_load.png"),
            qc.join("area_vs_load.svg"),
            qc.join("area_vs_load.sha256"),
        );
        // The plot of an unchanged archive is not drawn again (most of a re-run's time): its
        // data's digest is kept beside it.
        let data = crate::provenance::sha256_bytes(format!("{chart:?}").as_bytes());
        let same = std::fs::read_to_string(&digest).is_ok_and(|d| d == data)
            && png.is_file()
            && svg.is_file();
        if !same {
            crate::staging::write_atomic(&png, &chart.to_png()?)?;
            crate::staging::write_atomic(&svg, chart.to_svg()?.as_bytes())?;
            crate::staging::write_atomic(&digest, data.as_bytes())?;
        }
        written.extend([png, svg]);
    }
    let html = page(plan, entries, images, colour, combined.is_some(), warnings);
    let path = out.join("index.html");
    crate::staging::write_atomic(&path, html.as_bytes())?;
    written.push(path);
    Ok(written)
}

/// Every series' measured points and power law on one log–log chart, one colour per value of
/// the colouring column (series in pixels are left out: their areas are in another unit).
#[cfg(feature = "plots")]
fn combined_plot(
    entries: &[Entry],
    label: &dyn Fn(&Entry) -> String,
) -> Option<crate::plot::Chart> {
    use crate::plot::{Axes, Chart, Curve, Legend, PointSet};
    // Per colour: the measured points and the fitted lines (NaN between series).
    type Group = (Vec<(f64, f64)>, Vec<(f64, f64)>);
    let mut groups: BTreeMap<String, Group> = BTreeMap::new();
    let mut series = 0;
    for e in entries {
        let Some(r) = e.record.result.as_ref().filter(|r| r.area_unit == "um2") else {
            continue;
        };
        let points = loaded_points(r);
        if points.is_empty() {
            continue;
        }
        series += 1;
        let group = groups.entry(label(e)).or_default();
        group.0.extend(points.iter().map(|p| (p.0, p.1)));
        if let Some(law) = r.power_law {
            let (lo, hi) = force_range(&points);
            for i in 0..=20 {
                let f = lo * (hi / lo).powf(f64::from(i) / 20.0);
                group.1.push((f, law.prefactor * f.powf(law.exponent)));
            }
            // A break between series' lines.
            group.1.push((f64::NAN, f64::NAN));
        }
    }
    if groups.is_empty() {
        return None;
    }
    let (points, curves): (Vec<PointSet>, Vec<Curve>) = groups
        .into_iter()
        .map(|(name, (xy, fit))| {
            (
                PointSet {
                    label: name,
                    xy,
                    hollow: false,
                },
                Curve {
                    label: String::new(),
                    xy: fit,
                },
            )
        })
        .unzip();
    Some(Chart {
        title: format!("Contact area versus normal force, {series} series"),
        x_label: "normal force N (mN)".into(),
        y_label: "contact area A (µm²)".into(),
        axes: Axes::LogLog,
        legend: Legend::UpperLeft,
        points,
        curves,
        curves_follow_points: true,
        translucent: true,
    })
}

#[cfg(not(feature = "plots"))]
fn combined_plot(_: &[Entry], _: &dyn Fn(&Entry) -> String) -> Option<()> {
    None
}

/// (force mN, area, border contact) of the images a log–log plot shows.
fn loaded_points(r: &SeriesResult) -> Vec<(f64, f64, bool)> {
    r.images
        .iter()
        .filter_map(|i| {
            i.force_mn
                .filter(|f| *f > 0.0 && i.area > 0.0)
                .map(|f| (f, i.area, i.edge_contact))
        })
        .collect()
}

fn force_range(points: &[(f64, f64, bool)]) -> (f64, f64) {
    points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.0), hi.max(p.0))
    })
}

/// A small inline log–log plot of a series: its points, its power law, the extreme values
/// (the column's header gives the units).
fn mini_plot(r: &SeriesResult) -> String {
    let points = loaded_points(r);
    if points.is_empty() {
        return "<span class=\"none\">no loaded image with contact</span>".into();
    }
    // Plot area x0..x1 (right of the y labels), y0..y1 (above the x labels).
    let (w, h) = (200.0, 118.0);
    let (left, right, top, bottom) = (38.0, 194.0, 7.0, 100.0);
    let (f0, f1) = force_range(&points);
    let (a0, a1) = points.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), p| {
        (lo.min(p.1), hi.max(p.1))
    });
    let span = |lo: f64, hi: f64| {
        if hi > lo {
            (lo.ln(), hi.ln())
        } else {
            (lo.ln() - 0.5, lo.ln() + 0.5)
        }
    };
    let ((lx0, lx1), (ly0, ly1)) = (span(f0, f1), span(a0, a1));
    let px = |x: f64| left + (x.ln() - lx0) / (lx1 - lx0) * (right - left);
    let py = |y: f64| bottom - (y.ln() - ly0) / (ly1 - ly0) * (bottom - top);
    let mut svg = format!(
        "<svg class=\"mini\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\" role=\"img\" \
         aria-label=\"contact area versus normal force, log-log\"><rect x=\"{}\" y=\"{}\" \
         width=\"{}\" height=\"{}\" class=\"frame\"/>",
        left - 4.0,
        top - 4.0,
        right - left + 8.0,
        bottom - top + 8.0
    );
    if let Some(law) = r.power_law {
        let f = |n: f64| law.prefactor * n.powf(law.exponent);
        let _ = write!(
            svg,
            "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" class=\"fit\"/>",
            px(f0),
            py(f(f0)).clamp(0.0, h),
            px(f1),
            py(f(f1)).clamp(0.0, h)
        );
    }
    for (x, y, edge) in &points {
        let _ = write!(
            svg,
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.6\" class=\"{}\"/>",
            px(*x),
            py(*y),
            if *edge { "edge" } else { "pt" }
        );
    }
    let _ = write!(
        svg,
        "<text x=\"{left}\" y=\"{}\" class=\"lab\">{}</text>\
         <text x=\"{right}\" y=\"{}\" class=\"lab\" text-anchor=\"end\">{}</text>\
         <text x=\"{}\" y=\"{}\" class=\"lab\" text-anchor=\"end\">{}</text>\
         <text x=\"{}\" y=\"{bottom}\" class=\"lab\" text-anchor=\"end\">{}</text></svg>",
        h - 3.0,
        short(f0),
        h - 3.0,
        short(f1),
        left - 7.0,
        top + 6.0,
        short(a1),
        left - 7.0,
        short(a0)
    );
    svg
}

/// A number in at most 3 significant digits, without trailing zeros (`4`, `37.6`, `0.0123`).
fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{v:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

fn pm(value: Option<f64>, se: Option<f64>, digits: usize) -> String {
    match (value, se) {
        (Some(v), Some(s)) => format!("{v:.digits$} ± {s:.digits$}"),
        (Some(v), None) => format!("{v:.digits$}"),
        _ => "—".into(),
    }
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:1.2em;color:#222}\
h1{font-size:1.4em;margin:0 0 .3em}.meta{color:#555;font-size:.9em}\
table{border-collapse:collapse;font-size:.85em}th,td{border:1px solid #ccc;padding:4px 6px;\
vertical-align:top}th{background:#f2f2f2;cursor:pointer;position:sticky;top:0}\
tr.failed{background:#fde8e8}tr.flagged{background:#fff6e0}.thumb{width:128px;\
image-rendering:pixelated}.flag{display:inline-block;margin:1px;padding:1px 5px;\
border-radius:8px;background:#f0ad4e;color:#fff;font-size:.8em}.flag.failed{background:#d9534f}\
.none{color:#888}.mini .frame{fill:#fff;stroke:#bbb}.mini .pt{fill:#0072b2}\
.mini .edge{fill:#d55e00}.mini .fit{stroke:#009e73;stroke-width:1.5}.mini .lab{font-size:9px;\
fill:#555}.controls{margin:.6em 0}.combined{max-width:720px;width:100%;border:1px solid #ddd}\
details{max-width:28em}.num{text-align:right;white-space:nowrap}\
td{max-width:18em;overflow-wrap:break-word}td.status,td.notes{max-width:14em;\
overflow-wrap:anywhere}td.short{white-space:nowrap}";

/// Filtering, "flagged only", and sorting by a click on a column's head: each column sorts by
/// its kind, found from all its values (ISO dates as dates, numbers as numbers, anything else
/// as text in natural order); empty cells and "—" sort last in either direction. A cell's
/// `data-v` is its sort value when its text is not (`0.87 ± 0.01`).
const SCRIPT: &str = "(function(){\
var table=document.getElementById('series');var body=table.tBodies[0];\
var filter=document.getElementById('filter');var flagged=document.getElementById('flagged');\
function apply(){var q=filter.value.toLowerCase();var only=flagged.checked;\
for(var i=0;i<body.rows.length;i++){var r=body.rows[i];\
var show=r.textContent.toLowerCase().indexOf(q)>=0&&(!only||r.dataset.flags!=='');\
r.style.display=show?'':'none';}}\
filter.addEventListener('input',apply);flagged.addEventListener('change',apply);\
var DATE=/^\\d{4}-\\d{2}-\\d{2}([T ]\\d{2}:\\d{2}(:\\d{2}(\\.\\d+)?)?)?(Z|[+-]\\d{2}:?\\d{2})?$/;\
function key(cell){var v=cell.dataset.v;if(v===undefined)v=cell.textContent;v=v.trim();\
return(v===''||v==='\u{2014}'||v==='-')?null:v;}\
function kind(keys){var date=true,num=true,any=false;keys.forEach(function(k){if(k===null)return;\
any=true;if(!DATE.test(k))date=false;if(k===''||!isFinite(Number(k)))num=false;});\
return !any?'text':date?'date':num?'num':'text';}\
var heads=table.tHead.rows[0].cells;\
for(var c=0;c<heads.length;c++){(function(col){heads[col].addEventListener('click',function(){\
var rows=Array.prototype.slice.call(body.rows);var dir=heads[col].dataset.dir==='asc'?-1:1;\
heads[col].dataset.dir=dir===1?'asc':'desc';\
var keys=new Map();rows.forEach(function(r){keys.set(r,key(r.cells[col]));});\
var k=kind(Array.from(keys.values()));\
function val(x){return k==='num'?Number(x):k==='date'?Date.parse(x.replace(' ','T')):x;}\
rows.sort(function(a,b){var x=keys.get(a),y=keys.get(b);\
if(x===null||y===null)return (x===null)-(y===null);\
if(k==='text')return dir*x.localeCompare(y,undefined,{numeric:true});\
var d=val(x)-val(y);return dir*(d>0?1:d<0?-1:0);});\
rows.forEach(function(r){body.appendChild(r);});\
for(var h=0;h<heads.length;h++){if(h!==col)delete heads[h].dataset.dir;}});})(c);}\
})();";

fn page(
    plan: &Plan,
    entries: &[Entry],
    images: &Table,
    colour: Option<usize>,
    combined: bool,
    warnings: &[String],
) -> String {
    let metadata = &plan.sheet.metadata;
    let failed = entries
        .iter()
        .filter(|e| e.record.status == Status::Failed)
        .count();
    let flagged = entries.iter().filter(|e| !e.flags.is_empty()).count();
    let fits = entries
        .iter()
        .any(|e| e.record.command_lines.fit_hardening.is_some());
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for f in entries.iter().flat_map(|e| e.flags.iter()) {
        *counts.entry(f.code).or_default() += 1;
    }
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>contactscope batch: {} series</title><style>{STYLE}</style></head><body>\
         <h1>contactscope batch: {} series, {} images</h1>\
         <p class=\"meta\">{} ok, {failed} failed, {flagged} flagged. contactscope {} \
         {}, finished {}. Tables: <a href=\"series.csv\">series.csv</a> \
         (<a href=\"series.parquet\">Parquet</a>), <a href=\"images.csv\">images.csv</a> \
         (<a href=\"images.parquet\">Parquet</a>); provenance: <a href=\"batch.json\">batch.json</a>.\
         </p>",
        entries.len(),
        entries.len(),
        images.rows,
        entries.len() - failed,
        esc(provenance::version()),
        provenance::source_revision()
            .map_or_else(|| "(source revision unknown)".to_string(), |r| format!("(source {})", esc(r))),
        esc(&provenance::rfc3339(std::time::SystemTime::now())),
    );
    if !counts.is_empty() {
        html.push_str("<p class=\"meta\">Flags: ");
        let list: Vec<String> = counts
            .iter()
            .map(|(c, n)| format!("<span class=\"flag\">{}</span> {n}", esc(c)))
            .collect();
        html.push_str(&list.join(" · "));
        html.push_str(" (<code>docs/outputs.md</code> of contactscope defines each).</p>");
    }
    for w in warnings {
        let _ = write!(html, "<p class=\"meta\">Note: {}</p>", esc(w));
    }
    if combined {
        let by = match colour {
            Some(k) => format!("coloured by <b>{}</b>", esc(&metadata[k].name)),
            None => "one colour per series".to_string(),
        };
        let _ = write!(
            html,
            "<h2>All series</h2><p class=\"meta\">Measured points and power-law fits, {by} \
             (series with areas in pixels are left out).</p>\
             <a href=\"qc/area_vs_load.svg\"><img class=\"combined\" src=\"qc/area_vs_load.png\" \
             alt=\"contact area versus normal force of every series\"></a>"
        );
    }
    html.push_str(
        "<h2>Series</h2><div class=\"controls\"><input id=\"filter\" type=\"search\" \
         placeholder=\"filter rows\" aria-label=\"filter rows\"> <label><input id=\"flagged\" \
         type=\"checkbox\"> flagged only</label> (click a column to sort)</div>\
         <table id=\"series\"><thead><tr><th>series</th>",
    );
    for m in metadata {
        let _ = write!(html, "<th>{}</th>", esc(&m.name));
    }
    html.push_str(
        "<th>status</th><th>highest load</th><th>area A vs load N<br><span class=\"meta\">\
         (log–log; µm² or px, mN)</span></th><th>β (A ∝ N^β)</th>\
         <th>R²</th><th>p (MPa)</th>",
    );
    if fits {
        html.push_str("<th>k (MPa/nm)</th><th>p_Y (MPa)</th>");
    }
    html.push_str("<th>threshold</th><th>pixel size (µm)</th><th>flags</th><th>warnings</th></tr></thead><tbody>");
    for e in entries {
        row(&mut html, e, metadata.len(), fits);
    }
    html.push_str("</tbody></table>");
    let _ = writeln!(html, "<script>{SCRIPT}</script></body></html>");
    html
}

fn row(html: &mut String, e: &Entry, metadata: usize, fits: bool) {
    let id = &e.row.id;
    let class = match (e.record.status, e.flags.is_empty()) {
        (Status::Failed, _) => " class=\"failed\"",
        (_, false) => " class=\"flagged\"",
        _ => "",
    };
    let codes: Vec<&str> = e.flags.iter().map(|f| f.code).collect();
    let _ = write!(
        html,
        "<tr id=\"s-{}\" data-flags=\"{}\"{class}><td>",
        esc(id),
        esc(&codes.join(","))
    );
    let result = e.record.result.as_ref();
    if result.is_some() {
        let _ = write!(
            html,
            "<a href=\"series/{}/\">{}</a><br><a href=\"series/{}/summary.json\">summary</a> · \
             <a href=\"series/{}/areas.csv\">areas</a>",
            url(id),
            esc(id),
            url(id),
            url(id)
        );
        if e.record.fit.is_some() {
            let _ = write!(html, " · <a href=\"fit/{}/\">fit</a>", url(id));
        }
    } else {
        html.push_str(&esc(id));
    }
    html.push_str("</td>");
    for k in 0..metadata {
        // A short value (a date, a code) on one line; a long one wraps.
        let value = &e.row.metadata[k];
        let class = match value.chars().count() <= 16 {
            true => " class=\"short\"",
            false => "",
        };
        let _ = write!(html, "<td{class}>{}</td>", esc(value));
    }
    let status = e.record.status.name();
    match &e.record.error {
        Some(err) => {
            // Folded: a long error (a path deep in an archive) does not widen the table.
            let _ = write!(
                html,
                "<td class=\"status\" data-v=\"{status}\"><details><summary><b>{status}</b> \
                 ({})</summary>{}</details></td>",
                esc(e.record.failed_stage.as_deref().unwrap_or("")),
                esc(err)
            );
        }
        None => {
            let _ = write!(html, "<td>{status}</td>");
        }
    }
    match result {
        Some(r) => {
            let top = r
                .images
                .iter()
                .filter_map(|i| i.force_mn)
                .fold(None, |m: Option<f64>, f| Some(m.map_or(f, |m| m.max(f))));
            let caption = top.map_or("last image".to_string(), |f| format!("{} mN", short(f)));
            let _ = write!(
                html,
                "<td><a href=\"qc/{0}.png\"><img class=\"thumb\" src=\"qc/{0}.png\" \
                 alt=\"highest load of {1}\"></a><br>{2}</td><td>{3}</td>",
                url(id),
                esc(id),
                esc(&caption),
                mini_plot(r)
            );
            let law = r.power_law;
            let _ = write!(
                html,
                "<td class=\"num\" data-v=\"{}\">{}</td><td class=\"num\">{}</td>\
                 <td class=\"num\" data-v=\"{}\">{}</td>",
                law.map_or(String::new(), |l| l.exponent.to_string()),
                pm(law.map(|l| l.exponent), law.and_then(|l| l.exponent_se), 3),
                law.and_then(|l| l.r_squared)
                    .map_or("—".into(), |r| format!("{r:.4}")),
                r.proportional_mpa
                    .map_or(String::new(), |p| p.0.to_string()),
                r.proportional_mpa
                    .map_or("—".into(), |p| format!("{:.1}", p.0)),
            );
        }
        None => html.push_str("<td></td><td></td><td></td><td></td><td></td>"),
    }
    if fits {
        let f = e.record.fit.as_ref();
        let v = |x: Option<f64>| x.map_or(String::new(), |x| x.to_string());
        let _ = write!(
            html,
            "<td class=\"num\" data-v=\"{}\">{}</td><td class=\"num\" data-v=\"{}\">{}</td>",
            v(f.and_then(|f| f.k_pa_per_m)),
            pm(
                f.and_then(|f| f.k_pa_per_m).map(|k| k * 1e-15),
                f.and_then(|f| f.k_se_pa_per_m).map(|k| k * 1e-15),
                3
            ),
            v(f.and_then(|f| f.hardness_pa)),
            pm(
                f.and_then(|f| f.hardness_pa).map(|p| p * 1e-6),
                f.and_then(|f| f.hardness_se_pa).map(|p| p * 1e-6),
                1
            ),
        );
    }
    match result {
        Some(r) => {
            let threshold = match r.threshold {
                Some(t) => format!("{t}"),
                None => "per image".into(),
            };
            let pixel = match (r.pixel_size_um, &r.pixel_size_source) {
                (Some((x, y)), Some(source)) => {
                    let size = if x == y {
                        short(x)
                    } else {
                        format!("{} × {}", short(x), short(y))
                    };
                    let from = if r.pixel_size_from_default {
                        "batch default (file had none)"
                    } else if r.pixel_size_given {
                        "samplesheet"
                    } else {
                        source.as_str()
                    };
                    format!("{size}<br><span class=\"meta\">{}</span>", esc(from))
                }
                _ => "none (pixels)".into(),
            };
            let _ = write!(
                html,
                "<td class=\"num\">{}</td><td data-v=\"{}\">{pixel}</td>",
                esc(&threshold),
                r.pixel_size_um.map_or(String::new(), |p| p.0.to_string())
            );
        }
        None => html.push_str("<td></td><td></td>"),
    }
    html.push_str("<td>");
    for f in e.flags {
        let _ = write!(
            html,
            "<span class=\"flag{}\" title=\"{}\">{}</span> ",
            if f.code == "failed" { " failed" } else { "" },
            esc(&f.text),
            esc(f.code)
        );
    }
    html.push_str("</td><td class=\"notes\">");
    let warnings: Vec<&String> = result
        .iter()
        .flat_map(|r| r.warnings.iter())
        .chain(e.record.fit.iter().flat_map(|f| f.warnings.iter()))
        .collect();
    if !warnings.is_empty() {
        let _ = write!(html, "<details><summary>{}</summary><ul>", warnings.len());
        for w in warnings {
            let _ = write!(html, "<li>{}</li>", esc(w));
        }
        html.push_str("</ul></details>");
    }
    html.push_str("</td></tr>");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_numbers_short() {
        assert_eq!(
            esc("<a href=\"x\">&'"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
        assert_eq!(url("s 1/é"), "s%201/%C3%A9");
        assert_eq!(short(123.456), "123");
        assert_eq!(short(4.0), "4");
        assert_eq!(short(37.6), "37.6");
        assert_eq!(short(0.01234), "0.0123");
        assert_eq!(pm(Some(0.87), Some(0.004), 3), "0.870 ± 0.004");
        assert_eq!(pm(None, None, 3), "—");
    }
}
