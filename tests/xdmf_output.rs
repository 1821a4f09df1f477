//! Runs the ParaView output self test (`examples/xdmf_selftest.rs`) under `mpirun` on 1, 2 and
//! 3 ranks, then checks each output folder with an independent reader, `tests/check_xdmf.py`
//! (Python: xml.etree + h5py, and meshio when it is installed). MPI can be initialised only once
//! per process, so the writing happens in the example binary.

mod common;
use common::{example_binary, mpirun_example, run_captured as run};
use std::path::Path;
use std::process::{Command, Stdio};

const EXAMPLE: &str = "xdmf_selftest";

fn write_on(binary: &Path, ranks: u32, dir: &Path) -> Result<String, String> {
    mpirun_example(binary, ranks, &[dir.as_os_str()])
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
    let binary = example_binary(EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
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
