//! Stop requests from the batch system: SIGTERM, or SIGUSR1 that Slurm sends before the time
//! limit (`--signal=USR1@120`). The run finishes its current step, checkpoints and exits 0.
//!
//! The handlers are installed first thing in `main`: a chained batch job can receive its
//! pre-limit signal while it is still starting MPI or loading the case, and a signal that
//! arrives before a handler exists kills the rank (SIGUSR1's default action).

use pfem_partition::{max_f64, Comm};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// Set by the handlers; shared by every `StopRequest`.
static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Installs the handlers (they only set a flag) once per process; later calls do nothing.
pub fn install_stop_handlers() -> Result<(), super::RunError> {
    if FLAG.get().is_some() {
        return Ok(());
    }
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGUSR1] {
        signal_hook::flag::register(sig, Arc::clone(&flag))
            .map_err(|error| super::RunError::Signal { signal: sig, error })?;
    }
    let _ = FLAG.set(flag);
    Ok(())
}

pub struct StopRequest {
    flag: Arc<AtomicBool>,
}

impl StopRequest {
    /// The process's stop flag, installing the handlers if `main` has not (a library caller).
    pub fn install() -> Result<StopRequest, super::RunError> {
        install_stop_handlers()?;
        let flag = FLAG.get().map(Arc::clone).unwrap_or_default();
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
