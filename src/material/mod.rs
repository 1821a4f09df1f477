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

pub mod elastic;
pub mod tresca;

use std::fmt;

/// Per-Gauss-point history carried from one step to the next.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GaussState {
    /// Cauchy stress `[xx, yy, zz, xy]` (tensor shear). On input to [`Material::update`] it is σ_n,
    /// the stress at the start of the step; the element overwrites it with σ_{n+1}.
    pub stress: [f64; 4],
    /// Accumulated plastic strain `[xx, yy, zz, xy]` (engineering shear); zero for elastic models.
    pub plastic_strain: [f64; 4],
    /// Equivalent (accumulated) plastic strain; zero for elastic models.
    pub eps_q: f64,
}

impl GaussState {
    /// Number of scalars in the flat representation used for storage and communication.
    pub const LEN: usize = 9;

    /// Flattens as `[stress(4), plastic_strain(4), eps_q]`.
    pub fn to_array(&self) -> [f64; Self::LEN] {
        let s = &self.stress;
        let p = &self.plastic_strain;
        [s[0], s[1], s[2], s[3], p[0], p[1], p[2], p[3], self.eps_q]
    }

    /// Inverse of [`GaussState::to_array`].
    pub fn from_array(a: &[f64; Self::LEN]) -> Self {
        Self {
            stress: [a[0], a[1], a[2], a[3]],
            plastic_strain: [a[4], a[5], a[6], a[7]],
            eps_q: a[8],
        }
    }
}

/// Result of a constitutive update at one Gauss point.
#[derive(Clone, Copy, Debug, PartialEq)]
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
    /// from the same `state_n`. `d` must be symmetric (the P2 element forms the upper triangle
    /// of its tangent and mirrors it): a law with a non-symmetric tangent (non-associated flow)
    /// would need the element's full product back.
    fn update(&self, state_n: &GaussState, e: &[f64; 4])
        -> Result<MaterialResponse, MaterialError>;

    /// Computes the response to the *logarithmic* strain of the step with the step's rotation
    /// removed, for elements that do the rotation themselves ([`crate::fem::mixed`]).
    ///
    /// With the polar decomposition F = R U of the step deformation gradient, `eps` is
    /// ε = ln U = ½ ln(FᵀF) (Voigt, engineering shear, `eps[2] = 0`), expressed in the
    /// start-of-step frame. The returned `s` is then the end-of-step Cauchy stress *before* the
    /// rotation R is applied (σ_{n+1} = R s Rᵀ), and `d = ds/dε`. Elements that supply their own
    /// pressure field use only the deviatoric parts of `s` and `d`.
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_state_array_round_trip() {
        let s = GaussState {
            stress: [1.0, -2.0, 3.5, 0.25],
            plastic_strain: [1e-3, -2e-3, 0.0, 4e-3],
            eps_q: 7.0e-3,
        };
        let a = s.to_array();
        assert_eq!(a.len(), GaussState::LEN);
        assert_eq!(a, [1.0, -2.0, 3.5, 0.25, 1e-3, -2e-3, 0.0, 4e-3, 7.0e-3]);
        assert_eq!(GaussState::from_array(&a), s);
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
