//! Typed errors of the file formats. Every variant names the file and, where it matters, the
//! page or line, so that a front-end can print one self-explaining line.

use std::path::PathBuf;

use crate::param::{front_end, FrontEnd, Param};
use crate::ranges::Quantity;

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Where in the input an error was found: a file and, for multi-page files, a page.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file as the user named it (or as found in a directory or manifest).
    pub path: PathBuf,
    /// Zero-based TIFF page (IFD index), when the error concerns one page.
    pub page: Option<usize>,
}

impl Location {
    /// A whole file.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Location {
            path: path.into(),
            page: None,
        }
    }

    /// One page of a file.
    pub fn page(path: impl Into<PathBuf>, page: usize) -> Self {
        Location {
            path: path.into(),
            page: Some(page),
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.page {
            Some(p) => write!(f, "{} (page {p})", self.path.display()),
            None => write!(f, "{}", self.path.display()),
        }
    }
}

/// Everything that can go wrong reading (or encoding) a file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The file could not be opened, read or written.
    #[error("{at}: {source}")]
    Io {
        /// File concerned.
        at: Location,
        /// Underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a TIFF, or its structure is broken (truncated, bad offsets, bad tags).
    #[error("{at}: not a readable TIFF: {reason}")]
    BadTiff {
        /// File and page concerned.
        at: Location,
        /// What the decoder reported.
        reason: String,
    },
    /// A valid file that uses a feature contactscope does not read.
    #[error("{at}: unsupported: {reason}")]
    Unsupported {
        /// File and page concerned.
        at: Location,
        /// What is unsupported and, where there is one, the way out.
        reason: String,
    },
    /// Something about the file's content is wrong (a header, a size, a value).
    #[error("{at}: {reason}")]
    BadInput {
        /// File (and page) concerned.
        at: Location,
        /// What is wrong.
        reason: String,
    },
    /// A value outside its plausible range (a typo or a wrong unit), given as a parameter.
    #[error("{}", out_of_range(*param, *quantity, *value))]
    OutOfRange {
        /// The parameter it was given as.
        param: Param,
        /// What it is.
        quantity: Quantity,
        /// The value, SI.
        value: f64,
    },
    /// An argument given by the caller is invalid (a selection, a unit).
    #[error("{0}")]
    InvalidArgument(String),
    /// Encoding an output failed.
    #[error("cannot write {path}: {reason}")]
    Output {
        /// Output file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
}

impl Error {
    /// An I/O error on a file.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            at: Location::file(path),
            source,
        }
    }

    /// A bad-input error at a location.
    pub fn bad_input(at: Location, reason: impl Into<String>) -> Self {
        Error::BadInput {
            at,
            reason: reason.into(),
        }
    }
}

/// The message of [`Error::OutOfRange`]: the parameter as the front-end names it, the value in the
/// unit its range is written in, and for a caller who gives SI numbers an example.
fn out_of_range(param: Param, quantity: Quantity, value: f64) -> String {
    match front_end() {
        FrontEnd::Python => format!(
            "{param}{value:e}: {} (SI units: {})",
            quantity.refusal(value),
            quantity.si_example()
        ),
        _ => format!("{param}: {}", quantity.refusal(value)),
    }
}
