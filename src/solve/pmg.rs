//! The coarse level of a two-level p-multigrid for P2 displacements: P1 on the particles. The
//! P2 mesh's vertex nodes are its nodes, and since a midside node sits at its edge's midpoint
//! when the increment starts, P1 → P2 interpolation is exact: a vertex takes its own value, an
//! edge node the mean of its two ends. The coarse operator is the P1 stiffness of the same
//! triangles (rediscretised, not a Galerkin product of the P2 matrix, which couples a vertex
//! with its second ring of neighbours), so it is as sparse as a P1 matrix and carries the
//! rigid-body modes of its own nodes for the AMG that solves it.

use super::{Constraints, DofMap};
use crate::fem::p1;
use crate::material::{GaussState, Material};
use crate::mesh::LocalMesh;
use pfem_partition::{allgather_u64, exscan_u64, Comm, PartitionError};

/// The P1 space on this rank: numbering, interpolation pattern and stiffness pattern.
pub struct CoarseSpace {
    /// Owned coarse dofs (2 per owned vertex node).
    pub n_owned: usize,
    /// Per local node: the global number of its coarse x dof (y follows), `usize::MAX` for a
    /// midside node.
    coarse_dof: Vec<usize>,
    /// Per owned P2 row of the interpolation, nonzeros in owned and in other ranks' columns.
    pub interpolation_d_nnz: Vec<usize>,
    pub interpolation_o_nnz: Vec<usize>,
    /// Per owned coarse row of the stiffness, nonzeros in owned and in other ranks' columns.
    pub stiffness_d_nnz: Vec<usize>,
    pub stiffness_o_nnz: Vec<usize>,
}

impl CoarseSpace {
    /// Collective. Relies on [`DofMap`] numbering a rank's owned vertex nodes first, 2 dofs each
    /// (P2 only): a vertex's coarse number is its fine number shifted from the owner's first
    /// fine dof to the owner's first coarse dof.
    pub fn build(comm: &Comm, mesh: &LocalMesh, dofs: &DofMap) -> Result<Self, PartitionError> {
        assert_eq!(
            dofs.vertex_dofs, 2,
            "a p-multigrid coarse space is for P2 displacements"
        );
        let n_vertex = n_vertex_nodes(dofs);
        let owned_vertices = (0..n_vertex).filter(|&n| dofs.node_owned[n]).count();
        let (coarse_first, _) = exscan_u64(comm, 2 * owned_vertices as u64);
        let table = allgather_u64(comm, &[dofs.first_dof as u64, coarse_first]);
        let coarse_dof = (0..dofs.n_nodes())
            .map(|n| {
                if n >= n_vertex {
                    return usize::MAX;
                }
                let r = mesh.owner[dofs.node_point[n] as usize] as usize;
                dofs.node_global[n] - table[2 * r] as usize + table[2 * r + 1] as usize
            })
            .collect();
        let (mut interpolation_d_nnz, mut interpolation_o_nnz) = (Vec::new(), Vec::new());
        for n in (0..dofs.n_nodes()).filter(|&n| dofs.node_owned[n]) {
            let ends = interpolation_ends(dofs, n);
            let inside = ends.iter().filter(|&&(v, _)| dofs.node_owned[v]).count();
            // One entry per end: a component interpolates from the same component.
            for _ in 0..2 {
                interpolation_d_nnz.push(inside);
                interpolation_o_nnz.push(ends.len() - inside);
            }
        }
        let (mut stiffness_d_nnz, mut stiffness_o_nnz) = (Vec::new(), Vec::new());
        for (owned, other) in dofs.vertex_neighbour_counts() {
            for _ in 0..2 {
                stiffness_d_nnz.push(2 * owned);
                stiffness_o_nnz.push(2 * other);
            }
        }
        Ok(CoarseSpace {
            n_owned: 2 * owned_vertices,
            coarse_dof,
            interpolation_d_nnz,
            interpolation_o_nnz,
            stiffness_d_nnz,
            stiffness_o_nnz,
        })
    }

    /// Hands `add` the interpolation's entries on this rank's P2 rows, one row at a time
    /// (global row, global columns, weights). Entries of prescribed P2 rows and of prescribed
    /// coarse columns are zero (kept, so that the pattern does not depend on the constraints):
    /// a coarse correction never moves a prescribed dof, and the residual at one never reaches
    /// the coarse level.
    pub fn interpolation<E>(
        &self,
        dofs: &DofMap,
        constraints: &Constraints,
        mut add: impl FnMut(usize, &[usize], &[f64]) -> Result<(), E>,
    ) -> Result<(), E> {
        let fixed = |n: usize, c: usize| constraints.fixed[n][c].is_some();
        for n in (0..dofs.n_nodes()).filter(|&n| dofs.node_owned[n]) {
            let ends = interpolation_ends(dofs, n);
            for c in 0..2 {
                let cols: Vec<usize> = ends.iter().map(|&(v, _)| self.coarse_dof[v] + c).collect();
                let weights: Vec<f64> = ends
                    .iter()
                    .map(|&(v, w)| if fixed(n, c) || fixed(v, c) { 0.0 } else { w })
                    .collect();
                add(dofs.node_global[n] + c, &cols, &weights)?;
            }
        }
        Ok(())
    }

    /// Hands `add` the P1 stiffness of every triangle with an owned vertex, on the start-of-step
    /// geometry, with the material's tangent at the start of the step (the mean over a
    /// triangle's Gauss points, at zero step strain): the rows of its owned vertices (global
    /// rows, the triangle's six global columns, row-major values). Rows and columns of
    /// prescribed coarse dofs are zero (their diagonal is the caller's). Returns the sum and
    /// the count of this rank's free diagonal entries, for that diagonal.
    pub fn stiffness(
        &self,
        mesh: &LocalMesh,
        dofs: &DofMap,
        setup: (&Constraints, &[[GaussState; 3]], &dyn Material),
        mut add: impl FnMut(&[usize], &[usize], &[f64]) -> Result<(), String>,
    ) -> Result<(f64, usize), String> {
        let (constraints, states_n, material) = setup;
        let fixed = |n: usize, c: usize| constraints.fixed[n][c].is_some();
        let mut diagonal_sum = 0.0;
        let (mut rows, mut vals) = (Vec::with_capacity(6), Vec::with_capacity(36));
        for (t, nodes) in dofs.tri_nodes.iter().enumerate() {
            let v: [usize; 3] = std::array::from_fn(|k| nodes[k] as usize);
            if v.iter().all(|&n| !dofs.node_owned[n]) {
                continue;
            }
            let x = v.map(|n| mesh.points[dofs.node_point[n] as usize]);
            let mut d = [[0.0; 3]; 3];
            for state in &states_n[t] {
                let full = material
                    .update(state, &[0.0; 4])
                    .map_err(|e| format!("coarse stiffness, triangle {t}: {e}"))?
                    .d;
                for (i, &a) in [0, 1, 3].iter().enumerate() {
                    for (j, &b) in [0, 1, 3].iter().enumerate() {
                        d[i][j] += full[a][b] / 3.0;
                    }
                }
            }
            let k = p1::stiffness(&x, &d);
            let cols: Vec<usize> = (0..6).map(|j| self.coarse_dof[v[j / 2]] + j % 2).collect();
            rows.clear();
            vals.clear();
            for i in (0..6).filter(|&i| dofs.node_owned[v[i / 2]]) {
                rows.push(cols[i]);
                let row_fixed = fixed(v[i / 2], i % 2);
                for j in 0..6 {
                    let free = !row_fixed && !fixed(v[j / 2], j % 2);
                    vals.push(if free { k[i][j] } else { 0.0 });
                }
                if !row_fixed {
                    diagonal_sum += k[i][i];
                }
            }
            add(&rows, &cols, &vals)?;
        }
        let diagonal_count = (0..n_vertex_nodes(dofs))
            .filter(|&n| dofs.node_owned[n])
            .map(|n| (0..2).filter(|&c| !fixed(n, c)).count())
            .sum();
        Ok((diagonal_sum, diagonal_count))
    }

    /// The prescribed coarse dofs this rank owns (their rows get the diagonal alone).
    pub fn fixed_rows(&self, dofs: &DofMap, constraints: &Constraints) -> Vec<usize> {
        (0..n_vertex_nodes(dofs))
            .filter(|&n| dofs.node_owned[n])
            .flat_map(|n| (0..2).map(move |c| (n, c)))
            .filter(|&(n, c)| constraints.fixed[n][c].is_some())
            .map(|(n, c)| self.coarse_dof[n] + c)
            .collect()
    }

    /// x, y of every owned coarse node, in coarse order (for the coarse AMG's rigid-body modes).
    pub fn coordinates(&self, mesh: &LocalMesh, dofs: &DofMap) -> Vec<[f64; 2]> {
        (0..n_vertex_nodes(dofs))
            .filter(|&n| dofs.node_owned[n])
            .map(|n| mesh.points[dofs.node_point[n] as usize])
            .collect()
    }
}

fn n_vertex_nodes(dofs: &DofMap) -> usize {
    dofs.n_nodes() - dofs.edges.len()
}

/// The vertex nodes node `n` interpolates from, with their weights.
fn interpolation_ends(dofs: &DofMap, n: usize) -> Vec<(usize, f64)> {
    let n_vertex = n_vertex_nodes(dofs);
    if n < n_vertex {
        return vec![(n, 1.0)];
    }
    let [a, b] = dofs.edges[n - n_vertex];
    vec![
        (dofs.node_of_point[a as usize] as usize, 0.5),
        (dofs.node_of_point[b as usize] as usize, 0.5),
    ]
}
