//! Issue 11, "never hang, never lie": each case fails with one message naming what is wrong and
//! a non-zero exit, within a time limit, and destroys nothing.

mod common;
use common::*;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Runs `pfem-mpi args` on one rank in `dir`, killed after `limit`; returns (success, stderr).
fn run_limited(dir: &Path, args: &[&str], limit: Duration) -> (bool, String) {
    let mut child = Command::new(bin())
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("launch pfem-mpi");
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("pfem-mpi {args:?} did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut stderr = String::new();
    use std::io::Read;
    let _ = child.stderr.take().unwrap().read_to_string(&mut stderr);
    (status.success(), stderr)
}

fn refused(dir: &Path, args: &[&str], needles: &[&str]) {
    let (ok, stderr) = run_limited(dir, args, Duration::from_secs(60));
    assert!(!ok, "{args:?} should fail");
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{args:?}: should say {n:?}:\n{stderr}");
    }
}

#[test]
fn new_refuses_to_replace_what_is_not_a_case_file() {
    let dir = workdir("faults-new-out");
    // A link to /dev/null stands for the device: without the check only the link is replaced.
    std::os::unix::fs::symlink("/dev/null", dir.join("null.h5")).unwrap();
    refused(
        &dir,
        &["new", "cantilever", "-o", "null.h5"],
        &["null.h5: is a character device", "refusing"],
    );
    assert!(std::fs::symlink_metadata(dir.join("null.h5"))
        .unwrap()
        .file_type()
        .is_symlink());

    std::fs::create_dir(dir.join("d")).unwrap();
    refused(
        &dir,
        &["new", "cantilever", "-o", "d/"],
        &["d/: names a directory"],
    );
    refused(
        &dir,
        &["new", "cantilever", "-o", "d"],
        &["d: is a directory"],
    );
    assert_eq!(std::fs::read_dir(dir.join("d")).unwrap().count(), 0);
    assert!(!dir.join("d.tmp").exists());

    let scene = include_str!("../src/scene/builtin/cantilever.toml");
    std::fs::write(dir.join("s.toml"), scene).unwrap();
    ok(&dir, 1, &["new", "s.toml", "-o", "s.h5"]);
    refused(
        &dir,
        &["new", "s.toml", "-o", "./s.toml"],
        &["./s.toml: is the scene file being read"],
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("s.toml")).unwrap(),
        scene,
        "the scene file must be left as it was"
    );
}
