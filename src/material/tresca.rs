//! Undrained clay: plane-strain Tresca, elastic–perfectly plastic, strength `cu`.
//!
//! # Yield criterion
//! f(σ) = τ_max − cu with τ_max = √(((σxx − σyy)/2)² + σxy²), the largest *in-plane* shear
//! stress. This is the Tresca criterion of plane strain: it equals the 3-D Tresca criterion
//! (σ_1 − σ_3)/2 = cu whenever σzz is the intermediate principal stress, i.e. within cu of the
//! in-plane mean c = (σxx + σyy)/2. That holds for undrained clay loaded in plane strain from an
//! admissible isotropic or K0 state (σzz = σh gives |σzz − c| = |σv − σh|/2 ≤ cu), because
//! σzz − c = (3/2) s_zz changes, elastically and plastically alike, only by −G tr ε, which is
//! G Δp/K ≪ cu when nearly incompressible. [`max_shear_3d`] lets a caller check it. It is the criterion behind the textbook collapse loads (Prandtl
//! footing (2 + π) cu, unconfined block 2cu), and it holds them *exactly* from the first plastic
//! step.
//!
//! Why not the von Mises cylinder with σ_y = √3 cu: q² = 3 τ_max² + (9/4) s_zz², so von Mises
//! only reaches τ_max = cu once plastic flow has driven the out-of-plane deviator s_zz to zero
//! (radial return multiplies it by σ_y/q_trial < 1 per plastic step). From an initial state with
//! s_zz ≠ 0 (any K0 ≠ 1 geostatic state, or ν < 0.5 elastic loading) the in-plane strength is
//! √(cu² − ¾ s_zz²) until then; measured for unconfined plane-strain compression to 2 % with
//! E/cu = 300, ν = 0.49: σyy − σxx falls short of 2cu by 2.2e-7 (relative), 5.6e-5 at first yield.
//!
//! # Flow rule and update
//! Associated flow: Δε^p = Δλ ∂f/∂σ, which has no zz and no volumetric component, so plastic flow
//! is isochoric and compatible with ε_zz = 0. Backward Euler is a radial return in the in-plane
//! deviatoric plane and is closed form for perfect plasticity. With the trial state
//! S_tr = σ_n + D^e ε, a = (S_tr,xx − S_tr,yy)/2, τ = S_tr,xy, r = √(a² + τ²):
//! - r ≤ cu: elastic, S = S_tr;
//! - else β = cu / r, Δλ = (r − cu)/G, and the in-plane deviator (a, −a, 0, τ) is scaled by β;
//!   mean stress, σzz and (σxx + σyy)/2 keep their trial values.
//!
//! The consistent tangent is D = K m⊗m + 2G (P_dev − P_in) + 2Gβ (P_in − N⊗N), with P_in the
//! projector onto in-plane deviators and N the unit in-plane trial deviator (β = 1, no N⊗N term
//! when elastic); it is symmetric.
//!
//! `eps_q` accumulates Δγ̄ = √(2/3 Δε^p:Δε^p) = Δλ/√3 over steps (the accumulated equivalent
//! plastic strain of [`GaussState`]); for proportional loading it equals √(2/3 ε^p:ε^p) of the
//! total plastic strain.
//!
//! # Kinematics
//! Which strain/stress pair the update acts on is the element's choice. With
//! [`crate::fem::element::p2_element`] it is (Green–Lagrange strain, 2nd Piola–Kirchhoff stress
//! relative to x_n): the yield condition then holds for S, and the end-of-step Cauchy stress
//! F S Fᵀ/J misses it by O(step strain × |σ|), e.g. 1e-2 cu for a 1e-3 step at a mean stress of
//! 10 cu. With [`crate::fem::mixed::p2p1_element`] it is (logarithmic strain, rotation-free
//! Cauchy stress), and the end-of-step Cauchy stress is on the yield surface to round-off.

use super::elastic::LinearElastic;
use super::layout::{grew, internal_len};
use super::principal::Spectral;
use super::rounded_prism;
use super::{GaussState, InternalVar, Material, MaterialError, MaterialResponse};

/// The internal variables: the accumulated plastic strain (engineering shear) and its
/// equivalent `eps_q` (see the module docs).
pub static VARIABLES: [InternalVar; 2] = [
    InternalVar::strain("plastic_strain"),
    InternalVar::scalar("eps_q"),
];
/// Offset of the plastic strain in [`GaussState::internal`].
pub const PLASTIC_STRAIN: usize = 0;
/// Offset of `eps_q` in [`GaussState::internal`].
pub const EPS_Q: usize = 4;
/// With a strength profile, the point's own cu follows: fixed where its particle started, it
/// travels with the state like any internal variable.
pub static VARIABLES_WITH_CU: [InternalVar; 3] = [
    InternalVar::strain("plastic_strain"),
    InternalVar::scalar("eps_q"),
    InternalVar::scalar("cu"),
];
/// Offset of the point's `cu` in [`GaussState::internal`] (with a profile).
pub const CU: usize = 5;

/// Strength growing linearly with depth below a level: cu(y) = cu + gradient (level - y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CuProfile {
    /// Pa/m.
    pub gradient: f64,
    /// m.
    pub level: f64,
}

/// Elastic–perfectly plastic undrained clay (plane-strain Tresca); see the module docs.
///
/// Construct with [`Tresca::new`], which validates the parameters; the fields are public for
/// reading, and a value built by hand bypasses that validation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tresca {
    /// Young's modulus E (Pa), > 0 (undrained, i.e. total-stress, modulus).
    pub young: f64,
    /// Poisson's ratio ν, in (-1, 0.5); undrained clay uses 0.49–0.495.
    pub poisson: f64,
    /// Undrained shear strength cu (Pa), > 0: everywhere, or at and above the profile's level.
    pub cu: f64,
    /// Strength that varies with the initial depth of a point; None: uniform `cu`.
    pub profile: Option<CuProfile>,
    /// E / cu at every point (offshore practice: stiffness grows with strength), instead of one
    /// `young`; None: E = `young` everywhere.
    pub young_over_cu: Option<f64>,
    /// Judged in full principal stresses, σzz among them ([`Tresca::in_principal_stresses`]);
    /// false: the in-plane criterion of the module docs.
    pub principal: bool,
    /// In full principal stresses: the prism's edges rounded by this fraction of cu
    /// ([`super::rounded_prism`]; [`rounded_prism::DEFAULT_ROUNDING`] unless set).
    pub edge_rounding: f64,
}

/// Deviatoric projector on Voigt vectors, engineering shear on the strain side (tensor shear
/// 2G·γ/2 = G·γ, hence ½ in the shear slot).
pub(super) const P_DEV: [[f64; 4]; 4] = [
    [2.0 / 3.0, -1.0 / 3.0, -1.0 / 3.0, 0.0],
    [-1.0 / 3.0, 2.0 / 3.0, -1.0 / 3.0, 0.0],
    [-1.0 / 3.0, -1.0 / 3.0, 2.0 / 3.0, 0.0],
    [0.0, 0.0, 0.0, 0.5],
];

/// Projector onto the in-plane deviators spanned by (1, −1, 0, 0)/√2 and pure in-plane shear,
/// same Voigt conventions as [`P_DEV`].
pub(super) const P_IN: [[f64; 4]; 4] = [
    [0.5, -0.5, 0.0, 0.0],
    [-0.5, 0.5, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.5],
];

impl Tresca {
    /// Validates `young > 0`, `-1 < poisson < 0.5` and `cu > 0` (all finite).
    pub fn new(young: f64, poisson: f64, cu: f64) -> Result<Self, MaterialError> {
        // The elastic part has the linear-elastic bounds; K is infinite at ν = 0.5, and exact
        // incompressibility is the mixed element's job (its `bulk` may be infinite).
        LinearElastic::new(young, poisson)?;
        if !(cu.is_finite() && cu > 0.0) {
            return Err(MaterialError::InvalidParameter {
                name: "cu",
                value: cu,
                requirement: "0 < cu < inf",
            });
        }
        Ok(Self {
            young,
            poisson,
            cu,
            profile: None,
            young_over_cu: None,
            principal: false,
            edge_rounding: rounded_prism::DEFAULT_ROUNDING,
        })
    }

    /// The same material judged in full principal stresses: (σ1 − σ3)/2 = cu with σzz among
    /// them, the prism's edges rounded by `edge_rounding` · cu ([`super::rounded_prism`]: at
    /// the default 1 %, 0.25 % weaker on an edge, Tresca's to 2.5e-5 cu on a face away from
    /// them). Axisymmetry needs it: there σzz is the hoop stress, which can be the largest or
    /// the smallest, and plastic flow strains the hoop. In plane strain the in-plane criterion stays the default, since
    /// it holds the textbook collapse loads exactly from the first plastic step.
    pub fn in_principal_stresses(self) -> Self {
        Self {
            principal: true,
            ..self
        }
    }

    /// The same material with the prism's edges rounded by `rounding` · cu in full principal
    /// stresses, 0 < rounding ≤ [`rounded_prism::MAX_ROUNDING`].
    pub fn with_edge_rounding(self, rounding: f64) -> Result<Self, MaterialError> {
        if !(rounding > 0.0 && rounding <= rounded_prism::MAX_ROUNDING) {
            return Err(MaterialError::InvalidParameter {
                name: "edge_rounding",
                value: rounding,
                // MAX_ROUNDING, spelled out: the requirement is a static string.
                requirement: "0 < edge_rounding <= 0.1",
            });
        }
        Ok(Self {
            edge_rounding: rounding,
            ..self
        })
    }

    /// The same material with a strength profile: each point's cu is set from the height `y` it
    /// starts at ([`Material::initial_internal`]) and kept in its state.
    pub fn with_profile(self, profile: CuProfile) -> Self {
        Self {
            profile: Some(profile),
            ..self
        }
    }

    /// The same material with E = `ratio` · cu at every point (`young` then stands for the
    /// stiffness at the strength `cu`).
    pub fn with_young_over_cu(self, ratio: f64) -> Self {
        Self {
            young_over_cu: Some(ratio),
            ..self
        }
    }

    /// The elastic constants at a point of strength `cu`: this material, or with E = ratio · cu.
    pub(super) fn at_strength(&self, cu: f64) -> Tresca {
        match self.young_over_cu {
            Some(ratio) => Tresca {
                young: ratio * cu,
                ..*self
            },
            None => *self,
        }
    }

    /// The strength of a point in state `state` (laid out as this model's variables).
    fn strength_of(&self, state: &GaussState) -> f64 {
        match self.profile {
            Some(_) => state.internal.get(CU).copied().unwrap_or(self.cu),
            None => self.cu,
        }
    }

    /// cu at initial height `y`.
    pub fn cu_at(&self, y: f64) -> f64 {
        match self.profile {
            Some(p) => self.cu + p.gradient * (p.level - y).max(0.0),
            None => self.cu,
        }
    }

    /// Shear modulus G = E / (2(1 + ν)).
    pub fn shear_modulus(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }

    /// Bulk modulus K = E / (3(1 − 2ν)): the `bulk` to hand to the mixed element for the
    /// compressible response of this material.
    pub fn bulk_modulus(&self) -> f64 {
        self.young / (3.0 * (1.0 - 2.0 * self.poisson))
    }

    /// K m⊗m + 2G (P_dev − P_in) + 2Gβ (P_in − N⊗N), N⊗N omitted when `n` is `None`.
    pub(super) fn tangent(&self, beta: f64, n: Option<&[f64; 4]>) -> [[f64; 4]; 4] {
        let k = self.bulk_modulus();
        let g2 = 2.0 * self.shear_modulus();
        let mut d = [[0.0; 4]; 4];
        for (i, row) in d.iter_mut().enumerate() {
            for (j, dij) in row.iter_mut().enumerate() {
                let vol = if i < 3 && j < 3 { k } else { 0.0 };
                let nn = n.map_or(0.0, |n| n[i] * n[j]);
                *dij = vol + g2 * (P_DEV[i][j] - P_IN[i][j]) + g2 * beta * (P_IN[i][j] - nn);
            }
        }
        d
    }
}

/// Largest in-plane shear stress √(((σxx − σyy)/2)² + σxy²) of a Voigt stress: the quantity the
/// yield condition bounds by `cu`.
pub fn max_in_plane_shear(s: &[f64; 4]) -> f64 {
    (0.5 * (s[0] - s[1])).hypot(s[3])
}

/// Largest 3-D shear stress (σ_max − σ_min)/2 over the principal stresses, σzz included. Equal
/// to [`max_in_plane_shear`] exactly when σzz is the intermediate principal stress; a larger
/// value flags a state where the plane-strain Tresca assumption does not hold.
pub fn max_shear_3d(s: &[f64; 4]) -> f64 {
    let c = 0.5 * (s[0] + s[1]);
    let r = max_in_plane_shear(s);
    let hi = (c + r).max(s[2]);
    let lo = (c - r).min(s[2]);
    0.5 * (hi - lo)
}

impl Material for Tresca {
    fn update(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        let here = self.at_strength(self.strength_of(state_n));
        here.update_at_strength(state_n, e)
    }

    fn bulk_at(&self, state: &GaussState) -> Option<f64> {
        self.young_over_cu
            .map(|_| self.at_strength(self.strength_of(state)).bulk_modulus())
    }

    fn name(&self) -> &'static str {
        "tresca"
    }

    fn internal_variables(&self) -> &[InternalVar] {
        match self.profile {
            Some(_) => &VARIABLES_WITH_CU,
            None => &VARIABLES,
        }
    }

    fn initial_internal(&self, x0: [f64; 2], internal: &mut [f64]) {
        if self.profile.is_some() {
            internal[CU] = self.cu_at(x0[1]);
        }
    }

    fn yields(&self) -> bool {
        true
    }

    fn isochoric(&self) -> bool {
        true
    }

    fn yielded(&self, before: &GaussState, after: &GaussState) -> bool {
        grew(before, after, EPS_Q)
    }
}

impl Tresca {
    /// The return mapping with this value's elastic constants (those of the point's strength).
    fn update_at_strength(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        if self.principal {
            return self.principal_return(state_n, e);
        }
        // The elastic trial state is the linear-elastic update (which also rejects bad strains).
        let trial = LinearElastic {
            young: self.young,
            poisson: self.poisson,
        }
        .update(state_n, e)?;
        let (mut s, d_el) = (trial.s, trial.d);
        let a = 0.5 * (s[0] - s[1]);
        let tau = s[3];
        let r = a.hypot(tau);
        let mut state = state_n.clone();
        let len = internal_len(self.internal_variables());
        if state.internal.len() != len {
            // A fresh point (no internal variables yet) starts them at zero.
            state.internal.resize(len, 0.0);
        }
        let cu = self.strength_of(&state);

        // Strict comparison: a returned state has r = cu to round-off, so a tolerance would only
        // let round-off excursions above cu survive.
        if r <= cu {
            return Ok(MaterialResponse { s, d: d_el, state });
        }

        let beta = cu / r;
        let dlambda = (r - cu) / self.shear_modulus();
        let shrink = 1.0 - beta;
        s[0] -= shrink * a;
        s[1] += shrink * a;
        s[3] -= shrink * tau;

        // Δε^p = Δλ ∂f/∂σ = Δλ/(2r) (a, −a, 0, τ) as a tensor; engineering shear doubles τ.
        let c = dlambda / (2.0 * r);
        let ep = &mut state.internal[PLASTIC_STRAIN..PLASTIC_STRAIN + 4];
        ep[0] += c * a;
        ep[1] -= c * a;
        ep[3] += 2.0 * c * tau;
        state.internal[EPS_Q] += dlambda / 3.0_f64.sqrt();

        // Unit in-plane deviator (Frobenius norm √(2a² + 2τ²) = √2 r).
        let nrm = std::f64::consts::SQRT_2 * r;
        let n = [a / nrm, -a / nrm, 0.0, tau / nrm];
        Ok(MaterialResponse {
            s,
            d: self.tangent(beta, Some(&n)),
            state,
        })
    }
}

impl Tresca {
    /// The return in full principal stresses onto the prism with rounded edges
    /// ([`super::rounded_prism`]: on an edge, σr = σθ on the axis of a body of revolution, the
    /// exact prism's tangent has no deviatoric stiffness and Newton stalls). Internal variables
    /// as the in-plane return's; a strength profile's `cu` after them is kept.
    fn principal_return(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        let elastic = LinearElastic {
            young: self.young,
            poisson: self.poisson,
        };
        let trial = elastic.update(state_n, e)?;
        let cu = self.strength_of(state_n);
        let mut state = state_n.clone();
        let len = internal_len(self.internal_variables());
        if state.internal.len() != len {
            state.internal.resize(len, 0.0);
        }
        let frame = Spectral::of(&trial.s);
        let Some((values, dv)) = rounded_prism::principal_return(
            &frame.values,
            self.shear_modulus(),
            cu,
            self.edge_rounding,
        )?
        else {
            return Ok(MaterialResponse {
                s: trial.s,
                d: trial.d,
                state,
            });
        };
        // The relief is deviatoric (the flow is), so the plastic strain is it over 2G.
        let relief: [f64; 3] =
            std::array::from_fn(|i| (frame.values[i] - values[i]) / (2.0 * self.shear_modulus()));
        Ok(frame.returned(&values, &dv, &relief, &trial.d, state))
    }
}

#[cfg(test)]
// Index loops mirror the component notation of the formulas being checked.
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::material::elastic::LinearElastic;

    const CU: f64 = 2.0e4;

    fn clay() -> Tresca {
        // E/cu = 250, ν = 0.49: a typical soft clay.
        Tresca::new(5.0e6, 0.49, CU).expect("valid parameters")
    }

    fn stressed(s: [f64; 4]) -> GaussState {
        GaussState {
            stress: s,
            ..GaussState::default()
        }
    }

    /// Drives the model along a path of strain increments from `st`, returning all states.
    fn drive(m: &Tresca, st: GaussState, incs: &[[f64; 4]]) -> Vec<GaussState> {
        let mut out = Vec::new();
        let mut cur = st;
        for de in incs {
            let r = m.update(&cur, de).expect("finite strain");
            cur = r.state;
            cur.stress = r.s;
            out.push(cur.clone());
        }
        out
    }

    #[test]
    fn rejects_bad_parameters_naming_the_field() {
        for (e, nu, cu, field) in [
            (0.0, 0.49, 1e4, "young"),
            (f64::INFINITY, 0.49, 1e4, "young"),
            (f64::NAN, 0.49, 1e4, "young"),
            (1e6, 0.5, 1e4, "poisson"),
            (1e6, -1.0, 1e4, "poisson"),
            (1e6, f64::NAN, 1e4, "poisson"),
            (1e6, 0.49, 0.0, "cu"),
            (1e6, 0.49, -5.0, "cu"),
            (1e6, 0.49, f64::NAN, "cu"),
            (1e6, 0.49, f64::INFINITY, "cu"),
        ] {
            match Tresca::new(e, nu, cu) {
                Err(err @ MaterialError::InvalidParameter { name, .. }) => {
                    assert_eq!(name, field);
                    assert!(err.to_string().contains(field), "{err}");
                }
                other => panic!("expected rejection of ({e}, {nu}, {cu}), got {other:?}"),
            }
        }
        let m = Tresca::new(1e6, 0.495, 1e4).expect("valid");
        assert_eq!(m.name(), "tresca");
        assert!((m.shear_modulus() - 1e6 / 2.99).abs() < 1e-6);
        assert!((m.bulk_modulus() - 1e6 / 0.03).abs() < 1e-3);
    }

    #[test]
    fn rejects_non_finite_strain() {
        let r = clay().update(&GaussState::default(), &[0.0, f64::INFINITY, 0.0, 0.0]);
        assert!(matches!(r, Err(MaterialError::NonFiniteStrain { .. })));
    }

    #[test]
    fn below_yield_it_is_linear_elastic() {
        let m = clay();
        let lin = LinearElastic::new(m.young, m.poisson).expect("valid");
        let st = stressed([-1.0e5, -1.2e5, -1.1e5, 3.0e3]);
        let e = [2e-4, -1e-4, 0.0, 1e-4];
        let a = m.update(&st, &e).expect("ok");
        let b = lin.update(&st, &e).expect("ok");
        assert!(max_in_plane_shear(&a.s) < CU, "test must stay elastic");
        for i in 0..4 {
            assert!((a.s[i] - b.s[i]).abs() < 1e-9 * 1e5, "S[{i}]");
            for j in 0..4 {
                assert!(
                    (a.d[i][j] - b.d[i][j]).abs() < 1e-12 * b.d[0][0],
                    "D[{i}][{j}]"
                );
            }
        }
        assert_eq!(a.state.internal[..4], [0.0; 4]);
        assert_eq!(a.state.internal[EPS_Q], 0.0);
    }

    #[test]
    fn pure_shear_saturates_at_cu_exactly() {
        let m = clay();
        let g = m.shear_modulus();
        let dg = 0.25 * CU / g; // yield after four increments
        let states = drive(&m, GaussState::default(), &[[0.0, 0.0, 0.0, dg]; 40]);
        for (k, st) in states.iter().enumerate() {
            let gamma = dg * (k + 1) as f64;
            let want = (g * gamma).min(CU);
            assert!(
                (st.stress[3] - want).abs() <= 4.0 * f64::EPSILON * CU,
                "inc {k}"
            );
            assert_eq!(st.stress[..3], [0.0; 3], "inc {k}");
            let gp = (gamma - CU / g).max(0.0);
            assert!((st.internal[3] - gp).abs() < 1e-12 * gamma, "inc {k}");
            assert!(
                (st.internal[EPS_Q] - gp / 3.0_f64.sqrt()).abs() < 1e-12 * gamma,
                "inc {k}"
            );
            assert_eq!(st.internal[..3], [0.0; 3]);
        }
        assert!((states[39].stress[3] - CU).abs() <= 2.0 * f64::EPSILON * CU);
    }

    #[test]
    fn isochoric_plane_strain_compression_reaches_two_cu() {
        // ε = diag(δ, −δ, 0) from an isotropic state: σxx − σyy = 4Gδ until it saturates at 2cu;
        // the mean stress and σzz never change.
        let m = clay();
        let g = m.shear_modulus();
        let p0 = 3.0e5;
        let d = 0.1 * CU / g;
        let states = drive(&m, stressed([-p0, -p0, -p0, 0.0]), &[[d, -d, 0.0, 0.0]; 30]);
        for (k, st) in states.iter().enumerate() {
            let delta = d * (k + 1) as f64;
            let want = (4.0 * g * delta).min(2.0 * CU);
            let got = st.stress[0] - st.stress[1];
            assert!(
                (got - want).abs() <= 1e-12 * 2.0 * CU,
                "inc {k}: {got} vs {want}"
            );
            assert!((st.stress[0] + st.stress[1] + 2.0 * p0).abs() < 1e-9 * p0);
            assert!(
                (st.stress[2] + p0).abs() < 1e-9 * p0,
                "σzz stays the mean stress"
            );
        }
        assert!(states.iter().filter(|s| s.internal[EPS_Q] > 0.0).count() > 20);
    }

    #[test]
    fn unconfined_plane_strain_compression_gives_two_cu_exactly() {
        // σxx = 0 enforced by solving for ε_xx in each increment (1-D Newton with the model's own
        // tangent, which also exercises it). Unlike the von Mises cylinder, the strength is 2cu
        // from the first plastic increment on, although σzz ≠ (σxx + σyy)/2 there.
        let m = clay();
        let dyy = -5.0e-4;
        let mut st = GaussState::default();
        let mut plastic_incs = 0;
        for inc in 0..40 {
            let mut exx = -0.5 * dyy;
            let mut r = m.update(&st, &[exx, dyy, 0.0, 0.0]).expect("ok");
            let mut iters = 0;
            while r.s[0].abs() > 1e-12 * CU && iters < 20 {
                exx -= r.s[0] / r.d[0][0];
                r = m.update(&st, &[exx, dyy, 0.0, 0.0]).expect("ok");
                iters += 1;
            }
            assert!(r.s[0].abs() <= 1e-12 * CU, "inc {inc}: σxx = {}", r.s[0]);
            let diff = r.s[0] - r.s[1];
            if m.yielded(&st, &r.state) {
                plastic_incs += 1;
                assert!((diff - 2.0 * CU).abs() <= 1e-12 * CU, "inc {inc}: {diff}");
                assert!(
                    iters <= 3,
                    "consistent tangent: Newton in {iters} iterations"
                );
                // σzz stays between σyy and σxx: the 3-D Tresca criterion is met as well.
                assert!((max_shear_3d(&r.s) - CU).abs() <= 1e-12 * CU);
            } else {
                assert!(diff < 2.0 * CU);
            }
            st = r.state;
            st.stress = r.s;
        }
        assert!(plastic_incs > 25, "{plastic_incs}");
        let p = &st.internal[..4];
        assert!(
            (p[0] + p[1] + p[2]).abs() < 1e-15,
            "plastic flow is isochoric"
        );
        assert_eq!(p[2], 0.0, "and keeps ε^p_zz = 0");
    }

    #[test]
    fn loading_unloading_and_reverse_yield() {
        let m = clay();
        let g = m.shear_modulus();
        let dg = 0.3 * CU / g;
        let mut incs = vec![[0.0, 0.0, 0.0, dg]; 6]; // to γ = 1.8 cu/G: plastic from inc 3
        incs.extend(vec![[0.0, 0.0, 0.0, -dg]; 10]); // unload elastically, then reverse yield
        let states = drive(&m, GaussState::default(), &incs);
        let gp_fwd = 6.0 * dg - CU / g;
        assert!((states[5].internal[3] - gp_fwd).abs() < 1e-12);
        for k in 6..12 {
            let want = CU - g * dg * (k - 5) as f64;
            assert!((states[k].stress[3] - want).abs() < 1e-9 * CU, "inc {k}");
            assert_eq!(states[k].internal[..4], states[5].internal[..4]);
            assert_eq!(states[k].internal[EPS_Q], states[5].internal[EPS_Q]);
        }
        for k in 12..16 {
            assert!(
                (states[k].stress[3] + CU).abs() <= 4.0 * f64::EPSILON * CU,
                "inc {k}"
            );
        }
        let gp_rev = 10.0 * dg - 2.0 * CU / g;
        assert!((states[15].internal[3] - (gp_fwd - gp_rev)).abs() < 1e-12);
        // Accumulated equivalent strain counts both branches.
        let want_q = (gp_fwd + gp_rev) / 3.0_f64.sqrt();
        assert!((states[15].internal[EPS_Q] - want_q).abs() < 1e-12);
    }

    #[test]
    fn eps_q_is_the_equivalent_of_total_plastic_strain_under_proportional_loading() {
        let m = clay();
        let de = [4e-4, -3e-4, 0.0, 5e-4];
        let states = drive(&m, GaussState::default(), &[de; 30]);
        let st = &states[29];
        assert!(st.internal[EPS_Q] > 1e-3, "must be well into plastic flow");
        let p = &st.internal[..4];
        let tensor_sq = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + 0.5 * p[3] * p[3];
        let eq = (2.0 / 3.0 * tensor_sq).sqrt();
        assert!(
            (eq - st.internal[EPS_Q]).abs() < 1e-10 * st.internal[EPS_Q],
            "{eq} vs {}",
            st.internal[EPS_Q]
        );
    }

    fn fd_check(m: &Tresca, st: &GaussState, e: &[f64; 4]) -> f64 {
        crate::material::tangent_fd_error(m, st, e, 1e-8, 0.0)
    }

    #[test]
    fn consistent_tangent_matches_finite_differences() {
        let m = clay();
        let g = m.shear_modulus();
        let pre = stressed([-1.5e5, -1.7e5, -1.3e5, 1.2e4]);
        assert!(max_in_plane_shear(&pre.stress) < CU);
        let elastic_e = [1e-4, -5e-5, 0.0, 2e-5];
        assert!(max_in_plane_shear(&m.update(&pre, &elastic_e).expect("ok").s) < CU);
        let rel = fd_check(&m, &pre, &elastic_e);
        assert!(rel < 1e-7, "elastic: {rel:e}");
        for e in [
            [3e-2, -1e-2, 0.0, 4e-2],
            [-5.0 * CU / g, 4.0 * CU / g, 0.0, -CU / g],
            [1e-3, 1e-3, 0.0, 6.0 * CU / g], // with a volumetric part
        ] {
            let r = m.update(&pre, &e).expect("ok");
            assert!(r.state.internal[EPS_Q] > 0.0, "must be plastic: {e:?}");
            let rel = fd_check(&m, &pre, &e);
            assert!(rel < 1e-6, "plastic {e:?}: {rel:e}");
            for i in 0..4 {
                for j in 0..4 {
                    assert!((r.d[i][j] - r.d[j][i]).abs() <= 1e-12 * r.d[0][0]);
                }
            }
        }
        // The plastic tangent differs visibly from the elastic one, so the check bites.
        let r = m.update(&pre, &[3e-2, -1e-2, 0.0, 4e-2]).expect("ok");
        assert!((r.d[3][3] - g).abs() > 0.5 * g);
    }

    #[test]
    fn returned_stress_is_on_the_yield_surface() {
        let m = clay();
        let pre = stressed([-2.0e5, -1.0e5, -1.6e5, 1.0e4]); // τ_max > cu: inadmissible start
        assert!(max_in_plane_shear(&pre.stress) > CU);
        for e in [[0.0; 4], [1e-3, -2e-3, 0.0, 5e-4], [0.1, 0.2, 0.0, -0.3]] {
            let r = m.update(&pre, &e).expect("ok");
            // Round-off of σxx − σyy is relative to |σ|, which the mean stress can dominate.
            let scale = r.s.iter().fold(CU, |m, v| m.max(v.abs()));
            let t = max_in_plane_shear(&r.s);
            assert!((t - CU).abs() <= 4.0 * f64::EPSILON * scale, "{e:?}: {t}");
            // Flow is isochoric: the mean stress is the elastic trial's.
            let trial = LinearElastic::new(m.young, m.poisson)
                .expect("valid")
                .update(&pre, &e)
                .expect("ok")
                .s;
            let mean = |s: &[f64; 4]| s[0] + s[1] + s[2];
            assert!((mean(&r.s) - mean(&trial)).abs() <= 1e-9 * mean(&trial).abs());
            assert!((r.s[2] - trial[2]).abs() <= 1e-9 * trial[2].abs());
        }
    }

    #[test]
    fn max_shear_3d_flags_a_non_intermediate_out_of_plane_stress() {
        let s = [-1.0e5, -1.4e5, -1.2e5, 0.0];
        assert_eq!(max_shear_3d(&s), max_in_plane_shear(&s));
        let s = [-1.0e5, -1.4e5, -2.0e5, 0.0];
        assert!((max_shear_3d(&s) - 0.5e5).abs() < 1e-9);
        assert!((max_in_plane_shear(&s) - 0.2e5).abs() < 1e-9);
    }
}
