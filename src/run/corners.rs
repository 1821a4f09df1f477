//! A mesh node on every sharp corner of a rigid body that the soil wraps.
//!
//! Round a corner whose radius is below the particle spacing, one P2 edge cannot follow the
//! body: the soil's boundary cuts the corner with a chord, and as the soil flows round it the
//! chord either sags below the corner (a wedge of soil under the corner carries no load) or
//! cuts into the body, until a particle passes the corner and flips its contact normal; the
//! load jumps at each pass. So at every remesh the boundary particle nearest to such a corner
//! is moved onto it as smoothing moves a particle: it takes the old field's values there, and
//! the triangles around it are mapped afresh. The corner's node follows the body while the
//! soil flows past it (an arbitrary Lagrangian–Eulerian node); moving the particle with its own
//! state instead held one material point at the corner for the whole run.

use super::Simulation;
use crate::mesh::LocalMesh;
use crate::particles::flag;
use crate::rigid::shape::Corner;
use crate::rigid::Shape;
use pfem_partition::{allgather_u64, Comm};
use std::collections::HashSet;

/// A boundary particle within this fraction of its spacing of a corner is put on it.
const SNAP: f64 = 0.3;

/// A corner already has its node when a particle lies this close (in its spacing).
const ON_CORNER: f64 = 1e-3;

/// Only corners where the outline turns by at least this much (radians, about 29°): the
/// spudcan's 13° underside meets its tip at 26° and needs no node there.
const MIN_TURN: f64 = 0.5;

/// A corner whose rounding `radius` spans this many spacings or more is followed by the soil's
/// curved edges and needs no node.
const RESOLVED: f64 = 1.0;

/// The corners of `bodies` that the soil may need a node on: those where the outline turns by
/// [`MIN_TURN`] or more, the middle of their arc outside every other body (a corner hidden
/// inside another body, as the cone's top inside the penetrometer's shaft, touches no soil).
/// In a fixed order, the same on every rank.
pub(super) fn sharp_corners(bodies: &[Shape]) -> Vec<(u32, Corner)> {
    let mut out = Vec::new();
    for (b, shape) in bodies.iter().enumerate() {
        for corner in shape.corners().into_iter().filter(|c| c.turn() >= MIN_TURN) {
            let middle = corner.middle();
            let hidden = bodies
                .iter()
                .enumerate()
                .any(|(o, other)| o != b && other.closest(middle).distance < 0.0);
            if !hidden {
                out.push((b as u32, corner));
            }
        }
    }
    out
}

/// Of the candidates `(index, position, spacing, key)`, the one nearest to the middle of `corner`
/// within [`SNAP`] of its spacing where the corner is not resolved, with its distance; ties go
/// to the smaller key.
pub(super) fn nearest_candidate(
    corner: &Corner,
    candidates: impl Iterator<Item = (usize, [f64; 2], f64, u64)>,
) -> Option<(f64, u64, usize)> {
    let c = corner.middle();
    let mut best: Option<(f64, u64, usize)> = None;
    for (i, x, h, key) in candidates {
        if corner.radius >= RESOLVED * h {
            continue;
        }
        let d = (x[0] - c[0]).hypot(x[1] - c[1]);
        if d >= SNAP * h {
            continue;
        }
        if best.is_none_or(|(bd, bk, _)| (d, key) < (bd, bk)) {
            best = Some((d, key, i));
        }
    }
    best
}

impl Simulation {
    /// Collective. For every sharp corner of a rigid body at the current load factor (see
    /// [`sharp_corners`]), the owned boundary particle of `mesh` nearest to it within [`SNAP`]
    /// of its spacing and the corner, unless a particle is on the corner already; only bodies
    /// with `corner_nodes`. Particles in `removed` (merged away by this refinement) are left
    /// out; one held by a support or tracked is not moved, and being nearest it keeps the
    /// corner from the others. The nearest is chosen over all ranks (distance, then global
    /// id), so the partition does not change the choice.
    pub(super) fn corner_moves(
        &self,
        world: &Comm,
        mesh: &LocalMesh,
        removed: &HashSet<u32>,
    ) -> Vec<(u32, [f64; 2])> {
        let lambda = self.header.load_factor;
        let bodies: Vec<Shape> = self.model.bodies.iter().map(|b| b.shape(lambda)).collect();
        let corners: Vec<(u32, Corner)> = sharp_corners(&bodies)
            .into_iter()
            .filter(|(b, _)| self.model.bodies[*b as usize].corner_nodes)
            .collect();
        if corners.is_empty() {
            return Vec::new();
        }
        let p = &self.particles;
        let free = |i: usize| {
            p.flags[i] & flag::TRACKED == 0
                && self
                    .model
                    .step_bc(p.reference_position(i), p.position[i], lambda, lambda)
                    .iter()
                    .all(Option::is_none)
        };
        // A particle about to be merged away leaves the corner to the next nearest.
        let boundary: Vec<usize> = (0..mesh.n_owned.min(mesh.on_boundary.len()))
            .filter(|&i| mesh.on_boundary[i] && !removed.contains(&(i as u32)))
            .collect();
        let mut local = Vec::with_capacity(2 * corners.len());
        let mut picks = Vec::with_capacity(corners.len());
        for (_, corner) in &corners {
            let near = boundary
                .iter()
                .map(|&i| (i, mesh.points[i], mesh.h[i], mesh.gids[i]));
            let best = nearest_candidate(corner, near);
            local.extend(match best {
                Some((d, key, _)) => [d.to_bits(), key],
                None => [u64::MAX, u64::MAX],
            });
            picks.push(best);
        }
        let all = allgather_u64(world, &local);
        let mut moves = Vec::new();
        let mut taken = HashSet::new();
        for (k, ((_, corner), pick)) in corners.iter().zip(&picks).enumerate() {
            // Non-negative distances order as their bit patterns do.
            let global = all
                .chunks_exact(2 * corners.len())
                .map(|r| (r[2 * k], r[2 * k + 1]))
                .min()
                .filter(|&(bits, _)| bits != u64::MAX);
            let (Some((_, key)), Some((d, mine, i))) = (global, *pick) else {
                continue;
            };
            if mine != key || !free(i) || d < ON_CORNER * mesh.h[i] || !taken.insert(i) {
                continue;
            }
            let c = corner.middle();
            moves.push((i as u32, c));
        }
        moves
    }
}

#[cfg(test)]
mod tests;
