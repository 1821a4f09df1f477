//! The PFEM step loop (the method's Fig. 1): remesh, map, solve, update, output, checkpoint.

mod adapt;
mod axis;
mod boundary_rules;
mod contact;
mod corners;
mod curved_edges;
mod error;
mod geostatic;
mod node_values;
mod output;
mod progress;
mod progress_json;
mod rank_table;
mod refinement;
mod restart;
mod run_log;
mod sanity;
mod signals;
mod simulation;
mod step;
mod step_solver;
mod support_plane;
mod terminal;
mod test_hooks;

pub use error::{RunError, EXIT_FAILURE, EXIT_USAGE};
pub use signals::install_stop_handlers;
pub use simulation::{Simulation, StepReport};

use crate::petsc::Petsc;
use mpi::traits::Communicator;
use pfem_partition::Comm;
use progress::{PhaseTimer, Progress};
use std::path::PathBuf;

/// How a run was asked for on the command line.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub case: PathBuf,
    pub out_dir: PathBuf,
    pub until_step: Option<u64>,
    /// What stdout shows while the run steps (`--progress`).
    pub progress: crate::cli::ProgressMode,
    /// Every step's full line on the terminal too (`--verbose`).
    pub verbose: bool,
}

/// How long a rank with an error waits for the others before it takes them to be stuck in a
/// collective it left, and aborts the job with its message.
const ERROR_PATIENCE: std::time::Duration = std::time::Duration::from_secs(5);

/// Collective on `errors`, a communicator nothing else uses (a duplicate of the world): every
/// rank gets the lowest failing rank's error; a rank that failed alone while the others wait in
/// another collective prints its error and aborts the job after [`ERROR_PATIENCE`].
pub fn agree_or_abort(errors: &Comm, local: Result<(), RunError>) -> Result<(), RunError> {
    let rank = errors.rank();
    let abandon = |e: &str| {
        eprintln!(
            "pfem-mpi: error: {e} (on rank {rank} alone, while the other ranks wait elsewhere: \
             aborting the job)"
        )
    };
    let local = local.err();
    let message = local.as_ref().map(|e| e.to_string());
    let agreed = pfem_partition::agree_on_error_or_abort(errors, message, ERROR_PATIENCE, abandon);
    error::agreed(local, agreed)
}

/// Collective. Runs the case to its last step (or `until_step`, or the step during which SIGTERM
/// or SIGUSR1 arrived), ending with a checkpoint.
pub fn run(world: &Comm, petsc: &Petsc, opts: &RunOptions) -> Result<(), RunError> {
    let errors = world.duplicate();
    let mut held = None;
    let mut progress = None;
    let outcome = drive(world, petsc, opts, &mut held, &mut progress);
    // Rank 0 logs its own error before the agreement, which may abort the job when the other
    // ranks wait elsewhere; another rank's error once it is agreed.
    let logged = match (&outcome, progress.as_mut()) {
        (Err(e), Some(progress)) => {
            progress.failed(e);
            true
        }
        _ => false,
    };
    // Agreed before the simulation is dropped: destroying its solver is collective, and a rank
    // that failed alone would wait there for ever.
    let agreed = agree_or_abort(&errors, outcome);
    if let (Err(e), Some(progress), false) = (&agreed, progress.as_mut(), logged) {
        progress.failed(e);
    }
    drop(held);
    agreed
}

fn drive(
    world: &Comm,
    petsc: &Petsc,
    opts: &RunOptions,
    held: &mut Option<Simulation>,
    progress: &mut Option<Progress>,
) -> Result<(), RunError> {
    let stop = signals::StopRequest::install()?;
    let rank = world.rank();
    let fault = |phase: &str, step: u64| test_hooks::inject(rank, phase, step);
    fault("load", 0)?;
    let sim = held.insert(Simulation::load(world, &opts.case)?);
    sanity::check_until_step(opts, sim)?;
    // Chosen before the output folder is made: a bad solver option leaves no empty run behind.
    let linear = sim
        .linear_plan(world)
        .map_err(RunError::solver_option)?
        .to_string();
    let mut out = output::Output::open(world, sim, &opts.out_dir)?;
    let progress = progress.insert(Progress::new(world, sim, opts)?);
    let step_solver = step_solver::StepSolver::of(&sim.model, step::MAX_CUTS)
        .with_command_line()
        .map_err(RunError::solver_option)?;
    progress.note(&format!("step solver: {step_solver}"));
    progress.note(&format!("linear solver: {linear}"));
    let mut last = opts.until_step.unwrap_or(u64::MAX).min(sim.total_steps());
    // The per-rank table after the end-of-run line: sizes of the last mesh, CPU of the solves.
    let mut sizes = None;
    let mut solve_cpu = 0.0;
    let mut collapse = None;
    let equilibrate = sim.model.scene.geostatic.is_some_and(|g| g.equilibrate);
    if sim.step() == 0 && equilibrate {
        let (newton, left) = sim.equilibrate_geostatic(world, petsc)?;
        progress.note(&format!(
            "geostatic: equilibrated in {newton} Newton iterations (last pass moved {left:.1e} \
             of the first)"
        ));
    }
    while sim.step() < last {
        let mut t = PhaseTimer::default();
        let next = sim.step() + 1;
        let mut mesh = t.time("remesh", || {
            fault("remesh", next)?;
            sim.remesh(world)
        })?;
        fault("map", next)?;
        let states = t.time("map", || sim.map(&mesh));
        let cpu = rank_table::cpu_seconds();
        let report = t.time("solve", || {
            fault("solve", next)?;
            sim.advance(world, petsc, &mut mesh, states)
        })?;
        solve_cpu += rank_table::cpu_seconds() - cpu;
        sanity::check_step(world, sim, &mesh, &report)?;
        // A collapse in the first piece of a step leaves the step count: its row is the last.
        let advanced = sim.step() == next;
        if stop.requested(world) || report.collapse.is_some() {
            last = sim.step();
            collapse = collapse.or(report.collapse);
        }
        let mut row = None;
        t.time("output", || {
            fault("output", next)?;
            if advanced {
                row = out.record(world, sim)?;
            }
            out.fields_if_due(world, sim, &mesh, last)
        })?;
        t.time("checkpoint", || {
            fault("checkpoint", next)?;
            out.checkpoint_if_due(world, sim, last)
        })?;
        t.time("balance", || {
            fault("balance", next)?;
            sim.rebalance_if_needed(world)
        })?;
        let columns = crate::history::header(sim.scene());
        let history = row.as_deref().map(|r| (&columns[1..], r));
        progress.step(sim, &report, &t, history);
        // Measured once, on the last mesh: the same condition on every rank (`last` is agreed).
        if sim.step() >= last {
            let tri_material = sim.triangle_materials(&mesh);
            sizes = Some(rank_table::RankSizes::measure(
                world,
                &mesh,
                sim.model.pressure(&tri_material),
            )?);
        }
    }
    progress.finish(sim);
    if let Some(sizes) = &sizes {
        for line in rank_table::lines(world, sizes, solve_cpu) {
            progress.note(&line);
        }
    }
    out.plot(world)?;
    if let Some(line) = sanity::check_collapse(sim, collapse, opts.until_step)? {
        progress.note(&line);
    }
    Ok(())
}
