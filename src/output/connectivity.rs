//! Triangles from global particle ids to row numbers of a frame file.
//!
//! Particles are stored in rank order, so the row of an owned particle is the rank's first row
//! plus its index in the sorted `gid`; the row of a vertex owned elsewhere is asked of its owner.

use std::path::Path;

use mpi::traits::Communicator;
use pfem_partition::{fetch, Comm, PartitionError};

use super::error::{agree, OutputError};

/// Row of `g` among this rank's particles `gid` (sorted) starting at row `first`.
fn owned_row(gid: &[u64], first: u64, g: u64) -> Option<u64> {
    gid.binary_search(&g).ok().map(|i| first + i as u64)
}

fn to_i64(row: u64, file: &Path) -> Result<i64, OutputError> {
    i64::try_from(row).map_err(|_| OutputError::new(file, format!("row {row} exceeds i64")))
}

/// Collective. The rows of the vertices of `triangles`, three per triangle, given this rank's
/// sorted `gid` stored from row `first`. `owner_of` names the owner of every vertex this rank
/// does not own. Errors (unknown owner, a vertex its owner does not have) are the same on every
/// rank and name `file`.
pub(crate) fn triangle_rows(
    comm: &Comm,
    file: &Path,
    gid: &[u64],
    first: u64,
    triangles: &[[u64; 3]],
    owner_of: &dyn Fn(u64) -> Option<i32>,
) -> Result<Vec<i64>, OutputError> {
    let me = comm.rank();
    let mut local: Result<(), OutputError> = Ok(());
    let mut fail = |message: String| {
        if local.is_ok() {
            local = Err(OutputError::new(file, message));
        }
    };

    let mut ghosts: Vec<(u64, i32)> = Vec::new();
    for t in triangles {
        for &g in t {
            if owned_row(gid, first, g).is_some() {
                continue;
            }
            match owner_of(g) {
                Some(o) if o == me => fail(format!(
                    "triangle vertex {g} is said to be owned by rank {me}, which does not own it"
                )),
                Some(o) => ghosts.push((g, o)),
                None => fail(format!(
                    "triangle vertex {g} is neither owned by rank {me} nor has a known owner"
                )),
            }
        }
    }
    ghosts.sort_unstable();
    ghosts.dedup_by_key(|&mut (g, _)| g);

    // Every rank must take part in the exchange, whatever its own checks found.
    let requests: Vec<(i32, u64)> = ghosts.iter().map(|&(g, o)| (o, g)).collect();
    let answers = fetch(comm, &requests, |g: &u64| {
        owned_row(gid, first, *g).ok_or_else(|| {
            PartitionError::InvalidInput(format!(
                "triangle vertex {g} was asked of rank {me}, which does not own it"
            ))
        })
    })
    .map_err(|e| OutputError::new(file, e.to_string()))?;
    agree(comm, local)?;

    let mut rows = Vec::with_capacity(3 * triangles.len());
    for t in triangles {
        for &g in t {
            let row = match owned_row(gid, first, g) {
                Some(r) => r,
                // Present: every non-owned vertex was requested above.
                None => ghosts
                    .binary_search_by_key(&g, |&(h, _)| h)
                    .map(|i| answers[i])
                    .unwrap_or(u64::MAX),
            };
            rows.push(to_i64(row, file));
        }
    }
    let rows: Result<Vec<i64>, OutputError> = rows.into_iter().collect();
    agree(comm, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn owned_rows_follow_the_sorted_ids() {
        let gid = [3, 8, 20];
        assert_eq!(owned_row(&gid, 10, 3), Some(10));
        assert_eq!(owned_row(&gid, 10, 20), Some(12));
        assert_eq!(owned_row(&gid, 10, 4), None);
    }
}
