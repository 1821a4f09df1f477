//! Runs the multi-rank self test (`examples/partition_selftest.rs`) under `mpirun` on 1, 2 and
//! 3 ranks. MPI can be initialised only once per process, so multi-rank checks live in that
//! example binary and this test only launches it (with the workspace's shared launcher).

#[path = "../../tests/common/launch.rs"]
mod launch;

use launch::{example_binary, run_captured};
use std::path::Path;
use std::process::Command;

const EXAMPLE: &str = "partition_selftest";

fn run_on(binary: &Path, ranks: u32) -> Result<String, String> {
    let mut cmd = Command::new("mpirun");
    cmd.args(["-n", &ranks.to_string(), "--oversubscribe"])
        .arg(binary)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    run_captured(cmd, "mpirun (is OpenMPI installed?)")
}

#[test]
fn selftest_on_1_2_3_ranks() {
    let binary = example_binary(EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    let mut failures = Vec::new();
    for ranks in [1, 2, 3] {
        match run_on(&binary, ranks) {
            Ok(out) => print!("{out}"),
            Err(e) => failures.push(format!("-n {ranks}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
