// Index loops mirror the component notation of the formulas being checked.
#![allow(clippy::needless_range_loop)]

use super::*;

const C: f64 = 20.0e3;

fn soil(phi: f64, psi: f64, fit: Match) -> DruckerPrager {
    DruckerPrager::new(30.0e6, 0.3, C, phi, psi, fit).expect("valid parameters")
}

fn at(s: [f64; 4]) -> GaussState {
    GaussState {
        stress: s,
        ..GaussState::default()
    }
}

fn fd_error(m: &DruckerPrager, st: &GaussState, e: &[f64; 4]) -> f64 {
    crate::material::tangent_fd_error(m, st, e, 1e-9, m.young)
}

#[test]
fn plane_strain_match_is_the_textbook_one_when_associated() {
    for phi in [10.0f64, 20.0, 30.0, 40.0] {
        let m = soil(phi, phi, Match::PlaneStrain);
        let t = phi.to_radians().tan();
        let root = (9.0 + 12.0 * t * t).sqrt();
        assert!((m.eta - 3.0 * t / root).abs() < 1e-14, "{phi}");
        assert!((m.xi - 3.0 / root).abs() < 1e-14, "{phi}");
        assert!(m.symmetric_tangent());
    }
    let outer = soil(30.0, 30.0, Match::Outer);
    assert!((outer.eta - 6.0 * 0.5 / (3f64.sqrt() * 2.5)).abs() < 1e-14);
    let inner = soil(30.0, 30.0, Match::Inner);
    // The plane-strain cone lies inside both corner cones.
    assert!(soil(30.0, 30.0, Match::PlaneStrain).eta < inner.eta && inner.eta < outer.eta);
    assert!(!soil(30.0, 0.0, Match::PlaneStrain).symmetric_tangent());
}

#[test]
fn plane_strain_limit_state_is_mohr_coulomb() {
    // At a plane-strain limit s_zz = −(2/3) η̄ √J2; there the cone reads Mohr–Coulomb's in-plane
    // criterion, for ψ = φ and ψ < φ alike.
    for (phi, psi) in [(30.0f64, 30.0f64), (30.0, 0.0), (25.0, 10.0)] {
        let m = soil(phi, psi, Match::PlaneStrain);
        let (sf, cf) = phi.to_radians().sin_cos();
        let (centre, r) = (-100.0e3f64, 0.0f64);
        // Solve for the radius on the cone: r + centre sin φ = c cos φ.
        let r = r + C * cf - centre * sf;
        let q = r / (1.0 - m.eta_bar * m.eta_bar / 3.0).sqrt();
        let szz = centre - m.eta_bar * q; // σzz − centre = d = −η̄ √J2
        let s = [centre + r, centre - r, szz, 0.0];
        assert!(m.yield_function(&s).abs() < 1e-9 * 1e5, "{phi} {psi}");
    }
}

#[test]
fn cone_and_apex_returns() {
    let m = soil(30.0, 10.0, Match::PlaneStrain);
    let tr = [-50.0e3, -250.0e3, -120.0e3, 20.0e3];
    let r = m.update(&at(tr), &[0.0; 4]).expect("ok");
    assert!(m.yield_function(&r.s).abs() < 1e-10 * 250e3);
    // The deviator only shrinks: it keeps its direction.
    let (d0, q0) = deviator(&tr);
    let (d1, q1) = deviator(&r.s);
    for i in 0..4 {
        assert!((d1[i] / q1 - d0[i] / q0).abs() < 1e-12);
    }
    // Dilation: Δε_v^p / Δγ = η̄.
    let (l, g) = m.elastic().lame();
    let k = l + 2.0 * g / 3.0;
    let dgamma = (q0 - q1) / g;
    let ev: f64 = r.state.internal[..3].iter().sum();
    assert!(
        (ev / dgamma - m.eta_bar).abs() < 1e-9,
        "{} {}",
        ev / dgamma,
        m.eta_bar
    );
    let p_tr = (tr[0] + tr[1] + tr[2]) / 3.0;
    let p = (r.s[0] + r.s[1] + r.s[2]) / 3.0;
    assert!((p_tr - p - k * m.eta_bar * dgamma).abs() < 1e-9 * 1e5);
    // Apex.
    let apex = m.xi * C / m.eta;
    let r = m
        .update(&at([2.0 * apex, 2.0 * apex, 2.0 * apex, 10.0]), &[0.0; 4])
        .expect("ok");
    for i in 0..3 {
        assert!((r.s[i] - apex).abs() < 1e-12 * apex);
    }
    assert_eq!(r.s[3], 0.0);
}

#[test]
fn consistent_tangent_matches_finite_differences() {
    for fit in [Match::PlaneStrain, Match::Outer, Match::Inner] {
        for psi in [30.0, 10.0, 0.0] {
            let m = soil(30.0, psi, fit);
            let st = at([0.0, -300.0e3, -150.0e3, 30.0e3]);
            let e = [1e-5, -2e-5, 0.0, 1e-5];
            let r = m.update(&st, &e).expect("ok");
            assert!(r.state.internal[EPS_Q] > 0.0);
            let err = fd_error(&m, &st, &e);
            assert!(err < 1e-6, "{fit:?} ψ = {psi}: {err:e}");
            let asym = (0..4)
                .flat_map(|i| (0..4).map(move |j| (i, j)))
                .fold(0.0f64, |a, (i, j)| a.max((r.d[i][j] - r.d[j][i]).abs()));
            if psi == 30.0 {
                assert!(asym < 1e-9 * r.d[0][0], "{fit:?}: {asym:e}");
            } else {
                assert!(asym > 1e-3 * r.d[0][0], "{fit:?}: {asym:e}");
            }
        }
    }
}

#[test]
fn rejects_bad_parameters_naming_the_field() {
    for (c, phi, psi, field) in [
        (C, 30.0, 35.0, "dilation_angle"),
        (C, 95.0, 0.0, "friction_angle"),
        (-1.0, 30.0, 0.0, "cohesion"),
    ] {
        match DruckerPrager::new(30e6, 0.3, c, phi, psi, Match::PlaneStrain) {
            Err(MaterialError::InvalidParameter { name, .. }) => assert_eq!(name, field),
            other => panic!("expected rejection of {field}, got {other:?}"),
        }
    }
    assert!(DruckerPrager::new(0.0, 0.3, C, 30.0, 0.0, Match::Outer).is_err());
}
