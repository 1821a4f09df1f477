//! Collective MPI-IO transfers of dataset hyperslabs.
//!
//! hdf5-metno's high-level reads and writes always use an independent-I/O transfer property
//! list; a collective transfer needs `H5Pset_dxpl_mpio` and the raw `H5Dread`/`H5Dwrite`.
//! Also the two system calls a write makes before it starts (`fallocate`, `statvfs`). This is
//! the only unsafe code of the case file.

use hdf5::{Dataset, Dataspace, Datatype, H5Type};
use hdf5_sys::h5d::{H5Dread, H5Dwrite};
use hdf5_sys::h5p::{H5FD_mpio_xfer_t, H5Pclose, H5Pcreate, H5Pset_dxpl_mpio};

enum Buffer<'a, T> {
    Source(&'a [T]),
    Target(&'a mut [T]),
}

fn transfer<T: H5Type>(
    ds: &Dataset,
    file_space: &Dataspace,
    buf: Buffer<'_, T>,
) -> hdf5::Result<()> {
    let len = match &buf {
        Buffer::Source(b) => b.len(),
        Buffer::Target(b) => b.len(),
    };
    if file_space.selection_size() != len {
        return Err(hdf5::Error::Internal(format!(
            "selection of {} elements for a buffer of {len}",
            file_space.selection_size()
        )));
    }
    // The memory dataspace is exactly the buffer, so HDF5 never touches memory outside it.
    let mem_space = Dataspace::try_new(len)?;
    let mem_type = Datatype::from_type::<T>()?;
    let class = *hdf5::globals::H5P_DATASET_XFER;
    let status = hdf5::sync::sync(|| {
        // SAFETY: all ids are live handles owned by the caller or created here; the buffer
        // holds `len` elements of `T`, matching `mem_type` and `mem_space` (checked above); the
        // transfer list is closed before returning.
        unsafe {
            let dxpl = H5Pcreate(class);
            if dxpl < 0 {
                return -1;
            }
            let mut status = H5Pset_dxpl_mpio(dxpl, H5FD_mpio_xfer_t::H5FD_MPIO_COLLECTIVE);
            if status >= 0 {
                let (d, m, s, f) = (ds.id(), mem_type.id(), mem_space.id(), file_space.id());
                status = match buf {
                    Buffer::Source(b) => H5Dwrite(d, m, s, f, dxpl, b.as_ptr().cast()),
                    Buffer::Target(b) => H5Dread(d, m, s, f, dxpl, b.as_mut_ptr().cast()),
                };
            }
            H5Pclose(dxpl);
            status
        }
    });
    if status < 0 {
        Err(hdf5::Error::query().unwrap_or_else(|e| e))
    } else {
        Ok(())
    }
}

/// Collective write of `data` into the elements of `ds` selected by `file_space`. Every rank of
/// the file's communicator must call it, with an empty selection if it has nothing to write.
pub fn write_collective<T: H5Type>(
    ds: &Dataset,
    file_space: &Dataspace,
    data: &[T],
) -> hdf5::Result<()> {
    transfer(ds, file_space, Buffer::Source(data))
}

/// Collective read of the elements of `ds` selected by `file_space` into `data`.
pub fn read_collective<T: H5Type>(
    ds: &Dataset,
    file_space: &Dataspace,
    data: &mut [T],
) -> hdf5::Result<()> {
    transfer(ds, file_space, Buffer::Target(data))
}

/// Outcome of [`reserve`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reserved {
    /// The blocks are allocated to the file (beyond its end; its size is unchanged).
    Yes,
    /// The file system cannot reserve (no `fallocate`); only its free space could be checked.
    Unsupported,
}

/// Allocates `bytes` of disk blocks to `file` without changing its size, so that writes up to
/// that size cannot fail for want of space. A full disk is `ErrorKind::StorageFull`.
pub fn reserve(file: &std::fs::File, bytes: u64) -> std::io::Result<Reserved> {
    use std::os::fd::AsRawFd;
    let len = libc::off_t::try_from(bytes).unwrap_or(libc::off_t::MAX);
    // SAFETY: `fallocate` only reads its integer arguments; the descriptor is owned by `file`,
    // which outlives the call.
    let rc = unsafe { libc::fallocate(file.as_raw_fd(), libc::FALLOC_FL_KEEP_SIZE, 0, len) };
    if rc == 0 {
        return Ok(Reserved::Yes);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EOPNOTSUPP) | Some(libc::ENOSYS) => Ok(Reserved::Unsupported),
        _ => Err(e),
    }
}

/// Bytes an unprivileged writer may still use on the file system holding `path`.
pub fn free_space(path: &std::path::Path) -> std::io::Result<u64> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(path.as_os_str().as_bytes())
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))?;
    let mut st = std::mem::MaybeUninit::<libc::statvfs>::zeroed();
    // SAFETY: `c` is a NUL-terminated path and `st` is writable storage for one `statvfs`,
    // which the call fills on success (zeroed beforehand, so it is initialised either way).
    let rc = unsafe { libc::statvfs(c.as_ptr(), st.as_mut_ptr()) };
    if rc != 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: zero-initialised above and filled by a successful call.
    let st = unsafe { st.assume_init() };
    Ok(st.f_bavail.saturating_mul(st.f_frsize))
}
