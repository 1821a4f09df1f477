//! Drained soil, smooth: Drucker–Prager matched to Mohr–Coulomb, elastic–perfectly plastic with
//! non-associated flow.
//!
//! # Criterion and flow (de Souza Neto, Perić & Owen 2008, §8.3)
//! f = √J2 + η p − ξ c ≤ 0 with p = tr σ / 3 (tension positive), potential g = √J2 + η̄ p.
//! The cone is fitted to Mohr–Coulomb's (c, φ, ψ) by a named `match`:
//! - `plane-strain` (default): the cone whose plane-strain limit state is Mohr–Coulomb's exactly.
//!   At a plane-strain limit the plastic strain rate has no zz part, which fixes
//!   s_zz = −(2/3) η̄ √J2 and √J2 = r/u, u = √(1 − η̄²/3), r the in-plane radius; the criterion
//!   then reads r + (σxx + σyy)/2 · sin φ = c cos φ, Mohr–Coulomb's, when
//!   η = sin φ / (u + η̄ sin φ / 3), ξ = cos φ / (u + η̄ sin φ / 3), and its dilation rate is
//!   Mohr–Coulomb's sin ψ when η̄ = 3 sin ψ / √(9 + 3 sin² ψ). For ψ = φ these are the
//!   textbook η = 3 tan φ / √(9 + 12 tan² φ), ξ = 3 / √(9 + 12 tan² φ); for ψ < φ they keep the
//!   limit exact, which the textbook's pair (with ψ in η̄ only) does not;
//! - `outer`: through Mohr–Coulomb's compression corners, η = 6 sin φ / (√3 (3 − sin φ)),
//!   ξ = 6 cos φ / (√3 (3 − sin φ)), η̄ likewise with ψ;
//! - `inner`: through its extension corners, 3 + sin φ in the denominators.
//!
//! The limit state is reached as the out-of-plane stress settles (the plastic zz strain rate
//! decays with the plastic strain), not at first yield: this is the cone's price for its
//! smoothness, measured in the tests.
//!
//! # Return mapping
//! Closed form for perfect plasticity. Cone: Δγ = f_tr / (G + K η η̄),
//! s = (1 − G Δγ / √J2_tr) s_tr, p = p_tr − K η̄ Δγ, valid while √J2_tr ≥ G Δγ; otherwise the
//! apex σ = (ξ c / η) I with a zero tangent. The consistent tangent is symmetric when η̄ = η.

use super::elastic::LinearElastic;
use super::layout::{equivalent_plastic_strain, grew, internal_len};
use super::mohr_coulomb::{check_strength, EPS_Q, PLASTIC_STRAIN, VARIABLES};
use super::principal::product;
use super::{GaussState, InternalVar, Material, MaterialError, MaterialResponse};

/// Which Mohr–Coulomb section the cone goes through; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Match {
    PlaneStrain,
    Outer,
    Inner,
}

/// Elastic–perfectly plastic Drucker–Prager soil; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DruckerPrager {
    pub young: f64,
    pub poisson: f64,
    pub cohesion: f64,
    /// φ and ψ in degrees, as for [`super::mohr_coulomb::MohrCoulomb`].
    pub friction_angle: f64,
    pub dilation_angle: f64,
    pub matched: Match,
    /// η, ξ and η̄ of the module docs.
    pub eta: f64,
    pub xi: f64,
    pub eta_bar: f64,
}

/// (η, ξ) of the cone through `fit` for friction angle `phi` and dilation angle `psi`
/// (radians), and η̄.
pub fn cone(fit: Match, phi: f64, psi: f64) -> (f64, f64, f64) {
    let (sf, cf) = phi.sin_cos();
    let sg = psi.sin();
    let corner = |s: f64, sign: f64| 6.0 / (3.0f64.sqrt() * (3.0 + sign * s));
    match fit {
        Match::PlaneStrain => {
            let eta_bar = 3.0 * sg / (9.0 + 3.0 * sg * sg).sqrt();
            let den = (1.0 - eta_bar * eta_bar / 3.0).sqrt() + eta_bar * sf / 3.0;
            (sf / den, cf / den, eta_bar)
        }
        Match::Outer => (
            sf * corner(sf, -1.0),
            cf * corner(sf, -1.0),
            sg * corner(sg, -1.0),
        ),
        Match::Inner => (
            sf * corner(sf, 1.0),
            cf * corner(sf, 1.0),
            sg * corner(sg, 1.0),
        ),
    }
}

/// Deviator and √J2 of a tensor-shear Voigt stress.
fn deviator(s: &[f64; 4]) -> ([f64; 4], f64) {
    let p = (s[0] + s[1] + s[2]) / 3.0;
    let d = [s[0] - p, s[1] - p, s[2] - p, s[3]];
    let j2 = 0.5 * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + d[3] * d[3];
    (d, j2.sqrt())
}

impl DruckerPrager {
    /// Validates the parameters (as Mohr–Coulomb's), naming the offending one.
    pub fn new(
        young: f64,
        poisson: f64,
        cohesion: f64,
        friction_angle: f64,
        dilation_angle: f64,
        matched: Match,
    ) -> Result<Self, MaterialError> {
        LinearElastic::new(young, poisson)?;
        check_strength(cohesion, friction_angle, dilation_angle)?;
        let (eta, xi, mut eta_bar) = cone(
            matched,
            friction_angle.to_radians(),
            dilation_angle.to_radians(),
        );
        if dilation_angle == friction_angle {
            // Associated: the same cone to the last bit, so that the tangent is symmetric.
            eta_bar = eta;
        }
        Ok(Self {
            young,
            poisson,
            cohesion,
            friction_angle,
            dilation_angle,
            matched,
            eta,
            xi,
            eta_bar,
        })
    }

    fn elastic(&self) -> LinearElastic {
        LinearElastic {
            young: self.young,
            poisson: self.poisson,
        }
    }

    /// f at stress `s`.
    pub fn yield_function(&self, s: &[f64; 4]) -> f64 {
        let (_, q) = deviator(s);
        q + self.eta * (s[0] + s[1] + s[2]) / 3.0 - self.xi * self.cohesion
    }

    /// The returned stress and dσ/dσ_tr (tensor shear) of a trial outside the cone.
    fn plastic_return(&self, tr: &[f64; 4]) -> ([f64; 4], [[f64; 4]; 4]) {
        let (l, g) = self.elastic().lame();
        let k = l + 2.0 * g / 3.0;
        let (s_tr, q) = deviator(tr);
        let p_tr = (tr[0] + tr[1] + tr[2]) / 3.0;
        let f = q + self.eta * p_tr - self.xi * self.cohesion;
        let a = 1.0 / (g + k * self.eta * self.eta_bar);
        let dgamma = f * a;
        if q - g * dgamma < 0.0 && self.eta > 0.0 {
            let p = self.xi * self.cohesion / self.eta;
            return ([p, p, p, 0.0], [[0.0; 4]; 4]);
        }
        let beta = 1.0 - g * dgamma / q;
        let p = p_tr - k * self.eta_bar * dgamma;
        let mut s = [0.0; 4];
        for i in 0..4 {
            s[i] = beta * s_tr[i] + if i < 3 { p } else { 0.0 };
        }
        // ∂√J2/∂σ_tr (the shear counted twice) and ∂p/∂σ_tr.
        let dq = [s_tr[0], s_tr[1], s_tr[2], 2.0 * s_tr[3]].map(|v| v / (2.0 * q));
        let dp = [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0, 0.0];
        let ddg: [f64; 4] = std::array::from_fn(|j| a * (dq[j] + self.eta * dp[j]));
        let dbeta: [f64; 4] =
            std::array::from_fn(|j| -g * ddg[j] / q + g * dgamma / (q * q) * dq[j]);
        let mut m = [[0.0; 4]; 4];
        for i in 0..4 {
            let mi = if i < 3 { 1.0 } else { 0.0 };
            for j in 0..4 {
                let dev =
                    if i == j { 1.0 } else { 0.0 } - if i < 3 && j < 3 { 1.0 / 3.0 } else { 0.0 };
                m[i][j] =
                    s_tr[i] * dbeta[j] + beta * dev + mi * (dp[j] - k * self.eta_bar * ddg[j]);
            }
        }
        (s, m)
    }
}

impl Material for DruckerPrager {
    fn update(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        let trial = self.elastic().update(state_n, e)?;
        let mut state = state_n.clone();
        let len = internal_len(&VARIABLES);
        if state.internal.len() != len {
            state.internal.resize(len, 0.0);
        }
        if self.yield_function(&trial.s) <= 0.0 {
            return Ok(MaterialResponse {
                s: trial.s,
                d: trial.d,
                state,
            });
        }
        let (s, m) = self.plastic_return(&trial.s);
        // Δε^p = C (σ_tr − σ), engineering shear.
        let (l, g) = self.elastic().lame();
        let k = l + 2.0 * g / 3.0;
        let relief: [f64; 4] = std::array::from_fn(|i| trial.s[i] - s[i]);
        let (rd, _) = deviator(&relief);
        let rv = (relief[0] + relief[1] + relief[2]) / 3.0;
        let dep = [
            rd[0] / (2.0 * g) + rv / (3.0 * k),
            rd[1] / (2.0 * g) + rv / (3.0 * k),
            rd[2] / (2.0 * g) + rv / (3.0 * k),
            rd[3] / g,
        ];
        for (p, d) in state.internal[PLASTIC_STRAIN..PLASTIC_STRAIN + 4]
            .iter_mut()
            .zip(dep)
        {
            *p += d;
        }
        state.internal[EPS_Q] += equivalent_plastic_strain(&dep);
        Ok(MaterialResponse {
            s,
            d: product(&m, &trial.d),
            state,
        })
    }

    fn name(&self) -> &'static str {
        "drucker_prager"
    }

    fn internal_variables(&self) -> &[InternalVar] {
        &VARIABLES
    }

    fn yields(&self) -> bool {
        true
    }

    fn yielded(&self, before: &GaussState, after: &GaussState) -> bool {
        grew(before, after, EPS_Q)
    }

    fn symmetric_tangent(&self) -> bool {
        self.eta_bar == self.eta
    }

    fn isochoric(&self) -> bool {
        self.eta == 0.0 && self.eta_bar == 0.0
    }
}

#[cfg(test)]
mod tests;
