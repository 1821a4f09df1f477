//! Runs the ParaView output self test (`examples/xdmf_selftest.rs`) under `mpirun` on 1, 2 and
//! 3 ranks, then checks each output folder with an independent reader, `tests/check_xdmf.py`
//! (Python: xml.etree + h5py, and meshio when it is installed; `.ci/install-native` installs both). MPI can be initialised only once
//! per process, so the writing happens in the example binary.

mod common;
use common::{example_binary, mpirun_example, prerequisite, python_has, run_captured as run};
use std::path::Path;
use std::process::Command;

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

#[test]
fn xdmf_output_on_1_2_3_ranks_reads_back_independently() {
    let binary = example_binary(EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    // meshio is optional to the checker; h5py (with numpy) is not.
    if !prerequisite("Python's h5py (python3-h5py)", python_has("h5py")) {
        return;
    }
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
