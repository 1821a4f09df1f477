//! Case file errors: each names the file and, where there is one, the dataset, attribute or
//! field at fault.

use std::fmt;
use std::path::Path;

/// What kind of failure, for callers that react differently (e.g. to a too-new file).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CaseErrorKind {
    /// The file could not be read, created or renamed.
    Io,
    /// The file is not an HDF5 file.
    NotHdf5,
    /// An HDF5 file, but not a pfem-mpi case.
    NotACase,
    /// A case of a newer format version than this program reads.
    TooNew,
    /// A case whose contents are missing, mistyped, misshapen or truncated.
    Malformed,
    /// The caller passed inconsistent data (e.g. particle arrays of different lengths).
    InvalidInput,
}

impl CaseErrorKind {
    pub(crate) fn code(self) -> u8 {
        self as u8
    }

    pub(crate) fn from_code(code: u8) -> Self {
        use CaseErrorKind::*;
        [Io, NotHdf5, NotACase, TooNew, Malformed, InvalidInput]
            .into_iter()
            .find(|k| k.code() == code)
            .unwrap_or(Malformed)
    }
}

/// Displays as `case.h5: dataset /particles/position: expected shape (n, 2), found (729, 3)`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CaseError {
    /// The file, as the caller named it.
    pub file: String,
    /// The dataset, attribute or field at fault, e.g. `dataset /particles/position`.
    pub location: Option<String>,
    pub kind: CaseErrorKind,
    pub message: String,
}

impl CaseError {
    pub fn new(path: &Path, kind: CaseErrorKind, message: impl Into<String>) -> Self {
        CaseError {
            file: path.display().to_string(),
            location: None,
            kind,
            message: message.into(),
        }
    }

    pub fn at(mut self, location: impl Into<String>) -> Self {
        self.location = Some(location.into());
        self
    }
}

impl fmt::Display for CaseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: ", self.file)?;
        if let Some(loc) = &self.location {
            write!(f, "{loc}: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for CaseError {}
