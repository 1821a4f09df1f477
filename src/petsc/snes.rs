use super::error::{check, PetscError, PETSC_ERR_USER};
use super::ffi;
use super::init::cstring;
use super::ksp::KspRef;
use super::matrix::{to_int, Mat, MatRef};
use super::object::object;
use super::reason::{Divergence, KspDiverged, SnesDiverged, SolveFailure};
use super::vector::{PVec, VecRef};
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;
use std::ffi::c_void;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Why a callback could not evaluate.
#[derive(Debug, Clone)]
pub enum CallbackError {
    /// The trial state is outside the model's domain (e.g. an inverted element): SNES backtracks.
    Domain(String),
    /// Anything else: the solve stops with this message.
    Fatal(String),
}

/// The physics side of a Newton solve, in the style of PETSc's FormFunction/FormJacobian with a
/// context: SNES calls back into these with its current iterate.
pub trait NonlinearProblem {
    /// Collective. Residual F(x) into the owned entries of `f`.
    fn residual(&mut self, x: VecRef<'_>, f: VecRef<'_>) -> Result<(), CallbackError>;
    /// Collective. Consistent tangent dF/dx at `x` into `j` (assembled on return).
    fn jacobian(&mut self, x: VecRef<'_>, j: MatRef<'_>) -> Result<(), CallbackError>;
    /// Collective. What the linear solver takes from the Jacobian just assembled at `x`
    /// (its preconditioners' parts, set up before the linear solve): nothing by default.
    fn after_jacobian(&mut self, snes: SnesRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        let _ = (snes, x);
        Ok(())
    }
}

/// Newton's outcome.
#[derive(Debug, Clone, Copy, Default)]
pub struct SolveStats {
    pub newton_iterations: usize,
    pub linear_iterations: usize,
    pub residual_norm: f64,
}

/// A SNES we own; destroyed on drop.
pub struct Snes {
    raw: ffi::SNES,
}

/// A SNES borrowed for the length of one of its callbacks.
#[derive(Clone, Copy)]
pub struct SnesRef<'a> {
    raw: ffi::SNES,
    _owner: std::marker::PhantomData<&'a ()>,
}

/// A SNES's line search, borrowed.
#[derive(Clone, Copy)]
pub struct LineSearchRef<'a> {
    raw: ffi::SNESLineSearch,
    _owner: std::marker::PhantomData<&'a ()>,
}

object!(Snes, SnesRef<'_>, LineSearchRef<'_>);

struct Ctx<'a> {
    problem: &'a mut dyn NonlinearProblem,
    error: Option<String>,
    /// The last domain error's message: the divergence reports it (a UMAT's PNEWDT or NaN).
    domain: Option<String>,
}

/// Newton also stops when its update is this small relative to the solution: with a good
/// predictor the first residual is already small, and a residual tolerance relative to it alone
/// can lie below round-off.
const STEP_TOL: f64 = 1e-10;

impl Snes {
    /// Collective. Newton converged when the residual falls below `abstol` or by `rtol`, or
    /// its update below [`STEP_TOL`] of the solution, in at most `max_it` iterations. The
    /// direct solver (MUMPS LU) is robust for the indefinite saddle points of nearly
    /// incompressible soil and fast on 1-3 ranks, where SuperLU_dist stalled on 3
    /// oversubscribed ranks. MUMPS on several ranks sums contribution blocks in message-arrival
    /// order, so two identical multi-rank runs agree to round-off, not bit for bit;
    /// `-pc_factor_mat_solver_type superlu_dist` is bitwise reproducible on 2 ranks. Every
    /// choice is overridable by PETSc options on the command line ([`Snes::set_from_options`]).
    pub fn new(
        comm: &SimpleCommunicator,
        abstol: f64,
        rtol: f64,
        max_it: usize,
    ) -> Result<Snes, PetscError> {
        let mut raw: ffi::SNES = std::ptr::null_mut();
        // SAFETY: fresh handle, owned from the next line on.
        unsafe {
            check(ffi::SNESCreate(comm.as_raw(), &mut raw), "SNESCreate")?;
            let snes = Snes { raw };
            check(
                ffi::SNESSetTolerances(
                    raw,
                    abstol,
                    rtol,
                    STEP_TOL,
                    to_int(max_it, "solver.newton_max_it")?,
                    10_000,
                ),
                "SNESSetTolerances",
            )?;
            Ok(snes)
        }
    }

    /// The linear solver, borrowed.
    pub fn ksp(&self) -> Result<KspRef<'_>, PetscError> {
        // SAFETY: live SNES.
        unsafe { ksp_of(self.raw) }
    }

    /// Newton iterations one preconditioner serves (it is built afresh at the start of every
    /// Newton solve).
    pub fn set_lag_preconditioner(&self, lag: usize) -> Result<(), PetscError> {
        let lag = to_int(lag, "preconditioner lag")?;
        // SAFETY: live SNES.
        check(
            unsafe { ffi::SNESSetLagPreconditioner(self.raw, lag) },
            "SNESSetLagPreconditioner",
        )
    }

    /// Inexact Newton: each linear solve's tolerance by Eisenstat and Walker (PETSc's
    /// default version), at most `cap`.
    pub fn use_eisenstat_walker(&self, cap: f64) -> Result<(), PetscError> {
        let default = ffi::PETSC_DEFAULT as f64;
        // SAFETY: live SNES.
        unsafe {
            check(
                ffi::SNESKSPSetUseEW(self.raw, ffi::PetscBool_PETSC_TRUE),
                "SNESKSPSetUseEW",
            )?;
            check(
                ffi::SNESKSPSetParametersEW(
                    self.raw,
                    ffi::PETSC_DEFAULT as ffi::PetscInt,
                    default,
                    cap,
                    default,
                    default,
                    default,
                    default,
                ),
                "SNESKSPSetParametersEW",
            )
        }
    }

    /// The line search's type: full steps for elastic large rotations (the residual grows on
    /// the first iterate before the quadratic phase, and backtracking would crawl),
    /// backtracking for plastic flow (elastic-plastic switching overshoots).
    pub fn set_line_search(&self, kind: &str) -> Result<(), PetscError> {
        let mut ls: ffi::SNESLineSearch = std::ptr::null_mut();
        let kind = cstring(kind)?;
        // SAFETY: live SNES; its line search is borrowed.
        unsafe {
            check(
                ffi::SNESGetLineSearch(self.raw, &mut ls),
                "SNESGetLineSearch",
            )?;
            check(
                ffi::SNESLineSearchSetType(ls, kind.as_ptr()),
                "SNESLineSearchSetType",
            )
        }
    }

    /// Collective. Reads the command line's options, which override every choice made before.
    pub fn set_from_options(&self) -> Result<(), PetscError> {
        // SAFETY: live SNES.
        check(
            unsafe { ffi::SNESSetFromOptions(self.raw) },
            "SNESSetFromOptions",
        )
        .map_err(PetscError::naming_user_options)
    }

    /// Collective. Solves F(x) = 0 starting from `x`; `jac` holds the preallocated pattern.
    pub fn solve(
        &mut self,
        problem: &mut dyn NonlinearProblem,
        x: &PVec,
        jac: &Mat,
    ) -> Result<SolveStats, SolveFailure> {
        let r = x.duplicate()?;
        let mut ctx = Ctx {
            problem,
            error: None,
            domain: None,
        };
        let ctx_ptr = &mut ctx as *mut Ctx as *mut c_void;
        // SAFETY: ctx outlives SNESSolve, the only place the callbacks run; the callbacks catch
        // panics so none unwinds into C.
        let solved = unsafe {
            check(
                ffi::SNESSetFunction(self.raw, r.raw, Some(residual_cb), ctx_ptr),
                "SNESSetFunction",
            )?;
            check(
                ffi::SNESSetJacobian(self.raw, jac.raw, jac.raw, Some(jacobian_cb), ctx_ptr),
                "SNESSetJacobian",
            )?;
            check(
                ffi::SNESSolve(self.raw, std::ptr::null_mut(), x.raw),
                "SNESSolve",
            )
        };
        if let Some(msg) = ctx.error.take() {
            return Err(SolveFailure::Failed(PetscError {
                code: PETSC_ERR_USER,
                message: msg,
            }));
        }
        solved?;
        let mut reason: ffi::SNESConvergedReason = 0;
        let mut its: ffi::PetscInt = 0;
        let mut lits: ffi::PetscInt = 0;
        let mut norm = 0.0;
        // SAFETY: live SNES; the reason string is static in PETSc.
        unsafe {
            check(
                ffi::SNESGetConvergedReason(self.raw, &mut reason),
                "SNESGetConvergedReason",
            )?;
            check(
                ffi::SNESGetIterationNumber(self.raw, &mut its),
                "SNESGetIterationNumber",
            )?;
            check(
                ffi::SNESGetLinearSolveIterations(self.raw, &mut lits),
                "SNESGetLinearSolveIterations",
            )?;
            check(
                ffi::SNESGetFunctionNorm(self.raw, &mut norm),
                "SNESGetFunctionNorm",
            )?;
            let mut lambda = 1.0;
            if reason == ffi::SNESConvergedReason_SNES_CONVERGED_SNORM_RELATIVE {
                let mut ls: ffi::SNESLineSearch = std::ptr::null_mut();
                check(
                    ffi::SNESGetLineSearch(self.raw, &mut ls),
                    "SNESGetLineSearch",
                )?;
                check(
                    ffi::SNESLineSearchGetLambda(ls, &mut lambda),
                    "SNESLineSearchGetLambda",
                )?;
            }
            // A tiny update is convergence only when the line search took (about) the whole
            // Newton step; a strongly damped step is tiny because Newton is stuck, whatever the
            // residual.
            let (iterations, residual) = (its.max(0) as usize, norm);
            let linear_iterations = lits.max(0) as usize;
            if lambda < 0.5 {
                return Err(SolveFailure::Diverged(Divergence::Stalled {
                    lambda,
                    step_tol: STEP_TOL,
                    iterations,
                    linear_iterations,
                    residual,
                }));
            }
            if let Some(reason) = SnesDiverged::from_raw(reason) {
                let mut linear = None;
                if reason == SnesDiverged::LinearSolve {
                    let mut ksp: ffi::KSP = std::ptr::null_mut();
                    check(ffi::SNESGetKSP(self.raw, &mut ksp), "SNESGetKSP")?;
                    let mut kr: ffi::KSPConvergedReason = 0;
                    check(
                        ffi::KSPGetConvergedReason(ksp, &mut kr),
                        "KSPGetConvergedReason",
                    )?;
                    linear = KspDiverged::from_raw(kr);
                }
                let domain = match reason {
                    SnesDiverged::FunctionDomain => ctx.domain.take(),
                    _ => None,
                };
                return Err(SolveFailure::Diverged(Divergence::Snes {
                    reason,
                    linear,
                    iterations,
                    linear_iterations,
                    residual,
                    domain,
                }));
            }
        }
        Ok(SolveStats {
            newton_iterations: its.max(0) as usize,
            linear_iterations: lits.max(0) as usize,
            residual_norm: norm,
        })
    }
}

impl Snes {
    /// Collective. Frees what the last solve set up (work vectors, the preconditioner's
    /// hierarchy and the Krylov method's vectors), keeping the configuration; the next solve
    /// sets up again.
    pub fn reset(&mut self) -> Result<(), PetscError> {
        // SAFETY: live SNES we own; the matrices and vectors it referenced stay ours.
        check(unsafe { ffi::SNESReset(self.raw) }, "SNESReset")
    }
}

impl Drop for Snes {
    fn drop(&mut self) {
        // SAFETY: we own the SNES.
        unsafe {
            ffi::SNESDestroy(&mut self.raw);
        }
    }
}

fn report(
    snes: ffi::SNES,
    ctx: &mut Ctx,
    outcome: std::thread::Result<Result<(), CallbackError>>,
) -> ffi::PetscErrorCode {
    match outcome {
        Ok(Ok(())) => 0,
        Ok(Err(CallbackError::Domain(msg))) => {
            ctx_note(ctx, None, &msg);
            ctx.domain = Some(msg);
            // SAFETY: live SNES inside its own callback.
            unsafe { ffi::SNESSetFunctionDomainError(snes) }
        }
        Ok(Err(CallbackError::Fatal(msg))) => {
            ctx_note(ctx, Some(()), &msg);
            PETSC_ERR_USER
        }
        Err(_) => {
            ctx_note(
                ctx,
                Some(()),
                "internal error: a panic in the residual or Jacobian",
            );
            PETSC_ERR_USER
        }
    }
}

fn ctx_note(ctx: &mut Ctx, fatal: Option<()>, msg: &str) {
    if fatal.is_some() && ctx.error.is_none() {
        ctx.error = Some(msg.to_string());
    }
}

unsafe extern "C" fn residual_cb(
    snes: ffi::SNES,
    x: ffi::Vec,
    f: ffi::Vec,
    ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    // SAFETY: ctx is the `Ctx` that `Snes::solve` keeps alive during SNESSolve.
    let ctx = unsafe { &mut *(ctx as *mut Ctx) };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: PETSc keeps x and f alive during the callback, and the borrows end with it.
        let (x, f) = unsafe { (VecRef::lent(x), VecRef::lent(f)) };
        ctx.problem.residual(x, f)
    }));
    report(snes, ctx, outcome)
}

unsafe extern "C" fn jacobian_cb(
    snes: ffi::SNES,
    x: ffi::Vec,
    j: ffi::Mat,
    _p: ffi::Mat,
    ctx: *mut c_void,
) -> ffi::PetscErrorCode {
    // SAFETY: as in `residual_cb`.
    let ctx = unsafe { &mut *(ctx as *mut Ctx) };
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: as for the residual.
        let (x, j) = unsafe { (VecRef::lent(x), MatRef::lent(j)) };
        ctx.problem.jacobian(x, j)
    }));
    let code = report(snes, ctx, outcome);
    if code != 0 {
        return code;
    }
    let after = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: PETSc keeps x alive during the callback.
        // SAFETY: PETSc keeps the SNES alive during its callback.
        let snes = unsafe { SnesRef::lent(snes) };
        ctx.problem.after_jacobian(snes, unsafe { VecRef::lent(x) })
    }));
    let message = match after {
        Ok(Ok(())) => return 0,
        Ok(Err(e)) => e.to_string(),
        Err(_) => "internal error: a panic after the Jacobian".to_string(),
    };
    ctx_note(ctx, Some(()), &message);
    PETSC_ERR_USER
}

/// The KSP of `snes`, borrowed.
///
/// # Safety
/// `snes` must be live for `'a`.
unsafe fn ksp_of<'a>(snes: ffi::SNES) -> Result<KspRef<'a>, PetscError> {
    let mut ksp: ffi::KSP = std::ptr::null_mut();
    // SAFETY: as the caller promises; the KSP lives as long as the SNES.
    unsafe {
        check(ffi::SNESGetKSP(snes, &mut ksp), "SNESGetKSP")?;
        Ok(KspRef::lent(ksp))
    }
}

impl<'a> SnesRef<'a> {
    /// # Safety
    /// `raw` must be a live SNES for as long as the returned borrow is used.
    unsafe fn lent(raw: ffi::SNES) -> SnesRef<'a> {
        SnesRef {
            raw,
            _owner: std::marker::PhantomData,
        }
    }

    /// The linear solver, borrowed.
    pub fn ksp(&self) -> Result<KspRef<'a>, PetscError> {
        // SAFETY: live SNES.
        unsafe { ksp_of(self.raw) }
    }

    /// The norm of the residual at the current iterate.
    pub fn function_norm(&self) -> Result<f64, PetscError> {
        let mut norm = 0.0;
        // SAFETY: live SNES.
        check(
            unsafe { ffi::SNESGetFunctionNorm(self.raw, &mut norm) },
            "SNESGetFunctionNorm",
        )?;
        Ok(norm)
    }

    /// Whether the next linear solve keeps the last preconditioner or builds one from the
    /// new Jacobian. SNES reads the preconditioner lag after the Jacobian callback: −2
    /// rebuilds once, −1 keeps.
    pub fn keep_preconditioner(&self, keep: bool) -> Result<(), PetscError> {
        // SAFETY: live SNES.
        check(
            unsafe { ffi::SNESSetLagPreconditioner(self.raw, if keep { -1 } else { -2 }) },
            "SNESSetLagPreconditioner",
        )
    }

    /// The line search, borrowed.
    pub fn line_search(&self) -> Result<LineSearchRef<'a>, PetscError> {
        let mut ls: ffi::SNESLineSearch = std::ptr::null_mut();
        // SAFETY: live SNES; the line search lives as long as it.
        check(
            unsafe { ffi::SNESGetLineSearch(self.raw, &mut ls) },
            "SNESGetLineSearch",
        )?;
        Ok(LineSearchRef {
            raw: ls,
            _owner: std::marker::PhantomData,
        })
    }
}

impl LineSearchRef<'_> {
    /// Whether the line search has its work vectors (the trial point and its residual).
    pub fn has_work_vectors(&self) -> Result<bool, PetscError> {
        let mut w: ffi::Vec = std::ptr::null_mut();
        // SAFETY: live line search; the vector is only looked at.
        check(
            unsafe {
                ffi::SNESLineSearchGetVecs(
                    self.raw,
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    &mut w,
                    std::ptr::null_mut(),
                )
            },
            "SNESLineSearchGetVecs",
        )?;
        Ok(!w.is_null())
    }

    /// Gives the line search its work vectors: the trial point `w` and its residual `g`
    /// (the same vector may serve both). The line search takes no reference but destroys both
    /// on reset, so it is given one for each here.
    pub fn set_work_vectors(&self, w: VecRef<'_>, g: VecRef<'_>) -> Result<(), PetscError> {
        // SAFETY: live handles; the references taken are the line search's.
        unsafe {
            for v in [w, g] {
                check(
                    ffi::PetscObjectReference(v.raw as ffi::PetscObject),
                    "PetscObjectReference",
                )?;
            }
            check(
                ffi::SNESLineSearchSetVecs(
                    self.raw,
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    std::ptr::null_mut(),
                    w.raw,
                    g.raw,
                ),
                "SNESLineSearchSetVecs",
            )
        }
    }
}
