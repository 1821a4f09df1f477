//! Alpha-shape filtering of a particle triangulation and extraction of its boundary.
//!
//! A triangle survives when its circumradius is at most `alpha` times the local particle
//! spacing. The test is a pure, permutation-invariant function of the triangle's three points
//! and spacings, evaluated in a fixed order of IEEE operations, so every MPI rank that holds a
//! copy of a triangle takes the same decision bit for bit.

use super::predicates::orient2d;

/// Circumradius of triangle `(a, b, c)`; `f64::INFINITY` if the points are collinear (exact
/// test) or not finite.
///
/// The vertices are put in lexicographic order before any arithmetic, so the result is
/// bit-identical for all six orderings of the arguments.
pub fn circumradius(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let mut p = [a, b, c];
    p.sort_unstable_by(|u, v| u[0].total_cmp(&v[0]).then(u[1].total_cmp(&v[1])));
    let [a, b, c] = p;
    let twice_area = orient2d(a, b, c).abs();
    if !(twice_area > 0.0 && twice_area.is_finite()) {
        return f64::INFINITY;
    }
    let len = |u: [f64; 2], v: [f64; 2]| {
        let (dx, dy) = (v[0] - u[0], v[1] - u[1]);
        (dx * dx + dy * dy).sqrt()
    };
    let r = len(a, b) * len(b, c) * len(c, a) / (2.0 * twice_area);
    if r.is_nan() {
        f64::INFINITY
    } else {
        r
    }
}

/// Alpha-shape decision for each triangle of `tris` (local indices into `points` and `h`).
///
/// Triangle `T` is kept iff `circumradius(T) <= alpha * h_T`, where `h_T` is the largest of the
/// spacings `h` of its three vertices: in a graded cloud the triangles between a fine and a
/// coarse lattice are as large as the coarse ones and must survive. The decision depends only on
/// the triangle's own three points and spacings, not on their order ([`circumradius`] is
/// order-independent).
///
/// A triangle with an index outside `points` or `h`, a non-finite spacing, or zero area is not
/// kept.
pub fn alpha_keep(points: &[[f64; 2]], tris: &[[u32; 3]], h: &[f64], alpha: f64) -> Vec<bool> {
    tris.iter()
        .map(|t| keep_triangle(points, h, *t, alpha))
        .collect()
}

fn keep_triangle(points: &[[f64; 2]], h: &[f64], t: [u32; 3], alpha: f64) -> bool {
    let mut p = [[0.0; 2]; 3];
    let mut hs = [0.0; 3];
    for k in 0..3 {
        let i = t[k] as usize;
        match (points.get(i), h.get(i)) {
            (Some(&pi), Some(&hi)) => {
                p[k] = pi;
                hs[k] = hi;
            }
            _ => return false,
        }
    }
    hs.sort_unstable_by(f64::total_cmp);
    // A NaN on either side makes the comparison false, i.e. the triangle is dropped.
    circumradius(p[0], p[1], p[2]) <= alpha * hs[2]
}

/// Edges that belong to exactly one triangle of `tris` (typically the kept triangles).
///
/// Each edge is oriented as it appears in its counter-clockwise triangle, so the body lies to
/// its left: outer boundaries run counter-clockwise, hole boundaries clockwise. Edges are
/// sorted lexicographically by `[start, end]`. Triangles must have distinct vertices.
pub fn boundary_edges(tris: &[[u32; 3]]) -> Vec<[u32; 2]> {
    let mut edges: Vec<([u32; 2], [u32; 2])> = tris
        .iter()
        .flat_map(|t| {
            (0..3).map(move |i| {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                ([a.min(b), a.max(b)], [a, b])
            })
        })
        .collect();
    edges.sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        if j == i + 1 {
            out.push(edges[i].1);
        }
        i = j;
    }
    out.sort_unstable();
    out
}

/// Vertices lying on a boundary edge of `tris` (see [`boundary_edges`]), sorted, without
/// repetition.
pub fn boundary_vertices(tris: &[[u32; 3]]) -> Vec<u32> {
    let mut v: Vec<u32> = boundary_edges(tris).into_iter().flatten().collect();
    v.sort_unstable();
    v.dedup();
    v
}

#[cfg(test)]
mod tests {
    use super::super::delaunay::delaunay;
    use super::*;
    use std::collections::{BTreeSet, HashMap};

    fn lattice(nx: usize, ny: usize, h: f64, keep: impl Fn(usize, usize) -> bool) -> Vec<[f64; 2]> {
        let mut pts = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                if keep(i, j) {
                    pts.push([i as f64 * h, j as f64 * h]);
                }
            }
        }
        pts
    }

    /// Triangulates, filters with `alpha`, and returns (points, kept triangles).
    fn alpha_mesh(pts: &[[f64; 2]], h: f64, alpha: f64) -> Vec<[u32; 3]> {
        // Ids in reverse order of position, to make sure nothing relies on ids == indices.
        let ids: Vec<u64> = (0..pts.len() as u64).rev().map(|i| 1000 + 3 * i).collect();
        let tris = delaunay(pts, &ids).expect("triangulation");
        let hs = vec![h; pts.len()];
        let keep = alpha_keep(pts, &tris, &hs, alpha);
        tris.iter()
            .zip(keep)
            .filter(|(_, k)| *k)
            .map(|(t, _)| *t)
            .collect()
    }

    fn area2(pts: &[[f64; 2]], t: &[u32; 3]) -> f64 {
        orient2d(pts[t[0] as usize], pts[t[1] as usize], pts[t[2] as usize])
    }

    /// Twice the signed area enclosed by the boundary (shoelace over the edges) must equal
    /// twice the kept area: outer loops CCW, holes CW.
    fn check_boundary_encloses(pts: &[[f64; 2]], kept: &[[u32; 3]], edges: &[[u32; 2]]) {
        let kept_area: f64 = kept.iter().map(|t| area2(pts, t)).sum();
        let shoelace: f64 = edges
            .iter()
            .map(|e| {
                let (a, b) = (pts[e[0] as usize], pts[e[1] as usize]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum();
        assert!((kept_area - shoelace).abs() < 1e-9 * kept_area.abs().max(1.0));
    }

    /// Number of connected components of the boundary edge graph.
    fn loops(edges: &[[u32; 2]]) -> usize {
        let mut parent: HashMap<u32, u32> = HashMap::new();
        fn find(parent: &mut HashMap<u32, u32>, v: u32) -> u32 {
            let p = *parent.entry(v).or_insert(v);
            if p == v {
                v
            } else {
                let r = find(parent, p);
                parent.insert(v, r);
                r
            }
        }
        for e in edges {
            let (a, b) = (find(&mut parent, e[0]), find(&mut parent, e[1]));
            parent.insert(a, b);
        }
        let keys: Vec<u32> = parent.keys().copied().collect();
        let roots: BTreeSet<u32> = keys.into_iter().map(|v| find(&mut parent, v)).collect();
        roots.len()
    }

    #[test]
    fn circumradius_of_known_triangles() {
        let r = circumradius([0.0, 0.0], [2.0, 0.0], [0.0, 2.0]);
        assert!((r - 2f64.sqrt()).abs() < 1e-15);
        let s = 3f64.sqrt();
        let r = circumradius([0.0, 0.0], [1.0, 0.0], [0.5, s / 2.0]);
        assert!((r - 1.0 / s).abs() < 1e-15);
        assert_eq!(
            circumradius([0.0, 0.0], [1.0, 1.0], [3.0, 3.0]),
            f64::INFINITY
        );
        assert_eq!(
            circumradius([0.0, 0.0], [f64::NAN, 1.0], [3.0, 3.0]),
            f64::INFINITY
        );
    }

    #[test]
    fn decision_is_bitwise_independent_of_vertex_order() {
        let p = [[0.1, 0.7], [1.3, 0.2], [0.9, 1.1 + 1e-9]];
        let h = [0.3, 0.7, 0.1 + 1e-16];
        let base = circumradius(p[0], p[1], p[2]);
        let perms = [
            [0, 1, 2],
            [0, 2, 1],
            [1, 0, 2],
            [1, 2, 0],
            [2, 0, 1],
            [2, 1, 0],
        ];
        // alpha chosen so that R == alpha * h_T to the last bit for the reference order.
        let alpha = base / ((h[0] + h[1] + h[2]) / 3.0);
        let reference = alpha_keep(&p, &[[0, 1, 2]], &h, alpha);
        for q in perms {
            assert_eq!(
                circumradius(p[q[0]], p[q[1]], p[q[2]]).to_bits(),
                base.to_bits()
            );
            let pts = q.map(|i| p[i]);
            let hs = q.map(|i| h[i]);
            for t in perms {
                let tri = [t[0] as u32, t[1] as u32, t[2] as u32];
                assert_eq!(alpha_keep(&pts, &[tri], &hs, alpha), reference);
            }
        }
    }

    #[test]
    fn invalid_triangles_are_dropped() {
        let pts = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let tris = [[0, 1, 2], [0, 1, 7], [0, 1, 2]];
        assert_eq!(
            alpha_keep(&pts, &tris, &[1.0, 1.0, 1.0], 1.0),
            vec![true, false, true]
        );
        assert_eq!(
            alpha_keep(&pts, &tris[..1], &[1.0, f64::NAN, 1.0], 1.0),
            vec![false]
        );
        assert_eq!(alpha_keep(&pts, &tris[..1], &[1.0, 1.0], 1.0), vec![false]);
    }

    #[test]
    fn lattice_block_keeps_everything_and_bounds_its_perimeter() {
        let (nx, ny, h) = (12, 7, 0.25);
        let pts = lattice(nx, ny, h, |_, _| true);
        let kept = alpha_mesh(&pts, h, 1.3);
        assert_eq!(kept.len(), 2 * (nx - 1) * (ny - 1));
        let edges = boundary_edges(&kept);
        assert_eq!(edges.len(), 2 * (nx - 1) + 2 * (ny - 1));
        assert!(edges.windows(2).all(|w| w[0] < w[1]));
        check_boundary_encloses(&pts, &kept, &edges);
        assert_eq!(loops(&edges), 1);
        // Every perimeter point, and only those, is a boundary vertex.
        let on_perimeter: Vec<u32> = (0..pts.len() as u32)
            .filter(|&k| {
                let (i, j) = (k as usize % nx, k as usize / nx);
                i == 0 || j == 0 || i == nx - 1 || j == ny - 1
            })
            .collect();
        assert_eq!(boundary_vertices(&kept), on_perimeter);
    }

    #[test]
    fn block_with_hole_recovers_the_hole_boundary() {
        let (n, h) = (11, 1.0);
        // Remove the 3x3 points 4..=6 in both directions: a 4h x 4h square hole whose four
        // re-entrant corners are each cut by one kept half cell (R = 0.71h), leaving an
        // octagonal hole with 3 edges per side.
        let hole = |i: usize, j: usize| (4..=6).contains(&i) && (4..=6).contains(&j);
        let pts = lattice(n, n, h, |i, j| !hole(i, j));
        let kept = alpha_mesh(&pts, h, 1.3);
        let edges = boundary_edges(&kept);
        assert_eq!(edges.len(), 4 * (n - 1) + 12);
        assert_eq!(loops(&edges), 2);
        check_boundary_encloses(&pts, &kept, &edges);
        let kept_area: f64 = kept.iter().map(|t| area2(&pts, t)).sum();
        assert!((kept_area - 2.0 * (100.0 - 16.0 + 4.0 * 0.5)).abs() < 1e-9);
        // The hole loop runs clockwise: its edges have the removed points on their right.
        let centre = [5.0, 5.0];
        let near_hole = |v: u32| {
            let p = pts[v as usize];
            (p[0] - centre[0]).abs() <= 2.0 && (p[1] - centre[1]).abs() <= 2.0
        };
        let hole_edges = edges.iter().filter(|e| near_hole(e[0]) && near_hole(e[1]));
        let mut count = 0;
        for e in hole_edges {
            assert!(orient2d(pts[e[0] as usize], pts[e[1] as usize], centre) < 0.0);
            count += 1;
        }
        assert_eq!(count, 12);
    }

    #[test]
    fn l_shape_cuts_only_the_reentrant_corner() {
        let (n, h) = (11, 0.5);
        let pts = lattice(n, n, h, |i, j| i <= 5 || j <= 5);
        let kept = alpha_mesh(&pts, h, 1.3);
        let edges = boundary_edges(&kept);
        // 10 + 5 + 4 + 1 (corner diagonal) + 4 + 5 + 10 edges.
        assert_eq!(edges.len(), 39);
        assert_eq!(loops(&edges), 1);
        check_boundary_encloses(&pts, &kept, &edges);
        let kept_area: f64 = kept.iter().map(|t| area2(&pts, t)).sum::<f64>() / 2.0;
        assert!((kept_area - 75.5 * h * h).abs() < 1e-9);
    }

    #[test]
    fn separated_blocks_are_not_bridged() {
        let h = 1.0;
        // Two 5x5 blocks with a gap of three spacings between them.
        let pts = lattice(13, 5, h, |i, _| i <= 4 || i >= 8);
        let kept = alpha_mesh(&pts, h, 1.3);
        for t in &kept {
            let left = t.map(|v| pts[v as usize][0] <= 4.0 * h);
            assert!(left == [true; 3] || left == [false; 3], "bridging triangle");
        }
        assert_eq!(kept.len(), 2 * 2 * 4 * 4);
        let edges = boundary_edges(&kept);
        assert_eq!(edges.len(), 2 * 16);
        assert_eq!(loops(&edges), 2);
        check_boundary_encloses(&pts, &kept, &edges);
        assert_eq!(boundary_vertices(&kept).len(), 2 * 16);
    }

    #[test]
    fn variable_spacing_uses_the_largest_vertex_spacing() {
        // Right triangle with legs 2: R = sqrt(2).
        let pts = [[0.0, 0.0], [2.0, 0.0], [0.0, 2.0]];
        let tri = [[0, 1, 2]];
        let r = 2f64.sqrt();
        // Largest spacing 1: kept iff alpha >= sqrt(2).
        let h = [0.5, 1.0, 0.25];
        assert_eq!(alpha_keep(&pts, &tri, &h, r * 1.000_001), vec![true]);
        assert_eq!(alpha_keep(&pts, &tri, &h, r * 0.999_999), vec![false]);
    }

    #[test]
    fn boundary_of_two_triangles_and_of_nothing() {
        assert!(boundary_edges(&[]).is_empty());
        assert!(boundary_vertices(&[]).is_empty());
        // Square 0-1-2-3 split along 0-2.
        let tris = [[0, 1, 2], [0, 2, 3]];
        assert_eq!(boundary_edges(&tris), vec![[0, 1], [1, 2], [2, 3], [3, 0]]);
        assert_eq!(boundary_vertices(&tris), vec![0, 1, 2, 3]);
    }
}
