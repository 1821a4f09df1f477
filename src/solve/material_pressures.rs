//! Pressure unknowns of the P2–P1 element where several materials meet: their table, their
//! global numbering and the matrix patterns they give. The exact pressure jumps across an
//! interface between materials of different strength (two Tresca zones side by side under a
//! platen: p = cu on each side), which one continuous P1 pressure per vertex cannot follow: it
//! smeared the jump over the triangles beside the interface and put their stress off the yield
//! surfaces (the platen force 0.8 % high at h = 0.1; 5e-10 with a pressure per material). So a
//! vertex carries one pressure per material of the triangles around it, and a triangle reads
//! those of its own material: the pressure is continuous within a material and free to jump
//! between two. A vertex inside one material keeps the single unknown of the continuous element.

use super::DofMap;
use crate::mesh::LocalMesh;
use pfem_partition::{fetch_pairs, Comm, PartitionError};
use std::collections::HashMap;

/// Which pressure unknowns the vertex nodes of a mesh carry.
#[derive(Debug, Clone, Copy)]
pub enum Pressure<'a> {
    /// None: displacements only (the P2 element).
    None,
    /// One per vertex (P2–P1 in a body of one material).
    Continuous,
    /// One per vertex and material of the triangles around it (P2–P1 with several materials);
    /// the material of each local triangle. Every rank must give a triangle the same material.
    PerMaterial(&'a [u32]),
}

/// The pressure unknowns of the vertex nodes in a mesh of several materials, numbered locally
/// node by node and, within a node, by increasing material.
#[derive(Debug, Clone)]
pub struct MaterialPressures {
    /// Per vertex node, where its unknowns start (one entry more than vertex nodes).
    start: Vec<u32>,
    /// Material of each unknown.
    material: Vec<u32>,
    /// Global dof of each unknown (`usize::MAX` until numbered).
    global: Vec<usize>,
    /// Per triangle and vertex: the position of the triangle's material among the vertex's.
    tri_slot: Vec<[u32; 3]>,
}

impl MaterialPressures {
    /// The unknowns the triangles `tri_nodes` (vertex nodes first in each) of materials
    /// `tri_material` need on the first `n_vertex` nodes. An owned vertex has every triangle around
    /// it on its rank, so it gets all its materials; a ghost only those of this rank's triangles.
    pub fn new(tri_nodes: &[[u32; 6]], tri_material: &[u32], n_vertex: usize) -> Self {
        let mut pairs: Vec<(u32, u32)> = tri_nodes
            .iter()
            .zip(tri_material)
            .flat_map(|(nodes, &m)| nodes[..3].iter().map(move |&n| (n, m)))
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut start = vec![0u32; n_vertex + 1];
        for &(n, _) in &pairs {
            start[n as usize + 1] += 1;
        }
        for n in 0..n_vertex {
            start[n + 1] += start[n];
        }
        let material: Vec<u32> = pairs.iter().map(|&(_, m)| m).collect();
        let tri_slot = tri_nodes
            .iter()
            .zip(tri_material)
            .map(|(nodes, &m)| {
                std::array::from_fn(|k| {
                    let n = nodes[k] as usize;
                    let own = &material[start[n] as usize..start[n + 1] as usize];
                    // Present: every (vertex, material) of a triangle is a pair above.
                    own.binary_search(&m).unwrap_or(0) as u32
                })
            })
            .collect();
        MaterialPressures {
            start,
            global: vec![usize::MAX; material.len()],
            material,
            tri_slot,
        }
    }

    /// Unknowns on this rank (owned and ghost).
    pub fn len(&self) -> usize {
        self.material.len()
    }

    pub fn is_empty(&self) -> bool {
        self.material.is_empty()
    }

    /// Pressure unknowns of vertex node `n`.
    pub fn count(&self, n: usize) -> usize {
        (self.start[n + 1] - self.start[n]) as usize
    }

    /// The local index of vertex node `n`'s `slot`-th unknown.
    pub fn unknown(&self, n: usize, slot: usize) -> usize {
        self.start[n] as usize + slot
    }

    /// Where vertex node `n`'s unknowns start among all of this rank's.
    pub fn first(&self, n: usize) -> usize {
        self.start[n] as usize
    }

    /// The material of vertex node `n`'s `slot`-th unknown.
    pub fn material(&self, n: usize, slot: usize) -> u32 {
        self.material[self.unknown(n, slot)]
    }

    /// The position of triangle `t`'s material among the unknowns of its vertex `k`.
    pub fn slot(&self, t: usize, k: usize) -> usize {
        self.tri_slot[t][k] as usize
    }

    /// The global dof of vertex node `n`'s `slot`-th unknown.
    pub fn global(&self, n: usize, slot: usize) -> usize {
        self.global[self.unknown(n, slot)]
    }

    pub fn set_global(&mut self, n: usize, slot: usize, g: usize) {
        let u = self.unknown(n, slot);
        self.global[u] = g;
    }
}

/// The key of vertex `gid`'s pressure of material `m` in the by-id exchange of the dof numbering,
/// apart from the node keys (`[gid, u64::MAX]` for a vertex, two gids for an edge): particle ids
/// count particles and never come near 2⁶⁴ − 2³³.
pub fn pressure_key(gid: u64, m: u32) -> [u64; 2] {
    [gid, u64::MAX - 1 - u64::from(m)]
}

impl DofMap {
    /// [`DofMap::preallocation`] where pressures are per material: a displacement row couples to
    /// every dof of the triangles around its node, a pressure row only to those of the triangles
    /// of its material, which the node counts of the continuous case would overestimate.
    pub(super) fn preallocation_by_dof(&self) -> (Vec<usize>, Vec<usize>) {
        let n_local = self.n_local_dofs();
        let element_dofs = 12 + 3 * usize::from(self.vertex_dofs == 3);
        let mut owned_local = vec![false; n_local];
        for n in (0..self.n_nodes()).filter(|&n| self.node_owned[n]) {
            let o = self.node_local(n);
            owned_local[o..o + self.ndof(n)].fill(true);
        }
        // Columns (local dofs) of each row group: a node's two displacement rows share its
        // x row's.
        let mut cols: Vec<Vec<u32>> = vec![Vec::new(); n_local];
        let mut local = [0u32; 15];
        for t in 0..self.tri_nodes.len() {
            for (k, l) in local[..element_dofs].iter_mut().enumerate() {
                let (node, c) = self.element_dof(t, k);
                *l = (self.node_local(node) + c) as u32;
            }
            for k in 0..element_dofs {
                let (node, c) = self.element_dof(t, k);
                if self.node_owned[node] && c != 1 {
                    cols[local[k] as usize].extend_from_slice(&local[..element_dofs]);
                }
            }
        }
        let mut d = vec![0; self.n_owned_dofs];
        let mut o = vec![0; self.n_owned_dofs];
        for n in (0..self.n_nodes()).filter(|&n| self.node_owned[n]) {
            let row = self.node_global[n] - self.first_dof;
            for c in 0..self.ndof(n) {
                let group = &mut cols[self.node_local(n) + if c < 2 { 0 } else { c }];
                group.sort_unstable();
                group.dedup();
                let owned = group.iter().filter(|&&j| owned_local[j as usize]).count();
                d[row + c] = owned;
                o[row + c] = group.len() - owned;
            }
        }
        (d, o)
    }

    /// [`DofMap::pressure_neighbour_counts`] where pressures are per material: a material's
    /// pressures couple only among its own triangles.
    pub(super) fn material_pressure_neighbour_counts(&self) -> Vec<(usize, usize)> {
        let n_vertex = self.n_nodes() - self.edges.len();
        let mut node_of = vec![0usize; self.n_pressure_unknowns()];
        for n in 0..n_vertex {
            for c in 2..self.ndof(n) {
                node_of[self.pressure_unknown(n, c)] = n;
            }
        }
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); node_of.len()];
        for (t, nodes) in self.tri_nodes.iter().enumerate() {
            let u: [usize; 3] = std::array::from_fn(|k| {
                self.pressure_unknown(nodes[k] as usize, self.pressure_component(t, k))
            });
            for &r in &u {
                if self.node_owned[node_of[r]] {
                    cols[r].extend_from_slice(&u);
                }
            }
        }
        (0..node_of.len())
            .filter(|&r| self.node_owned[node_of[r]])
            .map(|r| {
                let c = &mut cols[r];
                c.sort_unstable();
                c.dedup();
                let owned = c.iter().filter(|&&j| self.node_owned[node_of[j]]).count();
                (owned, c.len() - owned)
            })
            .collect()
    }
}

/// The vertex nodes' points and every node's owner flag and first global dof, as `build` made
/// them.
pub(super) struct NodeTables<'a> {
    pub point: &'a [u32],
    pub owned: &'a [bool],
    pub global: &'a [usize],
}

/// Collective. Numbers the pressures of `mp`: an owned vertex's follow its displacements, by
/// material; a ghost's are asked of the vertex's owner by (gid, material), since a ghost may lack
/// some of the materials around the vertex.
pub(super) fn number_material_pressures(
    comm: &Comm,
    mesh: &LocalMesh,
    nodes: NodeTables,
    mp: &mut MaterialPressures,
) -> Result<(), PartitionError> {
    let mut owned_number: HashMap<[u64; 2], u64> = HashMap::new();
    let mut requests = Vec::new();
    let mut asked = Vec::new();
    for (n, &p) in nodes.point.iter().enumerate() {
        let p = p as usize;
        for slot in 0..mp.count(n) {
            let key = pressure_key(mesh.gids[p], mp.material(n, slot));
            if nodes.owned[n] {
                let g = nodes.global[n] + 2 + slot;
                mp.set_global(n, slot, g);
                owned_number.insert(key, g as u64);
            } else {
                requests.push((mesh.owner[p], key));
                asked.push((n, slot));
            }
        }
    }
    let answers = fetch_pairs(comm, &requests, |k| {
        owned_number.get(k).copied().ok_or_else(|| {
            PartitionError::InvalidInput(format!(
                "pressure {k:?} asked for by another rank is not on its owner: the ranks \
                 disagree on a triangle's material, or the halo is too narrow"
            ))
        })
    })?;
    for ((n, slot), g) in asked.into_iter().zip(answers) {
        mp.set_global(n, slot, g as usize);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vertex_gets_one_unknown_per_material_around_it() {
        // Four triangles around vertex 0 (nodes 0..4 are vertices; midside nodes unused here):
        // two of material 3, one of 1, one of 3 again.
        let tri = |a, b, c| [a, b, c, 9, 9, 9];
        let tris = [tri(0, 1, 2), tri(0, 2, 3), tri(0, 3, 4), tri(0, 4, 1)];
        let mats = [3, 1, 3, 3];
        let p = MaterialPressures::new(&tris, &mats, 5);
        assert_eq!(p.count(0), 2);
        assert_eq!((p.material(0, 0), p.material(0, 1)), (1, 3));
        // Vertex 2 and 3 touch both materials, 1 and 4 only material 3.
        assert_eq!([1, 2, 3, 4].map(|n| p.count(n)), [1, 2, 2, 1]);
        assert_eq!(p.len(), 8);
        // Triangle 1 (material 1) reads slot 0 at its vertices; triangle 2 (material 3) slot 1
        // at vertices 0 and 3, slot 0 at vertex 4.
        assert_eq!([0, 1, 2].map(|k| p.slot(1, k)), [0, 0, 0]);
        assert_eq!([0, 1, 2].map(|k| p.slot(2, k)), [1, 1, 0]);
        assert_eq!(p.unknown(3, 1), p.first(3) + 1);
    }

    #[test]
    fn pressure_keys_are_not_node_keys() {
        assert_ne!(pressure_key(7, 0), [7, u64::MAX]);
        assert_ne!(pressure_key(7, 0), pressure_key(7, 1));
    }
}
