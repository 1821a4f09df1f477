//! Moving items to new owners, and the initial contiguous block distribution.

use std::ops::Range;

use crate::comm::{alltoallv, collective_result, comm_rank, comm_size, is_uniform};
use crate::error::invalid;
use crate::{Comm, PartitionError};

/// Items held by a rank: (global ids, f64 records of stride k, u64 records of stride ku), in
/// the same item order.
pub type Items = (Vec<u64>, Vec<f64>, Vec<u64>);

/// Collective. Move items to new owners: each item is (global id, fixed-stride f64 record of
/// length k, fixed-stride u64 record of length ku); returns the items this rank owns
/// afterwards, sorted by global id.
///
/// Records are copied bit for bit. Items with equal global ids keep (source rank, input order)
/// order. `k` and `ku` must be the same on every rank. Lenient on malformed input instead of
/// failing: an item without a valid destination rank stays here, and values missing from short
/// records are filled with NaN / `u64::MAX`; [`try_migrate`] rejects such input instead.
pub fn migrate(
    comm: &Comm,
    dest: &[i32],
    ids: &[u64],
    data_f64: &[f64],
    k: usize,
    data_u64: &[u64],
    ku: usize,
) -> Items {
    let size = comm_size(comm);
    let me = comm_rank(comm);
    // One stream of u64 records [gid, f64 bits.., u64..] needs one exchange instead of three.
    let stride = 1 + k + ku;
    let mut send: Vec<Vec<u64>> = vec![Vec::new(); size];
    for (i, &gid) in ids.iter().enumerate() {
        let to = dest
            .get(i)
            .and_then(|&d| usize::try_from(d).ok())
            .filter(|&d| d < size)
            .unwrap_or(me);
        let buf = &mut send[to];
        buf.push(gid);
        buf.extend((0..k).map(|j| {
            data_f64
                .get(i * k + j)
                .copied()
                .unwrap_or(f64::NAN)
                .to_bits()
        }));
        buf.extend((0..ku).map(|j| data_u64.get(i * ku + j).copied().unwrap_or(u64::MAX)));
    }
    let recv = alltoallv(comm, &send);
    drop(send);

    let records: Vec<&[u64]> = recv
        .iter()
        .flat_map(|from| from.chunks_exact(stride))
        .collect();
    let mut order: Vec<usize> = (0..records.len()).collect();
    // Stable, so equal ids stay in (source rank, input order) order.
    order.sort_by_key(|&r| records[r][0]);

    let mut out_ids = Vec::with_capacity(order.len());
    let mut out_f64 = Vec::with_capacity(order.len() * k);
    let mut out_u64 = Vec::with_capacity(order.len() * ku);
    for &r in &order {
        let rec = records[r];
        out_ids.push(rec[0]);
        out_f64.extend(rec[1..1 + k].iter().map(|&b| f64::from_bits(b)));
        out_u64.extend_from_slice(&rec[1 + k..]);
    }
    (out_ids, out_f64, out_u64)
}

/// Collective. [`migrate`] that first checks, on every rank, that `dest` names a valid rank for
/// every item, that the records hold exactly `k` / `ku` values per item and that `k` and `ku`
/// are the same everywhere; fails on every rank otherwise.
pub fn try_migrate(
    comm: &Comm,
    dest: &[i32],
    ids: &[u64],
    data_f64: &[f64],
    k: usize,
    data_u64: &[u64],
    ku: usize,
) -> Result<Items, PartitionError> {
    let size = comm_size(comm);
    let n = ids.len();
    let local = if dest.len() != n {
        Err(invalid(format!(
            "migrate: {} destinations for {n} items",
            dest.len()
        )))
    } else if let Some(i) = dest
        .iter()
        .position(|&d| usize::try_from(d).map_or(true, |d| d >= size))
    {
        Err(invalid(format!(
            "migrate: item {} (id {}) has destination {}, outside 0..{size}",
            i, ids[i], dest[i]
        )))
    } else if Some(data_f64.len()) != n.checked_mul(k) {
        Err(invalid(format!(
            "migrate: {} f64 values for {n} items of stride {k}",
            data_f64.len()
        )))
    } else if Some(data_u64.len()) != n.checked_mul(ku) {
        Err(invalid(format!(
            "migrate: {} u64 values for {n} items of stride {ku}",
            data_u64.len()
        )))
    } else {
        Ok(())
    };
    let uniform = is_uniform(comm, k as u64) && is_uniform(comm, ku as u64);
    collective_result(comm, local)?;
    if !uniform {
        return Err(invalid("migrate: record strides differ between ranks"));
    }
    Ok(migrate(comm, dest, ids, data_f64, k, data_u64, ku))
}

/// Initial block distribution helper: given a global count n and the rank, the half-open range
/// this rank holds in a contiguous split (used for hyperslab reads).
///
/// The first `n % size` ranks hold one item more than the others. An invalid `size` (< 1) or
/// `rank` (outside 0..size) gets the empty range `0..0`.
pub fn block_range(n: u64, rank: i32, size: i32) -> Range<u64> {
    if size < 1 || rank < 0 || rank >= size {
        return 0..0;
    }
    let (r, p) = (rank as u64, size as u64);
    let base = n / p;
    let extra = n % p;
    let start = r * base + r.min(extra);
    let len = base + u64::from(r < extra);
    start..start + len
}

#[cfg(test)]
mod tests {
    use super::block_range;

    #[test]
    fn block_ranges_tile_the_range() {
        for n in [0u64, 1, 2, 5, 10, 11, 1000] {
            for size in 1..=7 {
                let mut next = 0;
                for rank in 0..size {
                    let r = block_range(n, rank, size);
                    assert_eq!(r.start, next, "n={n} size={size} rank={rank}");
                    let len = r.end - r.start;
                    assert!(len == n / size as u64 || len == n / size as u64 + 1);
                    next = r.end;
                }
                assert_eq!(next, n);
            }
        }
    }

    #[test]
    fn block_range_bad_arguments_are_empty() {
        assert_eq!(block_range(10, 0, 0), 0..0);
        assert_eq!(block_range(10, -1, 2), 0..0);
        assert_eq!(block_range(10, 2, 2), 0..0);
        assert_eq!(block_range(10, 1, 3), 4..7);
        assert_eq!(block_range(u64::MAX, 1, 2), u64::MAX / 2 + 1..u64::MAX);
    }
}
