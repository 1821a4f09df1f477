//! Output errors, each naming the file or folder at fault, and their agreement across ranks.

use std::fmt;
use std::path::{Path, PathBuf};

use pfem_partition::{agree_on_error, Comm};

/// Displays as `out/fields/step_000012.h5: field "p" has 3 values for 4 owned particles`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputError {
    /// The file or folder concerned, as the caller's output folder names it.
    pub file: PathBuf,
    /// What went wrong.
    pub message: String,
}

impl OutputError {
    pub(crate) fn new(file: &Path, message: impl Into<String>) -> Self {
        OutputError {
            file: file.to_path_buf(),
            message: message.into(),
        }
    }
}

impl fmt::Display for OutputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.file.display(), self.message)
    }
}

impl std::error::Error for OutputError {}

/// Collective. `local` when every rank succeeded, otherwise the lowest failing rank's error on
/// every rank, so that no rank goes on into a collective call the others have abandoned.
pub(crate) fn agree<T>(comm: &Comm, local: Result<T, OutputError>) -> Result<T, OutputError> {
    // A NUL cannot occur in a path, so it separates the two parts unambiguously.
    let encoded = local
        .as_ref()
        .err()
        .map(|e| format!("{}\0{}", e.file.display(), e.message));
    match agree_on_error(comm, encoded) {
        None => local,
        Some(text) => {
            let (file, message) = text.split_once('\0').unwrap_or(("", text.as_str()));
            Err(OutputError::new(Path::new(file), message))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_the_file() {
        let e = OutputError::new(Path::new("out/fields.xdmf"), "cannot rename");
        assert_eq!(e.to_string(), "out/fields.xdmf: cannot rename");
    }
}
