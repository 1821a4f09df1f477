//! Where a case file may be written. A write goes to `path.tmp` and is renamed over `path`, and
//! a rename replaces whatever is there: a device node, or the scene file the case is made from.
//! So the destination is checked first, and anything but a regular file (or nothing) is refused.

use std::fs::FileType;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::Path;

use super::error::{CaseError, CaseErrorKind};
use super::tmp_path;

fn refuse(path: &Path, message: String) -> CaseError {
    CaseError::new(path, CaseErrorKind::InvalidInput, message)
}

fn kind_of(t: FileType) -> &'static str {
    if t.is_dir() {
        "a directory"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_fifo() {
        "a named pipe"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_symlink() {
        "a symbolic link"
    } else {
        "not a regular file"
    }
}

/// Refuses a destination that is not a regular file or that is `input` itself (the same file
/// by device and inode, however it is spelled). Not collective: rank 0 asks, since rank 0
/// renames.
pub fn check_destination(path: &Path, input: Option<&Path>) -> Result<(), CaseError> {
    let spelled = path.as_os_str().as_bytes();
    if spelled.is_empty() || spelled.ends_with(b"/") || path.file_name().is_none() {
        return Err(refuse(
            path,
            "names a directory, not a file; give a file name such as case.h5".into(),
        ));
    }
    // Follows symbolic links: a link to /dev/null is refused as a device.
    if let Ok(meta) = std::fs::metadata(path) {
        if !meta.file_type().is_file() {
            return Err(refuse(
                path,
                format!(
                    "is {}; refusing to replace it with a case file",
                    kind_of(meta.file_type())
                ),
            ));
        }
        if let Some(input) = input.and_then(|i| std::fs::metadata(i).ok()) {
            if input.dev() == meta.dev() && input.ino() == meta.ino() {
                return Err(refuse(
                    path,
                    "is the scene file being read; refusing to overwrite it (write the case \
                     to another name, e.g. case.h5)"
                        .into(),
                ));
            }
        }
    }
    // The temporary is created in place (HDF5 truncates through a link), so it must be a plain
    // file or absent too.
    let tmp = tmp_path(path);
    if let Ok(meta) = std::fs::symlink_metadata(&tmp) {
        if !meta.file_type().is_file() {
            return Err(refuse(
                path,
                format!(
                    "its temporary {} is {}; remove it first",
                    tmp.display(),
                    kind_of(meta.file_type())
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_what_is_not_a_regular_file() {
        let dir = std::env::temp_dir().join(format!("pfem-dest-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let file = dir.join("a.h5");
        std::fs::write(&file, b"x").unwrap();
        assert!(check_destination(&file, None).is_ok());
        assert!(check_destination(&dir.join("new.h5"), None).is_ok());
        let e = check_destination(&dir.join("sub"), None).unwrap_err();
        assert!(e.message.contains("is a directory"), "{e}");
        let e = check_destination(Path::new("sub/"), None).unwrap_err();
        assert!(e.message.contains("names a directory"), "{e}");
        let e = check_destination(Path::new("/dev/null"), None).unwrap_err();
        assert!(e.message.contains("character device"), "{e}");
        let e = check_destination(&file, Some(&dir.join(".").join("a.h5"))).unwrap_err();
        assert!(e.message.contains("scene file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
