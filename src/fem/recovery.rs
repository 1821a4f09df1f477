//! Moving Gauss-point data to vertices, and linear interpolation of vertex data inside a triangle.
//!
//! Extrapolation assumes the 3-point rule [`crate::fem::quadrature::TRI3`], whose point q lies on
//! the median towards vertex q (area coordinate 2/3 there, 1/6 elsewhere). The linear field through
//! the three Gauss values g is then f_k = 2 g_k − (g_0 + g_1 + g_2)/3 at vertex k; this holds for
//! curved P2 elements too, because it is done in area coordinates.

/// Row k gives vertex k's value as a combination of the three Gauss values: the inverse of the
/// matrix of Gauss-point area coordinates in [`crate::fem::quadrature::TRI3_POINTS`].
pub const GAUSS_TO_VERTEX: [[f64; 3]; 3] = [
    [5.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0],
    [-1.0 / 3.0, 5.0 / 3.0, -1.0 / 3.0],
    [-1.0 / 3.0, -1.0 / 3.0, 5.0 / 3.0],
];

/// The unique linear field through the Gauss values (component by component), evaluated at the
/// three vertices. Row q of the input belongs to Gauss point q; row k of the output to vertex k.
pub fn extrapolate_to_vertices<const K: usize>(values_at_gauss: &[[f64; K]; 3]) -> [[f64; K]; 3] {
    let mut out = [[0.0; K]; 3];
    for (o, coeffs) in out.iter_mut().zip(GAUSS_TO_VERTEX.iter()) {
        for (c, g) in coeffs.iter().zip(values_at_gauss.iter()) {
            for (ok, gk) in o.iter_mut().zip(g.iter()) {
                *ok += c * gk;
            }
        }
    }
    out
}

/// Barycentric coordinates of `p` in triangle (a, b, c): weights of a, b, c, summing to 1.
///
/// Points outside the triangle get a negative coordinate, which callers use for point location.
/// A degenerate (zero-area) triangle yields non-finite values rather than a panic; callers that
/// can meet such triangles must check with `is_finite`.
pub fn barycentric(a: [f64; 2], b: [f64; 2], c: [f64; 2], p: [f64; 2]) -> [f64; 3] {
    let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    let lb = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / det;
    let lc = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / det;
    [1.0 - lb - lc, lb, lc]
}

/// `Σ_k bary[k] · vertex_values[k]`, component by component.
pub fn interpolate_linear<const K: usize>(
    bary: [f64; 3],
    vertex_values: &[[f64; K]; 3],
) -> [f64; K] {
    let mut out = [0.0; K];
    for (l, v) in bary.iter().zip(vertex_values.iter()) {
        for (o, vk) in out.iter_mut().zip(v.iter()) {
            *o += l * vk;
        }
    }
    out
}

#[cfg(test)]
// Index loops mirror the component notation of the formulas being checked.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::fem::element::p2_gauss_points;
    use crate::fem::p2;
    use crate::fem::quadrature::TRI3_POINTS;

    fn field(p: [f64; 2]) -> [f64; 4] {
        [
            1.0 + 2.0 * p[0] - 3.0 * p[1],
            -4.5e5 + 1.0e4 * p[1],
            0.25 * p[0],
            7.0,
        ]
    }

    #[test]
    fn gauss_to_vertex_inverts_the_rule() {
        for i in 0..3 {
            for j in 0..3 {
                let s: f64 = (0..3)
                    .map(|q| GAUSS_TO_VERTEX[i][q] * TRI3_POINTS[q][j])
                    .sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((s - want).abs() < 1e-15, "({i},{j}) = {s}");
            }
        }
    }

    #[test]
    fn extrapolation_reproduces_linear_fields() {
        let v = [[0.3, 0.1], [2.2, 0.4], [0.9, 1.7]];
        let x = p2::straight_sided(&v);
        let gp = p2_gauss_points(&x);
        let at_gauss = [field(gp[0]), field(gp[1]), field(gp[2])];
        let at_vertices = extrapolate_to_vertices(&at_gauss);
        for k in 0..3 {
            let want = field(v[k]);
            for c in 0..4 {
                let tol = 1e-12 * want[c].abs().max(1.0);
                assert!(
                    (at_vertices[k][c] - want[c]).abs() < tol,
                    "vertex {k} comp {c}"
                );
            }
        }
        // Not the identity: a plain copy of the Gauss values would fail the check above.
        assert!((at_vertices[0][0] - at_gauss[0][0]).abs() > 1e-3);
    }

    #[test]
    fn barycentric_coordinates() {
        let (a, b, c) = ([0.5, -0.2], [3.0, 0.3], [1.0, 2.5]);
        for (k, vtx) in [a, b, c].iter().enumerate() {
            let l = barycentric(a, b, c, *vtx);
            for (i, li) in l.iter().enumerate() {
                let want = if i == k { 1.0 } else { 0.0 };
                assert!((li - want).abs() < 1e-14);
            }
        }
        let p = [1.4, 0.9];
        let l = barycentric(a, b, c, p);
        assert!((l.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        for i in 0..2 {
            let r = l[0] * a[i] + l[1] * b[i] + l[2] * c[i];
            assert!((r - p[i]).abs() < 1e-14);
        }
        assert!(barycentric(a, b, c, [5.0, 5.0]).iter().any(|v| *v < 0.0));
        let degenerate = barycentric([0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.5, 0.5]);
        assert!(degenerate.iter().any(|v| !v.is_finite()));
    }

    #[test]
    fn interpolation_reproduces_linear_fields() {
        let (a, b, c) = ([0.5, -0.2], [3.0, 0.3], [1.0, 2.5]);
        let vals = [field(a), field(b), field(c)];
        for p in [[1.4, 0.9], [0.6, 0.0], [2.0, 0.8], [4.0, -1.0]] {
            let got = interpolate_linear(barycentric(a, b, c, p), &vals);
            let want = field(p);
            for k in 0..4 {
                assert!(
                    (got[k] - want[k]).abs() < 1e-12 * want[k].abs().max(1.0),
                    "{p:?} {k}"
                );
            }
        }
    }
}
