//! Helpers for tests that run the built binary, under mpirun when ranks > 1 (MPI can be
//! initialised only once per process, so multi-rank tests launch processes).
#![allow(dead_code)]

mod launch;
mod prereq;
mod progress;
mod rng;
#[allow(unused_imports)]
pub use launch::{example_binary, mpirun_example, run_captured};
#[allow(unused_imports)]
pub use prereq::{in_ci, prerequisite, python_has, tool_runs};
#[allow(unused_imports)]
pub use progress::{json_objects, json_steps};
#[allow(unused_imports)]
pub use rng::Rng;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

pub fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_pfem-mpi")
}

/// `pfem-mpi` under `mpirun -n ranks`, allowed as root, oversubscribed and unbound (Open MPI
/// would pin rank 0 of every concurrent test's job to core 0, where they starve each other),
/// one OpenMP thread per rank.
pub fn mpirun(ranks: usize) -> Command {
    let mut c = Command::new("mpirun");
    c.args([
        "-n",
        &ranks.to_string(),
        "--oversubscribe",
        "--bind-to",
        "none",
        bin(),
    ]);
    with_mpi_env(c)
}

/// `pfem-mpi` as a plain process for one rank, under [`mpirun`] for more.
pub fn pfem(ranks: usize) -> Command {
    if ranks == 1 {
        with_mpi_env(Command::new(bin()))
    } else {
        mpirun(ranks)
    }
}

/// Unbound, a rank would see both cores and the OpenMP threads of SuperLU_dist would add in a
/// varying order: the bitwise-reproducibility tests need one thread per rank.
fn with_mpi_env(mut c: Command) -> Command {
    c.env("OMP_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1");
    c
}

/// A fresh directory under the target dir, unique per test.
pub fn workdir(name: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "{name}-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::SeqCst)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create test dir");
    dir
}

/// Runs `pfem-mpi args` on `ranks` ranks (plain process for 1), in `dir`.
pub fn run(dir: &Path, ranks: usize, args: &[&str]) -> Output {
    let mut cmd = pfem(ranks);
    cmd.args(args).current_dir(dir);
    cmd.output().expect("launch pfem-mpi")
}

/// Like `run`, failing the test with the process output unless it succeeded.
pub fn ok(dir: &Path, ranks: usize, args: &[&str]) -> String {
    let out = run(dir, ranks, args);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "pfem-mpi {args:?} on {ranks} ranks failed\nstdout:\n{stdout}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// history.csv as (header, rows).
pub fn history(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
        .collect();
    (header, rows)
}

/// Two runs' histories on the same path: column `col` of every row within `rel` (relative), the
/// row named by its column 1 (the depth or displacement) when not.
pub fn same_path(a: &[Vec<f64>], b: &[Vec<f64>], col: usize, rel: f64) {
    assert_eq!(a.len(), b.len(), "rows");
    for (x, y) in a.iter().zip(b) {
        assert!(
            (x[col] - y[col]).abs() <= rel * x[col].abs(),
            "at {}: {} against {}",
            x[1],
            x[col],
            y[col]
        );
    }
}

/// `pfem-mpi new cantilever -o c.h5` with spacing `h` (m), `steps` load steps and any further
/// `--set key=value` overrides.
pub fn cantilever_case(dir: &Path, h: &str, steps: u32, sets: &[&str]) {
    let (spacing, steps) = (format!("mesh.h={h}"), format!("steps.count={steps}"));
    let mut args = vec![
        "new",
        "cantilever",
        "-o",
        "c.h5",
        "--set",
        &spacing,
        "--set",
        &steps,
    ];
    for s in sets {
        args.extend(["--set", s]);
    }
    ok(dir, 1, &args);
}

/// `pfem-mpi new cantilever -o c.h5` with h = 0.25 m (205 particles) and `steps` load steps, plus
/// any further `--set key=value` overrides: the small case most run tests need.
pub fn small_cantilever(dir: &Path, steps: u32, sets: &[&str]) {
    cantilever_case(dir, "0.25", steps, sets);
}

/// `pfem-mpi new footing -o f.h5` on a coarse cloud (0.5 m, 0.25 m within 4 m of the edge: B/8)
/// with sharp edges (radius 1 % of B; with or without the soil's node on each corner,
/// `corner_nodes`), pushed `depth` m in `steps` steps. The built-in's 0.2 m
/// edge radius is nearly this coarse spacing: at it the 2-rank run stopped at z/B = 0.1
/// (bench/VALIDATION.md).
pub fn coarse_sharp_footing(dir: &Path, depth: f64, steps: u32, corner_nodes: bool) {
    let stages = format!("rigid[0].stages=[{{to=[0.0,{}],steps={steps}}}]", -depth);
    let polygon = format!(
        "rigid[0].polygon={{vertices=[[-1.0,10.0],[1.0,10.0],[1.0,10.5],[-1.0,10.5]],\
         corner_radius=0.02,corner_nodes={corner_nodes}}}"
    );
    ok(
        dir,
        1,
        &[
            "new",
            "footing",
            "-o",
            "f.h5",
            "--set",
            "mesh.h=0.5",
            "--set",
            "mesh.fine=[{origin=[0.0,6.0],size=[4.0,4.0],h=0.25}]",
            "--set",
            &stages,
            "--set",
            &polygon,
        ],
    );
}

/// Runs the Python `body` with h5py and the HDF5 file open as `f` (read-only) and returns every
/// line it printed as numbers.
pub fn h5py_rows(file: &Path, body: &str) -> Vec<Vec<f64>> {
    let script = format!("import h5py, sys\nf = h5py.File(sys.argv[1], 'r')\n{body}");
    let out = Command::new("python3")
        .args(["-c", &script, &file.display().to_string()])
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "h5py on {}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| {
            l.split_whitespace()
                .map(|x| x.parse().unwrap_or_else(|e| panic!("{x:?}: {e}")))
                .collect()
        })
        .collect()
}
