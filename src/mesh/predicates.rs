//! Exact geometric predicates for the particle mesher.
//!
//! [`orient2d`] and [`incircle`] are Shewchuk's adaptive exact predicates (via the `robust`
//! crate): the *sign* of the returned value is always the sign of the exact determinant of
//! the `f64` inputs, so no epsilon is ever needed. Inputs must be finite and small enough
//! that the products of degree 4 in coordinate differences neither overflow nor underflow.
//!
//! [`incircle_sos`] adds *simulation of simplicity* so that cocircular points never produce
//! a tie; this is what makes the Delaunay triangulation of any point set unique.
//!
//! # Simulation-of-simplicity convention
//!
//! The in-circle determinant is the 4x4 determinant
//!
//! ```text
//!            | ax  ay  ax²+ay²  1 |
//! D(a,b,c,d) | bx  by  bx²+by²  1 |   > 0  iff  d is inside the circle through a, b, c
//!          = | cx  cy  cx²+cy²  1 |             when a, b, c are counter-clockwise.
//!            | dx  dy  dx²+dy²  1 |
//! ```
//!
//! Each point `p` with global id `id(p)` is lifted to height `px²+py² + ε^(k(p))`, where
//! `ε > 0` is infinitesimal and `k(p)` is the rank of `id(p)` among *all* ids, in
//! *decreasing* order: the point with the largest id gets the largest (most significant)
//! perturbation `ε^0`-like term, the next largest id the next one, and so on. Raising a
//! point's lift moves it outside every circle, so among tied points the larger id "loses"
//! first. Expanding `D` along the lifted column, the coefficient of the perturbation of
//! each point is its cofactor:
//!
//! ```text
//! coefficient of ε_a = +orient2d(b, c, d)      coefficient of ε_c = +orient2d(a, b, d)
//! coefficient of ε_b = -orient2d(a, c, d)      coefficient of ε_d = -orient2d(a, b, c)
//! ```
//!
//! When the exact `D` is zero, the result is the sign of the first non-zero coefficient,
//! taking the points in order of decreasing id. Orientation itself is never perturbed:
//! [`orient2d`] returns exactly 0 for collinear points.
//!
//! The perturbation depends only on the ids, never on argument order, so permuting the four
//! arguments (together with their ids) changes the result exactly by the parity of the
//! permutation, as for the exact determinant.

use robust::Coord;

#[inline]
fn coord(p: [f64; 2]) -> Coord<f64> {
    Coord { x: p[0], y: p[1] }
}

/// Twice the signed area of triangle `(a, b, c)`.
///
/// The sign is exact: positive if `a, b, c` are counter-clockwise (`c` left of `a → b`),
/// negative if clockwise, and exactly `0.0` if the three points are collinear. The magnitude
/// is an accurate approximation of the determinant.
#[inline]
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    robust::orient2d(coord(a), coord(b), coord(c))
}

/// Exact in-circle test without tie breaking.
///
/// Positive if `d` lies strictly inside the circle through `a, b, c` when `a, b, c` are
/// counter-clockwise (the sign flips if they are clockwise), negative if strictly outside,
/// exactly `0.0` if the four points are cocircular (or `a, b, c` are collinear and `d` is on
/// their line). The sign is that of the determinant `D(a, b, c, d)` in the module docs.
#[inline]
pub fn incircle(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> f64 {
    robust::incircle(coord(a), coord(b), coord(c), coord(d))
}

/// In-circle test with simulation-of-simplicity tie breaking by global particle id.
///
/// `p = [a, b, c, d]` with their global ids `ids`. Returns `+1` if `d` is inside the circle
/// through `a, b, c` (for counter-clockwise `a, b, c`; reversed for clockwise), `-1` if
/// outside. Exact ties (cocircular points) are resolved by the lifted-height perturbation
/// described in the module docs: the largest id is perturbed most, perturbations raise the
/// lift, and the result is the sign of the first non-zero cofactor in decreasing-id order.
///
/// Returns `0` only if all four points are collinear, which a triangulation never asks.
/// The four ids must be distinct and the four points pairwise distinct.
pub fn incircle_sos(p: [[f64; 2]; 4], ids: [u64; 4]) -> i32 {
    let det = incircle(p[0], p[1], p[2], p[3]);
    if det > 0.0 {
        return 1;
    }
    if det < 0.0 {
        return -1;
    }
    sos_tie_sign(p, ids)
}

/// The sign [`incircle_sos`] gives four points as if they were exactly cocircular: the first
/// non-zero lifted cofactor in decreasing-id order (`0` only if all four are collinear).
pub fn sos_tie_sign(p: [[f64; 2]; 4], ids: [u64; 4]) -> i32 {
    let mut by_id = [0usize, 1, 2, 3];
    by_id.sort_unstable_by(|&i, &j| ids[j].cmp(&ids[i]));
    for i in by_id {
        let c = lift_cofactor(p, i);
        if c > 0.0 {
            return 1;
        }
        if c < 0.0 {
            return -1;
        }
    }
    0
}

/// Cofactor of the lifted coordinate of point `i` in `D(p0, p1, p2, p3)`.
fn lift_cofactor(p: [[f64; 2]; 4], i: usize) -> f64 {
    match i {
        0 => orient2d(p[1], p[2], p[3]),
        1 => -orient2d(p[0], p[2], p[3]),
        2 => orient2d(p[0], p[1], p[3]),
        _ => -orient2d(p[0], p[1], p[2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic test randomness (SplitMix64, `crate::rng`).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            crate::rng::next(&mut self.0)
        }
        fn int(&mut self, lo: i64, hi: i64) -> i64 {
            lo + (self.next() % ((hi - lo + 1) as u64)) as i64
        }
    }

    fn sign_i128(v: i128) -> i32 {
        v.signum() as i32
    }

    fn sign_f64(v: f64) -> i32 {
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    }

    fn orient_exact(a: [i64; 2], b: [i64; 2], c: [i64; 2]) -> i128 {
        let (abx, aby) = ((b[0] - a[0]) as i128, (b[1] - a[1]) as i128);
        let (acx, acy) = ((c[0] - a[0]) as i128, (c[1] - a[1]) as i128);
        abx * acy - aby * acx
    }

    /// `D(a, b, c, d)` with lifted heights `scale * |p|² + pert[i]`, exactly.
    fn incircle_exact(p: [[i64; 2]; 4], scale: i128, pert: [i128; 4]) -> i128 {
        let lift = |i: usize| {
            let (x, y) = (p[i][0] as i128, p[i][1] as i128);
            scale * (x * x + y * y) + pert[i]
        };
        let d = 3;
        let row = |i: usize| {
            [
                (p[i][0] - p[d][0]) as i128,
                (p[i][1] - p[d][1]) as i128,
                lift(i) - lift(d),
            ]
        };
        let (r0, r1, r2) = (row(0), row(1), row(2));
        r0[0] * (r1[1] * r2[2] - r1[2] * r2[1]) - r0[1] * (r1[0] * r2[2] - r1[2] * r2[0])
            + r0[2] * (r1[0] * r2[1] - r1[1] * r2[0])
    }

    fn to_f64(p: [i64; 2]) -> [f64; 2] {
        [p[0] as f64, p[1] as f64]
    }

    /// Integer points on the circle of radius 5 centred at `c`.
    fn circle5(c: [i64; 2]) -> Vec<[i64; 2]> {
        let offs = [
            [5, 0],
            [4, 3],
            [3, 4],
            [0, 5],
            [-3, 4],
            [-4, 3],
            [-5, 0],
            [-4, -3],
            [-3, -4],
            [0, -5],
            [3, -4],
            [4, -3],
        ];
        offs.iter().map(|o| [c[0] + o[0], c[1] + o[1]]).collect()
    }

    #[test]
    fn orient2d_matches_exact_on_random_and_collinear() {
        let mut rng = Rng(1);
        for _ in 0..20_000 {
            let p: Vec<[i64; 2]> = (0..3)
                .map(|_| [rng.int(-1000, 1000), rng.int(-1000, 1000)])
                .collect();
            let exact = sign_i128(orient_exact(p[0], p[1], p[2]));
            assert_eq!(
                sign_f64(orient2d(to_f64(p[0]), to_f64(p[1]), to_f64(p[2]))),
                exact
            );
        }
        for _ in 0..5_000 {
            let a = [rng.int(-1000, 1000), rng.int(-1000, 1000)];
            let d = [rng.int(-20, 20), rng.int(-20, 20)];
            let (s, t) = (rng.int(-40, 40), rng.int(-40, 40));
            let b = [a[0] + s * d[0], a[1] + s * d[1]];
            let c = [a[0] + t * d[0], a[1] + t * d[1]];
            assert_eq!(orient2d(to_f64(a), to_f64(b), to_f64(c)), 0.0);
        }
    }

    #[test]
    fn orient2d_exact_with_large_offset_dyadic_coordinates() {
        // Coordinates 1e6 + k·2⁻²⁰ are exact in f64; a naive determinant loses the sign.
        let mut rng = Rng(2);
        let base = 1.0e6;
        let unit = 2f64.powi(-20);
        for _ in 0..20_000 {
            let p: Vec<[i64; 2]> = (0..3)
                .map(|_| [rng.int(-50, 50), rng.int(-50, 50)])
                .collect();
            let f = |q: [i64; 2]| [base + q[0] as f64 * unit, base + q[1] as f64 * unit];
            let exact = sign_i128(orient_exact(p[0], p[1], p[2]));
            assert_eq!(sign_f64(orient2d(f(p[0]), f(p[1]), f(p[2]))), exact);
        }
    }

    #[test]
    fn incircle_matches_exact_on_random_and_cocircular() {
        let mut rng = Rng(3);
        for _ in 0..20_000 {
            let p = [(); 4].map(|_| [rng.int(-300, 300), rng.int(-300, 300)]);
            let exact = sign_i128(incircle_exact(p, 1, [0; 4]));
            let got = incircle(to_f64(p[0]), to_f64(p[1]), to_f64(p[2]), to_f64(p[3]));
            assert_eq!(sign_f64(got), exact);
        }
        for _ in 0..5_000 {
            let c = [rng.int(-1000, 1000), rng.int(-1000, 1000)];
            let circ = circle5(c);
            let p = [(); 4].map(|_| circ[rng.next() as usize % circ.len()]);
            assert_eq!(incircle_exact(p, 1, [0; 4]), 0);
            let got = incircle(to_f64(p[0]), to_f64(p[1]), to_f64(p[2]), to_f64(p[3]));
            assert_eq!(got, 0.0);
        }
    }

    #[test]
    fn incircle_exact_with_large_offset_dyadic_coordinates() {
        let mut rng = Rng(4);
        let base = 3.0e5;
        let unit = 2f64.powi(-24);
        for _ in 0..20_000 {
            // Half the quads are cocircular, the rest are random near-degenerate ones.
            let p = if rng.next().is_multiple_of(2) {
                let circ = circle5([rng.int(-20, 20), rng.int(-20, 20)]);
                [(); 4].map(|_| circ[rng.next() as usize % circ.len()])
            } else {
                [(); 4].map(|_| [rng.int(-30, 30), rng.int(-30, 30)])
            };
            let f = |q: [i64; 2]| [base + q[0] as f64 * unit, base - q[1] as f64 * unit];
            // The y flip mirrors the configuration, which negates the determinant.
            let exact = -sign_i128(incircle_exact(p, 1, [0; 4]));
            assert_eq!(
                sign_f64(incircle(f(p[0]), f(p[1]), f(p[2]), f(p[3]))),
                exact
            );
        }
    }

    /// Reference SoS: the lifted heights are really perturbed, in exact integer arithmetic.
    /// With coordinates in [-8, 8] every cofactor is below 2¹⁰, so scaling the lift by B⁴ and
    /// adding Bʳ (r = rank of the id, largest id → r = 3) with B = 2¹² keeps every
    /// perturbation term strictly dominated by the next more significant one.
    fn incircle_sos_reference(p: [[i64; 2]; 4], ids: [u64; 4]) -> i32 {
        let b: i128 = 1 << 12;
        let mut pert = [0i128; 4];
        for i in 0..4 {
            let rank = ids.iter().filter(|&&o| o < ids[i]).count() as u32;
            pert[i] = b.pow(rank);
        }
        sign_i128(incircle_exact(p, b.pow(4), pert))
    }

    fn distinct_ids(rng: &mut Rng) -> [u64; 4] {
        loop {
            let ids = [(); 4].map(|_| rng.next() % 10);
            let mut s = ids;
            s.sort_unstable();
            if s.windows(2).all(|w| w[0] != w[1]) {
                return ids;
            }
        }
    }

    fn distinct_points(rng: &mut Rng, pick: &mut dyn FnMut(&mut Rng) -> [i64; 2]) -> [[i64; 2]; 4] {
        loop {
            let p = [(); 4].map(|_| pick(rng));
            let mut s = p;
            s.sort_unstable();
            if s.windows(2).all(|w| w[0] != w[1]) {
                return p;
            }
        }
    }

    #[test]
    fn incircle_sos_matches_perturbed_exact_determinant() {
        let mut rng = Rng(5);
        let mut ties = 0;
        for k in 0..40_000 {
            let p = if k % 2 == 0 {
                distinct_points(&mut rng, &mut |r| [r.int(-3, 3), r.int(-3, 3)])
            } else {
                let circ = circle5([0, 0]);
                distinct_points(&mut rng, &mut |r| circ[r.next() as usize % circ.len()])
            };
            let ids = distinct_ids(&mut rng);
            let all_collinear = orient_exact(p[0], p[1], p[2]) == 0
                && orient_exact(p[0], p[1], p[3]) == 0
                && orient_exact(p[0], p[2], p[3]) == 0;
            if incircle_exact(p, 1, [0; 4]) == 0 {
                ties += 1;
            }
            let got = incircle_sos(p.map(to_f64), ids);
            if all_collinear {
                assert_eq!(got, 0);
            } else {
                assert_eq!(got, incircle_sos_reference(p, ids), "{p:?} {ids:?}");
            }
        }
        assert!(ties > 10_000, "test must exercise many ties, got {ties}");
    }

    fn permutations() -> Vec<([usize; 4], i32)> {
        let mut out = Vec::new();
        for a in 0..4 {
            for b in 0..4 {
                for c in 0..4 {
                    for d in 0..4 {
                        let q = [a, b, c, d];
                        let mut s = q;
                        s.sort_unstable();
                        if s != [0, 1, 2, 3] {
                            continue;
                        }
                        let mut inversions = 0;
                        for i in 0..4 {
                            for j in i + 1..4 {
                                if q[i] > q[j] {
                                    inversions += 1;
                                }
                            }
                        }
                        out.push((q, if inversions % 2 == 0 { 1 } else { -1 }));
                    }
                }
            }
        }
        out
    }

    #[test]
    fn incircle_sos_is_consistent_under_permutation() {
        let mut rng = Rng(6);
        let perms = permutations();
        assert_eq!(perms.len(), 24);
        for k in 0..5_000 {
            let p = if k % 2 == 0 {
                let (x, y) = (rng.int(-100, 100) as f64, rng.int(-100, 100) as f64);
                let s = rng.int(1, 5) as f64;
                [[x, y], [x + s, y], [x + s, y + s], [x, y + s]]
            } else {
                distinct_points(&mut rng, &mut |r| [r.int(-3, 3), r.int(-3, 3)]).map(to_f64)
            };
            let ids = distinct_ids(&mut rng);
            let base = incircle_sos(p, ids);
            for (q, parity) in &perms {
                let pp = q.map(|i| p[i]);
                let ii = q.map(|i| ids[i]);
                assert_eq!(incircle_sos(pp, ii), parity * base);
            }
        }
    }

    #[test]
    fn cocircular_square_gets_exactly_one_diagonal() {
        let mut rng = Rng(7);
        for _ in 0..5_000 {
            let (x, y) = (rng.int(-1000, 1000) as f64, rng.int(-1000, 1000) as f64);
            let s = rng.int(1, 9) as f64 * 0.125;
            // Counter-clockwise unit cell a, b, c, d.
            let p = [[x, y], [x + s, y], [x + s, y + s], [x, y + s]];
            let ids = distinct_ids(&mut rng);
            let [a, b, c, d] = [0usize, 1, 2, 3];
            let t = |i: usize, j: usize, k: usize, l: usize| {
                incircle_sos([p[i], p[j], p[k], p[l]], [ids[i], ids[j], ids[k], ids[l]])
            };
            // Diagonal ac: triangles abc and acd, each with the fourth point outside.
            let diag_ac = t(a, b, c, d) < 0 && t(a, c, d, b) < 0;
            // Diagonal bd: triangles abd and bcd.
            let diag_bd = t(a, b, d, c) < 0 && t(b, c, d, a) < 0;
            assert!(diag_ac ^ diag_bd, "{p:?} {ids:?}");
            // The largest id is raised most, so it is outside the circle of the other three
            // and the chosen diagonal avoids it.
            let max = (0..4).max_by_key(|&i| ids[i]).unwrap_or(0);
            assert_eq!(diag_ac, max == b || max == d);
        }
    }

    #[test]
    fn orientation_is_not_perturbed() {
        assert_eq!(orient2d([0.0, 0.0], [1.0, 1.0], [3.0, 3.0]), 0.0);
        assert_eq!(
            incircle_sos(
                [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [5.0, 0.0]],
                [1, 2, 3, 4]
            ),
            0
        );
        assert!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]) > 0.0);
        assert!(incircle([0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.1, 0.1]) > 0.0);
    }
}
