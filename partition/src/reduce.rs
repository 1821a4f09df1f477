//! Small collectives on plain numbers: sums, maxima, all-gathers, and request/response with
//! two-word keys.

use mpi::collective::SystemOperation;
use mpi::datatype::PartitionMut;
use mpi::traits::*;
use mpi::Count;

use crate::comm::{alltoallv, comm_size};
use crate::error::invalid;
use crate::{Comm, PartitionError};

/// Collective. Element-wise sum over ranks (every rank gets the result).
pub fn sum_f64(comm: &Comm, local: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; local.len()];
    comm.all_reduce_into(local, &mut out[..], SystemOperation::sum());
    out
}

/// Collective. Maximum over ranks.
pub fn max_f64(comm: &Comm, local: f64) -> f64 {
    let mut out = 0.0;
    comm.all_reduce_into(&local, &mut out, SystemOperation::max());
    out
}

/// Collective. Concatenation of every rank's `local`, in rank order, on every rank.
pub fn allgather_u64(comm: &Comm, local: &[u64]) -> Vec<u64> {
    let size = comm_size(comm);
    let n = local.len() as Count;
    let mut counts = vec![0 as Count; size];
    comm.all_gather_into(&n, &mut counts[..]);
    let displs: Vec<Count> = counts
        .iter()
        .scan(0 as Count, |acc, &c| {
            let d = *acc;
            *acc += c;
            Some(d)
        })
        .collect();
    let total: Count = counts.iter().sum();
    let mut out = vec![0u64; total as usize];
    {
        let mut p = PartitionMut::new(&mut out[..], &counts[..], &displs[..]);
        comm.all_gather_varcount_into(local, &mut p);
    }
    out
}

/// Collective. [`crate::fetch`] for two-word keys (e.g. a pair of global ids naming an edge) and
/// one-word answers. Every rank gets the same error if any owner could not answer.
pub fn fetch_pairs(
    comm: &Comm,
    requests: &[(i32, [u64; 2])],
    answer: impl Fn(&[u64; 2]) -> Result<u64, PartitionError>,
) -> Result<Vec<u64>, PartitionError> {
    let size = comm_size(comm);
    let mut keys: Vec<Vec<u64>> = vec![Vec::new(); size];
    let mut slots: Vec<Vec<usize>> = vec![Vec::new(); size];
    let mut local_err: Option<PartitionError> = None;
    for (i, (owner, key)) in requests.iter().enumerate() {
        match usize::try_from(*owner).ok().filter(|&o| o < size) {
            Some(o) => {
                keys[o].extend_from_slice(key);
                slots[o].push(i);
            }
            None => {
                local_err.get_or_insert_with(|| {
                    invalid(format!("fetch_pairs: request {i} names rank {owner}"))
                });
            }
        }
    }
    let asked = alltoallv(comm, &keys);
    let replies: Vec<Vec<u64>> = asked
        .iter()
        .map(|ks| {
            ks.chunks_exact(2)
                .map(|k| match answer(&[k[0], k[1]]) {
                    Ok(v) => v,
                    Err(e) => {
                        local_err.get_or_insert(e);
                        u64::MAX
                    }
                })
                .collect()
        })
        .collect();
    let answers = alltoallv(comm, &replies);
    let mut out = vec![u64::MAX; requests.len()];
    for (o, vs) in answers.iter().enumerate() {
        for (&slot, &v) in slots[o].iter().zip(vs) {
            out[slot] = v;
        }
    }
    let msg = crate::agree_on_error(comm, local_err.map(|e| e.to_string()));
    match msg {
        Some(m) => Err(PartitionError::InvalidInput(m)),
        None => Ok(out),
    }
}

/// Collective. The owner rank of each of `queries` (global ids), given every rank's owned ids:
/// a directory spread over the ranks by `id % size` answers. Unknown ids get -1.
pub fn locate(comm: &Comm, owned: &[u64], queries: &[u64]) -> Vec<i32> {
    let size = comm_size(comm);
    let me = comm.rank() as u64;
    let mut register: Vec<Vec<u64>> = vec![Vec::new(); size];
    for &g in owned {
        register[(g % size as u64) as usize].extend_from_slice(&[g, me]);
    }
    let registered = alltoallv(comm, &register);
    let directory: std::collections::HashMap<u64, u64> = registered
        .iter()
        .flat_map(|r| r.chunks_exact(2).map(|c| (c[0], c[1])))
        .collect();
    let mut ask: Vec<Vec<u64>> = vec![Vec::new(); size];
    for &q in queries {
        ask[(q % size as u64) as usize].push(q);
    }
    let asked = alltoallv(comm, &ask);
    let replies: Vec<Vec<u64>> = asked
        .iter()
        .map(|qs| {
            qs.iter()
                .map(|q| directory.get(q).copied().unwrap_or(u64::MAX))
                .collect()
        })
        .collect();
    let answers = alltoallv(comm, &replies);
    let mut next = vec![0usize; size];
    queries
        .iter()
        .map(|&q| {
            let d = (q % size as u64) as usize;
            let a = answers[d][next[d]];
            next[d] += 1;
            if a == u64::MAX {
                -1
            } else {
                a as i32
            }
        })
        .collect()
}
