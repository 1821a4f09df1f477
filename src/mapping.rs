//! State transfer between meshes, rank-local. After a step the Gauss states are recovered at the
//! particles (Gauss point → vertex extrapolation, area-weighted average); after a remesh a triangle
//! that survived unchanged keeps its Gauss states exactly, and a new triangle interpolates the
//! particle values at its Gauss points. Both directions reproduce linear fields exactly.

use crate::fem::element::p2_gauss_points;
use crate::fem::p2::straight_sided;
use crate::fem::recovery::{barycentric, extrapolate_to_vertices, interpolate_linear};
use crate::material::GaussState;
use crate::mesh::LocalMesh;

const K: usize = GaussState::LEN;

/// Gauss states of a mesh's triangles, looked up by global-id key.
#[derive(Debug, Clone, Default)]
pub struct TriStates {
    keys: Vec<[u64; 3]>,
    states: Vec<[GaussState; 3]>,
}

impl TriStates {
    /// `states[t]` belongs to `mesh.tris[t]` (whose keys are sorted).
    pub fn new(mesh: &LocalMesh, states: Vec<[GaussState; 3]>) -> TriStates {
        let keys = (0..mesh.tris.len()).map(|t| mesh.tri_key(t)).collect();
        TriStates { keys, states }
    }

    pub fn get(&self, key: &[u64; 3]) -> Option<&[GaussState; 3]> {
        self.keys.binary_search(key).ok().map(|i| &self.states[i])
    }

    /// Drops the triangles with a vertex in `moved` (their Gauss points are no longer where the
    /// states were computed).
    pub fn forget_touching(&mut self, moved: &std::collections::HashSet<u64>) {
        let keep: Vec<bool> = self
            .keys
            .iter()
            .map(|k| !k.iter().any(|g| moved.contains(g)))
            .collect();
        let mut i = 0;
        self.keys.retain(|_| {
            i += 1;
            keep[i - 1]
        });
        let mut j = 0;
        self.states.retain(|_| {
            j += 1;
            keep[j - 1]
        });
    }

    pub fn states(&self) -> &[[GaussState; 3]] {
        &self.states
    }
}

/// How a mapping went.
#[derive(Debug, Clone, Copy, Default)]
pub struct MapStats {
    pub kept: usize,
    pub interpolated: usize,
}

/// States for `mesh`'s triangles: kept where the triangle existed before, otherwise interpolated
/// from the particle values `at_points` (indexed like `mesh.points`).
pub fn map_states(
    old: &TriStates,
    mesh: &LocalMesh,
    at_points: &[[f64; K]],
) -> (Vec<[GaussState; 3]>, MapStats) {
    let mut stats = MapStats::default();
    let states = (0..mesh.tris.len())
        .map(|t| {
            if let Some(s) = old.get(&mesh.tri_key(t)) {
                stats.kept += 1;
                return *s;
            }
            stats.interpolated += 1;
            let tri = mesh.tris[t];
            let v = [
                mesh.points[tri[0] as usize],
                mesh.points[tri[1] as usize],
                mesh.points[tri[2] as usize],
            ];
            let vals = [
                at_points[tri[0] as usize],
                at_points[tri[1] as usize],
                at_points[tri[2] as usize],
            ];
            let gp = p2_gauss_points(&straight_sided(&v));
            gp.map(|p| {
                GaussState::from_array(&interpolate_linear(barycentric(v[0], v[1], v[2], p), &vals))
            })
        })
        .collect();
    (states, stats)
}

/// Particle values of the Gauss states: each triangle's linear extrapolation to its vertices,
/// averaged over the triangles around an owned particle with their areas as weights. Owned
/// particles in no triangle keep `previous`.
pub fn recover_at_particles(
    mesh: &LocalMesh,
    states: &[[GaussState; 3]],
    previous: &[[f64; K]],
) -> Vec<[f64; K]> {
    let n = mesh.n_owned;
    let mut sum = vec![[0.0; K]; n];
    let mut weight = vec![0.0; n];
    for (tri, s) in mesh.tris.iter().zip(states) {
        let [a, b, c] = tri.map(|v| mesh.points[v as usize]);
        let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        let at_vertices = extrapolate_to_vertices(&s.map(|g| g.to_array()));
        for (k, &v) in tri.iter().enumerate() {
            let v = v as usize;
            if v < n {
                weight[v] += area;
                for (acc, x) in sum[v].iter_mut().zip(&at_vertices[k]) {
                    *acc += area * x;
                }
            }
        }
    }
    (0..n)
        .map(|i| {
            if weight[i] > 0.0 {
                sum[i].map(|x| x / weight[i])
            } else {
                previous[i]
            }
        })
        .collect()
}
