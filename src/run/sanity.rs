//! Checks that a run does what it was asked and that what it reports means something: a
//! request that would run no step, ...

use super::{RunOptions, Simulation};

/// Refuses an `--until-step` that leaves nothing to run: 0, or a step the case has already
/// reached. Not collective: every rank holds the same header, so every rank agrees.
pub(super) fn check_until_step(opts: &RunOptions, sim: &Simulation) -> Result<(), String> {
    let Some(until) = opts.until_step else {
        return Ok(());
    };
    let (step, total) = (sim.step(), sim.total_steps());
    if until > step {
        return Ok(());
    }
    let why = if until == 0 {
        "a run stops after a step it has made".to_string()
    } else {
        format!("{} is already at step {step}", opts.case.display())
    };
    let instead = if step < total {
        format!("give a step from {} to {total} (steps.count)", step + 1)
    } else {
        format!("the case has made all its steps (steps.count = {total})")
    };
    Err(format!(
        "--until-step {until}: nothing to run, {why}; {instead}"
    ))
}
