//! Geometric halo: which owned items each other rank needs as ghosts, and exchanges over it.
//!
//! The search is exact (up to a relative slack of 1e-9 on the squared width) and O(n) for
//! compact subdomains:
//! 1. every rank publishes its bounding box; ranks whose boxes are within the width of each
//!    other are candidate neighbours;
//! 2. each rank sends each candidate the occupied cells (of a grid with spacing >= width) that
//!    come within the width of the candidate's box;
//! 3. each rank answers with the positions of its points lying in cells adjacent to those;
//!    any pair of points within the width is found on both sides in this step;
//! 4. each rank keeps, per neighbour, its candidate points that are within the width of one of
//!    the neighbour's positions, and tells the neighbour their global ids.

use mpi::datatype::Equivalence;
use mpi::request::WaitGuard;
use mpi::traits::*;

use crate::comm::{alltoallv, collective_result, comm_rank, comm_size, is_uniform, MAX_COUNT};
use crate::error::invalid;
use crate::geom::{BBox, Bins, Grid, MAX_CELL_INDEX};
use crate::{Comm, PartitionError};

/// Message tag of halo exchanges. Point-to-point messages with this tag on the same
/// communicator would interleave with them, so callers should avoid it.
pub const HALO_TAG: i32 = 0x7046;

/// Relative slack on the squared width in the final distance test: errs towards including a
/// point whose distance equals the width up to rounding.
const R2_SLACK: f64 = 1e-9;

/// Exchange pattern of a geometric halo.
///
/// Built once by [`Halo::build`] and then used for any number of
/// [`exchange_f64`](Halo::exchange_f64)/[`exchange_u64`](Halo::exchange_u64) calls on the same
/// communicator, as long as the owned items (and their order) do not change.
#[derive(Debug, Clone, PartialEq)]
pub struct Halo {
    /// Communicator size at build time.
    size: usize,
    /// Number of owned items at build time.
    n_owned: usize,
    /// Ranks we send to, ascending; `send_idx[send_off[n]..send_off[n + 1]]` go to `send_ranks[n]`.
    send_ranks: Vec<i32>,
    send_off: Vec<usize>,
    /// Local owned indices, sorted by global id within each destination.
    send_idx: Vec<usize>,
    /// Ranks we receive from, ascending; ghosts `recv_off[n]..recv_off[n + 1]` come from
    /// `recv_ranks[n]`.
    recv_ranks: Vec<i32>,
    recv_off: Vec<usize>,
    ghost_ids: Vec<u64>,
    ghost_owners: Vec<i32>,
}

impl Halo {
    /// Collective. Finds, for every other rank s, which of our owned items lie within distance
    /// `width` of any item owned by s, and, symmetrically, which items of other ranks lie within
    /// `width` of ours (our ghosts).
    ///
    /// `owned_ids[i]` and `owned_pos[i]` describe owned item i. The widest `width` over all ranks
    /// is used. Fails on every rank when any rank passes mismatched lengths, a non-finite
    /// position, or a width that is not finite and positive.
    pub fn build(
        comm: &Comm,
        owned_ids: &[u64],
        owned_pos: &[[f64; 2]],
        width: f64,
    ) -> Result<Halo, PartitionError> {
        collective_result(comm, validate(owned_ids, owned_pos, width))?;
        let size = comm_size(comm);
        let me = comm_rank(comm);

        let mybox = BBox::of(owned_pos);
        let record = [
            mybox.min[0],
            mybox.min[1],
            mybox.max[0],
            mybox.max[1],
            width,
        ];
        let mut all = vec![0.0f64; 5 * size];
        comm.all_gather_into(&record[..], &mut all[..]);
        let boxes: Vec<BBox> = all
            .chunks_exact(5)
            .map(|c| BBox {
                min: [c[0], c[1]],
                max: [c[2], c[3]],
            })
            .collect();
        let w = all.chunks_exact(5).fold(0.0f64, |m, c| m.max(c[4]));
        let global = boxes.iter().fold(BBox::empty(), |u, b| u.union(b));

        let mut halo = Halo {
            size,
            n_owned: owned_ids.len(),
            send_ranks: Vec::new(),
            send_off: vec![0],
            send_idx: Vec::new(),
            recv_ranks: Vec::new(),
            recv_off: vec![0],
            ghost_ids: Vec::new(),
            ghost_owners: Vec::new(),
        };
        if global.is_empty() {
            return Ok(halo);
        }

        // Absolute slack covers rounding of coordinates far from the origin; the relative part
        // covers the squared-width slack of the final test. Every decision below is made with
        // this inflated width so no pair within `w` can be lost to rounding.
        let w_box = w * (1.0 + 1e-6) + 16.0 * f64::EPSILON * global.max_abs();
        let grid = Grid {
            origin: global.min,
            h: w_box,
        };
        let extent = (global.max[0] - global.min[0]).max(global.max[1] - global.min[1]);
        let span = extent / grid.h;
        if span.is_nan() || span >= MAX_CELL_INDEX {
            // Same data on every rank, so every rank reaches this verdict.
            return Err(invalid(format!(
                "halo width {w} is too small for a domain of extent {extent}"
            )));
        }
        let w_box2 = w_box * w_box;
        let r2 = w * w * (1.0 + R2_SLACK);

        let bins = Bins::new(&grid, owned_pos);

        // Step 2: our occupied cells near each candidate neighbour's box.
        let mut cell_msgs: Vec<Vec<i64>> = vec![Vec::new(); size];
        for (s, msg) in cell_msgs.iter_mut().enumerate() {
            if s == me || mybox.gap2(&boxes[s]) > w_box2 {
                continue;
            }
            for (c, _) in bins.cells() {
                if grid.cell_box(c).gap2(&boxes[s]) <= w_box2 {
                    msg.extend([c.0, c.1]);
                }
            }
        }
        let their_cells = alltoallv(comm, &cell_msgs);
        drop(cell_msgs);

        // Step 3: our points in cells adjacent to a neighbour's reported cells.
        let mut stamp = vec![usize::MAX; bins.n_cells()];
        let mut cand: Vec<Vec<usize>> = vec![Vec::new(); size];
        for (s, cells) in their_cells.iter().enumerate() {
            if s == me {
                continue;
            }
            for c in cells.chunks_exact(2) {
                for di in -1..=1 {
                    for dj in -1..=1 {
                        if let Some((id, members)) = bins.get((c[0] + di, c[1] + dj)) {
                            if stamp[id] != s {
                                stamp[id] = s;
                                cand[s].extend_from_slice(members);
                            }
                        }
                    }
                }
            }
        }
        let pos_msgs: Vec<Vec<f64>> = cand
            .iter()
            .map(|c| c.iter().flat_map(|&i| owned_pos[i]).collect())
            .collect();
        let their_pos = alltoallv(comm, &pos_msgs);
        drop(pos_msgs);

        // Step 4: exact filter of our candidates against the neighbour's candidates.
        let mut gid_msgs: Vec<Vec<u64>> = vec![Vec::new(); size];
        for (s, mine) in cand.iter().enumerate() {
            if mine.is_empty() || their_pos[s].is_empty() {
                continue;
            }
            let pts: Vec<[f64; 2]> = their_pos[s].chunks_exact(2).map(|c| [c[0], c[1]]).collect();
            let their_bins = Bins::new(&grid, &pts);
            let mut list: Vec<usize> = mine
                .iter()
                .copied()
                .filter(|&i| their_bins.any_within(&grid, &pts, owned_pos[i], r2))
                .collect();
            if list.is_empty() {
                continue;
            }
            list.sort_unstable_by_key(|&i| (owned_ids[i], i));
            gid_msgs[s] = list.iter().map(|&i| owned_ids[i]).collect();
            halo.send_ranks.push(s as i32);
            halo.send_idx.extend_from_slice(&list);
            halo.send_off.push(halo.send_idx.len());
        }
        let ghosts = alltoallv(comm, &gid_msgs);
        for (s, ids) in ghosts.into_iter().enumerate() {
            if ids.is_empty() {
                continue;
            }
            halo.recv_ranks.push(s as i32);
            halo.ghost_owners
                .extend(std::iter::repeat_n(s as i32, ids.len()));
            halo.ghost_ids.extend(ids);
            halo.recv_off.push(halo.ghost_ids.len());
        }
        Ok(halo)
    }

    /// Global ids of our ghosts, ordered by (owner rank, gid) — deterministic.
    pub fn ghost_ids(&self) -> &[u64] {
        &self.ghost_ids
    }

    /// Owner rank of each ghost, parallel to [`ghost_ids`](Halo::ghost_ids).
    pub fn ghost_owners(&self) -> &[i32] {
        &self.ghost_owners
    }

    /// Collective. Generic halo exchange of fixed-stride f64 records: owned data (stride k per
    /// owned item, in owned order) -> ghost data (stride k per ghost, in ghost order). Bit-for-bit
    /// copies.
    ///
    /// `k` must be the same on every rank and `comm` must be the communicator the halo was built
    /// on. Values missing from a too-short `owned` are sent as NaN;
    /// [`try_exchange_f64`](Halo::try_exchange_f64) reports such misuse instead.
    pub fn exchange_f64(&self, comm: &Comm, owned: &[f64], k: usize) -> Vec<f64> {
        self.exchange(comm, owned, k, f64::NAN)
    }

    /// Collective. Same for u64 records. Values missing from a too-short `owned` are sent as
    /// `u64::MAX`.
    pub fn exchange_u64(&self, comm: &Comm, owned: &[u64], k: usize) -> Vec<u64> {
        self.exchange(comm, owned, k, u64::MAX)
    }

    /// Collective. [`exchange_f64`](Halo::exchange_f64) that first checks, on every rank, that
    /// `owned` holds exactly `k` values per owned item, that `k` is the same everywhere and that
    /// `comm` has the size the halo was built for; fails on every rank otherwise.
    pub fn try_exchange_f64(
        &self,
        comm: &Comm,
        owned: &[f64],
        k: usize,
    ) -> Result<Vec<f64>, PartitionError> {
        self.check(comm, owned.len(), k)?;
        Ok(self.exchange_f64(comm, owned, k))
    }

    fn check(&self, comm: &Comm, len: usize, k: usize) -> Result<(), PartitionError> {
        let local = if comm_size(comm) != self.size {
            Err(invalid(format!(
                "halo built on {} ranks used on a communicator of {}",
                self.size,
                comm_size(comm)
            )))
        } else if Some(len) != self.n_owned.checked_mul(k) {
            Err(invalid(format!(
                "halo exchange got {len} values for {} owned items of stride {k}",
                self.n_owned
            )))
        } else {
            Ok(())
        };
        let uniform = is_uniform(comm, k as u64);
        collective_result(comm, local)?;
        if uniform {
            Ok(())
        } else {
            Err(invalid("halo exchange stride differs between ranks"))
        }
    }

    fn exchange<T: Equivalence + Copy>(
        &self,
        comm: &Comm,
        owned: &[T],
        k: usize,
        pad: T,
    ) -> Vec<T> {
        let mut recv = vec![pad; self.ghost_ids.len() * k];
        if k == 0 || comm_size(comm) != self.size {
            return recv;
        }
        let mut sendbuf: Vec<T> = Vec::with_capacity(self.send_idx.len() * k);
        for &i in &self.send_idx {
            match owned.get(i * k..(i + 1) * k) {
                Some(rec) => sendbuf.extend_from_slice(rec),
                None => {
                    sendbuf.extend((0..k).map(|j| owned.get(i * k + j).copied().unwrap_or(pad)))
                }
            }
        }

        mpi::request::scope(|scope| {
            let mut guards = Vec::new();
            // Receives first so that matching sends find them posted.
            let mut rest: &mut [T] = &mut recv[..];
            for (n, &src) in self.recv_ranks.iter().enumerate() {
                let len = (self.recv_off[n + 1] - self.recv_off[n]) * k;
                let (mine, tail) = std::mem::take(&mut rest).split_at_mut(len);
                rest = tail;
                let proc = comm.process_at_rank(src);
                // Chunks are matched in order: MPI does not reorder messages of one
                // (source, tag, communicator).
                for chunk in mine.chunks_mut(MAX_COUNT) {
                    guards.push(WaitGuard::from(
                        proc.immediate_receive_into_with_tag(scope, chunk, HALO_TAG),
                    ));
                }
            }
            for (n, &dst) in self.send_ranks.iter().enumerate() {
                let part = &sendbuf[self.send_off[n] * k..self.send_off[n + 1] * k];
                let proc = comm.process_at_rank(dst);
                for chunk in part.chunks(MAX_COUNT) {
                    guards.push(WaitGuard::from(
                        proc.immediate_send_with_tag(scope, chunk, HALO_TAG),
                    ));
                }
            }
            drop(guards);
        });
        recv
    }
}

fn validate(ids: &[u64], pos: &[[f64; 2]], width: f64) -> Result<(), PartitionError> {
    if ids.len() != pos.len() {
        return Err(invalid(format!(
            "halo: {} ids but {} positions",
            ids.len(),
            pos.len()
        )));
    }
    if !(width.is_finite() && width > 0.0) {
        return Err(invalid(format!(
            "halo width must be finite and positive, got {width}"
        )));
    }
    if let Some(i) = pos
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(invalid(format!(
            "halo: item {} (id {}) has a non-finite position {:?}",
            i, ids[i], pos[i]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::validate;

    #[test]
    fn validation_rejects_bad_input() {
        assert!(validate(&[1, 2], &[[0.0, 0.0], [1.0, 1.0]], 0.5).is_ok());
        assert!(validate(&[], &[], 0.5).is_ok());
        assert!(validate(&[1], &[], 0.5).is_err());
        assert!(validate(&[1], &[[0.0, 0.0]], 0.0).is_err());
        assert!(validate(&[1], &[[0.0, 0.0]], f64::NAN).is_err());
        assert!(validate(&[1], &[[0.0, 0.0]], f64::INFINITY).is_err());
        let e = validate(&[7], &[[f64::NAN, 0.0]], 1.0).unwrap_err();
        assert!(e.to_string().contains("id 7"));
    }
}
