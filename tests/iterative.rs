//! The iterative linear path (for P2 a two-level p-multigrid whose P1 coarse level has the
//! rigid-body near-null space, or GAMG on P2 with `-pfem_pmg false`; a Schur-complement field
//! split for P2–P1) against the direct one: same Newton histories, a
//! linear iteration count that does not grow with refinement, convergence for a nearly
//! incompressible solid, and the rigid-body modes in the kernel of the stiffness.

mod common;

use common::{history, ok, workdir};
use pfem_mpi::fem::analysis::Analysis;
use pfem_mpi::fem::element::p2_element;
use pfem_mpi::fem::mixed::p2p1_element;
use pfem_mpi::fem::p2::straight_sided;
use pfem_mpi::material::elastic::LinearElastic;
use pfem_mpi::material::GaussState;
use pfem_mpi::solve::nullspace::rigid_body_modes;
use std::collections::HashMap;
use std::path::Path;

/// Largest relative difference between two histories (same columns and rows).
fn max_relative_difference(a: &Path, b: &Path) -> f64 {
    let (ha, ra) = history(a);
    let (hb, rb) = history(b);
    assert_eq!(ha, hb, "history columns");
    assert_eq!(ra.len(), rb.len(), "history rows");
    let mut worst: f64 = 0.0;
    for (x, y) in ra.iter().zip(&rb) {
        for (u, v) in x.iter().zip(y) {
            let scale = u.abs().max(v.abs());
            if scale > 0.0 {
                worst = worst.max((u - v).abs() / scale);
            }
        }
    }
    worst
}

/// (Newton iterations, linear iterations) from the end-of-run line.
fn iterations(stdout: &str) -> (usize, usize) {
    let done = stdout
        .lines()
        .find(|l| l.starts_with("done:"))
        .unwrap_or_else(|| panic!("no end-of-run line in\n{stdout}"));
    let count = |what: &str| -> usize {
        let words: Vec<&str> = done.split([' ', ',']).filter(|w| !w.is_empty()).collect();
        let at = words
            .iter()
            .position(|w| *w == what)
            .unwrap_or_else(|| panic!("no '{what}' in {done}"));
        words[at - 1].parse().expect("a count")
    };
    (count("Newton"), count("linear"))
}

/// Writes `case` (scene `scene` with `sets`), runs it with the direct and the iterative
/// solver (given the PETSc options `petsc`) on `ranks` ranks for `steps` steps, and returns the
/// histories' largest relative difference and the iterative run's (Newton, linear) iterations.
fn direct_against_iterative(
    dir: &Path,
    scene: &str,
    sets: &[&str],
    ranks: usize,
    steps: u32,
    petsc: &[&str],
) -> (f64, (usize, usize)) {
    let until = steps.to_string();
    let mut outs = Vec::new();
    for linear in ["direct", "iterative"] {
        let case = format!("{linear}.h5");
        let choice = format!("solver.linear=\"{linear}\"");
        let mut args = vec!["new", scene, "-o", &case, "--set", &choice];
        for s in sets {
            args.extend(["--set", s]);
        }
        ok(dir, 1, &args);
        let out = format!("{linear}{ranks}");
        let mut run = vec![case.as_str(), "--out", &out, "--until-step", &until];
        if linear == "iterative" && !petsc.is_empty() {
            run.push("--");
            run.extend(petsc);
        }
        let stdout = ok(dir, ranks, &run);
        outs.push((out, stdout));
    }
    let diff = max_relative_difference(
        &dir.join(&outs[0].0).join("history.csv"),
        &dir.join(&outs[1].0).join("history.csv"),
    );
    (diff, iterations(&outs[1].1))
}

#[test]
fn iterative_cantilever_matches_the_direct_history_on_1_and_2_ranks() {
    let dir = workdir("iterative-cantilever");
    for petsc in [&[][..], &["-pfem_pmg", "false"][..]] {
        for ranks in [1, 2] {
            let (diff, (newton, linear)) = direct_against_iterative(
                &dir,
                "cantilever",
                &["mesh.h=0.25", "steps.count=10"],
                ranks,
                3,
                petsc,
            );
            println!("cantilever {petsc:?}, {ranks} ranks: max relative difference {diff:.2e}, {newton} Newton and {linear} linear iterations");
            assert!(diff < 1e-6, "{petsc:?}, {ranks} ranks: {diff:e}");
            assert!(
                linear > newton,
                "the iterative path ran: {linear} linear iterations"
            );
        }
    }
}

#[test]
fn the_p2_iterative_path_is_a_p_multigrid_unless_asked_for_gamg() {
    let dir = workdir("iterative-pmg");
    common::small_cantilever(&dir, 10, &["solver.linear=\"iterative\""]);
    let view = |extra: &[&str]| {
        let mut args = vec!["c.h5", "--until-step", "1", "--", "-ksp_view"];
        args.extend(extra);
        ok(&dir, 2, &args)
    };
    // The outer PC is the two-level p-multigrid: a damped Jacobi sweep on P2 before and after
    // two GAMG cycles on the coarse P1 operator (its options under `mg_coarse_`, as PCMG's).
    let pmg = view(&[]);
    for want in [
        "type: shell",
        "p-multigrid",
        "KSP Object: (mg_coarse_)",
        "type: gamg",
    ] {
        assert!(pmg.contains(want), "no '{want}' in\n{pmg}");
    }
    let history = || std::fs::read_to_string(dir.join("c.out/history.csv")).expect("history");
    let cycle_history = history();
    // On a symmetric tangent the sweeps are damped by the Jacobian's spectral bound:
    // 2 / (1.1 b) with the elements' Gershgorin bound b, about 0.45 (PETSc's own default
    // Richardson damping would be 1).
    let damping = |view: &str| -> f64 {
        view.split("damping factor=")
            .nth(1)
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.trim_end_matches('.').parse().ok())
            .unwrap_or_else(|| panic!("no damping in\n{view}"))
    };
    assert!(
        (0.3..0.6).contains(&damping(&pmg)),
        "damping {}",
        damping(&pmg)
    );
    // An option of PCMG's own cycle brings PCMG back, with the same two levels and the same
    // damped Richardson–Jacobi smoother: the same history, bit for bit.
    let fine_smoother = |view: &str| {
        let at = view
            .find("KSP Object: (mg_levels_1_)")
            .unwrap_or_else(|| panic!("no fine smoother in\n{view}"));
        let end = view[at..]
            .find("PC Object: (mg_levels_1_)")
            .expect("its PC");
        view[at..at + end].to_string()
    };
    let pcmg = view(&["-pc_mg_log"]);
    for want in ["type: mg", "levels=2", "type: gamg"] {
        assert!(pcmg.contains(want), "no '{want}' in\n{pcmg}");
    }
    let smoother = fine_smoother(&pcmg);
    assert!(smoother.contains("type: richardson"), "{smoother}");
    assert!((0.3..0.6).contains(&damping(&smoother)), "{smoother}");
    let after_smoother = &pcmg[pcmg.find("KSP Object: (mg_levels_1_)").expect("found")..];
    assert!(after_smoother.contains("type: jacobi"), "{after_smoother}");
    assert_eq!(history(), cycle_history, "PCMG against the two-level cycle");
    // The cantilever's tangent is symmetric: only its upper triangle is stored, in blocks.
    // Declared unsymmetric, the whole tangent is stored and GMRES replaces CG, with the same
    // history.
    assert!(pmg.contains("type: mpisbaij"), "no SBAIJ tangent in\n{pmg}");
    let unsym = workdir("iterative-pmg-unsymmetric");
    common::small_cantilever(
        &unsym,
        10,
        &["solver.linear=\"iterative\"", "solver.symmetric=false"],
    );
    let full = ok(&unsym, 2, &["c.h5", "--until-step", "1", "--", "-ksp_view"]);
    for want in ["type: mpibaij", "type: gmres", "type: mg"] {
        assert!(full.contains(want), "no '{want}' in\n{full}");
    }
    assert!(!full.contains("sbaij"), "{full}");
    let diff = max_relative_difference(
        &dir.join("c.out/history.csv"),
        &unsym.join("c.out/history.csv"),
    );
    assert!(diff < 1e-6, "BAIJ/GMRES against SBAIJ/CG: {diff:e}");
    // (Compared before the runs below overwrite `c.out`.) PETSc's SOR has no SBAIJ version for
    // 2 × 2 blocks: asked for, it gets the whole tangent.
    let sor = view(&["-mg_levels_pc_type", "sor"]);
    for want in ["type: mpibaij", "type: sor"] {
        assert!(sor.contains(want), "no '{want}' in\n{sor}");
    }
    // Named on the command line, the fine smoother is PETSc's Chebyshev again.
    let chebyshev = view(&["-mg_levels_ksp_type", "chebyshev"]);
    assert!(
        fine_smoother(&chebyshev).contains("type: chebyshev"),
        "{chebyshev}"
    );
    // Two sweeps are PCMG's too.
    let two_sweeps = view(&["-mg_levels_ksp_max_it", "2"]);
    assert!(two_sweeps.contains("type: mg"), "{two_sweeps}");
    // Asked for GAMG, or for any preconditioner on the command line (the p-multigrid's BAIJ
    // tangent would stop GAMG: "No method creategraph for Mat of type seqbaij").
    for asked in [&["-pfem_pmg", "false"][..], &["-pc_type", "gamg"][..]] {
        let gamg = view(asked);
        assert!(gamg.contains("type: gamg"), "{asked:?}: {gamg}");
        assert!(!gamg.contains("levels=2,"), "{asked:?}: {gamg}");
    }
}

#[test]
fn iterative_footing_shallow_matches_the_direct_history_on_1_and_2_ranks() {
    let dir = workdir("iterative-footing");
    for ranks in [1, 2] {
        let (diff, (newton, linear)) = direct_against_iterative(
            &dir,
            "footing-shallow",
            &[
                "mesh.h=0.5",
                "mesh.fine=[{origin=[0.0,8.0],size=[4.0,2.0],h=0.25},\
                 {origin=[0.5,9.5],size=[1.0,0.5],h=0.125}]",
            ],
            ranks,
            3,
            &[],
        );
        println!("footing-shallow, {ranks} ranks: max relative difference {diff:.2e}, {newton} Newton and {linear} linear iterations");
        assert!(diff < 1e-6, "{ranks} ranks: {diff:e}");
        assert!(
            linear > newton,
            "the iterative path ran: {linear} linear iterations"
        );
    }
}

#[test]
fn linear_iterations_per_newton_iteration_barely_grow_with_refinement() {
    let dir = workdir("iterative-refinement");
    let mut per_newton = Vec::new();
    for h in ["0.25", "0.125"] {
        let spacing = format!("mesh.h={h}");
        let case = format!("c{h}.h5");
        ok(
            &dir,
            1,
            &[
                "new",
                "cantilever",
                "-o",
                &case,
                "--set",
                &spacing,
                "--set",
                "steps.count=10",
                "--set",
                "solver.linear=\"iterative\"",
            ],
        );
        let out = format!("out{h}");
        let stdout = ok(&dir, 1, &[&case, "--out", &out, "--until-step", "2"]);
        let (newton, linear) = iterations(&stdout);
        let mean = linear as f64 / newton as f64;
        println!("h = {h}: {newton} Newton iterations, {linear} linear iterations, {mean:.1} per Newton iteration");
        per_newton.push(mean);
    }
    let growth = per_newton[1] / per_newton[0];
    assert!(
        (growth - 1.0).abs() < 0.3,
        "linear iterations per Newton iteration {per_newton:?}: ratio {growth:.2}"
    );
}

#[test]
fn nearly_incompressible_elastic_block_converges_with_the_field_split() {
    let dir = workdir("iterative-incompressible");
    let (diff, (newton, linear)) = direct_against_iterative(
        &dir,
        "block-compression",
        &[
            "material={model=\"linear-elastic\",young=3.0e6,poisson=0.4999,density=0.0}",
            "solver.element=\"p2p1\"",
            "mesh.h=0.1",
            "steps.count=20",
        ],
        1,
        3,
        &[],
    );
    println!("block, nu = 0.4999: max relative difference {diff:.2e}, {newton} Newton and {linear} linear iterations");
    assert!(diff < 1e-6, "{diff:e}");
    // Measured 41.5 per Newton iteration at h = 0.1 and 45.9 at h = 0.05.
    assert!(
        linear <= 80 * newton,
        "{linear} linear iterations for {newton} Newton iterations"
    );
}

/// `iterative.h5` in `dir` (block-compression, yielded everywhere from step 2) with GAMG alone
/// (`-pfem_yield_zone false`): the step is cut to failure.
fn gamg_alone_stops_at_step_2(dir: &Path) {
    let out = common::run(
        dir,
        1,
        &[
            "iterative.h5",
            "--out",
            "gamg",
            "--until-step",
            "2",
            "--",
            "-pfem_yield_zone",
            "false",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("step 2") && stderr.contains("DIVERGED_ITS"),
        "{stderr}"
    );
}

#[test]
fn the_field_split_holds_a_yielded_block_through_its_exact_zone() {
    let dir = workdir("iterative-yield-zone");
    // block-compression yields everywhere from step 2 on: the displacement block's flow
    // direction has no stiffness at any Gauss point.
    for ranks in [1, 2] {
        let (diff, (newton, linear)) =
            direct_against_iterative(&dir, "block-compression", &[], ranks, 8, &[]);
        println!("block-compression, {ranks} ranks: max relative difference {diff:.2e}, {newton} Newton and {linear} linear iterations");
        assert!(diff < 1e-6, "{ranks} ranks: {diff:e}");
        // Measured 5.4 per Newton iteration over the 100 steps (step 1, elastic: 39).
        assert!(
            linear > newton && linear <= 12 * newton,
            "{ranks} ranks: {linear} linear iterations for {newton} Newton iterations"
        );
    }
    // The zone is the block's preconditioner, and at step 2 it holds every row.
    let view = ok(
        &dir,
        1,
        &[
            "iterative.h5",
            "--out",
            "view",
            "--until-step",
            "2",
            "--",
            "-ksp_view",
        ],
    );
    let sizes: Vec<(usize, usize)> = view
        .lines()
        .filter_map(|l| l.trim().strip_prefix("yielded zone: "))
        .map(|l| {
            let w: Vec<&str> = l.split(' ').collect();
            (
                w[0].parse().expect("zone rows"),
                w[2].parse().expect("rows"),
            )
        })
        .collect();
    assert!(
        sizes
            .first()
            .is_some_and(|&(zone, rows)| zone > 0 && zone < rows),
        "step 1 yields at the platens' corners only: {sizes:?}"
    );
    assert!(
        sizes.last().is_some_and(|&(zone, rows)| zone == rows),
        "step 2 yields everywhere: {sizes:?}"
    );
    // Without it, GAMG alone does not converge at yield.
    gamg_alone_stops_at_step_2(&dir);
}

#[test]
fn a_yielded_p2_mesh_converges_through_the_yield_zone() {
    let dir = workdir("iterative-yield-zone-p2");
    // The P2 block yields everywhere from step 2 on; GAMG alone stopped there.
    for ranks in [1, 2] {
        let (diff, (newton, linear)) = direct_against_iterative(
            &dir,
            "block-compression",
            &["solver.element=\"p2\""],
            ranks,
            4,
            &[],
        );
        println!("block-compression (P2), {ranks} ranks: max relative difference {diff:.2e}, {newton} Newton and {linear} linear iterations");
        assert!(diff < 1e-6, "{ranks} ranks: {diff:e}");
        assert!(linear > newton, "{ranks} ranks: the iterative path ran");
    }
    gamg_alone_stops_at_step_2(&dir);
}

/// A P2 mesh of a distorted 3 x 2 patch of squares cut into triangles: node coordinates
/// (vertices, then midside nodes) and the 6 nodes of every triangle.
fn patch() -> (Vec<[f64; 2]>, Vec<[usize; 6]>) {
    let (nx, ny) = (3, 2);
    let mut coords = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            // A shear and a bulge, so that no element is a scaled copy of another.
            let (x, y) = (i as f64, j as f64);
            coords.push([0.7 * x + 0.2 * y + 0.05 * (x * y), 0.5 * y + 0.03 * x * x]);
        }
    }
    let v = |i: usize, j: usize| j * (nx + 1) + i;
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            tris.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            tris.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    let mut out = Vec::new();
    for t in &tris {
        let mut nodes = [t[0], t[1], t[2], 0, 0, 0];
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let next = coords.len();
            let m = *edges.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (pa, pb) = (coords[a], coords[b]);
                coords.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]);
                next
            });
            nodes[3 + k] = m;
        }
        out.push(nodes);
    }
    (coords, out)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// ‖K r‖ / (‖K‖_F ‖r‖) for each vector r of `modes(coords)` (zero on pressure dofs), K the
/// unconstrained patch matrix assembled from `element` (row-major, the 12 displacement dofs
/// first, then `extra` dofs per vertex).
fn kernel_residuals(
    extra: usize,
    element: impl Fn(&[[f64; 2]; 6]) -> Vec<f64>,
    modes: impl Fn(&[[f64; 2]]) -> Vec<Vec<f64>>,
) -> Vec<f64> {
    let (coords, tris) = patch();
    let n_vertex = 12;
    let n_u = 2 * coords.len();
    let n = n_u + extra * n_vertex;
    let mut k = vec![0.0; n * n];
    for t in &tris {
        let ke = element(&straight_sided(&[coords[t[0]], coords[t[1]], coords[t[2]]]));
        let mut dofs: Vec<usize> = t.iter().flat_map(|&a| [2 * a, 2 * a + 1]).collect();
        if extra > 0 {
            dofs.extend(t[..3].iter().map(|&a| n_u + a));
        }
        let m = dofs.len();
        for (r, &gr) in dofs.iter().enumerate() {
            for (c, &gc) in dofs.iter().enumerate() {
                k[gr * n + gc] += ke[r * m + c];
            }
        }
    }
    let k_norm = norm(&k);
    modes(&coords)
        .into_iter()
        .map(|mut r| {
            r.resize(n, 0.0);
            let kr: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| k[i * n + j] * r[j]).sum())
                .collect();
            norm(&kr) / (k_norm * norm(&r))
        })
        .collect()
}

fn rigid(coords: &[[f64; 2]]) -> Vec<Vec<f64>> {
    rigid_body_modes(coords, [0.9, 0.6]).to_vec()
}

#[test]
fn rigid_body_modes_are_in_the_kernel_of_the_stress_free_tangents() {
    let states = <[GaussState; 3]>::default();
    let mat = LinearElastic::new(12.0e6, 0.3).expect("material");
    let p2 = kernel_residuals(
        0,
        |x| {
            let e = p2_element(x, &[[0.0; 2]; 6], &states, &mat, [0.0; 2]).expect("element");
            e.tangent.as_flattened().to_vec()
        },
        rigid,
    );
    // ν = 0.4999: the displacement and pressure blocks of a nearly incompressible solid.
    let nu = 0.4999;
    let soft = LinearElastic::new(12.0e6, nu).expect("material");
    let bulk = 12.0e6 / (3.0 * (1.0 - 2.0 * nu));
    let mixed = kernel_residuals(
        1,
        |x| {
            let e = p2p1_element(
                x,
                &[[0.0; 2]; 6],
                &[0.0; 3],
                &states,
                &soft,
                bulk,
                [0.0; 2],
                Analysis::PlaneStrain,
            )
            .expect("element")
            .with_pressure_scale(4.0e6);
            e.tangent.as_flattened().to_vec()
        },
        rigid,
    );
    println!("|K r| / (|K| |r|): P2 {p2:?}, P2-P1 {mixed:?}");
    for r in p2.iter().chain(&mixed) {
        assert!(*r < 1e-14, "a rigid-body mode is not in the kernel: {r:e}");
    }
    // The check can fail: a stretch is no rigid-body mode.
    let stretch = kernel_residuals(
        0,
        |x| {
            let e = p2_element(x, &[[0.0; 2]; 6], &states, &mat, [0.0; 2]).expect("element");
            e.tangent.as_flattened().to_vec()
        },
        |c| vec![c.iter().flat_map(|x| [x[0], 0.0]).collect()],
    );
    assert!(stretch[0] > 1e-3, "a stretch in the kernel: {stretch:?}");
}

#[test]
fn a_linear_solve_that_does_not_converge_is_a_divergence_the_step_cuts_on() {
    let dir = workdir("iterative-diverged");
    common::small_cantilever(&dir, 10, &["solver.linear=\"iterative\""]);
    // Three Krylov iterations cannot reach the tolerance: every piece fails, is retried with
    // the other line search and cut, and the run ends naming both reasons.
    let out = common::run(
        &dir,
        1,
        &[
            "c.h5",
            "--until-step",
            "1",
            "--",
            "-ksp_max_it",
            "3",
            "-snes_ksp_ew",
            "false",
        ],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("DIVERGED_LINEAR_SOLVE: the linear solver DIVERGED_ITS")
            && stderr.contains("after 6 cuts"),
        "{stderr}"
    );
}

/// Runs `scene` (with `sets`) on `ranks` ranks for `steps` steps with the direct solver three
/// ways: LU factored every Newton iteration (the reference), the default (LDLᵀ where the
/// tangent is symmetric), and the default keeping factorisations (`-pfem_lu_reuse true`).
/// Returns, for the last two, the histories' largest relative difference from the reference
/// and their (Newton, linear) iterations.
fn direct_variants(
    dir: &Path,
    scene: &str,
    sets: &[&str],
    ranks: usize,
    steps: u32,
) -> Vec<(f64, (usize, usize))> {
    let until = steps.to_string();
    for (case, symmetric) in [("lu.h5", "false"), ("default.h5", "true")] {
        let symmetric = format!("solver.symmetric={symmetric}");
        let mut args = vec![
            "new",
            scene,
            "-o",
            case,
            "--set",
            "solver.linear=\"direct\"",
            "--set",
            &symmetric,
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        ok(dir, 1, &args);
    }
    let mut outs = Vec::new();
    for (case, reuse) in [
        ("lu.h5", "false"),
        ("default.h5", "false"),
        ("default.h5", "true"),
    ] {
        let out = format!("{}_{reuse}{ranks}", case.trim_end_matches(".h5"));
        let stdout = ok(
            dir,
            ranks,
            &[
                case,
                "--out",
                &out,
                "--until-step",
                &until,
                "--",
                "-pfem_lu_reuse",
                reuse,
            ],
        );
        outs.push((out, stdout));
    }
    let reference = dir.join(&outs[0].0).join("history.csv");
    outs[1..]
        .iter()
        .map(|(out, stdout)| {
            let diff = max_relative_difference(&reference, &dir.join(out).join("history.csv"));
            (diff, iterations(stdout))
        })
        .collect()
}

#[test]
fn symmetric_and_reused_factorisations_match_the_lu_history_on_1_and_2_ranks() {
    let dir = workdir("direct-variants");
    for ranks in [1, 2] {
        let runs = direct_variants(
            &dir,
            "cantilever",
            &["mesh.h=0.25", "steps.count=10"],
            ranks,
            3,
        );
        for ((diff, (newton, linear)), what) in runs.iter().zip(["LDLT", "LDLT kept"]) {
            println!("cantilever, {ranks} ranks, {what}: max relative difference from LU {diff:.2e}, {newton} Newton and {linear} linear iterations");
            assert!(*diff < 1e-6, "{what}, {ranks} ranks: {diff:e}");
        }
        // A fresh factorisation solves in one Krylov iteration; more mean some were kept.
        let (newton, linear) = runs[1].1;
        assert!(
            linear > newton,
            "factorisations were kept: {linear} linear iterations"
        );
    }
}

#[test]
fn reused_factorisations_solve_the_mixed_plastic_footing() {
    let dir = workdir("direct-variants-footing");
    let runs = direct_variants(
        &dir,
        "footing-shallow",
        &[
            "mesh.h=0.5",
            "mesh.fine=[{origin=[0.0,8.0],size=[4.0,2.0],h=0.25},\
             {origin=[0.5,9.5],size=[1.0,0.5],h=0.125}]",
        ],
        2,
        3,
    );
    for ((diff, (newton, linear)), what) in runs.iter().zip(["default", "kept"]) {
        println!("footing-shallow, 2 ranks, {what}: max relative difference from LU {diff:.2e}, {newton} Newton and {linear} linear iterations");
        assert!(*diff < 1e-6, "{what}: {diff:e}");
    }
}

#[test]
#[ignore = "slow end-to-end: two solver runs on an 83 000 dof cantilever"]
fn the_p_multigrid_takes_fewer_krylov_iterations_than_gamg_on_2_ranks() {
    // A coarse level with a wrong numbering on several ranks or without its rotations still
    // converges, so equal histories cannot catch it; its iteration count does. Measured on
    // this case (h = 1/32, one step of 50): 80 against 152 CG iterations (112 with the
    // start-of-step P1 stiffness as the coarse operator and one GAMG cycle).
    let dir = workdir("iterative-pmg-count");
    common::cantilever_case(&dir, "0.03125", 50, &["solver.linear=\"iterative\""]);
    let count = |extra: &[&str]| {
        let mut args = vec!["c.h5", "--out", "o", "--until-step", "1", "--"];
        args.extend(extra);
        iterations(&ok(&dir, 2, &args))
    };
    // Both at the same tight linear tolerance: the p-multigrid's inexact Newton would
    // otherwise be compared with GAMG's exact one.
    let (n_pmg, pmg) = count(&["-ksp_converged_reason", "-snes_ksp_ew", "false"]);
    let (n_gamg, gamg) = count(&["-pfem_pmg", "false"]);
    println!("p-multigrid {pmg} CG iterations in {n_pmg} Newton, GAMG {gamg} in {n_gamg}");
    assert_eq!(n_pmg, n_gamg, "the same Newton iterations");
    assert!(
        (pmg as f64) < 0.7 * gamg as f64,
        "p-multigrid {pmg} against GAMG {gamg} CG iterations"
    );
}

#[test]
#[ignore = "slow end-to-end: an 83 000 dof cantilever through a large rotation"]
fn the_coarse_operator_follows_the_tangent_through_a_large_rotation() {
    // With the coarse level solved exactly, the two-level method converges in a few Krylov
    // iterations whatever the tangent, as long as the coarse operator is the Galerkin product
    // of the current one. The cantilever's first increment of five rotates the tip by about
    // 30 degrees. Measured here (h = 1/32, 2 ranks, step 1): 101 CG iterations in 8 Newton
    // iterations; with the start-of-step P1 stiffness as the coarse operator, 539.
    let dir = workdir("iterative-pmg-galerkin");
    common::cantilever_case(&dir, "0.03125", 5, &["solver.linear=\"iterative\""]);
    let args = [
        "c.h5",
        "--out",
        "o",
        "--until-step",
        "1",
        "--",
        "-mg_coarse_pc_type",
        "lu",
        "-mg_coarse_pc_factor_mat_solver_type",
        "mumps",
        // Tight solves, as measured: inexact Newton's looser ones would hide a wrong coarse
        // operator under the bound.
        "-snes_ksp_ew",
        "false",
    ];
    let (newton, linear) = iterations(&ok(&dir, 2, &args));
    println!("exact coarse solve: {linear} CG iterations in {newton} Newton iterations");
    assert!(newton >= 5, "a large increment: {newton} Newton iterations");
    assert!(
        linear < 20 * newton,
        "{linear} CG iterations in {newton} Newton iterations"
    );
}

#[test]
#[ignore = "slow end-to-end: one step of 83 000 and 186 000 dof cantilevers on 2 ranks"]
fn auto_turns_to_the_p_multigrid_where_it_is_faster() {
    // One step of the 50-step cantilever, 2 ranks: at h = 1/32 (83 330 dofs) the direct path
    // and the p-multigrid tie (1.16 against 1.19 s), at h = 1/48 (186 434 dofs) the p-multigrid
    // leads (2.1–2.3 against 3.3–3.5 s, half the memory): `auto` switches between.
    for (h, dofs, iterative) in [
        ("0.03125", 83_330, false),
        ("0.0208333333333", 186_434, true),
    ] {
        let dir = workdir("iterative-auto");
        common::cantilever_case(&dir, h, 50, &[]);
        let view = ok(&dir, 2, &["c.h5", "--until-step", "1", "--", "-ksp_view"]);
        let dof_count: usize = view
            .lines()
            .filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit()))
            .filter_map(|l| l.split_whitespace().nth(3)?.parse::<usize>().ok())
            .sum();
        assert_eq!(dof_count, dofs, "owned dofs summed over the rank table");
        // The PC's own name in PETSc's view, not the `linear solver:` line (which names the
        // p-multigrid as the path above the switch whichever side the scene is on).
        let pmg_in_view = view.contains("p-multigrid (P2 Richardson-Jacobi");
        assert_eq!(pmg_in_view, iterative, "h = {h}:\n{view}");
        assert_eq!(view.contains("type: cholesky"), !iterative, "h = {h}");
    }
}

/// The p-multigrid on a scene with contact (its tangent is not symmetric: GMRES, and PETSc's
/// Chebyshev on P2) on 2 ranks, where the contact pairs lie on one rank's part: every
/// collective call of the Jacobian must be made on both. (A first version decided whether to
/// bound the spectrum from each rank's own contact list, so one rank's allreduce met another
/// collective and the run hung; a hang ends here at the timeout, as a failure.)
#[test]
#[ignore = "slow end-to-end: the default footing mesh on the iterative path"]
fn the_p_multigrid_runs_a_contact_scene_on_2_ranks() {
    let dir = workdir("iterative-pmg-contact");
    let mut new = vec!["new", "footing", "-o", "f.h5"];
    for set in [
        "material.model=\"linear-elastic\"",
        "solver.element=\"p2\"",
        "solver.linear=\"iterative\"",
        "mesh.fine=[]",
    ] {
        new.extend(["--set", set]);
    }
    ok(&dir, 1, &new);
    let out = std::process::Command::new("timeout")
        .args([
            "120",
            "mpirun",
            "-n",
            "2",
            "--oversubscribe",
            "--bind-to",
            "none",
        ])
        .args([
            common::bin(),
            "f.h5",
            "--until-step",
            "1",
            "--",
            "-ksp_view",
        ])
        .env("OMP_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .current_dir(&dir)
        .output()
        .expect("launch mpirun");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "status {:?}\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let fine = &stdout[stdout
        .find("KSP Object: (mg_levels_1_)")
        .expect("a PCMG level")..];
    let fine = &fine[..fine.find("PC Object").expect("its PC")];
    assert!(fine.contains("type: chebyshev"), "{fine}");
    assert!(stdout.contains("done: step 1"), "{stdout}");
}
