//! Rust errors as Python exceptions: a file that cannot be opened is an
//! `OSError` (`FileNotFoundError` when it is missing), everything else a
//! `mocap.MocapError` (a `ValueError`). The message is the Rust error's, so a
//! malformed file is named with its line and column as the CLI names it.

use std::io::ErrorKind;

use mocap_nn::{CapabilityError, NnError};
use mocap_search::SearchError;
use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyIsADirectoryError, PyNotADirectoryError, PyOSError,
    PyPermissionError, PyValueError,
};
use pyo3::PyErr;

pyo3::create_exception!(
    mocap,
    MocapError,
    PyValueError,
    "An input mocap cannot use: a malformed file (the message names its path, line and column), \
     a rig without a body part a method needs, arrays of the wrong shape."
);

/// The Python exception of a file that could not be read or written.
fn os_error(kind: ErrorKind, message: String) -> PyErr {
    match kind {
        ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
        ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
        ErrorKind::AlreadyExists => PyFileExistsError::new_err(message),
        ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
        ErrorKind::NotADirectory => PyNotADirectoryError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// A request or input that does not fit (raised by the bindings themselves).
pub fn invalid(message: impl Into<String>) -> PyErr {
    MocapError::new_err(message.into())
}

pub fn core(error: mocap_core::Error) -> PyErr {
    match &error {
        mocap_core::Error::Io { error: io, .. } => os_error(io.kind(), error.to_string()),
        _ => MocapError::new_err(error.to_string()),
    }
}

pub fn capability(error: CapabilityError) -> PyErr {
    match error {
        CapabilityError::Core(e) | CapabilityError::Nn(NnError::Core(e)) => core(e),
        other => MocapError::new_err(other.to_string()),
    }
}

pub fn search(error: SearchError) -> PyErr {
    if let SearchError::Io { error: io, .. } = &error {
        return os_error(io.kind(), error.to_string());
    }
    match error {
        SearchError::Core(e) => core(e),
        other => MocapError::new_err(other.to_string()),
    }
}

/// The error of a temporary file the bindings write for a file-to-file
/// entry point.
pub fn temporary(error: std::io::Error) -> PyErr {
    os_error(
        error.kind(),
        format!("a temporary folder for mocap: {error}"),
    )
}
