//! Generic typed exchanges: all-to-all, request/response by key, prefix sums, gathers and
//! error agreement.

use mpi::collective::SystemOperation;
use mpi::datatype::{Equivalence, Partition, PartitionMut};
use mpi::traits::*;
use mpi::Count;

use crate::error::invalid;
use crate::{Comm, PartitionError};

/// Largest element count (and buffer offset) a single MPI call can carry: they are C ints.
pub(crate) const MAX_COUNT: usize = i32::MAX as usize;

/// Longest error message forwarded by [`agree_on_error`]; longer ones are cut, because a
/// diagnostic never needs to be large and the broadcast count is a C int.
const MAX_MESSAGE_BYTES: usize = 1 << 16;

/// Number of ranks as a `usize` (MPI guarantees at least one).
pub(crate) fn comm_size(comm: &Comm) -> usize {
    usize::try_from(comm.size()).unwrap_or(1).max(1)
}

/// This rank as a `usize`.
pub(crate) fn comm_rank(comm: &Comm) -> usize {
    usize::try_from(comm.rank()).unwrap_or(0)
}

/// Collective. Sends `send[r]` to rank r; returns what every rank sent to us, indexed by source
/// rank.
///
/// `send` should have one entry per rank; missing entries are treated as empty and extra ones
/// are ignored. Messages larger than a C int are split into several rounds transparently.
pub fn alltoallv<T: Equivalence + Clone + Default>(comm: &Comm, send: &[Vec<T>]) -> Vec<Vec<T>> {
    let cap = (MAX_COUNT / comm_size(comm)).max(1);
    alltoallv_capped(comm, send, cap)
}

/// Collective. [`alltoallv`] moving at most `cap` elements per (source, destination) pair in
/// each round, so that every round's total fits a C int. Exposed so the chunking can be tested
/// with tiny caps.
#[doc(hidden)]
pub fn alltoallv_capped<T: Equivalence + Clone + Default>(
    comm: &Comm,
    send: &[Vec<T>],
    cap: usize,
) -> Vec<Vec<T>> {
    let size = comm_size(comm);
    let cap = cap.clamp(1, (MAX_COUNT / size).max(1));
    let send_counts: Vec<u64> = (0..size)
        .map(|r| send.get(r).map_or(0, Vec::len) as u64)
        .collect();
    let mut recv_counts = vec![0u64; size];
    comm.all_to_all_into(&send_counts[..], &mut recv_counts[..]);

    let local_max = send_counts
        .iter()
        .chain(&recv_counts)
        .copied()
        .max()
        .unwrap_or(0);
    let mut global_max = 0u64;
    comm.all_reduce_into(&local_max, &mut global_max, SystemOperation::max());
    let rounds = global_max.div_ceil(cap as u64);

    let mut out: Vec<Vec<T>> = recv_counts
        .iter()
        .map(|&n| Vec::with_capacity(usize::try_from(n).unwrap_or(0)))
        .collect();
    for round in 0..rounds {
        let lo = round * cap as u64;
        let window = |n: u64| (lo.min(n) as usize, (lo + cap as u64).min(n) as usize);

        let mut sbuf: Vec<T> = Vec::new();
        let mut scounts: Vec<Count> = Vec::with_capacity(size);
        let mut sdispls: Vec<Count> = Vec::with_capacity(size);
        for (r, &n) in send_counts.iter().enumerate() {
            let (a, b) = window(n);
            // Both fit a C int: cap * size <= MAX_COUNT.
            sdispls.push(sbuf.len() as Count);
            scounts.push((b - a) as Count);
            if b > a {
                sbuf.extend_from_slice(&send[r][a..b]);
            }
        }
        let mut rcounts: Vec<Count> = Vec::with_capacity(size);
        let mut rdispls: Vec<Count> = Vec::with_capacity(size);
        let mut total = 0usize;
        for &n in &recv_counts {
            let (a, b) = window(n);
            rdispls.push(total as Count);
            rcounts.push((b - a) as Count);
            total += b - a;
        }
        let mut rbuf = vec![T::default(); total];
        {
            let sp = Partition::new(&sbuf[..], &scounts[..], &sdispls[..]);
            let mut rp = PartitionMut::new(&mut rbuf[..], &rcounts[..], &rdispls[..]);
            comm.all_to_all_varcount_into(&sp, &mut rp);
        }
        for (r, dst) in out.iter_mut().enumerate() {
            let a = rdispls[r] as usize;
            dst.extend_from_slice(&rbuf[a..a + rcounts[r] as usize]);
        }
    }
    out
}

/// Collective. Request/response by key: `requests` = (owner rank, key) pairs; each owner
/// answers with `answer(&key)`; results returned in request order. Used e.g. to learn the global
/// number of a ghost item.
///
/// A request naming a rank outside the communicator, or an `answer` that fails on the owner,
/// makes every rank return the same [`PartitionError::OnRank`].
pub fn fetch<K, V>(
    comm: &Comm,
    requests: &[(i32, K)],
    answer: impl Fn(&K) -> Result<V, PartitionError>,
) -> Result<Vec<V>, PartitionError>
where
    K: Equivalence + Clone + Default,
    V: Equivalence + Clone + Default,
{
    let size = comm_size(comm);
    let mut local_err: Option<PartitionError> = None;
    let mut keys: Vec<Vec<K>> = vec![Vec::new(); size];
    let mut slots: Vec<Vec<usize>> = vec![Vec::new(); size];
    for (i, (owner, key)) in requests.iter().enumerate() {
        match usize::try_from(*owner).ok().filter(|&o| o < size) {
            Some(o) => {
                keys[o].push(key.clone());
                slots[o].push(i);
            }
            None => {
                local_err.get_or_insert_with(|| {
                    invalid(format!(
                        "fetch: request {i} names owner rank {owner}, outside 0..{size}"
                    ))
                });
            }
        }
    }

    let asked = alltoallv(comm, &keys);
    let mut replies: Vec<Vec<V>> = Vec::with_capacity(size);
    for ks in &asked {
        let mut vs = Vec::with_capacity(ks.len());
        for k in ks {
            match answer(k) {
                Ok(v) => vs.push(v),
                Err(e) => {
                    local_err.get_or_insert(e);
                    vs.push(V::default());
                }
            }
        }
        replies.push(vs);
    }

    let answers = alltoallv(comm, &replies);
    let mut out = vec![V::default(); requests.len()];
    for (o, vs) in answers.iter().enumerate() {
        if vs.len() != slots[o].len() {
            local_err.get_or_insert_with(|| {
                invalid(format!(
                    "fetch: rank {o} answered {} of {} requests",
                    vs.len(),
                    slots[o].len()
                ))
            });
            continue;
        }
        for (&slot, v) in slots[o].iter().zip(vs) {
            out[slot] = v.clone();
        }
    }
    collective_result(comm, local_err.map_or(Ok(out), Err))
}

/// Collective. Exclusive prefix sum of a u64 over ranks, plus the total.
///
/// Rank 0 gets 0. Sums wrap on overflow (they cannot overflow for counts of real items).
pub fn exscan_u64(comm: &Comm, v: u64) -> (u64, u64) {
    let mut inclusive = 0u64;
    comm.scan_into(&v, &mut inclusive, SystemOperation::sum());
    let mut total = 0u64;
    comm.all_reduce_into(&v, &mut total, SystemOperation::sum());
    (inclusive.wrapping_sub(v), total)
}

/// Collective. Gather variable-length data on root 0 (others get empty).
///
/// The result on rank 0 is the concatenation of every rank's `local`, in rank order.
pub fn gather_to_root<T: Equivalence + Clone + Default>(comm: &Comm, local: &[T]) -> Vec<T> {
    let cap = (MAX_COUNT / comm_size(comm)).max(1);
    gather_to_root_capped(comm, local, cap)
}

/// Collective. [`gather_to_root`] moving at most `cap` elements per rank in each round.
#[doc(hidden)]
pub fn gather_to_root_capped<T: Equivalence + Clone + Default>(
    comm: &Comm,
    local: &[T],
    cap: usize,
) -> Vec<T> {
    let size = comm_size(comm);
    let cap = cap.clamp(1, (MAX_COUNT / size).max(1));
    let root = comm.process_at_rank(0);
    let is_root = comm.rank() == 0;
    let n = local.len() as u64;

    let mut counts = vec![0u64; if is_root { size } else { 0 }];
    if is_root {
        root.gather_into_root(&n, &mut counts[..]);
    } else {
        root.gather_into(&n);
    }
    let mut rounds = counts
        .iter()
        .copied()
        .max()
        .unwrap_or(0)
        .div_ceil(cap as u64);
    root.broadcast_into(&mut rounds);

    let mut pieces: Vec<Vec<T>> = vec![Vec::new(); counts.len()];
    for round in 0..rounds {
        let lo = round * cap as u64;
        let window = |n: u64| (lo.min(n) as usize, (lo + cap as u64).min(n) as usize);
        let (a, b) = window(n);
        let chunk = &local[a..b];
        if is_root {
            let mut rcounts: Vec<Count> = Vec::with_capacity(size);
            let mut rdispls: Vec<Count> = Vec::with_capacity(size);
            let mut total = 0usize;
            for &c in &counts {
                let (a, b) = window(c);
                rdispls.push(total as Count);
                rcounts.push((b - a) as Count);
                total += b - a;
            }
            let mut rbuf = vec![T::default(); total];
            {
                let mut rp = PartitionMut::new(&mut rbuf[..], &rcounts[..], &rdispls[..]);
                root.gather_varcount_into_root(chunk, &mut rp);
            }
            for (r, piece) in pieces.iter_mut().enumerate() {
                let a = rdispls[r] as usize;
                piece.extend_from_slice(&rbuf[a..a + rcounts[r] as usize]);
            }
        } else {
            root.gather_varcount_into(chunk);
        }
    }
    pieces.concat()
}

/// Collective: all ranks agree whether any rank reported an error; returns the first error
/// message (lowest rank) to everyone so the whole job can exit with it.
pub fn agree_on_error(comm: &Comm, local: Option<String>) -> Option<String> {
    first_error(comm, local).map(|(_, message)| message)
}

/// Collective. Like [`agree_on_error`], also naming the lowest failing rank.
pub(crate) fn first_error(comm: &Comm, local: Option<String>) -> Option<(i32, String)> {
    let size = comm.size();
    let mine = if local.is_some() { comm.rank() } else { size };
    let mut first = size;
    comm.all_reduce_into(&mine, &mut first, SystemOperation::min());
    broadcast_first(comm, first, local)
}

/// Collective on `comm`, which nothing else may use (a duplicate of the world made for this):
/// [`agree_on_error`] for the end of a command, where one rank may return an error that the
/// others know nothing of while they wait for it in another collective. A rank with an error
/// waits at most `patience` for the others; when they do not come, `abandon` gets the message
/// (to print it) and the whole job is aborted (MPI_Abort, exit code 1). Ranks without an error
/// wait as long as it takes: either every rank arrives or a failed one aborts them all.
pub fn agree_on_error_or_abort(
    comm: &Comm,
    local: Option<String>,
    patience: std::time::Duration,
    abandon: impl FnOnce(&str),
) -> Option<String> {
    let size = comm.size();
    let mut first = size;
    match &local {
        None => comm.all_reduce_into(&size, &mut first, SystemOperation::min()),
        Some(message) => {
            let rank = comm.rank();
            let start = std::time::Instant::now();
            mpi::request::scope(|scope| {
                let mut request = comm.immediate_all_reduce_into(
                    scope,
                    &rank,
                    &mut first,
                    SystemOperation::min(),
                );
                loop {
                    match request.test() {
                        Ok(_) => break,
                        Err(pending) => request = pending,
                    }
                    if start.elapsed() > patience {
                        abandon(message);
                        comm.abort(1);
                    }
                    std::thread::sleep(std::time::Duration::from_millis(5));
                }
            });
        }
    }
    broadcast_first(comm, first, local).map(|(_, message)| message)
}

/// Collective. The message of rank `first` (the lowest failing rank; `comm.size()` when none
/// failed) to every rank.
fn broadcast_first(comm: &Comm, first: i32, local: Option<String>) -> Option<(i32, String)> {
    let (size, rank) = (comm.size(), comm.rank());
    if first >= size {
        return None;
    }
    let root = comm.process_at_rank(first);
    let mut bytes = if rank == first {
        truncate_utf8(local.unwrap_or_default(), MAX_MESSAGE_BYTES).into_bytes()
    } else {
        Vec::new()
    };
    let mut len = bytes.len() as u64;
    root.broadcast_into(&mut len);
    bytes.resize(usize::try_from(len).unwrap_or(0), 0);
    root.broadcast_into(&mut bytes[..]);
    Some((first, String::from_utf8_lossy(&bytes).into_owned()))
}

/// Collective. Turns a per-rank outcome into one every rank agrees on: `Ok` only when all ranks
/// succeeded, otherwise the lowest failing rank's error as [`PartitionError::OnRank`].
pub(crate) fn collective_result<T>(
    comm: &Comm,
    local: Result<T, PartitionError>,
) -> Result<T, PartitionError> {
    let message = local.as_ref().err().map(ToString::to_string);
    match first_error(comm, message) {
        None => local,
        Some((rank, message)) => Err(PartitionError::OnRank { rank, message }),
    }
}

/// Collective. True when `v` has the same value on every rank.
pub(crate) fn is_uniform(comm: &Comm, v: u64) -> bool {
    let mut lo = 0u64;
    let mut hi = 0u64;
    comm.all_reduce_into(&v, &mut lo, SystemOperation::min());
    comm.all_reduce_into(&v, &mut hi, SystemOperation::max());
    lo == hi
}

fn truncate_utf8(mut s: String, max: usize) -> String {
    if s.len() > max {
        let mut cut = max;
        while !s.is_char_boundary(cut) {
            cut -= 1;
        }
        s.truncate(cut);
    }
    s
}

/// Makes a panic on one rank end every rank: after the default report, the panicking rank
/// aborts the MPI job (the others would otherwise wait in their next collective for ever).
/// Call once, after MPI is initialised.
pub fn abort_job_on_panic() {
    let report = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        report(info);
        eprintln!("pfem-mpi: internal error (a panic, above): aborting every rank");
        mpi::topology::SimpleCommunicator::world().abort(70);
    }));
}

#[cfg(test)]
mod tests {
    use super::truncate_utf8;

    #[test]
    fn truncation_respects_char_boundaries() {
        assert_eq!(truncate_utf8("abc".into(), 10), "abc");
        assert_eq!(truncate_utf8("abcdef".into(), 3), "abc");
        // 'é' is two bytes: cutting in its middle must back off to the boundary.
        assert_eq!(truncate_utf8("aé".into(), 2), "a");
    }
}
