//! Axisymmetric analysis through the whole PFEM loop (issue 29): x is the radius, y the axis,
//! and every force is the whole circle's. Closed forms: a solid cylinder squeezed between smooth
//! platens (elastic at large strain, and Tresca at 2 cu), Lamé's thick-walled cylinder; the
//! mesh and the history do not depend on the rank count, a checkpoint continues on another
//! count, and a scene that breaks the symmetry is refused naming the field.

mod common;
use common::*;
use std::f64::consts::PI;
use std::path::Path;

/// A solid cylinder of radius 1 and height 2 on a smooth base, its top pushed down `total`
/// in `steps` steps by a smooth platen; `material` is the body of a `[material]` table.
fn cylinder(material: &str, total: f64, steps: u32, h: f64, extra: &str) -> String {
    format!(
        r#"
name = "cylinder"
analysis = "axisymmetric"
[body]
rectangles = [{{ origin = [0.0, 0.0], size = [1.0, 2.0] }}]
{extra}
[mesh]
h = {h}
alpha = 1.3
[material]
{material}
[[fixed]]
where = "y <= 0"
dofs = ["y"]
[[prescribed]]
name = "top"
where = "y >= 2"
dofs = ["y"]
total = [0.0, {total}]
select = "current"
[steps]
count = {steps}
[history]
columns = [
  {{ name = "fy", measure = "reaction.top.fy" }},
  {{ name = "lambda", measure = "load_factor" }},
]
[solver]
newton_rtol = 1e-13
"#
    )
}

/// Writes `scene` to `dir/name.toml`, makes the case and runs it on `ranks`; returns the
/// history rows.
fn run_scene(dir: &Path, name: &str, scene: &str, ranks: usize) -> Vec<Vec<f64>> {
    std::fs::write(dir.join(format!("{name}.toml")), scene).expect("write scene");
    let case = format!("{name}.h5");
    ok(dir, 1, &["new", &format!("{name}.toml"), "-o", &case]);
    ok(dir, ranks, &[&case, "--out", name]);
    history(&dir.join(name).join("history.csv")).1
}

/// Per particle of the last frame: x, y, σxx, σyy, σzz, σxy.
fn last_frame(dir: &Path) -> Vec<Vec<f64>> {
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("fields"))
        .expect("fields")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "h5"))
        .collect();
    frames.sort();
    h5py_rows(
        frames.last().expect("a frame"),
        "import numpy as np\n\
         g = f['geometry'][:]\n\
         d = f['point_data']\n\
         for row in zip(g[:, 0], g[:, 1], d['sigma_xx'][:], d['sigma_yy'][:], \
         d['sigma_zz'][:], d['tau_xy'][:]):\n    print(*[repr(float(v)) for v in row])\n",
    )
}

#[test]
fn elastic_cylinder_squeezed_5_percent_matches_the_large_strain_closed_form_to_1e_10() {
    // Ten steps of 0.5 % of the height each. In a step the P2 element's law is S = σ_n + D E
    // (Green–Lagrange relative to x_n, St Venant–Kirchhoff increment), homogeneous here: the
    // free lateral face gives E_rr = E_θθ = −ν E_yy, S_yy = σ_n,yy + E · E_yy, and the Cauchy
    // stress λ_y² S_yy / J with J = λ_y λ_r². The platen force over the whole circle is
    // σ_yy π R², R the current radius: a recursion the run must follow to round-off.
    let dir = workdir("axi-elastic-cylinder");
    let (young, nu, steps, total) = (1.0e6, 0.3, 10, 0.1);
    let scene = cylinder(
        &format!("model = \"linear-elastic\"\nyoung = {young}\npoisson = {nu}"),
        -total,
        steps,
        0.25,
        "",
    );
    let rows = run_scene(&dir, "e", &scene, 1);
    assert_eq!(rows.len(), steps as usize, "one row a step, no cut pieces");
    let (mut height, mut radius, mut sigma) = (2.0f64, 1.0f64, 0.0f64);
    for (k, row) in rows.iter().enumerate() {
        let lambda_y = (height - total / steps as f64) / height;
        let e_yy = 0.5 * (lambda_y * lambda_y - 1.0);
        let lambda_r = (1.0 - 2.0 * nu * e_yy).sqrt();
        let s_yy = sigma + young * e_yy;
        sigma = lambda_y * lambda_y * s_yy / (lambda_y * lambda_r * lambda_r);
        height *= lambda_y;
        radius *= lambda_r;
        let exact = sigma * PI * radius * radius;
        assert!(
            (row[1] - exact).abs() <= 1e-10 * exact.abs(),
            "step {}: fy = {} against {exact}",
            k + 1,
            row[1]
        );
    }
    // Uniform: σyy the same everywhere, nothing else; the section is the closed form's.
    let frame = last_frame(&dir.join("e"));
    let r_max = frame.iter().fold(0.0f64, |m, r| m.max(r[0]));
    assert!(
        (r_max - radius).abs() <= 1e-10 * radius,
        "{r_max} vs {radius}"
    );
    for r in &frame {
        assert!(
            (r[3] - sigma).abs() <= 1e-10 * sigma.abs(),
            "σyy {r:?} vs {sigma}"
        );
        for c in [2, 4, 5] {
            assert!(r[c].abs() <= 1e-10 * sigma.abs(), "{r:?}");
        }
    }
}

#[test]
fn tresca_cylinder_flows_at_the_edge_strength_with_the_hoop_in_the_criterion_to_1e_8() {
    // Undrained clay squeezed 10 % in 10 steps, remeshed every step, on 1 and 2 ranks: after
    // yield the axial stress is the rounded prism's edge strength (σ_r = σ_θ = 0: the hoop
    // stress is one of the two extremes the criterion must see, on an edge of the prism;
    // 2 cu less 0.25 %) at every particle, and the platen carries it over the current section.
    let dir = workdir("axi-tresca-cylinder");
    let cu = 1.0e4;
    let strength = pfem_mpi::material::rounded_prism::edge_strength(
        cu,
        pfem_mpi::material::rounded_prism::DEFAULT_ROUNDING,
    );
    let scene = cylinder(
        &format!("model = \"tresca\"\nyoung = 3.0e6\npoisson = 0.49\ncu = {cu}"),
        -0.2,
        10,
        0.2,
        "",
    );
    for ranks in [1, 2] {
        let name = format!("t{ranks}");
        let rows = run_scene(&dir, &name, &scene, ranks);
        let frame = last_frame(&dir.join(&name));
        let radius = frame.iter().fold(0.0f64, |m, r| m.max(r[0]));
        for r in &frame {
            assert!(
                (r[3] + strength).abs() <= 1e-8 * cu,
                "{ranks} ranks: σyy {} at {:?}",
                r[3],
                &r[..2]
            );
            assert!(r[2].abs() <= 1e-8 * cu && r[4].abs() <= 1e-8 * cu, "{r:?}");
        }
        let fy = rows.last().unwrap()[1];
        let exact = -strength * PI * radius * radius;
        assert!(
            (fy - exact).abs() <= 1e-8 * exact.abs(),
            "{ranks} ranks: fy {fy} vs {exact}"
        );
    }
}

/// Lamé's long cylinder (a = 1, b = 2, ends held axially) under internal pressure p = 1 kPa.
fn lame(element: &str) -> String {
    format!(
        r#"
name = "lame"
analysis = "axisymmetric"
[body]
rectangles = [{{ origin = [1.0, 0.0], size = [1.0, 0.5] }}]
[mesh]
h = 0.025
alpha = 1.3
refine = false
[material]
model = "linear-elastic"
young = 1.0e9
poisson = 0.49
[[fixed]]
where = "y <= 0"
dofs = ["y"]
[[fixed]]
where = "y >= 0.5"
dofs = ["y"]
[[surface_pressure]]
where = "x <= 1"
pressure = 1.0e3
[steps]
count = 1
[history]
columns = [{{ name = "lambda", measure = "load_factor" }}]
[solver]
element = "{element}"
"#
    )
}

#[test]
fn thick_walled_cylinder_matches_lame_through_the_loop_with_p2_and_p2p1() {
    // Radial displacement u = (1 + ν)/E [(1 − 2ν) A r + B/r] to 2e-5 of its largest value, and
    // the stresses recovered at the particles within 1e-3 p (the Gauss points hold 1e-4: the
    // unit test `thick_walled_cylinder_matches_lame_with_p2_and_p2p1`).
    let dir = workdir("axi-lame");
    let (p, a, b, young, nu) = (1.0e3, 1.0, 2.0, 1.0e9, 0.49);
    let big_a = p * a * a / (b * b - a * a);
    let big_b = p * a * a * b * b / (b * b - a * a);
    for element in ["p2", "p2p1"] {
        run_scene(&dir, element, &lame(element), 1);
        let mut frames: Vec<_> = std::fs::read_dir(dir.join(element).join("fields"))
            .expect("fields")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "h5"))
            .collect();
        frames.sort();
        let rows = h5py_rows(
            frames.last().expect("a frame"),
            "g = f['geometry'][:]\n\
             d = f['point_data']\n\
             u = d['displacement'][:]\n\
             for row in zip(g[:, 0], u[:, 0], d['sigma_xx'][:], d['sigma_zz'][:]):\n    \
             print(*[repr(float(v)) for v in row])\n",
        );
        let u_max = (1.0 + nu) / young * ((1.0 - 2.0 * nu) * big_a * a + big_b / a);
        let (mut du, mut ds) = (0.0f64, 0.0f64);
        for r in &rows {
            // The geometry is the current one: the radius it started at is x − u.
            let x = r[0] - r[1];
            let u = (1.0 + nu) / young * ((1.0 - 2.0 * nu) * big_a * x + big_b / x);
            du = du.max((r[1] - u).abs() / u_max);
            ds = ds
                .max((r[2] - (big_a - big_b / (x * x))).abs() / p)
                .max((r[3] - (big_a + big_b / (x * x))).abs() / p);
        }
        println!("{element}: displacement {du:.2e}, stresses {ds:.2e}");
        assert!(du <= 2e-5, "{element}: displacement error {du:e}");
        assert!(ds <= 1e-3, "{element}: stress error {ds:e}");
    }
}

#[test]
#[ignore = "slow end-to-end: a coarse circular footing on 1, 2 and 3 ranks and its restart"]
fn an_axisymmetric_run_is_the_same_on_1_2_3_ranks_and_restarts_on_another_count() {
    // A coarse circular footing on an irregular cloud, remeshed and refined every step.
    let dir = workdir("axi-ranks");
    ok(
        &dir,
        1,
        &[
            "new",
            "circular-footing",
            "-o",
            "c.h5",
            "--set",
            "mesh.h=0.5",
            "--set",
            "mesh.fine=[{origin=[0.0,3.5],size=[2.5,1.5],h=0.25}]",
            "--set",
            "steps.count=8",
            "--set",
            "prescribed[0].total=[0.0,-0.004]",
        ],
    );
    let prints: Vec<String> = [1, 2, 3]
        .iter()
        .map(|&n| ok(&dir, n, &["mesh", "c.h5"]).trim().to_string())
        .collect();
    assert!(prints[0].starts_with("fingerprint "), "{}", prints[0]);
    assert!(prints.iter().all(|p| p == &prints[0]), "{prints:#?}");
    for n in [1, 2, 3] {
        ok(&dir, n, &["c.h5", "--out", &format!("r{n}")]);
    }
    let (_, one) = history(&dir.join("r1/history.csv"));
    for n in [2, 3] {
        let (_, other) = history(&dir.join(format!("r{n}/history.csv")));
        assert_eq!(one.len(), other.len());
        for (a, b) in one.iter().zip(&other) {
            for (x, y) in a.iter().zip(b) {
                assert!(
                    (x - y).abs() <= 1e-6 * x.abs().max(1e-12),
                    "{n} ranks: {x} vs {y}"
                );
            }
        }
    }
    ok(&dir, 2, &["c.h5", "--out", "part", "--until-step", "4"]);
    ok(&dir, 3, &["part/checkpoints/step_000004.h5", "--out", "c3"]);
    let (_, continued) = history(&dir.join("c3/history.csv"));
    let (a, b) = (one.last().unwrap(), continued.last().unwrap());
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x - y).abs() <= 1e-3 * x.abs(),
            "continued on 3 ranks: {y} against {x}"
        );
    }
}

#[test]
fn scenes_that_break_the_symmetry_are_refused_naming_the_field() {
    let dir = workdir("axi-bad");
    let base = cylinder(
        "model = \"linear-elastic\"\nyoung = 1e6\npoisson = 0.3",
        -0.1,
        1,
        0.25,
        "",
    );
    let cases = [
        (
            base.replace("origin = [0.0, 0.0]", "origin = [-0.5, 0.0]"),
            "body",
        ),
        (
            base.replace("[steps]", "[gravity]\ng = [1.0, -9.81]\n[steps]"),
            "gravity.g",
        ),
    ];
    for (k, (scene, field)) in cases.iter().enumerate() {
        std::fs::write(dir.join(format!("bad{k}.toml")), scene).expect("write");
        let out = run(&dir, 1, &["new", &format!("bad{k}.toml"), "-o", "x.h5"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{field}: accepted");
        assert!(
            err.contains(field) && err.contains(&format!("bad{k}.toml")),
            "{field}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
#[ignore = "coarse benchmark: circular footing against Shield's Nc on 1 and 2 ranks"]
fn coarse_circular_footing_is_within_4_percent_of_shields_nc_on_1_and_2_ranks() {
    // Shield's smooth circular footing, Nc = 5.69 (Houlsby & Martin 2003), within 4 % on a
    // coarse cloud.
    let dir = workdir("axi-circular-footing");
    ok(
        &dir,
        1,
        &[
            "new",
            "circular-footing",
            "-o",
            "cf.h5",
            "--set",
            "mesh.h=0.25",
            "--set",
            "mesh.fine=[{origin=[0.0,3.5],size=[2.5,1.5],h=0.125},{origin=[0.75,4.75],size=[0.5,0.25],h=0.0625}]",
        ],
    );
    for ranks in [1, 2] {
        let name = format!("r{ranks}");
        ok(&dir, ranks, &["cf.h5", "--out", &name]);
        let (header, rows) = history(&dir.join(&name).join("history.csv"));
        assert_eq!(header, ["step", "w_over_B", "Nc"]);
        let nc = rows.last().unwrap()[2];
        println!(
            "{ranks} ranks: Nc = {nc:.4} at w/B = {}",
            rows.last().unwrap()[1]
        );
        assert!((nc / 5.69 - 1.0).abs() <= 0.04, "{ranks} ranks: Nc = {nc}");
    }
}

#[test]
fn coarse_ball_stays_within_4_percent_of_the_smooth_ball_factor_on_2_ranks() {
    // The smooth ball (Randolph, Martin & Hu 2000: N_ball = 11.0) on a coarse cloud (470
    // particles, 0.01 m at the ball, D = 0.04 m), pushed 0.12 D in 12 steps: from w/D = 0.05 the
    // factor must lie within 4 % of 11.0 (the issue asks 6 %; measured 10.69–10.87).
    let dir = workdir("axi-ball");
    ok(
        &dir,
        1,
        &[
            "new",
            "ball",
            "-o",
            "ball.h5",
            "--set",
            "mesh.h=0.04",
            "--set",
            "mesh.fine=[{origin=[0.0,0.24],size=[0.16,0.32],h=0.02},{origin=[0.0,0.32],size=[0.08,0.2],h=0.01}]",
            "--set",
            "rigid[0].stages=[{to=[0.0,-0.0048],steps=12}]",
        ],
    );
    ok(&dir, 2, &["ball.h5", "--out", "r2"]);
    let (header, rows) = history(&dir.join("r2").join("history.csv"));
    assert_eq!(header, ["step", "w_over_D", "N_ball"]);
    assert_eq!(rows.len(), 12);
    for r in rows.iter().filter(|r| r[1] >= 0.05 - 1e-9) {
        println!("w/D = {:.2}: N_ball = {:.4}", r[1], r[2]);
        assert!(
            (r[2] / 11.0 - 1.0).abs() <= 0.04,
            "w/D = {}: N_ball = {}",
            r[1],
            r[2]
        );
    }
}

#[test]
fn a_cone_tip_pushed_in_small_steps_meets_the_node_under_it() {
    // A 60° cone (R = 0.02 m, tip rounded by 0.5 mm) on the axis, its tip 1 mm above the
    // surface, pushed down 0.25 mm a step: from the step its tip passes the surface node on the
    // axis, that node carries a force. (The node under a sharp tip is near the body while the
    // midpoints of the edges beside it are not: it was left out of the contact, the tip passed
    // through the soil and the force stayed 0.)
    let dir = workdir("axi-cone-tip");
    let scene = r#"
name = "cone-tip"
analysis = "axisymmetric"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [0.2, 0.2] }]
[mesh]
h = 0.01
alpha = 1.3
[material]
model = "tresca"
young = 1.5e6
poisson = 0.49
cu = 5.0e3
[[fixed]]
where = "x >= 0.2"
dofs = ["x"]
[[fixed]]
where = "y <= 0"
dofs = ["x", "y"]
[[rigid]]
name = "cone"
polygon = { vertices = [[0.0, 0.201], [0.02, 0.235641], [0.02, 0.3], [-0.02, 0.3], [-0.02, 0.235641]], corner_radius = 0.0005 }
stages = [{ to = [0.0, -0.003], steps = 12 }]
[history]
columns = [{ name = "fy", measure = "rigid.cone.fy" }]
"#;
    let rows = run_scene(&dir, "cone", scene, 1);
    // The rounded tip's lowest point starts 1 mm + 0.5 mm (1/sin 30° − 1) above the surface.
    for r in &rows {
        let depth = r[0] * 0.00025 - 0.0015;
        if depth > 0.0 {
            assert!(
                r[1] > 0.0,
                "step {}: tip {depth} m below the surface, force {}",
                r[0],
                r[1]
            );
        }
    }
}
