//! Tests of the mixed element: kinematics, tangent, objectivity, yield, locking, block
//! compression, conditioning. Includes a tiny dense assembler and solver for small meshes.

use super::*;
use crate::fem::element::p2_element;
use crate::fem::recovery::extrapolate_to_vertices;
use crate::material::elastic::LinearElastic;
use crate::material::tresca::{max_in_plane_shear, max_shear_3d, Tresca, EPS_Q};

const CU: f64 = 2.0e4;

/// The element in plane strain, as most tests here take it.
fn p2p1_element(
    x: &[[f64; 2]; N_NODES],
    du: &[[f64; 2]; N_NODES],
    p: &[f64; N_P_DOFS],
    states_n: &[GaussState; N_GAUSS],
    mat: &dyn Material,
    bulk: f64,
    body_force: [f64; 2],
) -> Result<MixedOutput, ElementError> {
    super::p2p1_element(
        x,
        du,
        p,
        states_n,
        mat,
        bulk,
        body_force,
        Analysis::PlaneStrain,
    )
}

fn clay() -> Tresca {
    // E/cu = 300, ν = 0.49.
    Tresca::new(6.0e6, 0.49, CU).expect("valid parameters")
}

fn elastic() -> LinearElastic {
    LinearElastic::new(12e6, 0.2).expect("valid parameters")
}

fn rot(theta: f64) -> Mat2 {
    let (s, c) = theta.sin_cos();
    [[c, -s], [s, c]]
}

fn transpose(a: &Mat2) -> Mat2 {
    [[a[0][0], a[1][0]], [a[0][1], a[1][1]]]
}

fn apply(a: &Mat2, v: [f64; 2]) -> [f64; 2] {
    [
        a[0][0] * v[0] + a[0][1] * v[1],
        a[1][0] * v[0] + a[1][1] * v[1],
    ]
}

/// Δu_a = G (x_a − c): the homogeneous step F = I + G about c.
fn homogeneous_du(x: &[[f64; 2]; 6], g: &Mat2, c: [f64; 2]) -> [[f64; 2]; 6] {
    x.map(|xa| apply(g, [xa[0] - c[0], xa[1] - c[1]]))
}

fn curved_element() -> [[f64; 2]; 6] {
    let mut x = p2::straight_sided(&[[0.3, -0.2], [1.9, 0.1], [0.6, 1.4]]);
    x[4][0] += 0.08;
    x[4][1] += 0.05;
    x[5][0] -= 0.04;
    x
}

fn state(s: [f64; 4]) -> GaussState {
    GaussState {
        stress: s,
        ..GaussState::default()
    }
}

/// Different prestress at each Gauss point, with a mean stress of several cu.
fn prestress() -> [GaussState; 3] {
    [
        state([-1.2e5, -1.5e5, -1.3e5, 0.6e4]),
        state([-0.9e5, -1.2e5, -1.0e5, -0.5e4]),
        state([-1.5e5, -1.8e5, -1.6e5, 0.2e4]),
    ]
}

/// Vertex pressures whose interpolant matches p_n at the Gauss points.
fn vertex_pressure(states: &[GaussState; 3]) -> [f64; 3] {
    let at_gauss = states
        .each_ref()
        .map(|s| [-(s.stress[0] + s.stress[1] + s.stress[2]) / 3.0]);
    extrapolate_to_vertices(&at_gauss).map(|v| v[0])
}

fn rel_close(a: &[f64], b: &[f64], tol: f64) -> bool {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b.iter())
        .all(|(x, y)| (x - y).abs() <= tol * scale)
}

// ---- kinematics -------------------------------------------------------------------------

/// ½ ln(FᵀF) by an explicit eigen-decomposition, as an independent reference.
fn log_strain_by_eigenvectors(f: &Mat2) -> [f64; 4] {
    let c = mul(&transpose(f), f);
    let m = 0.5 * (c[0][0] + c[1][1]);
    let r = (0.5 * (c[0][0] - c[1][1])).hypot(c[0][1]);
    let phi = 0.5 * (2.0 * c[0][1]).atan2(c[0][0] - c[1][1]);
    let (s, co) = phi.sin_cos();
    let (l1, l2) = (0.5 * (m + r).ln(), 0.5 * (m - r).ln());
    let exx = l1 * co * co + l2 * s * s;
    let eyy = l1 * s * s + l2 * co * co;
    let exy = (l1 - l2) * s * co;
    [exx, eyy, 0.0, 2.0 * exy]
}

fn sample_gradients() -> Vec<Mat2> {
    vec![
        [[0.3, 0.8], [-0.1, -0.2]],
        [[0.5, 0.0], [0.0, -0.3]],
        [[-0.6, 0.4], [0.9, 0.7]],
        // F = 1.3 rot(2.5): isotropic stretch, x = 0 exactly.
        {
            let r = rot(2.5);
            [
                [1.3 * r[0][0] - 1.0, 1.3 * r[0][1]],
                [1.3 * r[1][0], 1.3 * r[1][1] - 1.0],
            ]
        },
        // x close to the series/closed-form switch at 0.2.
        [[0.1, 0.0], [0.0, -0.1]],
        [[0.02, 0.01], [0.03, -0.005]],
    ]
}

#[test]
fn log_strain_matches_eigen_decomposition_and_closed_forms() {
    for h in sample_gradients() {
        let f = [[1.0 + h[0][0], h[0][1]], [h[1][0], 1.0 + h[1][1]]];
        let eps = log_strain(&h).expect("det F > 0");
        let want = log_strain_by_eigenvectors(&f);
        assert!(rel_close(&eps, &want, 1e-13), "{h:?}: {eps:?} vs {want:?}");
        // R is a rotation and U = Rᵀ F is symmetric positive definite.
        let r = step_rotation(&h).expect("det F > 0");
        assert!((r[0][0] * r[1][1] - r[0][1] * r[1][0] - 1.0).abs() < 1e-15);
        let u = mul(&transpose(&r), &f);
        assert!((u[0][1] - u[1][0]).abs() < 1e-15, "{u:?}");
        assert!(u[0][0] > 0.0 && u[0][0] * u[1][1] - u[0][1] * u[1][0] > 0.0);
    }
    // Pure stretch, with and without a rotation: ε = (ln a, ln b).
    for theta in [0.0, 0.4, -2.9] {
        let fr = mul(&rot(theta), &[[1.7, 0.0], [0.0, 0.6]]);
        let h = [[fr[0][0] - 1.0, fr[0][1]], [fr[1][0], fr[1][1] - 1.0]];
        let eps = log_strain(&h).expect("det F > 0");
        let want = [1.7_f64.ln(), 0.6_f64.ln(), 0.0, 0.0];
        assert!(rel_close(&eps, &want, 1e-14), "{theta}: {eps:?}");
        let r = step_rotation(&h).expect("det F > 0");
        assert!(rel_close(&r.concat(), &rot(theta).concat(), 1e-14));
    }
    // Tiny steps keep full relative precision: ε = E − E² + O(E³).
    let h = [[1.0e-9, -0.4e-9], [0.7e-9, -0.6e-9]];
    let eps = log_strain(&h).expect("det F > 0");
    let e = green_lagrange(&h);
    let em = [[e[0], 0.5 * e[3]], [0.5 * e[3], e[1]]];
    let e2 = mul(&em, &em);
    let want = [
        e[0] - e2[0][0],
        e[1] - e2[1][1],
        0.0,
        2.0 * (0.5 * e[3] - e2[0][1]),
    ];
    assert!(rel_close(&eps, &want, 1e-15), "{eps:?} vs {want:?}");
    assert!(log_strain(&[[-1.0, 0.0], [0.0, 0.0]]).is_none(), "J = 0");
    assert!(step_rotation(&[[-2.0, 0.0], [0.0, 0.0]]).is_none(), "J < 0");
}

#[test]
fn atanh_ratio_is_continuous_at_the_series_switch() {
    for x in [0.2_f64 - 1e-12, 0.2, 0.15, 0.25] {
        let g = x.atanh() / x;
        let h = (1.0 / (1.0 - x * x) - g) / (x * x);
        let (gs, hs) = atanh_ratio(x);
        assert!((gs - g).abs() < 2e-15 && (hs - h).abs() < 1e-13, "{x}");
    }
    assert_eq!(atanh_ratio(0.0), (1.0, 2.0 / 3.0));
}

#[test]
fn kinematic_derivatives_match_finite_differences() {
    // Round-off dominates below this step for the strongly distorted samples (J = 0.32).
    let step = 1e-5;
    for h in sample_gradients() {
        let k = step_kinematics(&h, 0.0).expect("valid");
        let theta = |h: &Mat2| {
            let r = step_rotation(h).expect("valid");
            r[1][0].atan2(r[0][0])
        };
        for jl in 0..4 {
            let mut hp = h;
            let mut hm = h;
            hp[jl / 2][jl % 2] += step;
            hm[jl / 2][jl % 2] -= step;
            let ep = log_strain(&hp).expect("valid");
            let em = log_strain(&hm).expect("valid");
            for c in 0..4 {
                let fd = (ep[c] - em[c]) / (2.0 * step);
                assert!(
                    (fd - k.deps[jl][c]).abs() < 1e-8,
                    "{h:?} dε{c}/dH{jl}: {fd} vs {}",
                    k.deps[jl][c]
                );
            }
            let fd = (theta(&hp) - theta(&hm)) / (2.0 * step);
            assert!((fd - k.dtheta[jl]).abs() < 1e-8, "{h:?} dθ/dH{jl}");
        }
    }
}

// ---- element tangent --------------------------------------------------------------------

/// Blockwise relative error (uu, up, pu, pp) of the tangent against central differences.
fn fd_errors(
    x: &[[f64; 2]; 6],
    du: &[[f64; 2]; 6],
    p: &[f64; 3],
    st: &[GaussState; 3],
    mat: &dyn Material,
    bulk: f64,
) -> [f64; 4] {
    fd_errors_in(Analysis::PlaneStrain, x, du, p, st, mat, bulk)
}

/// [`fd_errors`] in the given analysis.
fn fd_errors_in(
    analysis: Analysis,
    x: &[[f64; 2]; 6],
    du: &[[f64; 2]; 6],
    p: &[f64; 3],
    st: &[GaussState; 3],
    mat: &dyn Material,
    bulk: f64,
) -> [f64; 4] {
    let body = [0.5e3, -2.0e4];
    let element = |du: &[[f64; 2]; 6], p: &[f64; 3]| {
        super::p2p1_element(x, du, p, st, mat, bulk, body, analysis).expect("valid element")
    };
    let out = element(du, p);
    let mut fd = [[0.0; N_MIXED_DOFS]; N_MIXED_DOFS];
    for l in 0..N_MIXED_DOFS {
        let (mut dup, mut dum, mut pp, mut pm) = (*du, *du, *p, *p);
        // The residual is linear in p, so a large pressure step is exact and round-off free.
        let hstep = if l < N_U_DOFS { 1e-7 } else { 1e2 };
        if l < N_U_DOFS {
            dup[l / 2][l % 2] += hstep;
            dum[l / 2][l % 2] -= hstep;
        } else {
            pp[l - N_U_DOFS] += hstep;
            pm[l - N_U_DOFS] -= hstep;
        }
        let rp = element(&dup, &pp);
        let rm = element(&dum, &pm);
        for k in 0..N_MIXED_DOFS {
            fd[k][l] = (rp.residual[k] - rm.residual[k]) / (2.0 * hstep);
        }
    }
    let mut err = [0.0; 4];
    let blocks = [(0, 0), (0, 1), (1, 0), (1, 1)];
    for (e, (bi, bj)) in err.iter_mut().zip(blocks) {
        let range = |b: usize| {
            if b == 0 {
                0..N_U_DOFS
            } else {
                N_U_DOFS..N_MIXED_DOFS
            }
        };
        let (mut num, mut den) = (0.0, 0.0);
        for k in range(bi) {
            for l in range(bj) {
                num += (fd[k][l] - out.tangent[k][l]).powi(2);
                den += out.tangent[k][l].powi(2);
            }
        }
        *e = if den == 0.0 {
            num.sqrt()
        } else {
            (num / den).sqrt()
        };
    }
    err
}

/// A large rotating, stretching and spatially varying step.
fn big_step(x: &[[f64; 2]; 6], scale: f64) -> [[f64; 2]; 6] {
    let u = [
        [1.0 + 0.25 * scale, 0.1 * scale],
        [0.1 * scale, 1.0 - 0.15 * scale],
    ];
    let f = mul(&rot(0.6), &u);
    let g = [[f[0][0] - 1.0, f[0][1]], [f[1][0], f[1][1] - 1.0]];
    let mut du = homogeneous_du(x, &g, [0.5, 0.2]);
    for (d, xa) in du.iter_mut().zip(x.iter()) {
        d[0] += 0.03 * scale * xa[0] * xa[1];
        d[1] -= 0.02 * scale * xa[0] * xa[0];
    }
    du
}

#[test]
fn tangent_matches_finite_differences_elastic_prestressed_rotated() {
    let x = curved_element();
    let st = prestress();
    let mat = elastic();
    let (l, mu) = mat.lame();
    let du = big_step(&x, 1.0);
    let p = [1.1e5, 1.4e5, 0.9e5];
    for bulk in [l + 2.0 * mu / 3.0, f64::INFINITY] {
        let err = fd_errors(&x, &du, &p, &st, &mat, bulk);
        assert!(err.iter().all(|e| *e < 1e-6), "bulk {bulk}: {err:?}");
    }
    // Also about the undeformed state, where the geometric terms are pure prestress.
    let err = fd_errors(&x, &[[0.0; 2]; 6], &p, &st, &mat, 1e8);
    assert!(err.iter().all(|e| *e < 1e-6), "{err:?}");
}

#[test]
fn tangent_matches_finite_differences_plastic_prestressed_rotated() {
    let x = curved_element();
    let st = prestress();
    let mat = clay();
    for scale in [1.0, 0.05] {
        let du = big_step(&x, scale);
        let p = [1.1e5, 1.4e5, 0.9e5];
        let out =
            p2p1_element(&x, &du, &p, &st, &mat, mat.bulk_modulus(), [0.0; 2]).expect("valid");
        for (q, s) in out.states.iter().enumerate() {
            assert!(
                s.internal[EPS_Q] > 1e-3 * scale,
                "gauss {q} must flow plastically"
            );
        }
        for bulk in [mat.bulk_modulus(), f64::INFINITY] {
            let err = fd_errors(&x, &du, &p, &st, &mat, bulk);
            assert!(err.iter().all(|e| *e < 1e-6), "scale {scale}: {err:?}");
        }
    }
}

#[test]
fn axisymmetric_tangent_matches_finite_differences() {
    use crate::material::mohr_coulomb::MohrCoulomb;
    // The element lies at r = x > 0.3: the hoop terms are large.
    let x = curved_element();
    let st = prestress();
    let p = [1.1e5, 1.4e5, 0.9e5];
    let el = elastic();
    let (l, mu) = el.lame();
    for bulk in [l + 2.0 * mu / 3.0, f64::INFINITY] {
        let err = fd_errors_in(
            Analysis::Axisymmetric,
            &x,
            &big_step(&x, 1.0),
            &p,
            &st,
            &el,
            bulk,
        );
        assert!(
            err.iter().all(|e| *e < 1e-6),
            "elastic, bulk {bulk}: {err:?}"
        );
    }
    let tresca = clay().in_principal_stresses();
    let mc = MohrCoulomb::new(6.0e6, 0.3, 5.0e3, 30.0, 5.0, None).expect("valid");
    let models: [(&dyn Material, f64); 2] =
        [(&tresca, tresca.bulk_modulus()), (&mc, 6.0e6 / (3.0 * 0.4))];
    let zero: [GaussState; 3] = std::array::from_fn(|_| GaussState::default());
    for (mat, bulk) in models {
        // Unconfined, so that Mohr–Coulomb flows too.
        let (st, p) = if mat.isochoric() {
            (&st, p)
        } else {
            (&zero, [0.0; 3])
        };
        for scale in [0.3, 0.05] {
            let du = big_step(&x, scale);
            let out =
                super::p2p1_element(&x, &du, &p, st, mat, bulk, [0.0; 2], Analysis::Axisymmetric)
                    .expect("valid");
            assert!(
                out.states.iter().any(|s| s.internal[EPS_Q] > 0.0),
                "{mat:?} must flow plastically"
            );
            let err = fd_errors_in(Analysis::Axisymmetric, &x, &du, &p, st, mat, bulk);
            assert!(err.iter().all(|e| *e < 1e-6), "{mat:?} {scale}: {err:?}");
        }
    }
}

#[test]
fn axisymmetric_tresca_yields_on_the_hoop_stress_too() {
    // A uniform radial stretch strains r and θ alike and leaves y: the hoop stress is one of
    // the extremes, which the in-plane criterion cannot see. σr = σθ: the prism's rounded
    // edge, whose strength is stated exactly.
    let x = curved_element();
    let zero: [GaussState; 3] = std::array::from_fn(|_| GaussState::default());
    let mat = clay().in_principal_stresses();
    let eps = 0.02;
    let du = x.map(|xa| [eps * xa[0], -eps * xa[1]]);
    let out = super::p2p1_element(
        &x,
        &du,
        &[0.0; 3],
        &zero,
        &mat,
        f64::INFINITY,
        [0.0; 2],
        Analysis::Axisymmetric,
    )
    .expect("valid");
    for st in &out.states {
        let tau = max_shear_3d(&st.stress);
        let edge = 0.5 * crate::material::rounded_prism::edge_strength(CU, mat.edge_rounding);
        assert!(
            (tau - edge).abs() <= 1e-9 * CU,
            "{tau} vs {edge}: {:?}",
            st.stress
        );
    }
}

#[test]
fn tangent_matches_finite_differences_frictional_dilatant() {
    use crate::material::drucker_prager::{DruckerPrager, Match};
    use crate::material::mohr_coulomb::MohrCoulomb;
    let x = curved_element();
    let st = prestress();
    let mc = |psi| MohrCoulomb::new(6.0e6, 0.3, 5.0e3, 30.0, psi, None).expect("valid");
    let dp = |psi| DruckerPrager::new(6.0e6, 0.3, 5.0e3, 30.0, psi, Match::PlaneStrain);
    let models: Vec<Box<dyn Material>> = vec![
        Box::new(mc(30.0)),
        Box::new(mc(5.0)),
        Box::new(dp(30.0).expect("valid")),
        Box::new(dp(0.0).expect("valid")),
    ];
    let bulk = 6.0e6 / (3.0 * 0.4);
    for mat in &models {
        assert!(!mat.isochoric());
        for scale in [0.3, 0.1] {
            let du = big_step(&x, scale);
            let p = [1.1e5, 1.4e5, 0.9e5];
            let out = p2p1_element(&x, &du, &p, &st, mat.as_ref(), bulk, [0.0; 2]).expect("ok");
            assert!(
                out.states.iter().all(|s| s.internal[EPS_Q] > 0.0),
                "{mat:?} must flow plastically"
            );
            let err = fd_errors(&x, &du, &p, &st, mat.as_ref(), bulk);
            assert!(err.iter().all(|e| *e < 1e-6), "{mat:?} {scale}: {err:?}");
        }
    }
    // Not isochoric needs a finite K: it scales the projected pressure.
    let r = p2p1_element(
        &x,
        &big_step(&x, 0.01),
        &[0.0; 3],
        &st,
        &mc(0.0),
        f64::INFINITY,
        [0.0; 2],
    );
    assert!(matches!(r, Err(ElementError::Material { .. })));
}

#[test]
fn pressure_coupling_is_an_exact_transpose() {
    let x = curved_element();
    let st = prestress();
    let mat = clay();
    let du = big_step(&x, 0.3);
    let out = p2p1_element(&x, &du, &[1e5; 3], &st, &mat, 5e7, [0.0; 2]).expect("valid");
    let k = &out.tangent;
    for a in 0..N_U_DOFS {
        for m in N_U_DOFS..N_MIXED_DOFS {
            assert_eq!(k[a][m], k[m][a]);
        }
    }
    for m in N_U_DOFS..N_MIXED_DOFS {
        for n in N_U_DOFS..N_MIXED_DOFS {
            assert_eq!(k[m][n], k[n][m]);
            if m == n {
                assert!(k[m][n] < 0.0, "K_pp is negative definite");
            }
        }
    }
}

/// ‖K_uu − K_uuᵀ‖ / ‖K_uu‖.
fn uu_asymmetry(out: &MixedOutput) -> f64 {
    let (mut num, mut den) = (0.0, 0.0);
    for a in 0..N_U_DOFS {
        for b in 0..N_U_DOFS {
            num += (out.tangent[a][b] - out.tangent[b][a]).powi(2);
            den += out.tangent[a][b].powi(2);
        }
    }
    (num / den).sqrt()
}

#[test]
fn displacement_block_asymmetry_is_of_order_stress_over_modulus() {
    let x = curved_element();
    let mat = elastic();
    let (l, mu) = mat.lame();
    let bulk = l + 2.0 * mu / 3.0;
    let zero = <[GaussState; 3]>::default();
    let p0 = [0.0; 3];
    let small = homogeneous_du(&x, &[[1e-4, 2e-4], [-1e-4, 5e-5]], [0.0; 2]);
    let a0 = p2p1_element(&x, &small, &p0, &zero, &mat, bulk, [0.0; 2]).expect("ok");
    let a1 = p2p1_element(&x, &small, &[1.3e5; 3], &prestress(), &mat, bulk, [0.0; 2]).expect("ok");
    let (s0, s1) = (uu_asymmetry(&a0), uu_asymmetry(&a1));
    println!("K_uu asymmetry: unstressed, |H| = 2e-4: {s0:e}; |σ|/G = 3e-2: {s1:e}");
    assert!(s0 < 1e-3, "{s0:e}");
    assert!(s1 < 0.1, "{s1:e}");
}

// ---- objectivity and the yield condition ------------------------------------------------

#[test]
fn rigid_rotation_rotates_stress_exactly() {
    let x = curved_element();
    let st = prestress();
    let mat = clay();
    let p = vertex_pressure(&st);
    let zero = [[0.0; 2]; 6];
    let r0 = p2p1_element(&x, &zero, &p, &st, &mat, mat.bulk_modulus(), [0.0; 2]).expect("ok");
    for theta in [std::f64::consts::FRAC_PI_2, 1.1, -2.7] {
        let r = rot(theta);
        let g = [[r[0][0] - 1.0, r[0][1]], [r[1][0], r[1][1] - 1.0]];
        let du = homogeneous_du(&x, &g, [0.7, 0.4]);
        let r1 = p2p1_element(&x, &du, &p, &st, &mat, mat.bulk_modulus(), [0.0; 2]).expect("ok");
        for q in 0..3 {
            let s = st[q].stress;
            let rs = rotate(&r, &[[s[0], s[3]], [s[3], s[1]]]);
            let want = [rs[0][0], rs[1][1], s[2], rs[0][1]];
            assert!(
                rel_close(&r1.states[q].stress, &want, 3e-14),
                "θ {theta} gauss {q}: {:?} vs {want:?}",
                r1.states[q].stress
            );
            assert_eq!(r1.states[q].internal[EPS_Q], 0.0);
        }
        for a in 0..6 {
            let v = apply(&r, [r0.residual[2 * a], r0.residual[2 * a + 1]]);
            assert!(
                rel_close(&r1.residual[2 * a..2 * a + 2], &v, 1e-12),
                "θ {theta}"
            );
        }
        for i in N_U_DOFS..N_MIXED_DOFS {
            assert!(
                r1.residual[i].abs() < 1e-15,
                "volume residual {}",
                r1.residual[i]
            );
        }
    }
    // Not vacuous: the prestress is not in element equilibrium.
    assert!(r0.residual[..N_U_DOFS].iter().any(|v| v.abs() > 1e3));
}

#[test]
fn superposed_rotation_is_objective_elastic_and_plastic() {
    let x = curved_element();
    let st = prestress();
    let p = [1.2e5, 1.0e5, 1.5e5];
    let lin = elastic();
    let clay = clay();
    let mats: [&dyn Material; 2] = [&lin, &clay];
    for mat in mats {
        let g = [[0.1, 0.05], [0.05, -0.08]];
        let r = rot(1.1);
        let rg = mul(&r, &[[1.1, 0.05], [0.05, 0.92]]);
        let g2 = [[rg[0][0] - 1.0, rg[0][1]], [rg[1][0], rg[1][1] - 1.0]];
        let a = p2p1_element(
            &x,
            &homogeneous_du(&x, &g, [0.2, 0.3]),
            &p,
            &st,
            mat,
            4e7,
            [0.0; 2],
        )
        .expect("ok");
        let b = p2p1_element(
            &x,
            &homogeneous_du(&x, &g2, [0.2, 0.3]),
            &p,
            &st,
            mat,
            4e7,
            [0.0; 2],
        )
        .expect("ok");
        for q in 0..3 {
            let s = a.states[q].stress;
            let rs = rotate(&r, &[[s[0], s[3]], [s[3], s[1]]]);
            let want = [rs[0][0], rs[1][1], s[2], rs[0][1]];
            assert!(
                rel_close(&b.states[q].stress, &want, 1e-12),
                "{}",
                mat.name()
            );
            let eq = |s: &GaussState| s.internal.get(EPS_Q).copied().unwrap_or(0.0);
            assert!(
                (eq(&a.states[q]) - eq(&b.states[q])).abs() <= 1e-12 * eq(&a.states[q]).max(1e-30)
            );
        }
        for n in 0..6 {
            let v = apply(&r, [a.residual[2 * n], a.residual[2 * n + 1]]);
            assert!(rel_close(&b.residual[2 * n..2 * n + 2], &v, 1e-10));
        }
        assert!(rel_close(
            &b.residual[N_U_DOFS..],
            &a.residual[N_U_DOFS..],
            1e-10
        ));
    }
}

// ---- yield condition and the choice of kinematics ---------------------------------------

#[test]
fn end_of_step_cauchy_stress_is_on_the_yield_surface() {
    // Start on the yield surface (σxy = cu) under a mean stress p0 and continue shearing.
    // The displacement element imposes yield on S; this element on σ_{n+1}.
    let mat = clay();
    let x = p2::straight_sided(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    println!("p0/cu  step   |τmax−cu|/cu: GL/S (p2_element)   log/Cauchy (p2p1_element)");
    for p0_cu in [0.0, 1.0, 10.0, 100.0] {
        let p0 = p0_cu * CU;
        let st: [GaussState; 3] = std::array::from_fn(|_| state([-p0, -p0, -p0, CU]));
        for dg in [1e-3, 1e-2] {
            for g in [
                [[0.0, dg], [0.0, 0.0]],
                [[0.5 * dg, 0.3 * dg], [0.9 * dg, -0.5 * dg]],
            ] {
                let du = homogeneous_du(&x, &g, [0.3, 0.3]);
                let gl = p2_element(&x, &du, &st, &mat, [0.0; 2]).expect("ok");
                let mx = p2p1_element(&x, &du, &[p0; 3], &st, &mat, mat.bulk_modulus(), [0.0; 2])
                    .expect("ok");
                let err = |s: &[GaussState; 3]| {
                    s.iter()
                        .map(|g| (max_in_plane_shear(&g.stress) - CU).abs() / CU)
                        .fold(0.0, f64::max)
                };
                let (e_gl, e_mx) = (err(&gl.states), err(&mx.states));
                println!("{p0_cu:5} {dg:6.0e} {e_gl:24.2e} {e_mx:26.2e}");
                assert!(
                    mx.states.iter().all(|s| s.internal[EPS_Q] > 0.0),
                    "plastic step"
                );
                // Round-off of σxx − σyy is relative to |σ| ≈ p0.
                assert!(e_mx <= 1e-14 * p0_cu.max(1.0), "{e_mx:e}");
                if p0_cu >= 10.0 {
                    assert!(e_gl > 1e-3, "GL error at p0 = {p0_cu} cu: {e_gl:e}");
                }
            }
        }
    }
    // A large rotating step under high pressure: still on the surface to round-off.
    let st: [GaussState; 3] = std::array::from_fn(|_| state([-1e6, -1e6, -1e6, CU]));
    let du = big_step(&curved_element(), 1.0);
    let mx = p2p1_element(
        &curved_element(),
        &du,
        &[2e6; 3],
        &st,
        &mat,
        f64::INFINITY,
        [0.0; 2],
    )
    .expect("ok");
    for s in &mx.states {
        assert!(
            (max_in_plane_shear(&s.stress) - CU).abs() <= 1e-15 * 2e6,
            "{s:?}"
        );
    }
}

#[test]
fn elastic_response_matches_displacement_element_to_second_order() {
    let mat = elastic();
    let (l, mu) = mat.lame();
    let bulk = l + 2.0 * mu / 3.0;
    let x = curved_element();
    let g0 = [[0.8, 0.5], [-0.3, -0.6]];
    let zero = <[GaussState; 3]>::default();
    let mut diffs = Vec::new();
    for t in [1e-2, 5e-3, 2.5e-3] {
        let g = g0.map(|r| r.map(|v| t * v));
        let du = homogeneous_du(&x, &g, [0.4, 0.1]);
        let j = (1.0 + g[0][0]) * (1.0 + g[1][1]) - g[0][1] * g[1][0];
        let p = -bulk * (j - 1.0);
        let a = p2_element(&x, &du, &zero, &mat, [0.0; 2]).expect("ok");
        let b = p2p1_element(&x, &du, &[p; 3], &zero, &mat, bulk, [0.0; 2]).expect("ok");
        for k in N_U_DOFS..N_MIXED_DOFS {
            assert!(
                b.residual[k].abs() < 1e-16,
                "volume residual {}",
                b.residual[k]
            );
        }
        let sa = a.states[0].stress;
        let sb = b.states[0].stress;
        let scale = sa.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let d = sa
            .iter()
            .zip(&sb)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max)
            / scale;
        let ra = &a.residual[..N_U_DOFS];
        let rb = &b.residual[..N_U_DOFS];
        let rs = ra.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let dr = ra
            .iter()
            .zip(rb)
            .map(|(u, v)| (u - v).abs())
            .fold(0.0, f64::max)
            / rs;
        println!("step {t:.1e}: relative stress difference {d:.3e}, force difference {dr:.3e}");
        diffs.push((d, dr));
    }
    // Relative differences O(t), i.e. absolute O(t²): halving the step halves them.
    for w in diffs.windows(2) {
        for (big, small) in [(w[0].0, w[1].0), (w[0].1, w[1].1)] {
            let ratio = big / small;
            assert!((1.8..2.2).contains(&ratio), "ratio {ratio}");
        }
    }
    // And the constant is O(|g0|) = O(1): |Δσ| ≲ 3 t |σ| ~ 3 E t².
    assert!(diffs[0].0 < 3e-2 && diffs[0].1 < 3e-2, "{diffs:?}");

    // With a prestress the rates differ at first order: Truesdell (F S Fᵀ/J) against the
    // corotational update here, |Δσ| = O(t |σ_n|) on top of the O(E t²) above.
    let st = prestress();
    for t in [1e-2, 1e-3] {
        let g = g0.map(|r| r.map(|v| t * v));
        let du = homogeneous_du(&x, &g, [0.4, 0.1]);
        let jm1 = g[0][0] + g[1][1] + g[0][0] * g[1][1] - g[0][1] * g[1][0];
        let p: [f64; 3] = vertex_pressure(&st).map(|pv| pv - bulk * jm1);
        let a = p2_element(&x, &du, &st, &mat, [0.0; 2]).expect("ok");
        let b = p2p1_element(&x, &du, &p, &st, &mat, bulk, [0.0; 2]).expect("ok");
        for q in 0..3 {
            let sn = max_abs(st[q].stress);
            let d = max_abs((0..4).map(|k| a.states[q].stress[k] - b.states[q].stress[k]));
            let bound = 3.0 * t * (sn + mat.young * t);
            println!(
                "prestressed, step {t:.0e}: |Δσ| = {d:.3e}, t|σ_n| = {:.3e}",
                t * sn
            );
            assert!(d < bound, "{d:e} vs {bound:e}");
        }
    }
}

#[test]
fn undeformed_state_and_body_force() {
    let v = [[0.0, 0.0], [2.0, 0.5], [0.5, 1.5]];
    let x = p2::straight_sided(&v);
    let area = 0.5 * (2.0 * 1.5 - 0.5 * 0.5);
    let b = [3.0, -19620.0];
    let st = prestress();
    let p = vertex_pressure(&st);
    let mat = clay();
    let out = p2p1_element(&x, &[[0.0; 2]; 6], &p, &st, &mat, 1e8, b).expect("ok");
    let pure = p2p1_element(&x, &[[0.0; 2]; 6], &p, &st, &mat, 1e8, [0.0; 2]).expect("ok");
    for a in 0..6 {
        for i in 0..2 {
            let want = if a < 3 { 0.0 } else { -b[i] * area / 3.0 };
            let got = out.residual[2 * a + i] - pure.residual[2 * a + i];
            assert!(
                (got - want).abs() < 1e-10 * b[1].abs(),
                "node {a} comp {i}: {got}"
            );
        }
    }
    for q in 0..3 {
        assert!(rel_close(&out.states[q].stress, &st[q].stress, 1e-14));
    }
    for k in N_U_DOFS..N_MIXED_DOFS {
        assert!(out.residual[k].abs() < 1e-15);
    }
    // Nodal forces of the undeformed element are those of the displacement element.
    let d = p2_element(&x, &[[0.0; 2]; 6], &st, &mat, b).expect("ok");
    assert!(rel_close(&out.residual[..N_U_DOFS], &d.residual, 1e-13));
}

#[test]
fn errors_are_reported_not_panicked() {
    let x = curved_element();
    let st = prestress();
    let mat = clay();
    let zero = [[0.0; 2]; 6];
    for bulk in [0.0, -1.0, f64::NAN, f64::NEG_INFINITY] {
        match p2p1_element(&x, &zero, &[0.0; 3], &st, &mat, bulk, [0.0; 2]) {
            Err(e @ ElementError::Material { .. }) => {
                assert!(e.to_string().contains("bulk"), "{e}");
            }
            other => panic!("bulk {bulk}: {other:?}"),
        }
    }
    let reflect = [[-2.0, 0.0], [0.0, 0.0]];
    let du = homogeneous_du(&x, &reflect, [0.0, 0.0]);
    match p2p1_element(&x, &du, &[0.0; 3], &st, &mat, 1e8, [0.0; 2]) {
        Err(ElementError::Inverted { j, .. }) => assert!((j + 1.0).abs() < 1e-12),
        other => panic!("{other:?}"),
    }
    let mut nan = zero;
    nan[2][1] = f64::NAN;
    assert!(matches!(
        p2p1_element(&x, &nan, &[0.0; 3], &st, &mat, 1e8, [0.0; 2]),
        Err(ElementError::Inverted { .. })
    ));
    let cw = p2::straight_sided(&[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]);
    assert!(matches!(
        p2p1_element(&cw, &zero, &[0.0; 3], &st, &mat, 1e8, [0.0; 2]),
        Err(ElementError::DegenerateGeometry { .. })
    ));
}

#[test]
fn pressure_scaling_rescales_rows_and_columns() {
    let x = curved_element();
    let mat = clay();
    let du = big_step(&x, 0.1);
    let p = [1e5, 2e5, 1.5e5];
    let out = p2p1_element(&x, &du, &p, &prestress(), &mat, 1e8, [0.0; 2]).expect("ok");
    let alpha = 3.7e6;
    let sc = out.clone().with_pressure_scale(alpha);
    for k in 0..N_MIXED_DOFS {
        let fk = if k < N_U_DOFS { 1.0 } else { alpha };
        assert_eq!(sc.residual[k], fk * out.residual[k]);
        for l in 0..N_MIXED_DOFS {
            let fl = if l < N_U_DOFS { 1.0 } else { alpha };
            assert!(
                (sc.tangent[k][l] - fk * fl * out.tangent[k][l]).abs()
                    <= 1e-15 * (fk * fl * out.tangent[k][l]).abs()
            );
        }
    }
    assert_eq!(sc.states, out.states);
}

// ---- small meshes: test-only assembler and dense solver ---------------------------------

/// P2 mesh whose first `n_vert` nodes are the vertices (so vertex k carries pressure dof k).
struct Mesh {
    nodes: Vec<[f64; 2]>,
    elems: Vec<[usize; 6]>,
    n_vert: usize,
    /// Node lies on an edge used by one triangle only.
    boundary: Vec<bool>,
}

fn p2_mesh(verts: Vec<[f64; 2]>, tris: &[[usize; 3]]) -> Mesh {
    use std::collections::HashMap;
    let n_vert = verts.len();
    let mut nodes = verts;
    let mut edge_node: HashMap<(usize, usize), usize> = HashMap::new();
    let mut edge_count: HashMap<(usize, usize), usize> = HashMap::new();
    let mut elems = Vec::new();
    for t in tris {
        let mut e = [t[0], t[1], t[2], 0, 0, 0];
        for (k, [i, j]) in p2::EDGES.iter().enumerate() {
            let key = (t[*i].min(t[*j]), t[*i].max(t[*j]));
            *edge_count.entry(key).or_insert(0) += 1;
            e[3 + k] = *edge_node.entry(key).or_insert_with(|| {
                let (a, b) = (nodes[key.0], nodes[key.1]);
                nodes.push([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
                nodes.len() - 1
            });
        }
        elems.push(e);
    }
    let mut boundary = vec![false; nodes.len()];
    for (key, id) in &edge_node {
        if edge_count[key] == 1 {
            boundary[key.0] = true;
            boundary[key.1] = true;
            boundary[*id] = true;
        }
    }
    Mesh {
        nodes,
        elems,
        n_vert,
        boundary,
    }
}

/// nx × ny rectangles on [0, lx] × [0, ly], each split into two triangles with alternating
/// diagonals.
fn grid(nx: usize, ny: usize, lx: f64, ly: f64) -> Mesh {
    grid_with(nx, ny, lx, ly, true)
}

/// As [`grid`]; `alternate = false` puts every diagonal from lower left to upper right, so
/// that no interior vertex is "singular" (4 triangles on 2 lines): the mesh on which a pure
/// P2 discretisation of an incompressible problem has the fewest divergence-free modes.
fn grid_with(nx: usize, ny: usize, lx: f64, ly: f64, alternate: bool) -> Mesh {
    let mut verts = Vec::new();
    for j in 0..=ny {
        for i in 0..=nx {
            verts.push([lx * i as f64 / nx as f64, ly * j as f64 / ny as f64]);
        }
    }
    let v = |i: usize, j: usize| j * (nx + 1) + i;
    let mut tris = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1));
            if !alternate || (i + j) % 2 == 0 {
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            } else {
                tris.push([a, b, d]);
                tris.push([b, c, d]);
            }
        }
    }
    p2_mesh(verts, &tris)
}

/// Which element to assemble: the mixed one (with K and the pressure scale α) or the
/// displacement-only P2 element of `crate::fem::element`.
#[derive(Clone, Copy)]
enum Kind {
    Mixed { bulk: f64, alpha: f64 },
    Displacement,
}

struct System {
    r: Vec<f64>,
    k: Vec<Vec<f64>>,
    states: Vec<[GaussState; 3]>,
}

/// Unknowns: 2 per node, then (mixed only) the scaled pressures π = p/α at the vertices.
fn n_dofs(m: &Mesh, kind: Kind) -> usize {
    2 * m.nodes.len()
        + match kind {
            Kind::Mixed { .. } => m.n_vert,
            Kind::Displacement => 0,
        }
}

fn assemble(
    m: &Mesh,
    z: &[f64],
    states: &[[GaussState; 3]],
    mat: &dyn Material,
    kind: Kind,
) -> Result<System, ElementError> {
    assemble_in(Analysis::PlaneStrain, m, z, states, mat, kind)
}

/// [`assemble`] in the given analysis.
fn assemble_in(
    analysis: Analysis,
    m: &Mesh,
    z: &[f64],
    states: &[[GaussState; 3]],
    mat: &dyn Material,
    kind: Kind,
) -> Result<System, ElementError> {
    let n = n_dofs(m, kind);
    let nu = 2 * m.nodes.len();
    let mut r = vec![0.0; n];
    let mut k = vec![vec![0.0; n]; n];
    let mut new_states = Vec::new();
    for (e, st) in m.elems.iter().zip(states) {
        let x: [[f64; 2]; 6] = std::array::from_fn(|a| m.nodes[e[a]]);
        let du: [[f64; 2]; 6] = std::array::from_fn(|a| [z[2 * e[a]], z[2 * e[a] + 1]]);
        let (re, ke, se, dofs): (Vec<f64>, Vec<Vec<f64>>, _, Vec<usize>) = match kind {
            Kind::Mixed { bulk, alpha } => {
                let p: [f64; 3] = std::array::from_fn(|i| alpha * z[nu + e[i]]);
                let o = super::p2p1_element(&x, &du, &p, st, mat, bulk, [0.0; 2], analysis)?
                    .with_pressure_scale(alpha);
                let dofs = (0..N_MIXED_DOFS)
                    .map(|l| {
                        if l < N_U_DOFS {
                            2 * e[l / 2] + l % 2
                        } else {
                            nu + e[l - N_U_DOFS]
                        }
                    })
                    .collect();
                (
                    o.residual.to_vec(),
                    o.tangent.iter().map(|row| row.to_vec()).collect(),
                    o.states,
                    dofs,
                )
            }
            Kind::Displacement => {
                let o = crate::fem::element::p2_element_with(
                    &x, &du, st, mat, [0.0; 2], analysis, true,
                )?;
                let dofs = (0..N_U_DOFS).map(|l| 2 * e[l / 2] + l % 2).collect();
                (
                    o.residual.to_vec(),
                    o.tangent.iter().map(|row| row.to_vec()).collect(),
                    o.states,
                    dofs,
                )
            }
        };
        for (a, &da) in dofs.iter().enumerate() {
            r[da] += re[a];
            for (b, &db) in dofs.iter().enumerate() {
                k[da][db] += ke[a][b];
            }
        }
        new_states.push(se);
    }
    Ok(System {
        r,
        k,
        states: new_states,
    })
}

/// Dense LU with partial pivoting (pivots are needed: the saddle point has a zero or tiny
/// pressure block); solves for every column of `b`.
fn lu_solve(mut a: Vec<Vec<f64>>, mut b: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let n = a.len();
    for c in 0..n {
        let piv = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap_or(c);
        a.swap(c, piv);
        b.swap(c, piv);
        assert!(a[c][c].abs() > 1e-300, "singular test system");
        for i in c + 1..n {
            let f = a[i][c] / a[c][c];
            if f != 0.0 {
                for j in c..n {
                    a[i][j] -= f * a[c][j];
                }
                for j in 0..b[i].len() {
                    b[i][j] -= f * b[c][j];
                }
            }
        }
    }
    let m = b.first().map_or(0, |r| r.len());
    let mut x = vec![vec![0.0; m]; n];
    for i in (0..n).rev() {
        for col in 0..m {
            let s: f64 = (i + 1..n).map(|j| a[i][j] * x[j][col]).sum();
            x[i][col] = (b[i][col] - s) / a[i][i];
        }
    }
    x
}

fn reduce(k: &[Vec<f64>], free: &[usize]) -> Vec<Vec<f64>> {
    free.iter()
        .map(|&i| free.iter().map(|&j| k[i][j]).collect())
        .collect()
}

/// Newton on the free dofs from the given iterate `z` (fixed dofs already hold their
/// prescribed values). Returns the converged states and the iteration count.
fn newton(
    m: &Mesh,
    z: &mut [f64],
    free: &[usize],
    states: &[[GaussState; 3]],
    mat: &dyn Material,
    kind: Kind,
    tol: f64,
) -> (Vec<[GaussState; 3]>, usize) {
    for it in 0..25 {
        let sys = assemble(m, z, states, mat, kind).expect("valid mesh");
        let rmax = free.iter().fold(0.0_f64, |a, &d| a.max(sys.r[d].abs()));
        if rmax <= tol {
            return (sys.states, it);
        }
        let rhs = free.iter().map(|&d| vec![-sys.r[d]]).collect();
        let dz = lu_solve(reduce(&sys.k, free), rhs);
        for (&d, v) in free.iter().zip(dz) {
            z[d] += v[0];
        }
    }
    panic!("Newton did not converge");
}

fn max_abs(v: impl IntoIterator<Item = f64>) -> f64 {
    v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
}

// ---- patch test ---------------------------------------------------------------------------

/// Closed form of this element's update for a homogeneous step F = I + G of a linear elastic
/// material, computed independently: U = (C + J I)/√(tr C + 2J) (Cayley–Hamilton),
/// R = F U⁻¹, ε by eigenvectors, p = p_n − K (J − 1).
fn closed_form_sigma(g: &Mat2, sigma_n: &[f64; 4], mu: f64, bulk: f64) -> [f64; 4] {
    let f = [[1.0 + g[0][0], g[0][1]], [g[1][0], 1.0 + g[1][1]]];
    let j = f[0][0] * f[1][1] - f[0][1] * f[1][0];
    let c = mul(&transpose(&f), &f);
    let t = (c[0][0] + c[1][1] + 2.0 * j).sqrt();
    let u = [
        [(c[0][0] + j) / t, c[0][1] / t],
        [c[1][0] / t, (c[1][1] + j) / t],
    ];
    let uinv = [[u[1][1] / j, -u[0][1] / j], [-u[1][0] / j, u[0][0] / j]];
    let r = mul(&f, &uinv);
    let e = log_strain_by_eigenvectors(&f);
    let tr = (e[0] + e[1]) / 3.0;
    let mean_n = (sigma_n[0] + sigma_n[1] + sigma_n[2]) / 3.0;
    let s = [
        sigma_n[0] - mean_n + 2.0 * mu * (e[0] - tr),
        sigma_n[1] - mean_n + 2.0 * mu * (e[1] - tr),
        sigma_n[2] - mean_n - 2.0 * mu * tr,
        sigma_n[3] + mu * e[3],
    ];
    let jm1 = g[0][0] + g[1][1] + g[0][0] * g[1][1] - g[0][1] * g[1][0];
    let p = -mean_n - bulk * jm1;
    let rs = rotate(&r, &[[s[0], s[3]], [s[3], s[1]]]);
    [rs[0][0] - p, rs[1][1] - p, s[2] - p, rs[0][1]]
}

/// The curved 8-element patch of the displacement element's tests.
fn patch_mesh() -> Mesh {
    let mut m = grid(2, 2, 2.0, 2.0);
    m.nodes[4] = [1.15, 0.85];
    // Re-centre the midside nodes of the moved vertex, then bow all interior edges.
    for e in m.elems.clone() {
        for (k, [i, j]) in p2::EDGES.iter().enumerate() {
            let (a, b) = (m.nodes[e[*i]], m.nodes[e[*j]]);
            m.nodes[e[3 + k]] = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        }
    }
    for id in m.n_vert..m.nodes.len() {
        if !m.boundary[id] {
            let s = 0.04 * (1.0 + (id % 3) as f64);
            m.nodes[id][0] += s;
            m.nodes[id][1] -= 0.5 * s;
        }
    }
    m
}

#[test]
fn patch_test_homogeneous_large_step_with_prestress() {
    let m = patch_mesh();
    let mat = elastic();
    let (l, mu) = mat.lame();
    let bulk = l + 2.0 * mu / 3.0;
    let kind = Kind::Mixed { bulk, alpha: mu };
    // The tiny step runs without prestress: the prestress forces cancel between elements
    // only to round-off (~1e-16 × 1e5), which would swamp a 1e-8 strain increment.
    // The eigenvector-based closed form itself loses ~1e-8 relative accuracy at 1e-8 strain
    // (ln of eigenvalues 1 ± 1e-8), hence the looser stress tolerance there.
    for (g, sigma_n, tol, stol) in [
        (
            [[0.2, 0.05], [-0.1, -0.1]],
            [-1.0e5, -2.0e5, -1.2e5, 4.0e4],
            1e-8,
            1e-10,
        ),
        (
            [[1.0e-8, -0.4e-8], [0.7e-8, -0.6e-8]],
            [0.0; 4],
            1e-12,
            1e-7,
        ),
    ] {
        let st = vec![std::array::from_fn(|_| state(sigma_n)); m.elems.len()];
        let exact: Vec<[f64; 2]> = m.nodes.iter().map(|x| apply(&g, *x)).collect();
        let nu = 2 * m.nodes.len();
        let mut z = vec![0.0; n_dofs(&m, kind)];
        let mut free = Vec::new();
        for (a, e) in exact.iter().enumerate() {
            if m.boundary[a] {
                z[2 * a] = e[0];
                z[2 * a + 1] = e[1];
            } else {
                free.extend([2 * a, 2 * a + 1]);
            }
        }
        free.extend(nu..z.len());
        assert_eq!(free.len(), 18 + 9);
        let (states, _) = newton(&m, &mut z, &free, &st, &mat, kind, tol);
        let uscale = max_abs(exact.iter().flatten().copied());
        let err = max_abs(
            (0..m.nodes.len()).flat_map(|a| [z[2 * a] - exact[a][0], z[2 * a + 1] - exact[a][1]]),
        );
        assert!(
            err < 1e-10 * uscale,
            "interior displacement error {:e}",
            err / uscale
        );
        let want = closed_form_sigma(&g, &sigma_n, mu, bulk);
        let p_want = -(want[0] + want[1] + want[2]) / 3.0;
        for v in 0..m.n_vert {
            let p = mu * z[nu + v];
            assert!(
                (p - p_want).abs() < stol * p_want.abs(),
                "vertex {v}: {p} vs {p_want}"
            );
        }
        for s in states.iter().flatten() {
            assert!(
                rel_close(&s.stress, &want, stol),
                "{:?} vs {want:?}",
                s.stress
            );
        }
    }
}

// ---- volumetric locking -----------------------------------------------------------------

/// u = s ∇φ with φ = e^{2x} cos 2y harmonic: div u = Δφ = 0 and Δu = ∇Δφ = 0, so u solves
/// linear elasticity without body force for *every* ν with the same G, with zero pressure.
/// It is not a polynomial, so no nodal superconvergence makes a discretisation look exact.
fn divergence_free_field(x: [f64; 2]) -> [f64; 2] {
    let s = 1e-7;
    let e = (2.0 * x[0]).exp();
    let (sn, cs) = (2.0 * x[1]).sin_cos();
    [2.0 * s * e * cs, -2.0 * s * e * sn]
}

/// Solves the Dirichlet problem with boundary values from [`divergence_free_field`];
/// returns the nodal displacements.
fn solve_divergence_free(m: &Mesh, nu: f64, mixed: bool) -> Vec<[f64; 2]> {
    let g = 1e6;
    let mat = LinearElastic::new(2.0 * g * (1.0 + nu), nu).expect("valid");
    let (l, mu) = mat.lame();
    let kind = if mixed {
        Kind::Mixed {
            bulk: l + 2.0 * mu / 3.0,
            alpha: g / 0.25,
        }
    } else {
        Kind::Displacement
    };
    let mut z = vec![0.0; n_dofs(m, kind)];
    let mut free = Vec::new();
    for (a, x) in m.nodes.iter().enumerate() {
        if m.boundary[a] {
            let u = divergence_free_field(*x);
            z[2 * a] = u[0];
            z[2 * a + 1] = u[1];
        } else {
            free.extend([2 * a, 2 * a + 1]);
        }
    }
    free.extend(2 * m.nodes.len()..z.len());
    let st = vec![<[GaussState; 3]>::default(); m.elems.len()];
    newton(m, &mut z, &free, &st, &mat, kind, 1e-9);
    (0..m.nodes.len())
        .map(|a| [z[2 * a], z[2 * a + 1]])
        .collect()
}

#[test]
fn mixed_element_does_not_lock_where_p2_does() {
    // err[mesh][case], cases: P2–P1 at ν = 0.3, 0.4999, 0.49999, then P2 at the same.
    let nus = [0.3, 0.4999, 0.49999];
    let mut err = Vec::new();
    let mut gap = Vec::new(); // ‖u(0.4999) − u(0.3)‖ / ‖u‖ for P2–P1 and P2
    for n in [4, 8] {
        let m = grid_with(n, n, 1.0, 1.0, false);
        let exact: Vec<[f64; 2]> = m.nodes.iter().map(|x| divergence_free_field(*x)).collect();
        let scale = max_abs(exact.iter().flatten().copied());
        let diff = |u: &[[f64; 2]], v: &[[f64; 2]]| {
            max_abs(
                u.iter()
                    .zip(v)
                    .flat_map(|(a, b)| [a[0] - b[0], a[1] - b[1]]),
            ) / scale
        };
        let mut e = Vec::new();
        let mut sols = Vec::new();
        for mixed in [true, false] {
            for nu in nus {
                let u = solve_divergence_free(&m, nu, mixed);
                e.push(diff(&u, &exact));
                sols.push(u);
            }
        }
        gap.push([diff(&sols[1], &sols[0]), diff(&sols[4], &sols[3])]);
        println!(
            "n = {n}: nodal error / max|u|  P2–P1: {:.2e} {:.2e} {:.2e}   P2: {:.2e} {:.2e} {:.2e} \
             (ν = 0.3, 0.4999, 0.49999); |u(0.4999) − u(0.3)|: P2–P1 {:.2e}, P2 {:.2e}",
            e[0], e[1], e[2], e[3], e[4], e[5], gap[gap.len() - 1][0], gap[gap.len() - 1][1]
        );
        err.push(e);
    }
    // P2–P1: third-order convergence at every ν, and independent of K once K ≫ G.
    for case in 0..3 {
        assert!(
            err[0][case] / err[1][case] > 6.0,
            "P2–P1 case {case}: {err:?}"
        );
    }
    assert!(
        (err[1][2] - err[1][1]).abs() < 0.01 * err[1][1],
        "K-independent"
    );
    // So the nearly incompressible answer is the ν = 0.3 answer to discretisation accuracy.
    assert!(gap[1][0] < 5e-4, "{gap:?}");
    // P2: locks. Convergence drops to about second order, the error at K/G = 5e3 is many
    // times the compressible one and that of P2–P1, and it grows with K.
    assert!(err[0][4] / err[1][4] < 5.0, "{err:?}");
    assert!(err[1][4] > 20.0 * err[1][3]);
    assert!(err[1][4] > 5.0 * err[1][1]);
    assert!(err[1][5] > err[1][4]);
    assert!(gap[1][1] > 4.0 * gap[1][0]);
}

// ---- plane-strain compression of a block to 2 % -----------------------------------------

#[test]
fn block_compression_reaches_two_cu_without_volume_change() {
    let mat = clay();
    // The material's own K (ν = 0.49) and exact incompressibility.
    for bulk in [mat.bulk_modulus(), f64::INFINITY] {
        compress_block(&mat, bulk);
    }
}

/// Unconfined plane-strain compression of the unit block between frictionless platens to
/// 2 % nominal strain in 40 steps, with the checks of
/// [`block_compression_reaches_two_cu_without_volume_change`].
fn compress_block(mat: &Tresca, bulk: f64) {
    let mut m = grid(2, 2, 1.0, 1.0);
    let g = mat.shear_modulus();
    let kind = Kind::Mixed {
        bulk,
        alpha: g / 0.5,
    };
    let n_steps = 40;
    let dy = -0.02 / n_steps as f64;
    let nu = 2 * m.nodes.len();
    // Frictionless platens: ux = 0 on x = 0, uy = 0 on y = 0, prescribed uy on y = 1.
    let mut fixed = vec![None; nu];
    for (a, x) in m.nodes.iter().enumerate() {
        if x[0] == 0.0 {
            fixed[2 * a] = Some(0.0);
        }
        if x[1] == 0.0 {
            fixed[2 * a + 1] = Some(0.0);
        }
        if x[1] == 1.0 {
            fixed[2 * a + 1] = Some(dy);
        }
    }
    let mut free: Vec<usize> = (0..nu).filter(|&d| fixed[d].is_none()).collect();
    free.extend(nu..nu + m.n_vert);
    let area = |m: &Mesh| (m.nodes[2][0] - m.nodes[0][0]) * (m.nodes[6][1] - m.nodes[0][1]);
    let a0 = area(&m);
    let mut states = vec![<[GaussState; 3]>::default(); m.elems.len()];
    let mut pi = vec![0.0; m.n_vert]; // scaled pressures carried between steps
    let mut yield_area = None;
    let mut max_iters = 0;
    let mut sum_jm1 = 0.0; // Σ (J_k − 1), J_k = A_k / A_{k−1} (homogeneous)
    let mut plastic_jm1 = 0.0_f64;
    // Predictor: the previous step's increment. At the limit load the incremental solution
    // is not unique (a 45° shear band along the element diagonals is a zero-energy mode of
    // the perfectly plastic tangent), and a predictor that is not homogeneous (e.g. zero in
    // the interior) lets Newton settle on a localised solution with the same load. A
    // homogeneous predictor keeps the iterates in the homogeneous branch.
    let mut last = vec![0.0; nu];
    for step in 0..n_steps {
        let mut z = vec![0.0; nu + m.n_vert];
        for (d, f) in fixed.iter().enumerate() {
            z[d] = f.unwrap_or(last[d]);
        }
        z[nu..].copy_from_slice(&pi);
        let (new_states, iters) = newton(&m, &mut z, &free, &states, mat, kind, 1e-9 * CU);
        max_iters = max_iters.max(iters);
        let a_prev = area(&m);
        for (a, x) in m.nodes.iter_mut().enumerate() {
            x[0] += z[2 * a];
            x[1] += z[2 * a + 1];
        }
        let jm1 = area(&m) / a_prev - 1.0;
        sum_jm1 += jm1;
        pi.copy_from_slice(&z[nu..]);
        last.copy_from_slice(&z[..nu]);
        let plastic = new_states.iter().flatten().any(|s| s.internal[EPS_Q] > 0.0);
        if yield_area.is_some() {
            // Fully plastic step (the first plastic one still loads elastically to yield).
            plastic_jm1 = plastic_jm1.max(jm1.abs());
        }
        if plastic {
            yield_area.get_or_insert(area(&m));
        }
        for s in new_states.iter().flatten() {
            let t = max_in_plane_shear(&s.stress);
            if s.internal[EPS_Q] > 0.0 {
                // On the yield surface to round-off at every plastic step, with σzz
                // intermediate, so that the 3-D Tresca criterion holds as well.
                assert!((t - CU).abs() <= 1e-12 * CU, "step {step}: {s:?}");
                assert!(
                    (max_shear_3d(&s.stress) - CU).abs() <= 1e-12 * CU,
                    "step {step}"
                );
            } else {
                assert!(t <= CU, "step {step}: elastic state above yield {s:?}");
            }
        }
        states = new_states;
    }
    let yield_area = yield_area.expect("the block must yield");
    let s = states[0][0].stress;
    let p = -(s[0] + s[1] + s[2]) / 3.0;
    let a1 = area(&m);
    println!(
        "block at 2 %, K = {bulk:.1e}: σyy − σxx = {:.15} cu, σxx = {:.1e} cu, σxy = {:.1e} cu; \
         A/A0 − 1 = {:.6e}, Σ(J_k − 1) = {:.9e}, −p/K = {:.9e}; plastic steps: \
         max |J_k − 1| = {plastic_jm1:.1e}, A change {:.1e}; Newton iterations ≤ {max_iters}",
        (s[1] - s[0]) / CU,
        s[0] / CU,
        s[3] / CU,
        a1 / a0 - 1.0,
        sum_jm1,
        -p / bulk,
        a1 / yield_area - 1.0
    );
    for st in states.iter().flatten() {
        let s = st.stress;
        assert!(
            (s[1] - s[0] + 2.0 * CU).abs() <= 1e-8 * CU,
            "σyy − σxx = {}",
            s[1] - s[0]
        );
        assert!(s[0].abs() <= 1e-8 * CU && s[3].abs() <= 1e-8 * CU, "{s:?}");
        assert!(st.internal[EPS_Q] > 0.01, "plastic flow of about 1.5 %");
    }
    // Volume: exactly the elastic change. The constraint makes p_{k} − p_{k−1} =
    // −K (J_k − 1) in every step, so Σ (J_k − 1) = −p/K (A/A0 = Π J_k differs from
    // 1 + Σ (J_k − 1) by O(Σ (J_k − 1)²) = 2e-8), and plastic steps do not change it.
    assert!(
        (sum_jm1 + p / bulk).abs() <= 1e-12,
        "{sum_jm1} vs {}",
        -p / bulk
    );
    assert!(plastic_jm1 <= 1e-12, "{plastic_jm1:e}");
    assert!((a1 / yield_area - 1.0).abs() <= 1e-12);
    // Homogeneous: every node on the affine map of the corners. Not to round-off: at the
    // limit load the tangent is nearly singular in the shear-band direction, which amplifies
    // round-off in the first plastic step to ~5e-9.
    let (w, h) = (m.nodes[2][0], m.nodes[6][1]);
    let ref_mesh = grid(2, 2, 1.0, 1.0);
    for (x, x0) in m.nodes.iter().zip(&ref_mesh.nodes) {
        assert!((x[0] - w * x0[0]).abs() < 1e-8 && (x[1] - h * x0[1]).abs() < 1e-8);
    }
    // Quadratic convergence with the consistent tangent.
    assert!(max_iters <= 3, "Newton needed {max_iters} iterations");
}

// ---- conditioning of the assembled saddle point ------------------------------------------

/// ‖A‖₁ ‖A⁻¹‖₁.
fn condition_1(a: Vec<Vec<f64>>) -> f64 {
    let n = a.len();
    let norm1 = |m: &[Vec<f64>]| {
        (0..n)
            .map(|j| m.iter().map(|row| row[j].abs()).sum::<f64>())
            .fold(0.0, f64::max)
    };
    let id = (0..n)
        .map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    let na = norm1(&a);
    na * norm1(&lu_solve(a, id))
}

#[test]
fn pressure_scaling_conditions_the_saddle_point() {
    let m = grid(4, 4, 1.0, 1.0);
    let mat = clay();
    let (bulk, g) = (mat.bulk_modulus(), mat.shear_modulus());
    let h = 0.25;
    // Free: ux everywhere except x = 0, uy except y = 0 (a supported block), all pressures.
    let nu = 2 * m.nodes.len();
    let mut free: Vec<usize> = (0..nu).filter(|&d| m.nodes[d / 2][d % 2] != 0.0).collect();
    free.extend(nu..nu + m.n_vert);
    let st = vec![<[GaussState; 3]>::default(); m.elems.len()];
    let mut conds = Vec::new();
    for alpha in [1.0, g / h] {
        let kind = Kind::Mixed { bulk, alpha };
        let z = vec![0.0; n_dofs(&m, kind)];
        let sys = assemble(&m, &z, &st, &mat, kind).expect("ok");
        conds.push(condition_1(reduce(&sys.k, &free)));
    }
    let disp = {
        let z = vec![0.0; nu];
        let sys = assemble(&m, &z, &st, &mat, Kind::Displacement).expect("ok");
        condition_1(reduce(&sys.k, &free[..free.len() - m.n_vert]))
    };
    println!(
        "cond₁: P2–P1 unscaled {:.2e}, scaled α = G/h {:.2e}; P2 displacement {:.2e}",
        conds[0], conds[1], disp
    );
    assert!(conds[1] < 1e-6 * conds[0]);
    assert!(
        conds[1] < disp,
        "scaled saddle point no worse than the P2 system at ν = 0.49"
    );
}

// ---- axisymmetry: Lamé's thick-walled cylinder ---------------------------------------------

/// A long thick-walled cylinder (a = 1, b = 2, ends held axially) under internal pressure p:
/// σ_r = A − B/r², σ_θ = A + B/r², σ_z = 2νA with A = p a²/(b² − a²), B = p a² b²/(b² − a²).
/// The section is a strip of `nx` radial elements; the pressure is the consistent load of
/// [`crate::fem::surface_load::edge_pressure_in`] on the bore (p/E = 1e-6, so the geometric
/// nonlinearity is below the tolerance). Returns the largest error of σ_r, σ_θ and σ_z over
/// every Gauss point, relative to p.
fn lame_error(kind: Kind, nx: usize) -> f64 {
    use crate::fem::element::p2_gauss_points;
    use crate::fem::surface_load::edge_pressure_in;
    let nu = 0.49;
    let mat = LinearElastic::new(1.0e9, nu).expect("valid");
    let p = 1.0e3;
    let (a, b, height) = (1.0, 2.0, 0.05);
    let mut m = grid_with(nx, 1, b - a, height, false);
    for x in m.nodes.iter_mut() {
        x[0] += a;
    }
    let n = n_dofs(&m, kind);
    let nu_dofs = 2 * m.nodes.len();
    let tol = 1e-12;
    let held = |x: [f64; 2]| x[1] <= tol || x[1] >= height - tol;
    let free: Vec<usize> = (0..n)
        .filter(|&d| d >= nu_dofs || d % 2 == 0 || !held(m.nodes[d / 2]))
        .collect();
    // The bore's edge: from the top vertex down to the bottom one (body on the left).
    let bore: Vec<usize> = (0..m.nodes.len())
        .filter(|&k| (m.nodes[k][0] - a).abs() <= tol)
        .collect();
    let mut sorted = bore.clone();
    sorted.sort_by(|&i, &j| m.nodes[j][1].total_cmp(&m.nodes[i][1]));
    let load = edge_pressure_in(
        Analysis::Axisymmetric,
        [m.nodes[sorted[0]], m.nodes[sorted[1]], m.nodes[sorted[2]]],
        p,
    );
    let mut f_ext = vec![0.0; n];
    for (j, &k) in sorted.iter().enumerate() {
        f_ext[2 * k] += load.force[2 * j];
        f_ext[2 * k + 1] += load.force[2 * j + 1];
    }
    let zero: Vec<[GaussState; 3]> =
        vec![std::array::from_fn(|_| GaussState::default()); m.elems.len()];
    let mut z = vec![0.0; n];
    let mut states = Vec::new();
    for _ in 0..3 {
        let sys = assemble_in(Analysis::Axisymmetric, &m, &z, &zero, &mat, kind).expect("valid");
        let rhs = free.iter().map(|&d| vec![f_ext[d] - sys.r[d]]).collect();
        let dz = lu_solve(reduce(&sys.k, &free), rhs);
        for (&d, v) in free.iter().zip(dz) {
            z[d] += v[0];
        }
        states = sys.states;
    }
    let sys = assemble_in(Analysis::Axisymmetric, &m, &z, &zero, &mat, kind).expect("valid");
    let residual = max_abs(free.iter().map(|&d| sys.r[d] - f_ext[d]));
    assert!(residual <= 1e-9 * p, "not converged: {residual}");
    states = if states.is_empty() {
        sys.states
    } else {
        sys.states.clone()
    };
    let big_a = p * a * a / (b * b - a * a);
    let big_b = p * a * a * b * b / (b * b - a * a);
    let mut worst = 0.0f64;
    for (e, st) in m.elems.iter().zip(&states) {
        let x: [[f64; 2]; 6] = std::array::from_fn(|k| m.nodes[e[k]]);
        for (g, s) in p2_gauss_points(&x).iter().zip(st) {
            let r2 = g[0] * g[0];
            let exact = [
                big_a - big_b / r2,
                2.0 * nu * big_a,
                big_a + big_b / r2,
                0.0,
            ];
            for c in 0..4 {
                worst = worst.max((s.stress[c] - exact[c]).abs() / p);
            }
        }
    }
    worst
}

#[test]
fn thick_walled_cylinder_matches_lame_with_p2_and_p2p1() {
    let bulk = 1.0e9 / (3.0 * (1.0 - 2.0 * 0.49));
    for (name, kind) in [
        ("P2", Kind::Displacement),
        (
            "P2-P1",
            Kind::Mixed {
                bulk,
                alpha: 1.0e9 / 0.03,
            },
        ),
    ] {
        // Gauss-point stresses converge as h²: 5.0e-3 at 16 radial elements, 1.3e-3 at 32.
        let coarse = lame_error(kind, 64);
        let fine = lame_error(kind, 128);
        println!("{name}: Lamé error {coarse:.2e} (64 elements), {fine:.2e} (128)");
        assert!(fine < 1e-4, "{name}: {fine:e}");
        assert!(coarse > 3.0 * fine, "{name}: second order");
    }
}
