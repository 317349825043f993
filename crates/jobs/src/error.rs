//! Typed errors of the jobs: the errors of the layers below pass through unchanged
//! ([`Error::Format`], [`Error::Algorithm`]); the jobs add what concerns a request (its
//! arguments and their ranges), a series (manifests, forces) and the outputs (tables, plots,
//! folders). Every variant that concerns a file names it (and its page or line).

use std::path::PathBuf;

pub use contactscope_formats::error::Location;

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong running a command.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be read or is not what it claims to be.
    #[error(transparent)]
    Format(#[from] contactscope_formats::Error),
    /// An algorithm refused its input or did not converge.
    #[error(transparent)]
    Algorithm(contactscope::Error),
    /// The images of a series do not agree (shape, sample type, channels).
    #[error("{at}: {reason} (the series started with {expected})")]
    SeriesMismatch {
        /// First offending file and page.
        at: Location,
        /// What differs.
        reason: String,
        /// What the first image of the series had.
        expected: String,
    },
    /// Something about the input data or its description is wrong (manifest, forces, pages).
    #[error("{at}: {reason}")]
    BadInput {
        /// File (and page or line) concerned.
        at: Location,
        /// What is wrong.
        reason: String,
    },
    /// An argument or value given by the caller is invalid (unit, count, range).
    #[error("{0}")]
    InvalidArgument(String),
    /// A plot could not be drawn.
    #[error("plot: {0}")]
    Plot(String),
    /// Writing an output file failed.
    #[error("cannot write {path}: {reason}")]
    Output {
        /// Output file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
}

impl From<contactscope::Error> for Error {
    /// An algorithm's error; a file error or a job's own error that travelled through an
    /// algorithm (a sink or a plane source of this crate) comes back as what it was.
    fn from(e: contactscope::Error) -> Self {
        match e {
            contactscope::Error::Format(inner) => Error::Format(inner),
            contactscope::Error::External(boxed) => match boxed.downcast::<Error>() {
                Ok(job) => *job,
                Err(other) => Error::Algorithm(contactscope::Error::External(other)),
            },
            other => Error::Algorithm(other),
        }
    }
}

impl From<Error> for contactscope::Error {
    /// A job's error raised inside an algorithm's callback (a sink, a plane source).
    fn from(e: Error) -> Self {
        match e {
            Error::Algorithm(inner) => inner,
            Error::Format(inner) => contactscope::Error::Format(inner),
            other => contactscope::Error::External(Box::new(other)),
        }
    }
}

impl Error {
    /// An I/O error on a file (a [`contactscope_formats::Error::Io`], as the readers raise).
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Format(contactscope_formats::Error::io(path, source))
    }

    /// A bad-input error at a location.
    pub fn bad_input(at: Location, reason: impl Into<String>) -> Self {
        Error::BadInput {
            at,
            reason: reason.into(),
        }
    }
}
