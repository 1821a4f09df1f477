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

use super::predicates::{incircle, orient2d, sos_tie_sign};
use std::collections::{BTreeSet, HashMap};

/// In-circle determinants within this fraction of their permanent (the sum of the absolute
/// products, Shewchuk's error-bound scale) count as ties. Round-off in moved positions is about
/// 1e-11 of the spacing; any physical departure from a rectangle this small is immaterial to
/// which diagonal the cell gets.
pub const TIE_TOLERANCE: f64 = 1e-8;

/// The in-circle sign with near ties broken as exact ones: `+1` if `d` counts as inside the circle
/// through counter-clockwise `a, b, c`.
pub fn incircle_near_sos(p: [[f64; 2]; 4], ids: [u64; 4]) -> i32 {
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
    if det.abs() <= TIE_TOLERANCE * permanent {
        return sos_tie_sign(p, ids);
    }
    let exact = incircle(a, b, c, d);
    if exact > 0.0 {
        1
    } else if exact < 0.0 {
        -1
    } else {
        sos_tie_sign(p, ids)
    }
}

/// Flips the diagonals of near-cocircular convex quads of the Delaunay triangulation `tris`
/// (counter-clockwise, local indices into `points`) until every edge is legal under
/// [`incircle_near_sos`]. Edges are visited in global-id order. If the flips do not settle (a
/// configuration where the near-tie rule is inconsistent), the exact triangulation is kept.
pub fn settle_near_ties(points: &[[f64; 2]], ids: &[u64], tris: &mut Vec<[u32; 3]>) {
    let original = tris.clone();
    let mut across: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            across.insert((tri[k], tri[(k + 1) % 3]), t);
        }
    }
    let edge_key = |u: u32, v: u32| {
        let (gu, gv) = (ids[u as usize], ids[v as usize]);
        if gu < gv {
            (gu, gv, u, v)
        } else {
            (gv, gu, v, u)
        }
    };
    let mut queue: BTreeSet<(u64, u64, u32, u32)> = BTreeSet::new();
    for tri in tris.iter() {
        for k in 0..3 {
            queue.insert(edge_key(tri[k], tri[(k + 1) % 3]));
        }
    }
    let max_flips = 3 * tris.len() + 16;
    let mut flips = 0;
    while let Some(e) = queue.pop_first() {
        let (u, v) = (e.2, e.3);
        // t1 holds u -> v, t2 holds v -> u; either orientation may be the stored one.
        let (Some(&t1), Some(&t2)) = (across.get(&(u, v)), across.get(&(v, u))) else {
            continue;
        };
        let c = third(tris[t1], u, v);
        let d = third(tris[t2], v, u);
        let quad = [u, v, c, d];
        let pts = quad.map(|i| points[i as usize]);
        if incircle_near_sos(pts, quad.map(|i| ids[i as usize])) <= 0 {
            continue;
        }
        // u -> d -> v -> c is the quad counter-clockwise; the new diagonal is c-d.
        let (pu, pv, pc, pd) = (pts[0], pts[1], pts[2], pts[3]);
        if orient2d(pu, pd, pc) <= 0.0 || orient2d(pd, pv, pc) <= 0.0 {
            continue;
        }
        flips += 1;
        if flips > max_flips {
            *tris = original;
            return;
        }
        for (t, tri) in [(t1, tris[t1]), (t2, tris[t2])] {
            for k in 0..3 {
                if across.get(&(tri[k], tri[(k + 1) % 3])) == Some(&t) {
                    across.remove(&(tri[k], tri[(k + 1) % 3]));
                }
            }
        }
        tris[t1] = [u, d, c];
        tris[t2] = [d, v, c];
        for t in [t1, t2] {
            let tri = tris[t];
            for k in 0..3 {
                across.insert((tri[k], tri[(k + 1) % 3]), t);
            }
        }
        for (a, b) in [(u, d), (d, v), (v, c), (c, u)] {
            queue.insert(edge_key(a, b));
        }
    }
}

/// The vertex of counter-clockwise `tri` opposite its directed edge `u -> v`.
fn third(tri: [u32; 3], u: u32, v: u32) -> u32 {
    let k = (0..3)
        .find(|&k| tri[k] == u && tri[(k + 1) % 3] == v)
        .unwrap_or(0);
    tri[(k + 2) % 3]
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
        let ids = (0..pts.len() as u64).map(|i| (i * 7919) % 10007).collect();
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

    /// A stretched lattice with round-off noise in its positions gets the undeformed lattice's
    /// triangles back; without the near-tie rule the noise flips many of its diagonals.
    #[test]
    fn a_noisy_stretched_lattice_keeps_the_lattice_mesh() {
        let (p0, ids) = lattice(21, |p| p);
        let mut reference = delaunay(&p0, &ids).unwrap();
        settle_near_ties(&p0, &ids, &mut reference);
        let mut state = 7u64;
        let (p1, _) = lattice(21, |p| {
            let noise = (crate::rng::next(&mut state) % 1000) as f64 * 1e-15 - 5e-13;
            [p[0] * 1.6 + 0.3 + noise, p[1] * 0.625 - 0.1 - noise]
        });
        let exact = delaunay(&p1, &ids).unwrap();
        let mut settled = exact.clone();
        settle_near_ties(&p1, &ids, &mut settled);
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
        settle_near_ties(&p, &ids, &mut settled);
        assert_eq!(settled, exact);
    }
}
