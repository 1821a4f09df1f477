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

/// The start-of-step Gauss states of every local triangle, as the step reads them. An elastic
/// law's plastic fields are zero, so its states keep the stress alone: stored whole they were
/// five ninths of the states' 71 MB at the solve's memory peak (the cantilever at h = 1/128,
/// 1 rank).
#[derive(Debug, Clone)]
pub enum StartStates {
    Full(Vec<[GaussState; 3]>),
    StressOnly(Vec<[[f64; 4]; 3]>),
}

impl StartStates {
    /// `states` per triangle; `plastic` keeps every field, else the stress alone (the plastic
    /// fields must then be zero).
    pub fn new(states: Vec<[GaussState; 3]>, plastic: bool) -> StartStates {
        if plastic {
            return StartStates::Full(states);
        }
        debug_assert!(states
            .iter()
            .flatten()
            .all(|g| g.plastic_strain == [0.0; 4] && g.eps_q == 0.0));
        StartStates::StressOnly(states.iter().map(|s| s.map(|g| g.stress)).collect())
    }

    /// The states of triangle `t`.
    pub fn get(&self, t: usize) -> [GaussState; 3] {
        match self {
            StartStates::Full(s) => s[t],
            StartStates::StressOnly(s) => s[t].map(|stress| GaussState {
                stress,
                ..GaussState::default()
            }),
        }
    }
}

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

    /// From unordered (key, states) pairs; a key given twice keeps its first states.
    pub fn from_pairs(mut pairs: Vec<([u64; 3], [GaussState; 3])>) -> TriStates {
        pairs.sort_by_key(|p| p.0);
        pairs.dedup_by_key(|p| p.0);
        let (keys, states) = pairs.into_iter().unzip();
        TriStates { keys, states }
    }

    pub fn iter(&self) -> impl Iterator<Item = (&[u64; 3], &[GaussState; 3])> {
        self.keys.iter().zip(&self.states)
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
    /// Interpolated triangles this rank owns (a sum over ranks counts each triangle once).
    pub interpolated_owned: usize,
}

/// States for `mesh`'s triangles: kept where the triangle existed before (same three global
/// ids), otherwise interpolated linearly from the particle values `at_points` (indexed like
/// `mesh.points`). Both inputs are bitwise identical on every rank that holds the triangle (the
/// particle values travel with the halo), so every copy of an interface triangle gets the same
/// states. (Interpolating from the old triangle that contains a new Gauss point would smooth less,
/// but a rank does not hold every old triangle around its ghost triangles, so copies could differ.)
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
            stats.interpolated_owned += usize::from(mesh.tri_owned[t]);
            let tri = mesh.tris[t];
            let v = tri.map(|i| mesh.points[i as usize]);
            let vals = tri.map(|i| at_points[i as usize]);
            p2_gauss_points(&straight_sided(&v)).map(|p| {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A square lattice meshed twice with different global ids, so SoS picks other diagonals.
    fn meshes(n: usize, h: f64) -> (LocalMesh, LocalMesh) {
        let mut pts = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                pts.push([i as f64 * h, j as f64 * h]);
            }
        }
        let np = pts.len();
        let build = |gids: Vec<u64>| {
            LocalMesh::build(
                pts.clone(),
                gids,
                vec![0; np],
                vec![h; np],
                np,
                0,
                1.3,
                true,
            )
            .unwrap()
        };
        (
            build((0..np as u64).collect()),
            build((0..np as u64).rev().collect()),
        )
    }

    fn states_of(mesh: &LocalMesh, f: &impl Fn([f64; 2]) -> f64) -> Vec<[GaussState; 3]> {
        (0..mesh.tris.len())
            .map(|t| {
                let v = mesh.tris[t].map(|i| mesh.points[i as usize]);
                p2_gauss_points(&straight_sided(&v)).map(|p| {
                    let mut a = [0.0; K];
                    for (k, x) in a.iter_mut().enumerate() {
                        *x = f(p) * (k + 1) as f64;
                    }
                    GaussState::from_array(&a)
                })
            })
            .collect()
    }

    /// Largest error at the new mesh's Gauss points after Gauss -> particle -> Gauss.
    fn round_trip_error(n: usize, f: impl Fn([f64; 2]) -> f64) -> f64 {
        let h = 1.0 / n as f64;
        let (a, b) = meshes(n, h);
        let at_particles = recover_at_particles(&a, &states_of(&a, &f), &vec![[0.0; K]; a.n_owned]);
        // Mesh b numbers the same points in reverse: its particle values are a's, reversed.
        let on_b: Vec<[f64; K]> = (0..b.points.len()).map(|i| at_particles[i]).collect();
        let (mapped, stats) = map_states(&TriStates::default(), &b, &on_b);
        assert_eq!(stats.kept, 0);
        let exact = states_of(&b, &f);
        let mut worst: f64 = 0.0;
        for (m, e) in mapped.iter().zip(&exact) {
            for q in 0..3 {
                for (x, y) in m[q].to_array().iter().zip(e[q].to_array()) {
                    worst = worst.max((x - y).abs());
                }
            }
        }
        worst
    }

    #[test]
    fn linear_fields_are_reproduced_exactly() {
        let err = round_trip_error(6, |p| 3.0 + 2.0 * p[0] - 5.0 * p[1]);
        assert!(err < 1e-12, "linear field changed by {err}");
    }

    #[test]
    fn smoothing_of_a_curved_field_is_second_order() {
        let f = |p: [f64; 2]| (3.0 * p[0]).sin() * (2.0 * p[1]).cos();
        let (e1, e2) = (round_trip_error(8, f), round_trip_error(16, f));
        println!("Gauss -> particle -> Gauss error of sin(3x)cos(2y) (x 1..9 per component): h=1/8 {e1:.2e}, h=1/16 {e2:.2e}");
        assert!(e1 < 0.05 * 9.0, "{e1}");
        assert!(e2 < e1 / 3.0, "not second order: {e1} -> {e2}");
    }

    #[test]
    fn unchanged_triangles_keep_their_states() {
        let (a, _) = meshes(4, 0.25);
        let states = states_of(&a, &|p| p[0] * p[0]);
        let old = TriStates::new(&a, states.clone());
        let (mapped, stats) = map_states(&old, &a, &vec![[0.0; K]; a.points.len()]);
        assert_eq!(stats.interpolated, 0);
        assert_eq!(mapped, states);
    }
}
