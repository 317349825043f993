//! The record of one series (`records/ID.json` in the batch's folder): what it was made from
//! (every input file with size, modification time and SHA-256; the options in SI units; the
//! version), what became of it (status, error, times, the command lines of its folders) and its
//! numbers (one row per image, the series' fits), from which the batch's tables are built. A
//! record is written, atomically, after the series' folders: a batch killed at any moment keeps
//! every series it finished, and the next run redoes only what has no record or a stale one.
//!
//! A re-run compares a series with its record ([`Record::staleness`]): options, version, the
//! input's listing, then each file's size and modification time, and a file's hash only when
//! those differ. An unchanged archive is re-used without reading a byte of image data.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::options::OutputSettings;
use crate::analyze::Row;
use crate::error::{Error, Result};
use crate::provenance::{sha256_file, Stat};

/// How a series ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every stage succeeded.
    Ok,
    /// A stage failed: the record says which and why.
    Failed,
}

impl Status {
    /// `ok` or `failed`.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
        }
    }
}

/// One input file as a series used it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileRecord {
    /// As the batch named it.
    pub path: String,
    /// `image`, `manifest`, `topography` or `psf`; `seen` for a file of a series that failed before
    /// reading it (size and time only, no hash).
    pub role: String,
    /// Canonical path.
    pub canonical: PathBuf,
    /// Size, bytes.
    pub size_bytes: u64,
    /// Modification time, ns since the Unix epoch.
    pub modified_ns: u64,
    /// SHA-256 of the bytes, hex.
    pub sha256: String,
}

impl FileRecord {
    /// Stat and hash a file; also the number of bytes read.
    pub fn of(path: &Path, role: &str) -> Result<(FileRecord, u64)> {
        let stat = Stat::of(path)?;
        let (sha256, bytes) = sha256_file(path)?;
        let canonical = path.canonicalize().map_err(|e| Error::io(path, e))?;
        Ok((
            FileRecord {
                path: path.display().to_string(),
                role: role.to_string(),
                canonical,
                size_bytes: stat.size_bytes,
                modified_ns: u64::try_from(stat.modified_ns).unwrap_or(u64::MAX),
                sha256,
            },
            bytes,
        ))
    }
}

impl FileRecord {
    /// Size and time of a file, without its hash (`sha256` empty); `None` if it cannot be seen.
    pub fn stat_only(path: &Path, role: &str) -> Option<FileRecord> {
        let stat = Stat::of(path).ok()?;
        Some(FileRecord {
            path: path.display().to_string(),
            role: role.to_string(),
            canonical: path.canonicalize().ok()?,
            size_bytes: stat.size_bytes,
            modified_ns: u64::try_from(stat.modified_ns).unwrap_or(u64::MAX),
            sha256: String::new(),
        })
    }
}

/// The input path itself: a folder's listing of image files and manifest (what a folder input
/// reads), or a file's canonical path.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct InputState {
    /// Canonical path of the input, `None` when it does not exist.
    pub canonical: Option<PathBuf>,
    /// For a folder: the names of its TIFF, CZI, ND2, LIF files and `manifest.csv`, sorted.
    pub listing: Option<Vec<String>>,
}

impl InputState {
    /// The state of `input` now.
    pub fn of(input: &Path) -> InputState {
        let canonical = input.canonicalize().ok();
        let listing = input.is_dir().then(|| {
            let mut names: Vec<String> = std::fs::read_dir(input)
                .map(|entries| {
                    entries
                        .filter_map(|e| e.ok())
                        .map(|e| e.file_name().to_string_lossy().into_owned())
                        .filter(|n| {
                            let l = n.to_ascii_lowercase();
                            l == "manifest.csv"
                                || [".tif", ".tiff", ".czi", ".nd2", ".lif"]
                                    .iter()
                                    .any(|x| l.ends_with(x))
                        })
                        .collect()
                })
                .unwrap_or_default();
            names.sort();
            names
        });
        InputState { canonical, listing }
    }
}

/// The command lines that make a series' folders on their own.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct CommandLines {
    /// `contactscope analyze …` (`series/ID`).
    pub analyze: Vec<String>,
    /// `contactscope fit-hardening …` (`fit/ID`), for a series with a height map.
    pub fit_hardening: Option<Vec<String>>,
}

/// One image's numbers: the row of `areas.csv` (its `image` relative to the series' input: its
/// folder, or the file's name), and whether its contact touches the image border.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImageResult {
    /// The row as `analyze` has it.
    pub row: Row,
    /// A contact pixel lies on the image's border.
    pub edge_contact: bool,
}

impl std::ops::Deref for ImageResult {
    type Target = Row;

    fn deref(&self) -> &Row {
        &self.row
    }
}

/// The power law A = c·N^β of a series (N in mN, A in the area unit).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PowerLaw {
    /// c.
    pub prefactor: f64,
    /// β.
    pub exponent: f64,
    /// Standard error of β (none for two points).
    pub exponent_se: Option<f64>,
    /// 95 % interval of β (bootstrap over the images and their area intervals); none for
    /// fewer than three images or in a record written before intervals existed.
    #[serde(default)]
    pub exponent_ci95: Option<(f64, f64)>,
    /// R² in log–log (none from fewer than three distinct forces, or identical areas).
    pub r_squared: Option<f64>,
    /// Points fitted.
    pub points: usize,
}

/// A series' numbers (what `analyze` gave).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeriesResult {
    /// `um2` or `px`.
    pub area_unit: String,
    /// Sample type of the images (`uint16`, …).
    pub sample_type: String,
    /// Image size, pixels.
    pub width_px: usize,
    /// Image size, pixels.
    pub height_px: usize,
    /// Threshold method (`otsu-global`, `otsu-per-image`, `manual`).
    pub threshold_method: String,
    /// The one threshold of the series (none per image).
    pub threshold: Option<f64>,
    /// Pixel size used, µm (x, y).
    pub pixel_size_um: Option<(f64, f64)>,
    /// Where it came from (metadata field, or given).
    pub pixel_size_source: Option<String>,
    /// The pixel size was given (a samplesheet cell or the batch's default), not read.
    pub pixel_size_given: bool,
    /// The batch's own default gave the pixel size (no cell of the row, no file metadata used).
    pub pixel_size_from_default: bool,
    /// The pixel size's relative uncertainty the intervals carry (0: taken as exact).
    #[serde(default)]
    pub pixel_size_uncertainty: f64,
    /// The first file's metadata pixel size, µm (x, y), when it has one.
    pub metadata_pixel_size_um: Option<(f64, f64)>,
    /// The power-law fit.
    pub power_law: Option<PowerLaw>,
    /// p of A = N/p, MPa, and its points.
    pub proportional_mpa: Option<(f64, usize)>,
    /// Smallest and largest mean pressure, MPa.
    pub mean_pressure_range_mpa: Option<(f64, f64)>,
    /// `analyze`'s warnings.
    pub warnings: Vec<String>,
    /// One row per image, in load order.
    pub images: Vec<ImageResult>,
}

/// What `fit-hardening` gave a series.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct FitSummary {
    /// k, Pa/m.
    pub k_pa_per_m: Option<f64>,
    /// Its standard error.
    pub k_se_pa_per_m: Option<f64>,
    /// Its 95 % interval, Pa/m.
    #[serde(default)]
    pub k_ci95_pa_per_m: Option<(f64, f64)>,
    /// Misfit (RMS of ln A_sim/A_exp) of the hardening model.
    pub k_misfit: Option<f64>,
    /// Penetration hardness p_Y, Pa.
    pub hardness_pa: Option<f64>,
    /// Its standard error.
    pub hardness_se_pa: Option<f64>,
    /// Its 95 % interval, Pa.
    #[serde(default)]
    pub hardness_ci95_pa: Option<(f64, f64)>,
    /// Misfit of the hardness model.
    pub hardness_misfit: Option<f64>,
    /// Misfit of the elastic model.
    pub elastic_misfit: Option<f64>,
    /// Misfit of Greenwood–Tripp.
    pub gt_misfit: Option<f64>,
    /// The model with the lowest misfit.
    pub best_model: Option<String>,
    /// `fit-hardening`'s warnings.
    pub warnings: Vec<String>,
}

/// The record of one series.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// The series id.
    pub id: String,
    /// How it ended.
    pub status: Status,
    /// The one-line error of a failed series.
    pub error: Option<String>,
    /// The stage that failed: `inputs`, `analyze`, `fit-hardening` or `qc`.
    pub failed_stage: Option<String>,
    /// contactscope's version.
    pub contactscope_version: String,
    /// The source revision it was built from (`None`: unknown).
    pub source_revision: Option<String>,
    /// The options, in SI units.
    pub options: Value,
    /// The batch-wide output settings.
    pub settings: OutputSettings,
    /// The input path's state.
    pub input: InputState,
    /// Every input file read.
    pub files: Vec<FileRecord>,
    /// Bytes read to hash the inputs.
    pub bytes_hashed: u64,
    /// The command lines of its folders.
    pub command_lines: CommandLines,
    /// When the series started (RFC 3339).
    pub started: String,
    /// When it ended.
    pub finished: String,
    /// Wall time, s.
    pub seconds: f64,
    /// `analyze`'s numbers (also kept when a later stage failed).
    pub result: Option<SeriesResult>,
    /// `fit-hardening`'s numbers.
    pub fit: Option<FitSummary>,
    /// The folders it describes, by the SHA-256 of their summaries.
    #[serde(default)]
    pub outputs: Outputs,
}

/// The SHA-256 of the summary each of a series' folders holds (`series/ID/summary.json`,
/// `fit/ID/fit.json`; each holds its run's times, so no two runs' summaries are alike): a
/// folder that another run replaced no longer matches its record.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, Default)]
pub struct Outputs {
    /// Of `series/ID/summary.json`.
    pub series_summary_sha256: Option<String>,
    /// Of `fit/ID/fit.json`.
    pub fit_summary_sha256: Option<String>,
}

impl Outputs {
    /// The summaries of `task`'s folders as they are now.
    pub fn of(task: &super::SeriesTask) -> Outputs {
        let sha = |path: PathBuf| {
            std::fs::read(path)
                .ok()
                .map(|b| crate::provenance::sha256_bytes(&b))
        };
        Outputs {
            series_summary_sha256: sha(task.series_dir().join("summary.json")),
            fit_summary_sha256: sha(task.fit_dir().join("fit.json")),
        }
    }

    /// The first folder (`series/ID`, `fit/ID`) of `now` that differs from `self`.
    pub fn disagreement(&self, now: &Outputs, id: &str) -> Option<String> {
        if self.series_summary_sha256 != now.series_summary_sha256 {
            return Some(format!("series/{id}"));
        }
        if self.fit_summary_sha256 != now.fit_summary_sha256 {
            return Some(format!("fit/{id}"));
        }
        None
    }
}

/// Why a series is analysed again (or `None`: its record still holds).
pub type Staleness = Option<String>;

impl Record {
    /// The record's file in the batch folder.
    pub fn path(out: &Path, id: &str) -> PathBuf {
        out.join("records").join(format!("{id}.json"))
    }

    /// Read a record; `None` when there is none, or it cannot be read (then the series is
    /// done again).
    pub fn read(out: &Path, id: &str) -> Option<Record> {
        let bytes = std::fs::read(Record::path(out, id)).ok()?;
        serde_json::from_slice(&bytes).ok()
    }

    /// Write the record atomically.
    pub fn write(&self, out: &Path) -> Result<()> {
        let bytes = serde_json::to_vec_pretty(self)
            .map_err(|e| Error::InvalidArgument(format!("record of {}: {e}", self.id)))?;
        crate::staging::write_atomic(&Record::path(out, &self.id), &bytes)
    }

    /// Whether the record still describes the series made from `options` on `input` now;
    /// `Some(reason)` when it must be done again. Hashes a file only when its size or time
    /// changed, and reports the bytes so read in `hashed`. A file whose time changed but whose
    /// bytes did not gets its new time in `touched` (the caller re-writes the record).
    pub fn staleness(
        &self,
        options: &Value,
        settings: &OutputSettings,
        input: &Path,
        hashed: &mut u64,
        touched: &mut bool,
    ) -> Staleness {
        if self.contactscope_version != crate::provenance::version() {
            return Some(format!(
                "made by contactscope {} (this is {})",
                self.contactscope_version,
                crate::provenance::version()
            ));
        }
        if &self.options != options {
            return Some(changed_options(&self.options, options));
        }
        if &self.settings != settings {
            return Some("the batch's output settings changed".into());
        }
        let now = InputState::of(input);
        // The listing, not the path: the same archive read from another working directory,
        // or moved as a whole, is the same archive.
        if now.listing != self.input.listing
            || now.canonical.is_none() != self.input.canonical.is_none()
        {
            return Some(format!("{} changed (its listing or path)", input.display()));
        }
        for file in &self.files {
            let path = self.where_now(file, &now);
            // Named as the batch named it, or where it was looked for in a moved archive.
            let shown = match path == file.canonical {
                true => file.path.clone(),
                false => path.display().to_string(),
            };
            let Ok(stat) = Stat::of(&path) else {
                return Some(format!("{shown} is gone"));
            };
            // Found elsewhere (a moved archive): the record takes the new place.
            *touched |= path != file.canonical;
            if stat.size_bytes != file.size_bytes {
                return Some(format!("{shown} changed (size)"));
            }
            if u64::try_from(stat.modified_ns).ok() != Some(file.modified_ns) {
                if file.sha256.is_empty() {
                    // Seen, never hashed (its series failed before reading it): a new time is
                    // a change.
                    return Some(format!("{shown} changed (time)"));
                }
                match sha256_file(&path) {
                    Ok((sha, n)) => {
                        *hashed += n;
                        if sha != file.sha256 {
                            return Some(format!("{shown} changed (content)"));
                        }
                        *touched = true;
                    }
                    Err(_) => return Some(format!("{shown} cannot be read")),
                }
            }
        }
        None
    }

    /// Where a recorded file is now: its canonical path; for an archive that moved, the same
    /// place relative to the series' input (`now`) as it had to the input recorded.
    fn where_now(&self, file: &FileRecord, now: &InputState) -> PathBuf {
        let rebased = || {
            let (old, new) = (self.input.canonical.as_ref()?, now.canonical.as_ref()?);
            if old == new {
                return None;
            }
            // A folder input holds its files; a file input's files lie beside it.
            let root = |p: &Path| match self.input.listing {
                Some(_) => Some(p.to_path_buf()),
                None => p.parent().map(Path::to_path_buf),
            };
            let tail = file.canonical.strip_prefix(root(old)?).ok()?;
            Some(root(new)?.join(tail))
        };
        rebased().unwrap_or_else(|| file.canonical.clone())
    }

    /// The record with the files' current modification times (their bytes are unchanged), as
    /// found from `input` now.
    pub fn retouched(mut self, input: &Path) -> Record {
        let now = InputState::of(input);
        let places: Vec<(PathBuf, Option<u64>)> = self
            .files
            .iter()
            .map(|f| {
                let path = self.where_now(f, &now);
                let time = Stat::of(&path)
                    .ok()
                    .map(|s| u64::try_from(s.modified_ns).unwrap_or(u64::MAX));
                (path, time)
            })
            .collect();
        for (file, (path, time)) in self.files.iter_mut().zip(places) {
            if let Some(t) = time {
                if path != file.canonical {
                    file.path = path.display().to_string();
                    file.canonical = path;
                }
                file.modified_ns = t;
            }
        }
        self.input = now;
        self
    }
}

/// Which options differ, in words.
fn changed_options(old: &Value, new: &Value) -> String {
    let keys = |v: &Value| -> Vec<String> {
        v.as_object()
            .map(|m| m.keys().cloned().collect())
            .unwrap_or_default()
    };
    let mut names: Vec<String> = keys(old).into_iter().chain(keys(new)).collect();
    names.sort();
    names.dedup();
    let changed: Vec<String> = names
        .into_iter()
        .filter(|k| old.get(k) != new.get(k))
        .collect();
    format!("options changed: {}", changed.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn record(dir: &Path) -> (Record, PathBuf) {
        let file = dir.join("a.tif");
        std::fs::write(&file, b"0123456789").unwrap();
        let (f, n) = FileRecord::of(&file, "image").unwrap();
        assert_eq!(n, 10);
        let record = Record {
            id: "s1".into(),
            status: Status::Ok,
            error: None,
            failed_stage: None,
            contactscope_version: crate::provenance::version().into(),
            source_revision: None,
            options: json!({"pixel_size": [2e-7, 2e-7]}),
            settings: OutputSettings::default(),
            input: InputState::of(&file),
            files: vec![f],
            bytes_hashed: n,
            command_lines: CommandLines::default(),
            started: String::new(),
            finished: String::new(),
            seconds: 0.0,
            result: None,
            fit: None,
            outputs: Outputs::default(),
        };
        (record, file)
    }

    #[test]
    fn unchanged_inputs_are_not_read_and_changes_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let (record, file) = record(dir.path());
        let options = record.options.clone();
        let settings = OutputSettings::default();
        let (mut hashed, mut touched) = (0, false);
        let check = |r: &Record, o: &Value, h: &mut u64, t: &mut bool| {
            r.staleness(o, &settings, &file, h, t)
        };
        assert_eq!(check(&record, &options, &mut hashed, &mut touched), None);
        assert_eq!(
            (hashed, touched),
            (0, false),
            "size and time agree: nothing read"
        );
        // New bytes of the same size, the old time put back: not seen, by design.
        let time = std::fs::metadata(&file).unwrap().modified().unwrap();
        std::fs::write(&file, b"abcdefghij").unwrap();
        std::fs::File::options()
            .write(true)
            .open(&file)
            .unwrap()
            .set_modified(time)
            .unwrap();
        assert_eq!(check(&record, &options, &mut hashed, &mut touched), None);
        // A new time: hashed, and the change found.
        std::fs::File::options()
            .write(true)
            .open(&file)
            .unwrap()
            .set_modified(time + std::time::Duration::from_secs(5))
            .unwrap();
        let why = check(&record, &options, &mut hashed, &mut touched).unwrap();
        assert!(why.ends_with("changed (content)"), "{why}");
        assert_eq!(hashed, 10);
        // Only touched: same bytes, a new time.
        std::fs::write(&file, b"0123456789").unwrap();
        let (mut hashed, mut touched) = (0, false);
        assert_eq!(check(&record, &options, &mut hashed, &mut touched), None);
        assert!(touched);
        let retouched = record.clone().retouched(&file);
        let (mut hashed, mut touched) = (0, false);
        assert_eq!(check(&retouched, &options, &mut hashed, &mut touched), None);
        assert_eq!((hashed, touched), (0, false));
        // Options, size, a missing file.
        let why = check(
            &record,
            &json!({"pixel_size": [1e-7, 1e-7]}),
            &mut 0,
            &mut false,
        );
        assert_eq!(why.as_deref(), Some("options changed: pixel_size"));
        std::fs::write(&file, b"0123").unwrap();
        assert!(check(&record, &options, &mut 0, &mut false)
            .unwrap()
            .ends_with("(size)"));
        std::fs::remove_file(&file).unwrap();
        assert!(check(&record, &options, &mut 0, &mut false).is_some());
    }

    #[test]
    fn records_round_trip_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let (mut record, _) = record(dir.path());
        record.seconds = 0.1 + 0.2;
        record.write(dir.path()).unwrap();
        assert_eq!(Record::read(dir.path(), "s1"), Some(record));
        assert_eq!(Record::read(dir.path(), "s2"), None);
    }
}
