//! Runs the ParaView output self test (`examples/xdmf_selftest.rs`) under `mpirun` on 1, 2 and
//! 3 ranks, then checks each output folder with an independent reader, `tests/check_xdmf.py`
//! (Python: xml.etree + h5py, and meshio when it is installed). MPI can be initialised only once
//! per process, so the writing happens in the example binary.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

const EXAMPLE: &str = "xdmf_selftest";
const TIMEOUT: Duration = Duration::from_secs(300);

/// Finds the example next to this test binary (`target/<profile>/deps/<test>` ->
/// `target/<profile>/examples/<example>`); `cargo test` builds examples before running tests.
/// When only this test target was built (`cargo test --test xdmf_output`), builds it first.
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

/// Runs `cmd` to completion (with the timeout), returning its stdout, or a report of how it
/// failed with both streams.
fn run(mut cmd: Command, what: &str) -> Result<String, String> {
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start {what}: {e}"))?;
    let out = drain(child.stdout.take().expect("piped stdout"));
    let err = drain(child.stderr.take().expect("piped stderr"));
    let status = wait_with_timeout(&mut child);
    let out = out.join().unwrap_or_default();
    let err = err.join().unwrap_or_default();
    match status {
        Ok(s) if s.success() => Ok(out),
        Ok(s) => Err(format!("{what}: {s}\nstdout:\n{out}\nstderr:\n{err}")),
        Err(e) => Err(format!("{what}: {e}\nstdout:\n{out}\nstderr:\n{err}")),
    }
}

fn write_on(binary: &Path, ranks: u32, dir: &Path) -> Result<String, String> {
    let mut cmd = Command::new("mpirun");
    cmd.args(["-n", &ranks.to_string(), "--oversubscribe"])
        .arg(binary)
        .arg(dir)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    run(
        cmd,
        &format!("mpirun -n {ranks} {EXAMPLE} (is OpenMPI installed?)"),
    )
}

fn check_with_python(dir: &Path) -> Result<String, String> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/check_xdmf.py");
    let mut cmd = Command::new("python3");
    cmd.arg(script).arg(dir);
    run(cmd, "python3 tests/check_xdmf.py")
}

fn python_has(module: &str) -> bool {
    Command::new("python3")
        .args(["-c", &format!("import {module}")])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

fn pip_install(packages: &[&str]) -> String {
    let out = Command::new("python3")
        .args(["-m", "pip", "install", "--quiet"])
        .args(packages)
        .output();
    match out {
        Ok(o) if o.status.success() => String::new(),
        Ok(o) => format!(
            "`python3 -m pip install --quiet {}` failed ({}): {}",
            packages.join(" "),
            o.status,
            String::from_utf8_lossy(&o.stderr).trim()
        ),
        Err(e) => format!("cannot run python3: {e}"),
    }
}

/// Makes sure the checker can run: h5py is required, meshio is used when it installs.
fn python_ready() -> Result<(), String> {
    if python_has("h5py") && python_has("meshio") {
        return Ok(());
    }
    let mut report = pip_install(&["h5py", "meshio"]);
    if !python_has("h5py") {
        // meshio may be what failed; h5py alone is enough for the required checks.
        report.push('\n');
        report.push_str(&pip_install(&["h5py"]));
    }
    if python_has("h5py") {
        Ok(())
    } else {
        Err(format!(
            "the independent XDMF check needs python3 with h5py (and numpy), which could not \
             be installed:\n{report}"
        ))
    }
}

#[test]
fn xdmf_output_on_1_2_3_ranks_reads_back_independently() {
    let binary = example_binary().unwrap_or_else(|e| panic!("{e}"));
    python_ready().unwrap_or_else(|e| panic!("{e}"));
    let root =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("xdmf-output-{}", std::process::id()));
    let mut failures = Vec::new();
    for ranks in [1, 2, 3] {
        let dir = root.join(format!("ranks-{ranks}"));
        let checked = write_on(&binary, ranks, &dir).and_then(|out| {
            print!("{out}");
            check_with_python(&dir)
        });
        match checked {
            Ok(out) => print!("{out}"),
            Err(e) => failures.push(format!("-n {ranks}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    // Kept on failure for inspection.
    let _ = std::fs::remove_dir_all(&root);
}
