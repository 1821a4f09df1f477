//! The p-multigrid's V-cycle as one preconditioner (a PETSc shell): a damped Jacobi sweep on
//! the P2 level before and after a coarse correction through the P1 → P2 interpolation. It is
//! the cycle PCMG runs with a Richardson–Jacobi smoother of one sweep, step for step (the same
//! products with the tangent, the same history bit for bit), without PCMG's price in vectors
//! of the fine level: PCMG keeps a residual, the Richardson smoother two work vectors and
//! Jacobi its diagonal. Here the diagonal's inverse and one residual (which the full-step line
//! search borrows between applications) are all.

use crate::petsc::{
    Ksp, KspRef, Mat, MatRef, PVec, PcRef, PetscError, ShellPreconditioner, VecRef, ViewerRef,
};

/// The shell's name, as `-ksp_view` shows it.
const NAME: &str = "p-multigrid (P2 Richardson-Jacobi, P1 coarse solver)";
/// What messages call it.
pub(super) const WHAT: &str = "two-level p-multigrid";

/// The cycle: the interpolation and the coarse solver it was made with, and what its set-ups
/// make.
pub struct TwoLevel {
    interpolation: Mat,
    coarse: Ksp,
    /// The inverse of the tangent's diagonal (made at the first set-up).
    inverse_diagonal: Option<PVec>,
    /// The fine residual (lent to the line search; made at the first set-up if not given).
    residual: Option<PVec>,
    /// The coarse solution and right-hand side.
    coarse_vectors: Option<(PVec, PVec)>,
    /// Richardson's damping ω of the Jacobi sweeps.
    damping: f64,
}

impl TwoLevel {
    /// Collective. Makes `pc` the cycle with `interpolation` (P1 → P2; the cycle keeps a
    /// reference) and the coarse solver `coarse`.
    pub fn install(
        pc: PcRef<'_>,
        interpolation: MatRef<'_>,
        coarse: Ksp,
    ) -> Result<(), PetscError> {
        let cycle = TwoLevel {
            interpolation: interpolation.shared()?,
            coarse,
            inverse_diagonal: None,
            residual: None,
            coarse_vectors: None,
            damping: 1.0,
        };
        pc.set_shell(NAME, cycle)
    }

    /// The coarse solver.
    pub fn coarse(&self) -> KspRef<'_> {
        self.coarse.as_ref()
    }

    /// Sets the damping of the Jacobi sweeps.
    pub fn set_damping(&mut self, damping: f64) {
        self.damping = damping;
    }

    /// Takes `residual` (a vector of the fine layout) as the fine residual, before the first
    /// set-up.
    pub fn set_residual(&mut self, residual: VecRef<'_>) -> Result<(), PetscError> {
        self.residual = Some(residual.shared()?);
        Ok(())
    }

    /// Collective. Frees what the set-ups made (the coarse solver's hierarchy and the cycle's
    /// vectors), keeping the configuration: PCSHELL has no reset of its own, and `SNESReset` is
    /// how an increment's solver hands its memory back before the converged state's pass.
    pub fn reset(&mut self) -> Result<(), PetscError> {
        // KSPReset also drops the operator, which the next increment's set-up needs.
        let operator = self.coarse.as_ref().operator()?.shared()?;
        self.coarse.as_ref().reset()?;
        self.coarse
            .as_ref()
            .set_operators(operator.as_ref(), operator.as_ref())?;
        self.inverse_diagonal = None;
        self.residual = None;
        self.coarse_vectors = None;
        Ok(())
    }
}

impl ShellPreconditioner for TwoLevel {
    /// Collective. A new tangent: its diagonal is inverted (as PCJACOBI does) and the coarse
    /// solver set up for the new coarse operator.
    fn set_up(&mut self, pc: PcRef<'_>) -> Result<(), PetscError> {
        let (_, a) = pc.operators()?;
        let d = match &self.inverse_diagonal {
            Some(d) => d,
            None => self.inverse_diagonal.insert(a.right_vector()?),
        };
        if self.residual.is_none() {
            self.residual = Some(d.duplicate()?);
        }
        a.diagonal(d.as_ref())?;
        d.as_ref().reciprocal()?;
        // As PCJACOBI: a zero diagonal entry (left zero by the reciprocal) counts as one.
        d.as_ref().write(|d| {
            for v in d.iter_mut().filter(|v| **v == 0.0) {
                *v = 1.0;
            }
        })?;
        if self.coarse_vectors.is_none() {
            self.coarse_vectors = Some(self.coarse.as_ref().operator()?.vectors()?);
        }
        self.coarse.as_ref().set_up()
    }

    /// Collective. x = V-cycle(b): a damped Jacobi sweep from zero, the coarse correction of
    /// its residual, a second sweep. The same operations, in the same order, as PCMG's
    /// multiplicative cycle with a one-sweep Richardson–Jacobi smoother.
    fn apply(&mut self, pc: PcRef<'_>, b: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        let (_, a) = pc.operators()?;
        let (Some(d), Some(r), Some((solution, rhs))) =
            (&self.inverse_diagonal, &self.residual, &self.coarse_vectors)
        else {
            return Err(not_set_up());
        };
        let (d, r, w) = (d.as_ref(), r.as_ref(), self.damping);
        // Pre-sweep from x = 0: x = ω D⁻¹ b.
        x.pointwise_mult(d, b)?;
        x.scale(w)?;
        // Coarse correction of r = b − A x.
        a.mult(x, r)?;
        r.aypx(-1.0, b)?;
        let interpolation = self.interpolation.as_ref();
        interpolation.mult_transpose(r, rhs.as_ref())?;
        let coarse = self.coarse.as_ref();
        coarse.solve(rhs.as_ref(), solution.as_ref())?;
        // A failed coarse solve fails the preconditioner as PCMG reports it.
        coarse.check_solve(pc, solution.as_ref())?;
        interpolation.mult_add(solution.as_ref(), x, x)?;
        // Post-sweep: x = x + ω D⁻¹ (b − A x).
        a.mult(x, r)?;
        r.aypx(-1.0, b)?;
        r.pointwise_mult(d, r)?;
        x.axpy(w, r)
    }

    fn view(&self, viewer: ViewerRef<'_>) -> Result<(), PetscError> {
        let lines = [
            format!(
                "fine level (P2): one Richardson-Jacobi sweep before and after, damping \
                 factor={}",
                self.damping
            ),
            "coarse level (P1):".to_string(),
        ];
        viewer.nested(&lines, || self.coarse.as_ref().view(viewer))
    }
}

fn not_set_up() -> PetscError {
    PetscError {
        code: crate::petsc::error::PETSC_ERR_USER,
        message: format!("the {WHAT} was applied before its set-up"),
    }
}
