//! Sensitive clay: plane-strain Tresca whose strength softens with the accumulated plastic shear
//! strain and rises with the shear strain rate (Einav & Randolph 2005, the model behind the
//! interpretation of T-bar and ball penetrometer tests in soft clay).
//!
//! # Strength
//! su = su_ref · R(γ̇) · S(ξ) with
//! - S(ξ) = δ_rem + (1 − δ_rem) e^(−3ξ/ξ95): the intact strength at ξ = 0 falls towards the
//!   remoulded δ_rem · su_ref, 95 % of the way at ξ = ξ95;
//! - R(γ̇) = 1 + μ log10(max(γ̇, γ̇_ref)/γ̇_ref): μ per decade of shear strain rate above γ̇_ref,
//!   and never below 1.
//!
//! su_ref is `cu` (or its profile with depth, kept per point as Tresca keeps it). The yield
//! criterion and flow rule are [`super::tresca`]'s: f = τ_max − su, with τ_max the largest
//! in-plane shear stress, associated, isochoric flow.
//!
//! # ξ, eps_q and γ̇
//! ξ is the accumulated engineering plastic shear strain, ξ = Σ Δγ^p with Δγ^p = Δε^p_1 − Δε^p_3
//! the difference of the principal plastic strain increments (the largest engineering shear of
//! the increment), as Einav & Randolph accumulate it (ξ95 = 10 to 50 for marine clays, i.e.
//! 1000 % to 5000 % shear strain). For this flow rule Δγ^p is the plastic multiplier Δλ of the
//! return (the in-plane deviator's radius drops by G Δλ), and eps_q = Σ √(2/3 Δε^p:Δε^p)
//! = Σ Δλ/√3, so ξ = √3 eps_q exactly; both are kept, named, for output and checkpoints.
//!
//! γ̇ = Δγ/Δt is the operative shear strain rate of the step: Δγ = √((Δε_xx − Δε_yy)² + Δγ_xy²)
//! the largest engineering shear strain of the *total* strain increment of the step (the trial,
//! not the plastic part: a point deformed at a rate has that rate whether its increment is
//! elastic or plastic, and in steady flow the two agree), and Δt the step's duration
//! ([`super::umat::site::step_seconds`], from `steps.duration` or timed `[[rigid]]` stages).
//! A zero-length increment (the geostatic equilibration) has rate factor 1. With μ > 0 and no
//! duration the update is an error naming `rate_parameter`.
//!
//! # Return mapping and tangent
//! Backward Euler with the strength implicit in Δλ: with the trial radius r_tr of the in-plane
//! deviator, the consistency condition F(Δλ) = r_tr − G Δλ − su_ref R S(ξ_n + Δλ) = 0 is solved
//! by a scalar Newton iteration (F is concave and decreasing while G exceeds the softening
//! modulus H = −∂su/∂Δλ, so Newton from the perfectly plastic estimate converges, monotonically
//! after its first step). The deviator is then scaled onto su, as in [`super::tresca`].
//!
//! The consistent tangent is Tresca's with the radial stiffness of the softening, and the rate
//! factor's dependence on the strain:
//!
//! ```text
//! D = K m⊗m + 2G (P_dev − P_in) + 2Gβ (P_in − N⊗N) − 2G H/(G − H) N⊗N
//!     + G/(G − H) · √2 N ⊗ ∂su/∂ε,
//! ```
//!
//! β = su/r_tr, N the unit in-plane trial deviator, ∂su/∂ε = su_ref S μ/(ln 10 Δγ) ∂Δγ/∂ε above
//! γ̇_ref (0 below). Without the rate term (μ = 0, or γ̇ ≤ γ̇_ref) it is symmetric: the
//! strength is a scalar function of the multiplier and the flow associated. The rate term
//! couples the stress direction N to the strain-increment direction, which differ in general:
//! with μ > 0 the tangent is not symmetric ([`Material::symmetric_tangent`] says so).
//!
//! # Regularisation
//! Softening localises into bands one element wide, so the load–displacement curve after the
//! peak depends on the spacing. With `xi95_reference_spacing` = h_ref, a point in an element of
//! size h (CELENT, √(2 × area), [`super::umat::site::element_size`]) softens with
//! ξ95 · h_ref/h: the displacement across a band, ξ h, then softens the same at any spacing
//! (bench/VALIDATION.md has the measured effect).
//!
//! # Admissible states
//! The point keeps its strength at the end of its last step, `su` = su_ref R S(ξ) (with that
//! step's rate and element size), for output and as the bound of its stress. Bounds: eps_q ≥ 0,
//! ξ ≥ 0 (see [`super::layout::lower_bound`]), su ≥ δ_rem su_ref (the least strength the model
//! has), and τ_max ≤ su. The set {τ_max(σ) ≤ su} is a convex cone in (σ, su), so interpolating
//! admissible particle states at a new Gauss point stays admissible; the recovery's
//! extrapolation does not, and [`Material::admit`] returns a recovered or mapped state by
//! clamping the scalars and scaling the in-plane deviator onto su (mean stress and σzz kept).

use super::elastic::LinearElastic;
use super::layout::{clamp_to_bounds, grew, internal_len};
use super::tresca::{CuProfile, Tresca};
use super::umat::site;
use super::{GaussState, InternalVar, Material, MaterialError, MaterialResponse};

/// The variables without a strength profile: plastic strain, eps_q, ξ, and the point's
/// strength su at the end of its last step (output, and the bound of [`Material::admit`]).
static PLAIN: [InternalVar; 4] = [
    InternalVar::strain("plastic_strain"),
    InternalVar::scalar("eps_q"),
    InternalVar::scalar("xi"),
    InternalVar::scalar("su"),
];
/// With a strength profile, the point's su_ref follows (named `cu`, as Tresca's).
static WITH_CU: [InternalVar; 5] = [
    InternalVar::strain("plastic_strain"),
    InternalVar::scalar("eps_q"),
    InternalVar::scalar("xi"),
    InternalVar::scalar("su"),
    InternalVar::scalar("cu"),
];

/// Offset of the plastic strain in [`GaussState::internal`].
pub const PLASTIC_STRAIN: usize = 0;
/// Offset of `eps_q`.
pub const EPS_Q: usize = 4;
/// Offset of `xi`.
pub const XI: usize = 5;
/// Offset of `su`.
pub const SU: usize = 6;
/// Offset of the point's `cu` (su_ref) with a profile.
pub const CU: usize = 7;

/// The internal variables of the model, with a strength profile or without.
pub fn variables(profile: bool) -> &'static [InternalVar] {
    if profile {
        &WITH_CU
    } else {
        &PLAIN
    }
}

/// The rate dependence: μ per decade above γ̇_ref.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rate {
    /// μ, > 0.
    pub mu: f64,
    /// γ̇_ref (1/s), > 0.
    pub reference: f64,
}

/// Strain-softening, rate-dependent undrained clay; see the module docs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrescaSoftening {
    /// The intact clay at the reference rate: E (at the strength `cu` when `young_over_cu` is
    /// given; the stiffness does not soften), ν, su_ref as `cu` and its profile, with Tresca's
    /// own checks. Only its elastic constants and strength are read: the criterion is always
    /// the in-plane one.
    pub intact: Tresca,
    /// δ_rem in (0, 1].
    pub remoulded_ratio: f64,
    /// ξ95 > 0.
    pub xi95: f64,
    /// h_ref (m) at which `xi95` holds; None: no regularisation.
    pub xi95_reference_spacing: Option<f64>,
    /// None: rate-independent (μ = 0).
    pub rate: Option<Rate>,
}

fn invalid(name: &'static str, value: f64, requirement: &'static str) -> MaterialError {
    MaterialError::InvalidParameter {
        name,
        value,
        requirement,
    }
}

/// Iterations of the local Newton before the return is declared failed.
const MAX_ITERATIONS: usize = 60;

impl TrescaSoftening {
    /// Validates every parameter, naming the one at fault. `rate_parameter` μ = 0 is
    /// rate-independent (and then `reference_rate` is not read); μ > 0 needs `reference_rate`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        young: f64,
        poisson: f64,
        cu: f64,
        remoulded_ratio: f64,
        xi95: f64,
        rate_parameter: f64,
        reference_rate: Option<f64>,
    ) -> Result<Self, MaterialError> {
        let intact = Tresca::new(young, poisson, cu)?;
        if !(remoulded_ratio > 0.0 && remoulded_ratio <= 1.0) {
            return Err(invalid(
                "remoulded_ratio",
                remoulded_ratio,
                "0 < remoulded_ratio <= 1",
            ));
        }
        if !(xi95.is_finite() && xi95 > 0.0) {
            return Err(invalid("xi95", xi95, "0 < xi95 < inf"));
        }
        if !(rate_parameter.is_finite() && rate_parameter >= 0.0) {
            return Err(invalid(
                "rate_parameter",
                rate_parameter,
                "0 <= rate_parameter < inf",
            ));
        }
        let rate = if rate_parameter > 0.0 {
            let r = reference_rate.unwrap_or(f64::NAN);
            if !(r.is_finite() && r > 0.0) {
                return Err(invalid(
                    "reference_rate",
                    r,
                    "0 < reference_rate < inf (1/s; required when rate_parameter > 0)",
                ));
            }
            Some(Rate {
                mu: rate_parameter,
                reference: r,
            })
        } else {
            None
        };
        Ok(Self {
            intact,
            remoulded_ratio,
            xi95,
            xi95_reference_spacing: None,
            rate,
        })
    }

    /// With a strength profile (as [`super::tresca::Tresca::with_profile`]).
    pub fn with_profile(self, profile: CuProfile) -> Self {
        Self {
            intact: self.intact.with_profile(profile),
            ..self
        }
    }

    /// With E = ratio · su_ref at every point.
    pub fn with_young_over_cu(self, ratio: f64) -> Self {
        Self {
            intact: self.intact.with_young_over_cu(ratio),
            ..self
        }
    }

    /// With ξ95 holding at element size `h_ref` (m, > 0) and scaled by h_ref/h elsewhere.
    pub fn with_reference_spacing(self, h_ref: f64) -> Result<Self, MaterialError> {
        if !(h_ref.is_finite() && h_ref > 0.0) {
            return Err(invalid(
                "xi95_reference_spacing",
                h_ref,
                "0 < xi95_reference_spacing < inf",
            ));
        }
        Ok(Self {
            xi95_reference_spacing: Some(h_ref),
            ..self
        })
    }

    /// su_ref at initial height `y`.
    pub fn cu_at(&self, y: f64) -> f64 {
        self.intact.cu_at(y)
    }

    /// su_ref of a point: its own with a profile (at this model's offset [`CU`]).
    fn su_ref_of(&self, state: &GaussState) -> f64 {
        match self.intact.profile {
            Some(_) => state.internal.get(CU).copied().unwrap_or(self.intact.cu),
            None => self.intact.cu,
        }
    }

    /// The intact clay's elastic constants at a point of reference strength `su_ref`.
    fn elastic_at(&self, su_ref: f64) -> Tresca {
        self.intact.at_strength(su_ref)
    }

    /// ξ95 in the element being evaluated (regularised by its size when asked to).
    pub fn xi95_here(&self) -> f64 {
        match (self.xi95_reference_spacing, site::element_size()) {
            (Some(h_ref), Some(h)) if h > 0.0 => self.xi95 * h_ref / h,
            _ => self.xi95,
        }
    }

    /// S(ξ) and −dS/dξ.
    fn softening(&self, xi: f64, xi95: f64) -> (f64, f64) {
        let k = 3.0 / xi95;
        let e = (-k * xi).exp();
        let d = self.remoulded_ratio;
        (d + (1.0 - d) * e, (1.0 - d) * k * e)
    }

    /// The rate factor of a step with strain `e`, and its derivative by `e`.
    fn rate_factor(&self, e: &[f64; 4]) -> Result<(f64, [f64; 4]), MaterialError> {
        let Some(rate) = self.rate else {
            return Ok((1.0, [0.0; 4]));
        };
        let Some(dt) = site::step_seconds() else {
            return Err(invalid(
                "rate_parameter",
                rate.mu,
                "a step duration (steps.duration, or timed [[rigid]] stages) when > 0",
            ));
        };
        let d = e[0] - e[1];
        let dgamma = d.hypot(e[3]);
        if dt <= 0.0 || dgamma <= rate.reference * dt {
            return Ok((1.0, [0.0; 4]));
        }
        let gdot = dgamma / dt;
        let r = 1.0 + rate.mu * (gdot / rate.reference).log10();
        let c = rate.mu / (std::f64::consts::LN_10 * dgamma * dgamma);
        Ok((r, [c * d, -c * d, 0.0, c * e[3]]))
    }
}

impl Material for TrescaSoftening {
    fn update(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        let su_ref = self.su_ref_of(state_n);
        let clay = self.elastic_at(su_ref);
        let elastic = LinearElastic {
            young: clay.young,
            poisson: clay.poisson,
        };
        let trial = elastic.update(state_n, e)?;
        let (mut s, d_el) = (trial.s, trial.d);
        let mut state = state_n.clone();
        let len = internal_len(self.internal_variables());
        if state.internal.len() != len {
            state.internal.resize(len, 0.0);
        }
        let (rate, drate) = self.rate_factor(e)?;
        let a = 0.5 * (s[0] - s[1]);
        let tau = s[3];
        let r_tr = a.hypot(tau);
        let xi_n = state.internal[XI].max(0.0);
        let xi95 = self.xi95_here();
        let scale = su_ref * rate;
        let su_n = scale * self.softening(xi_n, xi95).0;
        state.internal[SU] = su_n;
        if r_tr <= su_n {
            return Ok(MaterialResponse { s, d: d_el, state });
        }

        // F(Δλ) = r_tr − G Δλ − scale S(ξ_n + Δλ), from the perfectly plastic estimate.
        let g = clay.shear_modulus();
        let mut dl = (r_tr - scale * self.softening(xi_n, xi95).0) / g;
        let tol = 1e-14 * r_tr;
        let mut it = 0;
        let (su, h) = loop {
            let (sv, ds) = self.softening(xi_n + dl, xi95);
            let (su, h) = (scale * sv, scale * ds);
            let f = r_tr - g * dl - su;
            let slope = h - g;
            if slope >= 0.0 {
                // Softening faster than the elastic unloading: no unique return (snap-back).
                return Err(MaterialError::ReturnMappingFailed {
                    iterations: it,
                    residual: f,
                });
            }
            if f.abs() <= tol {
                break (su, h);
            }
            it += 1;
            if it > MAX_ITERATIONS {
                return Err(MaterialError::ReturnMappingFailed {
                    iterations: it,
                    residual: f,
                });
            }
            dl -= f / slope;
        };

        let beta = su / r_tr;
        let shrink = 1.0 - beta;
        s[0] -= shrink * a;
        s[1] += shrink * a;
        s[3] -= shrink * tau;
        let c = dl / (2.0 * r_tr);
        let ep = &mut state.internal[PLASTIC_STRAIN..PLASTIC_STRAIN + 4];
        ep[0] += c * a;
        ep[1] -= c * a;
        ep[3] += 2.0 * c * tau;
        state.internal[EPS_Q] += dl / 3.0_f64.sqrt();
        state.internal[XI] = xi_n + dl;
        state.internal[SU] = su;

        let nrm = std::f64::consts::SQRT_2 * r_tr;
        let n = [a / nrm, -a / nrm, 0.0, tau / nrm];
        let g2 = 2.0 * g;
        let radial = -h / (g - h);
        // ∂su/∂ε = su_ref S(ξ_{n+1}) ∂R/∂ε = (su / R) ∂R/∂ε.
        let rate_col = g / (g - h) * std::f64::consts::SQRT_2 * su / rate;
        // Tresca's plastic tangent, then the softening's radial and the rate's terms.
        let mut d = clay.tangent(beta, Some(&n));
        for (i, row) in d.iter_mut().enumerate() {
            for (j, dij) in row.iter_mut().enumerate() {
                let nn = n[i] * n[j];
                *dij += g2 * radial * nn;
                *dij += rate_col * n[i] * drate[j];
            }
        }
        Ok(MaterialResponse { s, d, state })
    }

    fn name(&self) -> &'static str {
        "tresca-softening"
    }

    fn internal_variables(&self) -> &[InternalVar] {
        variables(self.intact.profile.is_some())
    }

    fn initial_internal(&self, x0: [f64; 2], internal: &mut [f64]) {
        let su_ref = self.cu_at(x0[1]);
        internal[SU] = su_ref;
        if self.intact.profile.is_some() {
            internal[CU] = su_ref;
        }
    }

    fn yields(&self) -> bool {
        true
    }

    fn yielded(&self, before: &GaussState, after: &GaussState) -> bool {
        grew(before, after, EPS_Q)
    }

    fn symmetric_tangent(&self) -> bool {
        self.rate.is_none()
    }

    fn isochoric(&self) -> bool {
        true
    }

    fn bulk_at(&self, state: &GaussState) -> Option<f64> {
        self.intact
            .young_over_cu
            .map(|_| self.elastic_at(self.su_ref_of(state)).bulk_modulus())
    }

    fn admit(&self, state: &mut GaussState) -> bool {
        let mut changed = clamp_to_bounds(self.internal_variables(), &mut state.internal);
        // The point's strength, never below the least the model has (remoulded, at the
        // reference rate): a variable of another material met at an interface reads 0.
        let floor = self.remoulded_ratio * self.su_ref_of(state);
        let Some(su) = state.internal.get_mut(SU) else {
            return changed;
        };
        // NaN included: a strength that is not at least the floor is raised to it.
        if (*su).partial_cmp(&floor).is_none_or(|o| o.is_lt()) {
            *su = floor;
            changed = true;
        }
        let su = *su;
        let s = &mut state.stress;
        let a = 0.5 * (s[0] - s[1]);
        let r = a.hypot(s[3]);
        // On the surface to round-off (a converged state, rotated by the element): admissible.
        if r > su * (1.0 + 1e-12) {
            let shrink = 1.0 - su / r;
            s[0] -= shrink * a;
            s[1] += shrink * a;
            s[3] -= shrink * s[3];
            changed = true;
        }
        changed
    }
}

#[cfg(test)]
mod tests;
