//! Errors of motion search.

use std::path::PathBuf;

/// Anything that can go wrong while building, loading or querying an index.
#[derive(Debug, thiserror::Error)]
pub enum SearchError {
    /// A motion file could not be read, or its skeleton lacks a body part
    /// the features need.
    #[error(transparent)]
    Core(#[from] mocap_core::Error),
    /// (The I/O error is in the message, not a `source`, so that printing
    /// the error chain does not repeat it, as in `mocap_core::Error::Io`.)
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// A label pattern, label file or clip name that does not give a label.
    #[error("{0}")]
    Labels(String),
    /// A file that is not a search index, or one that is damaged.
    #[error("{path}: {message}")]
    BadIndex { path: PathBuf, message: String },
    /// An index written by another version of the index format or of the
    /// features: it must be rebuilt.
    #[error("{path}: {message}; rebuild it with `mocap search index`")]
    StaleIndex { path: PathBuf, message: String },
    /// A request that does not fit the data (too few clips, an empty class...).
    #[error("{0}")]
    Invalid(String),
}

pub type Result<T, E = SearchError> = std::result::Result<T, E>;
