//! Preconditioners (PC): ours, or borrowed from a Krylov solver.

use super::error::{check, PetscError, PETSC_ERR_USER};
use super::ffi;
use super::index_set::IndexSet;
use super::init::cstring;
use super::ksp::KspRef;
use super::matrix::{to_int, MatRef};
use super::object::{comm_of, object, reference, Object};
use super::vector::VecRef;
use super::viewer::ViewerRef;
use std::marker::PhantomData;

/// A PC we own (or one more reference to a PC that others hold too); released on drop.
pub struct Pc {
    raw: ffi::PC,
}

/// A PC borrowed for `'a` (from a `Pc` or a KSP: live while its owner keeps its type).
#[derive(Clone, Copy)]
pub struct PcRef<'a> {
    pub(super) raw: ffi::PC,
    _owner: PhantomData<&'a ()>,
}

object!(Pc, PcRef<'_>);

impl Pc {
    /// Collective. A new PC on the communicator of `like`.
    pub fn create_like(like: &impl Object) -> Result<Pc, PetscError> {
        let comm = comm_of(like)?;
        let mut raw: ffi::PC = std::ptr::null_mut();
        // SAFETY: out-pointer to a fresh handle, owned from here on.
        check(unsafe { ffi::PCCreate(comm, &mut raw) }, "PCCreate")?;
        Ok(Pc { raw })
    }

    pub fn as_ref(&self) -> PcRef<'_> {
        // SAFETY: our own live handle, borrowed for as long as `self`.
        unsafe { PcRef::lent(self.raw) }
    }
}

impl Drop for Pc {
    fn drop(&mut self) {
        // SAFETY: we own this reference.
        unsafe {
            ffi::PCDestroy(&mut self.raw);
        }
    }
}

impl<'a> PcRef<'a> {
    /// # Safety
    /// `raw` must be a live PC for as long as the returned borrow is used.
    pub(crate) unsafe fn lent(raw: ffi::PC) -> PcRef<'a> {
        PcRef {
            raw,
            _owner: PhantomData,
        }
    }

    /// A reference of our own to this PC, which keeps it alive.
    pub fn shared(&self) -> Result<Pc, PetscError> {
        reference(self)?;
        Ok(Pc { raw: self.raw })
    }

    pub fn set_type(&self, kind: &str) -> Result<(), PetscError> {
        let kind = cstring(kind)?;
        // SAFETY: live PC; PETSc copies the name.
        check(
            unsafe { ffi::PCSetType(self.raw, kind.as_ptr()) },
            "PCSetType",
        )
    }

    pub fn set_options_prefix(&self, prefix: &str) -> Result<(), PetscError> {
        let prefix = cstring(prefix)?;
        // SAFETY: live PC; PETSc copies the prefix.
        check(
            unsafe { ffi::PCSetOptionsPrefix(self.raw, prefix.as_ptr()) },
            "PCSetOptionsPrefix",
        )
    }

    /// Collective. Reads the PC's options (the command line's errors name its options).
    pub fn set_from_options(&self) -> Result<(), PetscError> {
        // SAFETY: live PC.
        check(
            unsafe { ffi::PCSetFromOptions(self.raw) },
            "PCSetFromOptions",
        )
        .map_err(PetscError::naming_user_options)
    }

    /// The factorisation package of a factor PC (`mumps`, ...).
    pub fn set_factor_package(&self, package: &str) -> Result<(), PetscError> {
        let package = cstring(package)?;
        // SAFETY: live PC; PETSc copies the name.
        check(
            unsafe { ffi::PCFactorSetMatSolverType(self.raw, package.as_ptr()) },
            "PCFactorSetMatSolverType",
        )
    }

    /// Whether GAMG keeps its interpolation (its aggregation) across set-ups.
    pub fn set_gamg_reuse_interpolation(&self, reuse: bool) -> Result<(), PetscError> {
        // SAFETY: live PC.
        check(
            unsafe { ffi::PCGAMGSetReuseInterpolation(self.raw, petsc_bool(reuse)) },
            "PCGAMGSetReuseInterpolation",
        )
    }

    /// Whether GAMG's smoothers take the eigenvalue estimate of its smoothed aggregation.
    pub fn set_gamg_use_sa_est_eig(&self, reuse: bool) -> Result<(), PetscError> {
        // SAFETY: live PC.
        check(
            unsafe { ffi::PCGAMGSetUseSAEstEig(self.raw, petsc_bool(reuse)) },
            "PCGAMGSetUseSAEstEig",
        )
    }

    /// The field `name` of a field split: the rows `is` (PETSc takes its own reference).
    pub fn set_field(&self, name: &str, is: &IndexSet) -> Result<(), PetscError> {
        let name = cstring(name)?;
        // SAFETY: live handles; PETSc copies the name.
        check(
            unsafe { ffi::PCFieldSplitSetIS(self.raw, name.as_ptr(), is.raw) },
            "PCFieldSplitSetIS",
        )
    }

    /// The first field's solver of a field split, borrowed.
    pub fn first_field_solver(&self) -> Result<KspRef<'a>, PetscError> {
        let mut n: ffi::PetscInt = 0;
        let mut sub: *mut ffi::KSP = std::ptr::null_mut();
        let (func, file) = (cstring("first_field_solver")?, cstring(file!())?);
        // SAFETY: live PC; PETSc allocates the array of borrowed KSPs, freed here.
        unsafe {
            check(
                ffi::PCFieldSplitGetSubKSP(self.raw, &mut n, &mut sub),
                "PCFieldSplitGetSubKSP",
            )?;
            let first = (n > 0 && !sub.is_null()).then(|| *sub);
            check(
                ffi::PetscFreeA(
                    1,
                    line!() as std::os::raw::c_int,
                    func.as_ptr(),
                    file.as_ptr(),
                    &mut sub as *mut *mut ffi::KSP as *mut std::ffi::c_void,
                ),
                "PetscFree",
            )?;
            match first {
                Some(ksp) => Ok(KspRef::lent(ksp)),
                None => Err(PetscError {
                    code: PETSC_ERR_USER,
                    message: "the field split has no fields".into(),
                }),
            }
        }
    }

    /// Collective. Makes a field split Schur's, its factorisation upper block-triangular, its
    /// Schur complement preconditioned by `pre`.
    pub fn set_upper_schur(&self, pre: MatRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles; PETSc references `pre`.
        unsafe {
            check(
                ffi::PCFieldSplitSetType(self.raw, ffi::PCCompositeType_PC_COMPOSITE_SCHUR),
                "PCFieldSplitSetType",
            )?;
            check(
                ffi::PCFieldSplitSetSchurFactType(
                    self.raw,
                    ffi::PCFieldSplitSchurFactType_PC_FIELDSPLIT_SCHUR_FACT_UPPER,
                ),
                "PCFieldSplitSetSchurFactType",
            )?;
            check(
                ffi::PCFieldSplitSetSchurPre(
                    self.raw,
                    ffi::PCFieldSplitSchurPreType_PC_FIELDSPLIT_SCHUR_PRE_USER,
                    pre.raw,
                ),
                "PCFieldSplitSetSchurPre",
            )
        }
    }

    /// Collective. A multigrid's levels, with the interpolation `interpolation` to the finest
    /// from the next (two levels), and no Galerkin products: each level has its operator.
    pub fn set_two_levels(&self, interpolation: MatRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles; PETSc references the interpolation.
        unsafe {
            check(
                ffi::PCMGSetLevels(self.raw, 2, std::ptr::null_mut()),
                "PCMGSetLevels",
            )?;
            check(
                ffi::PCMGSetInterpolation(self.raw, 1, interpolation.raw),
                "PCMGSetInterpolation",
            )?;
            check(
                ffi::PCMGSetGalerkin(self.raw, ffi::PCMGGalerkinType_PC_MG_GALERKIN_NONE),
                "PCMGSetGalerkin",
            )
        }
    }

    /// A multigrid's number of levels.
    pub fn mg_levels(&self) -> Result<usize, PetscError> {
        let mut levels: ffi::PetscInt = 0;
        // SAFETY: live PC.
        check(
            unsafe { ffi::PCMGGetLevels(self.raw, &mut levels) },
            "PCMGGetLevels",
        )?;
        Ok(levels.max(0) as usize)
    }

    /// A multigrid's coarse solver, borrowed.
    pub fn mg_coarse_solver(&self) -> Result<KspRef<'a>, PetscError> {
        let mut ksp: ffi::KSP = std::ptr::null_mut();
        // SAFETY: live PC; the KSP lives as long as its levels.
        check(
            unsafe { ffi::PCMGGetCoarseSolve(self.raw, &mut ksp) },
            "PCMGGetCoarseSolve",
        )?;
        Ok(unsafe { KspRef::lent(ksp) })
    }

    /// A multigrid's smoother of `level`, borrowed.
    pub fn mg_smoother(&self, level: usize) -> Result<KspRef<'a>, PetscError> {
        let mut ksp: ffi::KSP = std::ptr::null_mut();
        let level = to_int(level, "level")?;
        // SAFETY: live PC; the KSP lives as long as its levels.
        check(
            unsafe { ffi::PCMGGetSmoother(self.raw, level, &mut ksp) },
            "PCMGGetSmoother",
        )?;
        Ok(unsafe { KspRef::lent(ksp) })
    }

    /// A multigrid's residual vector of `level` (PETSc takes its own reference).
    pub fn set_mg_residual(&self, level: usize, r: VecRef<'_>) -> Result<(), PetscError> {
        let level = to_int(level, "level")?;
        // SAFETY: live handles.
        check(unsafe { ffi::PCMGSetR(self.raw, level, r.raw) }, "PCMGSetR")
    }

    /// The operator and preconditioning matrix, borrowed.
    pub fn operators(&self) -> Result<(MatRef<'a>, MatRef<'a>), PetscError> {
        let (mut a, mut p): (ffi::Mat, ffi::Mat) = (std::ptr::null_mut(), std::ptr::null_mut());
        // SAFETY: live PC; the matrices live while it holds them.
        check(
            unsafe { ffi::PCGetOperators(self.raw, &mut a, &mut p) },
            "PCGetOperators",
        )?;
        Ok(unsafe { (MatRef::lent(a), MatRef::lent(p)) })
    }

    /// The operator and preconditioning matrix (PETSc takes its own references).
    pub fn set_operators(&self, a: MatRef<'_>, p: MatRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(
            unsafe { ffi::PCSetOperators(self.raw, a.raw, p.raw) },
            "PCSetOperators",
        )
    }

    /// Collective.
    pub fn set_up(&self) -> Result<(), PetscError> {
        // SAFETY: live PC.
        check(unsafe { ffi::PCSetUp(self.raw) }, "PCSetUp")
    }

    /// Collective. x = M⁻¹ b.
    pub fn apply(&self, b: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(unsafe { ffi::PCApply(self.raw, b.raw, x.raw) }, "PCApply")
    }

    /// Collective. Frees what the set-up made.
    pub fn reset(&self) -> Result<(), PetscError> {
        // SAFETY: live PC.
        check(unsafe { ffi::PCReset(self.raw) }, "PCReset")
    }

    pub fn view(&self, viewer: ViewerRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles.
        check(unsafe { ffi::PCView(self.raw, viewer.raw) }, "PCView")
    }

    /// Whether the last set-up or application failed.
    pub fn failed(&self) -> Result<bool, PetscError> {
        let mut reason: ffi::PCFailedReason = ffi::PCFailedReason_PC_NOERROR;
        // SAFETY: live PC.
        check(
            unsafe { ffi::PCGetFailedReason(self.raw, &mut reason) },
            "PCGetFailedReason",
        )?;
        Ok(reason != ffi::PCFailedReason_PC_NOERROR)
    }

    /// Marks this PC failed through an inner one (`PC_SUBPC_ERROR`, which the outer Krylov
    /// method reports as DIVERGED_PC_FAILED).
    pub fn set_inner_failure(&self) -> Result<(), PetscError> {
        // SAFETY: live PC.
        check(
            unsafe { ffi::PCSetFailedReason(self.raw, ffi::PCFailedReason_PC_SUBPC_ERROR) },
            "PCSetFailedReason",
        )
    }
}

fn petsc_bool(b: bool) -> ffi::PetscBool {
    if b {
        ffi::PetscBool_PETSC_TRUE
    } else {
        ffi::PetscBool_PETSC_FALSE
    }
}
