//! Abaqus UMAT plug-ins: a user's constitutive model, compiled from Fortran into a shared
//! library, called at every Gauss point through the Abaqus UMAT interface.
//!
//! What the UMAT sees, in the Abaqus conventions (NDI = 3, NSHR = 1, NTENS = 4: components
//! 11, 22, 33, 12, tensor shear stress, engineering shear strain γ12, as pfem-mpi's own Voigt
//! vectors, so nothing is reordered):
//! - STRESS: the Cauchy stress at the start of the step, σ_n; on return, the stress at its end.
//! - DSTRAN: the strain of the step, the measure the element uses. On the P2–P1 element (the
//!   default for a UMAT with state variables) it is the logarithmic strain ln U of the step with
//!   its rotation removed (the polar decomposition F = R U), which is what Abaqus hands a UMAT at
//!   finite strain (its Hughes–Winget increment is ln U to second order); the element rotates
//!   the returned stress by R, as Abaqus rotates STRESS before the call. On the P2 element it is
//!   the Green–Lagrange strain E relative to x_n, equal to ln U to first order: there the stress
//!   returned is taken as the second Piola–Kirchhoff stress relative to x_n, as for the built-in
//!   models. STRAN is the sum of the earlier steps' DSTRAN, kept as the internal variable `stran`.
//! - DROT is the identity and DFGRD0 = I, DFGRD1 = U: the UMAT works in the frame with the step's
//!   rotation removed, so a rotation applied by the UMAT (ROTSIG) must do nothing; the element
//!   applies R to the stress itself. Tensor-valued state variables are not rotated (they are
//!   declared scalars here).
//! - STATEV: the model's internal variables `statev_1 ... statev_N` (or `state_names`), which
//!   checkpoints, halo exchange, mapping and output carry like any model's.
//! - PNEWDT: set to 1e36 before the call; a value below 1 makes the step be cut (the call
//!   fails as a Newton divergence does).
//! - The analysis is one Abaqus step (KSTEP = 1). Its time is the scene's in seconds when the
//!   scene gives one (`steps.duration`, or timed `[[rigid]]` stages: [`crate::scene::clock`]),
//!   else the load factor: TIME(1) = TIME(2) = the time at the start of the increment, DTIME
//!   its increment (a cut step's piece), KINC = the step number. NOEL is the triangle's rank-local index + 1 (PFEM remeshes
//!   every step, so element numbers identify nothing across steps or ranks), NPT = 1..3 the
//!   Gauss point, COORDS its position at the start of the step, CELENT = √(2 × area) of the
//!   triangle; LAYER = KSPT = 1; temperatures and field variables 0 (isothermal).
//!
//! Which element: a UMAT with state variables counts as inelastic ([`Material::yields`]), so
//! `solver.element = "auto"` gives it the P2–P1 element, as for Tresca clay; one without, the P2
//! element. The P2–P1 element takes only the deviator of the returned stress and tangent: the
//! pressure is its own field, with the bulk modulus of the material's `young` and `poisson`
//! (which a UMAT material therefore still gives, matching its elastic constants). A UMAT whose
//! volumetric response matters (pressure-dependent, dilatant) needs `solver.element = "p2"`.
//!
//! A UMAT runs inside an MPI rank, once per Gauss point and Newton iteration, from the same
//! state each iteration: it must not keep state between calls (SAVE variables, COMMON blocks),
//! write files, call MPI, or STOP (which ends the rank, and with it the run).

mod ffi;
pub mod site;

use std::borrow::Cow;
use std::path::Path;

use super::{GaussState, Internal, InternalVar, Material, MaterialError, MaterialResponse};
use crate::material::layout::VarKind;

/// The internal variable that keeps STRAN, the strain accumulated over the earlier steps.
pub const STRAN: &str = "stran";

/// PNEWDT as Abaqus sets it before a call: no request.
const PNEWDT_NONE: f64 = 1e36;

/// A UMAT-defined material.
#[derive(Debug)]
pub struct Umat {
    lib: ffi::Library,
    props: Vec<f64>,
    vars: Vec<InternalVar>,
    /// CMNAME: the scene material's name, or "UMAT".
    cmname: String,
}

/// The internal variables of a UMAT with state variables named `names`: STRAN, then them.
pub fn variables(names: &[String]) -> Vec<InternalVar> {
    let mut v = vec![InternalVar {
        name: Cow::Borrowed(STRAN),
        kind: VarKind::Strain,
    }];
    v.extend(names.iter().map(|n| InternalVar {
        name: Cow::Owned(n.clone()),
        kind: VarKind::Scalar,
    }));
    v
}

/// The default state-variable names: `statev_1 ... statev_n`.
pub fn default_names(n: usize) -> Vec<String> {
    (1..=n).map(|i| format!("statev_{i}")).collect()
}

/// Whether `path` is a library with a UMAT in it (the scene's check, before a run).
pub fn check_library(path: &Path) -> Result<(), String> {
    ffi::Library::open(path).map(|_| ())
}

impl Umat {
    /// Opens `library`; the state variables are called `names`.
    pub fn new(
        library: &Path,
        props: Vec<f64>,
        names: &[String],
        cmname: Option<&str>,
    ) -> Result<Umat, String> {
        Ok(Umat {
            lib: ffi::Library::open(library)?,
            props,
            vars: variables(names),
            cmname: cmname.unwrap_or("UMAT").to_uppercase(),
        })
    }

    fn failure(&self, what: String) -> MaterialError {
        MaterialError::Plugin(format!("UMAT {}: {what}", self.lib.path().display()))
    }

    /// One call at `state_n` with step strain `dstran` and stretch `u` (tensor components,
    /// `[xx, yy, zz, xy]`).
    fn call(
        &self,
        state_n: &GaussState,
        dstran: &[f64; 4],
        u: [f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        if dstran.iter().any(|v| !v.is_finite()) {
            return Err(MaterialError::NonFiniteStrain { strain: *dstran });
        }
        let mut internal = state_n.internal.clone();
        // A state from before the model was chosen (or mapped across a material interface)
        // may be short: the missing variables start at zero.
        let need = 4 + self.vars.len() - 1;
        if internal.len() < need {
            internal.resize(need, 0.0);
        }
        let (stran, statev) = internal.split_at_mut(4);
        let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let (inc, element) = site::take_call();
        let (noel, npt, coords, celent) = match element {
            Some((e, q)) => (e.number, q as i32 + 1, e.gauss[q], e.size),
            None => (0, 0, [0.0; 2], 0.0),
        };
        // Column-major 3x3: (1,2) and (2,1) are the two in-plane off-diagonals.
        let dfgrd1 = [u[0], u[3], 0.0, u[3], u[1], 0.0, 0.0, 0.0, u[2]];
        let mut c = ffi::Call {
            stress: state_n.stress,
            statev,
            ddsdde: [0.0; 16],
            sse: 0.0,
            spd: 0.0,
            scd: 0.0,
            stran: [stran[0], stran[1], stran[2], stran[3]],
            dstran: *dstran,
            time: [inc.time, inc.time],
            dtime: inc.dtime,
            props: &self.props,
            coords: [coords[0], coords[1], 0.0],
            drot: identity,
            pnewdt: PNEWDT_NONE,
            celent,
            dfgrd0: identity,
            dfgrd1,
            noel,
            npt,
            kstep: 1,
            kinc: inc.step,
        };
        self.lib.call(&mut c, &self.cmname);
        if c.pnewdt < 1.0 {
            return Err(self.failure(format!("asks for a smaller step (PNEWDT = {})", c.pnewdt)));
        }
        if c.stress.iter().any(|v| !v.is_finite()) {
            return Err(self.failure(format!("returned a non-finite STRESS {:?}", c.stress)));
        }
        if c.ddsdde.iter().any(|v| !v.is_finite()) {
            return Err(self.failure("returned a non-finite DDSDDE".to_string()));
        }
        if c.statev.iter().any(|v| !v.is_finite()) {
            return Err(self.failure("returned a non-finite STATEV".to_string()));
        }
        let s = c.stress;
        let d = std::array::from_fn(|i| std::array::from_fn(|j| c.ddsdde[i + 4 * j]));
        for (a, b) in stran.iter_mut().zip(dstran) {
            *a += b;
        }
        Ok(MaterialResponse {
            s,
            d,
            state: GaussState {
                stress: s,
                internal: Internal::from_slice(&internal),
            },
        })
    }
}

/// f applied to the symmetric tensor of a Voigt strain (engineering shear), through its
/// eigenvalues: the stretch U of a step from its strain.
fn tensor_function(e: &[f64; 4], f: impl Fn(f64) -> f64) -> [f64; 4] {
    let (a, b, c) = (e[0], e[1], 0.5 * e[3]);
    let mean = 0.5 * (a + b);
    let r = (0.25 * (a - b) * (a - b) + c * c).sqrt();
    let (l1, l2) = (mean + r, mean - r);
    let (f1, f2) = (f(l1), f(l2));
    let zz = f(e[2]);
    if r <= 1e-14 * (1.0 + mean.abs()) {
        return [f1, f1, zz, 0.0];
    }
    // f(A) = f1 P1 + f2 P2 with the projector P1 = (A − l2 I)/(l1 − l2).
    let p = 1.0 / (l1 - l2);
    let (p11, p22, p12) = ((a - l2) * p, (b - l2) * p, c * p);
    [
        f2 + (f1 - f2) * p11,
        f2 + (f1 - f2) * p22,
        zz,
        (f1 - f2) * p12,
    ]
}

impl Material for Umat {
    fn update(
        &self,
        state_n: &GaussState,
        e: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        let u = tensor_function(e, |l| (1.0 + 2.0 * l).max(0.0).sqrt());
        self.call(state_n, e, u)
    }

    fn update_log_strain(
        &self,
        state_n: &GaussState,
        eps: &[f64; 4],
    ) -> Result<MaterialResponse, MaterialError> {
        self.call(state_n, eps, tensor_function(eps, f64::exp))
    }

    fn name(&self) -> &'static str {
        "umat"
    }

    fn internal_variables(&self) -> &[InternalVar] {
        &self.vars
    }

    /// A UMAT with state variables is taken to be inelastic: the mixed element and Newton's
    /// backtracking are then used, as for the built-in plastic model.
    fn yields(&self) -> bool {
        self.vars.len() > 1
    }

    /// A point whose state variables changed in the step.
    fn yielded(&self, before: &GaussState, after: &GaussState) -> bool {
        let tail = |s: &GaussState| s.internal.get(4..).map(<[f64]>::to_vec).unwrap_or_default();
        tail(before) != tail(after)
    }

    /// Nothing: the bounds of a UMAT's state variables are its author's, and calling it outside
    /// an increment (to return a mapped stress) is no call a UMAT expects.
    fn admit(&self, _state: &mut GaussState) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretch_of_a_shear_strain_squares_to_c() {
        // U² = I + 2E for the Green–Lagrange strain.
        let e = [0.03, -0.01, 0.0, 0.04];
        let u = tensor_function(&e, |l| (1.0 + 2.0 * l).sqrt());
        let c = [
            u[0] * u[0] + u[3] * u[3],
            u[1] * u[1] + u[3] * u[3],
            u[3] * (u[0] + u[1]),
        ];
        let want = [1.0 + 2.0 * e[0], 1.0 + 2.0 * e[1], e[3]];
        for k in 0..3 {
            assert!((c[k] - want[k]).abs() < 1e-14, "{c:?} vs {want:?}");
        }
        assert_eq!(u[2], 1.0);
    }

    #[test]
    fn missing_library_is_named() {
        let e = Umat::new(Path::new("/nonexistent/libx.so"), vec![], &[], None)
            .expect_err("no such file");
        assert!(e.contains("/nonexistent/libx.so"), "{e}");
        let names = default_names(2);
        assert_eq!(names, ["statev_1", "statev_2"]);
        assert_eq!(variables(&names)[2].name, "statev_2");
    }
}
