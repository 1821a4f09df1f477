//! Issue 11, finding 7: results do not depend on the rank count, whatever the partition. A rank
//! count that cannot balance the particles better must not repartition (and so re-interpolate)
//! every step, and a repartition must carry the Gauss states and the Newton predictor.

mod common;
use common::*;

use std::path::Path;

/// The 9-particle block of the issue: 1 m x 1 m, h = 0.5, fixed bottom, 1 kN at the top corner.
fn block9(dir: &Path) {
    ok(
        dir,
        1,
        &[
            "new",
            "cantilever",
            "-o",
            "b.h5",
            "--set",
            "body.rectangles=[{origin=[0.0,0.0],size=[1.0,1.0]}]",
            "--set",
            "mesh.h=0.5",
            "--set",
            "mesh.refine=false",
            "--set",
            "fixed[0].where=\"y <= 0\"",
            "--set",
            "point_load[0].at=[1.0,1.0]",
            "--set",
            "point_load[0].force=[1000.0,0.0]",
            "--set",
            "steps.count=3",
        ],
    );
}

/// Runs `case` on `ranks` ranks into `out`, with `PFEM_TEST_REPARTITION` when `rotate`; returns
/// stdout and the history rows.
fn run_case(
    dir: &Path,
    case: &str,
    out: &str,
    ranks: usize,
    rotate: bool,
) -> (String, Vec<Vec<f64>>) {
    let mut cmd = mpirun(ranks);
    cmd.args([case, "--out", out]).current_dir(dir);
    if rotate {
        cmd.env("PFEM_TEST_REPARTITION", "rotate");
    }
    let o = cmd.output().expect("launch mpirun");
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        o.status.success(),
        "{case} on {ranks} ranks failed\n{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    (stdout, history(&dir.join(out).join("history.csv")).1)
}

/// Triangles remapped per step, from the progress lines.
fn remapped(stdout: &str) -> Vec<u64> {
    stdout
        .lines()
        .filter_map(|l| l.split("remapped ").nth(1))
        .map(|r| r.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

fn assert_close(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: row counts");
    for (ra, rb) in a.iter().zip(b) {
        for (x, y) in ra.iter().zip(rb) {
            let rel = (x - y).abs() / x.abs().max(y.abs()).max(1e-300);
            assert!(rel <= 1e-9, "{what}: {ra:?} vs {rb:?} ({rel:.1e} relative)");
        }
    }
}

#[test]
fn nine_particles_give_the_same_history_on_one_to_five_ranks() {
    let dir = workdir("part9");
    block9(&dir);
    let mut reference = None;
    for ranks in 1..=5 {
        let (stdout, rows) = run_case(&dir, "b.h5", &format!("o{ranks}"), ranks, false);
        assert_eq!(rows.len(), 3, "{ranks} ranks: 3 steps");
        let r = remapped(&stdout);
        assert_eq!(
            r.len(),
            3,
            "{ranks} ranks: one progress line per step:\n{stdout}"
        );
        assert!(
            r[1..].iter().all(|&n| n == 0),
            "{ranks} ranks: triangles remapped after step 1 (a repartition dropped the kept \
             Gauss states): {r:?}"
        );
        match &reference {
            None => reference = Some(rows),
            Some(base) => assert_close(base, &rows, &format!("{ranks} ranks vs 1")),
        }
    }
}

#[test]
fn a_repartition_after_every_step_changes_no_result() {
    let dir = workdir("rotate");
    small_cantilever(&dir, 6, &[]);
    let (_, base) = run_case(&dir, "c.h5", "one", 1, false);
    // Every particle moves to another rank after every step.
    let (stdout, rotated) = run_case(&dir, "c.h5", "three", 3, true);
    assert_close(
        &base,
        &rotated,
        "3 ranks, repartitioned every step, vs 1 rank",
    );
    let (one, three) = (
        remapped(&stdout),
        remapped(&ok(&dir, 1, &["c.h5", "--out", "again"])),
    );
    assert_eq!(
        one, three,
        "remapped triangles per step, 3 ranks rotated vs 1 rank"
    );
}
