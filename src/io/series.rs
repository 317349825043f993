//! A load series: which page of which file is which load step, and its normal force.
//!
//! Inputs are one multi-page TIFF, several files, a directory of TIFFs (natural sort order, so
//! `img2` comes before `img10`) or a manifest CSV with columns `file`, optional `page`,
//! `force_mN` and optional `friction_mN`, paths relative to the manifest's folder.
//! Pages are zero-based TIFF page (IFD) indices, as tifffile numbers them.

use std::cmp::Ordering;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use serde::Serialize;

use super::tiff::{TiffInfo, TiffReader};
use crate::error::{Error, Location, Result};

/// One image of a series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageRef {
    /// File holding the image.
    pub path: PathBuf,
    /// Zero-based page (IFD index) in the file.
    pub page: usize,
    /// Normal force in newtons, when known.
    pub force_n: Option<f64>,
    /// Friction force in newtons, when the manifest gives it.
    pub friction_n: Option<f64>,
}

/// The images of a series with the header facts of each distinct file.
#[derive(Debug, Clone)]
pub struct Series {
    /// Images in load order.
    pub images: Vec<ImageRef>,
    /// Header facts per distinct file, in first-use order.
    pub files: Vec<TiffInfo>,
    /// Selected channel.
    pub channel: usize,
    /// The manifest the series came from, if any.
    pub manifest: Option<PathBuf>,
}

impl Series {
    /// Header facts of the file holding image `i`.
    pub fn info_of(&self, path: &Path) -> Option<&TiffInfo> {
        self.files.iter().find(|f| f.path == path)
    }
}

/// Compare names so that digit runs compare by value: `img2` < `img10`.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (mut a, mut b) = (a, b);
    loop {
        match (a.chars().next(), b.chars().next()) {
            (None, None) => return Ordering::Equal,
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(x), Some(y)) if x.is_ascii_digit() && y.is_ascii_digit() => {
                let (da, ra) = split_digits(a);
                let (db, rb) = split_digits(b);
                let (ta, tb) = (da.trim_start_matches('0'), db.trim_start_matches('0'));
                let ord = ta
                    .len()
                    .cmp(&tb.len())
                    .then(ta.cmp(tb))
                    .then(da.len().cmp(&db.len()));
                if ord != Ordering::Equal {
                    return ord;
                }
                (a, b) = (ra, rb);
            }
            (Some(x), Some(y)) => {
                if x != y {
                    return x.cmp(&y);
                }
                (a, b) = (&a[x.len_utf8()..], &b[y.len_utf8()..]);
            }
        }
    }
}

fn split_digits(s: &str) -> (&str, &str) {
    let end = s.find(|c: char| !c.is_ascii_digit()).unwrap_or(s.len());
    s.split_at(end)
}

fn is_tiff_name(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tif") || e.eq_ignore_ascii_case("tiff"))
}

/// Expand inputs into files: directories give their TIFF files in natural order, files are kept
/// in the order given.
pub fn collect_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    if inputs.is_empty() {
        return Err(Error::InvalidArgument("no input files given".into()));
    }
    let mut files = Vec::new();
    for input in inputs {
        let meta = std::fs::metadata(input).map_err(|e| Error::io(input, e))?;
        if !meta.is_dir() {
            files.push(input.clone());
            continue;
        }
        let mut found: Vec<PathBuf> = std::fs::read_dir(input)
            .map_err(|e| Error::io(input, e))?
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .filter(|p| p.is_file() && is_tiff_name(p))
            .collect();
        if found.is_empty() {
            return Err(Error::bad_input(
                Location::file(input),
                "directory holds no .tif or .tiff files",
            ));
        }
        found.sort_by(|a, b| natural_cmp(&a.to_string_lossy(), &b.to_string_lossy()));
        files.extend(found);
    }
    Ok(files)
}

/// Check that a file's header agrees with the series' first file and resolve the channel.
fn check_file(info: &TiffInfo, first: Option<&TiffInfo>, channel: Option<usize>) -> Result<usize> {
    if let Some(first) = first {
        let describe = |i: &TiffInfo| {
            format!(
                "{}×{} {} with {} channel(s)",
                i.width,
                i.height,
                i.sample_type.name(),
                i.channels
            )
        };
        if (info.width, info.height, info.sample_type, info.channels)
            != (first.width, first.height, first.sample_type, first.channels)
        {
            return Err(Error::SeriesMismatch {
                at: Location::page(&info.path, info.pages.first().copied().unwrap_or(0)),
                reason: format!("image is {}", describe(info)),
                expected: describe(first),
            });
        }
    }
    match channel {
        None if info.channels > 1 => Err(Error::bad_input(
            Location::file(&info.path),
            format!(
                "file has {} channels ({}); choose one with --channel 0..{}",
                info.channels,
                info.channel_layout.describe(),
                info.channels - 1
            ),
        )),
        Some(c) if c >= info.channels => Err(Error::bad_input(
            Location::file(&info.path),
            format!(
                "channel {c} requested but the file has {} channel(s) (0..{})",
                info.channels,
                info.channels - 1
            ),
        )),
        c => Ok(c.unwrap_or(0)),
    }
}

/// Header facts of several files, opened once each, in first-use order.
struct FileTable {
    files: Vec<TiffInfo>,
    index: HashMap<PathBuf, usize>,
    channel: Option<usize>,
}

impl FileTable {
    fn new(channel: Option<usize>) -> Self {
        FileTable {
            files: Vec::new(),
            index: HashMap::new(),
            channel,
        }
    }

    fn get(&mut self, path: &Path) -> Result<&TiffInfo> {
        if let Some(&i) = self.index.get(path) {
            return Ok(&self.files[i]);
        }
        let info = TiffReader::open(path)?.info().clone();
        check_file(&info, self.files.first(), self.channel)?;
        self.index.insert(path.to_path_buf(), self.files.len());
        self.files.push(info);
        Ok(self.files.last().expect("just pushed"))
    }

    fn channel(&self) -> usize {
        self.channel.unwrap_or(0)
    }
}

/// Every page of the selected channel of every file, in order.
pub fn from_files(inputs: &[PathBuf], channel: Option<usize>) -> Result<Series> {
    let mut table = FileTable::new(channel);
    let mut images = Vec::new();
    for path in collect_files(inputs)? {
        let channel = table.channel();
        let pages = table.get(&path)?.pages_of_channel(channel);
        images.extend(pages.into_iter().map(|page| ImageRef {
            path: path.clone(),
            page,
            force_n: None,
            friction_n: None,
        }));
    }
    Ok(Series {
        images,
        channel: table.channel(),
        files: table.files,
        manifest: None,
    })
}

/// Give each image its force (newtons); the counts must agree.
pub fn assign_forces(series: &mut Series, forces_n: &[f64]) -> Result<()> {
    if forces_n.len() != series.images.len() {
        return Err(Error::InvalidArgument(format!(
            "{} force(s) given for {} image(s); give one force per image",
            forces_n.len(),
            series.images.len()
        )));
    }
    if let Some(bad) = forces_n.iter().find(|f| !f.is_finite() || **f < 0.0) {
        return Err(Error::InvalidArgument(format!(
            "force {} N is negative or not finite",
            bad
        )));
    }
    for (image, &f) in series.images.iter_mut().zip(forces_n) {
        image.force_n = Some(f);
    }
    Ok(())
}

fn manifest_number(
    row: &csv::StringRecord,
    column: Option<usize>,
    name: &str,
    at: &Location,
) -> Result<Option<f64>> {
    let Some(text) = column.and_then(|c| row.get(c)).map(str::trim) else {
        return Ok(None);
    };
    if text.is_empty() {
        return Ok(None);
    }
    let value: f64 = text
        .parse()
        .map_err(|_| Error::bad_input(at.clone(), format!("{name} '{text}' is not a number")))?;
    if !value.is_finite() || value < 0.0 {
        return Err(Error::bad_input(
            at.clone(),
            format!("{name} {text} must be a finite, non-negative number"),
        ));
    }
    Ok(Some(value))
}

/// Read a manifest CSV (`file`, optional `page`, `force_mN`, optional `friction_mN`).
pub fn from_manifest(manifest: &Path, channel: Option<usize>) -> Result<Series> {
    let at_manifest = Location::file(manifest);
    let text = std::fs::read_to_string(manifest).map_err(|e| Error::io(manifest, e))?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = reader
        .headers()
        .map_err(|e| Error::bad_input(at_manifest.clone(), format!("bad CSV header: {e}")))?
        .clone();
    let column = |name: &str| headers.iter().position(|h| h == name);
    let (Some(file_col), Some(force_col)) = (column("file"), column("force_mN")) else {
        return Err(Error::bad_input(
            at_manifest,
            format!(
                "manifest needs columns 'file' and 'force_mN' (found: {})",
                headers.iter().collect::<Vec<_>>().join(", ")
            ),
        ));
    };
    let (page_col, friction_col) = (column("page"), column("friction_mN"));
    let base = manifest.parent().unwrap_or(Path::new("."));
    let mut table = FileTable::new(channel);
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
        let force = manifest_number(&row, Some(force_col), "force_mN", &at)?
            .ok_or_else(|| Error::bad_input(at.clone(), "missing force_mN"))?;
        let friction = manifest_number(&row, friction_col, "friction_mN", &at)?;
        let page = resolve_page(&mut table, &path, &row, page_col, &at)?;
        images.push(ImageRef {
            path,
            page,
            force_n: Some(force * 1e-3),
            friction_n: friction.map(|f| f * 1e-3),
        });
    }
    if images.is_empty() {
        return Err(Error::bad_input(
            Location::file(manifest),
            "manifest lists no images",
        ));
    }
    Ok(Series {
        images,
        channel: table.channel(),
        files: table.files,
        manifest: Some(manifest.to_path_buf()),
    })
}

fn resolve_page(
    table: &mut FileTable,
    path: &Path,
    row: &csv::StringRecord,
    page_col: Option<usize>,
    at: &Location,
) -> Result<usize> {
    let channel = table.channel();
    let pages = table.get(path)?.pages_of_channel(channel);
    let text = page_col.and_then(|c| row.get(c)).unwrap_or("").trim();
    if text.is_empty() {
        return match pages.as_slice() {
            [only] => Ok(*only),
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
    if !pages.contains(&page) {
        return Err(Error::bad_input(
            at.clone(),
            format!(
                "page {page} is not in {} (its pages for channel {channel}: {})",
                path.display(),
                page_list(&pages)
            ),
        ));
    }
    Ok(page)
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
    fn natural_order() {
        let mut names = vec!["img10.tif", "img2.tif", "img1.tif", "img02.tif", "a.tif"];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            names,
            ["a.tif", "img1.tif", "img2.tif", "img02.tif", "img10.tif"]
        );
        assert_eq!(natural_cmp("T00009", "T00010"), Ordering::Less);
        assert_eq!(natural_cmp("x", "x"), Ordering::Equal);
    }

    #[test]
    fn page_lists_read_well() {
        assert_eq!(page_list(&[0, 1, 2, 3]), "0..3");
        assert_eq!(page_list(&[1, 3, 5]), "1,3,5");
        assert_eq!(page_list(&[4]), "4");
    }
}
