//! Runs the case-file multi-rank self test (`examples/case_file_selftest.rs`: write on some ranks,
//! read on others) under `mpirun` on 1, 2 and 3 ranks. MPI can be initialised only once per
//! process, so the checks live in that example binary and this test only launches it.

mod common;
use common::{example_binary, mpirun_example};

const EXAMPLE: &str = "case_file_selftest";

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
