//! Near-cocircular quads decided like exact ties.
//!
//! A lattice cell is four cocircular particles, and simulation of simplicity picks its diagonal by
//! global id. Once the lattice has moved, the cell is cocircular only up to the round-off of the
//! position updates, and the exact predicate then picks the diagonal by that round-off: a
//! homogeneously deforming lattice flipped hundreds of diagonals per step, and every flipped
//! triangle had its Gauss states re-interpolated. In a perfectly plastic body that re-interpolation
//! is what seeded shear bands. Here a quad whose in-circle determinant is below a relative
//! tolerance is given the diagonal that simulation of simplicity gives an exactly cocircular one,
//! so the mesh of a homogeneously deformed lattice is the mesh of the undeformed one.
//!
//! Decisions read only the quad's four points and ids, so the result is the same on every rank
//! that holds the quad: the mesh stays independent of the rank count.

use super::predicates::{orient2d, sos_tie_sign};
use std::collections::BTreeSet;

/// In-circle determinants within this fraction of their permanent (the sum of the absolute
/// products, Shewchuk's error-bound scale) count as ties. Round-off in moved positions is about
/// 1e-11 of the spacing; any physical departure from a rectangle this small is immaterial to
/// which diagonal the cell gets.
const TIE_TOLERANCE: f64 = 1e-8;

/// The in-circle sign with near ties broken as exact ones: `+1` if `d` counts as inside the circle
/// through counter-clockwise `a, b, c`. Whether the quad is a near tie is decided on the four
/// points taken in global-id order (the permanent depends on the reference corner), so both
/// diagonals of a quad, tested from either side, get one consistent answer.
fn incircle_near_sos(p: [[f64; 2]; 4], ids: [u64; 4]) -> i32 {
    let mut order = [0usize, 1, 2, 3];
    order.sort_unstable_by_key(|&i| ids[i]);
    let (det, permanent) = incircle_float(order.map(|i| p[i]));
    // Beyond the tolerance the floating-point sign is the exact one: its error bound is about
    // 1e-15 of the permanent.
    if det.abs() <= TIE_TOLERANCE * permanent {
        sos_tie_sign(p, ids)
    } else {
        // The determinant is alternating: reordering the points multiplies it by the parity.
        let sign = if det > 0.0 { 1 } else { -1 };
        sign * parity(order)
    }
}

/// The in-circle determinant of `p` in floating point, and its permanent.
fn incircle_float(p: [[f64; 2]; 4]) -> (f64, f64) {
    let [a, b, c, d] = p;
    let (adx, ady) = (a[0] - d[0], a[1] - d[1]);
    let (bdx, bdy) = (b[0] - d[0], b[1] - d[1]);
    let (cdx, cdy) = (c[0] - d[0], c[1] - d[1]);
    let (al, bl, cl) = (
        adx * adx + ady * ady,
        bdx * bdx + bdy * bdy,
        cdx * cdx + cdy * cdy,
    );
    let det =
        al * (bdx * cdy - cdx * bdy) + bl * (cdx * ady - adx * cdy) + cl * (adx * bdy - bdx * ady);
    let permanent = al * ((bdx * cdy).abs() + (cdx * bdy).abs())
        + bl * ((cdx * ady).abs() + (adx * cdy).abs())
        + cl * ((adx * bdy).abs() + (bdx * ady).abs());
    (det, permanent)
}

/// +1 for an even permutation, -1 for an odd one.
fn parity(order: [usize; 4]) -> i32 {
    let mut inversions = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            if order[i] > order[j] {
                inversions += 1;
            }
        }
    }
    if inversions % 2 == 0 {
        1
    } else {
        -1
    }
}

/// Flips the diagonals of near-cocircular convex quads of the Delaunay triangulation `tris`
/// (counter-clockwise, local indices into `points`) until every edge is legal under
/// [`incircle_near_sos`]. Edges are visited in global-id order (the two sides of one edge give
/// the same answer), so the flips do not depend on local indices. Returns `false`, with the exact
/// triangulation restored, if the flips do not settle (a cluster where the near-tie rule is
/// inconsistent); the caller must then keep the exact triangulation on every rank.
pub fn settle_near_ties(points: &[[f64; 2]], ids: &[u64], tris: &mut Vec<[u32; 3]>) -> bool {
    settle(points, ids, tris).is_some()
}

/// [`settle_near_ties`], returning the neighbour array it kept up to date (`None` if unsettled).
fn settle(points: &[[f64; 2]], ids: &[u64], tris: &mut Vec<[u32; 3]>) -> Option<Vec<[u32; 3]>> {
    let mut nbr = neighbours(tris);
    let edge = |t: usize, k: usize, tris: &[[u32; 3]]| {
        let (u, v) = (tris[t][k], tris[t][(k + 1) % 3]);
        let (gu, gv) = (ids[u as usize], ids[v as usize]);
        (gu.min(gv), gu.max(gv), t as u32, k as u8)
    };
    // Only an edge whose quad is a near tie can be illegal: the rest are exact Delaunay edges.
    let mut queue: BTreeSet<(u64, u64, u32, u8)> = BTreeSet::new();
    for t in 0..tris.len() {
        for k in 0..3 {
            let o = nbr[t][k];
            if o != NONE && (t as u32) < o && illegal(points, ids, tris, &nbr, t, k) {
                queue.insert(edge(t, k, tris));
            }
        }
    }
    if queue.is_empty() {
        return Some(nbr);
    }
    let original = tris.clone();
    let max_flips = 3 * tris.len() + 16;
    let mut flips = 0;
    while let Some((g0, g1, t, k)) = queue.pop_first() {
        let (t, k) = (t as usize, k as usize);
        // Stale entry: the triangle was flipped since; its edges were queued again then.
        if edge(t, k, tris).0 != g0 || edge(t, k, tris).1 != g1 || nbr[t][k] == NONE {
            continue;
        }
        if !illegal(points, ids, tris, &nbr, t, k) {
            continue;
        }
        flips += 1;
        if flips > max_flips {
            *tris = original;
            return None;
        }
        let (t1, t2) = flip(tris, &mut nbr, t, k);
        for (t, k) in [(t1, 0), (t1, 2), (t2, 0), (t2, 1)] {
            if nbr[t][k] != NONE {
                queue.insert(edge(t, k, tris));
            }
        }
    }
    Some(nbr)
}

const NONE: u32 = u32::MAX;

/// `nbr[t][k]`: the triangle across edge `tris[t][k] -> tris[t][k + 1]`, or `NONE` on the hull.
fn neighbours(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut half: Vec<(u64, u32)> = Vec::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (tri[k] as u64, tri[(k + 1) % 3] as u64);
            half.push(((u.min(v) << 32) | u.max(v), (3 * t + k) as u32));
        }
    }
    half.sort_unstable();
    let mut nbr = vec![[NONE; 3]; tris.len()];
    for w in half.windows(2) {
        if w[0].0 == w[1].0 {
            let (a, b) = (w[0].1 as usize, w[1].1 as usize);
            nbr[a / 3][a % 3] = (b / 3) as u32;
            nbr[b / 3][b % 3] = (a / 3) as u32;
        }
    }
    nbr
}

/// The quad of edge k of triangle t: `[u, v, c, d]` with `t = (u, v, c)` and d across the edge.
fn quad(tris: &[[u32; 3]], nbr: &[[u32; 3]], t: usize, k: usize) -> ([u32; 4], usize, usize) {
    let (u, v, c) = (tris[t][k], tris[t][(k + 1) % 3], tris[t][(k + 2) % 3]);
    let o = nbr[t][k] as usize;
    let j = (0..3).find(|&j| tris[o][j] == v);
    debug_assert!(
        j.is_some(),
        "neighbour {o} of triangle {t} lacks vertex {v}"
    );
    let j = j.unwrap_or(0);
    ([u, v, c, tris[o][(j + 2) % 3]], o, j)
}

/// Whether edge k of triangle t fails the near-tie in-circle test and its quad can be flipped.
fn illegal(
    points: &[[f64; 2]],
    ids: &[u64],
    tris: &[[u32; 3]],
    nbr: &[[u32; 3]],
    t: usize,
    k: usize,
) -> bool {
    let (q, _, _) = quad(tris, nbr, t, k);
    let p = q.map(|i| points[i as usize]);
    if incircle_near_sos(p, q.map(|i| ids[i as usize])) <= 0 {
        return false;
    }
    // u -> d -> v -> c is the quad counter-clockwise; the new diagonal c-d needs it convex.
    orient2d(p[0], p[3], p[2]) > 0.0 && orient2d(p[3], p[1], p[2]) > 0.0
}

/// Replaces edge u-v of t = (u, v, c) and its neighbour (v, u, d) by c-d: t becomes (u, d, c)
/// and the neighbour (d, v, c). Returns the two triangles' indices.
fn flip(tris: &mut [[u32; 3]], nbr: &mut [[u32; 3]], t: usize, k: usize) -> (usize, usize) {
    let ([u, v, c, d], o, j) = quad(tris, nbr, t, k);
    let n_ud = nbr[o][(j + 1) % 3];
    let n_dv = nbr[o][(j + 2) % 3];
    let n_vc = nbr[t][(k + 1) % 3];
    let n_cu = nbr[t][(k + 2) % 3];
    tris[t] = [u, d, c];
    nbr[t] = [n_ud, o as u32, n_cu];
    tris[o] = [d, v, c];
    nbr[o] = [n_dv, n_vc, t as u32];
    // The triangles across u-d and v-c now face the other of the pair.
    for (n, from, to) in [(n_ud, o, t), (n_vc, t, o)] {
        if n != NONE {
            for slot in nbr[n as usize].iter_mut() {
                if *slot == from as u32 {
                    *slot = to as u32;
                }
            }
        }
    }
    (t, o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::delaunay::delaunay;

    fn lattice(n: usize, mut map: impl FnMut([f64; 2]) -> [f64; 2]) -> (Vec<[f64; 2]>, Vec<u64>) {
        let mut pts = Vec::new();
        for j in 0..n {
            for i in 0..n {
                pts.push(map([i as f64 * 0.05, j as f64 * 0.05]));
            }
        }
        let ids = (0..pts.len() as u64)
            .map(|i| (i * 7919) % 1_000_003)
            .collect();
        (pts, ids)
    }

    fn sorted(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
        let mut v: Vec<[u32; 3]> = tris
            .iter()
            .map(|t| {
                let m = (0..3).min_by_key(|&k| t[k]).unwrap_or(0);
                [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
            })
            .collect();
        v.sort();
        v
    }

    /// Settled, with the neighbour array the flips kept equal to one built afresh; every triangle
    /// counter-clockwise, every directed edge used once, the same area as the exact
    /// triangulation, and no edge illegal from either side.
    fn check_settled(
        points: &[[f64; 2]],
        ids: &[u64],
        tris: &[[u32; 3]],
        exact: &[[u32; 3]],
        kept: Option<Vec<[u32; 3]>>,
    ) {
        let kept = kept.expect("the flips should settle");
        assert_eq!(kept, neighbours(tris), "neighbour array out of date");
        let area = |ts: &[[u32; 3]]| -> f64 {
            ts.iter()
                .map(|t| {
                    orient2d(
                        points[t[0] as usize],
                        points[t[1] as usize],
                        points[t[2] as usize],
                    )
                })
                .sum()
        };
        for t in tris {
            assert!(
                orient2d(
                    points[t[0] as usize],
                    points[t[1] as usize],
                    points[t[2] as usize]
                ) > 0.0
            );
        }
        assert!((area(tris) - area(exact)).abs() <= 1e-12 * area(exact));
        let nbr = neighbours(tris);
        let mut directed = std::collections::HashSet::new();
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                assert!(
                    directed.insert((tri[k], tri[(k + 1) % 3])),
                    "edge used twice"
                );
                if nbr[t][k] != NONE {
                    assert!(!illegal(points, ids, tris, &nbr, t, k), "illegal edge left");
                }
            }
        }
    }

    /// A ring of near-cocircular points inside a second ring: every quad of the inner ring is a
    /// near tie, so the noisy exact triangulation needs cascading flips, and the result must be
    /// the one the noise-free ring gets (whose cos/sin round-off is itself a near tie).
    #[test]
    fn a_noisy_ring_settles_to_the_clean_ring() {
        let n = 16;
        let mut state = 9u64;
        let ring = |noise: f64, state: &mut u64| -> Vec<[f64; 2]> {
            let mut pts = Vec::new();
            for (r, turn) in [(1.0, 0.0), (2.0, 0.5)] {
                for i in 0..n {
                    let a = (i as f64 + turn) * std::f64::consts::TAU / n as f64;
                    let e = ((crate::rng::next(state) % 2001) as f64 - 1000.0) * noise;
                    let rr = if r == 1.0 { r * (1.0 + e) } else { r };
                    pts.push([0.3 + rr * a.cos(), -0.2 + rr * a.sin()]);
                }
            }
            pts
        };
        let ids: Vec<u64> = (0..2 * n as u64).map(|i| (i * 7919) % 1_000_003).collect();
        let clean = ring(0.0, &mut state);
        let noisy = ring(1e-13, &mut state);
        let mut settled_clean = delaunay(&clean, &ids).unwrap();
        let exact_clean = settled_clean.clone();
        let kept = settle(&clean, &ids, &mut settled_clean);
        check_settled(&clean, &ids, &settled_clean, &exact_clean, kept);
        let exact = delaunay(&noisy, &ids).unwrap();
        let mut settled = exact.clone();
        let kept = settle(&noisy, &ids, &mut settled);
        check_settled(&noisy, &ids, &settled, &exact, kept);
        assert_eq!(sorted(&settled), sorted(&settled_clean));
        assert_ne!(
            sorted(&exact),
            sorted(&settled),
            "the noise should need flips"
        );
    }

    /// A stretched lattice with round-off noise in its positions gets the undeformed lattice's
    /// triangles back; without the near-tie rule the noise flips many of its diagonals.
    #[test]
    fn a_noisy_stretched_lattice_keeps_the_lattice_mesh() {
        let (p0, ids) = lattice(21, |p| p);
        let mut reference = delaunay(&p0, &ids).unwrap();
        assert!(settle_near_ties(&p0, &ids, &mut reference));
        let mut state = 7u64;
        let (p1, _) = lattice(21, |p| {
            let noise = (crate::rng::next(&mut state) % 1000) as f64 * 1e-15 - 5e-13;
            [p[0] * 1.6 + 0.3 + noise, p[1] * 0.625 - 0.1 - noise]
        });
        let exact = delaunay(&p1, &ids).unwrap();
        let mut settled = exact.clone();
        let kept = settle(&p1, &ids, &mut settled);
        check_settled(&p1, &ids, &settled, &exact, kept);
        // The noisy hull gains slivers (the alpha shape drops them); every lattice triangle
        // must be back.
        let (settled, exact) = (sorted(&settled), sorted(&exact));
        let missing = |tris: &Vec<[u32; 3]>| {
            sorted(&reference)
                .iter()
                .filter(|t| tris.binary_search(t).is_err())
                .count()
        };
        assert_eq!(missing(&settled), 0);
        assert!(
            missing(&exact) > 100,
            "the noise flips many cells: {}",
            missing(&exact)
        );
    }

    /// A rank meshes a window of the cloud (owned particles plus halo): the settled triangles well
    /// inside the window are the settled triangles of the whole cloud.
    #[test]
    fn a_window_settles_like_the_whole_cloud() {
        let mut state = 11u64;
        let (p, ids) = lattice(31, |p| {
            let noise = (crate::rng::next(&mut state) % 1000) as f64 * 1e-15 - 5e-13;
            [p[0] * 1.3 + noise, p[1] * 0.77 + noise]
        });
        let mut whole = delaunay(&p, &ids).unwrap();
        settle_near_ties(&p, &ids, &mut whole);
        let key = |t: &[u32; 3], idx: &[usize]| {
            let mut k = t.map(|v| ids[idx[v as usize]]);
            k.sort();
            k
        };
        let all: Vec<usize> = (0..p.len()).collect();
        let global: std::collections::HashSet<[u64; 3]> =
            whole.iter().map(|t| key(t, &all)).collect();
        let inside = |q: [f64; 2], m: f64| {
            q[0] > 0.3 + m && q[0] < 1.2 - m && q[1] > 0.2 + m && q[1] < 0.8 - m
        };
        let window: Vec<usize> = (0..p.len()).filter(|&i| inside(p[i], 0.0)).collect();
        let wp: Vec<[f64; 2]> = window.iter().map(|&i| p[i]).collect();
        let wid: Vec<u64> = window.iter().map(|&i| ids[i]).collect();
        let exact = delaunay(&wp, &wid).unwrap();
        let mut local = exact.clone();
        let kept = settle(&wp, &wid, &mut local);
        check_settled(&wp, &wid, &local, &exact, kept);
        assert_ne!(
            sorted(&local),
            sorted(&exact),
            "the noise should need flips"
        );
        let mut checked = 0;
        for t in &local {
            if t.iter().all(|&v| inside(wp[v as usize], 0.1)) {
                assert!(global.contains(&key(t, &window)), "triangle {t:?} differs");
                checked += 1;
            }
        }
        assert!(checked > 100, "checked {checked}");
    }

    /// Timing, not a check: `cargo test --release --lib meshing_timing -- --ignored --nocapture`.
    #[test]
    #[ignore = "timing study of Delaunay on 100 000 points, run with the coarse benchmarks"]
    fn meshing_timing() {
        let mut state = 5u64;
        let mut unit = || (crate::rng::next(&mut state) >> 11) as f64 / (1u64 << 53) as f64;
        let random: Vec<[f64; 2]> = (0..100_000).map(|_| [unit(), unit()]).collect();
        let (lat, lat_ids) = lattice(316, |p| p);
        for (name, p, ids) in [
            (
                "100 k random",
                random,
                (0..100_000u64).collect::<Vec<u64>>(),
            ),
            ("316 x 316 lattice", lat, lat_ids),
        ] {
            let t0 = std::time::Instant::now();
            let mut tris = delaunay(&p, &ids).unwrap();
            let t1 = std::time::Instant::now();
            assert!(settle_near_ties(&p, &ids, &mut tris));
            let t2 = std::time::Instant::now();
            println!(
                "{name}: Delaunay {:.3} s, near-tie pass {:.3} s",
                (t1 - t0).as_secs_f64(),
                (t2 - t1).as_secs_f64()
            );
        }
    }

    /// A jittered cloud has no near ties: its Delaunay triangulation is left alone.
    #[test]
    fn a_jittered_cloud_is_unchanged() {
        let mut state = 3u64;
        let (p, ids) = lattice(15, |p| {
            let mut r = || (crate::rng::next(&mut state) % 10_000) as f64 / 10_000.0 - 0.5;
            [p[0] + 0.02 * r(), p[1] + 0.02 * r()]
        });
        let exact = delaunay(&p, &ids).unwrap();
        let mut settled = exact.clone();
        assert!(settle_near_ties(&p, &ids, &mut settled));
        assert_eq!(settled, exact);
    }
}
