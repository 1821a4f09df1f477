//! The p-multigrid's P1 → P2 interpolation applied instead of stored (a PETSc shell matrix):
//! a vertex node takes its own coarse value, a midside node the mean of its edge's ends. As an
//! AIJ matrix it held 2 rows a node with their column indices, about 200 bytes a particle on
//! one rank; here it is two coarse slots and a mask a node (9 bytes). Every sum runs in the
//! order PETSc's AIJ product ran it (owned columns, then ghosts, each by global number), so
//! the results are bit for bit those of the stored matrix.

use super::pmg::{n_vertex_nodes, CoarseSpace};
use super::{Constraints, DofMap};
use crate::petsc::{LinearOperator, PVec, PetscError, Scalar, Scatter, VecRef};
use pfem_partition::Comm;

/// No second end: a vertex node.
const NONE: u32 = u32::MAX;

/// The numbers of the interpolation on this rank, without PETSc: for the operator and its tests.
#[derive(Debug, Clone, PartialEq)]
pub struct InterpolationMap {
    /// Per owned fine node, in the order of its dofs: the coarse slots of the x dofs of the
    /// vertices it interpolates from (y follows), ascending; the second is [`NONE`] at a
    /// vertex node. Slots below `n_owned_coarse` are this rank's coarse dofs in order, the
    /// others its ghost vertices' (by global number).
    ends: Vec<[u32; 2]>,
    /// Per owned fine node, bit 2 e + c: end e reaches component c (the fine dof and the
    /// end's coarse dof are both free; a prescribed dof takes no coarse correction and gives
    /// the coarse level no residual).
    live: Vec<u8>,
    n_owned_coarse: usize,
    /// The global coarse dofs of the ghost slots, in slot order.
    ghost_dofs: Vec<usize>,
}

impl InterpolationMap {
    /// Relies on [`DofMap`] giving every owned node 2 consecutive dofs in the rank's range.
    pub fn new(dofs: &DofMap, constraints: &Constraints, space: &CoarseSpace) -> InterpolationMap {
        let owned: Vec<usize> = (0..dofs.n_nodes())
            .filter(|&n| dofs.node_owned[n])
            .collect();
        let n_vertex = n_vertex_nodes(dofs);
        let mut ghosts: Vec<usize> = owned
            .iter()
            .flat_map(|&n| vertices_of(dofs, n_vertex, n))
            .filter(|&v| !dofs.node_owned[v])
            .map(|v| space.coarse_dof(v))
            .collect();
        ghosts.sort_unstable();
        ghosts.dedup();
        let n_owned_coarse = space.n_owned;
        let slot = |v: usize| {
            let g = space.coarse_dof(v);
            let s = if dofs.node_owned[v] {
                g - space.first
            } else {
                n_owned_coarse + 2 * ghosts.binary_search(&g).expect("collected above")
            };
            u32::try_from(s).expect("coarse slots fit in 32 bits")
        };
        let mut ends = vec![[NONE; 2]; dofs.n_owned_dofs / 2];
        let mut live = vec![0u8; ends.len()];
        for &n in &owned {
            let i = (dofs.node_global[n] - dofs.first_dof) / 2;
            let mut by_slot = [(NONE, 0); 2];
            let mut len = 0;
            for v in vertices_of(dofs, n_vertex, n) {
                by_slot[len] = (slot(v), v);
                len += 1;
            }
            by_slot[..len].sort_unstable();
            for (e, &(s, v)) in by_slot[..len].iter().enumerate() {
                ends[i][e] = s;
                for c in 0..2 {
                    if !constraints.is_fixed(n, c) && !constraints.is_fixed(v, c) {
                        live[i] |= 1 << (2 * e + c);
                    }
                }
            }
        }
        let ghost_dofs = ghosts.iter().flat_map(|&g| [g, g + 1]).collect();
        InterpolationMap {
            ends,
            live,
            n_owned_coarse,
            ghost_dofs,
        }
    }

    /// fine = P coarse, or fine + P coarse with `add`; `own` and `ghost` are the coarse values
    /// of the owned and ghost slots.
    pub fn prolong(&self, own: &[f64], ghost: &[f64], fine: &mut [f64], add: bool) {
        let value = |s: usize| {
            if s < self.n_owned_coarse {
                own[s]
            } else {
                ghost[s - self.n_owned_coarse]
            }
        };
        for (i, (ends, &live)) in self.ends.iter().zip(&self.live).enumerate() {
            let w = if ends[1] == NONE { 1.0 } else { 0.5 };
            for c in 0..2 {
                let mut sum = if add { fine[2 * i + c] } else { 0.0 };
                for (e, &s) in ends.iter().enumerate() {
                    if live & 1 << (2 * e + c) != 0 {
                        sum += w * value(s as usize + c);
                    }
                }
                fine[2 * i + c] = sum;
            }
        }
    }

    /// (own, ghost) = Pᵀ fine, the ghost slots' sums still to be added on their owners.
    pub fn restrict(&self, fine: &[f64], own: &mut [f64], ghost: &mut [f64]) {
        own.fill(0.0);
        ghost.fill(0.0);
        for (i, (ends, &live)) in self.ends.iter().zip(&self.live).enumerate() {
            let w = if ends[1] == NONE { 1.0 } else { 0.5 };
            for c in 0..2 {
                let y = fine[2 * i + c];
                for (e, &s) in ends.iter().enumerate() {
                    if live & 1 << (2 * e + c) != 0 {
                        let s = s as usize + c;
                        if s < self.n_owned_coarse {
                            own[s] += w * y;
                        } else {
                            ghost[s - self.n_owned_coarse] += w * y;
                        }
                    }
                }
            }
        }
    }
}

/// The vertex nodes node `n` interpolates from (weight 1 for its own vertex, 1/2 for each
/// end of its edge): a vertex node is the first `n_vertex` nodes' own.
fn vertices_of(dofs: &DofMap, n_vertex: usize, n: usize) -> impl Iterator<Item = usize> + '_ {
    let ends = if n < n_vertex {
        [Some(n), None]
    } else {
        dofs.edges[n - n_vertex].map(|p| Some(dofs.node_of_point[p as usize] as usize))
    };
    ends.into_iter().flatten()
}

/// The interpolation as a PETSc operator: the map and the scatter of its coarse ghosts.
pub struct Interpolation {
    map: InterpolationMap,
    ghosts: Scatter,
}

impl Interpolation {
    /// Collective (builds the scatter of the coarse ghosts).
    pub fn new(comm: &Comm, map: InterpolationMap) -> Result<Interpolation, PetscError> {
        let template = PVec::mpi(comm, map.n_owned_coarse)?;
        let ghosts = Scatter::new(&template, &map.ghost_dofs)?;
        Ok(Interpolation { map, ghosts })
    }

    /// Collective.
    fn prolong(&self, x: VecRef<'_>, y: VecRef<'_>, add: bool) -> Result<(), PetscError> {
        self.ghosts.gather(x, |ghost: &[Scalar]| {
            x.read(|own| y.write(|fine| self.map.prolong(own, ghost, fine, add)))
        })??
    }
}

impl LinearOperator for Interpolation {
    fn mult(&self, x: VecRef<'_>, y: VecRef<'_>) -> Result<(), PetscError> {
        self.prolong(x, y, false)
    }

    fn mult_add(&self, x: VecRef<'_>, y: VecRef<'_>) -> Result<(), PetscError> {
        self.prolong(x, y, true)
    }

    fn mult_transpose(&self, y: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        self.ghosts.add_back(x, |ghost| {
            y.read(|fine| x.write(|own| self.map.restrict(fine, own, ghost)))?
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_orders_ends_as_petsc_did_and_masks_prescribed_components() {
        // A rank owning vertices 0 and 1 and the midside nodes of edges (0, 1) and (0, 2);
        // vertex 2 and edge (1, 2) are another rank's. Coarse numbers run against the local
        // order; x is prescribed at points 1 and 2.
        let dofs = super::super::pmg::one_triangle_dofs(
            [100, 102, 0, 104, 2, 106],
            [true, true, false, true, false, true],
            100,
            112,
        );
        let space = CoarseSpace::for_tests(4, 50, vec![52, 50, 10]);
        let constraints =
            Constraints::build(&dofs, |p| [if p == 0 { None } else { Some(0.0) }, None]);
        let map = InterpolationMap::new(&dofs, &constraints, &space);
        assert_eq!(map.ends, vec![[2, NONE], [0, NONE], [0, 2], [2, 4]]);
        assert_eq!(map.live, vec![0b11, 0b10, 0b1110, 0b1011]);
        assert_eq!(
            (map.n_owned_coarse, map.ghost_dofs.clone()),
            (4, vec![10, 11])
        );
    }

    /// One triangle whose third vertex is a ghost (slot 4 of a rank owning 4 coarse dofs):
    /// vertex nodes 0, 1, then the edge nodes (0, 1), (1, 2), (0, 2); all dofs free but the
    /// y of edge node (1, 2), and the ghost vertex's x.
    fn triangle() -> InterpolationMap {
        let full = 0b1111;
        InterpolationMap {
            ends: vec![[0, NONE], [2, NONE], [0, 2], [2, 4], [0, 4]],
            live: vec![0b11, 0b11, full, full & !0b1010 & !0b0100, full & !0b0100],
            n_owned_coarse: 4,
            ghost_dofs: vec![10, 11],
        }
    }

    #[test]
    fn a_linear_field_is_interpolated_exactly_where_nothing_is_prescribed() {
        let mut map = triangle();
        map.live = vec![0b11, 0b11, 0b1111, 0b1111, 0b1111];
        // u = (1 + x, 2 y) at vertices (0, 0), (1, 0), (0, 1).
        let (own, ghost) = ([1.0, 0.0, 2.0, 0.0], [1.0, 2.0]);
        let mut fine = [f64::NAN; 10];
        map.prolong(&own, &ghost, &mut fine, false);
        assert_eq!(fine, [1.0, 0.0, 2.0, 0.0, 1.5, 0.0, 1.5, 1.0, 1.0, 1.0]);
        let mut again = fine;
        map.prolong(&own, &ghost, &mut again, true);
        assert_eq!(again, fine.map(|v| 2.0 * v));
    }

    #[test]
    fn restriction_is_the_transpose_and_prescribed_dofs_take_no_part() {
        let map = triangle();
        let (own, ghost) = ([0.3, -1.7, 2.9, 0.4], [5.0, -0.25]);
        let fine_y = [0.7, -0.2, 1.3, 2.2, -0.9, 0.6, 1.1, -3.0, 0.05, 0.8];
        let mut fine = [0.0; 10];
        map.prolong(&own, &ghost, &mut fine, false);
        // The y of edge node (1, 2) is prescribed: no coarse correction reaches it.
        assert_eq!(fine[7], 0.0);
        // The ghost's x is prescribed: edge (0, 2) takes only half of vertex 0's x.
        assert_eq!(fine[8], 0.5 * own[0]);
        let (mut r_own, mut r_ghost) = ([f64::NAN; 4], [f64::NAN; 2]);
        map.restrict(&fine_y, &mut r_own, &mut r_ghost);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let left = dot(&fine, &fine_y);
        let right = dot(&own, &r_own) + dot(&ghost, &r_ghost);
        assert!((left - right).abs() < 1e-14, "{left} vs {right}");
        assert_eq!(r_ghost[0], 0.0);
    }
}
