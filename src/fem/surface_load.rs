//! Uniform follower pressure on one quadratic (P2) boundary edge, with its consistent tangent.
//!
//! Edge nodes `[a, m, b]`: vertex a, midside node m, vertex b, ordered so that the body lies on
//! the LEFT when walking from a to b (outer boundaries run counter-clockwise). The edge is
//! x(s) = N_a x_a + N_m x_m + N_b x_b, s ∈ [-1, 1], with N_a = s(s-1)/2, N_m = 1 - s²,
//! N_b = s(s+1)/2. The midside node may lie off the chord (curved edge).
//!
//! The pressure p (compression positive) acts on the CURRENT edge: traction t = -p n_out with
//! n_out dΓ = (x'_y, -x'_x) ds, so
//!   f_i = -p ∫ N_i (x'_y, -x'_x) ds = -p Σ_j C_ij (y_j, -x_j),   C_ij = ∫_{-1}^{1} N_i N_j' ds.
//! N_i N_j' is a cubic, so the 2-point Gauss rule is already exact; rather than loop over points
//! we use the rule's result in closed form ([`EDGE_C`]). It is checked against 3-point Gauss in
//! the tests.
//!
//! In 2D n_out dΓ is linear in the positions, so the force is linear in u and the tangent is
//! constant (depends only on p). It is NOT symmetric for a single edge: C + Cᵀ = diag(-1, 0, 1),
//! i.e. the skew part lives on the end vertices and cancels between neighbouring edges carrying
//! the same pressure (closed boundary, or equal pressure on both sides of a vertex). With a
//! pressure jump at a vertex, or a loaded edge ending at a free vertex, the Jacobian is
//! genuinely non-symmetric.
//!
//! Pure numerics: no MPI, no PETSc.

// Matrix code indexes rows and columns together.
#![allow(clippy::needless_range_loop)]

use crate::fem::analysis::Analysis;

/// C_ij = ∫_{-1}^{1} N_i(s) N_j'(s) ds for the node order [a, m, b]. Rows sum to zero (a rigid
/// translation does not change the load); C + Cᵀ = diag(-1, 0, 1) = [N_i N_j] from -1 to 1.
const EDGE_C: [[f64; 3]; 3] = [
    [-1.0 / 2.0, 2.0 / 3.0, -1.0 / 6.0],
    [-2.0 / 3.0, 0.0, 2.0 / 3.0],
    [1.0 / 6.0, -2.0 / 3.0, 1.0 / 2.0],
];

/// External forces of a uniform follower pressure on one P2 boundary edge and their derivative.
///
/// The solver's residual is R = f_int - f_ext, so `force` is SUBTRACTED from R and `tangent`
/// is SUBTRACTED from the Jacobian dR/du.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeLoad {
    /// Forces on [a, m, b] as [fa_x, fa_y, fm_x, fm_y, fb_x, fb_y] (N per metre).
    pub force: [f64; 6],
    /// d force_i / d u_j, row-major 6x6, same ordering.
    pub tangent: [[f64; 6]; 6],
}

/// `nodes`: current positions of [a, m, b] (x = X + u); `pressure`: p, compression positive.
///
/// Body on the left of a→b; the forces push into the body for p > 0. Their sum is
/// -p (y_b - y_a, -(x_b - x_a)) whatever the midside position. See [`EdgeLoad`] for how the
/// solver uses the result (subtract from residual and Jacobian).
pub fn edge_pressure(nodes: [[f64; 2]; 3], pressure: f64) -> EdgeLoad {
    let mut force = [0.0; 6];
    let mut tangent = [[0.0; 6]; 6];
    for i in 0..3 {
        for j in 0..3 {
            let c = pressure * EDGE_C[i][j];
            // f_i += -p C_ij (y_j, -x_j)
            force[2 * i] -= c * nodes[j][1];
            force[2 * i + 1] += c * nodes[j][0];
            // d f_ix / d y_j = -p C_ij, d f_iy / d x_j = p C_ij; the other entries vanish.
            tangent[2 * i][2 * j + 1] = -c;
            tangent[2 * i + 1][2 * j] = c;
        }
    }
    EdgeLoad { force, tangent }
}

/// [`edge_pressure`] in the given analysis. In axisymmetry (x the radius) the pressure acts on
/// the surface of revolution of the edge, f_i = −p ∫ N_i (x'_y, −x'_x) 2π r ds with
/// r = Σ N_j x_j: the integrand is of degree 5 in s, so the 3-point Gauss rule is exact, and a
/// uniform pressure on any surface of revolution sums to its exact resultant. The tangent then
/// has, besides the turning of the normal, the growth of the ring with r.
pub fn edge_pressure_in(analysis: Analysis, nodes: [[f64; 2]; 3], pressure: f64) -> EdgeLoad {
    if !analysis.has_hoop() {
        return edge_pressure(nodes, pressure);
    }
    let g = 0.6f64.sqrt();
    let points = [(-g, 5.0 / 9.0), (0.0, 8.0 / 9.0), (g, 5.0 / 9.0)];
    let mut force = [0.0; 6];
    let mut tangent = [[0.0; 6]; 6];
    for (s, wq) in points {
        let n = [0.5 * s * (s - 1.0), 1.0 - s * s, 0.5 * s * (s + 1.0)];
        let dn = [s - 0.5, -2.0 * s, s + 0.5];
        let r: f64 = (0..3).map(|j| n[j] * nodes[j][0]).sum();
        let dx: f64 = (0..3).map(|j| dn[j] * nodes[j][0]).sum();
        let dy: f64 = (0..3).map(|j| dn[j] * nodes[j][1]).sum();
        let c = -pressure * wq * analysis.measure(1.0);
        for i in 0..3 {
            // f_i += c N_i r (x'_y, −x'_x)
            force[2 * i] += c * n[i] * r * dy;
            force[2 * i + 1] -= c * n[i] * r * dx;
            for k in 0..3 {
                // ∂/∂x_k: r grows by N_k, x'_x by N'_k; ∂/∂y_k: x'_y grows by N'_k.
                tangent[2 * i][2 * k] += c * n[i] * n[k] * dy;
                tangent[2 * i][2 * k + 1] += c * n[i] * r * dn[k];
                tangent[2 * i + 1][2 * k] -= c * n[i] * (n[k] * dx + r * dn[k]);
            }
        }
    }
    EdgeLoad { force, tangent }
}

/// Simpson weights of the nodes of a straight edge of length `len`: [len/6, 4 len/6, len/6].
/// Contact uses them to turn node pressures into consistent nodal forces.
pub fn simpson_weights(len: f64) -> [f64; 3] {
    [len / 6.0, 4.0 * len / 6.0, len / 6.0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic LCG (Knuth's MMIX constants) returning values in [-1, 1).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        }
    }

    fn shape(s: f64) -> [f64; 3] {
        [0.5 * s * (s - 1.0), 1.0 - s * s, 0.5 * s * (s + 1.0)]
    }

    fn shape_ds(s: f64) -> [f64; 3] {
        [s - 0.5, -2.0 * s, s + 0.5]
    }

    /// A curved edge from the generator: random end points, midside off the chord midpoint.
    fn random_edge(rng: &mut Lcg) -> [[f64; 2]; 3] {
        let a = [3.0 * rng.next(), 3.0 * rng.next()];
        let b = [a[0] + 1.0 + rng.next(), a[1] + 2.0 * rng.next()];
        let m = [
            0.5 * (a[0] + b[0]) + 0.3 * rng.next(),
            0.5 * (a[1] + b[1]) + 0.3 * rng.next(),
        ];
        [a, m, b]
    }

    fn total(force: &[f64; 6]) -> [f64; 2] {
        [
            force[0] + force[2] + force[4],
            force[1] + force[3] + force[5],
        ]
    }

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * a.abs().max(b.abs())
    }

    #[test]
    fn axisymmetric_pressure_on_a_sphere_sums_to_the_exact_force() {
        // A sphere of radius R about the origin, meridian from the south pole to the north
        // pole in 24 P2 edges with the midside nodes on the arc (body inside, on the left).
        let radius = 1.7;
        let p = 3.0e3;
        let n = 24;
        let at = |t: f64| [radius * t.sin(), -radius * t.cos()];
        let mut upper = [0.0; 2];
        let mut whole = [0.0; 2];
        for e in 0..n {
            let (t0, t1) = (
                std::f64::consts::PI * e as f64 / n as f64,
                std::f64::consts::PI * (e + 1) as f64 / n as f64,
            );
            // Walking from the south pole up the outside (x ≥ 0), the body is on the left.
            let nodes = [at(t0), at(0.5 * (t0 + t1)), at(t1)];
            let f = total(&edge_pressure_in(Analysis::Axisymmetric, nodes, p).force);
            whole[0] += f[0];
            whole[1] += f[1];
            if e >= n / 2 {
                upper[0] += f[0];
                upper[1] += f[1];
            }
        }
        // The whole sphere: no resultant. Its upper half: the pressure on the projected disc.
        assert!(whole[1].abs() <= 1e-10 * p * radius * radius, "{whole:?}");
        let exact = -p * std::f64::consts::PI * radius * radius;
        assert!(
            (upper[1] - exact).abs() <= 1e-10 * exact.abs(),
            "{} vs {exact}",
            upper[1]
        );
    }

    #[test]
    fn axisymmetric_pressure_on_a_flat_annulus_is_exact() {
        // Top face y = 0 of a body below, from r = 2 to r = 0.5 (walking −x: body on the left).
        let nodes = [[2.0, 0.0], [1.25, 0.0], [0.5, 0.0]];
        let f = total(&edge_pressure_in(Analysis::Axisymmetric, nodes, 10.0).force);
        let exact = -10.0 * std::f64::consts::PI * (4.0 - 0.25);
        assert!((f[1] - exact).abs() <= 1e-12 * exact.abs(), "{f:?}");
        assert!(f[0].abs() <= 1e-12 * exact.abs());
    }

    #[test]
    fn axisymmetric_tangent_matches_central_differences() {
        let mut rng = Lcg(11);
        for _ in 0..20 {
            let mut e = random_edge(&mut rng);
            for x in e.iter_mut() {
                x[0] = x[0].abs() + 0.5;
            }
            let load = edge_pressure_in(Analysis::Axisymmetric, e, 2.5);
            let h = 1e-6;
            for k in 0..6 {
                let (mut ep, mut em) = (e, e);
                ep[k / 2][k % 2] += h;
                em[k / 2][k % 2] -= h;
                let fp = edge_pressure_in(Analysis::Axisymmetric, ep, 2.5).force;
                let fm = edge_pressure_in(Analysis::Axisymmetric, em, 2.5).force;
                for i in 0..6 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    assert!(
                        (fd - load.tangent[i][k]).abs() <= 1e-7 * (1.0 + fd.abs()),
                        "{i} {k}: {fd} vs {}",
                        load.tangent[i][k]
                    );
                }
            }
        }
    }

    #[test]
    fn closed_form_matches_three_point_gauss() {
        let g = (0.6f64).sqrt();
        let pts = [-g, 0.0, g];
        let wts = [5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0];
        for i in 0..3 {
            for j in 0..3 {
                let q: f64 = (0..3)
                    .map(|k| wts[k] * shape(pts[k])[i] * shape_ds(pts[k])[j])
                    .sum();
                assert!((q - EDGE_C[i][j]).abs() < 1e-15, "C[{i}][{j}]: {q}");
            }
        }
    }

    #[test]
    fn straight_horizontal_edge_pushes_into_body_above() {
        let p = 3.7e5;
        let len = 2.0;
        let load = edge_pressure([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]], p);
        let w = simpson_weights(len);
        for (i, wi) in w.iter().enumerate() {
            assert_eq!(load.force[2 * i], 0.0, "x force at node {i}");
            let expected = p * wi;
            assert!(
                close(load.force[2 * i + 1], expected, 1e-14),
                "node {i}: {} vs {expected}",
                load.force[2 * i + 1]
            );
        }
        // Independent of simpson_weights: p L (1/6, 4/6, 1/6), pointing +y.
        assert!(close(load.force[1], p * len / 6.0, 1e-14));
        assert!(close(load.force[3], p * len * 4.0 / 6.0, 1e-14));
        assert!(close(load.force[5], p * len / 6.0, 1e-14));
    }

    #[test]
    fn total_force_is_rotated_chord_and_moment_is_exact() {
        let mut rng = Lcg(7);
        for _ in 0..20 {
            let nodes = random_edge(&mut rng);
            let p = 1.0e3 * (1.5 + rng.next());
            let f = edge_pressure(nodes, p).force;
            let [a, _, b] = nodes;
            let chord = [b[0] - a[0], b[1] - a[1]];
            let sum = total(&f);
            let expected = [-p * chord[1], p * chord[0]];
            for d in 0..2 {
                assert!(
                    (sum[d] - expected[d]).abs() < 1e-12 * p,
                    "d{d}: {} vs {}",
                    sum[d],
                    expected[d]
                );
            }
            // ∫ x × t dΓ = p (|x_b|² - |x_a|²) / 2 (x × (x'_y, -x'_x) = -d/ds |x|²/2), and the
            // isoparametric nodal moment reproduces it exactly.
            let moment: f64 = (0..3)
                .map(|i| nodes[i][0] * f[2 * i + 1] - nodes[i][1] * f[2 * i])
                .sum();
            let r2 = |x: [f64; 2]| x[0] * x[0] + x[1] * x[1];
            let expected_m = 0.5 * p * (r2(b) - r2(a));
            assert!(
                (moment - expected_m).abs() < 1e-12 * p * 10.0,
                "{moment} vs {expected_m}"
            );
        }
    }

    #[test]
    fn rotation_invariance() {
        let mut rng = Lcg(11);
        for k in 0..10 {
            let nodes = random_edge(&mut rng);
            let theta = 0.7 + 0.5 * k as f64;
            let (sn, cs) = theta.sin_cos();
            let rot = |v: [f64; 2]| [cs * v[0] - sn * v[1], sn * v[0] + cs * v[1]];
            let p = 2.5e4;
            let f = edge_pressure(nodes, p).force;
            let fr = edge_pressure([rot(nodes[0]), rot(nodes[1]), rot(nodes[2])], p).force;
            for i in 0..3 {
                let expected = rot([f[2 * i], f[2 * i + 1]]);
                for d in 0..2 {
                    assert!(
                        (fr[2 * i + d] - expected[d]).abs() < 1e-12 * p,
                        "case {k} node {i} d{d}: {} vs {}",
                        fr[2 * i + d],
                        expected[d]
                    );
                }
            }
        }
    }

    #[test]
    fn tangent_matches_central_differences() {
        let mut rng = Lcg(12345);
        for case in 0..10 {
            let nodes = random_edge(&mut rng);
            let p = 1.0e4 * (1.5 + rng.next());
            let load = edge_pressure(nodes, p);
            let scale = load
                .tangent
                .iter()
                .flatten()
                .fold(0.0f64, |m, v| m.max(v.abs()));
            let h = 1e-6;
            for j in 0..6 {
                let mut plus = nodes;
                let mut minus = nodes;
                plus[j / 2][j % 2] += h;
                minus[j / 2][j % 2] -= h;
                let fp = edge_pressure(plus, p).force;
                let fm = edge_pressure(minus, p).force;
                for i in 0..6 {
                    let fd = (fp[i] - fm[i]) / (2.0 * h);
                    let err = (fd - load.tangent[i][j]).abs() / scale;
                    assert!(
                        err < 1e-7,
                        "case {case} K[{i}][{j}]: {} vs fd {fd}",
                        load.tangent[i][j]
                    );
                }
            }
        }
    }

    #[test]
    fn closed_square_is_in_equilibrium_with_symmetric_tangent() {
        // Global nodes: vertices 0..4 CCW, then midside nodes 4..8 (perturbed: curved edges).
        let pts: [[f64; 2]; 8] = [
            [0.3, -0.2],
            [2.3, -0.2],
            [2.3, 1.8],
            [0.3, 1.8],
            [1.3, -0.35],
            [2.5, 0.8],
            [1.2, 1.9],
            [0.15, 0.7],
        ];
        let edges = [[0, 4, 1], [1, 5, 2], [2, 6, 3], [3, 7, 0]];
        let p = 4.2e5;
        let mut f = [0.0; 16];
        let mut k = [[0.0; 16]; 16];
        for e in edges {
            let load = edge_pressure([pts[e[0]], pts[e[1]], pts[e[2]]], p);
            for (li, &gi) in e.iter().enumerate() {
                for di in 0..2 {
                    f[2 * gi + di] += load.force[2 * li + di];
                    for (lj, &gj) in e.iter().enumerate() {
                        for dj in 0..2 {
                            k[2 * gi + di][2 * gj + dj] += load.tangent[2 * li + di][2 * lj + dj];
                        }
                    }
                }
            }
        }
        let fx: f64 = (0..8).map(|n| f[2 * n]).sum();
        let fy: f64 = (0..8).map(|n| f[2 * n + 1]).sum();
        let moment: f64 = (0..8)
            .map(|n| pts[n][0] * f[2 * n + 1] - pts[n][1] * f[2 * n])
            .sum();
        assert!(fx.abs() < 1e-12 * p, "fx {fx}");
        assert!(fy.abs() < 1e-12 * p, "fy {fy}");
        assert!(moment.abs() < 1e-12 * p, "moment {moment}");
        // Net inward push: the midside node of the bottom edge is pushed up (into the body).
        assert!(f[2 * 4 + 1] > 0.0);
        // Equal pressure all round: the vertex skew parts cancel (load derives from p·area).
        for i in 0..16 {
            for j in 0..16 {
                assert!((k[i][j] - k[j][i]).abs() < 1e-12 * p, "K[{i}][{j}]");
            }
        }
    }

    #[test]
    fn single_edge_tangent_skew_part_only_on_vertices() {
        let p = 1.0;
        let k = edge_pressure([[0.0, 0.0], [1.0, 0.3], [2.0, 0.1]], p).tangent;
        for i in 0..6 {
            for j in 0..6 {
                let skew = k[i][j] - k[j][i];
                let node_i = i / 2;
                let node_j = j / 2;
                if node_i == node_j && node_i != 1 && i != j {
                    // d f_ax/d y_a - d f_ay/d x_a = p (for b: -p).
                    assert!((skew.abs() - p).abs() < 1e-15, "K[{i}][{j}] skew {skew}");
                } else {
                    assert!(skew.abs() < 1e-15, "K[{i}][{j}] skew {skew}");
                }
            }
        }
    }

    #[test]
    fn simpson_weights_sum_to_length() {
        for len in [1.0, 0.37, 12.5, 1e-3] {
            let w = simpson_weights(len);
            let s: f64 = w.iter().sum();
            assert!(close(s, len, 1e-15), "{len}: {s}");
            assert!(close(w[1], 4.0 * w[0], 1e-15) && w[0] == w[2]);
        }
    }
}
