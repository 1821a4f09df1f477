//! Any site (issue 27): strength that grows with depth, gravity ramped to collapse.

mod common;
use common::*;
use std::path::Path;

/// A 1 m square Tresca block whose cu grows from 10 kPa at the top (y = 1) to 15 kPa at the
/// bottom, squeezed horizontally between smooth platens by 5 %: its layers work in parallel, so
/// once all have yielded σxx = −2 cu(y0) at every depth, y0 the depth a particle started at.
const GRADED_BLOCK: &str = r#"
name = "graded-block"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 1.0] }]
[mesh]
h = 0.125
[material]
model = "tresca"
young = 3.0e6
poisson = 0.49
cu = 1.0e4
cu_gradient = 5.0e3
reference_level = 1.0
[[prescribed]]
name = "left"
where = "x <= 0"
dofs = ["x"]
total = [0.025, 0.0]
select = "current"
[[prescribed]]
name = "right"
where = "x >= 1"
dofs = ["x"]
total = [-0.025, 0.0]
select = "current"
[[fixed]]
where = "y <= 0 and x >= 0.5 and x <= 0.5"
dofs = ["y"]
[steps]
count = 10
[history]
columns = [
  { name = "force", measure = "reaction.right.fx" },
  { name = "area", measure = "area" },
]
[solver]
newton_max_it = 60
"#;

/// (x0, y0, σxx, cu) of every particle of a checkpoint, read back by h5py.
fn particles(file: &Path) -> Vec<[f64; 4]> {
    let script = format!(
        "import h5py\nf = h5py.File({:?}, 'r')\nd = f['particles/state']\n\
         names = [n if isinstance(n, str) else n.decode() for n in d.attrs['names']]\n\
         s = d[...]\nx = f['particles/position'][...] - f['particles/displacement'][...]\n\
         for i in range(len(s)):\n    \
         print(x[i, 0], x[i, 1], s[i, names.index('stress_xx')], s[i, names.index('cu')])",
        file.display().to_string()
    );
    let out = std::process::Command::new("python3")
        .args(["-c", &script])
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

#[test]
fn strength_growing_with_depth_is_carried_by_each_particle() {
    let dir = workdir("graded-block");
    std::fs::write(dir.join("graded.toml"), GRADED_BLOCK).unwrap();
    ok(&dir, 1, &["new", "graded.toml", "-o", "g.h5"]);
    // At the start every particle's cu is that of its height.
    for [_, y0, _, cu] in particles(&dir.join("g.h5")) {
        let want = 1.0e4 + 5.0e3 * (1.0 - y0);
        assert!(
            (cu - want).abs() <= 1e-9 * want,
            "cu {cu} at y {y0}: {want}"
        );
    }
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        ok(&dir, ranks, &["g.h5", "--out", &out]);
        let cp = dir.join(&out).join("checkpoints/step_000010.h5");
        let mut worst: f64 = 0.0;
        for [_, y0, sxx, cu] in particles(&cp) {
            let want = 1.0e4 + 5.0e3 * (1.0 - y0);
            assert!((cu - want).abs() <= 1e-9 * want, "cu {cu} at y0 {y0}");
            worst = worst.max((sxx + 2.0 * want).abs() / (2.0 * want));
        }
        println!("{ranks} rank(s): largest |σxx + 2 cu(y0)| / 2 cu(y0) = {worst:.2e}");
        assert!(
            worst < 1e-6,
            "σxx must be −2 cu(y0) at every depth: {worst:e}"
        );
        // The platen carries ∫ 2 cu dy over the layers: 2 x 12.5 kPa (the mean cu) over the
        // block's height now, its area over its width 0.95 m, to within the layers' different
        // elastic volume change (p = cu(y) over K = 50 MPa: a 1e-4 spread, weighted by the 20 %
        // spread of cu: measured 3.3e-6).
        let (_, rows) = history(&dir.join(&out).join("history.csv"));
        let (force, area) = (rows.last().unwrap()[1], rows.last().unwrap()[2]);
        let want = -2.0 * 1.25e4 * area / 0.95;
        assert!(
            (force - want).abs() <= 1e-5 * want.abs(),
            "platen force {force}, expected {want}"
        );
    }
}

#[test]
fn a_strength_that_turns_negative_is_refused() {
    let dir = workdir("graded-bad");
    let bad = GRADED_BLOCK.replace("cu_gradient = 5.0e3", "cu_gradient = -2.0e4");
    std::fs::write(dir.join("bad.toml"), bad).unwrap();
    let out = run(&dir, 1, &["new", "bad.toml", "-o", "b.h5"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("bad.toml") && err.contains("material.cu_gradient") && err.contains("y = 0"),
        "{err}"
    );
    assert!(!dir.join("b.h5").exists());
    let elastic = GRADED_BLOCK.replace("model = \"tresca\"", "model = \"linear-elastic\"");
    std::fs::write(dir.join("el.toml"), elastic).unwrap();
    let out = run(&dir, 1, &["new", "el.toml", "-o", "e.h5"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("material.cu_gradient"),
        "{err}"
    );
}

/// The coarse vertical cut (h = H/10) collapses within 5 % of Ns = 3.78 on 1 and 2 ranks, and
/// says so with exit 0.
#[test]
fn a_coarse_vertical_cut_collapses_near_the_exact_stability_number() {
    let dir = workdir("vertical-cut");
    ok(
        &dir,
        1,
        &["new", "vertical-cut", "-o", "vc.h5", "--set", "mesh.h=0.5"],
    );
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        let text = ok(&dir, ranks, &["vc.h5", "--out", &out]);
        assert!(text.contains("collapse reached"), "{text}");
        let (header, rows) = history(&dir.join(&out).join("history.csv"));
        assert_eq!(header, ["step", "load_factor", "Ns", "crest_ux"]);
        let ns = rows.last().unwrap()[2];
        println!("{ranks} rank(s): Ns at collapse {ns:.4} (exact 3.78)");
        assert!((ns - 3.78).abs() <= 0.05 * 3.78, "Ns {ns}");
    }
}
