//! The mesh one rank works on: Delaunay of its owned particles plus the halo, filtered by the alpha
//! shape, restricted to triangles that touch an owned particle. With a halo at least
//! `2 * alpha * h_max` wide these triangles are exactly the global mesh's triangles around the owned
//! particles, bit for bit on every rank that holds them (see `halo_width`).

use super::alpha::{alpha_keep, boundary_edges};
use super::delaunay::delaunay;
use super::near_ties::settle_near_ties;

/// Every kept triangle has circumradius R <= alpha*h and an owned vertex on its circumcircle, so its
/// circumdisk lies within 2R of that vertex: every particle that could spoil the empty-circle test
/// is within `2*alpha*h_max`. The 5 % margin covers particles moved by refinement in the same step.
pub fn halo_width(alpha: f64, h_max: f64) -> f64 {
    2.0 * alpha * h_max * 1.05
}

#[derive(Debug, Clone)]
pub struct LocalMesh {
    /// Owned particles first (`0..n_owned`, sorted by global id), then ghosts.
    pub points: Vec<[f64; 2]>,
    pub gids: Vec<u64>,
    pub n_owned: usize,
    /// Rank owning each local point.
    pub owner: Vec<i32>,
    /// Local particle spacing per point.
    pub h: Vec<f64>,
    /// Kept triangles touching an owned particle, CCW, smallest-gid vertex first, sorted by gids.
    pub tris: Vec<[u32; 3]>,
    /// Whether this rank owns the triangle: the owner of its smallest-gid vertex (fixed rule).
    pub tri_owned: Vec<bool>,
    /// Owned particles on the alpha-shape boundary.
    pub on_boundary: Vec<bool>,
    /// Boundary edges touching an owned particle (body on the left).
    pub boundary_edges: Vec<[u32; 2]>,
    /// False if the near-tie pass was asked for but did not settle here, so this rank kept the
    /// exact Delaunay triangulation: then every rank must rebuild without the pass, or the ranks'
    /// meshes may disagree.
    pub ties_settled: bool,
    /// Midside positions of the curved edges (`super::curved`) by sorted gid pair, sorted; every
    /// other edge is straight. The same on every rank that holds the edge.
    pub curved: Vec<([u64; 2], [f64; 2])>,
}

#[derive(Debug)]
pub struct MeshError(pub String);

impl std::fmt::Display for MeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl LocalMesh {
    /// Builds the rank-local mesh. `h` is the local spacing per point (same order as `points`);
    /// `near_ties` asks for the near-tie pass (`super::near_ties`) after the Delaunay.
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        points: Vec<[f64; 2]>,
        gids: Vec<u64>,
        owner: Vec<i32>,
        h: Vec<f64>,
        n_owned: usize,
        rank: i32,
        alpha: f64,
        near_ties: bool,
    ) -> Result<LocalMesh, MeshError> {
        let mut all = delaunay(&points, &gids)
            .map_err(|e| MeshError(format!("Delaunay triangulation failed: {e}")))?;
        let ties_settled = !near_ties || settle_near_ties(&points, &gids, &mut all);
        let keep = alpha_keep(&points, &all, &h, alpha);
        let mut tris: Vec<[u32; 3]> = all
            .iter()
            .zip(&keep)
            .filter(|(t, &k)| k && t.iter().any(|&v| (v as usize) < n_owned))
            .map(|(t, _)| canonical(*t, &gids))
            .collect();
        tris.sort_by_key(|t| key(t, &gids));
        let mut mesh = LocalMesh {
            points,
            gids,
            n_owned,
            owner,
            h,
            tris,
            tri_owned: Vec::new(),
            on_boundary: Vec::new(),
            boundary_edges: Vec::new(),
            ties_settled,
            curved: Vec::new(),
        };
        mesh.derive(rank);
        Ok(mesh)
    }

    /// Ownership and boundary from `tris`.
    fn derive(&mut self, rank: i32) {
        let n_owned = self.n_owned;
        self.tri_owned = self
            .tris
            .iter()
            .map(|t| self.owner[t[0] as usize] == rank)
            .collect();
        self.boundary_edges = boundary_edges(&self.tris)
            .into_iter()
            .filter(|e| (e[0] as usize) < n_owned || (e[1] as usize) < n_owned)
            .collect();
        self.on_boundary = vec![false; n_owned];
        for e in &self.boundary_edges {
            for &v in e {
                if (v as usize) < n_owned {
                    self.on_boundary[v as usize] = true;
                }
            }
        }
    }

    /// Removes the triangles `drop` rejects (given their points and the vertices' largest
    /// spacing). `drop` must depend only on those values, so that every rank holding a copy
    /// of a triangle decides the same. Returns how many were removed.
    pub fn drop_triangles(
        &mut self,
        rank: i32,
        drop: impl Fn([[f64; 2]; 3], f64) -> bool,
    ) -> usize {
        let before = self.tris.len();
        let points = &self.points;
        let h = &self.h;
        self.tris.retain(|t| {
            let p = t.map(|v| points[v as usize]);
            let hmax = t.iter().map(|&v| h[v as usize]).fold(0.0, f64::max);
            !drop(p, hmax)
        });
        let removed = before - self.tris.len();
        if removed > 0 {
            self.derive(rank);
        }
        removed
    }

    /// Removes triangle `t` where `drop[t]`; `drop` must be decided from data every rank holding
    /// the triangle has alike. Returns how many were removed.
    pub fn drop_flagged(&mut self, rank: i32, drop: &[bool]) -> usize {
        let before = self.tris.len();
        let mut t = 0;
        self.tris.retain(|_| {
            t += 1;
            !drop.get(t - 1).copied().unwrap_or(false)
        });
        let removed = before - self.tris.len();
        if removed > 0 {
            self.derive(rank);
        }
        removed
    }

    /// The triangle's global-id key (smallest gid first, CCW).
    pub fn tri_key(&self, t: usize) -> [u64; 3] {
        key(&self.tris[t], &self.gids)
    }

    /// The midside node of the edge between local points `a` and `b`: its curved position, or
    /// the chord's midpoint.
    pub fn midside(&self, a: u32, b: u32) -> [f64; 2] {
        let (ga, gb) = (self.gids[a as usize], self.gids[b as usize]);
        if !self.curved.is_empty() {
            let key = if ga < gb { [ga, gb] } else { [gb, ga] };
            if let Ok(i) = self.curved.binary_search_by_key(&key, |e| e.0) {
                return self.curved[i].1;
            }
        }
        let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
        [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])]
    }

    /// The six nodes of triangle `t` (vertices, then the midside nodes of edges 01, 12, 20).
    pub fn element_nodes(&self, t: usize) -> [[f64; 2]; 6] {
        let [a, b, c] = self.tris[t];
        let p = |v: u32| self.points[v as usize];
        [
            p(a),
            p(b),
            p(c),
            self.midside(a, b),
            self.midside(b, c),
            self.midside(c, a),
        ]
    }

    /// Number of owned triangles (for balance and the fingerprint).
    pub fn n_owned_tris(&self) -> usize {
        self.tri_owned.iter().filter(|&&o| o).count()
    }
}

fn key(t: &[u32; 3], gids: &[u64]) -> [u64; 3] {
    [
        gids[t[0] as usize],
        gids[t[1] as usize],
        gids[t[2] as usize],
    ]
}

/// Rotates a CCW triangle so its smallest-gid vertex comes first; orientation is kept.
fn canonical(t: [u32; 3], gids: &[u64]) -> [u32; 3] {
    let g = key(&t, gids);
    let m = (0..3).min_by_key(|&i| g[i]).unwrap_or(0);
    [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
}
