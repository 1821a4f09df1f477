//! Bodies drawn as polygons mesh without spurious triangles at their concave corners (issue 27
//! item 3): at a re-entrant corner or a polygonal hole the alpha shape alone keeps a triangle of
//! circumradius s/√2 across the notch. The meshes of the first two steps cover exactly the drawn
//! body (area to round-off, boundary edges on the polygon), on 1 and 2 ranks, and the first and
//! the last mesh are the same on 1, 2 and 3 ranks.

mod common;
use common::*;
use pfem_mpi::geometry::{Polygon, Shape};
use std::path::Path;

/// tests/site.rs's plate: an L with a quadrilateral hole, 5 concave corners, 8.6 m².
const PLATE: &str = r#"
name = "plate-with-hole"
[body]
zones = [
  { name = "plate", polygon = [[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [2.5, 1.0], [2.5, 3.0], [0.0, 3.0]], edges = ["base", "", "", "", "", "left"], holes = [[[1.0, 1.0], [1.6, 1.2], [1.4, 1.8], [0.8, 1.6]]] },
]
[mesh]
h = 0.1
[material]
model = "linear-elastic"
young = 1.0e7
poisson = 0.3
density = 1000.0
[gravity]
g = [0.0, -9.81]
[[fixed]]
name = "base"
on = "base"
dofs = ["x", "y"]
[steps]
count = 2
[output]
fields_every = 1
[history]
columns = [{ name = "area", measure = "area" }]
"#;

fn plate() -> Shape {
    let outer = vec![
        [0.0, 0.0],
        [4.0, 0.0],
        [4.0, 1.0],
        [2.5, 1.0],
        [2.5, 3.0],
        [0.0, 3.0],
    ];
    let hole = vec![[1.0, 1.0], [1.6, 1.2], [1.4, 1.8], [0.8, 1.6]];
    Shape::Polygon(Polygon::new(outer, vec![hole]).unwrap())
}

/// Ground with a 30° slope face (crest (5.4, 2.5), toe (5.4 − 1.5√3, 1)), a step cut out at the
/// left (a 270° corner at (1.5, 1)) and a round hole (a 40-gon of radius 0.5, edges 0.079 < h).
fn slope() -> (String, Shape) {
    let toe = 5.4 - 1.5 * 3f64.sqrt();
    let outer = vec![
        [0.0, 0.0],
        [8.0, 0.0],
        [8.0, 2.5],
        [5.4, 2.5],
        [toe, 1.0],
        [1.5, 1.0],
        [1.5, 2.0],
        [0.0, 2.0],
    ];
    let hole: Vec<[f64; 2]> = (0..40)
        .map(|k| {
            let t = -(k as f64) * std::f64::consts::TAU / 40.0;
            [6.5 + 0.5 * t.cos(), 1.2 + 0.5 * t.sin()]
        })
        .collect();
    let ring = |r: &[[f64; 2]]| {
        let p: Vec<String> = r
            .iter()
            .map(|p| format!("[{:?}, {:?}]", p[0], p[1]))
            .collect();
        format!("[{}]", p.join(", "))
    };
    let text = PLATE
        .replace("plate-with-hole", "slope-corner-hole")
        .replace(
            PLATE.lines().nth(4).unwrap(),
            &format!(
                "  {{ name = \"ground\", polygon = {}, edges = [\"base\", \"\", \"\", \"\", \"\", \"\", \"\", \"\"], holes = [{}] }},",
                ring(&outer),
                ring(&hole)
            ),
        );
    let shape = Shape::Polygon(Polygon::new(outer, vec![hole]).unwrap());
    (text, shape)
}

/// A field frame: reference positions and triangles.
type Frame = (Vec<[f64; 2]>, Vec<[usize; 3]>);

/// Every field frame of a run folder, in step order.
fn frames(dir: &Path) -> Vec<Frame> {
    let script = "import h5py, os, sys\nd = sys.argv[1]\n\
        for n in sorted(os.listdir(d)):\n    \
        f = h5py.File(os.path.join(d, n), 'r')\n    \
        x = f['geometry'][...] - f['point_data/displacement'][:, :2]\n    \
        t = f['connectivity'][...]\n    \
        print('frame', len(x), len(t))\n    \
        for p in x: print(repr(float(p[0])), repr(float(p[1])))\n    \
        for c in t: print(c[0], c[1], c[2])";
    let out = std::process::Command::new("python3")
        .args(["-c", script, &dir.join("fields").display().to_string()])
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let mut lines = text.lines();
    let mut all = Vec::new();
    while let Some(head) = lines.next() {
        let w: Vec<usize> = head
            .split_whitespace()
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        let x = (0..w[0])
            .map(|_| {
                let v: Vec<f64> = lines
                    .next()
                    .unwrap()
                    .split_whitespace()
                    .map(|s| s.parse().unwrap())
                    .collect();
                [v[0], v[1]]
            })
            .collect();
        let t = (0..w[1])
            .map(|_| {
                let v: Vec<usize> = lines
                    .next()
                    .unwrap()
                    .split_whitespace()
                    .map(|s| s.parse().unwrap())
                    .collect();
                [v[0], v[1], v[2]]
            })
            .collect();
        all.push((x, t));
    }
    all
}

/// The frame's mesh, in the reference configuration, is the drawn body cut into triangles: no
/// centroid outside it (nor in its hole), the area to round-off, every boundary edge on its
/// boundary (ends and midpoint: a chord across a notch has its ends on the boundary too).
fn assert_covers(what: &str, shape: &Shape, x: &[[f64; 2]], tris: &[[usize; 3]]) {
    let mut area = 0.0;
    let mut outside = Vec::new();
    let mut edges = std::collections::HashMap::new();
    for t in tris {
        let [a, b, c] = t.map(|k| x[k]);
        area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        let m = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        if shape.signed_distance(m) >= 0.0 {
            outside.push(m);
        }
        for (p, q) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *edges.entry((p.min(q), p.max(q))).or_insert(0) += 1;
        }
    }
    let exact = shape.area();
    println!(
        "{what}: {} triangles, area {area} against {exact} ({:.1e}), {} outside",
        tris.len(),
        area / exact - 1.0,
        outside.len()
    );
    assert!(
        outside.is_empty(),
        "{what}: centroids outside the body: {outside:?}"
    );
    assert!(
        (area / exact - 1.0).abs() < 1e-9,
        "{what}: mesh area {area}, body {exact}"
    );
    let mut boundary = 0;
    for ((p, q), n) in edges {
        if n == 1 {
            boundary += 1;
            let mid = [(x[p][0] + x[q][0]) / 2.0, (x[p][1] + x[q][1]) / 2.0];
            for y in [x[p], x[q], mid] {
                let d = shape.signed_distance(y).abs();
                assert!(d < 1e-9, "{what}: boundary edge point {y:?} is {d} off");
            }
        }
    }
    assert!(boundary > 100, "{what}: {boundary} boundary edges");
}

/// Writes `text`, meshes it on 1, 2, 3 ranks (same fingerprint), runs two steps on 1 and 2
/// ranks, checks both steps' meshes against `shape`, and meshes the last checkpoint on 1, 2, 3
/// ranks (same fingerprint).
fn check_scene(name: &str, text: &str, shape: &Shape) {
    let dir = workdir(name);
    std::fs::write(dir.join("s.toml"), text).unwrap();
    ok(&dir, 1, &["new", "s.toml", "-o", "s.h5"]);
    same_mesh_on_1_2_3_ranks(&dir, "s.h5");
    let mut counts = Vec::new();
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        ok(&dir, ranks, &["s.h5", "--out", &out]);
        let frames = frames(&dir.join(&out));
        assert_eq!(frames.len(), 2, "one field frame per step");
        for (k, (x, t)) in frames.iter().enumerate() {
            assert_covers(
                &format!("{name}, {ranks} rank(s), step {}", k + 1),
                shape,
                x,
                t,
            );
            counts.push(t.len());
        }
    }
    assert!(counts.iter().all(|&c| c == counts[0]), "{counts:?}");
    // The mesh after the last step, from the previous mesh's boundary held in the checkpoint.
    same_mesh_on_1_2_3_ranks(&dir, "r1/checkpoints/step_000002.h5");
}

fn same_mesh_on_1_2_3_ranks(dir: &Path, file: &str) {
    let prints: Vec<String> = [1, 2, 3]
        .iter()
        .map(|&n| ok(dir, n, &["mesh", file]).trim().to_string())
        .collect();
    println!("{file}: {}", prints[0]);
    assert!(prints[0].starts_with("fingerprint "));
    assert!(
        prints.iter().all(|p| p == &prints[0]),
        "{file}: fingerprints differ on 1, 2, 3 ranks: {prints:#?}"
    );
}

#[test]
fn the_plate_meshes_without_bridging_its_corners_or_hole() {
    check_scene("corners-plate", PLATE, &plate());
}

#[test]
fn a_slope_a_step_and_a_round_hole_mesh_exactly() {
    let (text, shape) = slope();
    check_scene("corners-slope", &text, &shape);
}

/// A body of rectangles whose union is an L (2 x 1 below, 1 x 1 on its left half above, h =
/// 0.1): the first mesh is the 300 lattice cells, two triangles each, and its boundary the
/// 80 edges of the L's perimeter; the alpha shape alone bridged the corner with a 601st.
#[test]
fn an_l_of_rectangles_meshes_to_its_cells() {
    let dir = workdir("corners-rectangles");
    let l = "body.rectangles=[{origin=[0.0,0.0],size=[2.0,1.0]},{origin=[0.0,1.0],size=[1.0,1.0]}]";
    ok(
        &dir,
        1,
        &["new", "block-compression", "-o", "l.h5", "--set", l],
    );
    for ranks in [1, 2] {
        let line = ok(&dir, ranks, &["mesh", "l.h5"]);
        assert!(
            line.contains("particles 341 triangles 600 boundary_edges 80"),
            "{ranks} rank(s): {line}"
        );
    }
}
