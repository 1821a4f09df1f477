//! What the preconditioners take from every Jacobian, apart from its assembly: the
//! p-multigrid's smoother damping and first coarse set-up, the yield zone's rows, and whether a
//! kept factorisation is refreshed. And the end of an increment's solver, which frees what
//! they set up.

use super::two_level::{self, TwoLevel};
use super::yield_zone::YieldZone;
use crate::petsc::snes::CallbackError;
use crate::petsc::{
    KspRef, MatRef, NonlinearProblem, Object, PcRef, PetscError, Snes, SnesRef, VecRef,
};
use crate::solve::linear_path::{Cycle, FactorReuse, LinearPath};

/// What an assembly yields for the preconditioners.
pub trait JacobianProducts {
    /// The Richardson damping of one Jacobi sweep on the last Jacobian, the same on every
    /// rank, where the problem knows a bound on its spectrum.
    fn smoother_damping(&self) -> Option<f64>;
    /// The global displacement dofs of the triangles whose tangent has yielded at the last
    /// Jacobian (this rank's triangles; repeats allowed).
    fn yielded_dofs(&mut self) -> Vec<usize>;
}

/// The hooks of one Newton solve on `path`.
pub struct Hooks<'a> {
    path: LinearPath,
    /// The yield zone's preconditioner, where the path has one.
    zone: Option<PcRef<'a>>,
    /// The residual norm at the last Jacobian of this solve.
    last_norm: Option<f64>,
    /// Set up the p-multigrid's coarse solver at the next Jacobian (the first of the solve).
    coarse_first: bool,
}

impl<'a> Hooks<'a> {
    pub fn new(path: LinearPath, zone: Option<PcRef<'a>>) -> Hooks<'a> {
        Hooks {
            path,
            zone,
            last_norm: None,
            coarse_first: matches!(path, LinearPath::PMultigrid { .. }),
        }
    }

    /// Collective. What the linear solver takes from a new Jacobian at `x`.
    pub fn after_jacobian(
        &mut self,
        snes: SnesRef<'_>,
        x: VecRef<'_>,
        products: &mut dyn JacobianProducts,
    ) -> Result<(), PetscError> {
        let pc = snes.ksp()?.pc()?;
        if self.path.damps_smoother() {
            let damping = products.smoother_damping().ok_or_else(|| PetscError {
                code: crate::petsc::error::PETSC_ERR_USER,
                message: "the p-multigrid's Jacobi smoother has no damping: this Jacobian gave \
                          no finite bound on its spectrum (an element tangent with a negative \
                          or zero diagonal, or not a number)"
                    .into(),
            })?;
            match self.cycle() {
                Some(Cycle::TwoLevel) => on_cycle(pc, |c| {
                    c.set_damping(damping);
                    Ok(())
                })?,
                _ => pc.mg_smoother(1)?.set_richardson_scale(damping)?,
            }
        }
        if let Some(zone) = self.zone {
            zone.with_shell(|z: &mut YieldZone| z.set_zone(x, &products.yielded_dofs()))?
                .transpose()?;
        }
        if self.coarse_first {
            self.coarse_first = false;
            self.set_up_coarse_solver(pc)?;
            self.share_work_vector(snes, pc, x)?;
        }
        if let LinearPath::Direct {
            reuse: Some(reuse), ..
        } = self.path
        {
            choose_factorisation(snes, &reuse, &mut self.last_norm)?;
        }
        Ok(())
    }

    fn cycle(&self) -> Option<Cycle> {
        match self.path {
            LinearPath::PMultigrid { cycle, .. } => Some(cycle),
            _ => None,
        }
    }

    /// Collective. Sets up the p-multigrid's coarse solver (GAMG on the coarse operator the
    /// Jacobian has just assembled) before the Krylov method, the multigrid and its fine
    /// smoother allocate their vectors of the fine level: GAMG's first aggregation of a solve
    /// is the memory peak of the iterative path, and those six vectors need not sit under it.
    /// The outer set-up that follows finds the coarse solver set up for this operator.
    fn set_up_coarse_solver(&self, pc: PcRef<'_>) -> Result<(), PetscError> {
        let LinearPath::PMultigrid {
            cycle,
            coarse_keeps_aggregation,
            ..
        } = self.path
        else {
            return Ok(());
        };
        let set_up = |coarse: KspRef<'_>| {
            // Its options are read first, as the multigrid's own set-up would read them.
            coarse.set_from_options()?;
            coarse.set_up()?;
            // GAMG has aggregated with the rigid-body modes. With its interpolation reused,
            // the set-ups of the later Newton iterations only redo the Galerkin products and
            // never read the modes again, so their vectors are freed (three of the coarse
            // level).
            if coarse.pc()?.has_type("gamg")? && coarse_keeps_aggregation {
                let operator: MatRef<'_> = coarse.operator()?;
                operator.clear_near_null_space()?;
            }
            Ok(())
        };
        match cycle {
            Cycle::TwoLevel => on_cycle(pc, |c| set_up(c.coarse())),
            Cycle::Pcmg => set_up(pc.mg_coarse_solver()?),
        }
    }

    /// Collective. One vector of the fine level serves as the p-multigrid's residual and as
    /// the full-step line search's trial point, instead of three. The multigrid's residual is
    /// written and read only inside a preconditioner application, the trial point only inside
    /// the line search, which follows the linear solve; the full step never touches its
    /// second vector (the trial residual: it evaluates into the residual itself). Any other
    /// line search keeps its own pair. Measured: two vectors of the fine level fewer at the
    /// memory peak.
    fn share_work_vector(
        &self,
        snes: SnesRef<'_>,
        pc: PcRef<'_>,
        x: VecRef<'_>,
    ) -> Result<(), PetscError> {
        let ls = snes.line_search()?;
        // Once per set-up: a later solve on the same SNES (a retried or cut increment on the
        // same pattern) finds the line search's vectors in place.
        if !ls.has_type("basic")? || ls.has_work_vectors()? {
            return Ok(());
        }
        let own_cycle = self.cycle() == Some(Cycle::TwoLevel);
        // Level 1 is the fine level only in the two-level hierarchy we build.
        if !own_cycle && pc.mg_levels()? != 2 {
            return Ok(());
        }
        let shared = x.duplicate()?;
        if own_cycle {
            on_cycle(pc, |c| c.set_residual(shared.as_ref()))?;
        } else {
            pc.set_mg_residual(1, shared.as_ref())?;
        }
        ls.set_work_vectors(shared.as_ref(), shared.as_ref())
    }
}

/// Runs `f` on the two-level cycle `pc`, or fails if `pc` is not it.
fn on_cycle<R>(
    pc: PcRef<'_>,
    f: impl FnOnce(&mut TwoLevel) -> Result<R, PetscError>,
) -> Result<R, PetscError> {
    pc.with_shell(f)?
        .unwrap_or_else(|| Err(super::not_shell(two_level::WHAT)))
}

/// Tells SNES whether the next linear solve factors the new tangent or keeps the last factors
/// (see [`FactorReuse`]). Every rank decides alike: the residual norm and the Krylov count
/// are global.
fn choose_factorisation(
    snes: SnesRef<'_>,
    reuse: &FactorReuse,
    last_norm: &mut Option<f64>,
) -> Result<(), PetscError> {
    let norm = snes.function_norm()?;
    let (its, converged) = snes.ksp()?.outcome()?;
    // The first Jacobian of a solve has no last norm: a new increment's tangent is factored.
    let keep = last_norm.is_some_and(|last| norm <= reuse.contraction * last)
        && converged
        && its <= reuse.max_krylov;
    *last_norm = Some(norm);
    snes.keep_preconditioner(keep)
}

/// Collective. Frees what the last solve on `snes` set up, keeping the configuration: the
/// end of an increment's solver. PCSHELL has no reset of its own, so the cycle and the zone
/// free theirs first. The p-multigrid's coarse operator lost its rigid-body modes after GAMG's
/// first aggregation, so a solve after a reset would aggregate without them, and the field
/// split drops its splits (and with them the displacement block's yield zone); each increment
/// makes its iterative solver afresh.
pub fn reset(snes: &mut Snes, zone: Option<PcRef<'_>>) -> Result<(), PetscError> {
    let pc = snes.ksp()?.pc()?;
    pc.with_shell(|c: &mut TwoLevel| c.reset())?.transpose()?;
    if let Some(zone) = zone {
        zone.with_shell(|z: &mut YieldZone| z.reset())?
            .transpose()?;
    }
    snes.reset()
}

/// A problem with the hooks of its linear solver: its assembly, then the hooks.
pub struct Hooked<'p, 'h, P> {
    pub problem: &'p mut P,
    pub hooks: Hooks<'h>,
}

impl<P: NonlinearProblem + JacobianProducts> NonlinearProblem for Hooked<'_, '_, P> {
    fn residual(&mut self, x: VecRef<'_>, f: VecRef<'_>) -> Result<(), CallbackError> {
        self.problem.residual(x, f)
    }

    fn jacobian(&mut self, x: VecRef<'_>, j: MatRef<'_>) -> Result<(), CallbackError> {
        self.problem.jacobian(x, j)
    }

    fn after_jacobian(&mut self, snes: SnesRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        self.hooks.after_jacobian(snes, x, self.problem)
    }
}
