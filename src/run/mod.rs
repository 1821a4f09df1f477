//! The PFEM step loop (the method's Fig. 1): remesh, map, solve, update, output, checkpoint.

mod progress;
mod refinement;
mod simulation;

pub use simulation::{Simulation, StepReport};

use crate::petsc::Petsc;
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

/// Collective. Runs the case to its last step (or `until_step`).
pub fn run(world: &Comm, petsc: &Petsc, opts: &RunOptions) -> Result<(), String> {
    let mut sim = Simulation::load(world, &opts.case)?;
    let mut out = simulation::Output::open(world, &sim, &opts.out_dir)?;
    let mut progress = Progress::new(world, sim.total_steps());
    let last = opts
        .until_step
        .map_or(sim.total_steps(), |k| k.min(sim.total_steps()));
    while sim.step() < last {
        let mut t = PhaseTimer::default();
        let mesh = t.time("remesh", || sim.remesh(world))?;
        let states = t.time("map", || sim.map(&mesh));
        let solved = t.time("solve", || sim.solve(world, petsc, &mesh, &states))?;
        let report = t.time("update", || sim.update(world, &mesh, solved))?;
        t.time("output", || out.record(world, &sim))?;
        t.time("checkpoint", || out.checkpoint_if_due(world, &sim, last))?;
        t.time("balance", || sim.rebalance_if_needed(world))?;
        progress.step(&sim, &report, &t);
    }
    progress.finish(&sim);
    Ok(())
}
