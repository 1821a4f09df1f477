//! The per-rank sizes printed after the end-of-run line: owned and halo particles, dofs and
//! triangles, CPU time and peak memory of every rank, so that weak scaling (halo against owned
//! size, memory per particle) can be measured from any run (bench/weak_scaling.sh,
//! bench/CLUSTER.md).

use super::RunError;
use crate::mesh::LocalMesh;
use crate::solve::{DofMap, Pressure};
use mpi::traits::Communicator;
use pfem_partition::{gather_to_root, Comm};

/// This rank's share of the mesh of the last solved increment.
#[derive(Debug, Clone, Copy, Default)]
pub struct RankSizes {
    pub owned: u64,
    /// Halo particles this rank received to triangulate its part (the mesh's ghost points).
    pub ghost: u64,
    pub owned_dofs: u64,
    /// Dofs of this rank's triangles that other ranks own: the solver's halo, what a
    /// matrix-vector product and the assembly exchange with the neighbours.
    pub ghost_dofs: u64,
    pub owned_tris: u64,
    /// Triangles this rank assembles (owned, and those of other ranks touching an owned particle).
    pub local_tris: u64,
}

impl RankSizes {
    /// Collective. Measures `mesh`, numbering its dofs again the way the solve does (the
    /// solve's numbering is dropped with its increment, and keeping it alive would add to the
    /// peak memory this table reports).
    pub fn measure(
        world: &Comm,
        mesh: &LocalMesh,
        pressure: Pressure,
    ) -> Result<RankSizes, RunError> {
        let dofs = DofMap::build(world, mesh, pressure)?;
        let local_dofs: usize = (0..dofs.n_nodes()).map(|n| dofs.ndof(n)).sum();
        Ok(RankSizes {
            owned: mesh.n_owned as u64,
            ghost: (mesh.points.len() - mesh.n_owned) as u64,
            owned_dofs: dofs.n_owned_dofs as u64,
            ghost_dofs: (local_dofs - dofs.n_owned_dofs) as u64,
            owned_tris: mesh.n_owned_tris() as u64,
            local_tris: mesh.tris.len() as u64,
        })
    }
}

/// Peak resident set size of this process in kB (`VmHWM` of /proc/self/status); 0 where there is
/// no /proc (the table then shows 0 rather than failing a finished run).
pub fn peak_rss_kb() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or(0)
}

/// User plus system CPU seconds of this process so far, from /proc/self/stat (fields 14 and 15,
/// in clock ticks of 1/100 s: USER_HZ is 100 on every Linux ABI, and reading it with sysconf
/// would need `unsafe` outside an FFI module). 0 where there is no /proc.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // The command name (field 2) may hold spaces; the fields after its closing parenthesis do not.
    let rest = stat.rsplit_once(')').map(|(_, r)| r).unwrap_or("");
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // `rest` starts at field 3 (state), so utime (14) and stime (15) are at 11 and 12.
    let ticks = |i: usize| -> f64 { fields.get(i).and_then(|v| v.parse().ok()).unwrap_or(0.0) };
    (ticks(11) + ticks(12)) / 100.0
}

/// Values per rank in the gather, in column order.
const COLUMNS: usize = 9;

/// Collective. Gathers every rank's sizes, the CPU seconds of its solve phases (`solve_cpu`)
/// and of the whole process, and its peak RSS on rank 0, which prints one line per rank under a
/// header. No word of it is one the progress lines' parsers look for ("particles ", "Newton",
/// "cpu_s", ...): tests and bench scripts grep the whole output.
pub fn lines(world: &Comm, sizes: &RankSizes, solve_cpu: f64) -> Vec<String> {
    // Milliseconds, so that one u64 gather carries every column.
    let ms = |s: f64| (s * 1000.0).round().max(0.0) as u64;
    let local: [u64; COLUMNS] = [
        sizes.owned,
        sizes.ghost,
        sizes.owned_dofs,
        sizes.ghost_dofs,
        sizes.owned_tris,
        sizes.local_tris,
        ms(solve_cpu),
        ms(cpu_seconds()),
        peak_rss_kb(),
    ];
    let all = gather_to_root(world, &local);
    if world.rank() != 0 {
        return Vec::new();
    }
    let mut lines = vec![
        "per-rank sizes of the last solved mesh (CPU in seconds: solve phases, whole process; peak RSS from VmHWM):".to_string(),
    ];
    lines.push(format!(
        "{:>5} {:>10} {:>9} {:>10} {:>10} {:>10} {:>10} {:>9} {:>9} {:>11}",
        "rank",
        "owned",
        "ghost",
        "dofs",
        "ghost_dofs",
        "owned_tris",
        "local_tris",
        "solve_cpu",
        "cpu_total",
        "peak_rss_MB"
    ));

    for (rank, row) in all.chunks_exact(COLUMNS).enumerate() {
        lines.push(format!(
            "{rank:>5} {:>10} {:>9} {:>10} {:>10} {:>10} {:>10} {:>9.2} {:>9.2} {:>11.1}",
            row[0],
            row[1],
            row[2],
            row[3],
            row[4],
            row[5],
            row[6] as f64 / 1000.0,
            row[7] as f64 / 1000.0,
            row[8] as f64 / 1024.0
        ));
    }
    lines
}
