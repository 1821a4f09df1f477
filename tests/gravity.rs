//! Body force: an elastic column under its own weight, sides on rollers, base fixed. Exact
//! (small strain): σ_yy(y) = −ρ g (H − y) and u_y(top) = −ρ g H² / (2 M), M the constrained
//! modulus; the P2 element reproduces the quadratic displacement exactly, so only the tiny
//! large-deformation correction separates the run from the formula.

mod common;
use common::*;

#[test]
fn column_settles_under_self_weight() {
    let dir = workdir("gravity");
    let scene = r#"
name = "column"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 2.0] }]
[mesh]
h = 0.25
[material]
model = "linear-elastic"
young = 1.0e8
poisson = 0.3
density = 2000.0
[gravity]
g = [0.0, -9.81]
[[fixed]]
where = "y <= 0"
dofs = ["x", "y"]
[[fixed]]
where = "x <= 0"
dofs = ["x"]
[[fixed]]
where = "x >= 1"
dofs = ["x"]
[[point_load]]
at = [0.5, 2.0]
force = [0.0, 0.0]
[steps]
count = 2
[history]
kind = "cantilever"
"#;
    std::fs::write(dir.join("column.toml"), scene).unwrap();
    ok(&dir, 1, &["new", "column.toml", "-o", "col.h5"]);
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        ok(&dir, ranks, &["col.h5", "--out", &out]);
        let (_, rows) = history(&dir.join(&out).join("history.csv"));
        let (e, nu, rho, g, h) = (1.0e8, 0.3, 2000.0, 9.81, 2.0);
        let m = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let exact = rho * g * h * h / (2.0 * m);
        // history's v_over_L is the downward displacement of the tracked top particle / width (1 m).
        let v = rows[1][3];
        let rel = (v - exact) / exact;
        println!(
            "{ranks} ranks: top settlement {v:.6e} m, exact {exact:.6e} m ({:+.2e} relative)",
            rel
        );
        assert!(rel.abs() < 1e-3, "settlement {v} vs {exact}");
    }
}
