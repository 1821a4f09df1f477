use pfem_mpi::cli::{self, Command};
use pfem_mpi::commands;
use pfem_mpi::run::RunError;

/// Installs the stop handlers from the executable's `.preinit_array`, which the dynamic loader
/// runs once the ~100 libraries of PETSc and MPI are mapped but before their constructors:
/// measured here, `main` starts about 50 ms after `exec`, and a SIGUSR1 that mpirun forwards
/// in that window would kill the rank. `main` installs them again and reports a failure.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".preinit_array"]
static EARLY_STOP_HANDLERS: extern "C" fn() = early_stop_handlers;

#[cfg(target_os = "linux")]
extern "C" fn early_stop_handlers() {
    let _ = pfem_mpi::run::install_stop_handlers();
}

fn main() {
    // Before anything else: a signal that comes while MPI starts or the case loads must set the
    // stop flag, not kill the rank.
    if let Err(e) = pfem_mpi::run::install_stop_handlers() {
        eprintln!("pfem-mpi: error: {e}");
        std::process::exit(e.exit_code());
    }
    let args: Vec<String> = std::env::args().skip(1).collect();
    let command = match cli::parse(&args) {
        Ok(c) => c,
        Err(e) => {
            let e = RunError::Usage(e);
            eprintln!("pfem-mpi: {e}\n{}", cli::usage());
            std::process::exit(e.exit_code());
        }
    };
    match command {
        Command::Help => println!("{}", cli::usage()),
        Command::Version => println!("pfem-mpi {}", env!("CARGO_PKG_VERSION")),
        Command::Schema => print!("{}", pfem_mpi::scene::REFERENCE),
        other => std::process::exit(commands::execute(other)),
    }
}
