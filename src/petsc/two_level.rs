//! The p-multigrid's V-cycle as one preconditioner (PCSHELL): a damped Jacobi sweep on the P2
//! level before and after a coarse correction through the P1 → P2 interpolation. It is the
//! cycle PCMG runs with a Richardson–Jacobi smoother of one sweep, step for step (the same
//! products with the tangent, the same history bit for bit), without PCMG's price in vectors
//! of the fine level: PCMG keeps a residual, the Richardson smoother two work vectors and
//! Jacobi its diagonal. Here the diagonal's inverse and one residual (which the full-step line
//! search borrows between applications) are all.

use super::error::{check, PetscError};
use super::ffi;
use super::vector::VecRef;

/// What messages call it.
const WHAT: &str = "two-level p-multigrid";
/// The shell's name, which tells the cycle from our other shells.
const NAME: &str = "p-multigrid (P2 Richardson-Jacobi, P1 coarse solver)";

/// What the shell keeps. Every handle is its own reference, released on destroy.
struct TwoLevel {
    interpolation: ffi::Mat,
    coarse: ffi::KSP,
    /// The inverse of the tangent's diagonal (made at the first set-up).
    inverse_diagonal: ffi::Vec,
    /// The fine residual (lent to the line search; made at the first set-up if not given).
    residual: ffi::Vec,
    coarse_rhs: ffi::Vec,
    coarse_solution: ffi::Vec,
    /// Richardson's damping ω of the Jacobi sweeps.
    damping: f64,
}

impl TwoLevel {
    /// The vectors the set-ups make (null until then).
    fn vectors(&mut self) -> [&mut ffi::Vec; 4] {
        [
            &mut self.inverse_diagonal,
            &mut self.residual,
            &mut self.coarse_rhs,
            &mut self.coarse_solution,
        ]
    }
}

/// Collective. Makes `pc` the two-level cycle with `interpolation` (P1 → P2, referenced) and
/// the coarse solver `coarse` (taken over: destroyed with the preconditioner).
///
/// # Safety
/// `pc`, `interpolation` and `coarse` must be live PETSc objects.
pub(super) unsafe fn set(
    pc: ffi::PC,
    interpolation: ffi::Mat,
    coarse: ffi::KSP,
) -> Result<(), PetscError> {
    // SAFETY: the caller's objects are live; the cycle holds a reference to each, which
    // `make_shell` hands to the preconditioner (or releases if it cannot).
    unsafe {
        if let Err(e) = check(
            ffi::PetscObjectReference(interpolation as ffi::PetscObject),
            "PetscObjectReference(interpolation)",
        ) {
            let mut coarse = coarse;
            ffi::KSPDestroy(&mut coarse);
            return Err(e);
        }
        let cycle = TwoLevel {
            interpolation,
            coarse,
            inverse_diagonal: std::ptr::null_mut(),
            residual: std::ptr::null_mut(),
            coarse_rhs: std::ptr::null_mut(),
            coarse_solution: std::ptr::null_mut(),
            damping: 1.0,
        };
        super::shell::make_shell(pc, cycle, NAME, release, OPS).map(|_| ())
    }
}

/// The cycle's callbacks.
const OPS: super::shell::ShellOps = super::shell::ShellOps {
    setup: setup_cb,
    apply: apply_cb,
    view: view_cb,
    destroy: destroy_cb,
};

/// The cycle behind `pc`, if `pc` is one.
///
/// # Safety
/// `pc` must be live; the borrow must end before the preconditioner is destroyed.
unsafe fn context<'a>(pc: ffi::PC) -> Result<Option<&'a mut TwoLevel>, PetscError> {
    // SAFETY: live PC; a shell named NAME is only ever made by `set`.
    Ok(unsafe { super::shell_context(pc, NAME) }?
        .map(|raw| unsafe { &mut *(raw as *mut TwoLevel) }))
}

/// Whether `pc` is the two-level cycle.
///
/// # Safety
/// `pc` must be live.
pub(super) unsafe fn is_two_level(pc: ffi::PC) -> Result<bool, PetscError> {
    // SAFETY: the caller's PC is live.
    Ok(unsafe { context(pc) }?.is_some())
}

/// The coarse solver of the cycle `pc`.
///
/// # Safety
/// `pc` must be a live two-level cycle; the KSP is borrowed from it.
pub(super) unsafe fn coarse_solver(pc: ffi::PC) -> Result<ffi::KSP, PetscError> {
    // SAFETY: as the caller promises.
    match unsafe { context(pc) }? {
        Some(c) => Ok(c.coarse),
        None => Err(super::shell::not_shell(WHAT)),
    }
}

/// Sets the damping of the cycle's Jacobi sweeps.
///
/// # Safety
/// `pc` must be a live two-level cycle.
pub(super) unsafe fn set_damping(pc: ffi::PC, damping: f64) -> Result<(), PetscError> {
    // SAFETY: as the caller promises.
    match unsafe { context(pc) }? {
        Some(c) => {
            c.damping = damping;
            Ok(())
        }
        None => Err(super::shell::not_shell(WHAT)),
    }
}

/// Gives the cycle its fine residual vector (referenced), before its first set-up.
///
/// # Safety
/// `pc` must be a live two-level cycle and `residual` a live vector of the fine layout.
pub(super) unsafe fn set_residual(pc: ffi::PC, residual: ffi::Vec) -> Result<(), PetscError> {
    // SAFETY: as the caller promises.
    unsafe {
        match context(pc)? {
            Some(c) => {
                check(
                    ffi::PetscObjectReference(residual as ffi::PetscObject),
                    "PetscObjectReference(residual)",
                )?;
                ffi::VecDestroy(&mut c.residual);
                c.residual = residual;
                Ok(())
            }
            None => Err(super::shell::not_shell(WHAT)),
        }
    }
}

/// Collective. Frees what the set-ups made (the coarse solver's hierarchy and the cycle's
/// vectors), keeping the configuration: PCSHELL has no reset of its own, and `SNESReset` is
/// how an increment's solver hands its memory back before the converged state's pass.
///
/// # Safety
/// `pc` must be live.
pub(super) unsafe fn reset(pc: ffi::PC) -> Result<(), PetscError> {
    // SAFETY: as the caller promises; destroying a null vector is a no-op.
    unsafe {
        if let Some(c) = context(pc)? {
            // KSPReset also drops the operator, which the next increment's set-up needs.
            let mut operator = coarse_operator(c.coarse)?;
            check(
                ffi::PetscObjectReference(operator as ffi::PetscObject),
                "PetscObjectReference(coarse operator)",
            )?;
            let reset = check(ffi::KSPReset(c.coarse), "KSPReset(coarse)").and_then(|()| {
                check(
                    ffi::KSPSetOperators(c.coarse, operator, operator),
                    "KSPSetOperators(coarse)",
                )
            });
            ffi::MatDestroy(&mut operator);
            reset?;
            for v in c.vectors() {
                check(ffi::VecDestroy(v), "VecDestroy")?;
            }
        }
    }
    Ok(())
}

/// Drops every reference the cycle holds.
///
/// # Safety
/// The handles must be the cycle's own references (or null).
unsafe fn release(mut c: TwoLevel) {
    // SAFETY: as the caller promises; destroying a null handle is a no-op in PETSc.
    unsafe {
        ffi::MatDestroy(&mut c.interpolation);
        ffi::KSPDestroy(&mut c.coarse);
        for v in c.vectors() {
            ffi::VecDestroy(v);
        }
    }
}

/// Runs `f` on the cycle behind `pc`; an error or panic is printed on this rank and becomes
/// PETSc's user-error code.
unsafe fn with_cycle(
    pc: ffi::PC,
    f: impl FnOnce(&mut TwoLevel) -> Result<(), PetscError>,
) -> ffi::PetscErrorCode {
    // SAFETY: PETSc calls back with the live shell `set` made.
    unsafe { super::shell::with_shell(pc, NAME, WHAT, f) }
}

/// The operator of the coarse solver `coarse`, borrowed from it.
///
/// # Safety
/// `coarse` must be live.
pub(super) unsafe fn coarse_operator(coarse: ffi::KSP) -> Result<ffi::Mat, PetscError> {
    let mut operator: ffi::Mat = std::ptr::null_mut();
    // SAFETY: as the caller promises.
    check(
        unsafe { ffi::KSPGetOperators(coarse, &mut operator, std::ptr::null_mut()) },
        "KSPGetOperators(coarse)",
    )?;
    Ok(operator)
}

/// The fine operator (PETSc's preconditioning matrix) of `pc`.
unsafe fn fine_operator(pc: ffi::PC) -> Result<ffi::Mat, PetscError> {
    let mut pmat: ffi::Mat = std::ptr::null_mut();
    // SAFETY: live PC inside its own callback.
    check(
        unsafe { ffi::PCGetOperators(pc, std::ptr::null_mut(), &mut pmat) },
        "PCGetOperators",
    )?;
    Ok(pmat)
}

/// Collective. A new tangent: its diagonal is inverted (as PCJACOBI does) and the coarse
/// solver set up for the new coarse operator.
unsafe extern "C" fn setup_cb(pc: ffi::PC) -> ffi::PetscErrorCode {
    // SAFETY: the operators and vectors are live while the preconditioner is.
    unsafe {
        with_cycle(pc, |c| {
            let a = fine_operator(pc)?;
            if c.inverse_diagonal.is_null() {
                check(
                    ffi::MatCreateVecs(a, &mut c.inverse_diagonal, std::ptr::null_mut()),
                    "MatCreateVecs",
                )?;
            }
            if c.residual.is_null() {
                check(
                    ffi::VecDuplicate(c.inverse_diagonal, &mut c.residual),
                    "VecDuplicate",
                )?;
            }
            check(ffi::MatGetDiagonal(a, c.inverse_diagonal), "MatGetDiagonal")?;
            check(ffi::VecReciprocal(c.inverse_diagonal), "VecReciprocal")?;
            // As PCJACOBI: a zero diagonal entry (left zero by the reciprocal) counts as one.
            VecRef::lent(c.inverse_diagonal).write(|d| {
                for v in d.iter_mut().filter(|v| **v == 0.0) {
                    *v = 1.0;
                }
            })?;
            if c.coarse_rhs.is_null() {
                check(
                    ffi::MatCreateVecs(
                        coarse_operator(c.coarse)?,
                        &mut c.coarse_solution,
                        &mut c.coarse_rhs,
                    ),
                    "MatCreateVecs(coarse)",
                )?;
            }
            check(ffi::KSPSetUp(c.coarse), "KSPSetUp(coarse)")
        })
    }
}

/// Collective. x = V-cycle(b): a damped Jacobi sweep from zero, the coarse correction of its
/// residual, a second sweep. The same operations, in the same order, as PCMG's multiplicative
/// cycle with a one-sweep Richardson–Jacobi smoother.
unsafe extern "C" fn apply_cb(pc: ffi::PC, b: ffi::Vec, x: ffi::Vec) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps b and x alive during the callback; the cycle's own vectors are live.
    unsafe {
        with_cycle(pc, |c| {
            let a = fine_operator(pc)?;
            let (d, r, w) = (c.inverse_diagonal, c.residual, c.damping);
            // Pre-sweep from x = 0: x = ω D⁻¹ b.
            check(ffi::VecPointwiseMult(x, d, b), "VecPointwiseMult")?;
            check(ffi::VecScale(x, w), "VecScale")?;
            // Coarse correction of r = b − A x.
            check(ffi::MatMult(a, x, r), "MatMult")?;
            check(ffi::VecAYPX(r, -1.0, b), "VecAYPX")?;
            check(
                ffi::MatMultTranspose(c.interpolation, r, c.coarse_rhs),
                "MatMultTranspose(interpolation)",
            )?;
            check(
                ffi::KSPSolve(c.coarse, c.coarse_rhs, c.coarse_solution),
                "KSPSolve(coarse)",
            )?;
            // A failed coarse solve fails the preconditioner as PCMG reports it: the solution
            // is marked (Inf) and the outer Krylov method stops with DIVERGED_PC_FAILED.
            check(
                ffi::KSPCheckSolve(c.coarse, pc, c.coarse_solution),
                "KSPCheckSolve(coarse)",
            )?;
            check(
                ffi::MatMultAdd(c.interpolation, c.coarse_solution, x, x),
                "MatMultAdd(interpolation)",
            )?;
            // Post-sweep: x = x + ω D⁻¹ (b − A x).
            check(ffi::MatMult(a, x, r), "MatMult")?;
            check(ffi::VecAYPX(r, -1.0, b), "VecAYPX")?;
            check(ffi::VecPointwiseMult(r, d, r), "VecPointwiseMult")?;
            check(ffi::VecAXPY(x, w, r), "VecAXPY")
        })
    }
}

unsafe extern "C" fn view_cb(pc: ffi::PC, viewer: ffi::PetscViewer) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps the viewer alive during the callback; the coarse solver is live.
    unsafe {
        with_cycle(pc, |c| {
            let lines = [
                format!(
                    "fine level (P2): one Richardson-Jacobi sweep before and after, damping \
                     factor={}",
                    c.damping
                ),
                "coarse level (P1):".to_string(),
            ];
            super::shell::view_nested(viewer, &lines, || {
                check(ffi::KSPView(c.coarse, viewer), "KSPView(coarse)")
            })
        })
    }
}

unsafe extern "C" fn destroy_cb(pc: ffi::PC) -> ffi::PetscErrorCode {
    // SAFETY: the context is the Box `set` leaked.
    unsafe { super::shell::reclaim::<TwoLevel>(pc, release) }
}
