//! How a step is solved, as one value chosen from the scene and printed at the start of a run.

use crate::model::Model;
use crate::petsc::error::PetscError;
use crate::scene::LineSearch;

/// The nonlinear method of every step.
#[derive(Debug, Clone, PartialEq)]
pub struct StepSolver {
    /// SNES line search, and the one a diverged piece is retried with.
    pub line_search: &'static str,
    pub retry: &'static str,
    /// `-snes_linesearch_type` from the command line: set after the scene's, it is every try's.
    pub command_line: Option<String>,
    /// Contact with rigid bodies, when there are any: decided inside every Newton iteration.
    pub contact: Option<ContactMethod>,
    /// Halvings of a step's increment before a divergence is final: the smallest piece is
    /// 1/2^max_cuts of the step (a converged piece lets the next grow back).
    pub max_cuts: usize,
}

/// Contact as part of Newton's nonlinear system (`rigid::contact`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactMethod {
    /// The complementarity constant as a multiple of E/h.
    pub constant: f64,
    /// The gap tolerance of a converged increment, as a fraction of the spacing.
    pub tolerance: f64,
}

impl StepSolver {
    pub fn of(model: &Model, max_cuts: usize) -> StepSolver {
        let line_search = match model.scene.solver.line_search {
            LineSearch::Auto if model.plastic() => "bt",
            LineSearch::Auto | LineSearch::Basic => "basic",
            LineSearch::Bt => "bt",
            LineSearch::L2 => "l2",
            LineSearch::Cp => "cp",
        };
        // Backtracking can stall at a kink of the plastic or contact response that a full step
        // jumps over, and a full step can overshoot where backtracking does not.
        let retry = if line_search == "bt" { "basic" } else { "bt" };
        let c = &model.scene.contact;
        StepSolver {
            line_search,
            retry,
            command_line: None,
            contact: (!model.bodies.is_empty()).then_some(ContactMethod {
                constant: c.penalty,
                tolerance: c.tolerance,
            }),
            max_cuts,
        }
    }

    /// Collective (PETSc's options are the same on every rank). With the line search the
    /// command line gives, if any.
    pub fn with_command_line(mut self) -> Result<StepSolver, PetscError> {
        self.command_line = crate::petsc::options::string("-snes_linesearch_type")?;
        Ok(self)
    }

    /// The line search of a try: the retry's after a divergence.
    pub fn line_search(&self, retry: bool) -> &'static str {
        if retry {
            self.retry
        } else {
            self.line_search
        }
    }
}

impl std::fmt::Display for StepSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.command_line {
            Some(ls) => write!(
                f,
                "Newton, line search {ls} (-snes_linesearch_type, on every try"
            )?,
            None => write!(
                f,
                "Newton, line search {} (a diverged piece retried with {}",
                self.line_search, self.retry
            )?,
        }
        write!(
            f,
            ", then halved down to 1/{} of the step)",
            1u64 << self.max_cuts
        )?;
        if let Some(c) = self.contact {
            write!(
                f,
                "; contact in the same Newton loop: semi-smooth active set (touch, stick, slip \
                 decided at every iteration, c = {} E/h, gaps closed to {:e} of the spacing)",
                c.constant, c.tolerance
            )?;
        }
        Ok(())
    }
}
