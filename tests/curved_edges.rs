//! Curved boundary edges (`mesh.curved_edges`, `src/mesh/curved.rs`): the curve a boundary edge's
//! midside node takes in a step is kept across the remesh and through a checkpoint. On the
//! footing nobody tuned (tests/scenes/untuned-footing.toml), the soil round the footing's rounded
//! corners bends its boundary edges; the checkpoint holds those curves, a restart from it
//! repeats the run bit for bit, and the same run with straight edges takes another path.

mod common;
use common::*;
use std::path::Path;

const SCENE: &str = include_str!("scenes/untuned-footing.toml");

fn rows(dir: &Path, out: &str) -> Vec<Vec<f64>> {
    history(&dir.join(out).join("history.csv")).1
}

#[test]
fn curves_survive_remesh_and_checkpoint_and_change_the_path() {
    let dir = workdir("curved-edges");
    std::fs::write(dir.join("untuned.toml"), SCENE).unwrap();
    let case = [
        "new",
        "untuned.toml",
        "-o",
        "u.h5",
        "--set",
        "output.checkpoint_every=3",
    ];
    ok(&dir, 1, &case);
    ok(&dir, 1, &["u.h5", "--out", "full", "--until-step", "6"]);
    ok(&dir, 1, &["u.h5", "--out", "split", "--until-step", "3"]);
    let cp = dir.join("split/checkpoints/step_000003.h5");

    // The checkpoint holds a curve for the boundary edges of the last mesh (NaN elsewhere):
    // relative offsets, at most a quarter of the chord, some clearly off the chord (measured:
    // 26 edges, the largest 0.115 of its chord).
    let curves: Vec<f64> = h5py_rows(
        &cp,
        "import math\nfor v in f['gauss/bulge'][()].ravel():\n    \
         print(v) if not math.isnan(v) else None",
    )
    .into_iter()
    .flatten()
    .collect();
    let largest = curves.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    println!("{} curved edges, largest offset {largest}", curves.len());
    assert!(curves.len() >= 10, "{} curved edges", curves.len());
    assert!(largest <= 0.25, "{largest}");
    assert!(largest > 1e-3, "{largest}: no edge bent");

    // Restarted from the checkpoint on the same rank count, the run is the uninterrupted one.
    ok(
        &dir,
        1,
        &["split/checkpoints/step_000003.h5", "--until-step", "6"],
    );
    assert_eq!(rows(&dir, "full"), rows(&dir, "split"));

    // Rebuilt straight at every remesh, the same push takes another path.
    ok(
        &dir,
        1,
        &[&case[..4], &["--set", "mesh.curved_edges=false"]].concat(),
    );
    ok(&dir, 1, &["u.h5", "--out", "straight", "--until-step", "6"]);
    let (curved, straight) = (rows(&dir, "full"), rows(&dir, "straight"));
    assert_eq!(curved.len(), 6);
    assert_eq!(straight.len(), 6);
    let largest_difference = curved
        .iter()
        .zip(&straight)
        .map(|(a, b)| (a[3] - b[3]).abs())
        .fold(0.0, f64::max);
    assert!(
        largest_difference > 1e-6,
        "V/(B cu) {largest_difference} apart with and without curves"
    );
}
