//! `DIR/run.log`: every line the run prints for a person, the per-step line of every step in
//! full whatever the terminal shows, and the error a run ends with. Rank 0 appends to it, so a
//! restart in the same folder continues the log, and a batch job keeps its whole account even
//! when stdout went to a progress bar or to JSON.

use super::RunError;
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

pub struct RunLog {
    path: PathBuf,
    /// None once a write failed: the run goes on without its log (warned once).
    file: Option<File>,
    /// Bytes of whole lines in the file.
    len: u64,
}

impl RunLog {
    /// Opens `DIR/run.log` for appending (created if absent).
    pub fn open(dir: &Path) -> Result<RunLog, RunError> {
        let path = dir.join("run.log");
        let file = OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .map_err(|e| RunError::Io {
                path: path.clone(),
                message: format!("cannot open the run's log: {e}"),
            })?;
        let len = file.metadata().map(|m| m.len()).unwrap_or(0);
        Ok(RunLog {
            path,
            file: Some(file),
            len,
        })
    }

    /// Appends `line` and a newline, unbuffered, so a killed run's log ends at its last line.
    /// A log that cannot be written is not worth stopping an analysis for: the part of the line
    /// that was written is cut off again (the log keeps whole lines, as every file of a run is
    /// whole), one warning, then the run continues without it.
    pub fn line(&mut self, line: &str) {
        let Some(file) = self.file.as_mut() else {
            return;
        };
        let text = format!("{line}\n");
        match file.write_all(text.as_bytes()) {
            Ok(()) => self.len += text.len() as u64,
            Err(e) => {
                let _ = file.set_len(self.len);
                eprintln!(
                    "pfem-mpi: warning: {}: cannot write the run's log ({e}); the run continues \
                     without it",
                    self.path.display()
                );
                self.file = None;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_appended_across_opens() {
        let dir = std::env::temp_dir().join(format!("pfem-run-log-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let _ = std::fs::remove_file(dir.join("run.log"));
        RunLog::open(&dir).unwrap().line("first run");
        RunLog::open(&dir).unwrap().line("restart");
        let text = std::fs::read_to_string(dir.join("run.log")).unwrap();
        assert_eq!(text, "first run\nrestart\n");
        let missing = RunLog::open(&dir.join("no-such-folder")).err().unwrap();
        assert!(missing.to_string().contains("run.log"), "{missing}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
