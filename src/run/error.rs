//! What can end a run or a subcommand, with the context the message needs (step, file, rank),
//! and the process exit code each maps to. Messages travel between ranks as text (the
//! collective error agreement), so a message that came from another rank is [`RunError::Agreed`].

use super::step::SolveError;
use super::test_hooks::FaultSpec;
use crate::case_file::CaseError;
use crate::mesh::local::MeshError;
use crate::output::OutputError;
use crate::petsc::PetscError;
use crate::plot::PlotError;
use crate::scene::SceneError;
use pfem_partition::{Comm, PartitionError};
use std::fmt;
use std::path::PathBuf;

/// Exit code of a run that failed.
pub const EXIT_FAILURE: i32 = 1;
/// Exit code of a command line that could not be parsed.
pub const EXIT_USAGE: i32 = 2;

#[derive(Debug)]
pub enum RunError {
    /// The command line could not be parsed.
    Usage(String),
    /// `--until-step` leaves nothing to run; `reason` says why and what to give instead.
    UntilStep {
        until: u64,
        reason: String,
    },
    /// A case file or checkpoint that cannot be read, written or used as a destination.
    Case(CaseError),
    Scene(SceneError),
    /// The case's scene does not make a model (material, bodies).
    Model {
        case: PathBuf,
        message: String,
    },
    /// A file or folder of the run's output that cannot be written.
    Io {
        path: PathBuf,
        message: String,
    },
    /// The output folder's scene.toml cannot be read back.
    UnreadableOutput {
        dir: PathBuf,
        error: SceneError,
    },
    /// The output folder holds another case's run.
    OtherCase {
        dir: PathBuf,
        scene_file: PathBuf,
    },
    History(String),
    Output(OutputError),
    Plot(PlotError),
    Petsc(PetscError),
    Partition(PartitionError),
    Mesh(MeshError),
    /// A refined edge that the global list of split edges lacks.
    Refinement {
        edge: [u64; 2],
    },
    /// Debug builds: a particle within the halo width of an owned one is missing on `rank`.
    Halo {
        gid: u64,
        width: f64,
        rank: i32,
    },
    /// A solve that failed for another reason than divergence.
    Solve(SolveError),
    /// Newton diverged on the smallest piece of the step, after all cuts.
    Diverged {
        message: String,
        /// The piece as 1/`piece` of the step.
        piece: f64,
        cuts: usize,
        from: f64,
        advice: String,
    },
    /// The step went through on a body that is gone (`what` says how).
    Sanity {
        step: u64,
        what: String,
    },
    /// A particle passed through a rigid body.
    Penetration {
        step: u64,
        gid: u64,
        body: String,
        depth: f64,
        limit: f64,
    },
    Signal {
        signal: i32,
        error: std::io::Error,
    },
    /// `PFEM_INJECT_FAULT` that cannot be parsed.
    FaultSpec(FaultSpec),
    /// The fault `PFEM_INJECT_FAULT` asked for.
    InjectedFault {
        phase: String,
        step: u64,
        rank: i32,
    },
    /// The message of an error that the agreement brought from another rank.
    Agreed(String),
}

impl RunError {
    /// An error of choosing the linear path: a command-line option or scene setting that does
    /// not name a path, or names one the scene cannot take, is a usage error in its own words;
    /// a failure of PETSc itself stays one.
    pub fn solver_option(e: PetscError) -> RunError {
        if e.code == crate::petsc::error::PETSC_ERR_USER {
            RunError::Usage(e.message)
        } else {
            RunError::Petsc(e)
        }
    }

    /// The process exit code: 2 for a command line that could not be parsed, 1 for the rest.
    pub fn exit_code(&self) -> i32 {
        match self {
            RunError::Usage(_) => EXIT_USAGE,
            _ => EXIT_FAILURE,
        }
    }
}

impl fmt::Display for RunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use RunError::*;
        match self {
            Usage(m) | History(m) | Agreed(m) => f.write_str(m),
            UntilStep { until, reason } => {
                write!(f, "--until-step {until}: nothing to run, {reason}")
            }
            Case(e) => e.fmt(f),
            Scene(e) => e.fmt(f),
            Model {
                case: path,
                message,
            }
            | Io { path, message } => {
                write!(f, "{}: {message}", path.display())
            }
            UnreadableOutput { dir, error } => write!(
                f,
                "{}: its scene.toml cannot be read back ({error}), so it cannot be told apart \
                 from another case's output; give another --out folder, or remove this one",
                dir.display()
            ),
            OtherCase { dir, scene_file } => write!(
                f,
                "{}: holds the output of another case ({} is not this case's scene); give \
                 another --out folder, or remove this one to start over",
                dir.display(),
                scene_file.display()
            ),
            Output(e) => e.fmt(f),
            Plot(e) => e.fmt(f),
            Petsc(e) => e.fmt(f),
            Partition(e) => e.fmt(f),
            Mesh(e) => e.fmt(f),
            Refinement { edge } => {
                write!(f, "refinement: edge {edge:?} missing from the global list")
            }
            Halo { gid, width, rank } => write!(
                f,
                "halo check: particle {gid} is within the halo width {width} of an owned \
                 particle but not on rank {rank}"
            ),
            Solve(e) => e.fmt(f),
            Diverged {
                message,
                piece,
                cuts,
                from,
                advice,
            } => write!(
                f,
                "{message}, on a piece of 1/{piece} of the step after {cuts} cuts (from load \
                 factor {from:.6}); {advice}"
            ),
            Sanity { step, what } => write!(f, "step {step}: {what}"),
            Penetration {
                step,
                gid,
                body,
                depth,
                limit,
            } => write!(
                f,
                "step {step}: particle {gid} is inside rigid body '{body}' by {depth:.3} of its \
                 spacing (limit {limit}): the soil passed through the body; try a larger \
                 contact.penalty or more steps"
            ),
            Signal { signal, error } => {
                write!(f, "cannot install the handler for signal {signal}: {error}")
            }
            FaultSpec(e) => e.fmt(f),
            InjectedFault { phase, step, rank } => match phase.as_str() {
                "load" => write!(f, "injected fault: load on rank {rank}"),
                _ => write!(f, "injected fault: {phase} of step {step} on rank {rank}"),
            },
        }
    }
}

impl std::error::Error for RunError {}

macro_rules! from_lower_layer {
    ($($t:ty => $v:ident),* $(,)?) => {
        $(impl From<$t> for RunError {
            fn from(e: $t) -> RunError {
                RunError::$v(e)
            }
        })*
    };
}

from_lower_layer!(
    CaseError => Case,
    SceneError => Scene,
    OutputError => Output,
    PlotError => Plot,
    PetscError => Petsc,
    PartitionError => Partition,
    MeshError => Mesh,
    FaultSpec => FaultSpec,
);

/// The agreed message as an error: this rank's own error when the agreement chose it (the
/// lowest failing rank's), else the message from the other rank.
pub(super) fn agreed(local: Option<RunError>, message: Option<String>) -> Result<(), RunError> {
    match (local, message) {
        (_, None) => Ok(()),
        (Some(e), Some(m)) if e.to_string() == m => Err(e),
        (_, Some(m)) => Err(RunError::Agreed(m)),
    }
}

/// Collective. Every rank gets the lowest failing rank's error (see
/// `pfem_partition::agree_on_error`).
pub(super) fn agree(world: &Comm, local: Option<RunError>) -> Result<(), RunError> {
    let message = pfem_partition::agree_on_error(world, local.as_ref().map(|e| e.to_string()));
    agreed(local, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes_and_agreed_messages() {
        assert_eq!(RunError::Usage("x".into()).exit_code(), EXIT_USAGE);
        let fault = || RunError::InjectedFault {
            phase: "solve".into(),
            step: 3,
            rank: 1,
        };
        assert_eq!(fault().exit_code(), EXIT_FAILURE);
        assert_eq!(
            fault().to_string(),
            "injected fault: solve of step 3 on rank 1"
        );
        let own = agreed(Some(fault()), Some(fault().to_string())).unwrap_err();
        assert!(matches!(own, RunError::InjectedFault { .. }));
        let other = agreed(None, Some("from rank 0".into())).unwrap_err();
        assert!(matches!(other, RunError::Agreed(ref m) if m == "from rank 0"));
    }

    /// The texts the run printed before the typed error (tests/ match parts of them).
    #[test]
    fn messages_keep_their_text() {
        let penetration = RunError::Penetration {
            step: 4,
            gid: 17,
            body: "footing".into(),
            depth: 0.61234,
            limit: 0.5,
        };
        assert_eq!(
            penetration.to_string(),
            "step 4: particle 17 is inside rigid body 'footing' by 0.612 of its spacing (limit \
             0.5): the soil passed through the body; try a larger contact.penalty or more steps"
        );
        let diverged = RunError::Diverged {
            message: "step 2: diverged".into(),
            piece: 64.0,
            cuts: 6,
            from: 0.25,
            advice: "try more steps".into(),
        };
        assert_eq!(
            diverged.to_string(),
            "step 2: diverged, on a piece of 1/64 of the step after 6 cuts (from load factor \
             0.250000); try more steps"
        );
        let until = RunError::UntilStep {
            until: 0,
            reason: "a run stops after a step it has made; give a step from 1 to 3".into(),
        };
        assert_eq!(
            until.to_string(),
            "--until-step 0: nothing to run, a run stops after a step it has made; give a step \
             from 1 to 3"
        );
        let io = RunError::Io {
            path: "out/scene.toml".into(),
            message: "No space left on device".into(),
        };
        assert_eq!(io.to_string(), "out/scene.toml: No space left on device");
    }
}
