//! Why a Newton or linear solve stopped without converging, by PETSc's own names.

use super::ffi;
use super::PetscError;
use std::fmt;

/// A diverged `SNESConvergedReason`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SnesDiverged {
    FunctionDomain,
    FunctionCount,
    LinearSolve,
    FnormNan,
    MaxIt,
    LineSearch,
    Inner,
    LocalMin,
    Dtol,
    JacobianDomain,
    TrDelta,
    /// A code this list does not know (a newer PETSc).
    Other(ffi::SNESConvergedReason),
}

impl SnesDiverged {
    /// `None` for a reason that is not a divergence (converged or still iterating).
    pub fn from_raw(r: ffi::SNESConvergedReason) -> Option<SnesDiverged> {
        use SnesDiverged::*;
        Some(match r {
            r if r >= 0 => return None,
            ffi::SNESConvergedReason_SNES_DIVERGED_FUNCTION_DOMAIN => FunctionDomain,
            ffi::SNESConvergedReason_SNES_DIVERGED_FUNCTION_COUNT => FunctionCount,
            ffi::SNESConvergedReason_SNES_DIVERGED_LINEAR_SOLVE => LinearSolve,
            ffi::SNESConvergedReason_SNES_DIVERGED_FNORM_NAN => FnormNan,
            ffi::SNESConvergedReason_SNES_DIVERGED_MAX_IT => MaxIt,
            ffi::SNESConvergedReason_SNES_DIVERGED_LINE_SEARCH => LineSearch,
            ffi::SNESConvergedReason_SNES_DIVERGED_INNER => Inner,
            ffi::SNESConvergedReason_SNES_DIVERGED_LOCAL_MIN => LocalMin,
            ffi::SNESConvergedReason_SNES_DIVERGED_DTOL => Dtol,
            ffi::SNESConvergedReason_SNES_DIVERGED_JACOBIAN_DOMAIN => JacobianDomain,
            ffi::SNESConvergedReason_SNES_DIVERGED_TR_DELTA => TrDelta,
            other => Other(other),
        })
    }
}

impl fmt::Display for SnesDiverged {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use SnesDiverged::*;
        let name = match self {
            FunctionDomain => "DIVERGED_FUNCTION_DOMAIN",
            FunctionCount => "DIVERGED_FUNCTION_COUNT",
            LinearSolve => "DIVERGED_LINEAR_SOLVE",
            FnormNan => "DIVERGED_FNORM_NAN",
            MaxIt => "DIVERGED_MAX_IT",
            LineSearch => "DIVERGED_LINE_SEARCH",
            Inner => "DIVERGED_INNER",
            LocalMin => "DIVERGED_LOCAL_MIN",
            Dtol => "DIVERGED_DTOL",
            JacobianDomain => "DIVERGED_JACOBIAN_DOMAIN",
            TrDelta => "DIVERGED_TR_DELTA",
            Other(c) => return write!(f, "SNESConvergedReason {c}"),
        };
        f.write_str(name)
    }
}

/// A diverged `KSPConvergedReason`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KspDiverged {
    Null,
    Its,
    Dtol,
    Breakdown,
    BreakdownBicg,
    NonSymmetric,
    IndefinitePc,
    NanOrInf,
    IndefiniteMat,
    PcFailed,
    Other(ffi::KSPConvergedReason),
}

impl KspDiverged {
    /// `None` for a reason that is not a divergence.
    pub fn from_raw(r: ffi::KSPConvergedReason) -> Option<KspDiverged> {
        use KspDiverged::*;
        Some(match r {
            r if r >= 0 => return None,
            ffi::KSPConvergedReason_KSP_DIVERGED_NULL => Null,
            ffi::KSPConvergedReason_KSP_DIVERGED_ITS => Its,
            ffi::KSPConvergedReason_KSP_DIVERGED_DTOL => Dtol,
            ffi::KSPConvergedReason_KSP_DIVERGED_BREAKDOWN => Breakdown,
            ffi::KSPConvergedReason_KSP_DIVERGED_BREAKDOWN_BICG => BreakdownBicg,
            ffi::KSPConvergedReason_KSP_DIVERGED_NONSYMMETRIC => NonSymmetric,
            ffi::KSPConvergedReason_KSP_DIVERGED_INDEFINITE_PC => IndefinitePc,
            ffi::KSPConvergedReason_KSP_DIVERGED_NANORINF => NanOrInf,
            ffi::KSPConvergedReason_KSP_DIVERGED_INDEFINITE_MAT => IndefiniteMat,
            ffi::KSPConvergedReason_KSP_DIVERGED_PC_FAILED => PcFailed,
            other => Other(other),
        })
    }
}

impl fmt::Display for KspDiverged {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use KspDiverged::*;
        let name = match self {
            Null => "DIVERGED_NULL",
            Its => "DIVERGED_ITS",
            Dtol => "DIVERGED_DTOL",
            Breakdown => "DIVERGED_BREAKDOWN",
            BreakdownBicg => "DIVERGED_BREAKDOWN_BICG",
            NonSymmetric => "DIVERGED_NONSYMMETRIC",
            IndefinitePc => "DIVERGED_INDEFINITE_PC",
            NanOrInf => "DIVERGED_NANORINF",
            IndefiniteMat => "DIVERGED_INDEFINITE_MAT",
            PcFailed => "DIVERGED_PC_FAILED",
            Other(c) => return write!(f, "KSPConvergedReason {c}"),
        };
        f.write_str(name)
    }
}

/// Newton ran but did not converge: a smaller increment may.
#[derive(Debug, Clone, PartialEq)]
pub enum Divergence {
    /// SNES gave up; for a failed linear solve, `linear` is the Krylov solver's reason.
    Snes {
        reason: SnesDiverged,
        linear: Option<KspDiverged>,
        iterations: usize,
        /// Krylov iterations over the solve.
        linear_iterations: usize,
        residual: f64,
        /// Why the problem refused a trial state, for a domain error (a material's message).
        domain: Option<String>,
    },
    /// The update fell below the step tolerance after a line search damped the step to
    /// `lambda` (< 0.5): Newton is stuck, whatever the residual.
    Stalled {
        lambda: f64,
        step_tol: f64,
        iterations: usize,
        linear_iterations: usize,
        residual: f64,
    },
}

impl Divergence {
    /// The Newton and Krylov iterations the failed solve spent.
    pub fn spent(&self) -> [usize; 2] {
        match self {
            Divergence::Snes {
                iterations,
                linear_iterations,
                ..
            }
            | Divergence::Stalled {
                iterations,
                linear_iterations,
                ..
            } => [*iterations, *linear_iterations],
        }
    }
}

impl fmt::Display for Divergence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Divergence::Snes {
                reason,
                linear,
                iterations,
                residual,
                domain,
                ..
            } => {
                write!(f, "Newton did not converge ({reason}")?;
                if let Some(l) = linear {
                    write!(f, ": the linear solver {l}")?;
                }
                if let Some(d) = domain {
                    write!(f, ": {d}")?;
                }
                write!(
                    f,
                    ") after {iterations} iterations, residual {residual:.3e}"
                )
            }
            Divergence::Stalled {
                lambda,
                step_tol,
                iterations,
                residual,
                ..
            } => write!(
                f,
                "Newton stalled (update below {step_tol:e} of the solution after a step damped \
                 to {lambda:.1e}) after {iterations} iterations, residual {residual:.3e}"
            ),
        }
    }
}

/// A Newton solve that did not deliver a solution.
#[derive(Debug, Clone)]
pub enum SolveFailure {
    /// It ran and diverged: the caller may cut the increment.
    Diverged(Divergence),
    /// A call or a callback failed: final.
    Failed(PetscError),
}

impl From<PetscError> for SolveFailure {
    fn from(e: PetscError) -> Self {
        SolveFailure::Failed(e)
    }
}

impl fmt::Display for SolveFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolveFailure::Diverged(d) => d.fmt(f),
            SolveFailure::Failed(e) => f.write_str(&e.message),
        }
    }
}
