//! Coarse, quick versions of the rigid-body benchmarks (`footing`, `tbar-smooth`, `tbar-rough`,
//! `pipeline`) on 1 and 2 ranks (the footing and pipeline also on 3), asserting their figures within looser tolerances than the
//! full scenes reach, and a staged run stopped in its second stage and restarted on another
//! rank count. Every step of every run also checks that no particle is inside a body (the run
//! fails otherwise) and meshes without triangles crossing one.

mod common;
use common::*;
use std::path::Path;

fn column(dir: &Path, out: &str, name: &str) -> Vec<f64> {
    let (header, rows) = history(&dir.join(out).join("history.csv"));
    let i = header.iter().position(|h| h == name).expect(name);
    rows.iter().map(|r| r[i]).collect()
}

/// Runs `case` on 1 and 2 ranks; returns the run folders.
fn both(dir: &Path, case: &str) -> [String; 2] {
    let [r1, r2, _] = on_ranks(dir, case, [1, 2]);
    [r1, r2]
}

/// Runs `case` on each of `ranks`; returns the run folders `r1`, `r2`, `r3` (a rank count not
/// run leaves its folder absent).
fn on_ranks<const N: usize>(dir: &Path, case: &str, ranks: [usize; N]) -> [String; 3] {
    for r in ranks {
        let log = ok(dir, r, &[case, "--out", &format!("r{r}")]);
        assert!(
            log.contains("contact "),
            "the progress line reports contact time"
        );
    }
    ["r1".to_string(), "r2".to_string(), "r3".to_string()]
}

fn close(a: &[f64], b: &[f64], tol: f64) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert!((x - y).abs() <= tol * y.abs().max(1.0), "{x} against {y}");
    }
}

#[test]
#[ignore = "coarse benchmark: rigid footing against Prandtl, 20 steps on 1, 2 and 3 ranks"]
fn footing_coarse_is_within_15_percent_of_prandtl_and_below_the_deep_limit() {
    let dir = workdir("footing-coarse");
    coarse_sharp_footing(&dir, 0.4, 20, true);
    let [r1, r2, r3] = on_ranks(&dir, "f.h5", [1, 2, 3]);
    let q = column(&dir, &r1, "q_over_cu");
    let z = column(&dir, &r1, "z_over_B");
    println!("footing coarse q/cu: {q:?}");
    assert!((z[19] - 0.2).abs() < 1e-12);
    // Coarse (B/8 at the edge). With E/cu = 100 the load is mobilised by z/B ≈ 0.15: at
    // z/B = 0.2 within 15 % of 2 + π, and below 2 + 2π throughout.
    assert!(q.iter().all(|&v| v < 8.283), "{q:?}");
    assert!(
        (q[19] - 5.142).abs() < 0.15 * 5.142,
        "q/cu {} at z/B = 0.2",
        q[19]
    );
    // Measured: 1, 2 and 3 ranks within 5e-15 (0.4 % apart at step 13 while ranks kept their
    // own copies of triangles around a particle another rank smoothed).
    close(&q, &column(&dir, &r2, "q_over_cu"), 1e-9);
    close(&q, &column(&dir, &r3, "q_over_cu"), 1e-9);
}

fn tbar(name: &str, exact: f64) {
    let dir = workdir(name);
    ok(
        &dir,
        1,
        &[
            "new",
            name,
            "-o",
            "t.h5",
            "--set",
            "mesh.fine=[{origin=[0.0,0.26],size=[0.16,0.28],h=0.01}]",
            "--set",
            "rigid[0].stages=[{to=[0.0,-0.008],steps=8}]",
        ],
    );
    let [r1, r2] = both(&dir, "t.h5");
    let nc = column(&dir, &r1, "Nc");
    println!("{name} coarse Nc: {nc:?} (exact {exact})");
    // D/4 at the bar: within 8 % of the exact value from w = 0.1D on.
    for v in &nc[3..] {
        assert!((v - exact).abs() < 0.08 * exact, "Nc {v} against {exact}");
    }
    // 1 and 2 ranks on the same path (to round-off since every rank forgets the triangles
    // around a particle another rank smoothed).
    close(&nc, &column(&dir, &r2, "Nc"), 1e-7);
}

#[test]
#[ignore = "coarse benchmark: smooth T-bar against the exact Nc on 1 and 2 ranks"]
fn tbar_smooth_coarse_is_within_8_percent_of_the_exact_nc() {
    tbar("tbar-smooth", 9.142);
}

#[test]
#[ignore = "coarse benchmark: rough T-bar against the exact Nc on 1 and 2 ranks"]
fn tbar_rough_coarse_is_within_8_percent_of_the_exact_nc() {
    tbar("tbar-rough", 11.940);
}

/// 0.025 D a step down, then 0.042 D a step sideways. (With 10 and 6 steps, step 9 sat on the
/// edge of the Newton limit: 60 iterations without converging on 1 rank, cut; 41 and converged
/// on 2 in one of seven runs, whose path then stopped at step 11. Round-off between rank
/// counts tips such a step; these steps leave Newton well inside its limit.)
const PIPE_STAGES: &str = "rigid[0].stages=[{to=[0.0,-0.02],steps=20},{to=[0.02,-0.02],steps=12}]";

fn new_pipeline(dir: &Path) {
    ok(
        dir,
        1,
        &[
            "new",
            "pipeline",
            "-o",
            "p.h5",
            "--set",
            "mesh.h=0.02",
            "--set",
            "mesh.fine=[{origin=[0.16,0.12],size=[0.24,0.08],h=0.01}]",
            "--set",
            PIPE_STAGES,
        ],
    );
}

#[test]
#[ignore = "coarse benchmark: pipeline pushed down then sideways on 1, 2 and 3 ranks"]
fn pipeline_coarse_v_is_within_the_dnv_range_widened_25_percent_then_sideways_h_exceeds_1() {
    let dir = workdir("pipeline-coarse");
    new_pipeline(&dir);
    let [r1, r2, r3] = on_ranks(&dir, "p.h5", [1, 2, 3]);
    let v = column(&dir, &r1, "V_over_Dcu");
    let h = column(&dir, &r1, "H_over_Dcu");
    let uy = column(&dir, &r1, "uy_over_D");
    let ux = column(&dir, &r1, "ux_over_D");
    println!("pipeline coarse V: {v:?}\nH: {h:?}");
    // Stage 1: down 0.5D, no sideways motion; stage 2: depth held, 0.5D sideways.
    let (down, side) = (19, 31);
    assert!((uy[down] - 0.5).abs() < 1e-12 && ux[down] == 0.0);
    assert!((uy[side] - 0.5).abs() < 1e-12 && (ux[side] - 0.5).abs() < 1e-12);
    // V at 0.5D between the wished-in-place design value 5.05 less 25 % (coarse) and the
    // seed's 5.7 plus 25 %; sideways the soil resists (H > 0) and V drops.
    assert!(
        v[down] > 0.75 * 5.05 && v[down] < 1.25 * 5.7,
        "V {}",
        v[down]
    );
    assert!(h[side] > 1.0, "H {}", h[side]);
    assert!(v[side] < v[down]);
    // Smooth pipe in the vertical stage: no horizontal force to speak of.
    assert!(h[down].abs() < 0.1 * v[down]);
    // The same path on 1, 2 and 3 ranks through the cut steps (6 and 32, on each), vertical
    // and sideways. Measured: within 8e-14 (V) in six 2-rank runs and one 3-rank run; 6.2 %
    // and 11 % apart while ranks kept stale copies of the interface triangles around
    // particles another rank smoothed.
    for other in [&r2, &r3] {
        close(&v, &column(&dir, other, "V_over_Dcu"), 1e-7);
        for (a, b) in h.iter().zip(&column(&dir, other, "H_over_Dcu")) {
            assert!(
                (a - b).abs() <= 1e-7 * v[down],
                "H {a} against {b} ({other})"
            );
        }
    }
}

#[test]
#[ignore = "coarse benchmark: a staged pipeline run and its restart on another rank count"]
fn staged_run_restarts_in_its_second_stage_on_another_rank_count() {
    let dir = workdir("pipeline-restart");
    new_pipeline(&dir);
    // The checkpoint is written by 2 ranks in the lateral stage and continued on 1; the
    // uninterrupted run is the 1-rank one.
    ok(&dir, 1, &["p.h5", "--out", "whole"]);
    ok(&dir, 2, &["p.h5", "--out", "split", "--until-step", "24"]);
    ok(
        &dir,
        1,
        &["split/checkpoints/step_000024.h5", "--out", "split"],
    );
    for name in ["V_over_Dcu", "H_over_Dcu", "ux_over_D"] {
        let whole = column(&dir, "whole", name);
        let split = column(&dir, "split", name);
        println!("{name}: whole {:?} split {:?}", &whole[24..], &split[24..]);
        // Measured: within 4e-14 (V; H 2e-14); 15 % while ranks kept stale
        // copies of interface triangles (see `pipeline_coarse_...`).
        close(&split, &whole, 1e-7);
    }
}
