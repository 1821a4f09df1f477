//! Checkpoints and restart: a checkpoint is a case that continues on any rank count; the same
//! rank count reproduces the uninterrupted run bit for bit; signals stop a run cleanly; a crash
//! while writing never damages the previous checkpoint.

mod common;
use common::*;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn rows(dir: &Path, out: &str) -> Vec<Vec<f64>> {
    history(&dir.join(out).join("history.csv")).1
}

/// Bitwise reproduction needs a deterministic linear solver: sequential MUMPS on 1 rank, and
/// SuperLU_dist on 2 (parallel MUMPS sums in message-arrival order).
#[test]
fn restart_on_one_rank_is_bitwise() {
    let dir = workdir("restart1");
    small_cantilever(&dir, 8, &[]);
    ok(&dir, 1, &["c.h5", "--out", "full"]);
    ok(&dir, 1, &["c.h5", "--out", "split", "--until-step", "3"]);
    ok(&dir, 1, &["split/checkpoints/step_000003.h5"]);
    assert_eq!(rows(&dir, "full"), rows(&dir, "split"));
}

#[test]
fn restart_on_same_and_other_rank_counts() {
    let dir = workdir("restart");
    small_cantilever(&dir, 10, &[]);
    let det = ["--", "-pc_factor_mat_solver_type", "superlu_dist"];
    ok(&dir, 2, &[&["c.h5", "--out", "full"][..], &det].concat());
    ok(
        &dir,
        2,
        &[&["c.h5", "--out", "split", "--until-step", "5"][..], &det].concat(),
    );
    let cp = "split/checkpoints/step_000005.h5";
    assert!(dir.join(cp).exists());
    let info = ok(&dir, 1, &["info", cp]);
    assert!(info.contains("step 5 of 10"), "{info}");
    // Continue on 1 and 3 ranks in copies, then on 2 in place.
    for (ranks, out) in [(1, "on1"), (3, "on3")] {
        ok(&dir, ranks, &[cp, "--out", out]);
    }
    ok(&dir, 2, &[&[cp][..], &det].concat());
    let full = rows(&dir, "full");
    let same = rows(&dir, "split");
    assert_eq!(
        same.len(),
        10,
        "history appended after the restart, steps 1..10 once each"
    );
    assert_eq!(
        full, same,
        "restart on the same rank count must reproduce the run bit for bit"
    );
    for out in ["on1", "on3"] {
        let other = rows(&dir, out);
        assert_eq!(other.len(), 5, "{out}: steps 6..10");
        for (a, b) in full[5..].iter().zip(&other) {
            assert_eq!(a[0], b[0]);
            for c in 2..4 {
                let rel = ((a[c] - b[c]) / a[c]).abs();
                assert!(rel < 1e-3, "{out}: step {} differs by {rel}", a[0]);
            }
        }
    }
}

fn spawn(dir: &Path, mpi_ranks: Option<usize>, args: &[&str]) -> std::process::Child {
    let mut cmd = match mpi_ranks {
        None => Command::new(bin()),
        Some(n) => mpirun(n),
    };
    cmd.args(args)
        .current_dir(dir)
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn")
}

fn signal(pid: u32, sig: &str) {
    let ok = Command::new("kill")
        .args([sig, &pid.to_string()])
        .status()
        .expect("kill")
        .success();
    assert!(ok, "kill {sig} {pid}");
}

fn checkpoints(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|r| {
            r.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn sigterm_and_sigusr1_checkpoint_and_exit_zero() {
    let dir = workdir("signals");
    small_cantilever(&dir, 2000, &[]);
    for (ranks, sig, out) in [(None, "-TERM", "one"), (Some(2), "-USR1", "two")] {
        let mut child = spawn(&dir, ranks, &["c.h5", "--out", out]);
        std::thread::sleep(Duration::from_millis(2500));
        signal(child.id(), sig);
        let t = std::time::Instant::now();
        let status = child.wait().expect("wait");
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "must stop within 30 s"
        );
        assert!(status.success(), "{sig} on {ranks:?} ranks: exit {status}");
        let cps = checkpoints(&dir.join(out).join("checkpoints"));
        let last = cps
            .last()
            .unwrap_or_else(|| panic!("{sig}: no checkpoint written"));
        let step: usize = last
            .trim_start_matches("step_")
            .trim_end_matches(".h5")
            .parse()
            .expect("step");
        assert!(step > 0 && step < 2000, "{last}");
        assert_eq!(
            rows(&dir, out).len(),
            step,
            "history rows up to the checkpoint"
        );
        // And the analysis resumes from it.
        ok(
            &dir,
            1,
            &[
                &format!("{out}/checkpoints/{last}"),
                "--until-step",
                &(step + 1).to_string(),
            ],
        );
        assert_eq!(rows(&dir, out).len(), step + 1);
    }
}

#[test]
fn sigkill_while_writing_keeps_the_previous_checkpoint_loadable() {
    let dir = workdir("sigkill");
    ok(
        &dir,
        1,
        &[
            "new",
            "cantilever",
            "-o",
            "c.h5",
            "--set",
            "steps.count=5000",
            "--set",
            "output.checkpoint_every=1",
            "--set",
            "output.checkpoint_keep=2",
        ],
    );
    for (i, delay_ms) in [1500u64, 1730, 1910, 2270].iter().enumerate() {
        let out = format!("k{i}");
        let mut child = spawn(&dir, None, &["c.h5", "--out", &out]);
        std::thread::sleep(Duration::from_millis(*delay_ms));
        child.kill().expect("SIGKILL");
        let _ = child.wait();
        let cps = checkpoints(&dir.join(&out).join("checkpoints"));
        let finished: Vec<&String> = cps.iter().filter(|n| n.ends_with(".h5")).collect();
        let newest = finished
            .last()
            .unwrap_or_else(|| panic!("run {i}: no finished checkpoint in {cps:?}"));
        let info = ok(&dir, 1, &["info", &format!("{out}/checkpoints/{newest}")]);
        assert!(info.contains("particles"), "{info}");
        assert!(
            cps.iter()
                .all(|n| n.ends_with(".h5") || n.ends_with(".h5.tmp")),
            "{cps:?}"
        );
        // The run continues from it.
        let step: u64 = newest
            .trim_start_matches("step_")
            .trim_end_matches(".h5")
            .parse()
            .expect("step");
        ok(
            &dir,
            1,
            &[
                &format!("{out}/checkpoints/{newest}"),
                "--until-step",
                &(step + 1).to_string(),
            ],
        );
    }
}
