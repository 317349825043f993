//! Multi-file OME-TIFF sets among the files of an input: a set is read whole from any file
//! whose OME-XML places planes in the others (`docs/formats.md`, "TIFF"), so each set is read
//! once — whichever of its files comes first, and whether its other files carry the set's
//! OME-XML too or only point to it (`BinaryOnly`: the reader follows the pointer to the master
//! TIFF or the companion file; a pointer it cannot follow leaves the file read alone).

use std::collections::{HashMap, HashSet};
use std::path::PathBuf;

use contactscope_formats::microscopy::select::is_tiff;
use contactscope_formats::microscopy::set_member;
use contactscope_formats::tiff::{TiffInfo, TiffReader};

/// The files to read, in order, and the TIFF headers opened to decide (by path, for the reader
/// to take instead of opening them again). A file is left out when a file kept before it, or a
/// file that places planes in others while it places none, names it as a file of its set. A
/// TIFF that cannot be opened is kept: reading it gives its own error.
pub(crate) fn one_file_per_set(files: Vec<PathBuf>) -> (Vec<PathBuf>, HashMap<PathBuf, TiffInfo>) {
    let mut headers = HashMap::new();
    if files.len() < 2 {
        return (files, headers);
    }
    // Each file's canonical path and the canonical paths of the other files of its set.
    let sets: Vec<(PathBuf, Vec<PathBuf>)> = files
        .iter()
        .map(|path| {
            let canonical = path.canonicalize().unwrap_or_else(|_| path.clone());
            let mut members = Vec::new();
            if is_tiff(path) {
                if let Ok(reader) = TiffReader::open(path) {
                    let info = reader.info().clone();
                    members = info
                        .set_files()
                        .into_iter()
                        .filter_map(|name| set_member(&info, name).ok())
                        .filter_map(|m| m.canonicalize().ok())
                        .collect();
                    headers.insert(path.clone(), info);
                }
            }
            (canonical, members)
        })
        .collect();
    // For each file, the files that name it as a file of their set (one pass over the sets:
    // a folder of thousands of plain TIFFs names none).
    let mut named_by: HashMap<&PathBuf, Vec<usize>> = HashMap::new();
    for (j, (_, members)) in sets.iter().enumerate() {
        for m in members {
            named_by.entry(m).or_default().push(j);
        }
    }
    let mut kept: Vec<usize> = Vec::new();
    let mut is_kept = vec![false; files.len()];
    for (i, (canonical, members)) in sets.iter().enumerate() {
        let namers = named_by.get(canonical).map(Vec::as_slice).unwrap_or(&[]);
        let by_kept = namers.iter().any(|&j| is_kept[j]);
        let pointer = members.is_empty() && namers.iter().any(|&j| j != i);
        if !by_kept && !pointer {
            kept.push(i);
            is_kept[i] = true;
        }
    }
    let chosen: Vec<PathBuf> = kept.iter().map(|&i| files[i].clone()).collect();
    let wanted: HashSet<&PathBuf> = chosen.iter().collect();
    headers.retain(|p, _| wanted.contains(p));
    (chosen, headers)
}
