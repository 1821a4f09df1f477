//! What rank 0 shows while a run steps: a progress bar on a terminal, the per-step lines in a
//! batch job's output, or JSON for scripts (`--progress`), with a timer per phase as in deal.II's
//! step-40. Every line also goes to `DIR/run.log`, the per-step line of every step in full.

use super::progress_json::{self, StepFacts};
use super::run_log::RunLog;
use super::{RunError, RunOptions, Simulation, StepReport};
use crate::cli::ProgressMode;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use mpi::traits::Communicator;
use pfem_partition::Comm;
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

/// Where rank 0's lines go on stdout.
enum Shown {
    /// A terminal: the bar, with the full lines above it under `--verbose`.
    Bar(ProgressBar),
    /// Not a terminal (or `--progress lines`): the per-step line every `every` steps, and the
    /// run's last step's (kept until the next is printed).
    Lines { every: u64, unshown: Option<String> },
    /// `--progress json`: one object per step and one at the end, nothing else.
    Json,
}

pub struct Progress {
    /// Rank 0's; None on the other ranks, which show nothing.
    shown: Option<Shown>,
    log: Option<RunLog>,
    verbose: bool,
    total: u64,
    started: Instant,
    newton: usize,
    linear: usize,
    contact: f64,
}

impl Progress {
    /// Collective. Rank 0 opens `DIR/run.log` (after the output folder was accepted) and starts
    /// its record of this run in it.
    pub fn new(world: &Comm, sim: &Simulation, opts: &RunOptions) -> Result<Progress, RunError> {
        let total = sim.total_steps();
        let root = world.rank() == 0;
        let (mut log, local) = match root.then(|| RunLog::open(&opts.out_dir)) {
            Some(Ok(log)) => (Some(log), None),
            Some(Err(e)) => (None, Some(e)),
            None => (None, None),
        };
        super::error::agree(world, local)?;
        if let Some(log) = log.as_mut() {
            log.line(&format!(
                "pfem-mpi {}: {} on {} rank(s), from step {} of {total}, into {}",
                env!("CARGO_PKG_VERSION"),
                opts.case.display(),
                world.size(),
                sim.step(),
                opts.out_dir.display()
            ));
        }
        let shown = root.then(|| match opts.progress {
            ProgressMode::Json => Shown::Json,
            ProgressMode::Auto if super::terminal::stdout_is_terminal() => {
                Shown::Bar(bar(sim.step(), total))
            }
            ProgressMode::Auto | ProgressMode::Lines => Shown::Lines {
                every: if opts.verbose { 1 } else { every(total) },
                unshown: None,
            },
        });
        Ok(Progress {
            shown,
            log,
            verbose: opts.verbose,
            total,
            started: Instant::now(),
            newton: 0,
            linear: 0,
            contact: 0.0,
        })
    }

    /// A line for a person (rank 0): to the log, and to the terminal except under JSON.
    pub fn note(&mut self, line: &str) {
        if let Some(log) = self.log.as_mut() {
            log.line(line);
        }
        match &self.shown {
            Some(Shown::Bar(bar)) => bar.println(line),
            Some(Shown::Lines { .. }) => println!("{line}"),
            Some(Shown::Json) | None => {}
        }
    }

    /// After every step. `history` is the step's `history.csv` row by column name (rank 0).
    pub fn step(
        &mut self,
        sim: &Simulation,
        r: &StepReport,
        t: &PhaseTimer,
        history: Option<(&[String], &[f64])>,
    ) {
        self.newton += r.newton_iterations;
        self.linear += r.linear_iterations;
        self.contact += r.contact_seconds;
        let Some(shown) = self.shown.as_mut() else {
            return;
        };
        let step = sim.step();
        let done = step.saturating_sub(sim.first_step()) as f64;
        let left = self.total.saturating_sub(step) as f64 * self.started.elapsed().as_secs_f64()
            / done.max(1.0);
        let line = step_line(step, self.total, sim.load_factor(), r, t, left);
        match shown {
            Shown::Bar(bar) => {
                if self.verbose {
                    bar.println(&line);
                }
                bar.set_message(bar_message(sim.load_factor(), left, r, t.total()));
                bar.set_position(step);
            }
            Shown::Lines { every, unshown } => {
                if step.is_multiple_of(*every) || step == self.total {
                    println!("{line}");
                    *unshown = None;
                } else {
                    *unshown = Some(line.clone());
                }
            }
            Shown::Json => println!(
                "{}",
                progress_json::step_object(&StepFacts {
                    step,
                    steps: self.total,
                    time: sim.time(),
                    load_factor: sim.load_factor(),
                    report: r,
                    phases: &t.phases,
                    wall: t.total(),
                    left,
                    history,
                })
            ),
        }
        if let Some(log) = self.log.as_mut() {
            log.line(&line);
        }
    }

    /// After the last step: the bar stays where it ended (a run stopped by `--until-step` or a
    /// signal short of the end) above the end-of-run line; the lines end with the last step's,
    /// so a script reading the output sees where the run stopped.
    pub fn finish(&mut self, sim: &Simulation) {
        let wall = self.started.elapsed().as_secs_f64();
        match self.shown.as_mut() {
            Some(Shown::Bar(bar)) => bar.abandon(),
            Some(Shown::Lines { unshown, .. }) => {
                if let Some(line) = unshown.take() {
                    println!("{line}");
                }
            }
            _ => {}
        }
        if let Some(Shown::Json) = &self.shown {
            println!(
                "{}",
                progress_json::done_object(
                    sim.step(),
                    wall,
                    self.newton,
                    self.linear,
                    self.contact
                )
            );
        }
        self.note(&format!(
            "done: step {} in {wall:.2} s, {} Newton iterations, {} linear iterations, contact \
             {:.2} s",
            sim.step(),
            self.newton,
            self.linear,
            self.contact
        ));
    }

    /// The error the run ends with, for the log (stderr gets it from the caller). The bar is
    /// left where it stopped, on a line of its own.
    pub fn failed(&mut self, e: &RunError) {
        if let Some(Shown::Bar(bar)) = &self.shown {
            bar.abandon();
        }
        if let Some(log) = self.log.as_mut() {
            log.line(&format!("pfem-mpi: error: {e}"));
        }
    }
}

/// The per-step lines of a run that is not watched: about one per 5 % of the run, so a batch
/// job's output stays short (`DIR/run.log` has every step).
fn every(total: u64) -> u64 {
    (total / 20).max(1)
}

/// The bar, drawn on stdout once its first message is set (so it never shows an empty one).
fn bar(step: u64, total: u64) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
    let style = ProgressStyle::with_template("[{bar:20}] step {pos}/{len}  {msg}")
        .expect("a valid template")
        .progress_chars("=> ");
    bar.set_style(style);
    bar.set_position(step);
    bar.set_message("first step running");
    bar.set_draw_target(ProgressDrawTarget::stdout());
    bar
}

/// What the bar says after a step, short enough for 80 columns with the bar.
fn bar_message(load: f64, left: f64, r: &StepReport, wall: f64) -> String {
    let cut = if r.cuts > 0 {
        format!(" (cut {}x)", r.cuts)
    } else {
        String::new()
    };
    format!(
        "load {load:.4}  ETA {}  last: {} Newton{cut}, {wall:.2} s",
        duration(left),
        r.newton_iterations
    )
}

/// The full line of a step: what it did, its residual and mesh, and the seconds of each phase.
fn step_line(
    step: u64,
    total: u64,
    load: f64,
    r: &StepReport,
    t: &PhaseTimer,
    left: f64,
) -> String {
    let phases: Vec<String> = t
        .phases
        .iter()
        .map(|(n, s)| format!("{n} {s:.3}"))
        .collect();
    format!(
        "step {step:>5}/{total} load {load:.4} newton {:>2}{} linear {} |R| {:.2e} particles {} triangles {} remapped {} | {} (contact {:.3}, contact switches {}) | step {:.3}s left {left:.0}s",
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
    )
}

/// A time left as a person reads it: `45s`, `2m 13s`, `1h 02m`.
fn duration(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..60 => format!("{s}s"),
        60..3600 => format!("{}m {:02}s", s / 60, s % 60),
        _ => format!("{}h {:02}m", s / 3600, s % 3600 / 60),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_read_as_a_person_would() {
        assert_eq!(duration(0.4), "0s");
        assert_eq!(duration(45.0), "45s");
        assert_eq!(duration(133.0), "2m 13s");
        assert_eq!(duration(3720.0), "1h 02m");
        assert_eq!(duration(-3.0), "0s");
    }

    #[test]
    fn the_bar_says_load_eta_and_the_last_step() {
        let r = StepReport {
            newton_iterations: 5,
            ..StepReport::default()
        };
        assert_eq!(
            bar_message(0.25, 133.0, &r, 1.234),
            "load 0.2500  ETA 2m 13s  last: 5 Newton, 1.23 s"
        );
    }

    #[test]
    fn unwatched_runs_print_about_twenty_lines() {
        assert_eq!(every(10), 1);
        assert_eq!(every(100), 5);
        assert_eq!(every(1000), 50);
    }

    #[test]
    fn the_step_line_keeps_its_fields() {
        let r = StepReport {
            newton_iterations: 2,
            cuts: 3,
            particles: 608,
            ..StepReport::default()
        };
        let mut t = PhaseTimer::default();
        t.time("remesh", || ());
        let line = step_line(10, 10, 1.0, &r, &t, 0.0);
        assert!(line.starts_with("step    10/10 load 1.0000 newton  2 (cut 3x) linear 0"));
        assert!(line.contains(" particles 608 ") && line.contains("| remesh 0.000"));
    }
}
