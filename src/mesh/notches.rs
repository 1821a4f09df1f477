//! Keeping the alpha shape from bridging the body's concave notches.
//!
//! At a re-entrant corner v of the boundary, with boundary neighbours a and b at spacing s along
//! the two edges, the triangle (v, a, b) has circumradius s/√2 < alpha·h and lies outside the
//! body: no alpha separates it from the body's own triangles (also ≈ 0.71 h). Two rules remove
//! it, each a function of data every rank holding the triangle has bit for bit:
//! - the first mesh of a run drops triangles whose three vertices lie on the drawn boundary and
//!   whose centroid lies outside the drawn body ([`outside_drawn`]);
//! - later meshes drop a triangle that would fill the outside of two consecutive boundary edges
//!   of the previous mesh ([`closes_notch`]), so a notch stays a notch from step to step, while
//!   free surfaces that meet elsewhere (vertices not adjacent on the previous boundary) still
//!   merge as PFEM intends.

use crate::geometry::Shape;

/// Boundary edges `[v, w]` of the previous mesh (body on the left of v → w) whose start v
/// satisfies `owned`, sorted, from the keys of the previous triangles this rank holds (CCW).
///
/// Exact for every owned v as long as `keys` holds every previous triangle touching an owned
/// particle (as `TriStates` does): then every triangle on an edge from v is present.
pub fn boundary_out_edges<'a>(
    keys: impl Iterator<Item = &'a [u64; 3]>,
    owned: impl Fn(u64) -> bool,
) -> Vec<[u64; 2]> {
    // Each directed edge with its undirected key; an edge is on the boundary iff one triangle
    // has it.
    let mut edges: Vec<([u64; 2], [u64; 2])> = Vec::new();
    for k in keys {
        for i in 0..3 {
            let (a, b) = (k[i], k[(i + 1) % 3]);
            if owned(a) || owned(b) {
                edges.push(([a.min(b), a.max(b)], [a, b]));
            }
        }
    }
    edges.sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        if j == i + 1 && owned(edges[i].1[0]) {
            out.push(edges[i].1);
        }
        i = j;
    }
    out.sort_unstable();
    out
}

/// Whether the CCW triangle with vertex ids `g` fills the outside of two previous boundary
/// edges: two of its edges x → y are previous boundary edges run backwards (y → x; `was_edge`
/// answers for a directed pair). The body was on the left of those edges, so the triangle lies
/// on their right, in the notch between them; two such edges share a vertex v, the notch's
/// corner, whose neighbours along the old boundary are the triangle's other two vertices. (Such
/// a triangle exists only at a concave vertex: at a convex one the triangle on the outside of
/// both edges would be clockwise.)
pub fn closes_notch(g: [u64; 3], was_edge: impl Fn(u64, u64) -> bool) -> bool {
    (0..3).filter(|&i| was_edge(g[(i + 1) % 3], g[i])).count() >= 2
}

/// Whether the triangle `p` (vertices in a fixed order, the same on every rank) lies on the
/// outside of the drawn body: all three vertices on the boundary of some shape (within `tol`)
/// and the centroid in none of them (outside the zones or in a hole). The boundary's
/// notches are exactly such triangles; a triangle with a vertex inside the body is never one.
pub fn outside_drawn(shapes: &[Shape], p: [[f64; 2]; 3], tol: f64) -> bool {
    let on_boundary = |x: [f64; 2]| shapes.iter().any(|s| s.signed_distance(x).abs() <= tol);
    if !p.iter().all(|&x| on_boundary(x)) {
        return false;
    }
    let c = [
        (p[0][0] + p[1][0] + p[2][0]) / 3.0,
        (p[0][1] + p[1][1] + p[2][1]) / 3.0,
    ];
    !shapes.iter().any(|s| s.contains(c))
}

#[cfg(test)]
mod tests {
    use super::super::alpha::{alpha_keep, boundary_edges};
    use super::super::delaunay::delaunay;
    use super::*;
    use crate::geometry::{Circle, Polygon};

    /// An L-shaped lattice (spacing 1, 11 x 11 with the quadrant i > 5, j > 5 removed), its
    /// alpha-shape triangles as gid keys (gid = index), and the points.
    fn l_shape() -> (Vec<[f64; 2]>, Vec<[u64; 3]>) {
        let mut pts = Vec::new();
        for j in 0..11 {
            for i in 0..11 {
                if i <= 5 || j <= 5 {
                    pts.push([i as f64, j as f64]);
                }
            }
        }
        let ids: Vec<u64> = (0..pts.len() as u64).collect();
        let tris = delaunay(&pts, &ids).unwrap();
        let keep = alpha_keep(&pts, &tris, &vec![1.0; pts.len()], 1.3);
        let keys = tris
            .iter()
            .zip(keep)
            .filter(|(_, k)| *k)
            .map(|(t, _)| t.map(|v| v as u64))
            .collect();
        (pts, keys)
    }

    fn index(pts: &[[f64; 2]], x: [f64; 2]) -> u64 {
        pts.iter().position(|p| *p == x).unwrap() as u64
    }

    fn l_polygon() -> Shape {
        let outer = vec![
            [0.0, 0.0],
            [10.0, 0.0],
            [10.0, 5.0],
            [5.0, 5.0],
            [5.0, 10.0],
            [0.0, 10.0],
        ];
        Shape::Polygon(Polygon::new(outer, vec![]).unwrap())
    }

    #[test]
    fn the_first_mesh_loses_exactly_the_corner_triangle() {
        let (pts, keys) = l_shape();
        let shapes = [l_polygon()];
        let dropped: Vec<&[u64; 3]> = keys
            .iter()
            .filter(|k| outside_drawn(&shapes, k.map(|v| pts[v as usize]), 1e-9))
            .collect();
        assert_eq!(dropped.len(), 1);
        let mut corner = dropped[0].to_vec();
        corner.sort_unstable();
        let mut want = vec![
            index(&pts, [5.0, 5.0]),
            index(&pts, [6.0, 5.0]),
            index(&pts, [5.0, 6.0]),
        ];
        want.sort_unstable();
        assert_eq!(corner, want);
    }

    #[test]
    fn round_boundaries_lose_the_chord_triangles_of_holes_only() {
        let tau = std::f64::consts::TAU;
        let on = |k: usize, sign: f64| {
            let t = sign * k as f64 * tau / 32.0;
            [t.cos(), t.sin()]
        };
        // A square with a 32-gon hole of radius 1: three consecutive hole vertices make a
        // triangle in the hole.
        let hole: Vec<[f64; 2]> = (0..32).map(|k| on(k, -1.0)).collect();
        let square = vec![[-3.0, -3.0], [3.0, -3.0], [3.0, 3.0], [-3.0, 3.0]];
        let plate = [Shape::Polygon(Polygon::new(square, vec![hole]).unwrap())];
        // A disc of radius 1: three consecutive boundary points make a triangle in the disc.
        let disc = [Shape::Circle(Circle::new([0.0, 0.0], 1.0).unwrap())];
        for k in 0..32 {
            let tri = [on(k, 1.0), on(k + 1, 1.0), on(k + 2, 1.0)];
            assert!(
                outside_drawn(&plate, tri, 1e-12),
                "chord triangle {k} of the hole"
            );
            assert!(
                !outside_drawn(&disc, tri, 1e-12),
                "chord triangle {k} of the disc"
            );
        }
        // A triangle with a vertex off the boundary is never dropped.
        let inner = [on(0, 1.0), on(1, 1.0), [0.5, 0.0]];
        assert!(!outside_drawn(&plate, inner, 1e-12));
    }

    #[test]
    fn a_notch_of_the_previous_boundary_stays_open() {
        let (pts, keys) = l_shape();
        let shapes = [l_polygon()];
        let first: Vec<[u64; 3]> = keys
            .iter()
            .copied()
            .filter(|k| !outside_drawn(&shapes, k.map(|v| pts[v as usize]), 1e-9))
            .collect();
        let out = boundary_out_edges(first.iter(), |_| true);
        let was = |a: u64, b: u64| out.binary_search(&[a, b]).is_ok();
        // Remeshing the same cloud: the corner triangle alone closes a notch.
        let closing: Vec<&[u64; 3]> = keys.iter().filter(|k| closes_notch(**k, was)).collect();
        assert_eq!(closing.len(), 1);
        assert!(!first.contains(closing[0]));
        // Out edges restricted to owned starts are those of the full list starting there.
        let owned = |g: u64| g.is_multiple_of(3);
        let part = boundary_out_edges(keys.iter().filter(|k| k.iter().any(|&g| owned(g))), owned);
        let whole: Vec<[u64; 2]> = boundary_out_edges(keys.iter(), |_| true)
            .into_iter()
            .filter(|e| owned(e[0]))
            .collect();
        assert_eq!(part, whole);
    }

    #[test]
    fn separate_surfaces_still_merge() {
        // Two 4 x 5 blocks four spacings apart, then moved together: their facing boundaries
        // are not adjacent on the previous boundary, so the triangles that join them are kept.
        let mut pts = Vec::new();
        for j in 0..5 {
            for i in 0..11 {
                if i <= 3 || i >= 7 {
                    pts.push([i as f64, j as f64]);
                }
            }
        }
        let ids: Vec<u64> = (0..pts.len() as u64).collect();
        let mesh = |pts: &[[f64; 2]]| -> Vec<[u64; 3]> {
            let tris = delaunay(pts, &ids).unwrap();
            let keep = alpha_keep(pts, &tris, &vec![1.0; pts.len()], 1.3);
            tris.iter()
                .zip(keep)
                .filter(|(_, k)| *k)
                .map(|(t, _)| t.map(|v| v as u64))
                .collect()
        };
        let before = mesh(&pts);
        let local: Vec<[u32; 3]> = before.iter().map(|k| k.map(|g| g as u32)).collect();
        assert_eq!(boundary_edges(&local).len(), 2 * 14, "two separate blocks");
        let out = boundary_out_edges(before.iter(), |_| true);
        // The right block moves left by three spacings: one lattice of 8 x 5.
        for p in pts.iter_mut().filter(|p| p[0] > 4.0) {
            p[0] -= 3.0;
        }
        let after = mesh(&pts);
        let was = |a: u64, b: u64| out.binary_search(&[a, b]).is_ok();
        assert_eq!(after.len(), 2 * 7 * 4);
        assert!(after.iter().all(|k| !closes_notch(*k, was)));
    }
}
