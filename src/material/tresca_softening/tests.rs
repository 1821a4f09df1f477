// Index loops mirror the component notation of the formulas being checked.
#![allow(clippy::needless_range_loop)]

use super::*;
use crate::material::tresca::{self, Tresca};

const SU_REF: f64 = 2.0e4;
const E: f64 = 5.0e6;
const NU: f64 = 0.49;

fn g() -> f64 {
    E / (2.0 * (1.0 + NU))
}

fn clay(delta: f64, xi95: f64) -> TrescaSoftening {
    TrescaSoftening::new(E, NU, SU_REF, delta, xi95, 0.0, None).expect("valid")
}

fn rated(delta: f64, xi95: f64, mu: f64, gref: f64) -> TrescaSoftening {
    TrescaSoftening::new(E, NU, SU_REF, delta, xi95, mu, Some(gref)).expect("valid")
}

/// The steps last `dt` seconds (None: no time), outside any element.
fn clock(dt: Option<f64>) {
    site::set_increment(1, 0.0, 1.0, dt.map(|d| [0.0, d]));
    site::clear_element();
}

fn drive(m: &dyn Material, st: GaussState, incs: &[[f64; 4]]) -> Vec<GaussState> {
    let mut out = Vec::new();
    let mut cur = st;
    for de in incs {
        let r = m.update(&cur, de).expect("update");
        cur = r.state;
        cur.stress = r.s;
        out.push(cur.clone());
    }
    out
}

fn s_of(delta: f64, xi: f64, xi95: f64) -> f64 {
    delta + (1.0 - delta) * (-3.0 * xi / xi95).exp()
}

#[test]
fn rejects_bad_parameters_naming_the_field() {
    let nan = f64::NAN;
    type Case = (f64, f64, f64, f64, f64, f64, Option<f64>, &'static str);
    let cases: [Case; 16] = [
        (0.0, NU, SU_REF, 0.5, 1.0, 0.0, None, "young"),
        (E, 0.5, SU_REF, 0.5, 1.0, 0.0, None, "poisson"),
        (E, NU, 0.0, 0.5, 1.0, 0.0, None, "cu"),
        (E, NU, nan, 0.5, 1.0, 0.0, None, "cu"),
        (E, NU, SU_REF, 0.0, 1.0, 0.0, None, "remoulded_ratio"),
        (E, NU, SU_REF, 1.5, 1.0, 0.0, None, "remoulded_ratio"),
        (E, NU, SU_REF, nan, 1.0, 0.0, None, "remoulded_ratio"),
        (E, NU, SU_REF, 0.5, 0.0, 0.0, None, "xi95"),
        (E, NU, SU_REF, 0.5, -2.0, 0.0, None, "xi95"),
        (E, NU, SU_REF, 0.5, f64::INFINITY, 0.0, None, "xi95"),
        (E, NU, SU_REF, 0.5, nan, 0.0, None, "xi95"),
        (E, NU, SU_REF, 0.5, 1.0, -0.1, None, "rate_parameter"),
        (E, NU, SU_REF, 0.5, 1.0, nan, None, "rate_parameter"),
        (E, NU, SU_REF, 0.5, 1.0, 0.1, None, "reference_rate"),
        (E, NU, SU_REF, 0.5, 1.0, 0.1, Some(0.0), "reference_rate"),
        (E, NU, SU_REF, 0.5, 1.0, 0.1, Some(-1.0), "reference_rate"),
    ];
    for (e, nu, cu, d, x, mu, r, field) in cases {
        match TrescaSoftening::new(e, nu, cu, d, x, mu, r) {
            Err(err @ MaterialError::InvalidParameter { name, .. }) => {
                assert_eq!(name, field);
                assert!(err.to_string().contains(field), "{err}");
            }
            other => panic!("{field}: expected a rejection, got {other:?}"),
        }
    }
    let bad = clay(0.5, 1.0).with_reference_spacing(0.0);
    assert!(matches!(
        bad,
        Err(MaterialError::InvalidParameter {
            name: "xi95_reference_spacing",
            ..
        })
    ));
    // μ = 0 needs no reference rate; δ_rem = 1 is allowed (no softening).
    assert!(TrescaSoftening::new(E, NU, SU_REF, 1.0, 1.0, 0.0, None).is_ok());
}

#[test]
fn simple_shear_stress_follows_the_softening_formula() {
    // τ = su_ref S(ξ) at every plastic increment, with ξ both as the model accumulates it and
    // as the total shear strain less the elastic part, γ − τ/G.
    clock(None);
    let (delta, xi95) = (0.3, 0.05);
    let m = clay(delta, xi95);
    let dg = 0.2 * SU_REF / g();
    let states = drive(&m, GaussState::default(), &[[0.0, 0.0, 0.0, dg]; 200]);
    let mut plastic = 0;
    let mut worst: f64 = 0.0;
    for (k, st) in states.iter().enumerate() {
        let gamma = dg * (k + 1) as f64;
        let tau = st.stress[3];
        let xi = st.internal[XI];
        if xi == 0.0 {
            assert!(
                (tau - g() * gamma).abs() <= 1e-9 * SU_REF,
                "elastic inc {k}"
            );
            continue;
        }
        plastic += 1;
        let formula = SU_REF * s_of(delta, xi, xi95);
        worst = worst.max((tau / formula - 1.0).abs());
        assert!(
            (xi - (gamma - tau / g())).abs() <= 1e-10 * gamma,
            "inc {k}: ξ"
        );
        assert!((st.internal[EPS_Q] * 3.0_f64.sqrt() - xi).abs() <= 1e-12 * xi);
        assert!((st.internal[3] - xi).abs() <= 1e-12 * xi, "γ^p_xy = ξ");
        assert!(
            (st.internal[SU] - tau).abs() <= 1e-12 * SU_REF,
            "su is the stress"
        );
        assert_eq!(st.stress[..3], [0.0; 3]);
    }
    println!("simple shear, {plastic} plastic increments: τ/formula − 1 at most {worst:.1e}");
    assert!(plastic > 190);
    assert!(worst < 1e-8, "{worst:e}");
    // The strength has fallen to within 1 % of remoulded (ξ reaches 0.8 ≫ ξ95 = 0.05).
    let last = states.last().expect("states").stress[3];
    assert!((last / (delta * SU_REF) - 1.0).abs() < 1e-2, "{last}");
    assert!(last > delta * SU_REF);
}

#[test]
fn without_softening_it_is_tresca() {
    clock(None);
    let m = clay(1.0, 1.0);
    let t = Tresca::new(E, NU, SU_REF).expect("valid");
    let incs = [[3e-3, -2e-3, 0.0, 4e-3]; 20];
    let pre = GaussState::stressed([-1e5, -1.1e5, -1.05e5, 2e3], 0);
    let a = drive(&m, pre.clone(), &incs);
    let b = drive(&t, pre, &incs);
    for (x, y) in a.iter().zip(&b) {
        for i in 0..4 {
            assert!((x.stress[i] - y.stress[i]).abs() <= 1e-9 * 1e5);
        }
        assert!((x.internal[EPS_Q] - y.internal[EPS_Q]).abs() <= 1e-15);
    }
}

#[test]
fn the_rate_factor_multiplies_the_strength() {
    let (mu, gref) = (0.1, 1e-3);
    let (delta, xi95) = (0.5, 0.2);
    let m = rated(delta, xi95, mu, gref);
    let dg = 0.25 * SU_REF / g();
    for dt in [dg / (100.0 * gref), dg / gref * 10.0] {
        clock(Some(dt));
        let states = drive(&m, GaussState::default(), &[[0.0, 0.0, 0.0, dg]; 40]);
        let rate = (1.0 + mu * (dg / dt / gref).log10()).max(1.0);
        let st = &states[39];
        let xi = st.internal[XI];
        assert!(xi > 0.0);
        let want = SU_REF * rate * s_of(delta, xi, xi95);
        assert!(
            (st.stress[3] / want - 1.0).abs() < 1e-12,
            "dt {dt}: {} vs {want}",
            st.stress[3]
        );
        if dt > dg / gref {
            assert_eq!(rate, 1.0, "slower than γ̇_ref: no rate effect");
        } else {
            assert!((rate - 1.2).abs() < 1e-12, "two decades: {rate}");
        }
    }
    // Two rates, one decade apart, both above γ̇_ref, give strengths in the exact ratio.
    let at = |dt: f64| {
        clock(Some(dt));
        let states = drive(
            &clay_rated_no_softening(mu, gref),
            GaussState::default(),
            &[[0.0, 0.0, 0.0, dg]; 10],
        );
        states[9].stress[3]
    };
    let (slow, fast) = (at(dg / (10.0 * gref)), at(dg / (100.0 * gref)));
    assert!((fast / slow - 1.2 / 1.1).abs() < 1e-13, "{}", fast / slow);
    // Without time the rate-dependent model refuses, naming its parameter.
    clock(None);
    match m.update(&GaussState::default(), &[0.0, 0.0, 0.0, dg]) {
        Err(e @ MaterialError::InvalidParameter { name, .. }) => {
            assert_eq!(name, "rate_parameter");
            assert!(e.to_string().contains("duration"), "{e}");
        }
        other => panic!("expected an error, got {other:?}"),
    }
    // A zero-length increment (geostatic equilibration) has rate factor 1.
    clock(Some(0.0));
    let r = m
        .update(&GaussState::default(), &[0.0, 0.0, 0.0, 10.0 * dg])
        .expect("ok");
    assert!((r.state.internal[SU] - SU_REF * s_of(delta, r.state.internal[XI], xi95)).abs() < 1e-9);
}

fn clay_rated_no_softening(mu: f64, gref: f64) -> TrescaSoftening {
    rated(1.0, 1.0, mu, gref)
}

fn fd_error(m: &dyn Material, st: &GaussState, e: &[f64; 4]) -> f64 {
    crate::material::tangent_fd_error(m, st, e, 1e-8, 0.0)
}

fn asymmetry(d: &[[f64; 4]; 4]) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..4 {
        for j in 0..4 {
            worst = worst.max((d[i][j] - d[j][i]).abs() / g());
        }
    }
    worst
}

#[test]
fn consistent_tangent_matches_finite_differences() {
    let mut pre = GaussState::stressed([-1.5e5, -1.7e5, -1.3e5, 1.2e4], 0);
    let strains = [
        [3e-2, -1e-2, 0.0, 4e-2],
        [-2e-2, 1.6e-2, 0.0, -4e-3],
        [1e-3, 1e-3, 0.0, 2.4e-2],
        [2e-3, -1e-3, 0.0, 3e-3],
    ];
    // Rate-independent, fresh and part-softened: symmetric.
    clock(None);
    let m = clay(0.3, 0.1);
    assert!(m.symmetric_tangent());
    for xi in [0.0, 0.05] {
        pre.internal = smallvec::smallvec![0.0, 0.0, 0.0, 0.0, xi / 3f64.sqrt(), xi, SU_REF];
        for e in strains {
            let r = m.update(&pre, &e).expect("ok");
            assert!(r.state.internal[XI] > xi, "must be plastic: {e:?}");
            let err = fd_error(&m, &pre, &e);
            println!("ξ_n {xi}, {e:?}: tangent vs FD {err:.1e}");
            assert!(err < 1e-6, "{e:?}: {err:e}");
            assert!(asymmetry(&r.d) < 1e-10, "{e:?}");
            // The softening shows in the tangent: the radial stiffness is negative.
            assert!(r.d[3][3] < g() * 0.5);
        }
    }
    // Rate-dependent above γ̇_ref: not symmetric, and still the derivative.
    let m = rated(0.3, 0.1, 0.15, 1e-4);
    assert!(!m.symmetric_tangent());
    clock(Some(1.0));
    for e in strains {
        let err = fd_error(&m, &pre, &e);
        let r = m.update(&pre, &e).expect("ok");
        println!(
            "rate: {e:?}: tangent vs FD {err:.1e}, asymmetry {:.1e}",
            asymmetry(&r.d)
        );
        assert!(err < 1e-6, "{e:?}: {err:e}");
    }
    let r = m.update(&pre, &strains[3]).expect("ok");
    assert!(asymmetry(&r.d) > 1e-3, "the rate term is not symmetric");
    // Elastic: the elastic tangent.
    let err = fd_error(&m, &GaussState::default(), &[1e-4, -5e-5, 0.0, 2e-5]);
    assert!(err < 1e-7, "{err:e}");
}

#[test]
fn regularisation_scales_xi95_with_the_element_size() {
    clock(None);
    let h_ref = 0.1;
    let m = clay(0.3, 0.05)
        .with_reference_spacing(h_ref)
        .expect("valid");
    let plain_2x = clay(0.3, 0.1);
    // A right isosceles triangle of legs h has size √(2 · h²/2) = h.
    let h = 0.05;
    let corners = [[0.0, 0.0], [h, 0.0], [0.0, h]];
    let mid = |a: [f64; 2], b: [f64; 2]| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
    let x = [
        corners[0],
        corners[1],
        corners[2],
        mid(corners[0], corners[1]),
        mid(corners[1], corners[2]),
        mid(corners[2], corners[0]),
    ];
    site::set_element(0, &x);
    assert!((site::element_size().expect("set") - h).abs() < 1e-15);
    assert!((m.xi95_here() - 0.1).abs() < 1e-15, "ξ95 h_ref/h");
    let e = [0.0, 0.0, 0.0, 0.05];
    let a = m.update(&GaussState::default(), &e).expect("ok");
    site::clear_element();
    let b = plain_2x.update(&GaussState::default(), &e).expect("ok");
    assert_eq!(a.s, b.s);
    // Outside an element, ξ95 as given.
    let c = m.update(&GaussState::default(), &e).expect("ok");
    assert!(c.s[3] < a.s[3]);
}

#[test]
fn admit_clamps_and_scales_onto_the_strength() {
    clock(None);
    let m = clay(0.4, 0.1);
    // Admissible: unchanged, bitwise.
    let mut ok = GaussState::stressed([-1e5, -1.2e5, -1.1e5, 5e3], 7);
    ok.internal[EPS_Q] = 0.01;
    ok.internal[XI] = 0.01 * 3f64.sqrt();
    ok.internal[SU] = 1.5e4;
    let before = ok.clone();
    assert!(!m.admit(&mut ok));
    assert_eq!(ok, before);
    // Overshooting recovery: negative ξ and eps_q, τ_max above su.
    let mut bad = before.clone();
    bad.internal[EPS_Q] = -0.2;
    bad.internal[XI] = -0.3;
    bad.stress[3] = 3.0e4;
    assert!(m.admit(&mut bad));
    assert_eq!(bad.internal[EPS_Q], 0.0);
    assert_eq!(bad.internal[XI], 0.0);
    let r = tresca::max_in_plane_shear(&bad.stress);
    assert!((r - 1.5e4).abs() < 1e-9, "{r}");
    let mean = |s: &[f64; 4]| s[0] + s[1];
    assert_eq!(mean(&bad.stress), mean(&before.stress));
    assert_eq!(bad.stress[2], before.stress[2]);
    // A strength read as 0 (another material's column) is floored at the remoulded strength.
    let mut zero = before.clone();
    zero.internal[SU] = 0.0;
    assert!(m.admit(&mut zero));
    assert_eq!(zero.internal[SU], 0.4 * SU_REF);
    assert!((tresca::max_in_plane_shear(&zero.stress) - 0.4 * SU_REF).abs() < 1e-9);
}

#[test]
fn tresca_is_admitted_by_its_zero_strain_return() {
    let t = Tresca::new(E, NU, SU_REF).expect("valid");
    let mut ok = GaussState::stressed([-1e5, -1.2e5, -1.1e5, 5e3], 5);
    let before = ok.clone();
    assert!(!t.admit(&mut ok));
    assert_eq!(ok, before);
    let mut bad = before.clone();
    bad.stress[3] = 1.09 * SU_REF;
    bad.internal[4] = -0.6;
    assert!(t.admit(&mut bad));
    assert_eq!(bad.internal[4], 0.0, "eps_q clamped");
    assert_eq!(bad.internal[..4], [0.0; 4], "no plastic strain added");
    let r = tresca::max_in_plane_shear(&bad.stress);
    assert!((r - SU_REF).abs() < 1e-9 * 1e5, "{r}");
    assert!((bad.stress[0] + bad.stress[1] - (before.stress[0] + before.stress[1])).abs() < 1e-9);
}
