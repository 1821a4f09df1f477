//! Stop requests from the batch system: SIGTERM, or SIGUSR1 that Slurm sends before the time
//! limit (`--signal=USR1@120`). The run finishes its current step, checkpoints and exits 0.

use pfem_partition::{max_f64, Comm};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

pub struct StopRequest {
    flag: Arc<AtomicBool>,
}

impl StopRequest {
    /// Installs the handlers (they only set a flag).
    pub fn install() -> Result<StopRequest, super::RunError> {
        let flag = Arc::new(AtomicBool::new(false));
        for sig in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGUSR1] {
            signal_hook::flag::register(sig, Arc::clone(&flag))
                .map_err(|error| super::RunError::Signal { signal: sig, error })?;
        }
        Ok(StopRequest { flag })
    }

    /// Collective. Whether any rank was asked to stop: signals reach ranks at different moments,
    /// and all must stop after the same step.
    pub fn requested(&self, world: &Comm) -> bool {
        let mine = if self.flag.load(Ordering::Relaxed) {
            1.0
        } else {
            0.0
        };
        max_f64(world, mine) > 0.0
    }
}
