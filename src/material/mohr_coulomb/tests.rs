// Index loops mirror the component notation of the formulas being checked.
#![allow(clippy::needless_range_loop)]

use super::*;
use crate::material::tresca::Tresca;

const C: f64 = 20.0e3;

fn sand(phi: f64, psi: f64, t: Option<f64>) -> MohrCoulomb {
    MohrCoulomb::new(30.0e6, 0.3, C, phi, psi, t).expect("valid parameters")
}

fn at(s: [f64; 4]) -> GaussState {
    GaussState {
        stress: s,
        ..GaussState::default()
    }
}

fn moduli(m: &MohrCoulomb) -> (f64, f64) {
    let (l, g) = m.elastic().lame();
    (g, l + 2.0 * g / 3.0)
}

/// Principal values of `s` from largest to smallest.
fn principal(s: &[f64; 4]) -> [f64; 3] {
    let v = Spectral::of(s).values;
    descending(&v).map(|i| v[i])
}

/// Mohr–Coulomb's f at `s` (> 0 outside).
fn mc(m: &MohrCoulomb, s: &[f64; 4]) -> f64 {
    let p = principal(s);
    let (sf, cf) = m.friction_angle.to_radians().sin_cos();
    (p[0] - p[2]) + (p[0] + p[2]) * sf - 2.0 * m.cohesion * cf
}

/// The stress a zero strain returns from the (trial) state `s`.
fn returned(m: &MohrCoulomb, s: [f64; 4]) -> MaterialResponse {
    m.update(&at(s), &[0.0; 4]).expect("return")
}

fn close3(a: &[f64; 3], b: &[f64; 3], tol: f64) {
    for k in 0..3 {
        assert!((a[k] - b[k]).abs() <= tol, "{a:?} vs {b:?}");
    }
}

/// Frobenius distance between the tangent and central differences of the stress, relative to
/// the tangent's norm or E, whichever is larger (the apex's tangent is zero).
fn fd_error(m: &MohrCoulomb, st: &GaussState, e: &[f64; 4]) -> f64 {
    crate::material::tangent_fd_error(m, st, e, 1e-9, m.young)
}

#[test]
fn rejects_bad_parameters_naming_the_field() {
    for (c, phi, psi, t, field) in [
        (C, 30.0, 40.0, None, "dilation_angle"),
        (C, 30.0, -1.0, None, "dilation_angle"),
        (C, 90.0, 0.0, None, "friction_angle"),
        (C, -5.0, 0.0, None, "friction_angle"),
        (C, f64::NAN, 0.0, None, "friction_angle"),
        (-1.0, 30.0, 0.0, None, "cohesion"),
        (0.0, 0.0, 0.0, None, "cohesion"),
        (f64::INFINITY, 30.0, 0.0, None, "cohesion"),
        (C, 30.0, 0.0, Some(-1.0), "tension_cutoff"),
        (C, 30.0, 0.0, Some(f64::NAN), "tension_cutoff"),
    ] {
        match MohrCoulomb::new(30e6, 0.3, c, phi, psi, t) {
            Err(err @ MaterialError::InvalidParameter { name, .. }) => {
                assert_eq!(name, field);
                assert!(err.to_string().contains(field), "{err}");
            }
            other => panic!("expected rejection of {field}, got {other:?}"),
        }
    }
    assert!(MohrCoulomb::new(30e6, 0.5, C, 30.0, 0.0, None).is_err());
    assert!(MohrCoulomb::new(30e6, 0.3, 0.0, 35.0, 0.0, None).is_ok());
}

#[test]
fn below_yield_it_is_linear_elastic() {
    let m = sand(30.0, 10.0, None);
    let st = at([-1.0e5, -1.2e5, -1.1e5, 3.0e3]);
    let e = [2e-5, -1e-5, 0.0, 1e-5];
    let r = m.update(&st, &e).expect("ok");
    let lin = m.elastic().update(&st, &e).expect("ok");
    assert!(mc(&m, &r.s) < 0.0);
    assert_eq!(r.s, lin.s);
    assert_eq!(r.d, lin.d);
    assert_eq!(r.state.internal[EPS_Q], 0.0);
}

#[test]
fn main_face_return_matches_the_closed_form() {
    let m = sand(30.0, 10.0, None);
    let (g, k) = moduli(&m);
    let (sf, cf) = 30f64.to_radians().sin_cos();
    let sg = 10f64.to_radians().sin();
    // σ1 = σxx, σ2 = σzz, σ3 = σyy: clearly apart, on no edge.
    let tr = [-50.0e3, -250.0e3, -120.0e3, 0.0];
    let f = (tr[0] - tr[1]) + (tr[0] + tr[1]) * sf - 2.0 * C * cf;
    assert!(f > 0.0);
    let a = 4.0 * g + 4.0 * (k + g / 3.0) * sf * sg;
    let dg = f / a;
    let vol = (2.0 * k - 4.0 * g / 3.0) * sg;
    let want = [
        tr[0] - dg * (2.0 * g * (1.0 + sg) + vol),
        tr[2] - dg * vol,
        tr[1] - dg * (-2.0 * g * (1.0 - sg) + vol),
    ];
    let r = returned(&m, tr);
    close3(&principal(&r.s), &want, 1e-9 * 250e3);
    assert!(mc(&m, &r.s).abs() <= 1e-10 * 250e3, "{}", mc(&m, &r.s));
    assert!((r.s[2] - want[1]).abs() <= 1e-9 * 250e3, "σzz intermediate");
    // Dilation: tr Δε^p / (Δε^p_1 − Δε^p_3) = sin ψ.
    let ep = &r.state.internal[..4];
    let ratio = (ep[0] + ep[1] + ep[2]) / (ep[0] - ep[1]);
    assert!((ratio - sg).abs() < 1e-10, "{ratio} vs {sg}");
}

/// de Souza Neto et al. (2008), box 8.5: the two-face system of perfect plasticity.
fn edge_closed_form(m: &MohrCoulomb, tr: [f64; 3], right: bool) -> [f64; 3] {
    let (g, k) = moduli(m);
    let (sf, cf) = m.friction_angle.to_radians().sin_cos();
    let sg = m.dilation_angle.to_radians().sin();
    let face = |i: usize, j: usize| (tr[i] - tr[j]) + (tr[i] + tr[j]) * sf - 2.0 * C * cf;
    let a = 4.0 * g * (1.0 + sf * sg / 3.0) + 4.0 * k * sf * sg;
    let (b, fb) = if right {
        (
            2.0 * g * (1.0 - sf - sg - sf * sg / 3.0) + 4.0 * k * sf * sg,
            face(1, 2),
        )
    } else {
        (
            2.0 * g * (1.0 + sf + sg - sf * sg / 3.0) + 4.0 * k * sf * sg,
            face(0, 1),
        )
    };
    let fa = face(0, 2);
    let det = a * a - b * b;
    let (ga, gb) = ((a * fa - b * fb) / det, (a * fb - b * fa) / det);
    let d = m.principal_stiffness();
    let ng_a = [1.0 + sg, 0.0, -(1.0 - sg)];
    let ng_b = if right {
        [0.0, 1.0 + sg, -(1.0 - sg)]
    } else {
        [1.0 + sg, -(1.0 - sg), 0.0]
    };
    let flow: [f64; 3] = std::array::from_fn(|i| ga * ng_a[i] + gb * ng_b[i]);
    let ds = mat_vec(&d, &flow);
    std::array::from_fn(|i| tr[i] - ds[i])
}

#[test]
fn edge_returns_match_the_closed_form() {
    let m = sand(30.0, 10.0, None);
    // σ1 ≈ σ2 (σ1 = σxx, σ2 = σzz): the edge σ1 = σ2.
    let right = [-40.0e3, -300.0e3, -45.0e3, 0.0];
    let r = returned(&m, right);
    let p = principal(&r.s);
    let want = edge_closed_form(&m, principal(&right), true);
    close3(&p, &want, 1e-9 * 300e3);
    assert!((p[0] - p[1]).abs() < 1e-9 * 300e3, "on the edge: {p:?}");
    // σ2 ≈ σ3 (σ2 = σzz, σ3 = σyy): the edge σ2 = σ3.
    let left = [-40.0e3, -300.0e3, -295.0e3, 0.0];
    let r = returned(&m, left);
    let p = principal(&r.s);
    let want = edge_closed_form(&m, principal(&left), false);
    close3(&p, &want, 1e-9 * 300e3);
    assert!((p[1] - p[2]).abs() < 1e-9 * 300e3, "on the edge: {p:?}");
    assert!(mc(&m, &r.s).abs() < 1e-9 * 300e3);
}

#[test]
fn apex_and_tension_cutoff_returns() {
    // Hydrostatic tension past the apex c cot φ.
    let m = sand(30.0, 10.0, None);
    let apex = C / 30f64.to_radians().tan();
    let r = returned(&m, [2.0 * apex, 2.1 * apex, 1.9 * apex, 100.0]);
    close3(&principal(&r.s), &[apex; 3], 1e-12 * apex);
    assert_eq!(r.d, [[0.0; 4]; 4]);
    // The cut-off alone: σ1 = σxx over t, Mohr–Coulomb satisfied.
    let t = 5.0e3;
    let m = sand(30.0, 10.0, Some(t));
    let (g, k) = moduli(&m);
    let tr = [8.0e3, -20.0e3, -10.0e3, 0.0];
    let dg = (tr[0] - t) / (k + 4.0 * g / 3.0);
    let want = [
        t,
        tr[2] - dg * (k - 2.0 * g / 3.0),
        tr[1] - dg * (k - 2.0 * g / 3.0),
    ];
    let r = returned(&m, tr);
    close3(&principal(&r.s), &want, 1e-9 * 20e3);
    // Its corner σ1 = σ2 = σ3 = t below the apex.
    let r = returned(&m, [50.0e3, 40.0e3, 45.0e3, 0.0]);
    close3(&principal(&r.s), &[t; 3], 1e-12 * 50e3);
    // Its edge σ1 = σ2 = t.
    let r = returned(&m, [12.0e3, -5.0e3, 11.0e3, 0.0]);
    let p = principal(&r.s);
    assert!(
        (p[0] - t).abs() < 1e-9 * 12e3 && (p[1] - t).abs() < 1e-9 * 12e3,
        "{p:?}"
    );
    assert!(mc(&m, &r.s) <= 1e-9 * 12e3);
}

#[test]
fn out_of_plane_major_stress_is_judged_in_3d() {
    // σzz the least compressive: Mohr–Coulomb between σzz and σyy, an in-plane criterion
    // would miss it.
    let m = sand(30.0, 30.0, None);
    let tr = [-200.0e3, -260.0e3, -20.0e3, 0.0];
    let r = returned(&m, tr);
    assert!(r.state.internal[EPS_Q] > 0.0);
    assert!(mc(&m, &r.s).abs() < 1e-9 * 260e3);
    assert!(r.state.internal[2] > 0.0, "plastic flow out of plane");
}

#[test]
fn returned_stress_is_on_the_yield_surface() {
    for (phi, psi) in [(30.0, 30.0), (30.0, 0.0), (20.0, 5.0)] {
        let m = sand(phi, psi, None);
        let pre = at([-100.0e3, -150.0e3, -120.0e3, 10.0e3]);
        for e in [
            [1e-2, -2e-2, 0.0, 5e-3],
            [2e-2, -1e-3, 0.0, -3e-2],
            [-4e-2, 1e-2, 0.0, 0.0],
        ] {
            let r = m.update(&pre, &e).expect("ok");
            assert!(
                r.state.internal[EPS_Q] > 0.0,
                "{phi} {psi} {e:?} must yield"
            );
            let scale = r.s.iter().fold(C, |a, v| a.max(v.abs()));
            assert!(
                mc(&m, &r.s).abs() <= 1e-10 * scale,
                "{phi} {psi} {e:?}: f = {}",
                mc(&m, &r.s)
            );
        }
    }
}

#[test]
fn consistent_tangent_matches_finite_differences_in_every_region() {
    let apex = C / 30f64.to_radians().tan();
    for psi in [30.0, 10.0, 0.0] {
        let m = sand(30.0, psi, None);
        let cut = sand(30.0, psi, Some(5.0e3));
        let cases: [(&MohrCoulomb, [f64; 4], &str); 6] = [
            (&m, [-60.0e3, -250.0e3, -120.0e3, 30.0e3], "face"),
            (&m, [-40.0e3, -300.0e3, -45.0e3, 20.0e3], "edge σ1 = σ2"),
            (&m, [-40.0e3, -300.0e3, -295.0e3, 20.0e3], "edge σ2 = σ3"),
            (&m, [2.0 * apex, 2.1 * apex, 1.9 * apex, 100.0], "apex"),
            (&cut, [8.0e3, -20.0e3, -10.0e3, 1.0e3], "cut-off"),
            (&cut, [12.0e3, -5.0e3, 11.0e3, 1.0e3], "cut-off edge"),
        ];
        for (model, s, what) in cases {
            let e = [1e-5, -2e-5, 0.0, 1e-5];
            let st = at(s);
            let r = model.update(&st, &e).expect("ok");
            assert!(r.state.internal[EPS_Q] > 0.0, "{what}: must yield");
            let err = fd_error(model, &st, &e);
            assert!(err < 1e-6, "ψ = {psi}, {what}: {err:e}");
            let asym = (0..4)
                .flat_map(|i| (0..4).map(move |j| (i, j)))
                .fold(0.0f64, |a, (i, j)| a.max((r.d[i][j] - r.d[j][i]).abs()));
            let big = r.d.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
            if psi == 30.0 {
                assert!(
                    asym <= 1e-9 * big.max(1.0),
                    "{what}: ψ = φ is symmetric, {asym:e}"
                );
            } else if what == "face" {
                assert!(asym > 1e-3 * big, "{what}: ψ < φ is not symmetric");
            }
        }
        assert_eq!(m.symmetric_tangent(), psi == 30.0);
    }
}

#[test]
fn friction_free_is_tresca_where_the_out_of_plane_stress_is_intermediate() {
    let m = MohrCoulomb::new(5.0e6, 0.49, C, 0.0, 0.0, None).expect("valid");
    let t = Tresca::new(5.0e6, 0.49, C).expect("valid");
    assert!(m.isochoric());
    let pre = at([-1.5e5, -1.7e5, -1.6e5, 1.2e4]);
    // σzz − (σxx + σyy)/2 changes by −G tr ε: small volume changes keep it intermediate.
    for e in [[3e-2, -2.9e-2, 0.0, 4e-2], [-4e-3, 4e-3, 0.0, -1e-3]] {
        let a = m.update(&pre, &e).expect("ok");
        let b = t.update(&pre, &e).expect("ok");
        for i in 0..4 {
            assert!(
                (a.s[i] - b.s[i]).abs() < 1e-10 * 1.7e5,
                "S[{i}] {:?} {:?}",
                a.s,
                b.s
            );
            for j in 0..4 {
                assert!(
                    (a.d[i][j] - b.d[i][j]).abs() < 1e-8 * b.d[0][0],
                    "D[{i}][{j}]"
                );
            }
        }
        assert!((a.state.internal[EPS_Q] - b.state.internal[4]).abs() < 1e-12);
    }
}
