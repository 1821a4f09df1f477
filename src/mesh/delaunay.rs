//! Unique Delaunay triangulation of a particle cloud.
//!
//! Incremental Bowyer–Watson insertion over a triangulation closed by *ghost* triangles (one
//! per convex-hull edge, sharing a virtual vertex at infinity), so no bounding super-triangle
//! is needed and the hull is exact. Points are inserted in a biased randomized insertion order
//! (BRIO: rounds chosen by a hash of the global id, Hilbert-curve order inside each round) and
//! located by a stochastic visibility walk from the previously created triangle, which gives
//! expected `O(n log n)` time.
//!
//! Every decision is an exact predicate; cocircular ties are broken by [`incircle_sos`] using
//! the global ids. The result is therefore the unique triangulation that is Delaunay under
//! that perturbation, and does not depend on the order in which points are given.

use super::predicates::{incircle_sos, orient2d};
use std::fmt;

/// The virtual vertex at infinity shared by all ghost triangles.
const GHOST: u32 = u32::MAX;

/// Why a triangulation could not be built.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DelaunayError {
    /// `points` and `ids` have different lengths.
    LengthMismatch {
        /// Number of points.
        points: usize,
        /// Number of ids.
        ids: usize,
    },
    /// More points than `u32` local indices can address.
    TooManyPoints {
        /// Number of points given.
        count: usize,
    },
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// Global id of the offending particle.
        id: u64,
    },
    /// Two particles carry the same global id.
    DuplicateId {
        /// The repeated id.
        id: u64,
    },
    /// Two particles have identical coordinates.
    DuplicatePoint {
        /// The smaller of the two global ids.
        first: u64,
        /// The larger of the two global ids.
        second: u64,
    },
    /// The exact predicates gave inconsistent answers while inserting this particle. Only
    /// possible when coordinates are so large or so small that the predicates' internal
    /// products overflow or underflow `f64`.
    PredicateFailure {
        /// Global id of the particle being inserted.
        id: u64,
    },
}

impl fmt::Display for DelaunayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::LengthMismatch { points, ids } => {
                write!(f, "{points} points but {ids} particle ids")
            }
            Self::TooManyPoints { count } => {
                write!(f, "{count} points exceed the u32 local index range")
            }
            Self::NonFinite { id } => write!(f, "particle {id} has a non-finite coordinate"),
            Self::DuplicateId { id } => write!(f, "particle id {id} appears more than once"),
            Self::DuplicatePoint { first, second } => {
                write!(
                    f,
                    "particles {first} and {second} have identical coordinates"
                )
            }
            Self::PredicateFailure { id } => write!(
                f,
                "inconsistent geometric predicates inserting particle {id} \
                 (coordinates out of the representable range?)"
            ),
        }
    }
}

impl std::error::Error for DelaunayError {}

/// Delaunay triangulation of the convex hull of `points`.
///
/// `ids[i]` is the global particle id of `points[i]`; ids break cocircular ties (see
/// [`incircle_sos`]), so the result is unique and the same, as a set of global-id triangles,
/// whatever order the points are given in.
///
/// Returns counter-clockwise triangles of local indices into `points`, each with strictly
/// positive area. Every point is a vertex, including points lying on straight parts of the
/// hull. Each triangle is rotated so its smallest-id vertex comes first, and triangles are
/// sorted by their vertex ids in that order.
///
/// Fewer than three points, or all points collinear, give `Ok` with no triangles.
///
/// # Errors
/// Mismatched lengths, more than `u32::MAX - 1` points, non-finite coordinates, repeated
/// ids, or two points with identical coordinates (reported by their ids).
pub fn delaunay(points: &[[f64; 2]], ids: &[u64]) -> Result<Vec<[u32; 3]>, DelaunayError> {
    validate(points, ids)?;
    if points.len() < 3 {
        return Ok(Vec::new());
    }
    triangulate(points, ids, &insertion_order(points, ids))
}

/// Triangulates validated input, inserting points in `order` (a permutation of all indices).
/// The result does not depend on `order`; only the running time does.
fn triangulate(
    points: &[[f64; 2]],
    ids: &[u64],
    order: &[u32],
) -> Result<Vec<[u32; 3]>, DelaunayError> {
    let Some((seed, rest)) = initial_triangle(points, order) else {
        return Ok(Vec::new());
    };
    let mut mesh = Mesh::new(points, ids, seed);
    for p in rest {
        mesh.insert(p)?;
    }
    Ok(mesh.into_triangles())
}

fn validate(points: &[[f64; 2]], ids: &[u64]) -> Result<(), DelaunayError> {
    if points.len() != ids.len() {
        return Err(DelaunayError::LengthMismatch {
            points: points.len(),
            ids: ids.len(),
        });
    }
    // GHOST (u32::MAX) is reserved, so local indices stop one short of it.
    if points.len() >= GHOST as usize {
        return Err(DelaunayError::TooManyPoints {
            count: points.len(),
        });
    }
    if let Some(i) = points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(DelaunayError::NonFinite { id: ids[i] });
    }
    let mut sorted_ids = ids.to_vec();
    sorted_ids.sort_unstable();
    if let Some(w) = sorted_ids.windows(2).find(|w| w[0] == w[1]) {
        return Err(DelaunayError::DuplicateId { id: w[0] });
    }
    let mut by_coord: Vec<(u64, u64, u64)> = points
        .iter()
        .zip(ids)
        .map(|(p, &id)| (ordered_bits(p[0]), ordered_bits(p[1]), id))
        .collect();
    by_coord.sort_unstable();
    if let Some(w) = by_coord
        .windows(2)
        .find(|w| (w[0].0, w[0].1) == (w[1].0, w[1].1))
    {
        return Err(DelaunayError::DuplicatePoint {
            first: w[0].2,
            second: w[1].2,
        });
    }
    Ok(())
}

/// Maps a finite `f64` to a `u64` with the same order, `-0.0` and `+0.0` mapping alike.
fn ordered_bits(v: f64) -> u64 {
    // Adding 0.0 turns -0.0 into +0.0.
    let b = (v + 0.0).to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | 1 << 63
    }
}

fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Index along a Hilbert curve of order 16 through cell `(x, y)`, `x, y < 2¹⁶`.
fn hilbert_index(mut x: u32, mut y: u32) -> u64 {
    const N: u32 = 1 << 16;
    let mut d = 0u64;
    let mut s = N / 2;
    while s > 0 {
        let rx = u32::from(x & s != 0);
        let ry = u32::from(y & s != 0);
        d += u64::from(s) * u64::from(s) * u64::from((3 * rx) ^ ry);
        if ry == 0 {
            if rx == 1 {
                x = N - 1 - x;
                y = N - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        s /= 2;
    }
    d
}

/// BRIO order. Rounds come from a hash of the id, not from input position, and ties are
/// broken by id, so the order (and hence the running time) is independent of input order.
fn insertion_order(points: &[[f64; 2]], ids: &[u64]) -> Vec<u32> {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let scale = if span > 0.0 {
        f64::from((1u32 << 16) - 1) / span
    } else {
        0.0
    };
    // `as` saturates, which is exactly the clamping wanted for the extreme points.
    let cell = |v: f64, k: usize| ((v - lo[k]) * scale) as u32;
    let mut keyed: Vec<(u32, u64, u64, u32)> = points
        .iter()
        .zip(ids)
        .enumerate()
        .map(|(i, (p, &id))| {
            // Round r holds about n/2^(r+1) points; the sparse rounds are inserted first.
            let round = splitmix64(id).trailing_zeros().min(31);
            let h = hilbert_index(cell(p[0], 0), cell(p[1], 1));
            (31 - round, h, id, i as u32)
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|k| k.3).collect()
}

/// First non-collinear triple in insertion order, counter-clockwise, and the other points.
fn initial_triangle(points: &[[f64; 2]], order: &[u32]) -> Option<([u32; 3], Vec<u32>)> {
    let (&a, &b) = (order.first()?, order.get(1)?);
    let (pa, pb) = (points[a as usize], points[b as usize]);
    let k = (2..order.len()).find(|&k| orient2d(pa, pb, points[order[k] as usize]) != 0.0)?;
    let c = order[k];
    let seed = if orient2d(pa, pb, points[c as usize]) > 0.0 {
        [a, b, c]
    } else {
        [a, c, b]
    };
    let rest = order
        .iter()
        .enumerate()
        .filter(|&(i, _)| i >= 2 && i != k)
        .map(|(_, &p)| p)
        .collect();
    Some((seed, rest))
}

/// Triangulation with ghost triangles. Triangle `t` has vertices `vert[t]` in counter-clockwise
/// order and `adj[t][i]` is the triangle across the edge opposite `vert[t][i]`. A ghost
/// triangle `(a, b, GHOST)` (up to rotation) sits outside hull edge `a → b`: the exterior is
/// to the left of `a → b`.
struct Mesh<'a> {
    pts: &'a [[f64; 2]],
    ids: &'a [u64],
    vert: Vec<[u32; 3]>,
    adj: Vec<[u32; 3]>,
    /// Per-triangle visit stamp: `2·epoch` in the cavity, `2·epoch + 1` tested and outside.
    stamp: Vec<u64>,
    epoch: u64,
    cavity: Vec<u32>,
    /// Cavity boundary edges `(u, v, outer triangle)`, `u → v` counter-clockwise around the
    /// cavity.
    rim: Vec<(u32, u32, u32)>,
    /// New triangle whose rim edge starts at a vertex; `ghost_start` for the ghost vertex.
    start_at: Vec<u32>,
    ghost_start: u32,
    last: u32,
    rng: u32,
}

impl<'a> Mesh<'a> {
    fn new(pts: &'a [[f64; 2]], ids: &'a [u64], seed: [u32; 3]) -> Self {
        let [a, b, c] = seed;
        // Triangle 0 is real, 1..=3 are the ghosts outside edges bc, ca, ab.
        let vert = vec![[a, b, c], [c, b, GHOST], [a, c, GHOST], [b, a, GHOST]];
        let adj = vec![[1, 2, 3], [3, 2, 0], [1, 3, 0], [2, 1, 0]];
        Self {
            pts,
            ids,
            vert,
            adj,
            stamp: vec![0; 4],
            epoch: 0,
            cavity: Vec::new(),
            rim: Vec::new(),
            start_at: vec![0; pts.len()],
            ghost_start: 0,
            last: 0,
            rng: 0x2545_F491,
        }
    }

    #[inline]
    fn pt(&self, v: u32) -> [f64; 2] {
        self.pts[v as usize]
    }

    #[inline]
    fn ghost_pos(&self, t: u32) -> Option<usize> {
        self.vert[t as usize].iter().position(|&v| v == GHOST)
    }

    /// Whether the (perturbed) circumcircle of `t` contains point `p`. For a ghost triangle
    /// over hull edge `a → b` that is the open half-plane left of `a → b`, plus the open
    /// segment `ab` itself (a point there is inside the circle of the real triangle on `ab`).
    fn in_conflict(&self, t: u32, p: u32) -> bool {
        let v = self.vert[t as usize];
        let pp = self.pt(p);
        match self.ghost_pos(t) {
            None => {
                let q = [self.pt(v[0]), self.pt(v[1]), self.pt(v[2]), pp];
                let ids = [v[0], v[1], v[2], p].map(|i| self.ids[i as usize]);
                incircle_sos(q, ids) > 0
            }
            Some(g) => {
                let a = self.pt(v[(g + 1) % 3]);
                let b = self.pt(v[(g + 2) % 3]);
                let o = orient2d(a, b, pp);
                o > 0.0 || (o == 0.0 && strictly_between(a, b, pp))
            }
        }
    }

    fn next_rand(&mut self) -> u32 {
        self.rng ^= self.rng << 13;
        self.rng ^= self.rng >> 17;
        self.rng ^= self.rng << 5;
        self.rng
    }

    /// Stochastic visibility walk to a triangle in conflict with `p`: either the real triangle
    /// containing `p` or a ghost whose hull edge `p` is strictly outside of. `None` if the
    /// walk did not settle within a generous step budget.
    fn walk(&mut self, p: u32) -> Option<u32> {
        let pp = self.pt(p);
        let mut t = self.last;
        if let Some(g) = self.ghost_pos(t) {
            t = self.adj[t as usize][g];
        }
        for _ in 0..self.vert.len() + 16 {
            if self.ghost_pos(t).is_some() {
                return Some(t);
            }
            let v = self.vert[t as usize];
            let r = (self.next_rand() % 3) as usize;
            let exit = (0..3)
                .map(|k| (r + k) % 3)
                .find(|&i| orient2d(self.pt(v[(i + 1) % 3]), self.pt(v[(i + 2) % 3]), pp) < 0.0);
            match exit {
                Some(i) => t = self.adj[t as usize][i],
                None => return Some(t),
            }
        }
        None
    }

    fn insert(&mut self, p: u32) -> Result<(), DelaunayError> {
        let id = self.ids[p as usize];
        let failure = move || DelaunayError::PredicateFailure { id };
        let start = match self.walk(p) {
            Some(t) if self.in_conflict(t, p) => t,
            // Unreachable with exact predicates; a linear scan keeps it correct regardless.
            _ => (0..self.vert.len() as u32)
                .find(|&t| self.in_conflict(t, p))
                .ok_or_else(failure)?,
        };
        self.grow_cavity(start, p);
        // A cavity is a triangulated disk with all its vertices on its rim.
        if self.rim.len() != self.cavity.len() + 2 {
            return Err(failure());
        }
        self.fill_cavity(p);
        Ok(())
    }

    fn grow_cavity(&mut self, start: u32, p: u32) {
        self.epoch += 1;
        let (inside, outside) = (2 * self.epoch, 2 * self.epoch + 1);
        self.cavity.clear();
        self.rim.clear();
        self.cavity.push(start);
        self.stamp[start as usize] = inside;
        let mut next = 0;
        while next < self.cavity.len() {
            let t = self.cavity[next];
            next += 1;
            let (v, adj) = (self.vert[t as usize], self.adj[t as usize]);
            for i in 0..3 {
                let n = adj[i];
                let s = self.stamp[n as usize];
                if s == inside {
                    continue;
                }
                if s != outside && self.in_conflict(n, p) {
                    self.stamp[n as usize] = inside;
                    self.cavity.push(n);
                } else {
                    self.stamp[n as usize] = outside;
                    self.rim.push((v[(i + 1) % 3], v[(i + 2) % 3], n));
                }
            }
        }
    }

    /// Replaces the cavity by the fan of triangles `(u, v, p)` over its rim edges `u → v`,
    /// reusing the cavity's slots (there are always two fewer of them than rim edges).
    fn fill_cavity(&mut self, p: u32) {
        let rim = std::mem::take(&mut self.rim);
        let mut created = Vec::with_capacity(rim.len());
        for (k, &(u, v, outer)) in rim.iter().enumerate() {
            let t = match self.cavity.get(k) {
                Some(&slot) => slot,
                None => {
                    self.vert.push([0; 3]);
                    self.adj.push([0; 3]);
                    self.stamp.push(0);
                    (self.vert.len() - 1) as u32
                }
            };
            self.vert[t as usize] = [u, v, p];
            self.adj[t as usize][2] = outer;
            let ov = self.vert[outer as usize];
            if let Some(j) = (0..3).find(|&j| ov[j] != u && ov[j] != v) {
                self.adj[outer as usize][j] = t;
            }
            if u == GHOST {
                self.ghost_start = t;
            } else {
                self.start_at[u as usize] = t;
            }
            created.push(t);
        }
        for &t in &created {
            let v = self.vert[t as usize][1];
            let next = if v == GHOST {
                self.ghost_start
            } else {
                self.start_at[v as usize]
            };
            // Edge (v, p) of t is edge (p, v) of the triangle whose rim edge starts at v.
            self.adj[t as usize][0] = next;
            self.adj[next as usize][1] = t;
        }
        self.last = created.last().copied().unwrap_or(self.last);
        self.rim = rim;
    }

    fn into_triangles(self) -> Vec<[u32; 3]> {
        let ids = self.ids;
        let mut keyed: Vec<([u64; 3], [u32; 3])> = self
            .vert
            .into_iter()
            .filter(|t| !t.contains(&GHOST))
            .map(|t| {
                let first = (0..3).min_by_key(|&i| ids[t[i] as usize]).unwrap_or(0);
                let t = [t[first], t[(first + 1) % 3], t[(first + 2) % 3]];
                (t.map(|v| ids[v as usize]), t)
            })
            .collect();
        keyed.sort_unstable();
        keyed.into_iter().map(|(_, t)| t).collect()
    }
}

/// For `p` exactly on the line through distinct `a` and `b`: whether it lies strictly between
/// them. Points on a line are ordered by `x` unless the line is vertical, so one exact
/// coordinate comparison decides.
fn strictly_between(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> bool {
    let k = usize::from(a[0] == b[0]);
    (a[k] < p[k] && p[k] < b[k]) || (b[k] < p[k] && p[k] < a[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::{BTreeSet, HashMap, HashSet};

    /// Deterministic test randomness (SplitMix64, `crate::rng`).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            crate::rng::next(&mut self.0)
        }
        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
        fn normal(&mut self) -> f64 {
            let (u, v) = (self.unit().max(1e-300), self.unit());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
        fn shuffle<T>(&mut self, v: &mut [T]) {
            for i in (1..v.len()).rev() {
                v.swap(i, self.below(i + 1));
            }
        }
    }

    /// Distinct, shuffled, non-sequential ids so that SoS order differs from input order.
    fn random_ids(n: usize, rng: &mut Rng) -> Vec<u64> {
        let mut ids: Vec<u64> = (0..n as u64).map(|i| i * 7919 + 13).collect();
        rng.shuffle(&mut ids);
        ids
    }

    fn id_triangles(tris: &[[u32; 3]], ids: &[u64]) -> Vec<[u64; 3]> {
        tris.iter().map(|t| t.map(|v| ids[v as usize])).collect()
    }

    /// Structural validity: positive CCW triangles, every point used, each edge shared by at
    /// most two oppositely oriented triangles, boundary edges on the convex hull, Euler count.
    /// Returns the number of hull vertices.
    fn check_triangulation(pts: &[[f64; 2]], tris: &[[u32; 3]]) -> usize {
        let n = pts.len();
        let p = |v: u32| pts[v as usize];
        let mut used = vec![false; n];
        let mut directed = HashSet::new();
        for t in tris {
            assert!(orient2d(p(t[0]), p(t[1]), p(t[2])) > 0.0, "not CCW: {t:?}");
            for i in 0..3 {
                used[t[i] as usize] = true;
                assert!(directed.insert((t[i], t[(i + 1) % 3])), "edge twice");
            }
        }
        assert!(used.iter().all(|&u| u), "a point is not a vertex");
        let hull: Vec<(u32, u32)> = directed
            .iter()
            .copied()
            .filter(|&(a, b)| !directed.contains(&(b, a)))
            .collect();
        let mut hull_vertices = HashSet::new();
        for &(a, b) in &hull {
            hull_vertices.insert(a);
            for q in pts {
                assert!(orient2d(p(a), p(b), *q) >= 0.0, "boundary edge not on hull");
            }
        }
        // The boundary is a single cycle: each hull vertex starts exactly one boundary edge.
        assert_eq!(hull_vertices.len(), hull.len());
        assert_eq!(tris.len(), 2 * n - 2 - hull.len(), "Euler count");
        hull.len()
    }

    /// Brute force: no point is inside any triangle's circumcircle (with SoS ties).
    fn check_empty_circles(pts: &[[f64; 2]], ids: &[u64], tris: &[[u32; 3]]) {
        for t in tris {
            let tv = t.map(|v| v as usize);
            for (q, &qid) in pts.iter().zip(ids) {
                if tv.iter().any(|&v| ids[v] == qid) {
                    continue;
                }
                let s = incircle_sos(
                    [pts[tv[0]], pts[tv[1]], pts[tv[2]], *q],
                    [ids[tv[0]], ids[tv[1]], ids[tv[2]], qid],
                );
                assert_eq!(s, -1, "point {qid} inside circle of {t:?}");
            }
        }
    }

    /// Local Delaunay test over every interior edge (equivalent to the global one); O(n).
    fn check_locally_delaunay(pts: &[[f64; 2]], ids: &[u64], tris: &[[u32; 3]]) {
        let mut opposite = HashMap::new();
        for t in tris {
            for i in 0..3 {
                opposite.insert((t[i], t[(i + 1) % 3]), t[(i + 2) % 3]);
            }
        }
        for (&(a, b), &c) in &opposite {
            if let Some(&d) = opposite.get(&(b, a)) {
                let q = [a, b, c, d].map(|v| v as usize);
                let s = incircle_sos(q.map(|v| pts[v]), q.map(|v| ids[v]));
                assert_eq!(s, -1, "edge {a}-{b} is not locally Delaunay");
            }
        }
    }

    fn check_output_order(ids: &[u64], tris: &[[u32; 3]]) {
        let by_id = id_triangles(tris, ids);
        for t in &by_id {
            assert!(t[0] < t[1] && t[0] < t[2], "smallest id not first");
        }
        assert!(by_id.windows(2).all(|w| w[0] < w[1]), "not sorted");
    }

    /// Full check, including that a shuffled input gives the same id triangles.
    fn check_all(pts: &[[f64; 2]], ids: &[u64], rng: &mut Rng, brute: bool) -> Vec<[u32; 3]> {
        let tris = delaunay(pts, ids).expect("triangulation");
        check_triangulation(pts, &tris);
        check_output_order(ids, &tris);
        check_locally_delaunay(pts, ids, &tris);
        if brute {
            check_empty_circles(pts, ids, &tris);
        }
        // Uniqueness: any insertion order gives the same triangulation.
        for _ in 0..3 {
            let mut order: Vec<u32> = (0..pts.len() as u32).collect();
            rng.shuffle(&mut order);
            let t2 = triangulate(pts, ids, &order).expect("triangulation");
            assert_eq!(t2, tris, "insertion order changed the triangulation");
        }
        for _ in 0..2 {
            let mut perm: Vec<usize> = (0..pts.len()).collect();
            rng.shuffle(&mut perm);
            let p2: Vec<[f64; 2]> = perm.iter().map(|&i| pts[i]).collect();
            let i2: Vec<u64> = perm.iter().map(|&i| ids[i]).collect();
            let t2 = delaunay(&p2, &i2).expect("triangulation");
            assert_eq!(id_triangles(&t2, &i2), id_triangles(&tris, ids));
        }
        tris
    }

    fn square_lattice(nx: usize, ny: usize, h: f64) -> Vec<[f64; 2]> {
        (0..nx * ny)
            .map(|k| [(k % nx) as f64 * h, (k / nx) as f64 * h])
            .collect()
    }

    #[test]
    fn random_clouds() {
        let mut rng = Rng(11);
        for &n in &[3usize, 4, 5, 10, 50, 400] {
            let pts: Vec<[f64; 2]> = (0..n).map(|_| [rng.unit(), rng.unit()]).collect();
            let ids = random_ids(n, &mut rng);
            check_all(&pts, &ids, &mut rng, true);
        }
    }

    #[test]
    fn square_lattices_are_fully_degenerate_but_unique() {
        let mut rng = Rng(12);
        for &(nx, ny) in &[(2usize, 2usize), (3, 3), (20, 20), (30, 4), (1, 2)] {
            let pts = square_lattice(nx, ny, 0.1);
            let sequential: Vec<u64> = (0..pts.len() as u64).collect();
            let shuffled = random_ids(pts.len(), &mut rng);
            for ids in [sequential, shuffled] {
                let tris = if nx * ny < 3 {
                    delaunay(&pts, &ids).expect("triangulation")
                } else {
                    check_all(&pts, &ids, &mut rng, true)
                };
                // Every cell is split into two right triangles: collinear hull rows stay
                // vertices and no sliver appears.
                assert_eq!(tris.len(), 2 * (nx - 1) * (ny - 1));
            }
        }
    }

    #[test]
    fn triangular_lattices() {
        let mut rng = Rng(13);
        // Exact integer version (many cocircular rectangles) and the rounded equilateral one.
        for exact in [true, false] {
            let (nx, ny) = (18, 15);
            let pts: Vec<[f64; 2]> = (0..nx * ny)
                .map(|k| {
                    let (i, j) = ((k % nx) as f64, (k / nx) as f64);
                    let shift = ((k / nx) % 2) as f64;
                    if exact {
                        [2.0 * i + shift, j]
                    } else {
                        [i + 0.5 * shift, j * 3f64.sqrt() / 2.0]
                    }
                })
                .collect();
            let ids = random_ids(pts.len(), &mut rng);
            check_all(&pts, &ids, &mut rng, true);
        }
    }

    #[test]
    fn jittered_lattices() {
        let mut rng = Rng(14);
        for &jitter in &[1e-13, 1e-9, 0.05, 0.3] {
            let pts: Vec<[f64; 2]> = square_lattice(20, 17, 1.0)
                .into_iter()
                .map(|p| {
                    [
                        p[0] + jitter * (rng.unit() - 0.5),
                        p[1] + jitter * (rng.unit() - 0.5),
                    ]
                })
                .collect();
            let ids = random_ids(pts.len(), &mut rng);
            check_all(&pts, &ids, &mut rng, true);
        }
    }

    #[test]
    fn clustered_clouds() {
        let mut rng = Rng(15);
        let mut pts = Vec::new();
        for c in 0..6 {
            let centre = [1e3 * rng.unit(), 1e3 * rng.unit()];
            let spread = 10f64.powi(-c - 1);
            for _ in 0..60 {
                pts.push([
                    centre[0] + spread * rng.normal(),
                    centre[1] + spread * rng.normal(),
                ]);
            }
        }
        let ids = random_ids(pts.len(), &mut rng);
        check_all(&pts, &ids, &mut rng, true);
    }

    #[test]
    fn random_points_on_a_small_integer_grid() {
        // Heavy collinearity and cocircularity at every scale.
        let mut rng = Rng(16);
        for round in 0..6 {
            let side = 6 + 4 * round;
            let mut cells: Vec<usize> = (0..side * side).collect();
            rng.shuffle(&mut cells);
            cells.truncate(side * side / 2);
            let pts: Vec<[f64; 2]> = cells
                .iter()
                .map(|&c| [(c % side) as f64, (c / side) as f64])
                .collect();
            let ids = random_ids(pts.len(), &mut rng);
            check_all(&pts, &ids, &mut rng, true);
        }
    }

    #[test]
    fn cocircular_points_with_centre() {
        let mut rng = Rng(17);
        // All 36 integer points on the circle x² + y² = 65², then with the centre added.
        let r = 65i64;
        let mut pts: Vec<[f64; 2]> = Vec::new();
        for x in -r..=r {
            for y in -r..=r {
                if x * x + y * y == r * r {
                    pts.push([x as f64, y as f64]);
                }
            }
        }
        assert_eq!(pts.len(), 36);
        let ids = random_ids(pts.len(), &mut rng);
        let tris = check_all(&pts, &ids, &mut rng, true);
        assert_eq!(tris.len(), 34);
        pts.push([0.0, 0.0]);
        let ids = random_ids(pts.len(), &mut rng);
        check_all(&pts, &ids, &mut rng, true);
    }

    #[test]
    fn collinear_and_tiny_inputs() {
        let line: Vec<[f64; 2]> = (0..10).map(|i| [i as f64, 2.0 * i as f64]).collect();
        let ids: Vec<u64> = (0..10).collect();
        assert_eq!(delaunay(&line, &ids), Ok(Vec::new()));
        assert_eq!(delaunay(&line[..2], &ids[..2]), Ok(Vec::new()));
        assert_eq!(delaunay(&[], &[]), Ok(Vec::new()));
        // A line plus one apex: a fan whose hull contains every point.
        let mut rng = Rng(18);
        let mut pts = line.clone();
        pts.push([-3.0, 5.0]);
        let ids: Vec<u64> = (0..11).rev().collect();
        let tris = check_all(&pts, &ids, &mut rng, true);
        assert_eq!(tris.len(), 9);
        // Collinear points given first must not trip up the seed triangle.
        let mut pts = line;
        pts.insert(0, [1.0, -7.0]);
        pts.push([20.0, 0.0]);
        let ids: Vec<u64> = (0..pts.len() as u64).collect();
        check_all(&pts, &ids, &mut rng, true);
    }

    #[test]
    fn invalid_inputs_are_reported() {
        let pts = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 0.0]];
        assert_eq!(
            delaunay(&pts, &[10, 42, 7, 3]),
            Err(DelaunayError::DuplicatePoint {
                first: 3,
                second: 42
            })
        );
        let signed_zero = [[0.0, 0.0], [1.0, 0.0], [-0.0, 0.0]];
        assert_eq!(
            delaunay(&signed_zero, &[1, 2, 3]),
            Err(DelaunayError::DuplicatePoint {
                first: 1,
                second: 3
            })
        );
        assert_eq!(
            delaunay(&pts[..3], &[5, 6, 5]),
            Err(DelaunayError::DuplicateId { id: 5 })
        );
        assert_eq!(
            delaunay(&[[0.0, f64::NAN], [1.0, 0.0], [0.0, 1.0]], &[8, 9, 10]),
            Err(DelaunayError::NonFinite { id: 8 })
        );
        assert_eq!(
            delaunay(&pts, &[1, 2]),
            Err(DelaunayError::LengthMismatch { points: 4, ids: 2 })
        );
        let msg = DelaunayError::DuplicatePoint {
            first: 3,
            second: 42,
        }
        .to_string();
        assert!(msg.contains('3') && msg.contains("42"));
    }

    #[test]
    fn large_random_cloud_is_valid() {
        let mut rng = Rng(19);
        let n = 20_000;
        let pts: Vec<[f64; 2]> = (0..n).map(|_| [rng.unit(), rng.unit()]).collect();
        let ids = random_ids(n, &mut rng);
        let tris = delaunay(&pts, &ids).expect("triangulation");
        check_triangulation(&pts, &tris);
        check_locally_delaunay(&pts, &ids, &tris);
        check_output_order(&ids, &tris);
    }

    #[test]
    fn large_lattice_is_valid() {
        let mut rng = Rng(20);
        let pts = square_lattice(120, 90, 0.01);
        let ids = random_ids(pts.len(), &mut rng);
        let tris = delaunay(&pts, &ids).expect("triangulation");
        assert_eq!(check_triangulation(&pts, &tris), 2 * (119 + 89));
        check_locally_delaunay(&pts, &ids, &tris);
        let mut order: Vec<u32> = (0..pts.len() as u32).collect();
        rng.shuffle(&mut order);
        assert_eq!(triangulate(&pts, &ids, &order), Ok(tris));
    }

    #[test]
    fn triangles_of_a_superset_survive_in_the_subset() {
        let mut rng = Rng(21);
        for round in 0..8 {
            // Integer-grid points: plenty of ties, so the SoS rule is what is being tested.
            let side = 16;
            let mut cells: Vec<usize> = (0..side * side).collect();
            rng.shuffle(&mut cells);
            cells.truncate(120 + 10 * round);
            let pts: Vec<[f64; 2]> = cells
                .iter()
                .map(|&c| [(c % side) as f64, (c / side) as f64])
                .collect();
            let ids = random_ids(pts.len(), &mut rng);
            let sup = delaunay(&pts, &ids).expect("superset");

            let keep: Vec<usize> = (0..pts.len()).filter(|_| rng.below(3) > 0).collect();
            let sub_pts: Vec<[f64; 2]> = keep.iter().map(|&i| pts[i]).collect();
            let sub_ids: Vec<u64> = keep.iter().map(|&i| ids[i]).collect();
            let sub: BTreeSet<[u64; 3]> =
                id_triangles(&delaunay(&sub_pts, &sub_ids).expect("subset"), &sub_ids)
                    .into_iter()
                    .collect();
            let in_sub: HashSet<u64> = sub_ids.iter().copied().collect();

            let mut checked = 0;
            for t in &sup {
                let tid = t.map(|v| ids[v as usize]);
                if !tid.iter().all(|i| in_sub.contains(i)) {
                    continue;
                }
                let empty = (0..pts.len()).all(|q| {
                    t.contains(&(q as u32))
                        || incircle_sos(
                            [
                                pts[t[0] as usize],
                                pts[t[1] as usize],
                                pts[t[2] as usize],
                                pts[q],
                            ],
                            [tid[0], tid[1], tid[2], ids[q]],
                        ) < 0
                });
                if empty {
                    assert!(sub.contains(&tid), "{tid:?} missing from subset");
                    checked += 1;
                }
            }
            assert!(checked > 10);
        }
    }

    #[test]
    fn ordered_bits_preserves_order_and_merges_signed_zeros() {
        let v = [
            f64::MIN,
            -1e300,
            -1.0,
            -1e-310,
            -0.0,
            0.0,
            1e-310,
            1.0,
            1e300,
            f64::MAX,
        ];
        for w in v.windows(2) {
            if w[0] == w[1] {
                assert_eq!(ordered_bits(w[0]), ordered_bits(w[1]));
            } else {
                assert!(ordered_bits(w[0]) < ordered_bits(w[1]), "{w:?}");
            }
        }
    }

    #[test]
    fn insertion_order_is_a_permutation() {
        let mut rng = Rng(22);
        let pts: Vec<[f64; 2]> = (0..1000).map(|_| [rng.unit(), rng.unit()]).collect();
        let ids = random_ids(pts.len(), &mut rng);
        let mut order = insertion_order(&pts, &ids);
        order.sort_unstable();
        assert!(order.iter().enumerate().all(|(i, &o)| o as usize == i));
    }

    #[test]
    fn hilbert_index_is_a_bijection_on_a_small_grid() {
        // On the top-level 2x2 quadrants the curve visits (0,0), (0,1), (1,1), (1,0).
        let h = 1u32 << 15;
        let order: Vec<u64> = [[0, 0], [0, h], [h, h], [h, 0]]
            .iter()
            .map(|c| hilbert_index(c[0], c[1]))
            .collect();
        assert!(order.windows(2).all(|w| w[0] < w[1]));
        let mut seen = HashSet::new();
        for x in 0..64 {
            for y in 0..64 {
                assert!(seen.insert(hilbert_index(x, y)));
            }
        }
    }
}
