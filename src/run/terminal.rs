//! Whether a person watches stdout: the progress bar is drawn only then.

use std::io::IsTerminal;
use std::path::Path;

/// True when stdout is a terminal. Open MPI gives every rank a pseudo-terminal for stdout
/// whatever mpirun's own stdout is (a batch job's file, a pipe to a test), so under Open MPI the
/// answer is the launcher's: the rank's parent (mpirun, or the node's daemon) must write to a
/// terminal itself. A rank started by a remote daemon, whose stdout is not a terminal, answers
/// no: lines rather than a bar, the safe side.
pub fn stdout_is_terminal() -> bool {
    if !std::io::stdout().is_terminal() {
        return false;
    }
    if std::env::var_os("OMPI_COMM_WORLD_SIZE").is_none() {
        return true;
    }
    let parent = std::os::unix::process::parent_id();
    std::fs::read_link(format!("/proc/{parent}/fd/1")).is_ok_and(|t| is_terminal_device(&t))
}

/// A terminal device node: a pseudo-terminal (`/dev/pts/N`), a console (`/dev/ttyN`,
/// `/dev/console`).
fn is_terminal_device(target: &Path) -> bool {
    target.starts_with("/dev/pts")
        || target == Path::new("/dev/console")
        || target.to_str().is_some_and(|t| t.starts_with("/dev/tty"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terminal_devices_are_told_from_pipes_and_files() {
        for t in ["/dev/pts/0", "/dev/tty1", "/dev/console"] {
            assert!(is_terminal_device(Path::new(t)), "{t}");
        }
        for t in [
            "pipe:[1993665]",
            "/work/job.out",
            "/dev/null",
            "socket:[12]",
        ] {
            assert!(!is_terminal_device(Path::new(t)), "{t}");
        }
    }
}
