//! A body imported from Gmsh (issue 27, item 3): `.geo` → `.msh` (by the `gmsh` that
//! `.ci/install-native` installs) → `new` → run. Particles are the mesh nodes, physical surfaces
//! are zones of their materials, physical curves are selections, and the case file no longer
//! needs the mesh.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

/// The committed site: 3 m of soft clay over 4 m of stiff clay, 20 m wide. Elastic layers under
/// their own weight from the geostatic state: the stiff layer is named by its physical surface,
/// the soft one claimed by a zone entry for material "light".
const SITE: &str = r#"
name = "gmsh-site"
[body]
mesh = "site.msh"
zones = [{ name = "soft-clay", material = "light" }]
[mesh]
h = 1.0
[[material]]
name = "stiff-clay"
model = "linear-elastic"
young = 5.0e7
poisson = 0.3
density = 2000.0
[[material]]
name = "light"
model = "linear-elastic"
young = 1.0e7
poisson = 0.3
density = 1600.0
[gravity]
g = [0.0, -9.81]
[geostatic]
surface = 7.0
k0 = 0.4285714285714286
[[fixed]]
on = "base"
dofs = ["x", "y"]
[[fixed]]
on = "sides"
dofs = ["x"]
[steps]
count = 3
[history]
columns = [{ name = "uy", measure = "probe.top.uy" }]
[[probe]]
name = "top"
at = [10.0, 7.0]
"#;

/// Meshes the committed `.geo` into `dir/name` with Gmsh (`extra`: e.g. `-bin`); false when
/// there is no Gmsh (outside CI: the test is skipped).
fn gmsh(dir: &Path, name: &str, extra: &[&str]) -> bool {
    if !prerequisite("gmsh", tool_runs("gmsh")) {
        return false;
    }
    let geo = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/layered-site.geo");
    let out = Command::new("gmsh")
        .args(["-2", "-format", "msh41", "-clscale", "1"])
        .args(extra)
        .arg(&geo)
        .arg("-o")
        .arg(dir.join(name))
        .output()
        .expect("gmsh ran for --version");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    true
}

/// The node count of a MSH 4.1 file: the second number after `$Nodes` (ASCII), or from the
/// same header of a binary file, which Gmsh writes as text.
fn node_count(file: &Path) -> u64 {
    let bytes = std::fs::read(file).unwrap();
    let at = bytes.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
    let text = String::from_utf8_lossy(&bytes[at..at + 200]);
    if text.starts_with(|c: char| c.is_ascii_digit()) {
        return text.split_whitespace().nth(1).unwrap().parse().unwrap();
    }
    // Binary: four size_t (8 bytes) numbers.
    u64::from_le_bytes(bytes[at + 8..at + 16].try_into().unwrap())
}

fn particles_written(stdout: &str) -> u64 {
    let (_, rest) = stdout.split_once(" (").unwrap();
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

/// (y0, σyy, material) of every particle of a case file.
fn stresses(file: &Path) -> Vec<(f64, f64, u32)> {
    let rows = h5py_rows(
        file,
        "s = f['particles/state'][...]\nm = f['particles/material'][...]\n\
         x = f['particles/position'][...] - f['particles/displacement'][...]\n\
         for i in range(len(s)): print(x[i, 1], s[i, 1], m[i])",
    );
    rows.iter().map(|v| (v[0], v[1], v[2] as u32)).collect()
}

fn weight_above(y: f64) -> f64 {
    let above = |lo: f64, hi: f64| (hi - y.max(lo)).max(0.0);
    -9.81 * (2000.0 * above(0.0, 4.0) + 1600.0 * above(4.0, 7.0))
}

#[test]
fn a_site_meshed_in_gmsh_runs_from_its_nodes_and_physical_groups() {
    let dir = workdir("gmsh-site");
    std::fs::write(dir.join("site.toml"), SITE).unwrap();
    for (msh, extra) in [("site.msh", &[][..]), ("binary.msh", &["-bin"][..])] {
        if !gmsh(&dir, msh, extra) {
            return;
        }
        let toml = SITE.replace("site.msh", msh);
        std::fs::write(dir.join("s.toml"), toml).unwrap();
        let out = ok(&dir, 1, &["new", "s.toml", "-o", "s.h5"]);
        assert_eq!(
            particles_written(&out),
            node_count(&dir.join(msh)),
            "{msh}: one particle per node"
        );
    }
    // The binary and ASCII files give the same case; the case needs no mesh file any more.
    let out = ok(&dir, 1, &["new", "site.toml", "-o", "site.h5"]);
    std::fs::remove_file(dir.join("site.msh")).unwrap();
    let info = ok(&dir, 1, &["info", "site.h5"]);
    assert!(info.contains("\"light\""), "{info}");
    ok(&dir, 2, &["site.h5", "--out", "r"]);
    let n = particles_written(&out);
    let scale = -weight_above(0.0);
    for file in [
        dir.join("site.h5"),
        dir.join("r/checkpoints/step_000003.h5"),
    ] {
        let rows = stresses(&file);
        assert_eq!(rows.len() as u64, n);
        let mut worst: f64 = 0.0;
        for (y, syy, m) in &rows {
            worst = worst.max((syy - weight_above(*y)).abs() / scale);
            // An interface node belongs to the surface of the lower tag: stiff-clay (tag 1).
            let want = if *y <= 4.0 + 1e-9 { 0 } else { 1 };
            assert_eq!(*m, want, "material of the particle at y = {y}");
        }
        println!(
            "{}: largest |σyy − weight above| / weight = {worst:.2e}",
            file.display()
        );
        assert!(worst < 1e-12, "{worst:e}");
    }
    let (_, rows) = history(&dir.join("r/history.csv"));
    let uy = rows.last().unwrap()[1];
    assert!(
        uy.abs() < 1e-9,
        "the geostatic site must not move: uy = {uy}"
    );
}

#[test]
fn bad_gmsh_bodies_are_refused_naming_the_file_and_field() {
    let dir = workdir("gmsh-bad");
    if !gmsh(&dir, "site.msh", &[]) {
        return;
    }
    let cases: [(&str, &str, &str); 4] = [
        (
            "mesh = \"site.msh\"",
            "mesh = \"missing.msh\"",
            "missing.msh: mesh file not found",
        ),
        (
            "zones = [{ name = \"soft-clay\", material = \"light\" }]",
            "",
            "physical surface \"soft-clay\" is claimed by no [[material]]",
        ),
        (
            "name = \"soft-clay\", material = \"light\"",
            "name = \"sand\", material = \"light\"",
            "\"sand\" is no physical surface",
        ),
        ("on = \"sides\"", "on = \"flanks\"", "flanks"),
    ];
    for (from, to, message) in cases {
        std::fs::write(dir.join("bad.toml"), SITE.replace(from, to)).unwrap();
        let out = run(&dir, 1, &["new", "bad.toml", "-o", "bad.h5"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{to}: accepted");
        assert!(err.contains(message), "{to}: {err}");
        assert!(err.contains("bad.toml"), "{to}: the scene is named: {err}");
        assert!(!dir.join("bad.h5").exists(), "{to}: nothing is written");
    }
    std::fs::write(
        dir.join("damaged.msh"),
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2",
    )
    .unwrap();
    let text = SITE.replace("site.msh", "damaged.msh");
    std::fs::write(dir.join("bad.toml"), text).unwrap();
    let out = run(&dir, 1, &["new", "bad.toml", "-o", "bad.h5"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("damaged.msh"),
        "{err}"
    );
    assert!(err.contains("body.mesh"), "the field is named: {err}");
}

/// `examples/embankment`: the committed Gmsh site runs on 2 ranks to its stated settlement, and
/// the base carries the weight of the three zones.
fn embankment_case(dir: &Path) {
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/embankment");
    for f in ["embankment.toml", "embankment.msh"] {
        std::fs::copy(example.join(f), dir.join(f)).unwrap();
    }
    ok(dir, 1, &["new", "embankment.toml", "-o", "e.h5"]);
}

/// Σ density · g · area of the stiff clay (40 × 6 m), the soft clay (40 × 4 m) and the fill (a
/// trapezoid 24 m and 12 m wide, 3 m high).
const EMBANKMENT_WEIGHT: f64 = 9.81 * (1800.0 * 240.0 + 1600.0 * 160.0 + 1900.0 * 54.0);

#[test]
fn the_embankment_example_settles_as_stated_on_2_ranks() {
    let dir = workdir("embankment");
    embankment_case(&dir);
    ok(&dir, 2, &["e.h5", "--out", "r"]);
    let (names, rows) = history(&dir.join("r/history.csv"));
    let col = |n: &str| names.iter().position(|c| c == n).unwrap();
    let last = rows.last().unwrap();
    assert_eq!(last[col("load_factor")], 1.0);
    let weight = last[col("base_fy")];
    let crest = last[col("crest_uy")];
    println!(
        "crest settles {:.2} mm; the base carries {weight:.1} N/m",
        -1e3 * crest
    );
    assert!(
        (weight - EMBANKMENT_WEIGHT).abs() < 2e-3 * EMBANKMENT_WEIGHT,
        "{weight} against {EMBANKMENT_WEIGHT}"
    );
    // The figure the README states (32.0 mm, measured); the guard is the mesh's, not physics'.
    assert!((-crest - 0.0320).abs() < 0.0010, "crest settlement {crest}");
}

/// Zones of three materials: the mesh and the history do not depend on the rank count, and a
/// checkpoint written on 2 ranks continues on 3 as the uninterrupted 1-rank run.
#[test]
fn a_zoned_site_is_the_same_on_1_2_3_ranks_and_restarts_on_another_count() {
    let dir = workdir("embankment-ranks");
    embankment_case(&dir);
    let prints: Vec<String> = [1, 2, 3]
        .iter()
        .map(|&n| ok(&dir, n, &["mesh", "e.h5"]).trim().to_string())
        .collect();
    assert!(prints[0].starts_with("fingerprint "), "{}", prints[0]);
    assert!(prints.iter().all(|p| p == &prints[0]), "{prints:#?}");
    for n in [1, 2, 3] {
        ok(
            &dir,
            n,
            &["e.h5", "--out", &format!("r{n}"), "--until-step", "4"],
        );
    }
    ok(&dir, 3, &["r2/checkpoints/step_000004.h5", "--out", "c3"]);
    ok(&dir, 1, &["e.h5", "--out", "full"]);
    let (_, one) = history(&dir.join("r1/history.csv"));
    for n in [2, 3] {
        let (_, other) = history(&dir.join(format!("r{n}/history.csv")));
        assert_eq!(one.len(), other.len());
        for (a, b) in one.iter().zip(&other) {
            for (x, y) in a.iter().zip(b) {
                assert!(
                    (x - y).abs() <= 1e-9 * x.abs().max(1e-12),
                    "{n} ranks: {x} vs {y}"
                );
            }
        }
    }
    let (_, full) = history(&dir.join("full/history.csv"));
    let (_, continued) = history(&dir.join("c3/history.csv"));
    let (a, b) = (full.last().unwrap(), continued.last().unwrap());
    assert_eq!(a[0], b[0], "the continued run ends at the same step");
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x - y).abs() <= 1e-3 * x.abs(),
            "continued on 3 ranks: {y} against {x}"
        );
    }
}
