//! The alpha shape made to respect the boundary it already knows (`crate::mesh::notches`): the
//! drawn body on the first mesh of a run, the previous mesh's boundary on every later one.

use super::Simulation;
use crate::geometry::{Rectangle, Shape};
use crate::mesh::notches::{boundary_out_edges, closes_notch, outside_drawn};
use crate::mesh::LocalMesh;
use mpi::traits::Communicator;
use pfem_partition::{max_f64, Comm};

/// A particle within this fraction of its spacing of a drawn edge is on it: the fill puts
/// boundary particles on the edges to round-off and keeps interior ones at least a fraction of a
/// spacing away.
const ON_EDGE: f64 = 1e-6;

impl Simulation {
    /// The previous mesh's boundary edges leaving an owned particle, as gid pairs (body on the
    /// left), from `tri_states`, which holds every previous triangle touching an owned particle.
    /// Taken before refinement, which forgets the triangles around the particles it moves.
    pub(super) fn previous_boundary(&self) -> Vec<[u64; 2]> {
        let gid = &self.particles.gid;
        let owned = |g: u64| gid.binary_search(&g).is_ok();
        boundary_out_edges(self.tri_states.iter().map(|(k, _)| k), owned)
    }

    /// Collective. Drops the new mesh's triangles that bridge a notch of the body: on the first
    /// mesh of a run (step 0, no previous mesh anywhere) those outside the drawn body, later
    /// those that fill the outside of two consecutive edges of `previous` (see
    /// [`Simulation::previous_boundary`]). Every rank holding a triangle decides alike: the first
    /// rule reads positions, the second the previous boundary edges of the triangle's vertices,
    /// which the owners send to the ghosts through this mesh's halo.
    pub(super) fn respect_boundary(
        &self,
        world: &Comm,
        mesh: &mut LocalMesh,
        previous: &[[u64; 2]],
    ) -> usize {
        let rank = world.rank();
        let gid = &self.particles.gid;
        // Boundary edges leaving each owned particle: one on a boundary loop, more where loops
        // touch at a vertex; the exchange's stride is the largest count anywhere.
        let from = |g: u64| {
            let lo = previous.partition_point(|e| e[0] < g);
            let hi = previous.partition_point(|e| e[0] <= g);
            &previous[lo..hi]
        };
        let widest = gid.iter().map(|&g| from(g).len()).max().unwrap_or(0);
        let k = max_f64(world, widest as f64) as usize;
        if k == 0 {
            if self.header.step != 0 {
                return 0;
            }
            let Some(shapes) = drawn_shapes(self) else {
                return 0;
            };
            let drop: Vec<bool> = mesh
                .tris
                .iter()
                .map(|t| {
                    let p = t.map(|v| mesh.points[v as usize]);
                    let h = t.iter().map(|&v| mesh.h[v as usize]).fold(0.0, f64::max);
                    outside_drawn(&shapes, p, ON_EDGE * h)
                })
                .collect();
            return mesh.drop_flagged(rank, &drop);
        }
        let mut owned = vec![u64::MAX; k * gid.len()];
        for (i, &g) in gid.iter().enumerate() {
            for (slot, e) in owned[k * i..].iter_mut().zip(from(g)) {
                *slot = e[1];
            }
        }
        // `build_mesh` has just set the halo on every rank, so all take the same branch here.
        let Some(halo) = self.halo.as_ref() else {
            return 0;
        };
        let ghosts = halo.exchange_u64(world, &owned, k);
        owned.extend(ghosts);
        let ends = |v: u64| &owned[k * v as usize..k * (v as usize + 1)];
        let drop: Vec<bool> = mesh
            .tris
            .iter()
            .map(|t| {
                closes_notch(t.map(u64::from), |a, b| {
                    ends(a).contains(&mesh.gids[b as usize])
                })
            })
            .collect();
        mesh.drop_flagged(rank, &drop)
    }
}

/// The drawn body: its zones, or its rectangles (whose union has notches where rectangles
/// meet in an L or a step; a single rectangle has none, so its meshes are unchanged). `None` if
/// the zones fail their checks (the scene was checked when the case was written).
fn drawn_shapes(sim: &Simulation) -> Option<Vec<Shape>> {
    let body = &sim.model.scene.body;
    if !body.zones.is_empty() {
        return crate::scene::zones::shapes(&sim.model.scene).ok();
    }
    let rects: Option<Vec<Shape>> = body
        .rectangles
        .iter()
        .map(|r| Rectangle::new(r.origin, r.size).ok().map(Shape::Rectangle))
        .collect();
    rects.filter(|r| !r.is_empty())
}
