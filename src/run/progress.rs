//! Rank-0 progress lines with a timer per phase, as in deal.II's step-40.

use super::{Simulation, StepReport};
use mpi::traits::Communicator;
use pfem_partition::Comm;
use std::io::IsTerminal;
use std::time::Instant;

#[derive(Default)]
pub struct PhaseTimer {
    phases: Vec<(&'static str, f64)>,
}

impl PhaseTimer {
    pub fn time<R>(&mut self, name: &'static str, f: impl FnOnce() -> R) -> R {
        let t = Instant::now();
        let r = f();
        self.phases.push((name, t.elapsed().as_secs_f64()));
        r
    }

    pub fn total(&self) -> f64 {
        self.phases.iter().map(|p| p.1).sum()
    }
}

pub struct Progress {
    root: bool,
    every: u64,
    total: u64,
    started: Instant,
    newton: usize,
    linear: usize,
    contact: f64,
}

impl Progress {
    pub fn new(world: &Comm, total: u64) -> Progress {
        let tty = std::io::stdout().is_terminal();
        Progress {
            root: world.rank() == 0,
            every: if tty { 1 } else { (total / 20).max(1) },
            total,
            started: Instant::now(),
            newton: 0,
            linear: 0,
            contact: 0.0,
        }
    }

    pub fn step(&mut self, sim: &Simulation, r: &StepReport, t: &PhaseTimer) {
        self.newton += r.newton_iterations;
        self.linear += r.linear_iterations;
        self.contact += r.contact_seconds;
        let step = sim.step();
        if !self.root || (!step.is_multiple_of(self.every) && step != self.total) {
            return;
        }
        let phases: Vec<String> = t
            .phases
            .iter()
            .map(|(n, s)| format!("{n} {s:.3}"))
            .collect();
        let done = step.saturating_sub(sim.first_step()) as f64;
        let left =
            (self.total - step) as f64 * self.started.elapsed().as_secs_f64() / done.max(1.0);
        println!(
            "step {step:>5}/{} load {:.4} newton {:>2}{} linear {} |R| {:.2e} particles {} triangles {} remapped {} | {} (contact {:.3}, contact switches {}) | step {:.3}s left {:.0}s",
            self.total,
            sim.load_factor(),
            r.newton_iterations,
            if r.cuts > 0 { format!(" (cut {}x)", r.cuts) } else { String::new() },
            r.linear_iterations,
            r.residual_norm,
            r.particles,
            r.triangles,
            r.remapped,
            phases.join(" "),
            r.contact_seconds,
            r.contact_switches,
            t.total(),
            left
        );
    }

    pub fn finish(&self, sim: &Simulation) {
        if self.root {
            println!(
                "done: step {} in {:.2} s, {} Newton iterations, {} linear iterations, contact {:.2} s",
                sim.step(),
                self.started.elapsed().as_secs_f64(),
                self.newton,
                self.linear,
                self.contact
            );
        }
    }
}
