//! Constitutive models for the updated-Lagrangian load step.
//!
//! Conventions (shared with the rest of pfem-mpi):
//! - stress vectors are Voigt `[xx, yy, zz, xy]` with the *tensor* shear component σxy;
//! - strain vectors are `[xx, yy, zz, xy]` with *engineering* shear γxy = 2 Exy, and Ezz = 0
//!   (plane strain);
//! - a tangent `D` (4x4) maps engineering-strain increments to stress increments, `dS = D dE`.
//!
//! Within a step the reference configuration is the start-of-step configuration x_n. A model is
//! handed the Green–Lagrange strain of the step E (relative to x_n) and the state at x_n, whose
//! `stress` is the Cauchy stress σ_n. It returns the second Piola–Kirchhoff stress relative to x_n,
//! S = σ_n + ΔS(E), and D = dS/dE. At E = 0 the two stress measures coincide, which is why the
//! prestress enters S unchanged. Turning S into the end-of-step Cauchy stress needs the deformation
//! gradient, so that is the element's job, not the material's.

pub mod drucker_prager;
pub mod elastic;
pub mod layout;
pub mod mohr_coulomb;
pub mod placed;
pub mod principal;
pub mod rounded_prism;
pub mod tresca;
pub mod tresca_softening;
pub mod umat;

pub use layout::{InternalVar, Rows, StateLayout, VarKind, STRESS_LEN};

use std::fmt;

/// Per-Gauss-point history carried from one step to the next: the stress, then the model's
/// internal variables in the order of [`Material::internal_variables`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GaussState {
    /// Cauchy stress `[xx, yy, zz, xy]` (tensor shear). On input to [`Material::update`] it is σ_n,
    /// the stress at the start of the step; the element overwrites it with σ_{n+1}.
    pub stress: [f64; 4],
    /// The internal variables, as the model lays them out (empty for an elastic law).
    pub internal: Internal,
}

/// Internal variables of one Gauss point. Inline up to the size of the models here, so that
/// an element's Gauss states cost no allocation; a model with more spills to the heap.
pub type Internal = smallvec::SmallVec<[f64; 8]>;

impl GaussState {
    /// A state with stress `stress` and `n` zero internal variables.
    pub fn stressed(stress: [f64; 4], n: usize) -> GaussState {
        GaussState {
            stress,
            internal: smallvec::smallvec![0.0; n],
        }
    }

    /// Scalars in the flat row (stress and internal variables).
    pub fn len(&self) -> usize {
        STRESS_LEN + self.internal.len()
    }

    /// Never: the stress is always there.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Writes the flat row `[stress, internal]` into `out` (of length [`GaussState::len`]).
    pub fn write_to(&self, out: &mut [f64]) {
        out[..STRESS_LEN].copy_from_slice(&self.stress);
        out[STRESS_LEN..].copy_from_slice(&self.internal);
    }

    /// Inverse of [`GaussState::write_to`].
    pub fn from_row(row: &[f64]) -> GaussState {
        GaussState {
            stress: [row[0], row[1], row[2], row[3]],
            internal: Internal::from_slice(&row[STRESS_LEN..]),
        }
    }
}

/// Result of a constitutive update at one Gauss point.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialResponse {
    /// Second Piola–Kirchhoff stress relative to x_n, `[xx, yy, zz, xy]` (tensor shear).
    pub s: [f64; 4],
    /// Consistent tangent dS/dE, engineering shear on the strain side.
    pub d: [[f64; 4]; 4],
    /// Updated internal variables. Its `stress` field is not meaningful here: the element fills
    /// it with σ_{n+1} once it has the deformation gradient.
    pub state: GaussState,
}

/// Failure of a constitutive model.
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialError {
    /// A model parameter is outside its admissible range.
    InvalidParameter {
        /// Name of the offending field, e.g. `"poisson"`.
        name: &'static str,
        /// The value that was rejected.
        value: f64,
        /// The admissible range, in words.
        requirement: &'static str,
    },
    /// The strain handed to the model contains NaN or infinity.
    NonFiniteStrain {
        /// The strain that was rejected.
        strain: [f64; 4],
    },
    /// A local (return-mapping) iteration did not converge.
    ReturnMappingFailed {
        /// Iterations performed before giving up.
        iterations: usize,
        /// Norm of the local residual at the last iterate.
        residual: f64,
    },
    /// A plug-in model (a UMAT) failed or asked for a smaller step; the message names it.
    Plugin(String),
}

impl fmt::Display for MaterialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidParameter {
                name,
                value,
                requirement,
            } => write!(
                f,
                "invalid material parameter `{name}` = {value}: must satisfy {requirement}"
            ),
            Self::NonFiniteStrain { strain } => {
                write!(f, "non-finite strain handed to material: {strain:?}")
            }
            Self::ReturnMappingFailed {
                iterations,
                residual,
            } => write!(
                f,
                "return mapping failed to converge after {iterations} iterations \
                 (residual {residual:e})"
            ),
            Self::Plugin(message) => f.write_str(message),
        }
    }
}

impl std::error::Error for MaterialError {}

/// A constitutive model in the step-wise updated-Lagrangian setting described in the module docs.
pub trait Material: Send + Sync + fmt::Debug {
    /// Computes S and dS/dE for the step.
    ///
    /// `state_n` is the converged state at x_n (its `stress` is the Cauchy stress σ_n);
    /// `e` is the Green–Lagrange strain of the step relative to x_n (Voigt, engineering shear,
    /// `e[2] = 0` in plane strain). Must not mutate anything: Newton iterations call it repeatedly
    /// from the same `state_n`. `d` must be symmetric unless [`Material::symmetric_tangent`]
    /// says otherwise (the P2 element then forms its full product instead of mirroring the upper
    /// triangle).
    fn update(&self, state_n: &GaussState, e: &[f64; 4])
        -> Result<MaterialResponse, MaterialError>;

    /// Computes the response to the *logarithmic* strain of the step with the step's rotation
    /// removed, for elements that do the rotation themselves ([`crate::fem::mixed`]).
    ///
    /// With the polar decomposition F = R U of the step deformation gradient, `eps` is
    /// ε = ln U = ½ ln(FᵀF) (Voigt, engineering shear, `eps[2] = 0`), expressed in the
    /// start-of-step frame. The returned `s` is then the end-of-step Cauchy stress *before* the
    /// rotation R is applied (σ_{n+1} = R s Rᵀ), and `d = ds/dε`. Elements that supply their own
    /// pressure field use only the deviatoric parts of `s` and `d` when the model is
    /// [`Material::isochoric`], and otherwise also its pressure and the pressure's derivative.
    ///
    /// The default forwards to [`Material::update`]: the models in this module are of the form
    /// σ_n + ΔS(strain) with ΔS a small-strain law, which is exactly a rate-form (hypoelastic /
    /// plastic) law when it is fed a rotation-free strain measure. A model whose `update` is not of
    /// that form (e.g. a hyperelastic law in C) must override this.
    fn update_log_strain(
        &self,
        state_n: &GaussState,
        eps: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        self.update(state_n, eps)
    }

    /// Short identifier used in logs and input files.
    fn name(&self) -> &'static str;

    /// The internal variables the model keeps at a Gauss point, after the stress, in the order
    /// of [`GaussState::internal`]. Storage, exchange, checkpoints and output follow it.
    fn internal_variables(&self) -> &[InternalVar] {
        &[]
    }

    /// Sets the internal variables that a point takes from where it starts (a strength that
    /// varies with depth), in `internal` laid out as [`Material::internal_variables`]. The
    /// others start at zero.
    fn initial_internal(&self, _x0: [f64; 2], _internal: &mut [f64]) {}

    /// The layout of this model's state rows.
    fn layout(&self) -> StateLayout {
        StateLayout::new(self.internal_variables())
    }

    /// Whether the model can yield at all (Newton then backtracks, and the iterative path
    /// watches a yielded zone).
    fn yields(&self) -> bool {
        false
    }

    /// Whether a Gauss point yielded in going from `before` to `after`.
    fn yielded(&self, _before: &GaussState, _after: &GaussState) -> bool {
        false
    }

    /// Whether `d` is always symmetric. False for non-associated flow: every element and
    /// solver path that would mirror or assume symmetry then takes the full matrix.
    fn symmetric_tangent(&self) -> bool {
        true
    }

    /// The bulk modulus of the mixed element's volume law at a point in state `state`, when
    /// the model's stiffness varies from point to point (`young_over_cu`); None: the material's
    /// one bulk modulus.
    fn bulk_at(&self, _state: &GaussState) -> Option<f64> {
        None
    }

    /// Whether the deviatoric response ignores the mean stress and plastic flow keeps the
    /// volume (elasticity, Tresca): the mixed element may then take the deviator alone and
    /// close the pressure with its own volume law. False (the default, safe for any model):
    /// the element takes the model's own pressure as well, which a pressure-dependent or
    /// dilatant model needs.
    fn isochoric(&self) -> bool {
        false
    }

    /// Returns a state that was not computed by this model's update (recovered at a particle
    /// by extrapolation, interpolated at a new Gauss point) to the model's admissible set;
    /// whether it changed anything. An admissible state (its stress to 1e-12 of its size) is
    /// left bitwise as it is, so fields the transfer reproduces exactly stay exact.
    ///
    /// The default: every scalar variable with a [`layout::lower_bound`] (eps_q, xi) is raised
    /// to it, and a model that [`Material::yields`] returns the stress onto its yield surface
    /// with its own return mapping at zero strain (Tresca: the in-plane deviator scaled onto
    /// cu, mean stress and σzz kept; Mohr–Coulomb, Drucker–Prager: their return), keeping the
    /// internal variables (the correction is no plastic flow). A model for which that return
    /// is not the right correction (its strength would change with the plastic strain of the
    /// return, or it is a plug-in) overrides this.
    fn admit(&self, state: &mut GaussState) -> bool {
        let mut changed = layout::clamp_to_bounds(self.internal_variables(), &mut state.internal);
        if self.yields() {
            if let Ok(r) = self.update(state, &[0.0; 4]) {
                // A stress on the surface to round-off (a converged state rotated by the
                // element) is admissible: only a return that moves it by more than 1e-12 of
                // its size counts, so such states keep their bits.
                let size = state.stress.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
                let moved =
                    (r.s.iter().zip(&state.stress)).any(|(a, b)| (a - b).abs() > 1e-12 * size);
                if moved {
                    state.stress = r.s;
                    changed = true;
                }
            }
        }
        changed
    }
}

/// Test helper: the Frobenius distance between `m`'s tangent at the strain increment `e` from
/// `state` and central differences (step `h`) of its stress, relative to the tangent's norm or
/// `floor`, whichever is larger (a zero tangent, as at a cone's apex, needs a floor such as E).
#[cfg(test)]
pub(crate) fn tangent_fd_error(
    m: &dyn Material,
    state: &GaussState,
    e: &[f64; 4],
    h: f64,
    floor: f64,
) -> f64 {
    let r = m.update(state, e).expect("ok");
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..4 {
        let (mut ep, mut em) = (*e, *e);
        ep[j] += h;
        em[j] -= h;
        let sp = m.update(state, &ep).expect("ok").s;
        let sm = m.update(state, &em).expect("ok").s;
        for i in 0..4 {
            let fd = (sp[i] - sm[i]) / (2.0 * h);
            num += (fd - r.d[i][j]).powi(2);
            den += r.d[i][j].powi(2);
        }
    }
    (num / den.max(floor * floor)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_state_row_round_trip() {
        let s = GaussState {
            stress: [1.0, -2.0, 3.5, 0.25],
            internal: Internal::from_slice(&[1e-3, -2e-3, 0.0, 4e-3, 7.0e-3]),
        };
        let mut a = [0.0; 9];
        s.write_to(&mut a);
        assert_eq!(a, [1.0, -2.0, 3.5, 0.25, 1e-3, -2e-3, 0.0, 4e-3, 7.0e-3]);
        assert_eq!(GaussState::from_row(&a), s);
    }

    #[test]
    fn error_messages_name_the_problem() {
        let e = MaterialError::InvalidParameter {
            name: "poisson",
            value: 0.7,
            requirement: "-1 < poisson < 0.5",
        };
        let msg = e.to_string();
        assert!(msg.contains("poisson") && msg.contains("0.7"), "{msg}");
        let e = MaterialError::ReturnMappingFailed {
            iterations: 50,
            residual: 1.5e-3,
        };
        assert!(e.to_string().contains("50"));
    }
}
