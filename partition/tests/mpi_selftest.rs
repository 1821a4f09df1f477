//! Runs the multi-rank self test (`examples/partition_selftest.rs`) under `mpirun` on 1, 2 and
//! 3 ranks. MPI can be initialised only once per process, so multi-rank checks live in that
//! example binary and this test only launches it (with the workspace's shared launcher).

#[path = "../../tests/common/launch.rs"]
mod launch;

use launch::{example_binary, mpirun_example};

const EXAMPLE: &str = "partition_selftest";

#[test]
fn selftest_on_1_2_3_ranks() {
    let binary = example_binary(EXAMPLE).unwrap_or_else(|e| panic!("{e}"));
    let mut failures = Vec::new();
    for ranks in [1, 2, 3] {
        match mpirun_example(&binary, ranks, &[]) {
            Ok(out) => print!("{out}"),
            Err(e) => failures.push(format!("-n {ranks}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
