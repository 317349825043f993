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
                    members = (0..info.axes.other_files.len())
                        .filter_map(|k| set_member(&info, k).ok())
                        .filter_map(|m| m.canonicalize().ok())
                        .collect();
                    headers.insert(path.clone(), info);
                }
            }
            (canonical, members)
        })
        .collect();
    let names = |j: usize, i: usize| sets[j].1.contains(&sets[i].0);
    let mut kept: Vec<usize> = Vec::new();
    for i in 0..files.len() {
        let by_kept = kept.iter().any(|&j| names(j, i));
        let pointer = sets[i].1.is_empty()
            && (0..files.len()).any(|j| j != i && !sets[j].1.is_empty() && names(j, i));
        if !by_kept && !pointer {
            kept.push(i);
        }
    }
    let chosen: Vec<PathBuf> = kept.iter().map(|&i| files[i].clone()).collect();
    let wanted: HashSet<&PathBuf> = chosen.iter().collect();
    headers.retain(|p, _| wanted.contains(p));
    (chosen, headers)
}
