//! The PFEM step loop (the method's Fig. 1): remesh, map, solve, update, output, checkpoint.

mod contact;
mod output;
mod progress;
mod refinement;
mod restart;
mod sanity;
mod signals;
mod simulation;
mod step;
mod test_hooks;

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
}

/// Collective. Runs the case to its last step (or `until_step`, or the step during which SIGTERM
/// or SIGUSR1 arrived), ending with a checkpoint.
pub fn run(world: &Comm, petsc: &Petsc, opts: &RunOptions) -> Result<(), String> {
    let stop = signals::StopRequest::install()?;
    let rank = world.rank();
    let fault = |phase: &str, step: u64| test_hooks::inject(rank, phase, step);
    fault("load", 0)?;
    let mut sim = Simulation::load(world, &opts.case)?;
    sanity::check_until_step(opts, &sim)?;
    let mut out = output::Output::open(world, &sim, &opts.out_dir)?;
    let mut progress = Progress::new(world, sim.total_steps());
    let mut last = opts.until_step.unwrap_or(u64::MAX).min(sim.total_steps());
    while sim.step() < last {
        let mut t = PhaseTimer::default();
        let next = sim.step() + 1;
        let mut mesh = t.time("remesh", || {
            fault("remesh", next)?;
            sim.remesh(world)
        })?;
        fault("map", next)?;
        let states = t.time("map", || sim.map(&mesh));
        let report = t.time("solve", || {
            fault("solve", next)?;
            sim.advance(world, petsc, &mut mesh, states)
        })?;
        sanity::check_step(world, &sim, &mesh, &report)?;
        if stop.requested(world) {
            last = sim.step();
        }
        t.time("output", || {
            fault("output", next)?;
            out.record(world, &sim)
                .and_then(|_| out.fields_if_due(world, &sim, &mesh, last))
        })?;
        t.time("checkpoint", || {
            fault("checkpoint", next)?;
            out.checkpoint_if_due(world, &sim, last)
        })?;
        t.time("balance", || {
            fault("balance", next)?;
            sim.rebalance_if_needed(world)
        })?;
        progress.step(&sim, &report, &t);
    }
    progress.finish(&sim);
    out.plot(world)
}
