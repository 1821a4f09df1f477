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
