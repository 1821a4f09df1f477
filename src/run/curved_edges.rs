//! Curved boundary edges carried across a remesh (`crate::mesh::curved`): recorded from each
//! converged increment, given back to the boundary edges of the next mesh that join the same two
//! particles. The table is small (one entry per boundary edge) and every rank keeps all of it,
//! so a mesh's curves do not depend on the partition, and a checkpoint restarts on any rank count.

use super::step::edge_key;
use super::Simulation;
use crate::mesh::curved::{bulge, keeps_shape, midside, MAX_BULGE, MIN_BULGE};
use crate::mesh::LocalMesh;
use crate::rigid::{exit, gap, nearest};
use crate::solve::DofMap;
use pfem_partition::{allgather_u64, Comm};
use std::collections::{HashMap, HashSet};

/// A midside node within this fraction of its spacing of a rigid body at the end of the
/// increment lies on it.
const ON_BODY: f64 = 0.01;

/// On a rigid body a curve is kept only where the straight chord would cut into the body by at
/// least this fraction of the spacing: round a corner of radius 1.6 spacings (the built-in
/// footing's) a chord cuts in by 0.08, round the T-bars' circles (radius 4 spacings) by 0.03,
/// which the contact's start offset already holds. Carried there as well, the shallow curves made
/// single steps of the smooth T-bar dip by up to 10 % (the cause not found; measured 2026-11-28,
/// bench/VALIDATION.md); free surfaces keep every curve.
const DEEP_CHORD: f64 = 0.05;

/// The least turn (radians) of a body's surface between the ends of a chord that makes it a
/// chord across a corner (`onto_surface`): the spudcan's rim turns 77°, a chord of the split
/// length on the default T-bar's face 23°.
const MIN_CORNER_TURN: f64 = std::f64::consts::FRAC_PI_4;

/// Relative midside offset ([`bulge`]) per boundary edge, by sorted gid pair, sorted.
pub(super) type Bulges = Vec<([u64; 2], f64)>;

/// Collective. Every rank's entries, sorted by key, of repeated keys the first (they are equal:
/// computed from the same bits on every rank that holds the edge).
pub(super) fn gather(world: &Comm, local: &[([u64; 2], f64)]) -> Bulges {
    let flat: Vec<u64> = local
        .iter()
        .flat_map(|(k, s)| [k[0], k[1], s.to_bits()])
        .collect();
    let mut all: Bulges = allgather_u64(world, &flat)
        .chunks_exact(3)
        .map(|c| ([c[0], c[1]], f64::from_bits(c[2])))
        .collect();
    all.sort_by_key(|e| e.0);
    all.dedup_by_key(|e| e.0);
    all
}

/// The curve `s` of chord `a`→`b`, or as much of it as keeps its midside node out of every rigid
/// body: the last increment kept the node out of the body only where it was a contact node, and
/// a node left inside would stay inside, the contact holding it at its starting depth. Only
/// positions decide, so every rank finds the same.
fn outside_bodies(shapes: &[crate::rigid::Shape], a: [f64; 2], b: [f64; 2], s: f64) -> f64 {
    let depth = |s: f64| gap(shapes, midside(a, b, s));
    if depth(s) >= 0.0 {
        return s;
    }
    if depth(0.0) < 0.0 {
        // The chord itself cuts in: the shallower of the two.
        return if depth(0.0) >= depth(s) { 0.0 } else { s };
    }
    // Out at 0, in at s: the crossing, from the outside.
    exit(s, 0.0, |t| depth(t) >= 0.0)
}

/// The curve that puts the midside node of chord `a`→`b` (key order) on the surface of the
/// rigid body the chord's midpoint lies in, as far as a P2 edge can bend ([`MAX_BULGE`]); `None`
/// when the midpoint lies outside every body or less than `min_depth` inside. A chord formed by
/// the remesh across a body's corner (a particle on each face) has no recorded curve; left
/// straight, its midside node starts inside the corner, where the closest point jumps between
/// the faces as it moves: on the `spudcan` such a node at the rim took Newton directions of
/// 0.5-0.8 m in pieces of 0.0125 m and stalled the step. Only positions decide, so every rank
/// finds the same.
fn onto_surface(
    shapes: &[crate::rigid::Shape],
    a: [f64; 2],
    b: [f64; 2],
    min_depth: f64,
) -> Option<f64> {
    let start = nearest(shapes, midside(a, b, 0.0))?;
    if start.distance > -min_depth {
        return None;
    }
    // Only across a corner: on a smooth face a chord dips in by its sagitta L²/8R, which the
    // contact's start offset tolerates, and bending the default T-bar's chords of 1.3–1.6
    // spacings (0.05–0.08 spacing deep, the face turning 20–23° along them) onto its face made
    // its load fall 10 % from w/D = 1.25 on.
    let (na, nb) = (nearest(shapes, a)?.normal, nearest(shapes, b)?.normal);
    if na[0] * nb[0] + na[1] * nb[1] > MIN_CORNER_TURN.cos() {
        return None;
    }
    // The offset direction (the chord's right-hand normal, `midside`) that leads out.
    let d = [b[0] - a[0], b[1] - a[1]];
    let out = start.normal[0] * d[1] - start.normal[1] * d[0];
    let far = MAX_BULGE.copysign(out);
    let outside = |t: f64| gap(shapes, midside(a, b, t)) >= 0.0;
    if !outside(far) {
        return Some(far);
    }
    Some(exit(0.0, far, outside))
}

/// Sorted gid keys of the boundary edges of `mesh` that touch an owned particle.
fn boundary_keys(mesh: &LocalMesh) -> HashSet<[u64; 2]> {
    mesh.boundary_edges
        .iter()
        .map(|e| edge_key(mesh.gids[e[0] as usize], mesh.gids[e[1] as usize]))
        .collect()
}

impl Simulation {
    /// Where the last increment left the midside node of the boundary edge between local points
    /// `a` and `b` of `mesh` (a mesh of the current particles), if it recorded a curve there.
    pub(super) fn curved_midside(&self, mesh: &LocalMesh, a: usize, b: usize) -> Option<[f64; 2]> {
        let (mut a, mut b) = (a, b);
        if mesh.gids[a] > mesh.gids[b] {
            std::mem::swap(&mut a, &mut b);
        }
        let key = [mesh.gids[a], mesh.gids[b]];
        let i = self.bulges.binary_search_by_key(&key, |e| e.0).ok()?;
        Some(midside(mesh.points[a], mesh.points[b], self.bulges[i].1))
    }

    /// Collective. Records the curve of every boundary edge of `mesh` at the end of the
    /// increment `du` (per node of `dofs`) that ends at load factor `to`: on free surfaces
    /// all, on rigid bodies the deep ones ([`DEEP_CHORD`]).
    pub(super) fn record_bulges(
        &mut self,
        world: &Comm,
        mesh: &LocalMesh,
        dofs: &DofMap,
        du: &[[f64; 2]],
        to: f64,
    ) {
        if !self.model.scene.mesh.curved_edges {
            return;
        }
        let shapes: Vec<_> = self.model.bodies.iter().map(|b| b.shape(to)).collect();
        let boundary = boundary_keys(mesh);
        let mut local = Vec::with_capacity(boundary.len());
        let moved = |node: u32, x: [f64; 2]| {
            let d = du[node as usize];
            [x[0] + d[0], x[1] + d[1]]
        };
        for (t, tri) in mesh.tris.iter().enumerate() {
            for (k, [i, j]) in crate::fem::p2::EDGES.iter().enumerate() {
                let (mut a, mut b) = (tri[*i], tri[*j]);
                if mesh.gids[a as usize] > mesh.gids[b as usize] {
                    std::mem::swap(&mut a, &mut b);
                }
                let key = [mesh.gids[a as usize], mesh.gids[b as usize]];
                if !boundary.contains(&key) {
                    continue;
                }
                let nodes = dofs.tri_nodes[t];
                let xa = moved(dofs.node_of_point[a as usize], mesh.points[a as usize]);
                let xb = moved(dofs.node_of_point[b as usize], mesh.points[b as usize]);
                let xm = moved(nodes[3 + k], mesh.midside(a, b));
                let s = bulge(xa, xb, xm);
                let h = mesh.h[a as usize].max(mesh.h[b as usize]);
                let on_body = shapes
                    .iter()
                    .any(|sh| sh.closest(xm).distance <= ON_BODY * h);
                let len = (xb[0] - xa[0]).hypot(xb[1] - xa[1]);
                let keep = !on_body || s.abs() * len >= DEEP_CHORD * h;
                if keep && (MIN_BULGE..=MAX_BULGE).contains(&s.abs()) {
                    local.push((key, s));
                }
            }
        }
        self.bulges = gather(world, &local);
    }

    /// Collective. Curves the boundary edges of the new `mesh` that were boundary edges of the
    /// last one (the same two particles), unless that folds their triangle; the triangle's owner
    /// decides, every rank applies.
    pub(super) fn curve_boundary(&self, world: &Comm, mesh: &mut LocalMesh) {
        mesh.curved.clear();
        if !self.model.scene.mesh.curved_edges {
            return;
        }
        // Boundary edges of the new mesh with a recorded curve: every rank's, so that an edge
        // of a triangle this rank holds whose particles are both ghosts is known as well.
        // An edge without one whose chord cuts into a body by `DEEP_CHORD` of the spacing or
        // more (the depth from which curves on bodies are recorded) is fitted to its surface.
        let lambda = self.header.load_factor;
        let shapes: Vec<_> = self.model.bodies.iter().map(|b| b.shape(lambda)).collect();
        let index: HashMap<u64, u32> = mesh
            .gids
            .iter()
            .enumerate()
            .map(|(i, &g)| (g, i as u32))
            .collect();
        let found = |key: &[u64; 2]| self.bulges.binary_search_by_key(key, |e| e.0).ok();
        let fitted = |key: &[u64; 2]| -> Option<f64> {
            if shapes.is_empty() {
                return None;
            }
            let (a, b) = (*index.get(&key[0])? as usize, *index.get(&key[1])? as usize);
            let h = mesh.h[a].max(mesh.h[b]);
            onto_surface(&shapes, mesh.points[a], mesh.points[b], DEEP_CHORD * h)
        };
        let local: Vec<([u64; 2], f64)> = boundary_keys(mesh)
            .into_iter()
            .filter_map(|k| match found(&k) {
                Some(i) => Some(self.bulges[i]),
                None => fitted(&k).map(|s| (k, s)),
            })
            .collect();
        let candidates = gather(world, &local);
        if candidates.is_empty() {
            return;
        }
        let place = |key: &[u64; 2], s: f64| -> Option<[f64; 2]> {
            let a = mesh.points[*index.get(&key[0])? as usize];
            let b = mesh.points[*index.get(&key[1])? as usize];
            Some(midside(a, b, outside_bodies(&shapes, a, b, s)))
        };
        mesh.curved = candidates
            .iter()
            .filter_map(|(k, s)| place(k, *s).map(|m| (*k, m)))
            .collect();
        // The owner of each triangle with a curved edge checks its shape.
        let mut rejected = Vec::new();
        for t in 0..mesh.tris.len() {
            if !mesh.tri_owned[t] {
                continue;
            }
            let key = mesh.tri_key(t);
            let edges = crate::fem::p2::EDGES.map(|[i, j]| edge_key(key[i], key[j]));
            let curved: Vec<[u64; 2]> = edges
                .into_iter()
                .filter(|e| mesh.curved.binary_search_by_key(e, |c| c.0).is_ok())
                .collect();
            if !curved.is_empty() && !keeps_shape(&mesh.element_nodes(t)) {
                rejected.extend(curved.iter().flat_map(|e| [e[0], e[1], 0]));
            }
        }
        let rejected = gather(
            world,
            &rejected
                .chunks_exact(3)
                .map(|c| ([c[0], c[1]], 0.0))
                .collect::<Vec<_>>(),
        );
        mesh.curved
            .retain(|(k, _)| rejected.binary_search_by_key(k, |e| e.0).is_err());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rigid::Shape;

    #[test]
    fn a_curve_into_a_body_stops_at_its_surface() {
        // A unit circle below the chord y = 1.1 from x = -0.5 to 0.5: the chord's midpoint is
        // 0.1 above it; a downward curve of 0.3 of the chord would put the node 0.2 inside.
        let circle = [Shape::circle([0.0, 0.0], 1.0).unwrap()];
        let (a, b) = ([-0.5, 1.1], [0.5, 1.1]);
        let s = outside_bodies(&circle, a, b, 0.3);
        let m = midside(a, b, s);
        assert!((m[1] - 1.0).abs() < 1e-9 && m[0].abs() < 1e-15, "{m:?}");
        // A curve away from the body, or with no body, is kept.
        assert_eq!(outside_bodies(&circle, a, b, -0.2), -0.2);
        assert_eq!(outside_bodies(&[], a, b, 0.3), 0.3);
        // A chord cutting in keeps whichever of chord and curve lies shallower.
        let (a, b) = ([-0.5, 0.95], [0.5, 0.95]);
        assert_eq!(outside_bodies(&circle, a, b, 0.1), 0.0);
        assert_eq!(outside_bodies(&circle, a, b, -0.1), -0.1);
    }

    #[test]
    fn a_chord_cutting_into_a_body_is_fitted_to_its_surface() {
        let circle = [Shape::circle([0.0, 0.0], 1.0).unwrap()];
        // The chord y = 0.9 from x = -0.5 to 0.5 cuts 0.1 into the unit circle: its midside
        // node goes onto the surface at (0, 1).
        let (a, b) = ([-0.5, 0.9], [0.5, 0.9]);
        let s = onto_surface(&circle, a, b, 0.05).unwrap();
        let m = midside(a, b, s);
        assert!(m[0].abs() < 1e-15 && (m[1] - 1.0).abs() < 1e-9, "{m:?}");
        // The same chord reversed bends the other way to the same point.
        let r = onto_surface(&circle, b, a, 0.05).unwrap();
        assert!((r + s).abs() < 1e-12);
        // Shallower than asked, or outside: no curve.
        assert_eq!(onto_surface(&circle, a, b, 0.2), None);
        assert_eq!(onto_surface(&circle, [-0.5, 1.2], [0.5, 1.2], 0.0), None);
        assert_eq!(onto_surface(&[], a, b, 0.0), None);
        // A short chord deep inside a corner bends as far as a P2 edge may, and no further.
        let square =
            [Shape::polygon(&[[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]], 0.0).unwrap()];
        let (a, b) = ([0.6, 0.9], [0.9, 0.6]);
        let s = onto_surface(&square, a, b, 0.05).unwrap();
        assert_eq!(s.abs(), MAX_BULGE);
        let m = midside(a, b, s);
        assert!(m[0] + m[1] > 1.5, "{m:?}");
        // Along a smooth face (radius 4, a chord of 1.6 turning 23°, 0.08 deep): left straight.
        let big = [Shape::circle([0.0, 0.0], 4.0).unwrap()];
        let (a, b) = ([-0.8, 3.919], [0.8, 3.919]);
        assert!(gap(&big, midside(a, b, 0.0)) < -0.05);
        assert_eq!(onto_surface(&big, a, b, 0.05), None);
    }
}
