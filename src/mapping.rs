//! State transfer between meshes, rank-local. After a step the Gauss states are recovered at the
//! particles (Gauss point → vertex extrapolation, area-weighted average); after a remesh a triangle
//! that survived unchanged keeps its Gauss states exactly, and a new triangle interpolates the
//! particle values at its Gauss points. Both directions reproduce linear fields exactly. Every
//! column of the material's layout is transferred alike, so the layout's width is all this
//! module knows of it. The run then returns the recovered particle states, and the interpolated
//! Gauss states, to their material's admissible set ([`crate::material::Material::admit`]:
//! eps_q, ξ ≥ 0, the stress on or inside the yield surface): the recovery's extrapolation
//! overshoots where the field is not linear (issue 28 item 5). An admissible state is left as it
//! is, so the exactness for linear fields holds wherever the linear field is admissible.

use crate::fem::element::p2_gauss_points;
use crate::fem::p2::straight_sided;
use crate::fem::recovery::{barycentric, GAUSS_TO_VERTEX};
use crate::material::{GaussState, Rows};
use crate::mesh::LocalMesh;

/// Gauss points per triangle: a triangle's state row holds this many rows of the layout.
pub const POINTS: usize = 3;

/// The start-of-step Gauss states of every local triangle, as the step reads them: one row of
/// [`POINTS`] layout rows per triangle. An elastic law's layout is the stress alone, so its
/// states cost no more than the stress.
#[derive(Debug, Clone)]
pub struct StartStates(Rows);

impl StartStates {
    pub fn new(states: Rows) -> StartStates {
        StartStates(states)
    }

    /// The states of triangle `t`.
    pub fn get(&self, t: usize) -> [GaussState; POINTS] {
        let row = self.0.row(t);
        let w = row.len() / POINTS;
        std::array::from_fn(|q| GaussState::from_row(&row[q * w..(q + 1) * w]))
    }
}

/// Appends a triangle's Gauss states as one row.
pub fn push_states(rows: &mut Rows, states: &[GaussState; POINTS]) {
    let w = rows.width() / POINTS;
    let mut row = [0.0; 64];
    let mut heap;
    let buf: &mut [f64] = if rows.width() <= row.len() {
        &mut row[..rows.width()]
    } else {
        heap = vec![0.0; rows.width()];
        &mut heap
    };
    for (q, s) in states.iter().enumerate() {
        s.write_to(&mut buf[q * w..(q + 1) * w]);
    }
    rows.push(buf);
}

/// Gauss states of a mesh's triangles, looked up by global-id key.
#[derive(Debug, Clone, Default)]
pub struct TriStates {
    keys: Vec<[u64; 3]>,
    states: Rows,
}

impl TriStates {
    /// `states` row t belongs to `mesh.tris[t]` (whose keys are sorted).
    pub fn new(mesh: &LocalMesh, states: Rows) -> TriStates {
        let keys = (0..mesh.tris.len()).map(|t| mesh.tri_key(t)).collect();
        TriStates { keys, states }
    }

    /// From unordered keys and their rows; a key given twice keeps its first states.
    pub fn from_pairs(keys: Vec<[u64; 3]>, states: Rows) -> TriStates {
        let mut order: Vec<usize> = (0..keys.len()).collect();
        order.sort_by_key(|&i| keys[i]);
        order.dedup_by_key(|i| keys[*i]);
        TriStates {
            keys: order.iter().map(|&i| keys[i]).collect(),
            states: states.permuted(&order),
        }
    }

    pub fn iter(&self) -> impl Iterator<Item = (&[u64; 3], &[f64])> {
        self.keys.iter().zip(self.states.iter())
    }

    pub fn get(&self, key: &[u64; 3]) -> Option<&[f64]> {
        self.keys
            .binary_search(key)
            .ok()
            .map(|i| self.states.row(i))
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
        self.states.retain(&keep);
    }

    pub fn states(&self) -> &Rows {
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
    /// Interpolated triangles whose states were returned to admissibility.
    pub admitted: usize,
}

/// States for `mesh`'s triangles: kept where the triangle existed before (same three global
/// ids), otherwise interpolated linearly from the particle values `at_points` (a row per
/// `mesh.points` entry). Both inputs are bitwise identical on every rank that holds the triangle
/// (the particle values travel with the halo), so every copy of an interface triangle gets the
/// same states. (Interpolating from the old triangle that contains a new Gauss point would smooth
/// less, but a rank does not hold every old triangle around its ghost triangles, so copies could
/// differ.)
pub fn map_states(old: &TriStates, mesh: &LocalMesh, at_points: &Rows) -> (Rows, MapStats) {
    map_states_admitted(old, mesh, at_points, |_, _| false)
}

/// [`map_states`], with `admit(t, row)` returning the interpolated Gauss states of triangle `t`
/// (its row of [`POINTS`] layout rows) to its material's admissible set
/// ([`crate::material::Material::admit`]); kept triangles are not touched.
pub fn map_states_admitted(
    old: &TriStates,
    mesh: &LocalMesh,
    at_points: &Rows,
    mut admit: impl FnMut(usize, &mut [f64]) -> bool,
) -> (Rows, MapStats) {
    let w = at_points.width();
    let mut stats = MapStats::default();
    let mut states = Rows::with_capacity(POINTS * w, mesh.tris.len());
    let mut row = vec![0.0; POINTS * w];
    for t in 0..mesh.tris.len() {
        if let Some(s) = old.get(&mesh.tri_key(t)) {
            stats.kept += 1;
            states.push(s);
            continue;
        }
        stats.interpolated += 1;
        stats.interpolated_owned += usize::from(mesh.tri_owned[t]);
        let tri = mesh.tris[t];
        let v = tri.map(|i| mesh.points[i as usize]);
        let vals = tri.map(|i| at_points.row(i as usize));
        for (q, p) in p2_gauss_points(&straight_sided(&v)).iter().enumerate() {
            let bary = barycentric(v[0], v[1], v[2], *p);
            let out = &mut row[q * w..(q + 1) * w];
            out.fill(0.0);
            for (l, vk) in bary.iter().zip(&vals) {
                for (o, x) in out.iter_mut().zip(vk.iter()) {
                    *o += l * x;
                }
            }
        }
        if admit(t, &mut row) {
            stats.admitted += 1;
        }
        states.push(&row);
    }
    (states, stats)
}

/// Returns each row of `rows` (one [`POINTS`] triangle row or one particle row: `points` layout
/// rows of `state_len` each) to the admissible set of `material`; whether any changed.
pub fn admit_rows(
    material: &dyn crate::material::Material,
    row: &mut [f64],
    state_len: usize,
) -> bool {
    let mut changed = false;
    for chunk in row.chunks_exact_mut(state_len) {
        let mut st = GaussState::from_row(chunk);
        if material.admit(&mut st) {
            st.write_to(chunk);
            changed = true;
        }
    }
    changed
}

/// Particle values of the Gauss states: each triangle's linear extrapolation to its vertices,
/// averaged over the triangles around an owned particle with their areas as weights. Owned
/// particles in no triangle keep `previous`.
pub fn recover_at_particles(mesh: &LocalMesh, states: &Rows, previous: &Rows) -> Rows {
    let n = mesh.n_owned;
    let w = previous.width();
    let mut sum = Rows::zeros(w, n);
    let mut weight = vec![0.0; n];
    let mut at_vertex = vec![0.0; w];
    for (tri, s) in mesh.tris.iter().zip(states.iter()) {
        let [a, b, c] = tri.map(|v| mesh.points[v as usize]);
        let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
        for (k, &v) in tri.iter().enumerate() {
            let v = v as usize;
            if v >= n {
                continue;
            }
            at_vertex.fill(0.0);
            for (q, coeff) in GAUSS_TO_VERTEX[k].iter().enumerate() {
                for (o, g) in at_vertex.iter_mut().zip(&s[q * w..(q + 1) * w]) {
                    *o += coeff * g;
                }
            }
            weight[v] += area;
            for (acc, x) in sum.row_mut(v).iter_mut().zip(&at_vertex) {
                *acc += area * x;
            }
        }
    }
    for (i, &wt) in weight.iter().enumerate() {
        if wt > 0.0 {
            sum.row_mut(i).iter_mut().for_each(|x| *x /= wt);
        } else {
            sum.row_mut(i).copy_from_slice(previous.row(i));
        }
    }
    sum
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

    const K: usize = 9;

    fn states_of(mesh: &LocalMesh, f: &impl Fn([f64; 2]) -> f64) -> Rows {
        let mut out = Rows::new(POINTS * K);
        for t in 0..mesh.tris.len() {
            let v = mesh.tris[t].map(|i| mesh.points[i as usize]);
            let row: Vec<f64> = p2_gauss_points(&straight_sided(&v))
                .iter()
                .flat_map(|&p| (0..K).map(move |k| f(p) * (k + 1) as f64))
                .collect();
            out.push(&row);
        }
        out
    }

    /// Largest error at the new mesh's Gauss points after Gauss -> particle -> Gauss.
    fn round_trip_error(n: usize, f: impl Fn([f64; 2]) -> f64) -> f64 {
        let h = 1.0 / n as f64;
        let (a, b) = meshes(n, h);
        let at_particles = recover_at_particles(&a, &states_of(&a, &f), &Rows::zeros(K, a.n_owned));
        // Mesh b numbers the same points in reverse: its particle values are a's, reversed.
        let on_b = at_particles.slice(0..b.points.len());
        let (mapped, stats) = map_states(&TriStates::default(), &b, &on_b);
        assert_eq!(stats.kept, 0);
        let exact = states_of(&b, &f);
        let mut worst: f64 = 0.0;
        for (m, e) in mapped.iter().zip(exact.iter()) {
            for (x, y) in m.iter().zip(e) {
                worst = worst.max((x - y).abs());
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
        let (mapped, stats) = map_states(&old, &a, &Rows::zeros(K, a.points.len()));
        assert_eq!(stats.interpolated, 0);
        assert_eq!(mapped, states);
    }
}
