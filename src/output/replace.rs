//! Replacing a whole file so that its name always holds either the old or the complete new
//! contents: written to `NAME.tmp`, synced, renamed; the temporary is removed on failure.

use std::io::Write;
use std::path::{Path, PathBuf};

/// `path` with `.tmp` appended to its file name.
pub(crate) fn tmp_of(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".tmp");
    PathBuf::from(name)
}

/// Writes `bytes` to `path` through `path.tmp` and a rename. The error says what failed, for
/// the caller to put after `path` (`cannot write path.tmp: No space left on device ...`).
pub fn replace_file(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let tmp = tmp_of(path);
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes).and_then(|_| f.sync_all()))
        .and_then(|_| std::fs::rename(&tmp, path));
    written.map_err(|e| {
        // Best effort: the write already failed and the error says so.
        let _ = std::fs::remove_file(&tmp);
        format!("cannot write {}: {e}", tmp.display())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_whole_files_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("pfem-replace-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.txt");
        replace_file(&path, b"one").unwrap();
        replace_file(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        assert!(!tmp_of(&path).exists());
        let e = replace_file(&dir.join("no/such/b.txt"), b"x").unwrap_err();
        assert!(
            e.starts_with("cannot write") && e.contains("no/such/b.txt.tmp"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
