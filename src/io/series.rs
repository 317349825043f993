//! A load series: which page of which file is which load step, and its normal force.
//!
//! Inputs are one multi-page TIFF, several files, a directory of TIFFs (natural sort order, so
//! `img2` comes before `img10`) or a manifest CSV with columns `file`, optional `page`,
//! `force_mN` and optional `friction_mN`, paths relative to the manifest's folder.
//! Pages are zero-based TIFF page (IFD) indices, as tifffile numbers them.
//!
//! [`SeriesPlanes`] is the file-backed plane source the series analysis
//! ([`crate::analysis::analyze`]) reads through, and [`pixel_size`] the series' pixel size from
//! the files' metadata or an override.

use std::cmp::Ordering;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use serde::Serialize;

use super::tiff::{TiffInfo, TiffReader};
use crate::analysis::PlaneSource;
use crate::error::{Error, Location, Result};
use crate::image::{PixelSize, PixelSizeSource, Plane, SampleType};
use crate::io::ranges::Quantity;

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
    crate::io::staging::note_input(manifest);
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
        Quantity::Force.check_at(force * 1e-3, &at)?;
        let friction = manifest_number(&row, friction_col, "friction_mN", &at)?;
        if let Some(f) = friction {
            Quantity::Force.check_at(f * 1e-3, &at)?;
        }
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

/// Default budget for decoded planes of compressed files kept between the two passes of the
/// analysis.
pub const DEFAULT_MEMORY_BUDGET: usize = 128 << 20;

impl Series {
    /// The file-backed plane source of the series for [`crate::analysis`] (see
    /// [`SeriesPlanes`]).
    pub fn planes(&self, memory_budget: usize) -> SeriesPlanes<'_> {
        SeriesPlanes::new(self, memory_budget)
    }
}

/// The pixel size for the whole series: the override, or the files' metadata if they agree.
///
/// Notes from the files' metadata, and the lack of any pixel size, are added to `warnings`.
pub fn pixel_size(
    series: &Series,
    override_m: Option<(f64, f64)>,
    warnings: &mut Vec<String>,
) -> Result<Option<PixelSize>> {
    if let Some((x_m, y_m)) = override_m {
        return Ok(Some(PixelSize {
            x_m,
            y_m,
            source: PixelSizeSource::CommandLine,
        }));
    }
    let first = &series.files[0];
    for other in &series.files[1..] {
        let agree = match (&first.pixel_size, &other.pixel_size) {
            (Some(a), Some(b)) => a.same_size(b),
            (None, None) => true,
            _ => false,
        };
        if !agree {
            let show = |p: &Option<PixelSize>| {
                p.map_or("no pixel size".to_string(), |p| {
                    format!("{:.6}×{:.6} µm", p.x_m * 1e6, p.y_m * 1e6)
                })
            };
            return Err(Error::SeriesMismatch {
                at: Location::file(&other.path),
                reason: format!("pixel size is {}", show(&other.pixel_size)),
                expected: format!("{}; give --pixel-size to override", show(&first.pixel_size)),
            });
        }
    }
    for f in &series.files {
        warnings.extend(f.notes.iter().map(|n| format!("{}: {n}", f.path.display())));
    }
    if let Some(p) = &first.pixel_size {
        let at = Location::file(&first.path);
        Quantity::PixelSize.check_at(p.x_m, &at)?;
        Quantity::PixelSize.check_at(p.y_m, &at)?;
    }
    if first.pixel_size.is_none() {
        warnings.push(
            "no pixel size in the files' metadata and no --pixel-size: areas are in pixels".into(),
        );
    }
    Ok(first.pixel_size)
}

/// The file-backed [`PlaneSource`] of a series: pages decoded on demand, each run of images of one
/// file with its own decoder, decoded planes of compressed files kept between the analysis'
/// passes up to a memory budget (re-reading an uncompressed page costs less than keeping it).
pub struct SeriesPlanes<'a> {
    series: &'a Series,
    cache: Mutex<Vec<Option<Arc<Plane>>>>,
    cacheable: Vec<bool>,
    budget_left: Mutex<usize>,
}

impl<'a> SeriesPlanes<'a> {
    /// The planes of `series`, keeping up to `budget` bytes of decoded compressed planes.
    pub fn new(series: &'a Series, budget: usize) -> Self {
        let compressed = |path: &Path| {
            series
                .info_of(path)
                .is_some_and(|info| info.compression != "none")
        };
        SeriesPlanes {
            series,
            cache: Mutex::new(vec![None; series.images.len()]),
            cacheable: series.images.iter().map(|i| compressed(&i.path)).collect(),
            budget_left: Mutex::new(budget),
        }
    }

    fn plane(&self, reader: &mut Option<TiffReader>, i: usize) -> Result<Arc<Plane>> {
        if let Some(p) = self.cache.lock().expect("lock")[i].clone() {
            return Ok(p);
        }
        let plane = Arc::new(self.read(reader, &self.series.images[i])?);
        let mut left = self.budget_left.lock().expect("lock");
        if self.cacheable[i] && plane.heap_bytes() <= *left {
            *left -= plane.heap_bytes();
            self.cache.lock().expect("lock")[i] = Some(plane.clone());
        }
        Ok(plane)
    }

    fn read(&self, reader: &mut Option<TiffReader>, image: &ImageRef) -> Result<Plane> {
        if reader.as_ref().is_none_or(|r| r.info().path != image.path) {
            *reader = Some(TiffReader::open(&image.path)?);
        }
        let reader = reader.as_mut().expect("just opened");
        let plane = reader.read_page(image.page, self.series.channel)?;
        check_plane(&plane, self.series, &image.path, image.page)?;
        Ok(plane)
    }
}

impl PlaneSource for SeriesPlanes<'_> {
    fn len(&self) -> usize {
        self.series.images.len()
    }

    fn sample_type(&self) -> SampleType {
        self.series.files[0].sample_type
    }

    fn label(&self, index: usize) -> String {
        let image = &self.series.images[index];
        Location::page(&image.path, image.page).to_string()
    }

    /// In parallel over runs of images of one file.
    fn scan<T: Send, F: Fn(usize, &Plane) -> Result<T> + Sync>(&self, f: F) -> Result<Vec<T>> {
        let groups = work_units(&self.series.images, rayon::current_num_threads());
        let results: Vec<Vec<(usize, Result<T>)>> = groups
            .par_iter()
            .map(|indices| {
                let mut reader = None;
                let mut out = Vec::with_capacity(indices.len());
                for &i in indices {
                    let r = self.plane(&mut reader, i).and_then(|p| f(i, &p));
                    let failed = r.is_err();
                    out.push((i, r));
                    if failed {
                        break;
                    }
                }
                out
            })
            .collect();
        let mut flat: Vec<(usize, Result<T>)> = results.into_iter().flatten().collect();
        flat.sort_by_key(|(i, _)| *i);
        if let Some(pos) = flat.iter().position(|(_, r)| r.is_err()) {
            return Err(flat.swap_remove(pos).1.err().expect("is an error"));
        }
        Ok(flat.into_iter().map(|(_, r)| r.expect("checked")).collect())
    }
}

fn check_plane(plane: &Plane, series: &Series, path: &Path, page: usize) -> Result<()> {
    let first = &series.files[0];
    if (plane.width, plane.height, plane.sample_type)
        != (first.width, first.height, first.sample_type)
    {
        return Err(Error::SeriesMismatch {
            at: Location::page(path, page),
            reason: format!(
                "page is {}×{} {}",
                plane.width,
                plane.height,
                plane.sample_type.name()
            ),
            expected: format!(
                "{}×{} {}",
                first.width,
                first.height,
                first.sample_type.name()
            ),
        });
    }
    Ok(())
}

/// Units of parallel work: the image indices of each file (files in first-use order), split into
/// runs short enough that a single multi-page file keeps every thread busy. Each unit opens its
/// own decoder.
fn work_units(images: &[ImageRef], threads: usize) -> Vec<Vec<usize>> {
    let mut by_file: HashMap<&Path, usize> = HashMap::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for (i, image) in images.iter().enumerate() {
        let g = *by_file.entry(&image.path).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(i);
    }
    let run = images.len().div_ceil(4 * threads.max(1)).max(1);
    groups
        .iter()
        .flat_map(|g| g.chunks(run).map(<[usize]>::to_vec))
        .collect()
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
