//! The coarse level of a two-level p-multigrid for P2 displacements: P1 on the particles. The
//! P2 mesh's vertex nodes are its nodes, and since a midside node sits at its edge's midpoint
//! when the increment starts, P1 → P2 interpolation is exact: a vertex takes its own value, an
//! edge node the mean of its two ends. The coarse operator is the Galerkin product Pᵀ A P of
//! each Newton iterate's tangent A, formed triangle by triangle (Rᵀ K R): an edge node
//! interpolates from its own edge's ends, so the product has a P1 matrix's sparsity. It
//! follows the tangent through large rotations and yield, where the P1 stiffness of the
//! start-of-step geometry (the first version) left the cantilever's CG iterations per Newton
//! iteration growing from 21 to 98 within one large increment. It carries the rigid-body modes
//! of its own nodes for the AMG that solves it.

use super::{Constraints, DofMap};
use crate::fem::element::N_DOFS;
use crate::fem::p2::EDGES;
use crate::mesh::LocalMesh;
use pfem_partition::{allgather_u64, exscan_u64, Comm, PartitionError};

/// The P1 space on this rank: its numbering. The coarse operator's preallocation is made on
/// demand ([`Self::operator_preallocation`]); the interpolation is an operator
/// ([`super::interpolation`]).
pub struct CoarseSpace {
    /// Owned coarse dofs (2 per owned vertex node).
    pub n_owned: usize,
    /// The global number of this rank's first coarse dof.
    pub first: usize,
    /// Per local vertex node (the first nodes of the dof map): the global number of its coarse
    /// x dof (y follows).
    coarse_dof: Vec<usize>,
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
        let coarse_dof = (0..n_vertex)
            .map(|n| {
                let r = mesh.owner[dofs.node_point[n] as usize] as usize;
                dofs.node_global[n] - table[2 * r] as usize + table[2 * r + 1] as usize
            })
            .collect();
        Ok(CoarseSpace {
            n_owned: 2 * owned_vertices,
            first: coarse_first as usize,
            coarse_dof,
        })
    }

    /// Per owned coarse row of the coarse operator, its nonzeros in owned and in other ranks'
    /// columns. Made on demand and dropped once the matrix is preallocated: kept, the counts
    /// would sit under the memory peak of every Newton iteration.
    pub fn operator_preallocation(dofs: &DofMap) -> (Vec<usize>, Vec<usize>) {
        let (mut d_nnz, mut o_nnz) = (Vec::new(), Vec::new());
        for (owned, other) in dofs.vertex_neighbour_counts() {
            for _ in 0..2 {
                d_nnz.push(2 * owned);
                o_nnz.push(2 * other);
            }
        }
        (d_nnz, o_nnz)
    }

    /// A space from its numbers, for tests elsewhere.
    #[cfg(test)]
    pub(super) fn for_tests(n_owned: usize, first: usize, coarse_dof: Vec<usize>) -> Self {
        CoarseSpace {
            n_owned,
            first,
            coarse_dof,
        }
    }

    /// The global coarse x dof of local vertex node `v` (y follows).
    pub fn coarse_dof(&self, v: usize) -> usize {
        self.coarse_dof[v]
    }

    /// Hands `add` the Galerkin coarse operator Rᵀ K R of triangle `t` whose P2 tangent is `k`
    /// (row-major, 12 × 12, the element's dof order), R the triangle's own P1 → P2
    /// interpolation: the rows of its owned vertices as 2 × 2 blocks (global block rows, the
    /// triangle's three global block columns, row-major values). Summed over the triangles
    /// this is exactly Pᵀ A P of the elements' part A of the tangent (contact and follower
    /// pressures stay on the fine level), since a midside node interpolates from the ends of
    /// its own edge: it has the sparsity of a P1 matrix and follows the tangent of every
    /// Newton iterate (large rotations, yield). Prescribed P2 dofs take no part (zero rows of
    /// P), and rows and columns of prescribed coarse dofs are zero (their diagonal is the
    /// caller's). Returns the sum of the free diagonal entries added. On the assembly path:
    /// nothing is allocated.
    pub fn galerkin_element<E>(
        &self,
        dofs: &DofMap,
        constraints: &Constraints,
        t: usize,
        k: &[f64],
        add: impl FnOnce(&[usize], &[usize; 3], &[f64]) -> Result<(), E>,
    ) -> Result<f64, E> {
        let nodes = &dofs.tri_nodes[t];
        let v: [usize; 3] = std::array::from_fn(|a| nodes[a] as usize);
        if v.iter().all(|&n| !dofs.node_owned[n]) {
            return Ok(0.0);
        }
        let fixed = |n: usize, c: usize| constraints.is_fixed(n, c);
        let coarse = galerkin_product(
            k,
            std::array::from_fn(|d| !fixed(nodes[d / 2] as usize, d % 2)),
            std::array::from_fn(|d| !fixed(v[d / 2], d % 2)),
        );
        // Coarse dofs come in (x, y) pairs at (2 b, 2 b + 1): whole 2 × 2 blocks, the columns
        // in increasing order, where PETSc's insertion continues its search from the last one.
        let mut order = [0, 1, 2];
        order.sort_unstable_by_key(|&a| self.coarse_dof[v[a]]);
        let blocks: [usize; 3] = std::array::from_fn(|b| self.coarse_dof[v[order[b]]] / 2);
        let (mut rows, mut vals) = ([0; 3], [0.0; 36]);
        let (mut n_rows, mut diagonal_sum) = (0, 0.0);
        for (a, &block) in order.iter().zip(&blocks) {
            if !dofs.node_owned[v[*a]] {
                continue;
            }
            rows[n_rows] = block;
            for (r, i) in [2 * a, 2 * a + 1].into_iter().enumerate() {
                let at = 12 * n_rows + 6 * r;
                for (out, &b) in vals[at..at + 6].chunks_exact_mut(2).zip(&order) {
                    out.copy_from_slice(&coarse[i][2 * b..2 * b + 2]);
                }
                if !fixed(v[*a], i % 2) {
                    diagonal_sum += coarse[i][i];
                }
            }
            n_rows += 1;
        }
        add(&rows[..n_rows], &blocks, &vals[..12 * n_rows])?;
        Ok(diagonal_sum)
    }

    /// The number of free coarse dofs this rank owns (for the mean of their diagonal).
    pub fn free_count(&self, dofs: &DofMap, constraints: &Constraints) -> usize {
        (0..n_vertex_nodes(dofs))
            .filter(|&n| dofs.node_owned[n])
            .map(|n| (0..2).filter(|&c| !constraints.is_fixed(n, c)).count())
            .sum()
    }

    /// The prescribed coarse dofs this rank owns (their rows get the diagonal alone).
    pub fn fixed_rows(&self, dofs: &DofMap, constraints: &Constraints) -> Vec<usize> {
        (0..n_vertex_nodes(dofs))
            .filter(|&n| dofs.node_owned[n])
            .flat_map(|n| (0..2).map(move |c| (n, c)))
            .filter(|&(n, c)| constraints.is_fixed(n, c))
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

/// Rᵀ K R for the P2 triangle tangent `k` (row-major 12 × 12) and the triangle's P1 → P2
/// interpolation R (a vertex its own value, a midside node the mean of its edge's ends), with
/// the rows of R zero at fine dofs that are not `free_fine` and its columns zero at coarse dofs
/// that are not `free_coarse`.
pub fn galerkin_product(
    k: &[f64],
    free_fine: [bool; N_DOFS],
    free_coarse: [bool; 6],
) -> [[f64; 6]; 6] {
    let n = N_DOFS;
    assert_eq!(k.len(), n * n, "a P2 triangle tangent");
    // R as (fine dof, coarse dof, weight) triples: at most 6 vertex and 12 midside entries.
    let mut r = [(0, 0, 0.0); 18];
    let mut len = 0;
    for m in 0..6 {
        let ends: &[(usize, f64)] = if m < 3 {
            &[(m, 1.0)]
        } else {
            let [a, b] = EDGES[m - 3];
            &[(a, 0.5), (b, 0.5)]
        };
        for c in 0..2 {
            for &(a, w) in ends {
                if free_fine[2 * m + c] && free_coarse[2 * a + c] {
                    r[len] = (2 * m + c, 2 * a + c, w);
                    len += 1;
                }
            }
        }
    }
    let r = &r[..len];
    // K R, 12 × 6.
    let mut kr = [[0.0; 6]; N_DOFS];
    for &(m, j, w) in r {
        for (i, row) in kr.iter_mut().enumerate() {
            row[j] += w * k[i * n + m];
        }
    }
    let mut coarse = [[0.0; 6]; 6];
    for &(i, j, w) in r {
        for (cj, kij) in coarse[j].iter_mut().zip(kr[i].iter()) {
            *cj += w * kij;
        }
    }
    coarse
}

/// The P2 dofs of one triangle on points 0, 1, 2 (nodes: the vertices, then edges 01, 12, 02),
/// with the given global numbers and owners; for tests.
#[cfg(test)]
pub(super) fn one_triangle_dofs(
    node_global: [usize; 6],
    node_owned: [bool; 6],
    first_dof: usize,
    n_global_dofs: usize,
) -> DofMap {
    DofMap {
        node_of_point: vec![0, 1, 2],
        edges: vec![[0, 1], [1, 2], [0, 2]],
        tri_nodes: vec![[0, 1, 2, 3, 4, 5]],
        node_global: node_global.to_vec(),
        vertex_dofs: 2,
        material_pressures: None,
        node_owned: node_owned.to_vec(),
        node_point: vec![0, 1, 2, u32::MAX, u32::MAX, u32::MAX],
        n_owned_dofs: 2 * node_owned.iter().filter(|&&o| o).count(),
        first_dof,
        n_global_dofs,
    }
}

/// The vertex nodes come first in a dof map's node order.
pub(super) fn n_vertex_nodes(dofs: &DofMap) -> usize {
    dofs.n_nodes() - dofs.edges.len()
}

#[cfg(test)]
// Index loops compare a matrix with its transpose.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::fem::element::p2_element;
    use crate::fem::p2::straight_sided;
    use crate::material::elastic::LinearElastic;
    use crate::material::GaussState;

    fn apply(k: &[[f64; 6]; 6], u: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|i| (0..6).map(|j| k[i][j] * u[j]).sum())
    }

    /// The P2 tangent of an unstressed elastic triangle at zero step.
    fn p2_tangent(x: [[f64; 2]; 3], e: f64, nu: f64) -> Vec<f64> {
        let m = LinearElastic::new(e, nu).unwrap();
        let out = p2_element(
            &straight_sided(&x),
            &[[0.0; 2]; 6],
            &<[GaussState; 3]>::default(),
            &m,
            [0.0, 0.0],
        )
        .unwrap();
        out.tangent.as_flattened().to_vec()
    }

    #[test]
    fn the_galerkin_product_of_an_elastic_p2_triangle_is_its_p1_stiffness() {
        // Linear fields are P2 fields, and the 3-point rule integrates their constant strain
        // energy exactly: Rᵀ K R must be the P1 stiffness, which costs nothing for the rigid
        // modes and gives a uniform stretch its strain energy.
        let x = [[0.1, 0.2], [1.3, 0.1], [0.4, 0.9]];
        let (e, nu) = (10.0e6, 0.3);
        let k = galerkin_product(&p2_tangent(x, e, nu), [true; 12], [true; 6]);
        for mode in [
            [1.0, 0.0, 1.0, 0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0, 1.0, 0.0, 1.0],
            std::array::from_fn(|i| {
                if i % 2 == 0 {
                    -x[i / 2][1]
                } else {
                    x[i / 2][0]
                }
            }),
        ] {
            let f = apply(&k, &mode);
            assert!(f.iter().all(|v| v.abs() < 1e-9 * e), "{f:?}");
        }
        let u: [f64; 6] =
            std::array::from_fn(|i| if i % 2 == 0 { 1e-3 * x[i / 2][0] } else { 0.0 });
        let energy = 0.5 * u.iter().zip(apply(&k, &u)).map(|(a, b)| a * b).sum::<f64>();
        let lambda_2mu = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let want = 0.5 * lambda_2mu * 1e-6 * crate::fem::p1::area(&x);
        assert!((energy - want).abs() < 1e-12 * want, "{energy} vs {want}");
        for i in 0..6 {
            for j in 0..6 {
                assert!((k[i][j] - k[j][i]).abs() < 1e-9 * e, "symmetric");
            }
        }
    }

    #[test]
    fn galerkin_blocks_reach_petsc_under_their_own_columns_in_increasing_order() {
        // One triangle whose vertices' coarse numbers run against their local order.
        let dofs = one_triangle_dofs([0, 2, 4, 6, 8, 10], [true; 6], 0, 12);
        let space = CoarseSpace {
            n_owned: 6,
            first: 0,
            coarse_dof: vec![4, 0, 2],
        };
        let constraints = Constraints::build(&dofs, |_| [None, None]);
        let tangent = p2_tangent([[0.1, 0.2], [1.3, 0.1], [0.4, 0.9]], 1.0e6, 0.3);
        let want = galerkin_product(&tangent, [true; 12], [true; 6]);
        let (mut rows, mut cols, mut vals) = (Vec::new(), Vec::new(), Vec::new());
        space
            .galerkin_element(&dofs, &constraints, 0, &tangent, |r, c, v| {
                rows.extend_from_slice(r);
                cols.extend_from_slice(c);
                vals.extend_from_slice(v);
                Ok::<(), ()>(())
            })
            .unwrap();
        assert_eq!(cols, vec![0, 1, 2], "block columns in increasing order");
        let vertex_of_block = |b: usize| (0..3).find(|&a| space.coarse_dof[a] / 2 == b).unwrap();
        for (n, &r) in rows.iter().enumerate() {
            let a = vertex_of_block(r);
            for i in 0..2 {
                for (j, &c) in cols.iter().enumerate() {
                    let b = vertex_of_block(c);
                    for k in 0..2 {
                        let got = vals[12 * n + 6 * i + 2 * j + k];
                        assert_eq!(
                            got,
                            want[2 * a + i][2 * b + k],
                            "block ({r}, {c}), ({i}, {k})"
                        );
                    }
                }
            }
        }
        assert_eq!(rows.len(), 3);
    }

    #[test]
    fn prescribed_dofs_take_no_part_in_the_galerkin_product() {
        let x = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let tangent = p2_tangent(x, 1.0e6, 0.25);
        let all = galerkin_product(&tangent, [true; 12], [true; 6]);
        // Coarse dof 2 (vertex 1, x) prescribed: its row and column vanish, the rest stays.
        let mut free_coarse = [true; 6];
        free_coarse[2] = false;
        let k = galerkin_product(&tangent, [true; 12], free_coarse);
        for i in 0..6 {
            for j in 0..6 {
                let want = if i == 2 || j == 2 { 0.0 } else { all[i][j] };
                assert!((k[i][j] - want).abs() < 1e-9, "({i}, {j})");
            }
        }
        // A prescribed midside dof (node 3 on edge 0-1, y) drops out of the sum: the product
        // changes exactly by its row and column's contributions, and stays symmetric.
        let mut free_fine = [true; 12];
        free_fine[7] = false;
        let k = galerkin_product(&tangent, free_fine, [true; 6]);
        let changed = (0..6).any(|i| (0..6).any(|j| (k[i][j] - all[i][j]).abs() > 1e-6));
        assert!(changed);
        for i in 0..6 {
            for j in 0..6 {
                assert!((k[i][j] - k[j][i]).abs() < 1e-9);
            }
        }
    }
}
