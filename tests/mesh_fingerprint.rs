//! The global mesh does not depend on the rank count: `pfem-mpi mesh` prints the same fingerprint
//! on 1, 2 and 3 ranks for a lattice (all cells cocircular), a random cloud and a heavily
//! deformed cloud (the bent cantilever).

mod common;
use common::*;
use std::path::Path;

fn fingerprints(dir: &Path, file: &str) -> Vec<String> {
    [1, 2, 3]
        .iter()
        .map(|&n| ok(dir, n, &["mesh", file]).trim().to_string())
        .collect()
}

fn assert_same(what: &str, lines: &[String]) {
    println!("{what}: {}", lines[0]);
    assert!(lines[0].starts_with("fingerprint "), "{lines:?}");
    assert!(
        lines.iter().all(|l| l == &lines[0]),
        "{what}: fingerprints differ between 1, 2, 3 ranks: {lines:#?}"
    );
}

fn count(line: &str, key: &str) -> u64 {
    let words: Vec<&str> = line.split_whitespace().collect();
    let i = words.iter().position(|w| *w == key).expect(key);
    words[i + 1].parse().expect("count")
}

#[test]
fn lattice_mesh_is_rank_count_independent() {
    let dir = workdir("fp-lattice");
    ok(&dir, 1, &["new", "cantilever", "-o", "c.h5"]);
    let lines = fingerprints(&dir, "c.h5");
    assert_same("lattice", &lines);
    // 80 x 8 cells, two triangles each; perimeter 2 * (80 + 8) edges.
    assert_eq!(count(&lines[0], "particles"), 81 * 9);
    assert_eq!(count(&lines[0], "triangles"), 1280);
    assert_eq!(count(&lines[0], "boundary_edges"), 176);
}

#[test]
fn random_cloud_mesh_is_rank_count_independent() {
    let dir = workdir("fp-random");
    ok(
        &dir,
        1,
        &[
            "new",
            "cantilever",
            "-o",
            "j.h5",
            "--set",
            "body.jitter=0.45",
            "--set",
            "mesh.h=0.1",
        ],
    );
    assert_same("random cloud", &fingerprints(&dir, "j.h5"));
}

#[test]
fn deformed_cloud_mesh_is_rank_count_independent() {
    let dir = workdir("fp-deformed");
    small_cantilever(&dir, 10, &[]);
    ok(&dir, 2, &["c.h5"]);
    let bent = "c.out/checkpoints/step_000010.h5";
    let lines = fingerprints(&dir, bent);
    assert_same("bent cantilever", &lines);
    let straight = ok(&dir, 1, &["mesh", "c.h5"]);
    assert_ne!(
        straight.trim(),
        lines[0],
        "the bent beam must mesh differently from the straight one"
    );
}

/// A graded cloud (`mesh.fine` regions around the footing edge) meshes without holes (Euler:
/// triangles = 2 n − 2 − boundary vertices, one boundary loop) and identically on 1, 2, 3 ranks.
#[test]
fn graded_cloud_meshes_without_holes_on_any_rank_count() {
    let dir = workdir("fp-graded");
    let fine = "mesh.fine=[{origin=[0.0,8.5],size=[2.5,1.5],h=0.125},{origin=[0.5,9.5],size=[1.0,0.5],h=0.0625}]";
    ok(
        &dir,
        1,
        &["new", "footing-shallow", "-o", "g.h5", "--set", fine],
    );
    let lines = fingerprints(&dir, "g.h5");
    assert_same("graded cloud", &lines);
    let (n, t, b) = (
        count(&lines[0], "particles"),
        count(&lines[0], "triangles"),
        count(&lines[0], "boundary_edges"),
    );
    assert!(n > 41 * 41, "fine regions add particles: {n}");
    assert_eq!(
        t,
        2 * n - 2 - b,
        "a hole or a missing triangle: {}",
        lines[0]
    );
}

/// `[mesh.adapt]` sets the spacings from the last step's solution with max reductions and
/// bitwise ghost copies only, so the adapted and refined mesh of a checkpoint is the same on 1,
/// 2 and 3 ranks; it must differ from the checkpoint's own cloud (the adaptation acts: the coarse
/// footing refines round its edge from 355 particles).
#[test]
fn adapted_mesh_is_rank_count_independent() {
    let dir = workdir("fp-adapt");
    ok(
        &dir,
        1,
        &[
            "new",
            "footing",
            "-o",
            "a.h5",
            "--set",
            "mesh.h=1.0",
            "--set",
            "mesh.fine=[{origin=[0.0,5.0],size=[5.0,5.0],h=0.5},{origin=[0.0,6.5],size=[2.5,3.5],h=0.25}]",
            "--set",
            "rigid[0].stages=[{to=[0.0,-0.2],steps=10}]",
            "--set",
            "mesh.adapt={h_min=0.125,h_max=1.0}",
        ],
    );
    ok(&dir, 1, &["a.h5", "--until-step", "1"]);
    let after = "a.out/checkpoints/step_000001.h5";
    let lines = fingerprints(&dir, after);
    assert_same("adapted footing", &lines);
    let info = ok(&dir, 1, &["info", after]);
    let before: u64 = info
        .lines()
        .find_map(|l| l.strip_prefix("particles"))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no particle count in:\n{info}"));
    let adapted = count(&lines[0], "particles");
    assert!(
        adapted > 2 * before,
        "the spacing should have been refined round the edge: {before} -> {adapted}"
    );
}
