//! Global degree-of-freedom numbering of the P2 mesh across ranks. Vertex nodes are particles and
//! belong to the particle's owner; edge (midside) nodes belong to the owner of their smaller-gid
//! endpoint, which always holds every triangle around that edge. Owned dofs are numbered
//! contiguously per rank (offsets by exclusive scan); ghost numbers are fetched from their owners.

use super::material_pressures::{
    number_material_pressures, MaterialPressures, NodeTables, Pressure,
};
use crate::mesh::LocalMesh;
use pfem_partition::{exscan_u64, fetch_pairs, Comm, PartitionError};
use std::collections::HashMap;

/// Key of a node for the by-id exchange: `[gid, NO_GID]` for a vertex, `[gid_a, gid_b]` for an edge.
const NO_GID: u64 = u64::MAX;

#[derive(Debug, Clone)]
pub struct DofMap {
    /// Local nodes: vertex nodes for local points used by a triangle, then edge nodes.
    /// `node_of_point[p]` is the node of local point p, or `u32::MAX` when unused.
    pub node_of_point: Vec<u32>,
    /// Edge nodes as local point pairs, smaller gid first.
    pub edges: Vec<[u32; 2]>,
    /// Per triangle: its 6 nodes (3 vertices CCW, then edges 01, 12, 20).
    pub tri_nodes: Vec<[u32; 6]>,
    /// Global number of each node's first dof (ux; then uy, then the pressures at a vertex of a
    /// mixed mesh).
    pub node_global: Vec<usize>,
    /// Dofs per vertex node: 2, or 3 with a pressure unknown (mixed u–p elements); with
    /// `material_pressures`, a vertex has 2 and one per material around it.
    pub vertex_dofs: usize,
    /// A vertex's pressures per material, where the mesh has several ([`Pressure::PerMaterial`]);
    /// `None` for one pressure per vertex or none, which need no table.
    pub material_pressures: Option<MaterialPressures>,
    /// Whether this rank owns the node (and so its two rows).
    pub node_owned: Vec<bool>,
    /// Local point behind each vertex node (`u32::MAX` for edge nodes).
    pub node_point: Vec<u32>,
    pub n_owned_dofs: usize,
    pub first_dof: usize,
    pub n_global_dofs: usize,
}

impl DofMap {
    /// Collective. Numbers the dofs of `mesh` and the vertices' `pressure` unknowns. A vertex's
    /// dofs are consecutive on its owner: ux, uy, then its pressures by increasing material.
    pub fn build(
        comm: &Comm,
        mesh: &LocalMesh,
        pressure: Pressure,
    ) -> Result<DofMap, PartitionError> {
        let vertex_dofs = if matches!(pressure, Pressure::None) {
            2
        } else {
            3
        };
        let np = mesh.points.len();
        let mut used = vec![false; np];
        for t in &mesh.tris {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let mut node_of_point = vec![u32::MAX; np];
        let mut node_point = Vec::new();
        let mut node_owned = Vec::new();
        let mut keys: Vec<[u64; 2]> = Vec::new();
        for p in 0..np {
            if used[p] {
                node_of_point[p] = node_point.len() as u32;
                node_point.push(p as u32);
                node_owned.push(p < mesh.n_owned);
                keys.push([mesh.gids[p], NO_GID]);
            }
        }
        let mut edge_index: HashMap<(u32, u32), u32> = HashMap::new();
        let mut edges: Vec<[u32; 2]> = Vec::new();
        let mut tri_nodes = Vec::with_capacity(mesh.tris.len());
        for t in &mesh.tris {
            let mut nodes = [0u32; 6];
            for k in 0..3 {
                nodes[k] = node_of_point[t[k] as usize];
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let e = if mesh.gids[a as usize] < mesh.gids[b as usize] {
                    (a, b)
                } else {
                    (b, a)
                };
                let next = edges.len() as u32;
                let idx = *edge_index.entry(e).or_insert_with(|| {
                    edges.push([e.0, e.1]);
                    next
                });
                nodes[3 + k] = idx; // edge index for now, turned into a node below
            }
            tri_nodes.push(nodes);
        }
        // Edge nodes follow the vertex nodes, in key order so the numbering is reproducible.
        let mut order: Vec<u32> = (0..edges.len() as u32).collect();
        order.sort_by_key(|&e| {
            let [a, b] = edges[e as usize];
            (mesh.gids[a as usize], mesh.gids[b as usize])
        });
        let n_vertex_nodes = node_point.len() as u32;
        let mut node_of_edge = vec![0u32; edges.len()];
        let mut sorted_edges = Vec::with_capacity(edges.len());
        for (rank_in_order, &e) in order.iter().enumerate() {
            node_of_edge[e as usize] = n_vertex_nodes + rank_in_order as u32;
            let [a, b] = edges[e as usize];
            sorted_edges.push([a, b]);
            node_point.push(u32::MAX);
            node_owned.push((a as usize) < mesh.n_owned);
            keys.push([mesh.gids[a as usize], mesh.gids[b as usize]]);
        }
        for nodes in &mut tri_nodes {
            for n in nodes.iter_mut().skip(3) {
                *n = node_of_edge[*n as usize];
            }
        }
        let mut material_pressures = match pressure {
            Pressure::PerMaterial(tri_material) => Some(MaterialPressures::new(
                &tri_nodes,
                tri_material,
                n_vertex_nodes as usize,
            )),
            Pressure::None | Pressure::Continuous => None,
        };
        let ndof = |n: usize| {
            if n >= n_vertex_nodes as usize {
                2
            } else if let Some(mp) = &material_pressures {
                2 + mp.count(n)
            } else {
                vertex_dofs
            }
        };
        let n_owned_dofs: usize = (0..node_owned.len())
            .filter(|&n| node_owned[n])
            .map(ndof)
            .sum();
        let (first_dof, n_global_dofs) = exscan_u64(comm, n_owned_dofs as u64);
        let mut node_global = vec![usize::MAX; node_owned.len()];
        let mut owned_number: HashMap<[u64; 2], u64> = HashMap::with_capacity(node_owned.len());
        let mut next = first_dof;
        for (n, &own) in node_owned.iter().enumerate() {
            if own {
                node_global[n] = next as usize;
                owned_number.insert(keys[n], next);
                next += ndof(n) as u64;
            }
        }
        let mut requests = Vec::new();
        let mut asked = Vec::new();
        for (n, &own) in node_owned.iter().enumerate() {
            if !own {
                let owner_point = if node_point[n] != u32::MAX {
                    node_point[n]
                } else {
                    sorted_edges[n - n_vertex_nodes as usize][0]
                };
                requests.push((mesh.owner[owner_point as usize], keys[n]));
                asked.push(n);
            }
        }
        let answers = fetch_pairs(comm, &requests, |k| {
            owned_number.get(k).copied().ok_or_else(|| {
                PartitionError::InvalidInput(format!(
                    "node {:?} asked for by another rank is not on its owner: the halo is too narrow",
                    k
                ))
            })
        })?;
        for (n, g) in asked.into_iter().zip(answers) {
            node_global[n] = g as usize;
        }
        if let Some(mp) = &mut material_pressures {
            let nodes = NodeTables {
                point: &node_point[..n_vertex_nodes as usize],
                owned: &node_owned,
                global: &node_global,
            };
            number_material_pressures(comm, mesh, nodes, mp)?;
        }
        Ok(DofMap {
            node_of_point,
            edges: sorted_edges,
            tri_nodes,
            node_global,
            node_owned,
            node_point,
            vertex_dofs,
            material_pressures,
            n_owned_dofs,
            first_dof: first_dof as usize,
            n_global_dofs: n_global_dofs as usize,
        })
    }

    pub fn n_nodes(&self) -> usize {
        self.node_global.len()
    }

    /// Offset of node `n`'s first dof in the local (owned + ghost) vector: the vertex nodes'
    /// dofs come first, then two per midside node. Computed rather than stored (8 bytes a node,
    /// under the solve's memory peak).
    pub fn node_local(&self, n: usize) -> usize {
        let vertices = self.n_nodes() - self.edges.len();
        match &self.material_pressures {
            None if n < vertices => self.vertex_dofs * n,
            None => self.vertex_dofs * vertices + 2 * (n - vertices),
            Some(mp) if n < vertices => 2 * n + mp.first(n),
            Some(mp) => 2 * vertices + mp.len() + 2 * (n - vertices),
        }
    }

    /// Length of the local (owned + ghost) vector.
    pub fn n_local_dofs(&self) -> usize {
        self.node_local(self.n_nodes())
    }

    /// The particles behind node `n`: a vertex's point twice, or an edge node's two ends.
    pub fn node_points(&self, n: usize) -> [u32; 2] {
        let p = self.node_point[n];
        if p != u32::MAX {
            [p, p]
        } else {
            self.edges[n - (self.n_nodes() - self.edges.len())]
        }
    }

    /// Dofs of node `n`.
    pub fn ndof(&self, n: usize) -> usize {
        2 + self.pressure_count(n)
    }

    /// Pressure unknowns of node `n`: none at a midside node or without pressures.
    pub fn pressure_count(&self, n: usize) -> usize {
        if self.node_point[n] == u32::MAX {
            0
        } else if let Some(mp) = &self.material_pressures {
            mp.count(n)
        } else {
            self.vertex_dofs - 2
        }
    }

    /// The global dof of component `c` of node `n`: ux, uy, then the node's pressures in the
    /// order of their materials. A ghost vertex may lack some of its owner's materials, so its
    /// pressures are looked up rather than counted from its first dof.
    pub fn global_dof(&self, n: usize, c: usize) -> usize {
        match &self.material_pressures {
            Some(mp) if c >= 2 => mp.global(n, c - 2),
            _ => self.node_global[n] + c,
        }
    }

    /// Of vertex `k` of triangle `t`, the component of the pressure the triangle reads (that of
    /// its material).
    pub fn pressure_component(&self, t: usize, k: usize) -> usize {
        2 + self
            .material_pressures
            .as_ref()
            .map_or(0, |mp| mp.slot(t, k))
    }

    /// The local index of the pressure in component `c` (≥ 2) of vertex node `n` among this
    /// rank's pressure unknowns: the vertex node itself when there is one pressure per vertex.
    pub fn pressure_unknown(&self, n: usize, c: usize) -> usize {
        match &self.material_pressures {
            Some(mp) => mp.unknown(n, c - 2),
            None => n,
        }
    }

    /// The material of the pressure in component `c` (≥ 2) of vertex node `n` (0 when there is
    /// one pressure per vertex).
    pub fn pressure_material(&self, n: usize, c: usize) -> u32 {
        self.material_pressures
            .as_ref()
            .map_or(0, |mp| mp.material(n, c - 2))
    }

    /// Pressure unknowns on this rank (owned and ghost), in the order of
    /// [`Self::pressure_unknown`].
    pub fn n_pressure_unknowns(&self) -> usize {
        match &self.material_pressures {
            Some(mp) => mp.len(),
            None if self.vertex_dofs == 3 => self.n_nodes() - self.edges.len(),
            None => 0,
        }
    }

    /// Block size of the system: 2 (a node's ux, uy) for displacement-only dofs; 1 for mixed
    /// dofs, whose vertex nodes carry three unknowns and midside nodes two.
    pub fn block_size(&self) -> usize {
        if self.vertex_dofs == 2 {
            2
        } else {
            1
        }
    }

    /// Positions of this rank's owned nodes in the order of their dofs (a vertex at its
    /// particle in `points`, a midside node at its chord's midpoint): where the rigid-body
    /// modes are evaluated.
    pub fn owned_coordinates(&self, points: &[[f64; 2]]) -> Vec<[f64; 2]> {
        (0..self.n_nodes())
            .filter(|&n| self.node_owned[n])
            .map(|n| {
                let [a, b] = self.node_points(n).map(|p| points[p as usize]);
                [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
            })
            .collect()
    }

    /// Global indices of the dofs of the nodes this rank does not own (node order): what the
    /// ghost scatter gathers. Owned values are read from the global vector in place.
    pub fn ghost_globals(&self) -> Vec<usize> {
        (0..self.n_nodes())
            .filter(|&n| !self.node_owned[n])
            .flat_map(|n| (0..self.ndof(n)).map(move |c| self.global_dof(n, c)))
            .collect()
    }

    /// The local vector (every local node's dofs, node order) from this rank's owned entries
    /// of the global vector and the ghost values in [`Self::ghost_globals`] order.
    pub fn local_vector(&self, owned: &[f64], ghosts: &[f64]) -> Vec<f64> {
        let mut local = Vec::with_capacity(self.n_local_dofs());
        let mut ghost = 0;
        for n in 0..self.n_nodes() {
            let nd = self.ndof(n);
            if self.node_owned[n] {
                let o = self.node_global[n] - self.first_dof;
                local.extend_from_slice(&owned[o..o + nd]);
            } else {
                local.extend_from_slice(&ghosts[ghost..ghost + nd]);
                ghost += nd;
            }
        }
        local
    }

    /// Per owned vertex node, in node order: how many vertex nodes (itself included) share a
    /// triangle with it, owned by this rank and by others: the pattern of a P1 matrix on the
    /// vertices.
    pub fn vertex_neighbour_counts(&self) -> Vec<(usize, usize)> {
        let n_vertex = self.n_nodes() - self.edges.len();
        self.node_neighbours(3)[..n_vertex]
            .iter()
            .enumerate()
            .filter(|&(a, _)| self.node_owned[a])
            .map(|(_, nb)| {
                let owned = nb.iter().filter(|&&b| self.node_owned[b as usize]).count();
                (owned, nb.len() - owned)
            })
            .collect()
    }

    /// For a symmetric matrix stored by its upper triangle in node blocks (P2 displacements):
    /// per owned node, the neighbour nodes (itself included) at or after it in the global
    /// numbering, owned and on other ranks (which, numbered after this rank's, hold the rest
    /// of the upper triangle).
    pub fn upper_block_preallocation(&self) -> (Vec<usize>, Vec<usize>) {
        let cols = self.node_neighbours(6);
        let (mut d, mut o) = (Vec::new(), Vec::new());
        for r in (0..self.n_nodes()).filter(|&r| self.node_owned[r]) {
            let upper = cols[r]
                .iter()
                .filter(|&&n| self.node_global[n as usize] >= self.node_global[r]);
            let (mut nd, mut no) = (0, 0);
            for &n in upper {
                if self.node_owned[n as usize] {
                    nd += 1;
                } else {
                    no += 1;
                }
            }
            d.push(nd);
            o.push(no);
        }
        // Owned nodes come in the order of their dofs (see `owned_coordinates`), as the block
        // rows do.
        (d, o)
    }

    /// Per local node, the sorted nodes it shares a triangle with (itself included), among each
    /// triangle's first `first` nodes (3: the vertices, 6: all); empty for nodes this rank does
    /// not own and for nodes past `first` in their triangles.
    fn node_neighbours(&self, first: usize) -> Vec<Vec<u32>> {
        let mut cols: Vec<Vec<u32>> = vec![Vec::new(); self.n_nodes()];
        for nodes in &self.tri_nodes {
            let nodes = &nodes[..first];
            for &r in nodes {
                if self.node_owned[r as usize] {
                    cols[r as usize].extend_from_slice(nodes);
                }
            }
        }
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
        }
        cols
    }

    /// Exact nonzero counts per owned row in the diagonal and off-diagonal blocks, from the mesh
    /// graph: every triangle around an owned node is on this rank.
    pub fn preallocation(&self) -> (Vec<usize>, Vec<usize>) {
        if self.material_pressures.is_some() {
            return self.preallocation_by_dof();
        }
        let cols = self.node_neighbours(6);
        let mut d = vec![0; self.n_owned_dofs];
        let mut o = vec![0; self.n_owned_dofs];
        for (r, c) in cols.iter().enumerate() {
            if !self.node_owned[r] {
                continue;
            }
            let (mut nd, mut no) = (0, 0);
            for &n in c.iter() {
                let k = self.ndof(n as usize);
                if self.node_owned[n as usize] {
                    nd += k;
                } else {
                    no += k;
                }
            }
            let row = self.node_global[r] - self.first_dof;
            for k in 0..self.ndof(r) {
                d[row + k] = nd;
                o[row + k] = no;
            }
        }
        (d, o)
    }

    /// The local node and component of element dof `k` of triangle `t` (12 displacements and,
    /// on a mixed mesh, 3 pressures): x and y of the six nodes, then the pressure of the
    /// triangle's material at each vertex.
    pub fn element_dof(&self, t: usize, k: usize) -> (usize, usize) {
        let nodes = &self.tri_nodes[t];
        if k < 12 {
            (nodes[k / 2] as usize, k % 2)
        } else {
            (nodes[k - 12] as usize, self.pressure_component(t, k - 12))
        }
    }

    /// Per owned pressure unknown, in the order of their dofs: how many pressure unknowns
    /// (itself included) share a triangle with it, owned by this rank and by others: the pattern
    /// of the P1 pressure mass matrix, which couples a material's pressures only among its own
    /// triangles.
    pub fn pressure_neighbour_counts(&self) -> Vec<(usize, usize)> {
        if self.material_pressures.is_some() {
            return self.material_pressure_neighbour_counts();
        }
        self.vertex_neighbour_counts()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_local_vector_interleaves_owned_values_and_ghosts_in_node_order() {
        // Two vertex nodes of a mixed mesh (3 dofs) and two midside nodes (2 dofs); this rank
        // owns nodes 0 and 3, whose dofs start at its first dof 100.
        let dofs = DofMap {
            node_of_point: vec![0, 1],
            edges: vec![[0, 1], [1, 0]],
            tri_nodes: Vec::new(),
            node_global: vec![100, 50, 60, 103],
            vertex_dofs: 3,
            material_pressures: None,
            node_owned: vec![true, false, false, true],
            node_point: vec![0, 1, u32::MAX, u32::MAX],
            n_owned_dofs: 5,
            first_dof: 100,
            n_global_dofs: 200,
        };
        assert_eq!(dofs.ghost_globals(), vec![50, 51, 52, 60, 61]);
        let owned = [1.0, 2.0, 3.0, 4.0, 5.0];
        let ghosts = [50.0, 51.0, 52.0, 60.0, 61.0];
        assert_eq!(
            dofs.local_vector(&owned, &ghosts),
            vec![1.0, 2.0, 3.0, 50.0, 51.0, 52.0, 60.0, 61.0, 4.0, 5.0]
        );
    }
}
