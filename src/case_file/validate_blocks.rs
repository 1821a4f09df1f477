//! The rules of [`super::validate`] applied by every rank to the blocks it read: the rules
//! across the whole file gather their facts by global id (each id's facts at rank
//! `id % size`), so no rank ever holds the whole case.

use std::collections::HashMap;
use std::path::Path;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use pfem_partition::{alltoallv, exscan_u64, fetch_pairs, locate};

use super::collective::agree;
use super::error::{CaseError, CaseErrorKind};
use super::gauss::GaussRecords;
use super::particles::ParticleSet;
use super::validate::{
    check_displaced, check_gauss_block, check_gauss_lengths, check_header, check_particles,
    check_triangle, duplicate_id, duplicate_key, missing_tracked,
};
use super::CaseHeader;
use crate::scene::Scene;

/// Sends each item to rank `id % size`.
fn by_id<T: Clone>(size: usize, items: impl Iterator<Item = (u64, T)>) -> Vec<Vec<T>> {
    let mut send = vec![Vec::new(); size];
    for (id, item) in items {
        send[(id % size as u64) as usize].push(item);
    }
    send
}

/// Collective. Every rule of a case file, on this rank's block of particles (rows `first..` of
/// `n`) and of `/gauss` records; every rank returns the same result.
pub fn validate_blocks(
    comm: &SimpleCommunicator,
    path: &Path,
    h: &CaseHeader,
    p: &ParticleSet,
    first: usize,
    n: u64,
    g: &GaussRecords,
) -> Result<Scene, CaseError> {
    let size = comm.size() as usize;
    let scene = agree(comm, path, check_header(path, h, n))?;
    let displaced = agree(comm, path, check_particles(path, h, &scene, p, first))?;
    let mut any = 0u8;
    comm.all_reduce_into(&u8::from(displaced), &mut any, SystemOperation::max());
    check_displaced(path, h, any != 0)?;
    let (gfirst, _) = exscan_u64(comm, g.len() as u64);
    let local =
        check_gauss_lengths(path, g).and_then(|_| check_gauss_block(path, g, gfirst as usize));
    agree(comm, path, local)?;

    let mut ids: Vec<u64> =
        alltoallv(comm, &by_id(size, p.gid.iter().map(|&id| (id, id)))).concat();
    ids.sort_unstable();
    agree(comm, path, duplicate_id(path, &ids))?;

    // Every rank asks for the same tracked ids, so every rank finds the same one missing.
    let owners = locate(comm, &p.gid, &h.tracked_gids);
    if let Some(k) = owners.iter().position(|&o| o < 0) {
        return Err(missing_tracked(path, k, h.tracked_gids[k]));
    }

    let vertices: Vec<u64> = g.key.iter().flatten().copied().collect();
    let owners = locate(comm, &p.gid, &vertices);
    let requests: Vec<(i32, [u64; 2])> = vertices
        .iter()
        .zip(&owners)
        .filter(|(_, &o)| o >= 0)
        .flat_map(|(&v, &o)| [(o, [v, 0]), (o, [v, 1])])
        .collect();
    let at: HashMap<u64, [f64; 2]> = p
        .gid
        .iter()
        .copied()
        .zip(p.position.iter().copied())
        .collect();
    let answers = fetch_pairs(comm, &requests, |k| {
        let x = at.get(&k[0]).map_or(f64::NAN, |x| x[k[1] as usize & 1]);
        Ok(x.to_bits())
    })
    .map_err(|e| CaseError::new(path, CaseErrorKind::Io, e.to_string()))?;
    let mut next = answers.chunks_exact(2);
    let mut local = Ok(());
    for (t, key) in g.key.iter().enumerate() {
        let corners: [Option<[f64; 2]>; 3] = std::array::from_fn(|v| {
            (owners[3 * t + v] >= 0)
                .then(|| next.next())
                .flatten()
                .map(|c| [f64::from_bits(c[0]), f64::from_bits(c[1])])
        });
        local = check_triangle(path, *key, corners);
        if local.is_err() {
            break;
        }
    }
    agree(comm, path, local)?;

    let keys: Vec<u64> = alltoallv(
        comm,
        &by_id(size, g.key.iter().map(|k| (k[0], *k)))
            .iter()
            .map(|v| v.iter().flatten().copied().collect::<Vec<u64>>())
            .collect::<Vec<_>>(),
    )
    .concat();
    let mut keys: Vec<[u64; 3]> = keys.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    keys.sort_unstable();
    agree(comm, path, duplicate_key(path, &keys))?;
    Ok(scene)
}
