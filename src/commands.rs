//! The subcommands. Every one is collective: all ranks run it and all ranks exit with the same
//! code; the error is printed once, by rank 0.

use crate::case_file::{check_output, new_case, summarize, write_case};
use crate::cli::{default_out_dir, Command};
use crate::mesh::fingerprint::fingerprint;
use crate::petsc::Petsc;
use crate::run::{run, RunError, RunOptions, Simulation};
use crate::scene::{load_scene, scene_file};
use mpi::traits::Communicator;
use pfem_partition::{gather_to_root, sum_f64, Comm};

/// Runs a command under MPI; returns the process exit code.
pub fn execute(command: Command) -> i32 {
    let Some(universe) = mpi::initialize() else {
        eprintln!("pfem-mpi: MPI could not be initialised");
        return 1;
    };
    let world = universe.world();
    pfem_partition::abort_job_on_panic();
    // The end-of-command agreement has a communicator of its own: a rank that failed alone
    // must not have its agreement matched with a collective the others are waiting in.
    let errors = world.duplicate();
    let local = match command {
        Command::New { scene, out, sets } => new(&world, &scene, &out, &sets),
        Command::Info { file } => {
            if world.rank() == 0 {
                summarize(&file)
                    .map(|s| print!("{s}"))
                    .map_err(RunError::from)
            } else {
                Ok(())
            }
        }
        Command::Mesh { file } => mesh(&world, &file),
        Command::Plot { dir, window } => plot(&world, &dir, window),
        Command::Run {
            case,
            out,
            until_step,
            progress,
            verbose,
            petsc,
        } => {
            let out_dir = out.unwrap_or_else(|| default_out_dir(&case));
            match Petsc::initialize(&world, &petsc) {
                // `petsc` is dropped (PetscFinalize) before `universe` (MPI_Finalize).
                Ok(petsc) => run(
                    &world,
                    &petsc,
                    &RunOptions {
                        case,
                        out_dir,
                        until_step,
                        progress,
                        verbose,
                    },
                ),
                Err(e) => Err(e.into()),
            }
        }
        Command::Help | Command::Version | Command::Schema => Ok(()),
    };
    match crate::run::agree_or_abort(&errors, local) {
        Ok(()) => 0,
        Err(e) => {
            if world.rank() == 0 {
                eprintln!("pfem-mpi: error: {e}");
            }
            e.exit_code()
        }
    }
}

/// Collective. Rank 0 generates the particles; all ranks write the file together. The output
/// is checked first, so a refused destination costs no particle generation.
fn new(world: &Comm, scene: &str, out: &std::path::Path, sets: &[String]) -> Result<(), RunError> {
    check_output(world, out, scene_file(scene))?;
    let (scene_v, _toml) = load_scene(scene, sets)?;
    let (header, mut set) = new_case(&scene_v, scene);
    if world.rank() != 0 {
        set = Default::default();
    }
    write_case(world, out, &header, &set)?;
    if world.rank() == 0 {
        if let Some(n) = scene_v.contact.max_augmentations {
            eprintln!(
                "pfem-mpi: warning: scene '{scene}': contact.max_augmentations = {n} is no longer \
                 read: contact is solved inside every Newton iteration"
            );
        }
        for name in crate::scene::zones::unused_materials(&scene_v) {
            eprintln!(
                "pfem-mpi: warning: scene '{scene}': [[material]] \"{name}\" is named by no \
                 body.zones entry"
            );
        }
        println!(
            "wrote {} ({} particles, scene {})",
            out.display(),
            header_particles(&set),
            scene_v.name
        );
        // Probes follow the point loads in `tracked_gids`.
        let probes = header.tracked_gids.iter().skip(scene_v.point_load.len());
        for (probe, gid) in scene_v.probe.iter().zip(probes) {
            if let Some(i) = set.gid.iter().position(|g| g == gid) {
                let x = set.position[i];
                println!(
                    "probe {} follows particle {gid} at [{}, {}]",
                    probe.name, x[0], x[1]
                );
            }
        }
    }
    Ok(())
}

fn header_particles(set: &crate::case_file::ParticleSet) -> usize {
    set.gid.len()
}

/// Rank 0 draws the pictures of a run folder.
fn plot(
    world: &Comm,
    dir: &std::path::Path,
    window: Option<crate::plot::Window>,
) -> Result<(), RunError> {
    if world.rank() != 0 {
        return Ok(());
    }
    let files = crate::plot::plot_run_in(dir, window)?;
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

/// Collective. Meshes the case once and prints the rank-count independent fingerprint.
fn mesh(world: &Comm, file: &std::path::Path) -> Result<(), RunError> {
    let mut sim = Simulation::load(world, file)?;
    let mesh = sim.remesh(world)?;
    let owned: Vec<u64> = (0..mesh.tris.len())
        .filter(|&t| mesh.tri_owned[t])
        .flat_map(|t| mesh.tri_key(t))
        .collect();
    let boundary = mesh
        .boundary_edges
        .iter()
        .filter(|e| {
            let (a, b) = (e[0] as usize, e[1] as usize);
            let lo = if mesh.gids[a] < mesh.gids[b] { a } else { b };
            lo < mesh.n_owned
        })
        .count();
    let counts = sum_f64(world, &[mesh.n_owned as f64, boundary as f64]);
    let all = gather_to_root(world, &owned);
    if world.rank() == 0 {
        let mut tris: Vec<[u64; 3]> = all.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        tris.sort_unstable();
        println!(
            "fingerprint {:016x} particles {} triangles {} boundary_edges {}",
            fingerprint(&tris),
            counts[0] as u64,
            tris.len(),
            counts[1] as u64
        );
    }
    Ok(())
}
