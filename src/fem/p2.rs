//! Six-node quadratic (P2) triangle.
//!
//! Node order: the three vertices (counter-clockwise), then the midside nodes of edges
//! (0-1), (1-2), (2-0). Reference triangle (0,0), (1,0), (0,1) with coordinates (ξ, η) and area
//! coordinates L0 = 1 - ξ - η, L1 = ξ, L2 = η. The element is isoparametric: the geometry is
//! interpolated with the same shape functions, so curved edges (midside nodes off the chord) are
//! supported; straight-sided elements (midside nodes at chord midpoints) have a constant Jacobian.

use std::fmt;

/// Number of nodes of the element.
pub const N_NODES: usize = 6;

/// Local edges as (first vertex, second vertex); midside node `3 + k` lies on edge `k`.
pub const EDGES: [[usize; 2]; 3] = [[0, 1], [1, 2], [2, 0]];

/// Reference coordinates (ξ, η) of the six nodes.
pub const REFERENCE_NODES: [[f64; 2]; N_NODES] = [
    [0.0, 0.0],
    [1.0, 0.0],
    [0.0, 1.0],
    [0.5, 0.0],
    [0.5, 0.5],
    [0.0, 0.5],
];

/// Gradients of the area coordinates L0, L1, L2 with respect to (ξ, η).
const DL: [[f64; 2]; 3] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];

fn area_coords(xi: [f64; 2]) -> [f64; 3] {
    [1.0 - xi[0] - xi[1], xi[0], xi[1]]
}

/// Shape function values at reference point `xi`.
pub fn shape(xi: [f64; 2]) -> [f64; N_NODES] {
    let l = area_coords(xi);
    let mut n = [0.0; N_NODES];
    for k in 0..3 {
        n[k] = l[k] * (2.0 * l[k] - 1.0);
        let [i, j] = EDGES[k];
        n[3 + k] = 4.0 * l[i] * l[j];
    }
    n
}

/// Shape function gradients with respect to (ξ, η) at reference point `xi`; row `a` is ∇_ξ N_a.
pub fn shape_grad_ref(xi: [f64; 2]) -> [[f64; 2]; N_NODES] {
    let l = area_coords(xi);
    let mut g = [[0.0; 2]; N_NODES];
    for k in 0..3 {
        let [i, j] = EDGES[k];
        for d in 0..2 {
            g[k][d] = (4.0 * l[k] - 1.0) * DL[k][d];
            g[3 + k][d] = 4.0 * (l[j] * DL[i][d] + l[i] * DL[j][d]);
        }
    }
    g
}

/// Six-node geometry of a straight-sided element from its three vertices.
pub fn straight_sided(v: &[[f64; 2]; 3]) -> [[f64; 2]; N_NODES] {
    let mid = |a: [f64; 2], b: [f64; 2]| [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    [
        v[0],
        v[1],
        v[2],
        mid(v[0], v[1]),
        mid(v[1], v[2]),
        mid(v[2], v[0]),
    ]
}

/// Physical position of reference point `xi` for the element with node coordinates `x`.
pub fn map_to_physical(x: &[[f64; 2]; N_NODES], xi: [f64; 2]) -> [f64; 2] {
    interpolate(&shape(xi), x)
}

/// Σ_a N_a v_a for two-component nodal values.
pub fn interpolate(n: &[f64; N_NODES], v: &[[f64; 2]; N_NODES]) -> [f64; 2] {
    let mut out = [0.0; 2];
    for (na, va) in n.iter().zip(v.iter()) {
        out[0] += na * va[0];
        out[1] += na * va[1];
    }
    out
}

/// Shape function gradients with respect to physical coordinates at one reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhysicalGradients {
    /// Row `a` is ∇_x N_a.
    pub grad: [[f64; 2]; N_NODES],
    /// det(∂x/∂ξ) (> 0): the physical-to-reference area ratio at this point.
    pub det_j: f64,
}

/// The isoparametric map is singular or orientation-reversing at the evaluation point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonPositiveJacobian {
    /// det(∂x/∂ξ) found there (≤ 0 or not finite).
    pub det_j: f64,
}

impl fmt::Display for NonPositiveJacobian {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "isoparametric Jacobian det = {:e} is not positive (degenerate, inverted or clockwise element)",
            self.det_j
        )
    }
}

impl std::error::Error for NonPositiveJacobian {}

/// Physical gradients ∇_x N_a = J⁻ᵀ ∇_ξ N_a at reference point `xi`, with J = ∂x/∂ξ.
///
/// Fails when det J is not positive, which also rejects clockwise node orderings.
pub fn physical_gradients(
    x: &[[f64; 2]; N_NODES],
    xi: [f64; 2],
) -> Result<PhysicalGradients, NonPositiveJacobian> {
    let gr = shape_grad_ref(xi);
    // jac[i][j] = ∂x_i/∂ξ_j
    let mut jac = [[0.0; 2]; 2];
    for (xa, ga) in x.iter().zip(gr.iter()) {
        for i in 0..2 {
            for j in 0..2 {
                jac[i][j] += xa[i] * ga[j];
            }
        }
    }
    let det_j = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
    if !det_j.is_finite() || det_j <= 0.0 {
        return Err(NonPositiveJacobian { det_j });
    }
    // ∇_x N = J⁻ᵀ ∇_ξ N, with J⁻¹ = adj(J)/det.
    let inv = 1.0 / det_j;
    let mut grad = [[0.0; 2]; N_NODES];
    for (g, r) in grad.iter_mut().zip(gr.iter()) {
        g[0] = inv * (jac[1][1] * r[0] - jac[1][0] * r[1]);
        g[1] = inv * (-jac[0][1] * r[0] + jac[0][0] * r[1]);
    }
    Ok(PhysicalGradients { grad, det_j })
}

#[cfg(test)]
// Index loops mirror the component notation of the formulas being checked.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;

    const SAMPLE: [[f64; 2]; 5] = [
        [0.2, 0.3],
        [0.05, 0.9],
        [0.6, 0.1],
        [1.0 / 3.0, 1.0 / 3.0],
        [0.0, 0.0],
    ];

    #[test]
    fn partition_of_unity_and_zero_gradient_sum() {
        for xi in SAMPLE {
            let n = shape(xi);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-15, "{xi:?}");
            let g = shape_grad_ref(xi);
            for d in 0..2 {
                let s: f64 = g.iter().map(|ga| ga[d]).sum();
                assert!(s.abs() < 1e-14, "{xi:?} d{d}: {s}");
            }
        }
    }

    #[test]
    fn kronecker_delta_at_nodes() {
        for (b, xb) in REFERENCE_NODES.iter().enumerate() {
            let n = shape(*xb);
            for (a, na) in n.iter().enumerate() {
                let want = if a == b { 1.0 } else { 0.0 };
                assert!((na - want).abs() < 1e-15, "N_{a} at node {b} = {na}");
            }
        }
    }

    #[test]
    fn reference_gradients_match_finite_differences() {
        let h = 1e-6;
        for xi in SAMPLE {
            let g = shape_grad_ref(xi);
            for d in 0..2 {
                let mut p = xi;
                let mut m = xi;
                p[d] += h;
                m[d] -= h;
                let (np, nm) = (shape(p), shape(m));
                for a in 0..N_NODES {
                    let fd = (np[a] - nm[a]) / (2.0 * h);
                    assert!(
                        (fd - g[a][d]).abs() < 1e-8,
                        "a{a} d{d}: {fd} vs {}",
                        g[a][d]
                    );
                }
            }
        }
    }

    #[test]
    fn straight_sided_element_is_affine() {
        let v = [[1.0, 0.5], [3.0, 1.0], [1.5, 2.5]];
        let x = straight_sided(&v);
        let area2 =
            (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
        // A linear field f = c + a·x must have ∇f reproduced exactly by the nodal interpolant.
        let f = |p: [f64; 2]| 0.7 - 1.3 * p[0] + 2.1 * p[1];
        for xi in SAMPLE {
            let p = map_to_physical(&x, xi);
            let l = [1.0 - xi[0] - xi[1], xi[0], xi[1]];
            for i in 0..2 {
                let affine = l[0] * v[0][i] + l[1] * v[1][i] + l[2] * v[2][i];
                assert!((p[i] - affine).abs() < 1e-14);
            }
            let pg = physical_gradients(&x, xi).expect("valid element");
            assert!(
                (pg.det_j - area2).abs() < 1e-13,
                "det J must be twice the area"
            );
            let mut grad = [0.0; 2];
            for a in 0..N_NODES {
                for d in 0..2 {
                    grad[d] += pg.grad[a][d] * f(x[a]);
                }
            }
            assert!(
                (grad[0] + 1.3).abs() < 1e-13 && (grad[1] - 2.1).abs() < 1e-13,
                "{grad:?}"
            );
            for d in 0..2 {
                let s: f64 = pg.grad.iter().map(|g| g[d]).sum();
                assert!(s.abs() < 1e-13);
            }
        }
    }

    #[test]
    fn curved_element_reproduces_linear_fields() {
        let mut x = straight_sided(&[[0.0, 0.0], [2.0, 0.2], [0.4, 1.8]]);
        x[4][0] += 0.15; // bow edge (1-2) outwards
        x[3][1] -= 0.1;
        let f = |p: [f64; 2]| -0.4 + 0.9 * p[0] - 0.25 * p[1];
        for xi in SAMPLE {
            let pg = physical_gradients(&x, xi).expect("valid element");
            let mut grad = [0.0; 2];
            for a in 0..N_NODES {
                for d in 0..2 {
                    grad[d] += pg.grad[a][d] * f(x[a]);
                }
            }
            assert!(
                (grad[0] - 0.9).abs() < 1e-13 && (grad[1] + 0.25).abs() < 1e-13,
                "{grad:?}"
            );
        }
    }

    #[test]
    fn clockwise_or_degenerate_elements_are_rejected() {
        let cw = straight_sided(&[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]);
        let e = physical_gradients(&cw, [0.2, 0.2]).expect_err("clockwise must fail");
        assert!(e.det_j < 0.0);
        assert!(e.to_string().contains(&format!("{:e}", e.det_j)), "{e}");
        let flat = straight_sided(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]);
        assert!(physical_gradients(&flat, [0.2, 0.2]).is_err());
    }
}
