//! Runs the case-file multi-rank self test (write on some ranks, read on others) (`examples/case_file_selftest.rs`) under `mpirun` on 1, 2 and
//! 3 ranks. MPI can be initialised only once per process, so multi-rank checks live in that
//! example binary and this test only launches it.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

const EXAMPLE: &str = "case_file_selftest";
const TIMEOUT: Duration = Duration::from_secs(300);

/// Finds the example next to this test binary (`target/<profile>/deps/<test>` ->
/// `target/<profile>/examples/<example>`); `cargo test` builds examples before running tests.
/// When only this test target was built (`cargo test --test mpi_selftest`), builds it first.
fn example_binary() -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("current_exe: {e}"))?;
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .ok_or_else(|| format!("unexpected test binary location {}", exe.display()))?;
    let binary = profile_dir
        .join("examples")
        .join(format!("{EXAMPLE}{}", std::env::consts::EXE_SUFFIX));
    if binary.is_file() {
        return Ok(binary);
    }
    let target_dir = profile_dir
        .parent()
        .ok_or_else(|| format!("no target dir above {}", profile_dir.display()))?;
    let mut cmd = Command::new(env!("CARGO"));
    cmd.args(["build", "--example", EXAMPLE, "--manifest-path"])
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml"))
        .env("CARGO_TARGET_DIR", target_dir);
    if profile_dir.file_name().is_some_and(|n| n == "release") {
        cmd.arg("--release");
    }
    let status = cmd
        .status()
        .map_err(|e| format!("cannot run cargo to build {EXAMPLE}: {e}"))?;
    if !status.success() || !binary.is_file() {
        return Err(format!("building {EXAMPLE} failed ({status})"));
    }
    Ok(binary)
}

fn drain(mut stream: impl Read + Send + 'static) -> thread::JoinHandle<String> {
    thread::spawn(move || {
        let mut s = String::new();
        let _ = stream.read_to_string(&mut s);
        s
    })
}

fn wait_with_timeout(child: &mut Child) -> Result<std::process::ExitStatus, String> {
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Ok(status),
            Ok(None) if start.elapsed() > TIMEOUT => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(format!("timed out after {TIMEOUT:?}"));
            }
            Ok(None) => thread::sleep(Duration::from_millis(50)),
            Err(e) => return Err(format!("wait failed: {e}")),
        }
    }
}

fn run_on(binary: &Path, ranks: u32) -> Result<String, String> {
    let mut child = Command::new("mpirun")
        .args(["-n", &ranks.to_string(), "--oversubscribe"])
        .arg(binary)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start mpirun (is OpenMPI installed?): {e}"))?;
    let out = drain(child.stdout.take().expect("piped stdout"));
    let err = drain(child.stderr.take().expect("piped stderr"));
    let status = wait_with_timeout(&mut child);
    let out = out.join().unwrap_or_default();
    let err = err.join().unwrap_or_default();
    match status {
        Ok(s) if s.success() => Ok(out),
        Ok(s) => Err(format!("{s}\nstdout:\n{out}\nstderr:\n{err}")),
        Err(e) => Err(format!("{e}\nstdout:\n{out}\nstderr:\n{err}")),
    }
}

#[test]
fn selftest_on_1_2_3_ranks() {
    let binary = example_binary().unwrap_or_else(|e| panic!("{e}"));
    let mut failures = Vec::new();
    for ranks in [1, 2, 3] {
        match run_on(&binary, ranks) {
            Ok(out) => print!("{out}"),
            Err(e) => failures.push(format!("-n {ranks}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
