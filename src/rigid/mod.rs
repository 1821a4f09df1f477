//! Rigid bodies pushed into the soil: convex shapes, their staged motion, and the contact law
//! between them and the soil's boundary nodes that Newton solves with the soil. Pure numerics:
//! no MPI, no PETSc.

pub mod body;
pub mod contact;
pub mod edge_tree;
pub mod shape;

pub use body::RigidBody;
pub use contact::{node_law, node_law_among, ContactPair, NodeLaw, Status};
pub use shape::{Proximity, Shape};

/// The proximity of `x` to the body it lies deepest in, or nearest to (smallest signed
/// distance); `None` without bodies.
pub fn nearest(shapes: &[Shape], x: [f64; 2]) -> Option<Proximity> {
    shapes
        .iter()
        .map(|s| s.closest(x))
        .min_by(|p, q| p.distance.total_cmp(&q.distance))
}

/// The signed distance from `x` to the nearest body (negative inside; infinite without bodies).
pub fn gap(shapes: &[Shape], x: [f64; 2]) -> f64 {
    nearest(shapes, x).map_or(f64::INFINITY, |p| p.distance)
}

/// Where a path t ↦ x(t) leaves the bodies, by bisection between `inside` (a parameter where it
/// is inside) and `outside` (one where it is out), `out_at(t)` telling which: the last
/// parameter found outside, within 2⁻⁴⁰ of the bracket.
pub fn exit(mut inside: f64, mut outside: f64, out_at: impl Fn(f64) -> bool) -> f64 {
    for _ in 0..40 {
        let half = 0.5 * (inside + outside);
        if out_at(half) {
            outside = half;
        } else {
            inside = half;
        }
    }
    outside
}

/// A triangle reaching deeper than this fraction of its spacing (or of the body's inradius)
/// into a rigid body crosses it.
pub const CROSSING_DEPTH: f64 = 0.25;

/// Whether the triangle `tri` (largest vertex spacing `h`) crosses `shape`: it reaches into the
/// body deeper than a quarter of its spacing or of the body's half thickness, whichever is
/// less. The alpha shape alone would bridge particles across a thin body (such a triangle
/// reaches its middle) or close the soil over a body's corner; a chord between two particles on
/// a curved face dips in by only h²/8R. Decided from the triangle's own data, so every rank
/// holding a copy decides alike.
pub fn crosses(shape: &Shape, tri: [[f64; 2]; 3], h: f64) -> bool {
    let bb = shape.bounding_box();
    let lo = |c: usize| tri.iter().map(|q| q[c]).fold(f64::INFINITY, f64::min);
    let hi = |c: usize| tri.iter().map(|q| q[c]).fold(f64::NEG_INFINITY, f64::max);
    if (0..2).any(|c| lo(c) > bb[1][c] || hi(c) < bb[0][c]) {
        return false;
    }
    // The inradius (a search over the core's edges) only when the spacing alone does not decide.
    let depth = shape.triangle_depth(tri);
    if depth > CROSSING_DEPTH * h || depth > 0.0 && depth > CROSSING_DEPTH * shape.inradius() {
        return true;
    }
    // Across an obtuse corner (a cone's shoulder, 150°) the triangle of the corner particle
    // and its two neighbours on the faces lies inside the body yet reaches only a quarter of
    // its side in; its centroid is inside, where no soil triangle's is.
    depth > 0.0 && shape.closest(centroid(tri)).distance < -CENTROID_DEPTH * h
}

/// A triangle whose centroid lies deeper than this fraction of its spacing inside a rigid body
/// crosses it.
pub const CENTROID_DEPTH: f64 = 0.02;

fn centroid(t: [[f64; 2]; 3]) -> [f64; 2] {
    [
        (t[0][0] + t[1][0] + t[2][0]) / 3.0,
        (t[0][1] + t[1][1] + t[2][1]) / 3.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_picks_the_deepest_body_and_exit_finds_its_surface() {
        let bodies = [
            Shape::circle([0.0, 0.0], 1.0).unwrap(),
            Shape::circle([3.0, 0.0], 1.0).unwrap(),
        ];
        let p = nearest(&bodies, [2.5, 0.0]).unwrap();
        assert!((p.distance + 0.5).abs() < 1e-15 && p.normal[0] < 0.0);
        assert_eq!(gap(&[], [0.0, 0.0]), f64::INFINITY);
        // Along the x axis from the first circle's centre outwards: leaves it at x = 1.
        let t = exit(0.0, 1.7, |x| gap(&bodies, [x, 0.0]) >= 0.0);
        assert!(t >= 1.0 && t - 1.0 < 1e-11, "{t}");
    }
    use crate::mesh::LocalMesh;

    /// A 21 × 21 lattice of spacing 0.05 meshed whole, then the triangles crossing `shape`
    /// dropped: none of the kept ones may cross it, none may have a vertex inside it.
    fn mesh_around(shape: &Shape) -> LocalMesh {
        mesh_with(shape, true)
    }

    fn mesh_with(shape: &Shape, drop: bool) -> LocalMesh {
        let h = 0.05;
        let mut points = Vec::new();
        for j in 0..21 {
            for i in 0..21 {
                let p = [i as f64 * h, j as f64 * h];
                if shape.closest(p).distance >= 0.0 {
                    points.push(p);
                }
            }
        }
        let n = points.len();
        let gids = (0..n as u64).collect();
        let mut mesh =
            LocalMesh::build(points, gids, vec![0; n], vec![h; n], n, 0, 1.3, true).unwrap();
        if drop {
            mesh.drop_triangles(0, |p, hh| crosses(shape, p, hh));
        }
        mesh
    }

    #[test]
    fn no_kept_triangle_bridges_a_thin_plate() {
        // A plate 0.02 thick between two lattice columns: no particle is inside it, and the
        // alpha shape alone keeps the lattice triangles across it.
        let plate = Shape::polygon(
            &[[0.515, 0.3], [0.535, 0.3], [0.535, 1.2], [0.515, 1.2]],
            0.0,
        )
        .unwrap();
        let bridged = crossing_plate(&mesh_with(&plate, false));
        assert!(bridged > 0, "the alpha shape alone bridges the plate");
        assert_eq!(
            crossing_plate(&mesh_around(&plate)),
            0,
            "triangles bridge the plate"
        );
        let mesh = mesh_around(&plate);
        // The soil still wraps round its lower end: the region below the plate stays meshed.
        let below = mesh
            .tris
            .iter()
            .filter(|t| t.iter().all(|&v| mesh.points[v as usize][1] < 0.3))
            .count();
        assert_eq!(below, 200, "the 20 x 5 cells below the plate stay meshed");
    }

    /// Triangle edges crossing the plate's midline x = 0.525 above its end.
    fn crossing_plate(mesh: &LocalMesh) -> usize {
        // Count triangles with an edge crossing the plate's midline x = 0.525 above its end.
        let mut across = 0;
        for t in &mesh.tris {
            let p = t.map(|v| mesh.points[v as usize]);
            for k in 0..3 {
                let (a, b) = (p[k], p[(k + 1) % 3]);
                if (a[0] - 0.525) * (b[0] - 0.525) < 0.0 {
                    let y = a[1] + (b[1] - a[1]) * (0.525 - a[0]) / (b[0] - a[0]);
                    if y > 0.3 + 0.25 * 0.05 {
                        across += 1;
                    }
                }
            }
        }
        across
    }

    #[test]
    fn a_circle_keeps_the_chords_on_its_face() {
        // Particles on a circle of radius 0.2 at the lattice spacing: the chords between them
        // dip in by h²/8R = 1.6e-3, well below the limit, so the ring of triangles stays.
        let circle = Shape::circle([0.5, 0.5], 0.2).unwrap();
        let kept_all = mesh_around(&circle);
        for t in &kept_all.tris {
            let p = t.map(|v| kept_all.points[v as usize]);
            assert!(!crosses(&circle, p, 0.05));
            assert!(circle.triangle_depth(p) <= CROSSING_DEPTH * 0.05);
        }
        // And a triangle through the middle is a crossing one.
        assert!(crosses(
            &circle,
            [[0.2, 0.5], [0.8, 0.49], [0.8, 0.51]],
            0.05
        ));
    }

    #[test]
    fn the_triangle_inside_an_obtuse_corner_crosses_it() {
        // A cone's shoulder: a face 30° off the vertical meeting a vertical shaft, sharp. The
        // particle at the corner and one on each face a spacing away span a triangle inside
        // the body that reaches only 0.25 h in; its centroid is 0.17 h in.
        let h = 0.01;
        let (s, c) = 30f64.to_radians().sin_cos();
        let cone = Shape::polygon(
            &[
                [0.0, 0.0],
                [1.0, c / s],
                [1.0, 3.0],
                [-1.0, 3.0],
                [-1.0, c / s],
            ],
            0.0,
        )
        .unwrap();
        let corner = [1.0, c / s];
        let on_face = [corner[0] - h * s, corner[1] - h * c];
        let on_shaft = [1.0, corner[1] + h];
        let tri = [on_face, corner, on_shaft];
        let depth = cone.triangle_depth(tri);
        assert!(
            depth > 0.2 * h && depth < CROSSING_DEPTH * h,
            "depth {depth}"
        );
        assert!(crosses(&cone, tri, h));
        // The soil's triangle on the other side of the same two edges stays.
        let out = [1.0 + 0.8 * h, corner[1]];
        assert!(!crosses(&cone, [on_face, out, corner], h));
        assert!(!crosses(&cone, [corner, out, on_shaft], h));
    }
}
