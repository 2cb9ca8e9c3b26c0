//! Errors of the core crate.
//!
//! A reader never panics on bad input: it returns a [`ParseError`] that names
//! the file, the 1-based line and column, and what was expected there, so the
//! user can open the file at that spot.

use std::fmt;
use std::path::PathBuf;

/// Where in a text file something went wrong (1-based line and column).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub path: PathBuf,
    pub line: usize,
    pub column: usize,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let path = self.path.display().to_string();
        write!(f, "{}:{}:{}", printable(&path), self.line, self.column)
    }
}

/// `text` with its control characters escaped (`\u{1b}`), line breaks and
/// tabs kept: messages quote words of the files they are about, and a file
/// can hold terminal escapes that would retitle or repaint the user's
/// terminal when the message is printed.
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    let hidden = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.chars().any(hidden) {
        return text.into();
    }
    let mut shown = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if hidden(c) {
            shown.extend(c.escape_default());
        } else {
            shown.push(c);
        }
    }
    shown.into()
}

/// A file that does not follow its format: where, and what was expected.
/// Printed with its control characters escaped ([`printable`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{location}: {}", printable(message))]
pub struct ParseError {
    pub location: Location,
    pub message: String,
}

impl ParseError {
    /// What is wrong at `line` and `column` (1-based) of the file at `path`.
    pub fn new(
        path: impl Into<PathBuf>,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> ParseError {
        ParseError {
            location: Location {
                path: path.into(),
                line,
                column,
            },
            message: message.into(),
        }
    }
}

/// Any error of the core crate.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Parse(#[from] ParseError),
    // The I/O error is part of the message rather than a `source`, so that
    // printing the error chain does not repeat it.
    #[error("{}: {error}", printable(&path.display().to_string()))]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// A request that does not fit the data (a joint that does not exist, a
    /// frame range outside the take, a body part the rig lacks...).
    #[error("{}", printable(.0))]
    Invalid(String),
}

impl Error {
    /// A [`ParseError`] at `line` and `column` (1-based) of the file at
    /// `path`.
    pub fn parse(
        path: impl Into<PathBuf>,
        line: usize,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        Error::Parse(ParseError::new(path, line, column, message))
    }

    pub fn io(path: impl Into<PathBuf>, error: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            error,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// The 1-based line and column (in characters) of a byte offset into
/// `text`, for errors of parsers that report offsets (TOML's spans).
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let mut end = offset.min(text.len());
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    let before = &text[..end];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}
