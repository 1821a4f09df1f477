//! Bad input ends every rank with a clear message naming the field or file, and a non-zero exit;
//! never a panic trace or a hang.

mod common;
use common::*;

fn fails_with(dir: &std::path::Path, ranks: usize, args: &[&str], needles: &[&str]) {
    let out = run(dir, ranks, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    for n in needles {
        assert!(
            stderr.contains(n),
            "{args:?}: message should name {n:?}:\n{stderr}"
        );
    }
    assert!(
        !dir.join("bad.h5").exists(),
        "no half-written case file may be left"
    );
}

#[test]
fn bad_scene_values_name_the_field() {
    let dir = workdir("bad-scene");
    fails_with(
        &dir,
        1,
        &["new", "cantilever", "-o", "bad.h5", "--set", "mesh.h=-1"],
        &["mesh.h", "> 0"],
    );
    fails_with(
        &dir,
        1,
        &[
            "new",
            "cantilever",
            "-o",
            "bad.h5",
            "--set",
            "material.poisson=0.7",
        ],
        &["material.poisson"],
    );
    fails_with(
        &dir,
        1,
        &["new", "cantilever", "-o", "bad.h5", "--set", "mesh.hh=1"],
        &["mesh.hh"],
    );
    fails_with(
        &dir,
        1,
        &["new", "no-such-scene", "-o", "bad.h5"],
        &["no-such-scene"],
    );
    std::fs::write(dir.join("s.toml"), "name = \"x\"\n[mesh]\nh = \"big\"\n").unwrap();
    fails_with(&dir, 1, &["new", "s.toml", "-o", "bad.h5"], &["s.toml"]);
}

#[test]
fn bad_case_files_name_the_file_on_every_rank_count() {
    let dir = workdir("bad-case");
    std::fs::write(dir.join("garbage.h5"), b"not hdf5 at all").unwrap();
    for ranks in [1, 2] {
        fails_with(&dir, ranks, &["missing.h5"], &["missing.h5"]);
        fails_with(&dir, ranks, &["garbage.h5"], &["garbage.h5"]);
    }
}

#[test]
fn bad_command_lines_explain_usage() {
    let dir = workdir("bad-cli");
    fails_with(&dir, 1, &["new", "cantilever"], &["-o"]);
    fails_with(&dir, 1, &["case.h5", "-snes_monitor"], &["after --"]);
    fails_with(&dir, 1, &[], &["usage"]);
}

#[test]
fn a_step_that_cannot_converge_stops_all_ranks_with_the_reason() {
    let dir = workdir("bad-newton");
    small_cantilever(&dir, 2, &[]);
    let out = run(&dir, 2, &["c.h5", "--", "-snes_max_it", "1"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("step 1") && stderr.contains("Newton"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// A solver option that names no path (or one the scene cannot take) is a usage error on every
/// rank, in its own words, before an output folder is made.
#[test]
fn a_bad_linear_solver_option_is_a_usage_error_and_leaves_no_output() {
    let dir = workdir("bad-linear-solver");
    let mixed = "solver.element=\"p2p1\"";
    ok(
        &dir,
        1,
        &["new", "cantilever", "-o", "c.h5", "--set", mixed],
    );
    for ranks in [1, 2] {
        for (value, needle) in [
            ("bogus", "choose one of auto, direct"),
            ("pmg", "the p-multigrid solves P2 systems"),
        ] {
            let args = ["c.h5", "--out", "o", "--", "-pfem_linear_solver", value];
            let out = run(&dir, ranks, &args);
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(
                out.status.code(),
                Some(2),
                "{ranks} ranks, {value}:\n{stderr}"
            );
            assert!(stderr.contains(needle), "{value}: {stderr}");
            assert!(!stderr.contains("PETSc error"), "{value}: {stderr}");
            assert!(
                !dir.join("o").exists(),
                "{value}: an output folder was made"
            );
        }
    }
}
