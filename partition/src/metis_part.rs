//! Ownership: METIS k-way partitioning of a distributed graph, and load imbalance.

use metis::{Graph, Idx};
use mpi::collective::SystemOperation;
use mpi::traits::*;

use crate::comm::{alltoallv, collective_result, comm_rank, comm_size, gather_to_root};
use crate::error::invalid;
use crate::{Comm, PartitionError};

/// METIS random seed: fixed so that the same graph always gets the same partition.
static METIS_LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
const METIS_SEED: Idx = 20_240_601;

/// Collective. Partition a distributed graph whose vertices are this rank's owned items (global
/// ids `ids`, arbitrary u64, not contiguous) with adjacency lists given by neighbour global ids
/// (`xadj`/`adjncy` CSR in local order; neighbours may be owned by any rank; edges symmetric).
///
/// Gathers the graph on rank 0, relabels it to 0..N in global-id order, calls METIS k-way with
/// `nparts` = communicator size and a fixed seed (so the result is deterministic), and scatters
/// the parts back. Returns the new owner rank per local vertex. With one rank returns all zeros
/// without calling METIS; with no more vertices than ranks, vertex i (in global-id order) goes to
/// rank i, also without METIS, which misbehaves on such graphs.
///
/// Self loops and duplicate edges are dropped and missing reverse edges added, so METIS always
/// sees a valid symmetric graph. Fails on every rank when a CSR is malformed, a global id is
/// duplicated, or a neighbour id is not a vertex of the graph. A rank with no vertices may pass
/// an empty `xadj` or `[0]`.
pub fn partition_graph(
    comm: &Comm,
    ids: &[u64],
    xadj: &[usize],
    adjncy: &[u64],
) -> Result<Vec<i32>, PartitionError> {
    collective_result(comm, validate_csr(ids, xadj, adjncy))?;
    let size = comm_size(comm);
    if size == 1 {
        return Ok(vec![0; ids.len()]);
    }

    let n_local = [ids.len() as u64];
    let mut id_deg = Vec::with_capacity(2 * ids.len());
    for (i, &id) in ids.iter().enumerate() {
        id_deg.extend([id, (xadj[i + 1] - xadj[i]) as u64]);
    }
    let counts = gather_to_root(comm, &n_local);
    let all_id_deg = gather_to_root(comm, &id_deg);
    let all_adj = gather_to_root(comm, adjncy);

    let mut scatter: Vec<Vec<i32>> = vec![Vec::new(); size];
    let mut root_result = Ok(());
    if comm_rank(comm) == 0 {
        let all_ids: Vec<u64> = all_id_deg.iter().step_by(2).copied().collect();
        let degrees: Vec<u64> = all_id_deg.iter().skip(1).step_by(2).copied().collect();
        match partition_gathered(&all_ids, &degrees, &all_adj, size) {
            Ok(parts) => {
                let mut start = 0usize;
                for (r, &c) in counts.iter().enumerate() {
                    let end = start + c as usize;
                    // Always in range: counts and ids were gathered from the same ranks.
                    scatter[r] = parts.get(start..end).unwrap_or_default().to_vec();
                    start = end;
                }
            }
            Err(e) => root_result = Err(e),
        }
    }
    let mut received = alltoallv(comm, &scatter);
    let parts = std::mem::take(&mut received[0]);
    let local = root_result.and_then(|()| {
        if parts.len() == ids.len() {
            Ok(parts)
        } else {
            Err(invalid(format!(
                "received {} parts for {} vertices",
                parts.len(),
                ids.len()
            )))
        }
    });
    collective_result(comm, local)
}

/// Collective. Load imbalance max(n_local)/mean(n_local) (1.0 when all empty).
pub fn imbalance(comm: &Comm, n_local: usize) -> f64 {
    let n = n_local as u64;
    let mut max = 0u64;
    let mut sum = 0u64;
    comm.all_reduce_into(&n, &mut max, SystemOperation::max());
    comm.all_reduce_into(&n, &mut sum, SystemOperation::sum());
    if sum == 0 {
        1.0
    } else {
        max as f64 * comm_size(comm) as f64 / sum as f64
    }
}

fn validate_csr(ids: &[u64], xadj: &[usize], adjncy: &[u64]) -> Result<(), PartitionError> {
    if ids.is_empty() && adjncy.is_empty() && xadj.len() <= 1 && xadj.iter().all(|&x| x == 0) {
        return Ok(());
    }
    if xadj.len() != ids.len() + 1 {
        return Err(invalid(format!(
            "graph: xadj has {} entries for {} vertices (expected {})",
            xadj.len(),
            ids.len(),
            ids.len() + 1
        )));
    }
    if xadj[0] != 0 || xadj.windows(2).any(|w| w[0] > w[1]) {
        return Err(invalid("graph: xadj must start at 0 and never decrease"));
    }
    if xadj[ids.len()] != adjncy.len() {
        return Err(invalid(format!(
            "graph: xadj ends at {} but adjncy has {} entries",
            xadj[ids.len()],
            adjncy.len()
        )));
    }
    Ok(())
}

/// Symmetric, loop-free CSR over vertices relabelled 0..N in global-id order.
#[derive(Debug, PartialEq)]
struct Relabelled {
    /// New label of each input vertex (input order).
    label: Vec<usize>,
    xadj: Vec<Idx>,
    adjncy: Vec<Idx>,
}

/// Relabels a gathered graph: `ids[i]` has `degrees[i]` neighbours, listed consecutively in
/// `adj` as global ids.
fn relabel(ids: &[u64], degrees: &[u64], adj: &[u64]) -> Result<Relabelled, PartitionError> {
    let n = ids.len();
    let mut sorted: Vec<u64> = ids.to_vec();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(invalid(format!("graph: global id {} appears twice", w[0])));
    }
    let label_of = |gid: u64| sorted.binary_search(&gid).ok();
    let label: Vec<usize> = ids.iter().map(|&g| label_of(g).unwrap_or(0)).collect();

    let total: u64 = degrees.iter().sum();
    if degrees.len() != n || total != adj.len() as u64 {
        return Err(invalid("graph: gathered degrees do not match adjacency"));
    }
    let mut edges: Vec<(usize, usize)> = Vec::with_capacity(2 * adj.len());
    let mut at = 0usize;
    for (i, &deg) in degrees.iter().enumerate() {
        let a = label[i];
        for &nb in &adj[at..at + deg as usize] {
            let b = label_of(nb).ok_or_else(|| {
                invalid(format!(
                    "graph: vertex {} lists neighbour {nb}, which is not a vertex",
                    ids[i]
                ))
            })?;
            if a != b {
                edges.push((a, b));
                edges.push((b, a));
            }
        }
        at += deg as usize;
    }
    edges.sort_unstable();
    edges.dedup();

    let too_large = || invalid(format!("graph with {n} vertices is too large for METIS"));
    let mut xadj: Vec<Idx> = Vec::with_capacity(n + 1);
    xadj.push(0);
    let mut e = 0usize;
    for v in 0..n {
        while e < edges.len() && edges[e].0 == v {
            e += 1;
        }
        xadj.push(Idx::try_from(e).map_err(|_| too_large())?);
    }
    let adjncy = edges
        .iter()
        .map(|&(_, b)| Idx::try_from(b).map_err(|_| too_large()))
        .collect::<Result<Vec<Idx>, _>>()?;
    Ok(Relabelled {
        label,
        xadj,
        adjncy,
    })
}

/// Partitions the gathered graph into `nparts`; returns the part of each input vertex.
fn partition_gathered(
    ids: &[u64],
    degrees: &[u64],
    adj: &[u64],
    nparts: usize,
) -> Result<Vec<i32>, PartitionError> {
    let g = relabel(ids, degrees, adj)?;
    let n = ids.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    if nparts <= 1 {
        return Ok(vec![0; n]);
    }
    let parts_idx = Idx::try_from(nparts).map_err(|_| invalid("too many parts for METIS"))?;
    let mut part: Vec<Idx> = vec![0; n];
    if n <= nparts {
        // METIS rejects or degenerates on fewer vertices than parts; one vertex per part in
        // global-id order is optimal then.
        for (l, p) in part.iter_mut().enumerate() {
            *p = l as Idx;
        }
    } else {
        // METIS keeps its random generator in process-global state: two threads partitioning at
        // once (tests, or a threaded caller) would make each other's results differ.
        let _serial = METIS_LOCK.lock().unwrap_or_else(|p| p.into_inner());
        Graph::new(1, parts_idx, &g.xadj, &g.adjncy)
            .map_err(|e| PartitionError::Metis(e.to_string()))?
            .set_option(metis::option::Seed(METIS_SEED))
            .part_kway(&mut part)
            .map_err(|e| PartitionError::Metis(e.to_string()))?;
    }
    g.label
        .iter()
        .map(|&l| {
            let p = part[l];
            if p >= 0 && p < parts_idx {
                Ok(p as i32)
            } else {
                Err(PartitionError::Metis(format!("part {p} out of range")))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csr_validation() {
        assert!(validate_csr(&[], &[], &[]).is_ok());
        assert!(validate_csr(&[], &[0], &[]).is_ok());
        assert!(validate_csr(&[5, 9], &[0, 1, 2], &[9, 5]).is_ok());
        assert!(validate_csr(&[5, 9], &[0, 1], &[9]).is_err());
        assert!(validate_csr(&[5, 9], &[1, 1, 2], &[9, 5]).is_err());
        assert!(validate_csr(&[5, 9], &[0, 2, 1], &[9, 5]).is_err());
        assert!(validate_csr(&[5, 9], &[0, 1, 3], &[9, 5]).is_err());
    }

    #[test]
    fn relabel_sorts_symmetrises_and_drops_loops() {
        // Vertex 30 lists 10 (twice) and itself; 10 lists nobody; 20 lists 30.
        let g = relabel(&[30, 10, 20], &[3, 0, 1], &[10, 10, 30, 30]).unwrap();
        assert_eq!(g.label, vec![2, 0, 1]);
        // Edges {10-30, 20-30} in labels {0-2, 1-2}.
        assert_eq!(g.xadj, vec![0, 1, 2, 4]);
        assert_eq!(g.adjncy, vec![2, 2, 0, 1]);
    }

    #[test]
    fn relabel_rejects_bad_graphs() {
        assert!(relabel(&[1, 1], &[0, 0], &[]).is_err());
        let e = relabel(&[1, 2], &[1, 0], &[7]).unwrap_err();
        assert!(e.to_string().contains("neighbour 7"));
        assert!(relabel(&[1, 2], &[1, 0], &[]).is_err());
    }

    fn lattice(nx: u64, ny: u64) -> (Vec<u64>, Vec<u64>, Vec<u64>) {
        let mut ids = Vec::new();
        let mut deg = Vec::new();
        let mut adj = Vec::new();
        let id = |i: u64, j: u64| 1000 + 7 * (j * nx + i);
        for j in 0..ny {
            for i in 0..nx {
                ids.push(id(i, j));
                let before = adj.len();
                if i > 0 {
                    adj.push(id(i - 1, j));
                }
                if i + 1 < nx {
                    adj.push(id(i + 1, j));
                }
                if j > 0 {
                    adj.push(id(i, j - 1));
                }
                if j + 1 < ny {
                    adj.push(id(i, j + 1));
                }
                deg.push((adj.len() - before) as u64);
            }
        }
        (ids, deg, adj)
    }

    #[test]
    fn metis_partition_is_balanced_and_deterministic() {
        let (ids, deg, adj) = lattice(20, 15);
        let a = partition_gathered(&ids, &deg, &adj, 4).unwrap();
        let b = partition_gathered(&ids, &deg, &adj, 4).unwrap();
        assert_eq!(a, b);
        let mut count = [0usize; 4];
        for &p in &a {
            count[p as usize] += 1;
        }
        let max = *count.iter().max().unwrap() as f64;
        assert!(max / 75.0 <= 1.1, "counts {count:?}");
    }

    #[test]
    fn fewer_vertices_than_parts() {
        let p = partition_gathered(&[9, 4], &[1, 1], &[4, 9], 3).unwrap();
        assert_eq!(p, vec![1, 0]);
        assert!(partition_gathered(&[], &[], &[], 3).unwrap().is_empty());
    }

    #[test]
    fn small_and_edgeless_graphs() {
        let p = partition_gathered(&[1, 2, 3, 4], &[1, 2, 2, 1], &[2, 1, 3, 2, 4, 3], 3).unwrap();
        assert!(p.iter().all(|&x| (0..3).contains(&x)), "{p:?}");
        let ids: Vec<u64> = (0..10).collect();
        let p = partition_gathered(&ids, &[0; 10], &[], 3).unwrap();
        assert!(p.iter().all(|&x| (0..3).contains(&x)), "{p:?}");
    }
}
