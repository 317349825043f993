//! The folder walk: an archive folder → a samplesheet. Every folder holding `manifest.csv` is a
//! series (its files are the manifest's; the walk does not look inside it further), and every
//! file whose name matches one of the patterns (`*.czi`, `*.nd2` and `*.lif` by default) is a
//! series of its own; with `tiff_folders`, so is every other folder holding TIFF files. A series'
//! id is its path below the archive with `/` as `-` (`sampleA/run1.czi` → `sampleA-run1`).
//! Hidden entries (names starting with `.`) and the batch's own output folder are skipped;
//! symbolic links are not followed. An OME-Zarr store (`*.zarr`, a folder) is one series taken
//! whole (`plate.ome.zarr` → `plate`); the walk never looks inside it. A folder holding TIFF files that no pattern takes, and no
//! manifest, is not a series unless `tiff_folders`: it is listed in [`Sheet::skipped`] with the
//! options that would take it (the batch prints it as a warning). The files of a multi-file
//! OME-TIFF set that a pattern takes one by one are one series, read from the first file that
//! holds the set's OME-XML. The walk is in natural order (`run2` before `run10`) and
//! writes the samplesheet it used, so that the next run can be edited by hand and repeated.

use std::path::{Component, Path, PathBuf};

use globset::{GlobSet, GlobSetBuilder};

use super::options::{Opt, SeriesOptions};
use super::sheet::{id_from, MetaColumn, MetaKind, Row, Sheet};
use crate::error::{Error, Location, Result};
use crate::series::natural_cmp;
use crate::series::one_file_per_set;
use contactscope_formats::microscopy::zarr::{self, ZarrReader};

/// The default patterns of single-file series: the vendor formats that hold a load series in
/// one file, and OME-Zarr stores (folders, taken whole).
pub const DEFAULT_PATTERNS: &[&str] = &["*.czi", "*.nd2", "*.lif", "*.zarr"];

/// What a folder walk takes.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkSpec {
    /// The archive folder.
    pub root: PathBuf,
    /// Glob patterns of file names that are series on their own (empty: [`DEFAULT_PATTERNS`]).
    pub patterns: Vec<String>,
    /// Folders holding TIFF files (and no `manifest.csv`) are series too.
    pub tiff_folders: bool,
}

/// Walk the archive; `skip` is a folder not to enter (the batch's output).
pub fn walk(spec: &WalkSpec, skip: Option<&Path>) -> Result<Sheet> {
    let root = &spec.root;
    let meta = std::fs::metadata(root).map_err(|e| Error::io(root, e))?;
    if !meta.is_dir() {
        return Err(Error::bad_input(
            Location::file(root),
            "not a folder: give an archive folder, or a samplesheet with --samplesheet",
        ));
    }
    let patterns = globs(&spec.patterns)?;
    let skip = skip.and_then(|s| s.canonicalize().ok());
    let mut found: Vec<(PathBuf, bool)> = Vec::new();
    // Folders of micrographs that are not series, with the reason.
    let mut skipped: Vec<String> = Vec::new();
    let mut entries = walkdir::WalkDir::new(root)
        .follow_links(false)
        .sort_by(|a, b| {
            natural_cmp(
                &a.file_name().to_string_lossy(),
                &b.file_name().to_string_lossy(),
            )
        })
        .into_iter();
    while let Some(entry) = entries.next() {
        let entry = entry.map_err(|e| {
            let path = e.path().unwrap_or(root).to_path_buf();
            match e.into_io_error() {
                Some(io) => Error::io(path, io),
                None => Error::bad_input(Location::file(path), "a folder loop"),
            }
        })?;
        let path = entry.path();
        let hidden = entry.depth() > 0 && entry.file_name().to_string_lossy().starts_with('.');
        let is_skipped = skip.as_ref().is_some_and(|s| {
            entry.file_type().is_dir() && path.canonicalize().ok().as_ref() == Some(s)
        });
        if hidden || is_skipped {
            if entry.file_type().is_dir() {
                entries.skip_current_dir();
            }
            continue;
        }
        if entry.file_type().is_dir() {
            if path.join("manifest.csv").is_file() {
                found.push((path.to_path_buf(), true));
                entries.skip_current_dir();
            } else if entry.depth() > 0 && zarr::is_store(path) {
                // An OME-Zarr store is one input: never a folder of files to look into.
                if patterns.is_match(entry.file_name()) {
                    found.push((path.to_path_buf(), false));
                } else {
                    skipped.push(format!(
                        "{}: an OME-Zarr store that no --pattern takes (add --pattern '*.zarr')",
                        path.display()
                    ));
                }
                entries.skip_current_dir();
            } else if spec.tiff_folders && holds_tiffs(path) {
                found.push((path.to_path_buf(), true));
            } else if let Some(n) = unmatched_tiffs(path, &patterns) {
                skipped.push(format!(
                    "{}: {n} TIFF file(s) and no manifest.csv; not taken as series (give \
                     --tiff-folders to take each such folder as one series, --pattern '*.tif' to \
                     take each multi-page TIFF as one, or put a manifest.csv in the folder)",
                    path.display()
                ));
            }
        } else if entry.file_type().is_file() && patterns.is_match(entry.file_name()) {
            found.push((path.to_path_buf(), false));
        }
    }
    let found = one_file_per_ome_set(found);
    if found.is_empty() {
        return Err(Error::bad_input(
            Location::file(root),
            format!(
                "no series found: no folder holds manifest.csv and no file matches {} (--pattern){}{}",
                pattern_list(&spec.patterns),
                if spec.tiff_folders {
                    " and no folder holds TIFF files"
                } else {
                    ""
                },
                match skipped.first() {
                    Some(first) => format!("; {first}"),
                    None => String::new(),
                }
            ),
        ));
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut origin: Vec<PathBuf> = Vec::new();
    let mut plates = false;
    for (path, folder) in found {
        let relative = path.strip_prefix(root).unwrap_or(&path).to_path_buf();
        let named = if folder {
            relative.clone()
        } else {
            // `plate.ome.zarr` → `plate`, `run1.czi` → `run1`.
            let bare = relative.with_extension("");
            match bare
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("ome"))
            {
                true => bare.with_extension(""),
                false => bare,
            }
        };
        let text: Vec<String> = named
            .components()
            .filter_map(|c| match c {
                Component::Normal(n) => Some(n.to_string_lossy().into_owned()),
                _ => None,
            })
            .collect();
        let id = match text.is_empty() {
            true => id_from(
                &root
                    .file_name()
                    .map_or("series".into(), |n| n.to_string_lossy()),
            ),
            false => id_from(&text.join("-")),
        };
        if let Some(k) = rows.iter().position(|r| r.id.eq_ignore_ascii_case(&id)) {
            return Err(Error::bad_input(
                Location::file(&path),
                format!(
                    "its series id '{id}' is also that of {} (ids ignore case and turn characters \
                     other than letters, digits, '.', '_', '-' into '_'); rename one, or write a \
                     samplesheet",
                    origin[k].display()
                ),
            ));
        }
        // An HCS plate: each field of each well a series of its own (`--series` in the sheet),
        // its well and field as metadata.
        let fields = match folder {
            false if zarr::is_store(&path) => ZarrReader::plate_fields(&path),
            _ => None,
        };
        let Some(fields) = fields else {
            rows.push(Row {
                line: 0,
                id,
                input_text: path.display().to_string(),
                input: path.clone(),
                options: Default::default(),
                metadata: Vec::new(),
            });
            origin.push(path);
            continue;
        };
        plates = true;
        for (index, field) in fields.iter().enumerate() {
            let mut options = SeriesOptions::default();
            options.0.insert(Opt::Series, index.to_string());
            let (well, f) = field.rsplit_once('/').unwrap_or((field.as_str(), ""));
            let field_id = id_from(&format!("{id}-{}", field.replace('/', "-")));
            if let Some(k) = rows
                .iter()
                .position(|r| r.id.eq_ignore_ascii_case(&field_id))
            {
                return Err(Error::bad_input(
                    Location::file(&path),
                    format!(
                        "its field {field} has the series id '{field_id}' of {}",
                        origin[k].display()
                    ),
                ));
            }
            rows.push(Row {
                line: 0,
                id: field_id,
                input_text: path.display().to_string(),
                input: path.clone(),
                options,
                metadata: vec![well.to_string(), f.to_string()],
            });
            origin.push(path.clone());
        }
    }
    // Plate fields carry their well and field; every other row leaves those cells empty.
    let mut metadata = Vec::new();
    if plates {
        for row in &mut rows {
            row.metadata.resize(2, String::new());
        }
        metadata = ["plate_well", "plate_field"]
            .iter()
            .map(|n| MetaColumn {
                name: n.to_string(),
                kind: MetaKind::Text,
            })
            .collect();
    }
    Ok(Sheet {
        label: root.clone(),
        base: PathBuf::new(),
        metadata,
        option_columns: Vec::new(),
        rows,
        sha256: String::new(),
        skipped,
    })
}

fn pattern_list(patterns: &[String]) -> String {
    if patterns.is_empty() {
        DEFAULT_PATTERNS.join(", ")
    } else {
        patterns.join(", ")
    }
}

fn globs(patterns: &[String]) -> Result<GlobSet> {
    let mut builder = GlobSetBuilder::new();
    let defaults: Vec<String> = DEFAULT_PATTERNS.iter().map(|p| p.to_string()).collect();
    for p in if patterns.is_empty() {
        &defaults
    } else {
        patterns
    } {
        let glob = globset::GlobBuilder::new(p)
            .case_insensitive(true)
            .literal_separator(true)
            .build()
            .map_err(|e| Error::InvalidArgument(format!("pattern '{p}': {e}")))?;
        builder.add(glob);
    }
    builder
        .build()
        .map_err(|e| Error::InvalidArgument(format!("patterns: {e}")))
}

/// The series found, each multi-file OME-TIFF set once ([`one_file_per_set`]: the set is read
/// whole from the file kept).
fn one_file_per_ome_set(found: Vec<(PathBuf, bool)>) -> Vec<(PathBuf, bool)> {
    let files: Vec<PathBuf> = found
        .iter()
        .filter(|(_, folder)| !folder)
        .map(|(p, _)| p.clone())
        .collect();
    let (kept, _) = one_file_per_set(files);
    let kept: std::collections::HashSet<PathBuf> = kept.into_iter().collect();
    found
        .into_iter()
        .filter(|(p, folder)| *folder || kept.contains(p))
        .collect()
}

/// The TIFF files of `dir` that no pattern takes as a series (`None` for none).
fn unmatched_tiffs(dir: &Path, patterns: &GlobSet) -> Option<usize> {
    let n = std::fs::read_dir(dir)
        .ok()?
        .filter_map(|e| e.ok())
        .filter(|e| {
            let name = e.file_name().to_string_lossy().to_ascii_lowercase();
            !name.starts_with('.')
                && (name.ends_with(".tif") || name.ends_with(".tiff"))
                && !patterns.is_match(e.file_name())
        })
        .count();
    (n > 0).then_some(n)
}

fn holds_tiffs(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries.filter_map(|e| e.ok()).any(|e| {
            let name = e.file_name().to_string_lossy().to_ascii_lowercase();
            !name.starts_with('.') && (name.ends_with(".tif") || name.ends_with(".tiff"))
        })
    })
}

/// `path` relative to the folder `base`, when both exist (through `..` where needed); the
/// absolute path otherwise. What a samplesheet written in `base` says of an input.
pub fn relative_to(path: &Path, base: &Path) -> String {
    let (Ok(target), Some(from)) = (path.canonicalize(), canonical_or_new(base)) else {
        return std::path::absolute(path)
            .unwrap_or_else(|_| path.to_path_buf())
            .display()
            .to_string();
    };
    let t: Vec<Component> = target.components().collect();
    let f: Vec<Component> = from.components().collect();
    let common = t.iter().zip(&f).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return target.display().to_string();
    }
    let mut rel = PathBuf::new();
    for _ in common..f.len() {
        rel.push("..");
    }
    for c in &t[common..] {
        rel.push(c.as_os_str());
    }
    if rel.as_os_str().is_empty() {
        ".".into()
    } else {
        rel.display().to_string()
    }
}

/// The canonical path of `path`, or for a folder yet to be made, its nearest existing
/// ancestor's canonical path with the rest appended.
fn canonical_or_new(path: &Path) -> Option<PathBuf> {
    if let Ok(c) = path.canonicalize() {
        return Some(c);
    }
    let absolute = std::path::absolute(path).ok()?;
    let mut rest = Vec::new();
    let mut at = absolute.as_path();
    loop {
        if let Ok(c) = at.canonicalize() {
            return Some(rest.iter().rev().fold(c, |p: PathBuf, n| p.join(n)));
        }
        rest.push(at.file_name()?.to_os_string());
        at = at.parent()?;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    #[test]
    fn manifests_vendor_files_and_tiff_folders_become_series() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("archive");
        for folder in [
            "glass/run2",
            "glass/run10",
            "steel/a b",
            "steel/tiffs",
            ".hidden/x",
            "out/x",
        ] {
            fs::create_dir_all(root.join(folder)).unwrap();
        }
        for manifest in ["glass/run2", "glass/run10", ".hidden/x", "out/x"] {
            fs::write(root.join(manifest).join("manifest.csv"), "file,force_mN\n").unwrap();
        }
        // A vendor file inside a manifest folder belongs to that series.
        fs::write(root.join("glass/run2/inside.czi"), "").unwrap();
        fs::write(root.join("steel/a b/ramp.CZI"), "").unwrap();
        fs::write(root.join("steel/tiffs/1.tif"), "").unwrap();
        fs::write(root.join("notes.txt"), "").unwrap();
        let spec = WalkSpec {
            root: root.clone(),
            patterns: Vec::new(),
            tiff_folders: false,
        };
        let sheet = walk(&spec, Some(&root.join("out"))).unwrap();
        let ids: Vec<&str> = sheet.rows.iter().map(|r| r.id.as_str()).collect();
        assert_eq!(ids, ["glass-run2", "glass-run10", "steel-a_b-ramp"]);
        assert_eq!(sheet.rows[2].input, root.join("steel/a b/ramp.CZI"));
        let with_tiffs = walk(
            &WalkSpec {
                tiff_folders: true,
                ..spec.clone()
            },
            Some(&root.join("out")),
        )
        .unwrap();
        assert_eq!(with_tiffs.rows.last().unwrap().id, "steel-tiffs");
        let tif_only = WalkSpec {
            patterns: vec!["*.tif".into()],
            ..spec.clone()
        };
        let ids: Vec<String> = walk(&tif_only, None)
            .unwrap()
            .rows
            .into_iter()
            .map(|r| r.id)
            .collect();
        assert_eq!(ids, ["glass-run2", "glass-run10", "out-x", "steel-tiffs-1"]);
    }

    #[test]
    fn clashing_ids_and_empty_archives_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        fs::create_dir_all(root.join("a b")).unwrap();
        fs::create_dir_all(root.join("a_b")).unwrap();
        let spec = WalkSpec {
            root: root.to_path_buf(),
            patterns: Vec::new(),
            tiff_folders: false,
        };
        let err = walk(&spec, None).unwrap_err().to_string();
        assert!(err.contains("no series found"), "{err}");
        for d in ["a b", "a_b"] {
            fs::write(root.join(d).join("manifest.csv"), "").unwrap();
        }
        let err = walk(&spec, None).unwrap_err().to_string();
        assert!(err.contains("'a_b' is also that of"), "{err}");
        let bad = WalkSpec {
            patterns: vec!["[".into()],
            ..spec
        };
        assert!(walk(&bad, None)
            .unwrap_err()
            .to_string()
            .contains("pattern '['"));
    }

    #[test]
    fn relative_paths_go_through_parents() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        fs::create_dir_all(root.join("archive/s1")).unwrap();
        fs::create_dir_all(root.join("results")).unwrap();
        assert_eq!(
            relative_to(&root.join("archive/s1"), &root.join("results")),
            "../archive/s1"
        );
        assert_eq!(
            relative_to(&root.join("results"), &root.join("results")),
            "."
        );
        assert_eq!(
            relative_to(&root.join("archive/s1"), &root.join("new/out")),
            "../../archive/s1"
        );
        assert!(relative_to(&root.join("missing"), &root.join("results")).starts_with('/'));
    }
}
