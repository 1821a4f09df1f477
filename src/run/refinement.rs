//! Applying the refinement plan (method Fig. 4) to the distributed particles: new global ids that
//! do not depend on the rank count, state carried to new and moved particles.

use super::Simulation;
use crate::fem::recovery::{barycentric, interpolate_linear};
use crate::mesh::refine::{deep_chords, plan, RefineParams};
use crate::mesh::LocalMesh;
use crate::particles::flag;
use pfem_partition::{allgather_u64, sum_f64, Comm};
use std::collections::HashSet;

/// A boundary particle this close to a rigid body (in its spacing) slides on it.
const SLIDING_GAP: f64 = 0.1;

/// A boundary chord cutting this deep into a rigid body (in its spacing) is split
/// (`deep_chords`).
const MAX_CHORD_DEPTH: f64 = 0.1;

/// ...if it is longer than this (in its spacing): its halves are no closer than the merge
/// distance (0.4). At 1.0, chords of 0.8–1.0 spacing round `footing-gradient`'s rounded edge
/// (radius 0.8 spacing) cut 0.19 spacing into it unsplit, and their midside nodes, rebuilt
/// straight at every remesh, stalled Newton at step 75.
const MIN_CHORD_SPLIT: f64 = 0.8;

impl Simulation {
    /// Collective. Inserts, removes and smooths particles as the scene asks; returns whether
    /// anything changed anywhere (then the mesh must be rebuilt).
    pub(super) fn refine(
        &mut self,
        world: &Comm,
        mesh: &LocalMesh,
    ) -> Result<bool, super::RunError> {
        let settings = &self.model.scene.mesh;
        if !settings.refine && !settings.smooth {
            return Ok(false);
        }
        let params = RefineParams {
            smooth: settings.smooth,
            independent_merges: settings.adapt.is_some(),
            ..Default::default()
        };
        let protected = |p: usize| {
            self.particles.flags[p] & flag::TRACKED != 0
                || self
                    .model
                    .step_bc(
                        self.particles.reference_position(p),
                        self.particles.position[p],
                        self.header.load_factor,
                        self.header.load_factor,
                    )
                    .iter()
                    .any(Option::is_some)
        };
        let lambda = self.header.load_factor;
        let bodies: Vec<_> = self.model.bodies.iter().map(|b| b.shape(lambda)).collect();
        // Signed distance to the nearest body (negative inside; infinite without bodies).
        let gap = |x: [f64; 2]| crate::rigid::gap(&bodies, x);
        let slides = |p: usize| gap(mesh.points[p]) <= SLIDING_GAP * mesh.h[p];
        // A particle held in one direction only (a symmetry plane) near a body: its distance
        // to the body. Read for ghosts too, from their reference positions, as every rank
        // holding the point has them bit for bit.
        let support_gap = |p: usize| {
            if bodies.is_empty() {
                return None;
            }
            let bc = self.model.step_bc(
                self.reference_position(mesh, p),
                mesh.points[p],
                lambda,
                lambda,
            );
            (bc.iter().filter(|c| c.is_some()).count() == 1).then(|| gap(mesh.points[p]))
        };
        let mut plan = plan(mesh, protected, slides, support_gap, &params);
        if settings.refine && !bodies.is_empty() {
            for e in deep_chords(mesh, |x| -gap(x), MAX_CHORD_DEPTH, MIN_CHORD_SPLIT) {
                if !plan.split.contains(&e) {
                    plan.split.push(e);
                }
            }
        }
        if !settings.refine {
            plan.split.clear();
            plan.remove.clear();
        }
        let removing: HashSet<u32> = plan.remove.iter().copied().collect();
        let corners = self.corner_moves(world, mesh, &removing);
        plan.smooth
            .retain(|(p, _)| !corners.iter().any(|(c, _)| c == p));
        let changes = sum_f64(
            world,
            &[(plan.split.len() + plan.remove.len() + plan.smooth.len() + corners.len()) as f64],
        )[0];
        if changes == 0.0 {
            return Ok(false);
        }
        let n = mesh.n_owned;
        let value = |p: usize| {
            if p < n {
                self.particles.state.row(p)
            } else {
                self.ghosts.state.row(p - n)
            }
        };
        let disp = |p: usize| {
            if p < n {
                self.particles.displacement[p]
            } else {
                self.ghosts.displacement[p - n]
            }
        };
        let incr = |p: usize| {
            if p < n {
                self.particles.increment[p]
            } else {
                self.ghosts.increment[p - n]
            }
        };

        // Smoothed particles take the old field's values at their new place.
        let mut moved = HashSet::new();
        let mut smoothed = Vec::new();
        for &(p, target) in &plan.smooth {
            if let Some((state, u)) = sample_star(mesh, p as usize, target, &value, &disp) {
                smoothed.push((p as usize, target, state, u));
                moved.insert(mesh.gids[p as usize]);
            }
        }
        // A corner's node takes the old field's values at the corner, which may lie just off
        // the soil's boundary chord: the nearest point of the triangles around it.
        for &(p, target) in &corners {
            if let Some((state, u)) = sample_nearest(mesh, p as usize, target, &value, &disp) {
                smoothed.push((p as usize, target, state, u));
                moved.insert(mesh.gids[p as usize]);
            }
        }
        // New particles at edge midpoints; ids by the global sorted order of their edges.
        let keys: Vec<u64> = plan
            .split
            .iter()
            .flat_map(|[a, b]| [mesh.gids[*a as usize], mesh.gids[*b as usize]])
            .collect();
        let mut all: Vec<[u64; 2]> = allgather_u64(world, &keys)
            .chunks_exact(2)
            .map(|c| [c[0], c[1]])
            .collect();
        all.sort_unstable();
        let first_new = self.header.next_gid;
        self.header.next_gid += all.len() as u64;

        let mid = |x: [f64; 2], y: [f64; 2]| [0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1])];
        let mut born = Vec::with_capacity(plan.split.len());
        for [a, b] in &plan.split {
            let (a, b) = (*a as usize, *b as usize);
            let key = [mesh.gids[a], mesh.gids[b]];
            let Ok(rank) = all.binary_search(&key) else {
                return Err(super::RunError::Refinement { edge: key });
            };
            let (sa, sb) = (value(a), value(b));
            let state: Vec<f64> = sa.iter().zip(sb).map(|(x, y)| 0.5 * (x + y)).collect();
            let (mut x, mut u) = (mid(mesh.points[a], mesh.points[b]), mid(disp(a), disp(b)));
            // A curved boundary edge is split on its curve, where its soil is.
            if let Some(c) = self.curved_midside(mesh, a, b) {
                u = [u[0] + c[0] - x[0], u[1] + c[1] - x[1]];
                x = c;
            }
            // A boundary chord round a body's corner cuts into the body: its new particle goes
            // onto the body's surface, where the soil it stands for is, instead of starting
            // inside and held there by the contact's start offset. (Only positions decide, so
            // that every rank decides alike whether an end is a ghost or not.)
            for shape in &bodies {
                let prox = shape.closest(x);
                if prox.distance < 0.0 {
                    for k in 0..2 {
                        x[k] -= prox.distance * prox.normal[k];
                        u[k] -= prox.distance * prox.normal[k];
                    }
                }
            }
            // Between two materials the new particle takes the one of the end with the smaller
            // global id: the same on every rank and for any partition.
            let first = if mesh.gids[a] < mesh.gids[b] { a } else { b };
            born.push((
                first_new + rank as u64,
                x,
                u,
                mid(incr(a), incr(b)),
                0.5 * (mesh.h[a] + mesh.h[b]),
                state,
                self.point_material(mesh, first),
            ));
        }
        let p = &mut self.particles;
        for (i, target, state, u) in smoothed {
            p.position[i] = target;
            p.displacement[i] = u;
            p.state.row_mut(i).copy_from_slice(&state);
        }
        for (gid, x, u, du, h, state, material) in born {
            p.gid.push(gid);
            p.position.push(x);
            p.displacement.push(u);
            p.increment.push(du);
            p.h.push(h);
            p.state.push(&state);
            p.flags.push(0);
            p.material.push(material);
        }
        let removed: HashSet<u64> = plan.remove.iter().map(|&r| mesh.gids[r as usize]).collect();
        if !removed.is_empty() {
            let keep: Vec<bool> = p.gid.iter().map(|g| !removed.contains(g)).collect();
            retain(&mut p.gid, &keep);
            retain(&mut p.position, &keep);
            retain(&mut p.displacement, &keep);
            retain(&mut p.increment, &keep);
            retain(&mut p.h, &keep);
            p.state.retain(&keep);
            retain(&mut p.flags, &keep);
            retain(&mut p.material, &keep);
        }
        p.sort_by_gid();
        // Every rank forgets the triangles around every moved particle, its ghosts' too: a
        // rank that kept its copy of an interface triangle whose far vertex its owner moved
        // would start the next step from Gauss states the owner had replaced, and the copies
        // of one triangle would differ between ranks from then on (and so would recovery,
        // checkpoints and the answer on another rank count).
        let mine: Vec<u64> = moved.into_iter().collect();
        let moved: HashSet<u64> = allgather_u64(world, &mine).into_iter().collect();
        self.tri_states.forget_touching(&moved);
        Ok(true)
    }
}

fn retain<T: Copy>(v: &mut Vec<T>, keep: &[bool]) {
    let mut i = 0;
    v.retain(|_| {
        i += 1;
        keep[i - 1]
    });
}

/// Linear interpolation of particle values at `target` inside a triangle around particle `p`.
fn sample_star<'a>(
    mesh: &LocalMesh,
    p: usize,
    target: [f64; 2],
    value: &impl Fn(usize) -> &'a [f64],
    disp: &impl Fn(usize) -> [f64; 2],
) -> Option<(Vec<f64>, [f64; 2])> {
    let (tri, bary) =
        star_coordinates(mesh, p, target).find(|(_, l)| l.iter().all(|&l| l >= -1e-12))?;
    Some(sample_at(tri, bary, value, disp))
}

/// The triangles around particle `p` with the barycentric coordinates of `target` in each,
/// where they are finite.
fn star_coordinates(
    mesh: &LocalMesh,
    p: usize,
    target: [f64; 2],
) -> impl Iterator<Item = ([usize; 3], [f64; 3])> + '_ {
    mesh.tris
        .iter()
        .filter(move |t| t.contains(&(p as u32)))
        .map(move |t| {
            let [a, b, c] = t.map(|v| v as usize);
            let bary = barycentric(mesh.points[a], mesh.points[b], mesh.points[c], target);
            ([a, b, c], bary)
        })
        .filter(|(_, l)| l.iter().all(|l| l.is_finite()))
}

/// Linear interpolation of particle values at the point nearest to `target` of the triangles
/// around particle `p`: the one whose smallest barycentric coordinate at `target` is largest,
/// its coordinates clipped to the triangle.
fn sample_nearest<'a>(
    mesh: &LocalMesh,
    p: usize,
    target: [f64; 2],
    value: &impl Fn(usize) -> &'a [f64],
    disp: &impl Fn(usize) -> [f64; 2],
) -> Option<(Vec<f64>, [f64; 2])> {
    let lowest = |l: &[f64; 3]| l.iter().copied().fold(f64::INFINITY, f64::min);
    let mut best: Option<([usize; 3], [f64; 3])> = None;
    for (tri, bary) in star_coordinates(mesh, p, target) {
        if best.is_none_or(|(_, b)| lowest(&bary) > lowest(&b)) {
            best = Some((tri, bary));
        }
    }
    let (tri, bary) = best?;
    let clipped = bary.map(|l| l.max(0.0));
    let sum: f64 = clipped.iter().sum();
    if sum <= 0.0 {
        return None;
    }
    Some(sample_at(tri, clipped.map(|l| l / sum), value, disp))
}

/// The state and displacement at barycentric coordinates `bary` of triangle `tri`.
fn sample_at<'a>(
    tri: [usize; 3],
    bary: [f64; 3],
    value: &impl Fn(usize) -> &'a [f64],
    disp: &impl Fn(usize) -> [f64; 2],
) -> (Vec<f64>, [f64; 2]) {
    let vals = tri.map(value);
    let mut state = vec![0.0; vals[0].len()];
    for (l, v) in bary.iter().zip(vals) {
        for (o, x) in state.iter_mut().zip(v) {
            *o += l * x;
        }
    }
    (state, interpolate_linear(bary, &tri.map(disp)))
}
