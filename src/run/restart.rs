//! Checkpoints that restart exactly: the particles (in the writer's rank blocks, so the same rank
//! count keeps its partition) and the Gauss states of the last mesh, routed on restart to every
//! rank whose owned particles touch the triangle.

use super::Simulation;
use crate::case_file::{
    write_checkpoint, GaussRecords, ParticleSet, BULGE_LEN, CONTACT_LEN, GAUSS_POINTS, NODE_LEN,
};
use crate::mapping::TriStates;
use crate::material::Rows;
use crate::particles::flag;
use mpi::traits::Communicator;
use pfem_partition::{alltoallv, locate, Comm};

/// The node keys of a triangle `[a, b, c]`: its vertices, then the midside nodes of edges 01,
/// 12, 20 (the order of `/gauss/nodes`).
fn tri_node_keys(t: &[u64; 3]) -> [[u64; 2]; 6] {
    let edge = super::step::edge_key;
    [
        [t[0], t[0]],
        [t[1], t[1]],
        [t[2], t[2]],
        edge(t[0], t[1]),
        edge(t[1], t[2]),
        edge(t[2], t[0]),
    ]
}

impl Simulation {
    /// Collective. Writes this state as a case file that any rank count can continue from.
    pub fn write_checkpoint(
        &self,
        world: &Comm,
        path: &std::path::Path,
    ) -> Result<(), super::RunError> {
        let p = &self.particles;
        let set = ParticleSet {
            gid: p.gid.clone(),
            position: p.position.clone(),
            displacement: p.displacement.clone(),
            increment: p.increment.clone(),
            h: p.h.clone(),
            state: p.state.clone(),
            flags: p.flags.iter().map(|f| f & !flag::TRACKED).collect(),
            material: p.material.clone(),
        };
        let records = self.gauss_records();
        let mut header = self.header.clone();
        header.code_version = env!("CARGO_PKG_VERSION").to_string();
        Ok(write_checkpoint(world, path, &header, &set, &records)?)
    }

    /// The Gauss states of the last mesh with its node values (the Newton predictor) and contact
    /// state, each triangle once: from the owner of its smallest-gid vertex. Rank-local.
    pub(super) fn gauss_records(&self) -> GaussRecords {
        let p = &self.particles;
        let mut records = GaussRecords {
            state: Rows::new(self.gauss_width()),
            ..GaussRecords::default()
        };
        let last = self.last_nodes.borrow();
        let touching = self.last_contact.borrow();
        for (key, states) in self.tri_states.iter() {
            // Each triangle once: by the owner of its smallest-gid vertex.
            if p.gid.binary_search(&key[0]).is_ok() {
                records.key.push(*key);
                records.state.push(states);
                let mut nodes = [f64::NAN; NODE_LEN];
                // A vertex with a pressure per material gives its lowest material's: the file
                // keeps one per vertex, and a triangle's material is not stored to choose by.
                // Only the next predictor reads it, so a restart of a run of several materials
                // starts Newton a little off at their interfaces and converges to the same
                // tolerance, rather than repeating the run bit for bit.
                for (k, node) in tri_node_keys(key).iter().enumerate() {
                    if let Some(v) = last.get(node) {
                        nodes[3 * k..3 * k + 3].copy_from_slice(&v);
                    }
                }
                records.nodes.push(nodes);
                let mut contact = [f64::NAN; CONTACT_LEN];
                for (k, node) in tri_node_keys(key).iter().enumerate() {
                    let touched = (0..self.model.bodies.len() as u32)
                        .find_map(|b| touching.get(&(*node, b)).map(|v| (b, v)));
                    if let Some((b, v)) = touched {
                        contact[3 * k..3 * k + 3].copy_from_slice(&[b as f64, v[0], v[1]]);
                    }
                }
                records.contact.push(contact);
                let bulge = crate::fem::p2::EDGES.map(|[i, j]| {
                    let edge = super::step::edge_key(key[i], key[j]);
                    self.bulges
                        .binary_search_by_key(&edge, |e| e.0)
                        .map_or(f64::NAN, |i| self.bulges[i].1)
                });
                records.bulge.push(bulge);
            }
        }
        records
    }

    /// Values in a triangle's state row: its Gauss points' rows of the material's layout (the
    /// same on every rank, whatever it holds).
    fn gauss_width(&self) -> usize {
        GAUSS_POINTS * self.model.layout().len()
    }

    /// Collective. Sends each stored triangle (Gauss states and node values) to the owners of its
    /// vertices.
    pub(super) fn restore_gauss(&mut self, world: &Comm, records: GaussRecords) {
        let queries: Vec<u64> = records.key.iter().flatten().copied().collect();
        let owners = locate(world, &self.particles.gid, &queries);
        let mut send: Vec<Vec<u64>> = vec![Vec::new(); world.size() as usize];
        for (t, key) in records.key.iter().enumerate() {
            let mut dest: Vec<i32> = owners[3 * t..3 * t + 3]
                .iter()
                .copied()
                .filter(|&r| r >= 0)
                .collect();
            dest.sort_unstable();
            dest.dedup();
            for r in dest {
                send[r as usize].extend_from_slice(key);
                send[r as usize].extend(records.state.row(t).iter().map(|x| x.to_bits()));
                send[r as usize].extend(records.nodes[t].iter().map(|x| x.to_bits()));
                send[r as usize].extend(records.contact[t].iter().map(|x| x.to_bits()));
                send[r as usize].extend(records.bulge[t].iter().map(|x| x.to_bits()));
            }
        }
        let received = alltoallv(world, &send);
        let gw = self.gauss_width();
        let chunks = || {
            received
                .iter()
                .flat_map(|r| r.chunks_exact(3 + gw + NODE_LEN + CONTACT_LEN + BULGE_LEN))
        };
        let mut last = Vec::new();
        for c in chunks() {
            let nodes = &c[3 + gw..];
            for (k, node) in tri_node_keys(&[c[0], c[1], c[2]]).iter().enumerate() {
                let v: [f64; 3] = std::array::from_fn(|i| f64::from_bits(nodes[3 * k + i]));
                // A node's displacement is NaN only where it was not stored.
                if !v[0].is_nan() {
                    last.push((*node, v));
                }
            }
        }
        *self.last_nodes.borrow_mut() =
            super::node_values::NodeValues::new(last, self.model.mixed());
        let mut touching = self.last_contact.borrow_mut();
        touching.clear();
        for c in chunks() {
            let contact = &c[3 + gw + NODE_LEN..];
            for (k, node) in tri_node_keys(&[c[0], c[1], c[2]]).iter().enumerate() {
                let v: [f64; 3] = std::array::from_fn(|i| f64::from_bits(contact[3 * k + i]));
                if !v[0].is_nan() {
                    touching.insert((*node, v[0] as u32), [v[1], v[2]]);
                }
            }
        }
        drop(touching);
        let mut bulges = Vec::new();
        for c in chunks() {
            let bulge = &c[3 + gw + NODE_LEN + CONTACT_LEN..];
            for (k, [i, j]) in crate::fem::p2::EDGES.into_iter().enumerate() {
                let s = f64::from_bits(bulge[k]);
                if !s.is_nan() {
                    bulges.push((super::step::edge_key(c[i], c[j]), s));
                }
            }
        }
        self.bulges = super::curved_edges::gather(world, &bulges);
        let mut keys = Vec::new();
        let mut states = Rows::new(gw);
        for c in chunks() {
            keys.push([c[0], c[1], c[2]]);
            let row: Vec<f64> = c[3..3 + gw].iter().map(|&x| f64::from_bits(x)).collect();
            states.push(&row);
        }
        self.tri_states = TriStates::from_pairs(keys, states);
    }
}
