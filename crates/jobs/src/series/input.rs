//! Micrographs as a request carries them: files (folders, a manifest, CZI/ND2/LIF/OME-Zarr planes along a
//! load axis) or planes already in memory (Python hands over numpy arrays in their stored
//! sample type). Both become an [`OpenSeries`], whose [`Planes`] the analysis reads, so that a
//! series gives one threshold and one set of areas whichever front-end handed it over.

use std::path::PathBuf;

use contactscope::analysis::PlaneSource;
use contactscope::image::{Plane, SampleType};
use contactscope_formats::microscopy::select::{LoadAxis, Selection};
use contactscope_formats::param::Param;
use contactscope_formats::ranges::Quantity;

use super::{assign_forces, from_files_selected, from_manifest_selected, ImageRef, Series};
use super::{SeriesPlanes, DEFAULT_MEMORY_BUDGET};
use crate::error::{Error, Location, Result};

/// Files of a series: images (folders in natural order) or one manifest, which planes, and one
/// force per image when the files do not come with a manifest.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SeriesSpec {
    /// TIFF, CZI, ND2, LIF or OME-Zarr files, or folders of them (not with a manifest); a single folder
    /// holding `manifest.csv` (and no forces) is read as that manifest.
    pub inputs: Vec<PathBuf>,
    /// A manifest CSV (`file`, `page`, `force_mN` or `force_N`, `friction_mN`), or a folder
    /// holding `manifest.csv`.
    pub manifest: Option<PathBuf>,
    /// Which planes of confocal files (and the channel of TIFFs).
    pub selection: Selection,
    /// Axis of a CZI, ND2, LIF or OME-Zarr file whose planes are the loads.
    pub load_axis: Option<LoadAxis>,
    /// Normal forces, N, one per image (not with a manifest).
    pub forces_n: Option<Vec<f64>>,
}

/// Planes in memory: one per load, all of one size and sample type.
#[derive(Debug, Clone, PartialEq)]
pub struct MemorySeries {
    /// The images, in load order.
    pub planes: Vec<Plane>,
    /// Normal forces, N, one per image.
    pub forces_n: Option<Vec<f64>>,
    /// What to call the images in outputs and messages (`image 3` of it).
    pub label: String,
}

/// Micrographs as a request carries them.
#[derive(Debug, Clone, PartialEq)]
pub enum Micrographs {
    /// Files to read.
    Files(SeriesSpec),
    /// Planes in memory.
    Memory(MemorySeries),
}

impl Micrographs {
    /// Range checks of what the caller gave (the forces).
    pub fn check(&self) -> Result<()> {
        let forces = match self {
            Micrographs::Files(spec) => spec.forces_n.as_deref(),
            Micrographs::Memory(m) => m.forces_n.as_deref(),
        };
        for &f in forces.unwrap_or_default() {
            if f != 0.0 {
                Quantity::Force.check(f, Param::Forces)?;
            }
        }
        Ok(())
    }

    /// Open the series: read the files' headers (nothing is decoded yet) or take the planes.
    pub fn open(&self) -> Result<OpenSeries> {
        match self {
            Micrographs::Files(spec) => {
                // A manifest lists the images and their forces; a CSV, or a folder holding
                // `manifest.csv`, given as the only input (without forces) is one.
                let manifest = match (&spec.manifest, spec.inputs.as_slice(), &spec.forces_n) {
                    (Some(manifest), [], None) => Some(manifest),
                    (Some(_), _, _) => {
                        return Err(Error::InvalidArgument(format!(
                            "a manifest lists the images and their forces: give {} alone",
                            Param::Manifest
                        )))
                    }
                    (None, [only], None) if is_manifest(only) => Some(only),
                    (None, inputs, forces) => {
                        refuse_second_source(inputs, forces.is_some())?;
                        None
                    }
                };
                let mut series = match manifest {
                    Some(manifest) => from_manifest_selected(
                        &manifest_file(manifest)?,
                        &spec.selection,
                        spec.load_axis,
                    )?,
                    None => from_files_selected(&spec.inputs, &spec.selection, spec.load_axis)?,
                };
                if let Some(forces) = &spec.forces_n {
                    assign_forces(&mut series, forces)?;
                }
                Ok(OpenSeries {
                    series,
                    planes: None,
                })
            }
            Micrographs::Memory(m) => m.open(),
        }
    }
}

/// A manifest (a folder holding `manifest.csv`, or a CSV) among several inputs or beside forces
/// is refused: it lists the images and their forces itself, and reading the folder's images with
/// other forces, or ignoring the manifest, would be silently wrong (`analyze folder/
/// --forces 1mN..8mN:8` once analysed all 8 pages while the manifest listed 2).
fn refuse_second_source(inputs: &[PathBuf], forces_given: bool) -> Result<()> {
    let Some(manifest) = inputs.iter().find(|p| is_manifest(p)) else {
        return Ok(());
    };
    let what = if manifest.is_dir() {
        "holds manifest.csv, which lists the images and their forces"
    } else {
        "is a manifest (a CSV listing the images and their forces)"
    };
    let conflict = if forces_given {
        format!("{} would give the forces a second time", Param::Forces)
    } else {
        "other inputs beside it would be read without it".to_string()
    };
    Err(Error::bad_input(
        Location::file(manifest),
        format!(
            "{what}; {conflict}: give it alone (its forces are used), or the image files with {}",
            Param::Forces
        ),
    ))
}

/// Whether an input path names a manifest: a `.csv` file or a folder holding `manifest.csv`.
pub fn is_manifest(path: &std::path::Path) -> bool {
    path.join("manifest.csv").is_file()
        || (!path.is_dir()
            && path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("csv")))
}

/// The manifest a path names: a CSV, or a folder holding `manifest.csv`.
fn manifest_file(path: &std::path::Path) -> Result<PathBuf> {
    if !path.is_dir() {
        return Ok(path.to_path_buf());
    }
    let manifest = path.join("manifest.csv");
    if manifest.is_file() {
        Ok(manifest)
    } else {
        Err(Error::bad_input(
            Location::file(path),
            format!(
                "no manifest: give a manifest CSV (file, page, force_mN) or a folder holding \
                 manifest.csv, or image files with {}",
                Param::Forces
            ),
        ))
    }
}

impl MemorySeries {
    fn open(&self) -> Result<OpenSeries> {
        let first = self.planes.first().ok_or_else(|| {
            Error::InvalidArgument(format!("{}: the image stack is empty", self.label))
        })?;
        if first.is_empty() {
            return Err(Error::InvalidArgument(format!(
                "{}: the images have no pixels",
                self.label
            )));
        }
        for (i, p) in self.planes.iter().enumerate() {
            if (p.width, p.height, p.sample_type) != (first.width, first.height, first.sample_type)
            {
                return Err(Error::SeriesMismatch {
                    at: Location::page(&self.label, i),
                    reason: format!("{}×{} {}", p.width, p.height, p.sample_type.name()),
                    expected: format!(
                        "{}×{} {}",
                        first.width,
                        first.height,
                        first.sample_type.name()
                    ),
                });
            }
        }
        let mut series = Series {
            images: (0..self.planes.len())
                .map(|page| ImageRef {
                    path: PathBuf::from(&self.label),
                    page,
                    plane: None,
                    force_n: None,
                    friction_n: None,
                })
                .collect(),
            files: Vec::new(),
            channel: 0,
            manifest: None,
            selection: Selection::default(),
            load_axis: None,
            order: "the stack's first axis, as given".into(),
        };
        if let Some(forces) = &self.forces_n {
            assign_forces(&mut series, forces)?;
        }
        Ok(OpenSeries {
            series,
            planes: Some(self.planes.clone()),
        })
    }
}

/// A series ready for a job: its images with forces and file facts, and for a series in memory
/// its planes.
#[derive(Debug, Clone)]
pub struct OpenSeries {
    /// The images (for a series in memory, labelled `LABEL (page i)`; no files).
    pub series: Series,
    /// The planes of a series in memory.
    pub planes: Option<Vec<Plane>>,
}

impl OpenSeries {
    /// The planes as the analysis reads them, keeping up to `budget` bytes of decoded compressed
    /// planes of files between the passes.
    pub fn planes(&self, budget: usize) -> Planes<'_> {
        match &self.planes {
            Some(p) => Planes::Memory(p),
            None => Planes::Files(self.series.planes(budget)),
        }
    }

    /// The sample type of the images.
    pub fn sample_type(&self) -> SampleType {
        match &self.planes {
            Some(p) => p[0].sample_type,
            None => self.series.files[0].sample_type,
        }
    }

    /// The planes with the default memory budget.
    pub fn default_planes(&self) -> Planes<'_> {
        self.planes(DEFAULT_MEMORY_BUDGET)
    }
}

/// The planes of an [`OpenSeries`]: in memory, or decoded from the files on demand.
pub enum Planes<'a> {
    /// Planes in memory.
    Memory(&'a [Plane]),
    /// Planes of files.
    Files(SeriesPlanes<'a>),
}

impl PlaneSource for Planes<'_> {
    fn len(&self) -> usize {
        match self {
            Planes::Memory(p) => p.len(),
            Planes::Files(s) => s.len(),
        }
    }

    fn sample_type(&self) -> SampleType {
        match self {
            Planes::Memory(p) => PlaneSource::sample_type(*p),
            Planes::Files(s) => s.sample_type(),
        }
    }

    fn label(&self, index: usize) -> String {
        match self {
            Planes::Memory(p) => p.label(index),
            Planes::Files(s) => s.label(index),
        }
    }

    fn scan<T: Send, F: Fn(usize, &Plane) -> contactscope::Result<T> + Sync>(
        &self,
        f: F,
    ) -> contactscope::Result<Vec<T>> {
        match self {
            Planes::Memory(p) => p.scan(f),
            Planes::Files(s) => s.scan(f),
        }
    }
}

/// A series read whole into memory: what Python's `read_series` and `read_image` return.
#[derive(Debug, Clone)]
pub struct LoadedSeries {
    /// The planes in their stored sample type, in load order.
    pub planes: Vec<Plane>,
    /// Where each came from, with its force.
    pub images: Vec<ImageRef>,
    /// The pixel size: the override, else the files' metadata (they must agree).
    pub pixel_size: Option<contactscope::image::PixelSize>,
    /// Notes on the metadata, a missing pixel size.
    pub warnings: Vec<String>,
}

/// Read every image of the series the files name (as `analyze` reads them) into memory.
pub fn load(spec: &SeriesSpec, pixel_size_m: Option<(f64, f64)>) -> Result<LoadedSeries> {
    let micrographs = Micrographs::Files(spec.clone());
    micrographs.check()?;
    if let Some((x, y)) = pixel_size_m {
        Quantity::PixelSize.check(x, Param::PixelSize)?;
        Quantity::PixelSize.check(y, Param::PixelSize)?;
    }
    let open = micrographs.open()?;
    let mut warnings = Vec::new();
    // Reading does not need a pixel size: metadata that cannot be used (implausible, or files
    // that disagree) leave it unknown, with the reason, as `analyze` would refuse them.
    let pixel_size = match super::pixel_size(&open.series, pixel_size_m, None, &mut warnings) {
        Ok(p) => p,
        Err(e) => {
            warnings.push(format!(
                "{e}; the pixel size is left unknown (give {})",
                Param::PixelSize
            ));
            None
        }
    };
    let planes = open.default_planes().scan(|_, p| Ok(p.clone()))?;
    Ok(LoadedSeries {
        planes,
        images: open.series.images,
        pixel_size,
        warnings,
    })
}
