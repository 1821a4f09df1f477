//! Writing an HDF5 file collectively so that a failure on any rank ends every rank at the same
//! point with the same error, and nothing is left under the file's final name.
//!
//! Two things made a full disk hang or crash a job. A failed HDF5 call returned on one rank
//! while the others went on into the next collective call (each rank then waited in a
//! different one). And a file whose metadata could not be flushed could not be closed: HDF5
//! kept it, and tore it down inside `MPI_Finalize`, which crashed. So the space a file needs is
//! reserved before HDF5 writes into it (a full disk is then a plain error before any HDF5
//! write), and every HDF5 step of the contents is followed by an agreement of all ranks, so
//! that any other failure stops every rank before its next collective call.

use std::path::{Path, PathBuf};

use hdf5::File;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use super::collective::agree;
use super::error::{CaseError, CaseErrorKind};
use super::ffi::{free_space, reserve, Reserved};
use super::{mpio_file, tmp_path};

/// Space for what is not raw data (superblock, object headers, B-trees), as measured on the
/// files this program writes (10-13 kB for a case, a checkpoint or a frame), with room to spare.
const METADATA_BYTES: u64 = 32 * 1024;

/// Disk space, in bytes, reserved for a file holding `raw` bytes of datasets and `text` bytes of
/// string attributes.
pub(crate) fn estimate(raw: u64, text: u64) -> u64 {
    raw.saturating_add(raw / 256)
        .saturating_add(text.saturating_mul(2))
        .saturating_add(METADATA_BYTES)
}

/// The HDF5 steps of one collective write, each agreed by every rank.
pub(crate) struct Lockstep<'a> {
    comm: &'a SimpleCommunicator,
    path: &'a Path,
    tmp: PathBuf,
}

impl Lockstep<'_> {
    /// Collective. `outcome` of this rank's part of step `what`, made the same on every rank:
    /// after an error anywhere, every rank returns it and calls nothing collective but the close.
    pub(crate) fn step<T>(&self, what: &str, outcome: hdf5::Result<T>) -> Result<T, CaseError> {
        let local = outcome.map_err(|e| {
            CaseError::new(
                self.path,
                CaseErrorKind::Io,
                format!("cannot write {}: {what}: {e}", self.tmp.display()),
            )
        });
        agree(self.comm, self.path, local)
    }

    /// Collective. The sum over ranks of `part` (wrapping).
    pub(crate) fn total(&self, part: u64) -> u64 {
        super::checksum::total(self.comm, part)
    }
}

fn io_error(path: &Path, tmp: &Path, bytes: u64, e: &std::io::Error) -> CaseError {
    let need = if e.kind() == std::io::ErrorKind::StorageFull {
        format!(" (the file needs about {} kB)", bytes.div_ceil(1024))
    } else {
        String::new()
    };
    CaseError::new(
        path,
        CaseErrorKind::Io,
        format!("cannot write {}: {e}{need}", tmp.display()),
    )
}

/// Reserves `bytes` for the file `tmp` (rank 0 only). Where the file system cannot reserve,
/// its free space is checked instead.
fn reserve_for(path: &Path, tmp: &Path, bytes: u64) -> Result<(), CaseError> {
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(tmp)
        .map_err(|e| io_error(path, tmp, bytes, &e))?;
    match reserve(&file, bytes) {
        Ok(Reserved::Yes) => Ok(()),
        Ok(Reserved::Unsupported) => {
            let dir = tmp
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            let free = free_space(dir).map_err(|e| io_error(path, tmp, bytes, &e))?;
            if free < bytes {
                let full = std::io::Error::from(std::io::ErrorKind::StorageFull);
                return Err(io_error(path, tmp, bytes, &full));
            }
            Ok(())
        }
        Err(e) => Err(io_error(path, tmp, bytes, &e)),
    }
}

/// Gives back the reserved blocks beyond the end of the finished file.
fn release(path: &Path, tmp: &Path) -> Result<(), CaseError> {
    let file = std::fs::OpenOptions::new()
        .write(true)
        .open(tmp)
        .map_err(|e| io_error(path, tmp, 0, &e))?;
    let len = file
        .metadata()
        .map_err(|e| io_error(path, tmp, 0, &e))?
        .len();
    file.set_len(len).map_err(|e| io_error(path, tmp, 0, &e))
}

/// Collective. Writes the HDF5 file `path` through `path.tmp`: rank 0 reserves `bytes` of disk
/// for it, every rank opens it (MPI-IO), `contents` writes it in agreed steps ([`Lockstep`]),
/// every rank closes it, and rank 0 renames it to `path`. On any error every rank returns the
/// same error, the temporary is removed and `path` is left as it was.
pub(crate) fn write_hdf5(
    comm: &SimpleCommunicator,
    path: &Path,
    bytes: u64,
    contents: impl FnOnce(&File, &Lockstep<'_>) -> Result<(), CaseError>,
) -> Result<(), CaseError> {
    let tmp = tmp_path(path);
    let root = comm.rank() == 0;
    let remove_tmp = || {
        if root {
            // Best effort: the write already failed; the error says so.
            let _ = std::fs::remove_file(&tmp);
        }
    };
    // Before HDF5 sees the file: a full disk is found here, with nothing to unwind.
    let probed = if root {
        reserve_for(path, &tmp, bytes)
    } else {
        Ok(())
    };
    if let Err(e) = agree(comm, path, probed) {
        remove_tmp();
        return Err(e);
    }
    let created = mpio_file(comm, &tmp, true).map_err(|e| {
        CaseError::new(
            path,
            CaseErrorKind::Io,
            format!("cannot create {}: {e}", tmp.display()),
        )
    });
    let file = match agree(comm, path, created) {
        Ok(f) => f,
        Err(e) => {
            remove_tmp();
            return Err(e);
        }
    };
    // Creating truncates the file, which gives the reserved blocks back: reserve them again.
    let reserved = if root {
        reserve_for(path, &tmp, bytes)
    } else {
        Ok(())
    };
    let step = Lockstep {
        comm,
        path,
        tmp: tmp.clone(),
    };
    let written = agree(comm, path, reserved).and_then(|_| contents(&file, &step));
    let closed = file.close().map_err(|e| {
        CaseError::new(
            path,
            CaseErrorKind::Io,
            format!("cannot close {}: {e}", tmp.display()),
        )
    });
    if let Err(e) = agree(comm, path, written.and(closed)) {
        remove_tmp();
        return Err(e);
    }
    let finished = if root {
        release(path, &tmp).and_then(|_| {
            std::fs::rename(&tmp, path).map_err(|e| {
                CaseError::new(
                    path,
                    CaseErrorKind::Io,
                    format!("cannot rename {} to it: {e}", tmp.display()),
                )
            })
        })
    } else {
        Ok(())
    };
    let finished = agree(comm, path, finished);
    if finished.is_err() {
        remove_tmp();
    }
    finished
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimate_covers_the_metadata_measured() {
        // A 63-particle case: 8 820 bytes of datasets, 636 of scene text, 20 148 on disk.
        assert!(estimate(8_820, 636) >= 20_148);
        // Its 5-step checkpoint on 2 ranks: 51 060 bytes of datasets, 63 348 on disk.
        assert!(estimate(51_060, 636) >= 63_348);
        assert_eq!(estimate(u64::MAX, 1), u64::MAX);
    }

    #[test]
    fn reserving_allocates_without_growing_the_file() {
        let dir = std::env::temp_dir().join(format!("pfem-reserve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.h5");
        let tmp = tmp_path(&path);
        reserve_for(&path, &tmp, 1 << 20).unwrap();
        assert_eq!(std::fs::metadata(&tmp).unwrap().len(), 0);
        // The fallback where a file system cannot reserve.
        assert!(free_space(&dir).unwrap() > 0);
        release(&path, &tmp).unwrap();
        // More than any disk holds: refused, naming the file.
        let e = reserve_for(&path, &tmp, 1 << 62).unwrap_err();
        assert!(
            e.to_string()
                .starts_with(&format!("{}: cannot write", path.display())),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
