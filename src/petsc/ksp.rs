//! Krylov solvers (KSP): ours, or borrowed from a SNES or a preconditioner.

use super::error::{check, PetscError};
use super::ffi;
use super::init::cstring;
use super::matrix::{to_int, MatRef};
use super::object::{comm_of, object, Object};
use super::pc::PcRef;
use super::vector::VecRef;
use super::viewer::ViewerRef;
use std::marker::PhantomData;

/// A KSP we own; destroyed on drop.
pub struct Ksp {
    raw: ffi::KSP,
}

/// A KSP borrowed for `'a` (from a `Ksp`, a SNES or a preconditioner: live while its owner
/// keeps its type).
#[derive(Clone, Copy)]
pub struct KspRef<'a> {
    pub(super) raw: ffi::KSP,
    _owner: PhantomData<&'a ()>,
}

object!(Ksp, KspRef<'_>);

/// The side a Krylov method applies its preconditioner on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

/// The residual norm a Krylov method converges on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Norm {
    /// None: a fixed number of iterations.
    None,
    Unpreconditioned,
}

impl Ksp {
    /// Collective. A new KSP on the communicator of `like`.
    pub fn create_like(like: &impl Object) -> Result<Ksp, PetscError> {
        let comm = comm_of(like)?;
        let mut raw: ffi::KSP = std::ptr::null_mut();
        // SAFETY: out-pointer to a fresh handle, owned from here on.
        check(unsafe { ffi::KSPCreate(comm, &mut raw) }, "KSPCreate")?;
        Ok(Ksp { raw })
    }

    pub fn as_ref(&self) -> KspRef<'_> {
        // SAFETY: our own live handle, borrowed for as long as `self`.
        unsafe { KspRef::lent(self.raw) }
    }
}

impl Drop for Ksp {
    fn drop(&mut self) {
        // SAFETY: we own the handle.
        unsafe {
            ffi::KSPDestroy(&mut self.raw);
        }
    }
}

impl<'a> KspRef<'a> {
    /// # Safety
    /// `raw` must be a live KSP for as long as the returned borrow is used.
    pub(crate) unsafe fn lent(raw: ffi::KSP) -> KspRef<'a> {
        KspRef {
            raw,
            _owner: PhantomData,
        }
    }

    pub fn set_type(&self, kind: &str) -> Result<(), PetscError> {
        let kind = cstring(kind)?;
        // SAFETY: live KSP; PETSc copies the name.
        check(
            unsafe { ffi::KSPSetType(self.raw, kind.as_ptr()) },
            "KSPSetType",
        )
    }

    /// The GMRES restart length.
    pub fn set_gmres_restart(&self, restart: usize) -> Result<(), PetscError> {
        let restart = to_int(restart, "GMRES restart")?;
        // SAFETY: live KSP.
        check(
            unsafe { ffi::KSPGMRESSetRestart(self.raw, restart) },
            "KSPGMRESSetRestart",
        )
    }

    pub fn set_pc_side(&self, side: Side) -> Result<(), PetscError> {
        let side = match side {
            Side::Left => ffi::PCSide_PC_LEFT,
            Side::Right => ffi::PCSide_PC_RIGHT,
        };
        // SAFETY: live KSP.
        check(unsafe { ffi::KSPSetPCSide(self.raw, side) }, "KSPSetPCSide")
    }

    pub fn set_norm_type(&self, norm: Norm) -> Result<(), PetscError> {
        let norm = match norm {
            Norm::None => ffi::KSPNormType_KSP_NORM_NONE,
            Norm::Unpreconditioned => ffi::KSPNormType_KSP_NORM_UNPRECONDITIONED,
        };
        // SAFETY: live KSP.
        check(
            unsafe { ffi::KSPSetNormType(self.raw, norm) },
            "KSPSetNormType",
        )
    }

    /// Relative and absolute tolerances, divergence tolerance (`None`: PETSc's default) and
    /// the most iterations.
    pub fn set_tolerances(
        &self,
        rtol: f64,
        abstol: f64,
        dtol: Option<f64>,
        max_it: usize,
    ) -> Result<(), PetscError> {
        let dtol = dtol.unwrap_or(ffi::PETSC_DEFAULT as f64);
        let max_it = to_int(max_it, "KSP iterations")?;
        // SAFETY: live KSP.
        check(
            unsafe { ffi::KSPSetTolerances(self.raw, rtol, abstol, dtol, max_it) },
            "KSPSetTolerances",
        )
    }

    /// The preconditioner, borrowed.
    pub fn pc(&self) -> Result<PcRef<'a>, PetscError> {
        let mut pc: ffi::PC = std::ptr::null_mut();
        // SAFETY: live KSP; the PC lives as long as it.
        check(unsafe { ffi::KSPGetPC(self.raw, &mut pc) }, "KSPGetPC")?;
        Ok(unsafe { PcRef::lent(pc) })
    }

    pub fn set_options_prefix(&self, prefix: &str) -> Result<(), PetscError> {
        let prefix = cstring(prefix)?;
        // SAFETY: live KSP; PETSc copies the prefix.
        check(
            unsafe { ffi::KSPSetOptionsPrefix(self.raw, prefix.as_ptr()) },
            "KSPSetOptionsPrefix",
        )
    }

    /// The operator and preconditioning matrix (PETSc takes its own references).
    pub fn set_operators(&self, a: MatRef<'_>, p: MatRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(
            unsafe { ffi::KSPSetOperators(self.raw, a.raw, p.raw) },
            "KSPSetOperators",
        )
    }

    /// The operator, borrowed.
    pub fn operator(&self) -> Result<MatRef<'a>, PetscError> {
        let mut a: ffi::Mat = std::ptr::null_mut();
        // SAFETY: live KSP; the operator lives while the KSP holds it.
        check(
            unsafe { ffi::KSPGetOperators(self.raw, &mut a, std::ptr::null_mut()) },
            "KSPGetOperators",
        )?;
        Ok(unsafe { MatRef::lent(a) })
    }

    /// Collective. Reads the KSP's options (the command line's errors name its options).
    pub fn set_from_options(&self) -> Result<(), PetscError> {
        // SAFETY: live KSP.
        check(
            unsafe { ffi::KSPSetFromOptions(self.raw) },
            "KSPSetFromOptions",
        )
        .map_err(PetscError::naming_user_options)
    }

    /// Collective.
    pub fn set_up(&self) -> Result<(), PetscError> {
        // SAFETY: live KSP.
        check(unsafe { ffi::KSPSetUp(self.raw) }, "KSPSetUp")
    }

    /// Collective. x = A⁻¹ b.
    pub fn solve(&self, b: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(unsafe { ffi::KSPSolve(self.raw, b.raw, x.raw) }, "KSPSolve")
    }

    /// A failed solve inside the preconditioner `pc` fails `pc` as PETSc's own report it: `x`
    /// is marked (Inf) and the outer Krylov method stops with DIVERGED_PC_FAILED.
    pub fn check_solve(&self, pc: PcRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(
            unsafe { ffi::KSPCheckSolve(self.raw, pc.raw, x.raw) },
            "KSPCheckSolve",
        )
    }

    /// Collective. Frees what the set-up made, and the operators.
    pub fn reset(&self) -> Result<(), PetscError> {
        // SAFETY: live KSP.
        check(unsafe { ffi::KSPReset(self.raw) }, "KSPReset")
    }

    pub fn view(&self, viewer: ViewerRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(unsafe { ffi::KSPView(self.raw, viewer.raw) }, "KSPView")
    }

    /// Richardson's damping.
    pub fn set_richardson_scale(&self, scale: f64) -> Result<(), PetscError> {
        // SAFETY: live KSP.
        check(
            unsafe { ffi::KSPRichardsonSetScale(self.raw, scale) },
            "KSPRichardsonSetScale",
        )
    }

    /// Iterations of the last solve, and whether it converged.
    pub fn outcome(&self) -> Result<(usize, bool), PetscError> {
        let mut its: ffi::PetscInt = 0;
        let mut reason: ffi::KSPConvergedReason = 0;
        // SAFETY: live KSP.
        unsafe {
            check(
                ffi::KSPGetIterationNumber(self.raw, &mut its),
                "KSPGetIterationNumber",
            )?;
            check(
                ffi::KSPGetConvergedReason(self.raw, &mut reason),
                "KSPGetConvergedReason",
            )?;
        }
        Ok((its.max(0) as usize, reason > 0))
    }
}
