//! The rigid-body modes of plane elasticity on the displacement dofs: what an algebraic
//! multigrid must interpolate exactly to coarsen elasticity well (PETSc's near-null space).

use pfem_partition::{sum_f64, Comm};

/// The three in-plane rigid-body motions at nodes `coords` (two translations, and the rotation
/// about `centre`), as vectors of interleaved (ux, uy) per node.
pub fn rigid_body_modes(coords: &[[f64; 2]], centre: [f64; 2]) -> [Vec<f64>; 3] {
    let n = 2 * coords.len();
    let mut modes = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for (i, x) in coords.iter().enumerate() {
        modes[0][2 * i] = 1.0;
        modes[1][2 * i + 1] = 1.0;
        modes[2][2 * i] = -(x[1] - centre[1]);
        modes[2][2 * i + 1] = x[0] - centre[0];
    }
    modes
}

/// Collective. The rigid-body modes on this rank's owned displacement nodes (`coords`, in the
/// order of their dofs), orthonormal over all ranks: the translations are orthogonal to each
/// other, and to the rotation because it turns about the centroid of all nodes.
pub fn orthonormal_rigid_body_modes(comm: &Comm, coords: &[[f64; 2]]) -> [Vec<f64>; 3] {
    let mut s = [0.0; 3];
    for x in coords {
        s[0] += x[0];
        s[1] += x[1];
    }
    s[2] = coords.len() as f64;
    let s = sum_f64(comm, &s);
    let count = s[2].max(1.0);
    let mut modes = rigid_body_modes(coords, [s[0] / count, s[1] / count]);
    let local: Vec<f64> = modes
        .iter()
        .map(|m| m.iter().map(|v| v * v).sum())
        .collect();
    let norms = sum_f64(comm, &local);
    for (m, n2) in modes.iter_mut().zip(norms) {
        let scale = if n2 > 0.0 { 1.0 / n2.sqrt() } else { 0.0 };
        m.iter_mut().for_each(|v| *v *= scale);
    }
    modes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::element::p2_element;
    use crate::fem::mixed::p2p1_element;
    use crate::fem::p2::straight_sided;
    use crate::material::elastic::LinearElastic;
    use crate::material::GaussState;
    use std::collections::HashMap;

    /// A P2 mesh of a distorted 3 x 2 patch of squares cut into triangles: node coordinates
    /// (vertices, then midside nodes) and the 6 nodes of every triangle.
    fn patch() -> (Vec<[f64; 2]>, Vec<[usize; 6]>) {
        let (nx, ny) = (3, 2);
        let mut coords = Vec::new();
        for j in 0..=ny {
            for i in 0..=nx {
                // A shear and a bulge, so that no element is a scaled copy of another.
                let (x, y) = (i as f64, j as f64);
                coords.push([0.7 * x + 0.2 * y + 0.05 * (x * y), 0.5 * y + 0.03 * x * x]);
            }
        }
        let v = |i: usize, j: usize| j * (nx + 1) + i;
        let mut tris = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                tris.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                tris.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
            }
        }
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        let mut out = Vec::new();
        for t in &tris {
            let mut nodes = [t[0], t[1], t[2], 0, 0, 0];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let next = coords.len();
                let m = *edges.entry(key).or_insert_with(|| {
                    let (pa, pb) = (coords[a], coords[b]);
                    coords.push([0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]);
                    next
                });
                nodes[3 + k] = m;
            }
            out.push(nodes);
        }
        (coords, out)
    }

    fn norm(v: &[f64]) -> f64 {
        v.iter().map(|x| x * x).sum::<f64>().sqrt()
    }

    /// K·r relative to ‖K‖_F ‖r‖ for every rigid-body mode r of the patch, with K the
    /// unconstrained tangent (material and geometric parts) assembled from `element`, which
    /// returns a triangle's row-major tangent with the 12 displacement dofs first and `extra`
    /// dofs (pressures at the vertices) after them.
    fn kernel_residuals(extra: usize, element: impl Fn(&[[f64; 2]; 6]) -> Vec<f64>) -> [f64; 3] {
        let (coords, tris) = patch();
        let n_vertex = 12;
        let n_u = 2 * coords.len();
        let n = n_u + extra * n_vertex;
        let mut k = vec![0.0; n * n];
        for t in &tris {
            let x = straight_sided(&[coords[t[0]], coords[t[1]], coords[t[2]]]);
            let ke = element(&x);
            let mut dofs: Vec<usize> = t.iter().flat_map(|&a| [2 * a, 2 * a + 1]).collect();
            if extra > 0 {
                dofs.extend(t[..3].iter().map(|&a| n_u + a));
            }
            let m = dofs.len();
            for (r, &gr) in dofs.iter().enumerate() {
                for (c, &gc) in dofs.iter().enumerate() {
                    k[gr * n + gc] += ke[r * m + c];
                }
            }
        }
        let k_norm = norm(&k);
        let modes = rigid_body_modes(&coords, [0.9, 0.6]);
        modes.map(|mode| {
            let mut r = mode.clone();
            r.resize(n, 0.0);
            let kr: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| k[i * n + j] * r[j]).sum())
                .collect();
            norm(&kr) / (k_norm * norm(&r))
        })
    }

    #[test]
    fn rigid_body_modes_are_in_the_kernel_of_the_stress_free_p2_tangent() {
        let mat = LinearElastic::new(12.0e6, 0.3).expect("material");
        let states = [GaussState::default(); 3];
        let residuals = kernel_residuals(0, |x| {
            let e = p2_element(x, &[[0.0; 2]; 6], &states, &mat, [0.0; 2]).expect("element");
            e.tangent.as_flattened().to_vec()
        });
        println!("P2: |K r| / (|K| |r|) = {residuals:?}");
        for r in residuals {
            assert!(r < 1e-14, "rigid-body mode not in the kernel: {r:e}");
        }
    }

    #[test]
    fn rigid_body_modes_are_in_the_kernel_of_the_stress_free_mixed_tangent() {
        // ν = 0.4999: the displacement and pressure blocks of a nearly incompressible solid.
        let mat = LinearElastic::new(12.0e6, 0.4999).expect("material");
        let states = [GaussState::default(); 3];
        let bulk = 12.0e6 / (3.0 * (1.0 - 2.0 * 0.4999));
        let residuals = kernel_residuals(1, |x| {
            let e = p2p1_element(x, &[[0.0; 2]; 6], &[0.0; 3], &states, &mat, bulk, [0.0; 2])
                .expect("element")
                .with_pressure_scale(4.0e6);
            e.tangent.as_flattened().to_vec()
        });
        println!("P2-P1: |K r| / (|K| |r|) = {residuals:?}");
        for r in residuals {
            assert!(r < 1e-14, "rigid-body mode not in the kernel: {r:e}");
        }
    }

    #[test]
    fn a_non_rigid_motion_is_not_in_the_kernel() {
        // The test above can fail: a stretch is not a rigid-body mode.
        let mat = LinearElastic::new(12.0e6, 0.3).expect("material");
        let states = [GaussState::default(); 3];
        let (coords, _) = patch();
        let x = straight_sided(&[coords[0], coords[1], coords[5]]);
        let e = p2_element(&x, &[[0.0; 2]; 6], &states, &mat, [0.0; 2]).expect("element");
        let u: Vec<f64> = x.iter().flat_map(|p| [p[0], 0.0]).collect();
        let ku: Vec<f64> = (0..12)
            .map(|i| (0..12).map(|j| e.tangent[i][j] * u[j]).sum())
            .collect();
        let k_norm = norm(e.tangent.as_flattened());
        assert!(norm(&ku) / (k_norm * norm(&u)) > 1e-3);
    }
}
