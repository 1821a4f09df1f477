//! A checksum per dataset, so that damage the rules cannot see (a flipped bit in a position,
//! a changed stress) is still found. Attribute `checksum` (u64) of each dataset: the wrapping
//! sum over its rows r of FNV-1a over 64-bit words, fed r and then the row's values (f64 by
//! their bits, u32 widened). A sum of per-row hashes does not depend on which rank wrote or
//! reads which rows, so each rank hashes its own block and one allreduce adds them. Datasets
//! without the attribute (files written before it) are read unchecked.

use hdf5::{Dataset, H5Type};
use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

/// Name of the attribute on each dataset.
pub const ATTR: &str = "checksum";

const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const PRIME: u64 = 0x0100_0000_01b3;

/// A value as the 64-bit word the checksum is fed.
pub trait Word: Copy {
    fn word(self) -> u64;
}

impl Word for u64 {
    fn word(self) -> u64 {
        self
    }
}

impl Word for u32 {
    fn word(self) -> u64 {
        u64::from(self)
    }
}

impl Word for f64 {
    fn word(self) -> u64 {
        self.to_bits()
    }
}

/// This rank's part: rows `first..` of `width` values each (0 = a 1-D dataset).
pub fn rows_sum<T: Word>(first: usize, width: usize, data: &[T]) -> u64 {
    data.chunks(width.max(1))
        .enumerate()
        .fold(0u64, |sum, (r, row)| {
            let h = row
                .iter()
                .fold((OFFSET ^ (first + r) as u64).wrapping_mul(PRIME), |h, v| {
                    (h ^ v.word()).wrapping_mul(PRIME)
                });
            sum.wrapping_add(h)
        })
}

/// Collective. The whole dataset's checksum from every rank's part.
pub fn total(comm: &SimpleCommunicator, part: u64) -> u64 {
    let mut sum = 0u64;
    comm.all_reduce_into(&part, &mut sum, SystemOperation::sum());
    sum
}

/// Writes the checksum attribute (collective under MPI-IO: every rank passes the same value).
pub fn put(ds: &Dataset, sum: u64) -> hdf5::Result<()> {
    ds.new_attr::<u64>().create(ATTR)?.write_scalar(&sum)
}

/// The stored checksum, None when the dataset has none (or it is not one u64).
pub fn stored(ds: &Dataset) -> Option<u64> {
    let attr = ds.attr(ATTR).ok()?;
    if attr.dtype().ok()?.to_descriptor().ok()? != u64::type_descriptor() || attr.size() != 1 {
        return None;
    }
    attr.read_raw::<u64>().ok()?.first().copied()
}

/// Collective. `Err(message)` on every rank when `ds` carries a checksum its data does not
/// give; this rank read rows `first..` into `data`.
pub fn verify<T: Word>(
    comm: &SimpleCommunicator,
    ds: &Dataset,
    first: usize,
    width: usize,
    data: &[T],
) -> Result<(), String> {
    let want = stored(ds);
    let got = total(comm, rows_sum(first, width, data));
    match want {
        Some(w) if w != got => Err(format!(
            "checksum {w:#018x} stored but the data gives {got:#018x}: the data was changed or \
             damaged after it was written"
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_add_up_and_any_change_shows() {
        let data: Vec<f64> = (0..40).map(|i| i as f64 * 0.37).collect();
        let whole = rows_sum(0, 2, &data);
        assert_eq!(
            rows_sum(0, 2, &data[..14]).wrapping_add(rows_sum(7, 2, &data[14..])),
            whole
        );
        let mut bent = data.clone();
        bent[13] = f64::from_bits(bent[13].to_bits() ^ 1);
        assert_ne!(rows_sum(0, 2, &bent), whole);
        // Two rows swapped: the row index is in each row's hash.
        let mut swapped = data.clone();
        swapped.swap(0, 2);
        swapped.swap(1, 3);
        assert_ne!(rows_sum(0, 2, &swapped), whole);
        assert_eq!(rows_sum::<u32>(0, 0, &[]), 0);
    }
}
