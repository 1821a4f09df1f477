//! Drained soil: Mohr–Coulomb, elastic–perfectly plastic, with non-associated flow and an
//! optional tension cut-off. This module is the worked example of adding a model: the model
//! itself here, then one line each where models are listed (`material/mod.rs`, the scene's
//! `MaterialModel` and its parameters, `model.rs`).
//!
//! # Criterion and flow
//! With principal stresses σ1 ≥ σ2 ≥ σ3 (tension positive; σzz is one of them, so a state where
//! the out-of-plane stress is the major or minor one is judged in 3-D):
//! - f = (σ1 − σ3) + (σ1 + σ3) sin φ − 2c cos φ ≤ 0, and with a cut-off t, σ1 − t ≤ 0;
//! - plastic potential g = (σ1 − σ3) + (σ1 + σ3) sin ψ (ψ ≤ φ): the flow dilates at
//!   −Δε_v/Δε_1... = sin ψ of the principal shear; the cut-off flows along its own normal.
//!
//! # Return mapping (de Souza Neto, Perić & Owen 2008, §8.2, in its multi-surface form)
//! In principal space each face is a plane n_f·σ = k with a constant flow direction n_g, so the
//! backward-Euler return onto a set of active faces is linear: σ = σ_tr − D Σ Δγ_i n_g,i with
//! n_f,j·σ = k_j. The faces are, in the trial's order, the main face (1,3), the two faces that
//! meet it at the edges σ1 = σ2 (face (2,3)) and σ2 = σ3 (face (1,2)), and the cut-off's
//! σ1, σ2, σ3 = t. The return tries the main face, then each edge, the cut-off and its edges and
//! corners (sets of at most three faces) and takes the first whose multipliers are all ≥ 0 and
//! whose stress violates no face: the main-face, edge and apex returns of the book when there
//! is no cut-off. Where every set fails the stress goes to the apex σ = min(c cot φ, t) on the
//! hydrostatic axis, the book's apex return for a perfectly plastic material (with ψ = 0 the
//! flow has no volume change to reach it, and the apex is a limit, not a flow-rule result).
//!
//! The consistent tangent is the derivative of that linear map, I − D Nᵍᵀ A⁻¹ N_f with
//! A = N_f D Nᵍᵀ over the active faces (0 at the apex), taken to global components with the spin
//! of the principal frame ([`super::principal`]). It is symmetric exactly when ψ = φ.
//!
//! Internal variables as [`super::tresca`]'s: the plastic strain (σzz's out-of-plane component
//! included: a plane-strain point can flow plastically in z, its elastic strain then balances
//! it) and `eps_q` = Σ √(2/3 Δε^p:Δε^p).

use super::elastic::LinearElastic;
use super::layout::{grew, internal_len};
use super::principal::{solve_small, Spectral};
use super::{GaussState, InternalVar, Material, MaterialError, MaterialResponse};

/// The internal variables: as Tresca's, so that a scene of clay and sand shares the columns.
pub static VARIABLES: [InternalVar; 2] = [
    InternalVar::strain("plastic_strain"),
    InternalVar::scalar("eps_q"),
];
/// Offset of the plastic strain in [`GaussState::internal`].
pub const PLASTIC_STRAIN: usize = 0;
/// Offset of `eps_q` in [`GaussState::internal`].
pub const EPS_Q: usize = 4;

/// Elastic–perfectly plastic Mohr–Coulomb soil; see the module docs.
///
/// Construct with [`MohrCoulomb::new`]; fields are public for reading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MohrCoulomb {
    pub young: f64,
    pub poisson: f64,
    /// c (Pa), ≥ 0 (> 0 when φ = 0).
    pub cohesion: f64,
    /// φ in degrees, in [0, 90).
    pub friction_angle: f64,
    /// ψ in degrees, in [0, φ].
    pub dilation_angle: f64,
    /// Largest principal stress (Pa, tension positive), ≥ 0; None: no cut-off.
    pub tension_cutoff: Option<f64>,
}

/// Sorted principal stresses after a return, and their derivatives by the trial's.
type Returned = ([f64; 3], [[f64; 3]; 3]);

/// One face of the criterion in sorted principal space: n_f·σ ≤ k, flowing along n_g.
#[derive(Clone, Copy)]
struct Face {
    nf: [f64; 3],
    ng: [f64; 3],
    k: f64,
}

impl MohrCoulomb {
    /// Validates the parameters, naming the offending one.
    pub fn new(
        young: f64,
        poisson: f64,
        cohesion: f64,
        friction_angle: f64,
        dilation_angle: f64,
        tension_cutoff: Option<f64>,
    ) -> Result<Self, MaterialError> {
        LinearElastic::new(young, poisson)?;
        check_strength(cohesion, friction_angle, dilation_angle)?;
        if let Some(t) = tension_cutoff {
            if !(t.is_finite() && t >= 0.0) {
                return Err(MaterialError::InvalidParameter {
                    name: "tension_cutoff",
                    value: t,
                    requirement: "0 <= tension_cutoff < inf",
                });
            }
        }
        Ok(Self {
            young,
            poisson,
            cohesion,
            friction_angle,
            dilation_angle,
            tension_cutoff,
        })
    }

    fn elastic(&self) -> LinearElastic {
        LinearElastic {
            young: self.young,
            poisson: self.poisson,
        }
    }

    /// The 3-D isotropic stiffness on principal values (σzz included).
    fn principal_stiffness(&self) -> [[f64; 3]; 3] {
        let (l, m) = self.elastic().lame();
        std::array::from_fn(|i| std::array::from_fn(|j| l + if i == j { 2.0 * m } else { 0.0 }))
    }

    /// Principal compliance: inverse of [`Self::principal_stiffness`].
    fn principal_compliance(&self) -> [[f64; 3]; 3] {
        let (e, nu) = (self.young, self.poisson);
        std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 1.0 } else { -nu } / e))
    }

    /// The faces in sorted principal space: main (1,3), edge partners (2,3) and (1,2), then the
    /// cut-off's three.
    fn faces(&self) -> Vec<Face> {
        let (sf, cf) = self.friction_angle.to_radians().sin_cos();
        let sg = self.dilation_angle.to_radians().sin();
        let k = 2.0 * self.cohesion * cf;
        let mc = |i: usize, j: usize| {
            let mut nf = [0.0; 3];
            let mut ng = [0.0; 3];
            nf[i] = 1.0 + sf;
            nf[j] = -(1.0 - sf);
            ng[i] = 1.0 + sg;
            ng[j] = -(1.0 - sg);
            Face { nf, ng, k }
        };
        let mut out = vec![mc(0, 2), mc(1, 2), mc(0, 1)];
        if let Some(t) = self.tension_cutoff {
            for i in 0..3 {
                let mut n = [0.0; 3];
                n[i] = 1.0;
                out.push(Face { nf: n, ng: n, k: t });
            }
        }
        out
    }

    /// The apex on the hydrostatic axis: where the cone (or the cut-off) closes.
    fn apex(&self) -> Option<f64> {
        let phi = self.friction_angle.to_radians();
        let cone = (phi > 0.0).then(|| self.cohesion / phi.tan());
        match (cone, self.tension_cutoff) {
            (Some(a), Some(t)) => Some(a.min(t)),
            (a, t) => a.or(t),
        }
    }

    /// The most violated face's value at sorted principal stress `s` (> 0: outside).
    fn violation(faces: &[Face], s: &[f64; 3]) -> f64 {
        faces
            .iter()
            .map(|f| dot(&f.nf, s) - f.k)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Backward-Euler return of sorted principal trial stresses: the returned stresses and
    /// their derivatives with respect to the trial's; None when elastic.
    fn principal_return(&self, tr: &[f64; 3]) -> Result<Option<Returned>, MaterialError> {
        let faces = self.faces();
        if Self::violation(&faces, tr) <= 0.0 {
            return Ok(None);
        }
        let d = self.principal_stiffness();
        let scale = tr
            .iter()
            .fold(self.cohesion, |m, v| m.max(v.abs()))
            .max(self.tension_cutoff.unwrap_or(0.0));
        let tol = 1e-10 * scale;
        for set in candidate_sets(faces.len()) {
            let n = set.len();
            // D n_g of each active face, and A_ij = n_f,i · D n_g,j.
            let dng: Vec<[f64; 3]> = set.iter().map(|&j| mat_vec(&d, &faces[j].ng)).collect();
            let mut a = [[0.0; 3]; 3];
            let mut rhs = [0.0; 3];
            for (i, &fi) in set.iter().enumerate() {
                for (j, dn) in dng.iter().enumerate() {
                    a[i][j] = dot(&faces[fi].nf, dn);
                }
                rhs[i] = dot(&faces[fi].nf, tr) - faces[fi].k;
            }
            let Some(dgamma) = solve_small(n, &a, &rhs) else {
                continue;
            };
            if dgamma[..n].iter().any(|&g| g < -1e-12) {
                continue;
            }
            let mut s = *tr;
            for (g, dn) in dgamma[..n].iter().zip(&dng) {
                for k in 0..3 {
                    s[k] -= g * dn[k];
                }
            }
            // Judged in the returned stress's own order: a return that swapped two principal
            // stresses meets the faces of the other order.
            let order = descending(&s);
            if Self::violation(&faces, &order.map(|i| s[i])) > tol {
                continue;
            }
            // dσ/dσ_tr = I − Σ_ij (D n_g,i) (A⁻¹)_ij n_f,jᵀ, column by column of A⁻¹.
            let mut ds = [[0.0; 3]; 3];
            for (c, row) in ds.iter_mut().enumerate() {
                row[c] = 1.0;
            }
            for (j, &fj) in set.iter().enumerate() {
                let mut unit = [0.0; 3];
                unit[j] = 1.0;
                // The matrix has just been solved with.
                let col = solve_small(n, &a, &unit).unwrap_or_default();
                for (i, dn) in dng.iter().enumerate() {
                    for (row, dnr) in ds.iter_mut().zip(dn) {
                        for (v, nf) in row.iter_mut().zip(&faces[fj].nf) {
                            *v -= dnr * col[i] * nf;
                        }
                    }
                }
            }
            return Ok(Some((s, ds)));
        }
        match self.apex() {
            Some(a) => Ok(Some(([a; 3], [[0.0; 3]; 3]))),
            None => Err(MaterialError::ReturnMappingFailed {
                iterations: 1,
                residual: Self::violation(&faces, tr),
            }),
        }
    }
}

/// c ≥ 0, 0 ≤ φ < 90°, 0 ≤ ψ ≤ φ, and strength somewhere (c > 0 or φ > 0): the parameters
/// Mohr–Coulomb and Drucker–Prager share.
pub fn check_strength(cohesion: f64, friction: f64, dilation: f64) -> Result<(), MaterialError> {
    let bad = |name, value, requirement| {
        Err(MaterialError::InvalidParameter {
            name,
            value,
            requirement,
        })
    };
    if !(friction.is_finite() && (0.0..90.0).contains(&friction)) {
        return bad(
            "friction_angle",
            friction,
            "0 <= friction_angle < 90 (degrees)",
        );
    }
    if !(dilation.is_finite() && dilation >= 0.0 && dilation <= friction) {
        return bad(
            "dilation_angle",
            dilation,
            "0 <= dilation_angle <= friction_angle (degrees)",
        );
    }
    if !(cohesion.is_finite() && cohesion >= 0.0) {
        return bad("cohesion", cohesion, "0 <= cohesion < inf");
    }
    if cohesion == 0.0 && friction == 0.0 {
        return bad(
            "cohesion",
            cohesion,
            "cohesion > 0 when friction_angle = 0 (no strength at all)",
        );
    }
    Ok(())
}

/// The active sets to try, in order: single faces, pairs, triples of the `n` faces (main face
/// first), ending at the corners.
fn candidate_sets(n: usize) -> impl Iterator<Item = Vec<usize>> {
    let singles = (0..n).map(|i| vec![i]);
    let pairs = (0..n).flat_map(move |i| (i + 1..n).map(move |j| vec![i, j]));
    let triples = (0..n)
        .flat_map(move |i| (i + 1..n).flat_map(move |j| (j + 1..n).map(move |k| vec![i, j, k])));
    singles.chain(pairs).chain(triples)
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn mat_vec(m: &[[f64; 3]; 3], v: &[f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| dot(&m[i], v))
}

/// The order of `v`'s entries from largest to smallest.
pub fn descending(v: &[f64; 3]) -> [usize; 3] {
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| v[j].total_cmp(&v[i]));
    order
}

impl Material for MohrCoulomb {
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
        let frame = Spectral::of(&trial.s);
        let order = descending(&frame.values);
        let sorted = order.map(|i| frame.values[i]);
        let Some((returned, dsorted)) = self.principal_return(&sorted)? else {
            return Ok(MaterialResponse {
                s: trial.s,
                d: trial.d,
                state,
            });
        };
        let mut values = [0.0; 3];
        let mut dv = [[0.0; 3]; 3];
        for (i, &oi) in order.iter().enumerate() {
            values[oi] = returned[i];
            for (j, &oj) in order.iter().enumerate() {
                dv[oi][oj] = dsorted[i][j];
            }
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(MaterialError::ReturnMappingFailed {
                iterations: 1,
                residual: f64::NAN,
            });
        }
        let relief: [f64; 3] = std::array::from_fn(|i| frame.values[i] - values[i]);
        let plastic = mat_vec(&self.principal_compliance(), &relief);
        Ok(frame.returned(&values, &dv, &plastic, &trial.d, state))
    }

    fn name(&self) -> &'static str {
        "mohr_coulomb"
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
        self.dilation_angle == self.friction_angle
    }

    fn isochoric(&self) -> bool {
        // φ = ψ = 0 without a cut-off is the Tresca prism: strength and flow ignore the mean
        // stress, and the mixed element keeps its deviatoric formulation.
        self.friction_angle == 0.0 && self.dilation_angle == 0.0 && self.tension_cutoff.is_none()
    }
}

#[cfg(test)]
mod tests;
