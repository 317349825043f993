//! A load series: which page of which file is which load step, and its normal force.
//!
//! Inputs are one multi-page TIFF, several files, a directory of TIFFs (natural sort order, so
//! `img2` comes before `img10` and `load_1.25mN` before `load_1.5mN`: [`natural_cmp`]) or a
//! manifest CSV with columns `file`, optional `page`, `force_mN` and optional `friction_mN`,
//! paths relative to the manifest's folder. A TIFF gives the planes its axes and the selection
//! name (`contactscope_formats::microscopy::LoadDefault`).
//! Pages are zero-based TIFF page (IFD) indices, as tifffile numbers them.
//!
//! Zeiss CZI, Nikon ND2 and Leica LIF files ([`contactscope_formats::microscopy`]) are accepted as well,
//! detected by content: each gives the planes a [`Selection`] names (`--series`, `--channel`,
//! `--z`, `--t`): one plane per file, or, with a [`LoadAxis`] (`--load-axis t|z|series`), every
//! plane along that axis in order. For these files the "page" of an image (and a manifest's
//! `page` column) is its position along the load axis.
//!
//! [`SeriesPlanes`] is the file-backed plane source the series analysis
//! ([`contactscope::analysis::analyze`]) reads through, and [`pixel_size`] the series' pixel size from
//! the files' metadata or an override.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use rayon::prelude::*;
use serde::Serialize;

mod file;
mod input;
mod manifest;
mod ome_set;
mod order;
mod pixel;

pub use file::SeriesFile;
pub use input::{
    is_manifest, load, LoadedSeries, MemorySeries, Micrographs, OpenSeries, Planes, SeriesSpec,
};
pub use manifest::{from_manifest, from_manifest_selected};
pub(crate) use ome_set::one_file_per_set;
pub use order::natural_cmp;
pub use pixel::{
    pixel_size, pixel_size_warnings, PIXEL_SIZE_CONTRADICTION, SUB_DIFFRACTION_PIXEL_M,
};

use crate::error::{Error, Location, Result};
use contactscope::analysis::PlaneSource;
use contactscope::image::{Plane, SampleType, Samples};
use contactscope_formats::microscopy::select::{ChannelChoice, LoadAxis, SelectedPlane, Selection};
use contactscope_formats::microscopy::{zarr, LoadDefault, MicroscopyFile};
use contactscope_formats::param::Param;
use contactscope_formats::tiff::{TiffInfo, TiffReader};

/// One image of a series.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImageRef {
    /// File holding the image.
    pub path: PathBuf,
    /// Zero-based page (IFD index) in a TIFF; for CZI, ND2 and LIF files the position along
    /// the load axis (0 without one).
    pub page: usize,
    /// The plane of a CZI, ND2 or LIF file (`None` for TIFF pages).
    pub plane: Option<SelectedPlane>,
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
    pub files: Vec<SeriesFile>,
    /// Selected channel.
    pub channel: usize,
    /// The manifest the series came from, if any.
    pub manifest: Option<PathBuf>,
    /// The selection flags the series was built with.
    pub selection: Selection,
    /// The axis of CZI, ND2 or LIF files holding the loads, if any.
    pub load_axis: Option<LoadAxis>,
    /// How the images were put in load order, in words (`summary.json`'s `inputs.order`, and
    /// printed with the files): the manifest's rows, file names in natural order, the files
    /// as given, a file's planes.
    pub order: String,
}

impl Series {
    /// Header facts of the file holding image `i`.
    pub fn info_of(&self, path: &Path) -> Option<&SeriesFile> {
        self.files.iter().find(|f| f.path == path)
    }

    /// Every file the series reads images from: its files, each followed by the other files
    /// of its multi-file OME set that it reads planes from and the file its set's OME-XML was
    /// read from, where that is another file (a companion file).
    pub fn image_files(&self) -> Vec<PathBuf> {
        let mut all: Vec<PathBuf> = Vec::new();
        for f in &self.files {
            // The set's metadata file too (a companion `.companion.ome`): it places the planes.
            let metadata = f.tiff.as_ref().and_then(|t| t.metadata_file.as_deref());
            for p in std::iter::once(f.path.as_path())
                .chain(f.set_members())
                .chain(metadata)
            {
                if !all.iter().any(|a| a == p) {
                    all.push(p.to_path_buf());
                }
            }
        }
        all
    }
}

fn is_image_name(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| {
        ["tif", "tiff", "czi", "nd2", "lif"]
            .iter()
            .any(|x| e.eq_ignore_ascii_case(x))
    })
}

/// Expand inputs into files: directories give their image files (.tif, .tiff, .czi, .nd2,
/// .lif) and OME-Zarr stores in natural order, files are kept in the order given. An OME-Zarr
/// store (a folder) is one input, as a file is, and so is a URL.
pub fn collect_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    if inputs.is_empty() {
        return Err(Error::InvalidArgument("no input files given".into()));
    }
    let mut files = Vec::new();
    for input in inputs {
        // An object on a server (`s3://`, `https://`) is one input, file or store: a bucket
        // is not walked as a folder.
        if contactscope_formats::remote::is_url(input) {
            files.push(input.clone());
            continue;
        }
        let meta = std::fs::metadata(input).map_err(|e| Error::io(input, e))?;
        if !meta.is_dir() || zarr::is_store(input) {
            files.push(input.clone());
            continue;
        }
        let mut found: Vec<PathBuf> = std::fs::read_dir(input)
            .map_err(|e| Error::io(input, e))?
            .filter_map(|entry| entry.ok().map(|e| e.path()))
            .filter(|p| (p.is_file() && is_image_name(p)) || zarr::is_store(p))
            .collect();
        if found.is_empty() {
            return Err(Error::bad_input(
                Location::file(input),
                "directory holds no .tif, .tiff, .czi, .nd2 or .lif files nor OME-Zarr stores",
            ));
        }
        found.sort_by(|a, b| natural_cmp(&a.to_string_lossy(), &b.to_string_lossy()));
        files.extend(found);
    }
    Ok(files)
}

/// Check that a file's planes agree with the series' first file (size and sample type; the
/// channel count too between TIFF files).
fn check_file(file: &SeriesFile, first: Option<&SeriesFile>) -> Result<()> {
    let Some(first) = first else {
        return Ok(());
    };
    let both_tiff = file.tiff.is_some() && first.tiff.is_some();
    if (file.width, file.height, file.sample_type) != (first.width, first.height, first.sample_type)
        || (both_tiff && file.channels != first.channels)
    {
        let at = match &file.tiff {
            Some(info) => Location::page(&file.path, info.pages.first().copied().unwrap_or(0)),
            None => Location::file(&file.path),
        };
        return Err(Error::SeriesMismatch {
            at,
            reason: format!("image is {}", file.describe()),
            expected: first.describe(),
        });
    }
    Ok(())
}

/// Micrographs to threshold (`analyze`, `compare`): a TIFF of the series whose description says
/// it holds something other than intensities (a map written by `simulate`, a saved contact mask)
/// is refused naming what it holds and the command that reads it. Reading such a file as an
/// image (Python's `read_image`) is not refused.
pub fn refuse_maps(series: &Series) -> Result<()> {
    for info in series.files.iter().filter_map(|f| f.tiff.as_ref()) {
        refuse_map(info)?;
    }
    Ok(())
}

fn refuse_map(info: &TiffInfo) -> Result<()> {
    use contactscope_formats::tiff::write::quantity;
    let Some(q) = info.quantity.as_deref() else {
        return Ok(());
    };
    let hint = match q {
        quantity::INTENSITY => return Ok(()),
        quantity::HEIGHT => "read it with `contactscope topography` or `simulate --topography`",
        quantity::CONTACT => "compare a simulation's contact maps with `contactscope compare`",
        quantity::CONTACT_MASK => "a mask saved by `analyze --save-masks`",
        _ => "a map written by `contactscope simulate`",
    };
    let unit = info
        .value_unit
        .as_deref()
        .map_or(String::new(), |u| format!(" in {u}"));
    Err(Error::bad_input(
        Location::file(&info.path),
        format!(
            "holds {}{unit}, not a micrograph's intensities ({hint})",
            q.replace('_', " ")
        ),
    ))
}

/// Header facts of several files, opened once each, in first-use order.
struct FileTable {
    files: Vec<SeriesFile>,
    index: HashMap<PathBuf, usize>,
    selection: Selection,
    load_axis: Option<LoadAxis>,
    /// The files come from a manifest (which names their pages).
    manifest: bool,
    /// TIFF headers already read, taken by [`FileTable::get`] instead of reading them again.
    headers: HashMap<PathBuf, TiffInfo>,
}

impl FileTable {
    fn new(selection: Selection, load_axis: Option<LoadAxis>, manifest: bool) -> Self {
        FileTable {
            files: Vec::new(),
            index: HashMap::new(),
            selection,
            load_axis,
            manifest,
            headers: HashMap::new(),
        }
    }

    fn get(&mut self, path: &Path) -> Result<&SeriesFile> {
        if let Some(&i) = self.index.get(path) {
            return Ok(&self.files[i]);
        }
        let file = if contactscope_formats::microscopy::select::is_tiff(path) {
            let info = match self.headers.remove(path) {
                Some(info) => info,
                None => TiffReader::open(path)?.info().clone(),
            };
            // A manifest names a TIFF's pages one by one: a z stack's too.
            let default = match self.manifest {
                true => LoadDefault::AnyStack,
                false => LoadDefault::Series,
            };
            let (info, planes) = self.selection.tiff_planes(&info, self.load_axis, default)?;
            SeriesFile::from_tiff(info, planes)
        } else {
            SeriesFile::from_vendor(path, &self.selection, self.load_axis)?
        };
        check_file(&file, self.files.first())?;
        self.index.insert(path.to_path_buf(), self.files.len());
        self.files.push(file);
        Ok(self.files.last().expect("just pushed"))
    }

    /// The channel index read: the chosen index; for a channel chosen by name the index it
    /// named in the first file.
    fn channel(&self) -> usize {
        match &self.selection.channel {
            None => 0,
            Some(ChannelChoice::Index(i)) => *i,
            Some(ChannelChoice::Name(_)) => self
                .files
                .iter()
                .find_map(|f| f.planes.first().map(|p| p.index.c))
                .unwrap_or(0),
        }
    }

    fn into_series(
        self,
        images: Vec<ImageRef>,
        manifest: Option<PathBuf>,
        order: String,
    ) -> Series {
        Series {
            order,
            images,
            channel: self.channel(),
            files: self.files,
            manifest,
            selection: self.selection,
            load_axis: self.load_axis,
        }
    }
}

/// Every page of the selected channel of every file, in order.
pub fn from_files(inputs: &[PathBuf], channel: Option<usize>) -> Result<Series> {
    from_files_selected(inputs, &Selection::channel(channel), None)
}

/// The images of every file in order: every page of the channel of a TIFF; the planes the
/// selection names in a CZI, ND2 or LIF file (one plane, or every plane along `load_axis`).
pub fn from_files_selected(
    inputs: &[PathBuf],
    selection: &Selection,
    load_axis: Option<LoadAxis>,
) -> Result<Series> {
    let mut table = FileTable::new(selection.clone(), load_axis, false);
    let mut images = Vec::new();
    let files = collect_files(inputs)?;
    let planes = match load_axis {
        Some(axis) => format!("planes along {}", axis.name()),
        None => "planes in order".to_string(),
    };
    // A store is one input, as a file is: its planes are in the store's order.
    let folder = |p: &PathBuf| p.is_dir() && !zarr::is_store(p);
    let order = match (inputs.iter().any(folder), files.len()) {
        (true, _) => format!(
            "file names in natural order (numbers compared as numbers: load_1.25mN, \
             load_1.5mN, load_10mN), each file's {planes}"
        ),
        (false, 1) => format!("the file's {planes}"),
        (false, _) => format!("the files in the order given, each file's {planes}"),
    };
    // A multi-file OME set's files given together: its planes are read once.
    let (files, headers) = ome_set::one_file_per_set(files);
    table.headers = headers;
    for path in files {
        let planes = table.get(&path)?.images();
        images.extend(planes.into_iter().map(|(path, page, plane)| ImageRef {
            path,
            page,
            plane,
            force_n: None,
            friction_n: None,
        }));
    }
    Ok(table.into_series(images, None, order))
}

/// Give each image its force (newtons); the counts must agree.
pub fn assign_forces(series: &mut Series, forces_n: &[f64]) -> Result<()> {
    if forces_n.len() != series.images.len() {
        let along = series.load_axis.map_or(String::new(), |a| {
            format!(" (the planes along {} {})", Param::LoadAxis, a.name())
        });
        // Name the files, so that the person sees which images were counted.
        let mut files: Vec<String> = series
            .files
            .iter()
            .map(|f| f.path.display().to_string())
            .collect();
        if files.len() > 3 {
            let more = files.len() - 2;
            files.truncate(2);
            files.push(format!("… ({more} more files)"));
        }
        return Err(Error::InvalidArgument(format!(
            "{}: {} force(s) given for {} image(s) in {}{along}; give one force per image",
            Param::Forces,
            forces_n.len(),
            series.images.len(),
            files.join(", ")
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

/// Default budget for decoded planes of compressed files kept between the two passes of the
/// analysis.
pub const DEFAULT_MEMORY_BUDGET: usize = 128 << 20;

impl Series {
    /// The file-backed plane source of the series for [`contactscope::analysis`] (see
    /// [`SeriesPlanes`]).
    pub fn planes(&self, memory_budget: usize) -> SeriesPlanes<'_> {
        SeriesPlanes::new(self, memory_budget)
    }
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
    /// The planes of `series`, keeping up to `budget` bytes of decoded planes that cost more
    /// than a read from disk: compressed ones, and those fetched from a server (`s3://`,
    /// `https://`), which a second pass would download again.
    pub fn new(series: &'a Series, budget: usize) -> Self {
        let compressed = |path: &Path| {
            contactscope_formats::remote::is_url(path)
                || series
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

    fn plane(&self, reader: &mut Option<Reader>, i: usize) -> Result<Arc<Plane>> {
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

    fn read(&self, reader: &mut Option<Reader>, image: &ImageRef) -> Result<Plane> {
        if reader.as_ref().is_none_or(|r| r.path() != image.path) {
            *reader = Some(match image.plane {
                None => Reader::Tiff(Box::new(
                    match self
                        .series
                        .info_of(&image.path)
                        .and_then(|f| f.tiff.clone())
                    {
                        Some(info) => TiffReader::reopen(info)?,
                        None => TiffReader::open(&image.path)?,
                    },
                )),
                Some(_) => Reader::Vendor(Box::new(MicroscopyFile::open(&image.path)?)),
            });
        }
        let plane = match (reader.as_mut().expect("just opened"), &image.plane) {
            (Reader::Tiff(r), None) => r.read_page(image.page, self.series.channel)?,
            (Reader::Vendor(f), Some(p)) => f.read_plane(p.series, &p.index)?,
            _ => {
                return Err(Error::InvalidArgument(format!(
                    "{}: file changed its format during the analysis",
                    image.path.display()
                )))
            }
        };
        check_plane(&plane, self.series, image)?;
        Ok(plane)
    }
}

/// An open file of a series.
enum Reader {
    Tiff(Box<TiffReader>),
    Vendor(Box<MicroscopyFile>),
}

impl Reader {
    fn path(&self) -> &Path {
        match self {
            Reader::Tiff(r) => &r.info().path,
            Reader::Vendor(f) => &f.path,
        }
    }
}

/// Where an image is, for messages: `file (page 3)` or `file.czi (series 0, t 2, z 0, c 1)`.
pub fn image_location(image: &ImageRef) -> Location {
    match &image.plane {
        None => Location::page(&image.path, image.page),
        Some(p) => Location::file(format!("{} ({})", image.path.display(), p.describe())),
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
        image_location(&self.series.images[index]).to_string()
    }

    /// In parallel over runs of images of one file.
    fn scan<T: Send, F: Fn(usize, &Plane) -> contactscope::Result<T> + Sync>(
        &self,
        f: F,
    ) -> contactscope::Result<Vec<T>> {
        let groups = work_units(&self.series.images, rayon::current_num_threads());
        let results: Vec<Vec<(usize, contactscope::Result<T>)>> = groups
            .par_iter()
            .map(|indices| {
                let mut reader = None;
                let mut out = Vec::with_capacity(indices.len());
                for &i in indices {
                    let r = self
                        .plane(&mut reader, i)
                        .map_err(contactscope::Error::from)
                        .and_then(|p| {
                            let r = f(i, &p);
                            give_back(p);
                            r
                        });
                    let failed = r.is_err();
                    out.push((i, r));
                    if failed {
                        break;
                    }
                }
                out
            })
            .collect();
        let mut flat: Vec<(usize, contactscope::Result<T>)> =
            results.into_iter().flatten().collect();
        flat.sort_by_key(|(i, _)| *i);
        if let Some(pos) = flat.iter().position(|(_, r)| r.is_err()) {
            return Err(flat.swap_remove(pos).1.err().expect("is an error"));
        }
        Ok(flat.into_iter().map(|(_, r)| r.expect("checked")).collect())
    }
}

/// The codes of a plane no one else holds (not kept between the passes) go back to the TIFF
/// reader for the next page of this thread ([`contactscope_formats::tiff::spare`]).
fn give_back(plane: Arc<Plane>) {
    if let Ok(Plane {
        sample_type: SampleType::U16,
        samples: Samples::Int { codes, .. },
        ..
    }) = Arc::try_unwrap(plane)
    {
        contactscope_formats::tiff::spare::give_back(codes);
    }
}

fn check_plane(plane: &Plane, series: &Series, image: &ImageRef) -> Result<()> {
    let first = &series.files[0];
    if (plane.width, plane.height, plane.sample_type)
        != (first.width, first.height, first.sample_type)
    {
        return Err(Error::SeriesMismatch {
            at: image_location(image),
            reason: format!(
                "plane is {}×{} {}",
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
