//! A load series from a manifest: a CSV naming each image's file (and page), its force and,
//! optionally, its friction force (README, `--manifest`).

use std::path::Path;

use super::{FileTable, ImageRef, Series};
use crate::error::{Error, Location, Result};
use contactscope_formats::microscopy::select::{LoadAxis, SelectedPlane, Selection};
use contactscope_formats::ranges::Quantity;

fn manifest_number(
    row: &csv::StringRecord,
    column: Option<usize>,
    name: &str,
    at: &Location,
    delimiter: u8,
) -> Result<Option<f64>> {
    let Some(text) = column.and_then(|c| row.get(c)).map(str::trim) else {
        return Ok(None);
    };
    if text.is_empty() {
        return Ok(None);
    }
    let value = crate::table::parse_number(text, delimiter)
        .ok_or_else(|| Error::bad_input(at.clone(), format!("{name} '{text}' is not a number")))?;
    if !value.is_finite() || value < 0.0 {
        return Err(Error::bad_input(
            at.clone(),
            format!("{name} {text} must be a finite, non-negative number"),
        ));
    }
    Ok(Some(value))
}

/// Read a manifest CSV (`file`, optional `page`, `force_mN` or `force_N`, optional
/// `friction_mN` or `friction_N`).
pub fn from_manifest(manifest: &Path, channel: Option<usize>) -> Result<Series> {
    from_manifest_selected(manifest, &Selection::channel(channel), None)
}

/// A manifest whose files may be CZI, ND2 or LIF files too: their `page` is the position along
/// `load_axis` (empty when the selection names one plane).
pub fn from_manifest_selected(
    manifest: &Path,
    selection: &Selection,
    load_axis: Option<LoadAxis>,
) -> Result<Series> {
    let at_manifest = Location::file(manifest);
    crate::staging::note_input(manifest);
    let text = std::fs::read_to_string(manifest).map_err(|e| Error::io(manifest, e))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let delimiter = crate::table::sniff_delimiter(text);
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| Error::bad_input(at_manifest.clone(), format!("bad CSV header: {e}")))?
        .clone();
    let column = |name: &str| headers.iter().position(|h| h == name);
    let found = || headers.iter().collect::<Vec<_>>().join(", ");
    // A force column in millinewtons or newtons (one of them): (index, name, newtons per unit).
    let force_column = |stem: &str| -> Result<Option<(usize, String, f64)>> {
        let (mn, n) = (format!("{stem}_mN"), format!("{stem}_N"));
        match (column(&mn), column(&n)) {
            (Some(_), Some(_)) => Err(Error::bad_input(
                at_manifest.clone(),
                format!("columns {mn} and {n} say the same thing; keep one"),
            )),
            (Some(i), None) => Ok(Some((i, mn, 1e-3))),
            (None, Some(i)) => Ok(Some((i, n, 1.0))),
            (None, None) => Ok(None),
        }
    };
    let (Some(file_col), Some((force_col, force_name, force_unit))) =
        (column("file"), force_column("force")?)
    else {
        return Err(Error::bad_input(
            at_manifest,
            format!(
                "manifest needs columns 'file' and 'force_mN' (or 'force_N'); found: {}",
                found()
            ),
        ));
    };
    let (page_col, friction_col) = (column("page"), force_column("friction")?);
    let base = manifest.parent().unwrap_or(Path::new("."));
    let mut table = FileTable::new(selection.clone(), load_axis, true);
    let mut images = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let line = i + 2;
        let at = Location::file(format!("{}:{line}", manifest.display()));
        let row = row.map_err(|e| Error::bad_input(at.clone(), format!("bad CSV row: {e}")))?;
        let file = row.get(file_col).unwrap_or("").trim();
        if file.is_empty() {
            return Err(Error::bad_input(at, "empty 'file'"));
        }
        let path = base.join(file);
        let force = manifest_number(&row, Some(force_col), &force_name, &at, delimiter)?
            .ok_or_else(|| Error::bad_input(at.clone(), format!("missing {force_name}")))?
            * force_unit;
        // 0 is a reference frame recorded before loading: analysed, left out of the fits.
        if force != 0.0 {
            Quantity::Force.check_at(force, &at)?;
        }
        let friction = match &friction_col {
            Some((c, name, unit)) => {
                manifest_number(&row, Some(*c), name, &at, delimiter)?.map(|f| f * unit)
            }
            None => None,
        };
        if let Some(f) = friction.filter(|f| *f != 0.0) {
            Quantity::Force.check_at(f, &at)?;
        }
        // An error about the row's file (missing, unreadable, no such page) names the row too.
        let (page, plane) = resolve_page(&mut table, &path, &row, page_col, &at).map_err(|e| {
            let text = e.to_string();
            if text.contains(&manifest.display().to_string()) {
                e
            } else {
                Error::bad_input(at.clone(), text)
            }
        })?;
        images.push(ImageRef {
            path,
            page,
            plane,
            force_n: Some(force),
            friction_n: friction,
        });
    }
    if images.is_empty() {
        return Err(Error::bad_input(
            Location::file(manifest),
            "manifest lists no images",
        ));
    }
    Ok(table.into_series(
        images,
        Some(manifest.to_path_buf()),
        "the manifest's rows".into(),
    ))
}

fn resolve_page(
    table: &mut FileTable,
    path: &Path,
    row: &csv::StringRecord,
    page_col: Option<usize>,
    at: &Location,
) -> Result<(usize, Option<SelectedPlane>)> {
    let channel = table.channel();
    // A manifest names pages of the file it names (not of another file of its OME set).
    let images: Vec<(usize, Option<SelectedPlane>)> = table
        .get(path)?
        .images()
        .into_iter()
        .filter(|(file, _, _)| file == path)
        .map(|(_, page, plane)| (page, plane))
        .collect();
    let pages: Vec<usize> = images.iter().map(|(p, _)| *p).collect();
    let text = page_col.and_then(|c| row.get(c)).unwrap_or("").trim();
    if text.is_empty() {
        return match images.as_slice() {
            [only] => Ok(only.clone()),
            _ => Err(Error::bad_input(
                at.clone(),
                format!(
                    "{} has {} pages; give the page (0-based) in a 'page' column",
                    path.display(),
                    pages.len()
                ),
            )),
        };
    }
    let page: usize = text.parse().map_err(|_| {
        Error::bad_input(
            at.clone(),
            format!("page '{text}' is not a non-negative integer"),
        )
    })?;
    let Some(found) = images.into_iter().find(|(p, _)| *p == page) else {
        return Err(Error::bad_input(
            at.clone(),
            format!(
                "page {page} is not in {} (its pages for channel {channel}: {})",
                path.display(),
                page_list(&pages)
            ),
        ));
    };
    Ok(found)
}

fn page_list(pages: &[usize]) -> String {
    match pages {
        [] => "none".into(),
        [a] => a.to_string(),
        _ if pages.windows(2).all(|w| w[1] == w[0] + 1) => {
            format!("{}..{}", pages[0], pages[pages.len() - 1])
        }
        _ => pages
            .iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(","),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_lists_read_well() {
        assert_eq!(page_list(&[0, 1, 2, 3]), "0..3");
        assert_eq!(page_list(&[1, 3, 5]), "1,3,5");
        assert_eq!(page_list(&[4]), "4");
    }
}
