//! Contact with rigid bodies: the patch test (a frictionless platen wider than an elastic block
//! gives the exact uniform pressure), frictionless contact carries no shear, a rough interface
//! sticks below α·cu and slips at it, on 1 and 2 ranks.

mod common;
use common::*;
use std::path::Path;

/// Elastic block 1 m × 1 m (E = 1 MPa, ν = 0.3) on a smooth base, pressed 1 % by a rigid platen
/// wider than the block in one step.
const PATCH: &str = r#"
name = "patch"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 1.0] }]
[mesh]
h = 0.25
refine = false
[material]
model = "linear-elastic"
young = 1.0e6
poisson = 0.3
[[fixed]]
name = "base"
where = "y <= 0"
dofs = ["y"]
[[fixed]]
where = "y <= 0 and x <= 0"
dofs = ["x"]
[[probe]]
name = "left"
at = [0.0, 1.0]
[[probe]]
name = "mid"
at = [0.5, 1.0]
[[probe]]
name = "quarter"
at = [0.75, 1.0]
[[probe]]
name = "right"
at = [1.0, 1.0]
[[rigid]]
name = "platen"
polygon = { vertices = [[-0.5, 1.0], [1.5, 1.0], [1.5, 1.2], [-0.5, 1.2]] }
stages = [{ to = [0.0, -0.01], steps = 1 }]
[history]
columns = [
  { name = "fx", measure = "rigid.platen.fx" },
  { name = "fy", measure = "rigid.platen.fy" },
  { name = "base_fy", measure = "reaction.base.fy" },
  { name = "left_uy", measure = "probe.left.uy" },
  { name = "mid_uy", measure = "probe.mid.uy" },
  { name = "quarter_uy", measure = "probe.quarter.uy" },
  { name = "right_uy", measure = "probe.right.uy" },
  { name = "right_ux", measure = "probe.right.ux" },
]
"#;

/// The exact one-step solution of the element's material (S = C:E on the Green–Lagrange strain
/// of the step, σ = F S Fᵀ/J), uniaxial in plane strain: the platen force per metre and the
/// lateral stretch a of F = diag(1 + a, 1 − e).
fn exact_uniaxial(young: f64, nu: f64, e: f64) -> (f64, f64) {
    let lambda = young * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = young / (2.0 * (1.0 + nu));
    let eyy = 0.5 * ((1.0 - e).powi(2) - 1.0);
    let exx = -lambda * eyy / (lambda + 2.0 * mu);
    let a = (1.0 + 2.0 * exx).sqrt() - 1.0;
    let syy = (lambda + 2.0 * mu) * eyy + lambda * exx;
    // Force on the current top (width 1 + a): σ_yy (1 + a) = (1 − e) S_yy.
    ((1.0 - e) * syy, a)
}

fn last_row(dir: &Path, out: &str) -> (Vec<String>, Vec<f64>) {
    let (header, rows) = history(&dir.join(out).join("history.csv"));
    (header, rows.last().expect("a row").clone())
}

#[test]
fn frictionless_platen_gives_the_exact_uniform_pressure() {
    let dir = workdir("contact-patch");
    std::fs::write(dir.join("patch.toml"), PATCH).unwrap();
    ok(&dir, 1, &["new", "patch.toml", "-o", "p.h5"]);
    let (force, a) = exact_uniaxial(1.0e6, 0.3, 0.01);
    // The soil pushes the platen up: S_yy < 0, the platen's force > 0.
    let force = -force;
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        ok(&dir, ranks, &["p.h5", "--out", &out]);
        let (header, r) = last_row(&dir, &out);
        assert_eq!(header[0], "step");
        let col = |name: &str| r[header.iter().position(|h| h == name).expect(name)];
        println!(
            "{ranks} ranks: platen force {:e} (exact {force:e}), relative error {:.2e}",
            col("fy"),
            (col("fy") - force).abs() / force
        );
        // The soil pushes the platen up with the exact force: uniform pressure, no penetration.
        assert!((col("fy") - force).abs() < 1e-6 * force, "fy {}", col("fy"));
        assert!((col("base_fy") - force).abs() < 1e-6 * force);
        // Frictionless: no tangential force at all, and the top expands freely.
        assert!(col("fx").abs() < 1e-9 * force.abs(), "fx {}", col("fx"));
        assert!(
            (col("right_ux") - a).abs() < 1e-6 * a.abs(),
            "ux {}",
            col("right_ux")
        );
        // A uniform pressure keeps the top flat at the platen's face.
        for p in ["left_uy", "mid_uy", "quarter_uy", "right_uy"] {
            assert!((col(p) + 0.01).abs() < 1e-8, "{p} {}", col(p));
        }
    }
}

/// Tresca block (stiff, elastic here) fixed at its base; a rough platen (α = 0.1, so α·cu =
/// 1 kPa) pressed down 0.5 % and then moved sideways.
const ROUGH: &str = r#"
name = "rough"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 0.5] }]
[mesh]
h = 0.125
refine = false
[material]
model = "tresca"
young = 1.0e6
poisson = 0.3
cu = 1.0e4
[[fixed]]
where = "y <= 0"
dofs = ["x", "y"]
[[probe]]
name = "top"
at = [0.5, 0.5]
[[rigid]]
name = "platen"
polygon = { vertices = [[-0.5, 0.5], [1.5, 0.5], [1.5, 0.7], [-0.5, 0.7]] }
stages = [{ to = [0.0, -0.0025], steps = 1 }, { to = [STICK, -0.0025], steps = 1 }, { to = [SLIP, -0.0025], steps = 2 }]
adhesion = 0.1
[history]
columns = [
  { name = "fx", measure = "rigid.platen.fx" },
  { name = "fy", measure = "rigid.platen.fy" },
  { name = "platen_ux", measure = "rigid.platen.ux" },
  { name = "top_ux", measure = "probe.top.ux" },
]
"#;

#[test]
fn rough_platen_sticks_below_the_limit_and_slips_at_it() {
    let dir = workdir("contact-rough");
    // Sticking needs a shear below α·cu = 1 kPa over the 1 m top: a 5e-5 m shift of a 0.5 m
    // block with G = 385 kPa is about 40 Pa; 5e-3 m would need 4 kPa, so the top slips.
    let text = ROUGH.replace("STICK", "0.00005").replace("SLIP", "0.005");
    std::fs::write(dir.join("rough.toml"), text).unwrap();
    ok(&dir, 1, &["new", "rough.toml", "-o", "r.h5"]);
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        ok(&dir, ranks, &["r.h5", "--out", &out]);
        let (header, rows) = history(&dir.join(&out).join("history.csv"));
        let col = |r: &Vec<f64>, name: &str| r[header.iter().position(|h| h == name).unwrap()];
        // Step 2: stuck, the top follows the platen.
        let stick = &rows[1];
        println!("{ranks} ranks: stick {stick:?}, slip {:?}", rows[3]);
        let shift = col(stick, "platen_ux");
        assert!(
            (col(stick, "top_ux") - shift).abs() < 1e-3 * shift,
            "top {}",
            col(stick, "top_ux")
        );
        assert!(
            col(stick, "fx").abs() < 1e3,
            "below the limit: {}",
            col(stick, "fx")
        );
        assert!(
            col(stick, "fx") < 0.0,
            "the soil resists the platen's motion"
        );
        // Step 4: slipping, the shear is α·cu over the contact (the top, 1 m wide at the start
        // of the step).
        let slip = &rows[3];
        assert!(col(slip, "top_ux") < 0.5 * col(slip, "platen_ux"));
        let shear = -col(slip, "fx");
        assert!((shear - 1.0e3).abs() < 5e-3 * 1.0e3, "slip shear {shear}");
    }
}

#[test]
fn a_platen_made_of_two_overlapping_bodies_gives_the_one_platens_exact_force() {
    // Two bodies moving as one (a cone and its shaft): the nodes near both hold one law, the
    // nearer body's; each node's force counts once, so the halves sum to the exact force.
    let split = PATCH
        .replace(
            "name = \"platen\"\npolygon = { vertices = [[-0.5, 1.0], [1.5, 1.0], [1.5, 1.2], [-0.5, 1.2]] }",
            "name = \"left\"\npolygon = { vertices = [[-0.5, 1.0], [0.55, 1.0], [0.55, 1.2], [-0.5, 1.2]] }\n\
             stages = [{ to = [0.0, -0.01], steps = 1 }]\n\
             [[rigid]]\n\
             name = \"right\"\npolygon = { vertices = [[0.45, 1.0], [1.5, 1.0], [1.5, 1.2], [0.45, 1.2]] }",
        )
        .replace("rigid.platen.fx", "rigid.left.fx")
        .replace("rigid.platen.fy", "rigid.left.fy")
        .replace(
            "{ name = \"base_fy\"",
            "{ name = \"right_fy\", measure = \"rigid.right.fy\" },\n  { name = \"base_fy\"",
        );
    assert!(split.contains("rigid.right.fy") && split.contains("name = \"right\""));
    let dir = workdir("contact-two-bodies");
    std::fs::write(dir.join("split.toml"), &split).unwrap();
    ok(&dir, 1, &["new", "split.toml", "-o", "p.h5"]);
    let force = -exact_uniaxial(1.0e6, 0.3, 0.01).0;
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        let log = ok(&dir, ranks, &["p.h5", "--out", &out]);
        let (header, r) = last_row(&dir, &out);
        let col = |name: &str| r[header.iter().position(|h| h == name).expect(name)];
        let total = col("fy") + col("right_fy");
        let newton = newton_iterations(&log);
        println!(
            "{ranks} ranks: left {:e} + right {:e} = {total:e} (exact {force:e}), {newton} Newton \
             iterations",
            col("fy"),
            col("right_fy")
        );
        assert!(col("fy") > 0.0 && col("right_fy") > 0.0);
        // Measured: 1e-16 and 3 Newton iterations; with both laws on the shared nodes (before)
        // 5e-10 after 24 iterations, Newton slowed by the doubled constraint rows.
        assert!((total - force).abs() < 1e-11 * force, "total {total}");
        assert!(newton <= 8, "{newton} Newton iterations");
        assert!((col("base_fy") - force).abs() < 1e-6 * force);
        for p in ["left_uy", "mid_uy", "quarter_uy", "right_uy"] {
            assert!((col(p) + 0.01).abs() < 1e-8, "{p} {}", col(p));
        }
    }
}

/// The total Newton iterations of a run, from its `done:` line.
fn newton_iterations(log: &str) -> usize {
    let done = log
        .lines()
        .find(|l| l.starts_with("done:"))
        .expect("a done: line");
    let before = done
        .split(" Newton iterations")
        .next()
        .expect("Newton iterations");
    before
        .rsplit(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count in {done:?}"))
}
