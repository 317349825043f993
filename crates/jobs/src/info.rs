//! The `info` job: the header facts of one TIFF file (pages, shape, sample type, compression,
//! channels, pixel size and where it came from).

use std::path::PathBuf;

use crate::error::Result;
use contactscope_formats::tiff::{TiffInfo, TiffReader};

/// Which file to describe.
#[derive(Debug, Clone)]
pub struct InfoRequest {
    /// A TIFF file.
    pub file: PathBuf,
}

/// Read the file's header facts; nothing is written.
pub fn run_info(request: &InfoRequest) -> Result<TiffInfo> {
    Ok(TiffReader::open(&request.file)?.info().clone())
}
