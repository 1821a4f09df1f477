//! Plotting errors, each naming the file at fault.

use std::fmt;
use std::path::{Path, PathBuf};

/// Displays as `out/history.csv: line 4: "abc" in column lambda is not a number`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotError {
    /// The file or folder concerned: an input that cannot be read or a picture that cannot be
    /// written.
    pub file: PathBuf,
    /// What went wrong.
    pub message: String,
}

impl PlotError {
    pub(crate) fn new(file: &Path, message: impl Into<String>) -> Self {
        PlotError {
            file: file.to_path_buf(),
            message: message.into(),
        }
    }
}

impl fmt::Display for PlotError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file.display(), self.message)
    }
}

impl std::error::Error for PlotError {}

/// Turns a plotters drawing error into a [`PlotError`] on the picture `file`.
pub(crate) fn drawing<E: fmt::Display>(file: &Path) -> impl Fn(E) -> PlotError + '_ {
    move |e| PlotError::new(file, format!("cannot draw: {e}"))
}
