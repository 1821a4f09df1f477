//! Keeping ranks in step: a failure on any rank becomes the same error on every rank, so that
//! no rank goes on into a collective call that the others have abandoned.

use std::path::Path;

use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

use super::error::{CaseError, CaseErrorKind};

fn encode(e: &CaseError) -> Vec<u8> {
    let mut out = vec![e.kind.code(), u8::from(e.location.is_some())];
    out.extend_from_slice(e.location.as_deref().unwrap_or("").as_bytes());
    out.push(0);
    out.extend_from_slice(e.message.as_bytes());
    out
}

fn decode(path: &Path, bytes: &[u8]) -> CaseError {
    let kind = CaseErrorKind::from_code(bytes.first().copied().unwrap_or(u8::MAX));
    let has_location = bytes.get(1).copied().unwrap_or(0) != 0;
    let rest = bytes.get(2..).unwrap_or(&[]);
    let split = rest.iter().position(|&b| b == 0).unwrap_or(rest.len());
    let location = String::from_utf8_lossy(&rest[..split]).into_owned();
    let message = String::from_utf8_lossy(rest.get(split + 1..).unwrap_or(&[])).into_owned();
    let e = CaseError::new(path, kind, message);
    if has_location {
        e.at(location)
    } else {
        e
    }
}

/// Collective. Returns `local` when every rank succeeded; otherwise every rank returns the error
/// of the lowest failing rank. Also a synchronisation point.
pub fn agree<T>(
    comm: &SimpleCommunicator,
    path: &Path,
    local: Result<T, CaseError>,
) -> Result<T, CaseError> {
    let size = comm.size();
    let mine = if local.is_err() { comm.rank() } else { size };
    let mut first = size;
    comm.all_reduce_into(&mine, &mut first, mpi::collective::SystemOperation::min());
    if first == size {
        return local;
    }
    let mut bytes = match &local {
        Err(e) if comm.rank() == first => encode(e),
        _ => Vec::new(),
    };
    let root = comm.process_at_rank(first);
    let mut len = bytes.len() as u64;
    root.broadcast_into(&mut len);
    bytes.resize(len as usize, 0);
    root.broadcast_into(&mut bytes[..]);
    match local {
        Err(e) if comm.rank() == first => Err(e),
        _ => Err(decode(path, &bytes)),
    }
}

/// The contiguous block `[start, end)` of `n` items that `rank` of `size` reads: the first
/// `n % size` ranks get one extra.
pub fn block_range(n: u64, size: u64, rank: u64) -> std::ops::Range<u64> {
    let base = n / size;
    let extra = n % size;
    let start = rank * base + rank.min(extra);
    start..start + base + u64::from(rank < extra)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_tile_the_range() {
        for n in [0u64, 1, 2, 7, 729] {
            for size in 1..5u64 {
                let mut next = 0;
                for rank in 0..size {
                    let r = block_range(n, size, rank);
                    assert_eq!(r.start, next);
                    assert!(r.end - r.start <= n / size + 1);
                    next = r.end;
                }
                assert_eq!(next, n);
            }
        }
    }

    #[test]
    fn errors_survive_encoding() {
        let p = Path::new("case.h5");
        let e = CaseError::new(p, CaseErrorKind::TooNew, "format_version 7 is newer")
            .at("attribute format_version");
        assert_eq!(decode(p, &encode(&e)), e);
        let e = CaseError::new(p, CaseErrorKind::Io, "cannot create");
        assert_eq!(decode(p, &encode(&e)), e);
    }
}
