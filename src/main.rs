use pfem_mpi::cli::{self, Command};
use pfem_mpi::commands;
use pfem_mpi::run::RunError;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let command = match cli::parse(&args) {
        Ok(c) => c,
        Err(e) => {
            let e = RunError::Usage(e);
            eprintln!("pfem-mpi: {e}\n{}", cli::USAGE);
            std::process::exit(e.exit_code());
        }
    };
    match command {
        Command::Help => println!("{}", cli::USAGE),
        Command::Version => println!("pfem-mpi {}", env!("CARGO_PKG_VERSION")),
        other => std::process::exit(commands::execute(other)),
    }
}
