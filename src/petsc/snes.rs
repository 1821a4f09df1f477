use super::error::{check, PetscError, PETSC_ERR_USER};
use super::ffi;
use super::init::cstring;
use super::linear::{bool_option, FactorReuse, LinearSolver};
use super::matrix::{to_int, Mat, MatRef};
use super::reason::{Divergence, KspDiverged, SnesDiverged, SolveFailure};
use super::two_level;
use super::vector::{PVec, VecRef};
use super::yield_zone;
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
    /// The Richardson damping of one Jacobi sweep on the last Jacobian, the same on every
    /// rank, where the problem knows a bound on its spectrum: the p-multigrid's smoother
    /// ([`LinearSolver::damps_jacobi_smoother`]) then needs no eigenvalue estimate.
    fn smoother_damping(&self) -> Option<f64> {
        None
    }
    /// The global displacement dofs of the triangles whose tangent has yielded at the last
    /// Jacobian (this rank's triangles; repeats allowed), for the linear solver's yield zone
    /// ([`super::yield_zone`]). Asked once after every Jacobian where the zone is in use.
    fn yielded_dofs(&mut self) -> Vec<usize> {
        Vec::new()
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
    reuse: Option<FactorReuse>,
    /// The p-multigrid's fine smoother takes its damping from each Jacobian's spectral bound
    /// ([`LinearSolver::damps_jacobi_smoother`]).
    damped_smoother: bool,
    /// The p-multigrid's coarse solver is set up from the first Jacobian of a solve
    /// ([`set_up_coarse_solver`]).
    coarse_first: bool,
}

struct Ctx<'a> {
    problem: &'a mut dyn NonlinearProblem,
    error: Option<String>,
    /// The last domain error's message: the divergence reports it (a UMAT's PNEWDT or NaN).
    domain: Option<String>,
    reuse: Option<FactorReuse>,
    /// The residual norm at the last Jacobian of this solve.
    last_norm: Option<f64>,
    damped_smoother: bool,
    /// Set up the p-multigrid's coarse solver at the next Jacobian (the first of the solve).
    coarse_first: bool,
}

/// Collective. Hands the problem's yielded dofs to the yield zone (the field split's or the
/// whole system's), if the linear solver has one.
fn update_yield_zone(snes: ffi::SNES, x: VecRef<'_>, ctx: &mut Ctx) -> Result<(), PetscError> {
    // SAFETY: the SNES is live during its callback; its PCs are borrowed from it.
    unsafe {
        let pc = preconditioner(snes)?;
        if let Some(block) = yield_zone::find(pc)? {
            let dofs = ctx.problem.yielded_dofs();
            yield_zone::set_zone(block, x, &dofs)?;
        }
    }
    Ok(())
}

/// Newton also stops when its update is this small relative to the solution: with a good
/// predictor the first residual is already small, and a residual tolerance relative to it alone
/// can lie below round-off.
const STEP_TOL: f64 = 1e-10;

impl Snes {
    /// Collective. Newton with the caller's line search and linear solver. The direct solver
    /// (MUMPS LU) is robust for the indefinite saddle points of nearly incompressible soil and
    /// fast on 1-3 ranks, where SuperLU_dist stalled on 3 oversubscribed ranks. MUMPS on several
    /// ranks sums contribution blocks in message-arrival order, so two identical multi-rank runs
    /// agree to round-off, not bit for bit; `-pc_factor_mat_solver_type superlu_dist` is bitwise
    /// reproducible on 2 ranks. Every choice is overridable by PETSc options on the command line.
    pub fn new(
        comm: &SimpleCommunicator,
        abstol: f64,
        rtol: f64,
        max_it: usize,
        line_search: &str,
        linear: &LinearSolver,
    ) -> Result<Snes, PetscError> {
        let mut raw: ffi::SNES = std::ptr::null_mut();
        // SAFETY: fresh handle; KSP/PC are borrowed from the SNES and not destroyed by us.
        unsafe {
            check(ffi::SNESCreate(comm.as_raw(), &mut raw), "SNESCreate")?;
            let reuse = match linear {
                LinearSolver::Direct { reuse, .. } => *reuse,
                _ => None,
            };
            let snes = Snes {
                raw,
                reuse,
                damped_smoother: linear.damps_jacobi_smoother()?,
                coarse_first: matches!(linear, LinearSolver::PMultigrid { .. }),
            };
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
            let mut ksp: ffi::KSP = std::ptr::null_mut();
            check(ffi::SNESGetKSP(raw, &mut ksp), "SNESGetKSP")?;
            linear.configure(ksp)?;
            check(
                ffi::SNESSetLagPreconditioner(
                    raw,
                    to_int(linear.preconditioner_lag(), "preconditioner lag")?,
                ),
                "SNESSetLagPreconditioner",
            )?;
            if let Some(cap) = linear.inexact_newton_cap() {
                let default = ffi::PETSC_DEFAULT as f64;
                check(
                    ffi::SNESKSPSetUseEW(raw, ffi::PetscBool_PETSC_TRUE),
                    "SNESKSPSetUseEW",
                )?;
                check(
                    ffi::SNESKSPSetParametersEW(
                        raw,
                        ffi::PETSC_DEFAULT as ffi::PetscInt,
                        default,
                        cap,
                        default,
                        default,
                        default,
                        default,
                    ),
                    "SNESKSPSetParametersEW",
                )?;
            }
            // The caller's line search: full steps for elastic large rotations (the residual grows
            // on the first iterate before the quadratic phase, and backtracking would crawl),
            // backtracking for plastic flow (elastic-plastic switching overshoots).
            let mut ls: ffi::SNESLineSearch = std::ptr::null_mut();
            check(ffi::SNESGetLineSearch(raw, &mut ls), "SNESGetLineSearch")?;
            let kind = cstring(line_search)?;
            check(
                ffi::SNESLineSearchSetType(ls, kind.as_ptr()),
                "SNESLineSearchSetType",
            )?;
            check(ffi::SNESSetFromOptions(raw), "SNESSetFromOptions")
                .map_err(PetscError::naming_user_options)?;
            Ok(snes)
        }
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
            reuse: self.reuse,
            last_norm: None,
            damped_smoother: self.damped_smoother,
            coarse_first: self.coarse_first,
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
            if lambda < 0.5 {
                return Err(SolveFailure::Diverged(Divergence::Stalled {
                    lambda,
                    step_tol: STEP_TOL,
                    iterations,
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
    /// Whether the p-multigrid's fine smoother takes its damping from each Jacobian
    /// ([`NonlinearProblem::smoother_damping`]): the problem must then give one.
    pub fn damps_smoother(&self) -> bool {
        self.damped_smoother
    }

    /// Collective. Frees what the last solve set up (work vectors, the preconditioner's
    /// hierarchy and the Krylov method's vectors), keeping the configuration; the next solve
    /// sets up again. The end of an increment's solver: the p-multigrid's coarse operator lost
    /// its rigid-body modes after GAMG's first aggregation, so a solve after a reset would
    /// aggregate without them, and the field split drops its splits (and with them the
    /// displacement block's yield zone); each increment makes its iterative solver afresh.
    pub fn reset(&mut self) -> Result<(), PetscError> {
        // SAFETY: live SNES we own; its PC is borrowed from it; the matrices and vectors it
        // referenced stay owned by us. The two-level cycle has no reset of its own.
        unsafe {
            let pc = preconditioner(self.raw)?;
            two_level::reset(pc)?;
            if let Some(block) = yield_zone::find(pc)? {
                yield_zone::reset(block)?;
            }
            check(ffi::SNESReset(self.raw), "SNESReset")
        }
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
        after_jacobian(snes, unsafe { VecRef::lent(x) }, ctx)
    }));
    let message = match after {
        Ok(Ok(())) => return 0,
        Ok(Err(e)) => e.to_string(),
        Err(_) => "internal error: a panic after the Jacobian".to_string(),
    };
    ctx_note(ctx, Some(()), &message);
    PETSC_ERR_USER
}

/// Collective. What the linear solver takes from a new Jacobian at `x`: the p-multigrid's
/// smoother damping, the yield zone, the coarse solver's first set-up, and whether a kept
/// factorisation is refreshed.
fn after_jacobian(snes: ffi::SNES, x: VecRef<'_>, ctx: &mut Ctx) -> Result<(), PetscError> {
    if ctx.damped_smoother {
        let damping = ctx.problem.smoother_damping().ok_or_else(|| PetscError {
            code: PETSC_ERR_USER,
            message: "the p-multigrid's Jacobi smoother has no damping: this Jacobian gave no \
                      finite bound on its spectrum (an element tangent with a negative or zero \
                      diagonal, or not a number)"
                .into(),
        })?;
        damp_smoother(snes, damping)?;
    }
    update_yield_zone(snes, x, ctx)?;
    if ctx.coarse_first {
        ctx.coarse_first = false;
        set_up_coarse_solver(snes)?;
        share_work_vector(snes, x)?;
    }
    if let Some(reuse) = ctx.reuse {
        choose_factorisation(snes, &reuse, &mut ctx.last_norm)?;
    }
    Ok(())
}

/// The preconditioner of `snes`'s linear solver, borrowed from it.
///
/// # Safety
/// `snes` must be live; the PC must not outlive it.
unsafe fn preconditioner(snes: ffi::SNES) -> Result<ffi::PC, PetscError> {
    let mut ksp: ffi::KSP = std::ptr::null_mut();
    let mut pc: ffi::PC = std::ptr::null_mut();
    // SAFETY: as the caller promises.
    unsafe {
        check(ffi::SNESGetKSP(snes, &mut ksp), "SNESGetKSP")?;
        check(ffi::KSPGetPC(ksp, &mut pc), "KSPGetPC")?;
    }
    Ok(pc)
}

/// Sets the Richardson damping of the p-multigrid's fine smoother (level 1) for the next
/// linear solve.
fn damp_smoother(snes: ffi::SNES, damping: f64) -> Result<(), PetscError> {
    let mut smoother: ffi::KSP = std::ptr::null_mut();
    // SAFETY: the SNES is live during its callback; PC and smoother are borrowed from it.
    unsafe {
        let pc = preconditioner(snes)?;
        if two_level::is_two_level(pc)? {
            return two_level::set_damping(pc, damping);
        }
        check(
            ffi::PCMGGetSmoother(pc, 1, &mut smoother),
            "PCMGGetSmoother",
        )?;
        check(
            ffi::KSPRichardsonSetScale(smoother, damping),
            "KSPRichardsonSetScale",
        )
    }
}

/// Collective. One vector of the fine level serves as the p-multigrid's residual and as
/// the full-step line search's trial point, instead of three. The multigrid's residual is
/// written and read only inside a preconditioner application, the trial point only inside
/// the line search, which follows the linear solve; the full step never touches its
/// second vector (the trial residual: it evaluates into the residual itself). Any other
/// line search keeps its own pair. Measured: two vectors of the fine level fewer at the
/// memory peak.
fn share_work_vector(snes: ffi::SNES, x: VecRef<'_>) -> Result<(), PetscError> {
    let mut ls: ffi::SNESLineSearch = std::ptr::null_mut();
    // SAFETY: the SNES is live during its callback; its line search is borrowed.
    let basic = unsafe {
        check(ffi::SNESGetLineSearch(snes, &mut ls), "SNESGetLineSearch")?;
        super::has_type(ls as ffi::PetscObject, "basic")?
    };
    if !basic {
        return Ok(());
    }
    // Once per set-up: a later solve on the same SNES (a retried or cut increment on the same pattern) finds the line
    // search's vectors in place.
    let mut w: ffi::Vec = std::ptr::null_mut();
    // SAFETY: as above; the vectors are only looked at.
    unsafe {
        check(
            ffi::SNESLineSearchGetVecs(
                ls,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                &mut w,
                std::ptr::null_mut(),
            ),
            "SNESLineSearchGetVecs",
        )?;
    }
    if !w.is_null() {
        return Ok(());
    }
    // SAFETY: live SNES; its PC is borrowed from it. The multigrid takes its own reference to
    // the vector; the line search takes none but destroys both of its vectors on reset, so it
    // is given one reference for each. Ours goes with `shared`.
    unsafe {
        let pc = preconditioner(snes)?;
        let own_cycle = two_level::is_two_level(pc)?;
        if !own_cycle {
            // Level 1 is the fine level only in the two-level hierarchy we build.
            let mut levels: ffi::PetscInt = 0;
            check(ffi::PCMGGetLevels(pc, &mut levels), "PCMGGetLevels")?;
            if levels != 2 {
                return Ok(());
            }
        }
        let shared = x.duplicate()?;
        if own_cycle {
            two_level::set_residual(pc, shared.raw)?;
        } else {
            check(ffi::PCMGSetR(pc, 1, shared.raw), "PCMGSetR")?;
        }
        for _ in 0..2 {
            check(
                ffi::PetscObjectReference(shared.raw as ffi::PetscObject),
                "PetscObjectReference",
            )?;
        }
        check(
            ffi::SNESLineSearchSetVecs(
                ls,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                shared.raw,
                shared.raw,
            ),
            "SNESLineSearchSetVecs",
        )
    }
}

/// Collective. Sets up the p-multigrid's coarse solver (GAMG on the coarse operator the
/// Jacobian has just assembled) before the Krylov method, the multigrid and its fine smoother
/// allocate their vectors of the fine level: GAMG's first aggregation of a solve is the memory
/// peak of the iterative path, and those six vectors need not sit under it. The outer set-up
/// that follows finds the coarse solver set up for this operator and leaves it.
fn set_up_coarse_solver(snes: ffi::SNES) -> Result<(), PetscError> {
    let mut coarse: ffi::KSP = std::ptr::null_mut();
    // SAFETY: the SNES is live during its callback; PC and coarse KSP are borrowed from it.
    unsafe {
        let pc = preconditioner(snes)?;
        if two_level::is_two_level(pc)? {
            coarse = two_level::coarse_solver(pc)?;
        } else {
            check(
                ffi::PCMGGetCoarseSolve(pc, &mut coarse),
                "PCMGGetCoarseSolve",
            )?;
        }
        // Its options are read first, as the multigrid's own set-up would read them.
        check(ffi::KSPSetFromOptions(coarse), "KSPSetFromOptions(coarse)")?;
        check(ffi::KSPSetUp(coarse), "KSPSetUp(coarse)")?;
        // GAMG has aggregated with the rigid-body modes. With its interpolation reused, the
        // set-ups of the later Newton iterations only redo the Galerkin products and never read
        // the modes again, so their vectors are freed (three of the coarse level).
        let mut coarse_pc: ffi::PC = std::ptr::null_mut();
        check(ffi::KSPGetPC(coarse, &mut coarse_pc), "KSPGetPC(coarse)")?;
        if super::has_type(coarse_pc as ffi::PetscObject, "gamg")?
            && bool_option("-mg_coarse_pc_gamg_reuse_interpolation", true)?
        {
            check(
                ffi::MatSetNearNullSpace(two_level::coarse_operator(coarse)?, std::ptr::null_mut()),
                "MatSetNearNullSpace(coarse, none)",
            )?;
        }
        Ok(())
    }
}

/// Tells SNES whether the next linear solve factors the new tangent or keeps the last factors
/// (see [`FactorReuse`]). SNES reads the preconditioner lag after the Jacobian callback: −2
/// rebuilds once, −1 keeps. Every rank decides alike: the residual norm and the Krylov count
/// are global.
fn choose_factorisation(
    snes: ffi::SNES,
    reuse: &FactorReuse,
    last_norm: &mut Option<f64>,
) -> Result<(), PetscError> {
    let mut norm = 0.0;
    let mut ksp: ffi::KSP = std::ptr::null_mut();
    let mut its: ffi::PetscInt = 0;
    let mut reason: ffi::KSPConvergedReason = 0;
    // SAFETY: live SNES inside its own callback; its KSP is borrowed.
    unsafe {
        check(
            ffi::SNESGetFunctionNorm(snes, &mut norm),
            "SNESGetFunctionNorm",
        )?;
        check(ffi::SNESGetKSP(snes, &mut ksp), "SNESGetKSP")?;
        check(
            ffi::KSPGetIterationNumber(ksp, &mut its),
            "KSPGetIterationNumber",
        )?;
        check(
            ffi::KSPGetConvergedReason(ksp, &mut reason),
            "KSPGetConvergedReason",
        )?;
    }
    // The first Jacobian of a solve has no last norm: a new increment's tangent is factored.
    let keep = last_norm.is_some_and(|last| norm <= reuse.contraction * last)
        && reason > 0
        && (its.max(0) as usize) <= reuse.max_krylov;
    *last_norm = Some(norm);
    // SAFETY: as above.
    unsafe {
        check(
            ffi::SNESSetLagPreconditioner(snes, if keep { -1 } else { -2 }),
            "SNESSetLagPreconditioner",
        )
    }
}
