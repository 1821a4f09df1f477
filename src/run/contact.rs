//! Contact and surface pressure of an increment: found afresh on the mesh after every remesh,
//! with the contact state carried across it by node identity.

use super::step::edge_key;
use super::Simulation;
use crate::fem::surface_load::simpson_weights;
use crate::mesh::LocalMesh;
use crate::rigid::{ContactPair, NodeLaw, Shape, Status};
use crate::solve::{Constraints, DofMap};
use std::collections::HashMap;

/// Contact pairs with each pair's node spacing, the bodies at the end of the increment, and the
/// surface-pressure edges.
pub(super) struct BoundaryLoads {
    pub pairs: Vec<ContactPair>,
    pub spacing: Vec<f64>,
    pub bodies: Vec<Shape>,
    pub surface: Vec<([u32; 3], f64)>,
    /// Boundary edges each `[[surface_pressure]]` entry selects on this rank.
    pub surface_edges: Vec<usize>,
}

/// Contact state kept per node between increments: (node key, body) → (pressure, shear) of
/// the nodes touching at the end of the last one.
pub(super) type ContactState = HashMap<([u64; 2], u32), [f64; 2]>;

impl Simulation {
    /// Rank-local. Boundary nodes near each rigid body become contact pairs (owned nodes with a
    /// free component only; the search looks only inside each body's box grown by the search
    /// margin), and boundary
    /// edges whose ends started inside a `[[surface_pressure]]` region carry its pressure.
    pub(super) fn boundary_loads(
        &self,
        mesh: &LocalMesh,
        dofs: &DofMap,
        constraints: &Constraints,
        from: f64,
        to: f64,
    ) -> BoundaryLoads {
        let model = &self.model;
        let bodies: Vec<Shape> = model.bodies.iter().map(|b| b.shape(to)).collect();
        let mut out = BoundaryLoads {
            pairs: Vec::new(),
            spacing: Vec::new(),
            bodies,
            surface: Vec::new(),
            surface_edges: vec![0; model.scene.surface_pressure.len()],
        };
        if model.bodies.is_empty() && model.scene.surface_pressure.is_empty() {
            return out;
        }
        let n_vertex = dofs.n_nodes() - dofs.edges.len();
        let edge_node: HashMap<(u32, u32), u32> = dofs
            .edges
            .iter()
            .enumerate()
            .map(|(i, e)| ((e[0], e[1]), (n_vertex + i) as u32))
            .collect();
        // (nodes [a, m, b], the nodes' positions, the nodes' weights, spacing, whether it runs
        // along a support, `along_support`) of every boundary edge.
        type Edge = ([u32; 3], [[f64; 2]; 3], [f64; 3], f64, bool);
        let mut edges: Vec<Edge> = Vec::new();
        let analysis = model.scene.analysis;
        for e in &mesh.boundary_edges {
            let [a, b] = *e;
            let (ga, gb) = (mesh.gids[a as usize], mesh.gids[b as usize]);
            let pair = if ga < gb { (a, b) } else { (b, a) };
            let Some(&m) = edge_node.get(&pair) else {
                continue;
            };
            let na = dofs.node_of_point[a as usize];
            let nb = dofs.node_of_point[b as usize];
            let (xa, xb) = (mesh.points[a as usize], mesh.points[b as usize]);
            let len = ((xb[0] - xa[0]).powi(2) + (xb[1] - xa[1]).powi(2)).sqrt();
            let mid = mesh.midside(a, b);
            // The length (axisymmetry: the ring area) each node stands for, by Simpson's rule,
            // which is exact on a straight edge. A node on the axis stands for no area; it
            // carries its force R all the same, and the length of a ring an eighth of the edge
            // out only scales its pressure in the contact decision.
            let simpson = simpson_weights(len);
            let ring = |x: [f64; 2]| {
                let r = if x[0] > model.tol { x[0] } else { 0.125 * len };
                analysis.measure(r)
            };
            let weights = [
                ring(xa) * simpson[0],
                ring(mid) * simpson[1],
                ring(xb) * simpson[2],
            ];
            let on_support = along_support(
                |n, c| constraints.is_fixed(n as usize, c),
                [na, m, nb],
                xa,
                xb,
            );
            edges.push((
                [na, m, nb],
                [xa, mid, xb],
                weights,
                mesh.h[a as usize].max(mesh.h[b as usize]),
                on_support,
            ));
            for (k, sp) in model.scene.surface_pressure.iter().enumerate() {
                let inside = |p: u32| {
                    let x0 = self.reference_position(mesh, p as usize);
                    sp.region.matches(x0, model.tol) && model.on(sp.on.as_deref(), x0)
                };
                if inside(a) && inside(b) {
                    out.surface.push(([na, m, nb], sp.pressure));
                    out.surface_edges[k] += 1;
                }
            }
        }
        if model.bodies.is_empty() {
            return out;
        }
        let young = model.scene.material.young;
        let carried = self.last_contact.borrow();
        let none = ContactState::new();
        let state = if model.scene.contact.carry_state {
            &*carried
        } else {
            &none
        };
        // Each pair's distance to its body at the start (to keep the nearest body's pair).
        let mut start_distance = Vec::new();
        // Each pair's boundary edges facing its body (edge index, the node's weight on it).
        let mut facing_edges: Vec<Vec<(usize, f64)>> = Vec::new();
        // Nodes left out by the corner rule below.
        let mut cut_corners: Vec<CutCorner> = Vec::new();
        for (bi, body) in model.bodies.iter().enumerate() {
            let shape = &out.bodies[bi];
            let shape_from = body.shape(from);
            let d0 = body.displacement(from);
            let d1 = body.displacement(to);
            let inc = [d1[0] - d0[0], d1[1] - d0[1]];
            let moved = inc[0].hypot(inc[1]);
            let bb = shape.bounding_box();
            // A node's weight counts only the boundary edges facing this body (midpoint within
            // a quarter spacing of it, plus its motion): a corner node of a platen does not
            // stand for the free side below it, whose length would add to its share of α·cu.
            let mut weight: HashMap<u32, Vec<(usize, f64)>> = HashMap::new();
            let near = |x: &[f64; 2], h: f64| {
                let margin = 0.25 * h + moved;
                let outside_box = x[0] < bb[0][0] - margin
                    || x[0] > bb[1][0] + margin
                    || x[1] < bb[0][1] - margin
                    || x[1] > bb[1][1] + margin;
                !outside_box && shape.closest(*x).distance <= margin
            };
            for (ei, (nodes, xs, weights, h, on_support)) in edges.iter().enumerate() {
                if *on_support || !near(&xs[1], *h) {
                    continue;
                }
                for (node, wk) in nodes.iter().zip(weights) {
                    weight.entry(*node).or_default().push((ei, *wk));
                }
            }
            // A node near the body on no such edge (under a cone's tip, where the midpoints of
            // the edges beside it are still far off) stands for its own share of its edges.
            let mut tips: HashMap<u32, Vec<(usize, f64)>> = HashMap::new();
            for (ei, (nodes, xs, weights, h, _)) in edges.iter().enumerate().filter(|e| !e.1 .4) {
                for k in [0, 2] {
                    if !weight.contains_key(&nodes[k]) && near(&xs[k], *h) {
                        tips.entry(nodes[k]).or_default().push((ei, weights[k]));
                    }
                }
            }
            weight.extend(tips);
            let mut nodes: Vec<(u32, Vec<(usize, f64)>)> = weight
                .into_iter()
                .filter(|(n, _)| dofs.node_owned[*n as usize])
                .collect();
            nodes.sort_unstable_by_key(|(n, _)| *n);
            for (n, facing) in nodes {
                let w = facing.iter().map(|f| f.1).sum();
                let (x, h, key) = node_info(mesh, dofs, n as usize, n_vertex);
                // A midside node of an edge cut across a (rounded) corner starts well inside the
                // body, where the normal turns fast or jumps between faces: Newton stalls on
                // it. Its edge's ends carry the contact there. (A chord on a circle dips in by
                // h²/8R only.)
                let start = shape_from.closest(x).distance;
                if start < -0.25 * shape_from.radius() - 1e-6 * h {
                    cut_corners.push(CutCorner {
                        node: n,
                        body: bi as u32,
                        increment: inc,
                        suction: body.suction,
                        shear_limit: body.shear_limit,
                    });
                    continue;
                }
                let free = [0, 1].map(|c| !constraints.is_fixed(n as usize, c));
                if free == [false, false] {
                    continue;
                }
                // Touching: in contact at the end of the last increment, or, for a body that
                // holds suction, lying on it now (the soil on a bar's back follows it).
                let touching = state.contains_key(&(key, bi as u32))
                    || body.suction > 0.0 && start <= 0.01 * h;
                out.pairs.push(ContactPair {
                    node: n,
                    body: bi as u32,
                    partner: bi as u32,
                    partner_shear_limit: body.shear_limit,
                    start: x,
                    weight: w,
                    constant: model.scene.contact.penalty * young / h,
                    row_scale: young / h,
                    shear_limit: body.shear_limit,
                    body_increment: inc,
                    offset: start.min(0.0),
                    touching,
                    suction: body.suction,
                    free,
                });
                out.spacing.push(h);
                start_distance.push(start);
                facing_edges.push(facing);
            }
        }
        join_bodies(&mut out, &start_distance, &facing_edges);
        join_cut_corners(&mut out, &cut_corners);
        out
    }
}

/// A node the corner rule left out of one body's contact, with that body's motion and interface.
#[derive(Debug, Clone, Copy)]
struct CutCorner {
    node: u32,
    body: u32,
    increment: [f64; 2],
    suction: f64,
    /// α·cu (Pa).
    shear_limit: f64,
}

/// A node left out at one body's corner (`cut`) but paired with a body moving with it is held
/// against their union, as a node near both is ([`join_bodies`]). On the rough `cpt` a midside node 0.38 mm inside the cone's face beside
/// its hidden top corner (radius 0.5 mm) was left out of the cone but held against the shaft's
/// arc alone, which the cone hides there, 0.26 mm inside it; Newton cycled between holding it
/// and letting it go and stopped at z/D = 7.94.
fn join_cut_corners(out: &mut BoundaryLoads, cut: &[CutCorner]) {
    for p in &mut out.pairs {
        let with = cut.iter().find(|c| {
            p.partner == p.body
                && c.node == p.node
                && c.body != p.body
                && c.increment == p.body_increment
                && c.suction == p.suction
        });
        if let Some(c) = with {
            p.partner = c.body;
            p.partner_shear_limit = c.shear_limit;
        }
    }
}

/// A node near two bodies holds its rows for one law only: it keeps the pair of the body it
/// starts nearest to (the lower body index on a tie), so that the choice does not depend on
/// the partition. When the other body moves with it (the same increment and suction: a cone
/// and the shaft above it), that body becomes the pair's partner, the node is held against
/// their union (by the strength of the face it is on), and it stands for the boundary edges
/// facing either.
fn join_bodies(out: &mut BoundaryLoads, start_distance: &[f64], facing: &[Vec<(usize, f64)>]) {
    let mut best: HashMap<u32, usize> = HashMap::new();
    for (i, pair) in out.pairs.iter().enumerate() {
        best.entry(pair.node)
            .and_modify(|b| {
                if start_distance[i] < start_distance[*b] {
                    *b = i;
                }
            })
            .or_insert(i);
    }
    if best.len() == out.pairs.len() {
        return;
    }
    let together = |a: &ContactPair, b: &ContactPair| {
        a.body_increment == b.body_increment && a.suction == b.suction
    };
    // The nearest other pair of the same node whose body moves with the kept one.
    let mut partner: HashMap<u32, usize> = HashMap::new();
    for (i, pair) in out.pairs.iter().enumerate() {
        let b = best[&pair.node];
        if i == b || !together(&out.pairs[b], pair) {
            continue;
        }
        partner
            .entry(pair.node)
            .and_modify(|p| {
                if start_distance[i] < start_distance[*p] {
                    *p = i;
                }
            })
            .or_insert(i);
    }
    for (&node, &p) in &partner {
        let b = best[&node];
        let mut edges = facing[b].clone();
        edges.extend(
            facing[p]
                .iter()
                .filter(|e| !facing[b].iter().any(|f| f.0 == e.0)),
        );
        let other = out.pairs[p];
        let kept = &mut out.pairs[b];
        kept.partner = other.body;
        kept.partner_shear_limit = other.shear_limit;
        kept.weight = edges.iter().map(|e| e.1).sum();
        kept.touching |= other.touching;
    }
    let keep: Vec<bool> = (0..out.pairs.len())
        .map(|i| best[&out.pairs[i].node] == i)
        .collect();
    let mut k = keep.iter();
    out.pairs.retain(|_| *k.next().unwrap_or(&false));
    let mut k = keep.iter();
    out.spacing.retain(|_| *k.next().unwrap_or(&false));
}

impl Simulation {
    /// Collective. A `[[surface_pressure]]` whose `where` selects no boundary edge on any rank
    /// is an error: its pressure would silently act on nothing (`edges`: this rank's counts).
    pub(super) fn check_surface_selection(
        &self,
        world: &pfem_partition::Comm,
        edges: &[usize],
        step: u64,
    ) -> Result<(), super::step::SolveError> {
        if edges.is_empty() {
            return Ok(());
        }
        let counts: Vec<f64> = edges.iter().map(|&n| n as f64).collect();
        let counts = pfem_partition::sum_f64(world, &counts);
        match counts.iter().position(|&n| n == 0.0) {
            Some(k) => {
                let sp = &self.model.scene.surface_pressure[k];
                let what = match (&sp.on, sp.region.is_all()) {
                    (Some(on), true) => format!("on = \"{on}\""),
                    (Some(on), false) => format!("where = \"{}\" on \"{on}\"", sp.region),
                    (None, _) => format!("where = \"{}\"", sp.region),
                };
                Err(super::step::SolveError::Fatal(format!(
                    "step {step}: surface_pressure[{k}].{what} selects no boundary edge of the \
                     body (edges whose two ends started on it): its pressure would act on \
                     nothing"
                )))
            }
            None => Ok(()),
        }
    }
}

impl Simulation {
    /// Collective. Whether the converged contact holds every node on the body's face to
    /// `contact.tolerance` of its spacing: a touching node's gap, and a free node's
    /// penetration. Newton's tolerance puts them far below it; a node past it means the
    /// residual converged without the gaps closing, and a smaller increment is tried.
    pub(super) fn check_contact_gaps(
        &self,
        world: &pfem_partition::Comm,
        pairs: &[ContactPair],
        laws: &[NodeLaw],
        spacing: &[f64],
        step: u64,
    ) -> Result<(), super::step::SolveError> {
        if self.model.bodies.is_empty() {
            return Ok(());
        }
        let off = pairs
            .iter()
            .zip(laws)
            .zip(spacing)
            .map(|((_, law), h)| {
                let gap = if law.status == Status::Free {
                    (-law.gap).max(0.0)
                } else {
                    law.gap.abs()
                };
                gap / h
            })
            .fold(0.0, f64::max);
        let off = pfem_partition::max_f64(world, off);
        let tolerance = self.model.scene.contact.tolerance;
        if off > tolerance {
            return Err(super::step::SolveError::ContactUnsettled(format!(
                "step {step}: a contact node ended {off:.1e} of its spacing off the body's face \
                 (contact.tolerance = {tolerance:e})"
            )));
        }
        Ok(())
    }
}

/// A particle inside a rigid body by more than this fraction of its spacing ends the run.
pub const PENETRATION_LIMIT: f64 = 0.5;

impl Simulation {
    /// Collective. Whether a converged increment `du` (per local node of `dofs`) keeps every
    /// particle out of the rigid bodies, where they are at load factor `to`, to
    /// [`PENETRATION_LIMIT`] of its spacing. Contact holds only the nodes found near a body at
    /// the increment's start, and Newton can carry another one through it: on the `spudcan`
    /// an axis particle 0.2 m under the tip, its boundary edge a free surface, went 0.64 m up
    /// into the body in a step that moved the spudcan 0.025 m down, and the run ended. Such an
    /// increment is a divergence: a smaller one is tried.
    pub(super) fn check_through_bodies(
        &self,
        world: &pfem_partition::Comm,
        mesh: &crate::mesh::LocalMesh,
        dofs: &crate::solve::DofMap,
        du: &[[f64; 2]],
        to: f64,
        step: u64,
    ) -> Result<(), super::step::SolveError> {
        if self.model.bodies.is_empty() {
            return Ok(());
        }
        let shapes: Vec<_> = self.model.bodies.iter().map(|b| b.shape(to)).collect();
        let moved = (0..mesh.n_owned).filter_map(|p| {
            let node = dofs.node_of_point[p];
            (node != u32::MAX).then(|| {
                let d = du[node as usize];
                let x = [mesh.points[p][0] + d[0], mesh.points[p][1] + d[1]];
                (x, self.particles.h[p], mesh.gids[p])
            })
        });
        let worst = deepest(&shapes, moved);
        let local = worst
            .filter(|w| w.0 > PENETRATION_LIMIT)
            .map(|(depth, gid, b)| {
                format!(
                    "step {step}: Newton converged with particle {gid} inside rigid body '{}' by \
                 {depth:.2} of its spacing (limit {PENETRATION_LIMIT})",
                    self.model.bodies[b].name
                )
            });
        // Every rank returns the lowest failing rank's divergence.
        match pfem_partition::agree_on_error(world, local) {
            None => Ok(()),
            Some(message) => Err(super::step::SolveError::ContactUnsettled(message)),
        }
    }
}

impl Simulation {
    /// Collective. The deepest penetration of a particle into a rigid body, as a fraction of
    /// its spacing (0 when none), and an error when it passes [`PENETRATION_LIMIT`]: the soil
    /// has passed through the body.
    pub(super) fn check_penetration(
        &self,
        world: &pfem_partition::Comm,
    ) -> Result<f64, super::RunError> {
        if self.model.bodies.is_empty() {
            return Ok(0.0);
        }
        let lambda = self.header.load_factor;
        let shapes: Vec<_> = self.model.bodies.iter().map(|b| b.shape(lambda)).collect();
        let p = &self.particles;
        let here = (0..p.len()).map(|i| (p.position[i], p.h[i], p.gid[i]));
        let worst = deepest(&shapes, here);
        let local = worst.map_or(0.0, |w| w.0.max(0.0));
        let deepest = pfem_partition::max_f64(world, local);
        let error = worst
            .filter(|w| w.0 > PENETRATION_LIMIT)
            .map(|(depth, gid, bi)| super::RunError::Penetration {
                step: self.header.step,
                gid,
                body: self.model.bodies[bi].name.clone(),
                depth,
                limit: PENETRATION_LIMIT,
            });
        super::error::agree(world, error)?;
        Ok(deepest)
    }
}

/// The deepest of `points` (position, spacing, gid) inside any of `shapes`: its depth as a
/// fraction of its spacing (negative when all are outside), gid and body index.
fn deepest(
    shapes: &[Shape],
    points: impl Iterator<Item = ([f64; 2], f64, u64)>,
) -> Option<(f64, u64, usize)> {
    let mut worst: Option<(f64, u64, usize)> = None;
    for (x, h, gid) in points {
        for (b, shape) in shapes.iter().enumerate() {
            let depth = -shape.closest(x).distance / h;
            if worst.is_none_or(|w| depth > w.0) {
                worst = Some((depth, gid, b));
            }
        }
    }
    worst
}

/// Whether the boundary edge with nodes `nodes` from `xa` to `xb` runs along a support that holds
/// all three nodes across it (`fixed(node, component)`): the axis of revolution, a symmetry
/// plane. Such an edge is a cut through the soil, not its surface, and never touches a body.
/// Counted as contact surface, the axis below a spudcan's tip made an axis node 0.4 m under the
/// tip, within the search margin of the edge's midpoint, a contact node, and Newton pulled it up
/// through the soil to close its "gap" (directions of 0.2-1.0 m against the body's 0.1 m a step,
/// inverting the triangles between).
fn along_support(
    fixed: impl Fn(u32, usize) -> bool,
    nodes: [u32; 3],
    xa: [f64; 2],
    xb: [f64; 2],
) -> bool {
    let len = (xb[0] - xa[0]).hypot(xb[1] - xa[1]);
    (0..2).any(|c| nodes.iter().all(|&n| fixed(n, c)) && (xb[c] - xa[c]).abs() <= 1e-9 * len)
}

/// Start position, spacing and global key of local node `n`.
fn node_info(
    mesh: &LocalMesh,
    dofs: &DofMap,
    n: usize,
    n_vertex: usize,
) -> ([f64; 2], f64, [u64; 2]) {
    if n < n_vertex {
        let p = dofs.node_point[n] as usize;
        (mesh.points[p], mesh.h[p], [mesh.gids[p]; 2])
    } else {
        let [a, b] = dofs.edges[n - n_vertex];
        let mid = mesh.midside(a, b);
        let [a, b] = [a as usize, b as usize];
        (
            mid,
            mesh.h[a].max(mesh.h[b]),
            edge_key(mesh.gids[a], mesh.gids[b]),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::{
        along_support, deepest, join_bodies, join_cut_corners, BoundaryLoads, CutCorner,
        PENETRATION_LIMIT,
    };
    use crate::rigid::{ContactPair, Shape};

    /// A pair of `node` and `body` moving by `inc`, its partner itself, unit scales.
    fn pair(node: u32, body: u32, inc: [f64; 2], touching: bool) -> ContactPair {
        ContactPair {
            node,
            body,
            partner: body,
            partner_shear_limit: 0.0,
            start: [0.0; 2],
            weight: 0.0,
            constant: 1.0,
            row_scale: 1.0,
            shear_limit: 0.0,
            body_increment: inc,
            offset: 0.0,
            touching,
            suction: 0.0,
            free: [true, true],
        }
    }

    #[test]
    fn deepest_particle_is_measured_in_its_own_spacing() {
        let shapes = [
            Shape::circle([0.0, 0.0], 1.0).unwrap(),
            Shape::circle([5.0, 0.0], 1.0).unwrap(),
        ];
        assert!(deepest(&shapes, std::iter::empty()).is_none());
        let outside = deepest(&shapes, [([0.0, 3.0], 1.0, 7)].into_iter()).unwrap();
        assert!((outside.0 + 2.0).abs() < 1e-12 && outside.1 == 7);
        // 0.3 deep at spacing 0.5 is deeper (0.6) than 0.4 deep at spacing 1.
        let points = [
            ([0.0, 0.6], 1.0, 1),
            ([5.0, 0.7], 0.5, 2),
            ([2.5, 0.0], 0.1, 3),
        ];
        let (depth, gid, body) = deepest(&shapes, points.into_iter()).unwrap();
        assert!((depth - 0.6).abs() < 1e-12, "{depth}");
        assert_eq!((gid, body), (2, 1));
        assert!(depth > PENETRATION_LIMIT);
    }

    #[test]
    fn only_edges_along_a_support_that_holds_them_across_are_cuts() {
        // Nodes 0-2 held in x (on the axis), node 3 free.
        let fixed = |n: u32, c: usize| c == 0 && n < 3;
        assert!(along_support(fixed, [0, 1, 2], [0.0, 1.0], [0.0, 1.5]));
        // Off the axis at one end: a surface, though its nodes are held.
        assert!(!along_support(fixed, [0, 1, 2], [0.0, 1.0], [0.1, 1.5]));
        // One node free: a surface.
        assert!(!along_support(fixed, [0, 3, 2], [0.0, 1.0], [0.0, 1.5]));
        // A symmetry plane y = const held in y.
        let held_y = |_: u32, c: usize| c == 1;
        assert!(along_support(held_y, [4, 5, 6], [0.2, 0.0], [0.7, 0.0]));
        assert!(!along_support(held_y, [4, 5, 6], [0.2, 0.0], [0.7, 0.3]));
    }

    #[test]
    fn a_node_left_out_at_a_corner_is_held_against_the_union_with_the_bodies_moving_with_it() {
        let pair = |node: u32, body: u32, inc: [f64; 2]| pair(node, body, inc, false);
        let (down, held) = ([0.0, -0.01], [0.0; 2]);
        // Bodies 0 and 1 move down together, body 2 is held. Node 5 was left out at body 0's
        // corner (α·cu 7), node 6 at body 2's.
        let mut out = BoundaryLoads {
            pairs: vec![pair(5, 1, down), pair(6, 0, down), pair(7, 1, down)],
            spacing: vec![1.0, 2.0, 3.0],
            bodies: Vec::new(),
            surface: Vec::new(),
            surface_edges: Vec::new(),
        };
        let cut = |node: u32, body: u32, increment: [f64; 2], shear_limit: f64| CutCorner {
            node,
            body,
            increment,
            suction: 0.0,
            shear_limit,
        };
        join_cut_corners(&mut out, &[cut(5, 0, down, 7.0), cut(6, 2, held, 0.0)]);
        let got: Vec<(u32, u32, u32, f64)> = out
            .pairs
            .iter()
            .map(|p| (p.node, p.body, p.partner, p.partner_shear_limit))
            .collect();
        // Node 5 is held against bodies 1 and 0 with body 0's strength; node 6 stays on body 0
        // alone, which does not move with 2; node 7 is untouched.
        assert_eq!(got, [(5, 1, 0, 7.0), (6, 0, 0, 0.0), (7, 1, 1, 0.0)]);
    }

    #[test]
    fn a_node_near_two_bodies_moved_together_holds_against_both() {
        let down = [0.0, -0.01];
        // Node 5 near bodies 0 and 1 (moved together), node 6 near bodies 0 and 2 (body 2 held),
        // node 7 near body 1 only. Edges 10-12 face the bodies: node 5's edge 11 faces both.
        let mut out = BoundaryLoads {
            pairs: vec![
                pair(5, 0, down, false),
                pair(6, 0, down, false),
                pair(5, 1, down, true),
                pair(7, 1, down, false),
                pair(6, 2, [0.0; 2], false),
            ],
            spacing: vec![1.0, 2.0, 3.0, 4.0, 5.0],
            bodies: Vec::new(),
            surface: Vec::new(),
            surface_edges: Vec::new(),
        };
        out.pairs[0].shear_limit = 7.0;
        let start = [0.02, 0.01, 0.0, 0.5, -0.001];
        let facing = [
            vec![(10, 0.1), (11, 0.2)],
            vec![(10, 0.3)],
            vec![(11, 0.2), (12, 0.4)],
            vec![(12, 1.0)],
            vec![(13, 0.7)],
        ];
        join_bodies(&mut out, &start, &facing);
        let kept: Vec<(u32, u32, u32)> = out
            .pairs
            .iter()
            .map(|p| (p.node, p.body, p.partner))
            .collect();
        // Node 5 keeps body 1 (it starts on it) with body 0 as partner; node 6 keeps body 2, the
        // nearer, alone: body 0 does not move with it.
        assert_eq!(kept, [(5, 1, 0), (7, 1, 1), (6, 2, 2)]);
        let five = out.pairs.iter().find(|p| p.node == 5).unwrap();
        assert!(
            (five.weight - 0.7).abs() < 1e-12,
            "edges 10, 11, 12 once: {}",
            five.weight
        );
        assert!(five.touching);
        assert_eq!(
            five.partner_shear_limit, 7.0,
            "the partner's interface comes along"
        );
        assert_eq!(out.spacing, vec![3.0, 4.0, 5.0]);
    }
}
