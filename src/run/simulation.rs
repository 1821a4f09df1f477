//! The state of a running analysis on one rank and one function per phase of the method.

use super::RunError;
use crate::case_file::{read_checkpoint, CaseHeader};
use crate::history::Measures;
use crate::mapping::{admit_rows, map_states_admitted, StartStates, TriStates};
use crate::mesh::local::halo_width;
use crate::mesh::LocalMesh;
use crate::model::Model;
use crate::particles::{flag, Ghosts, Particles};
use crate::scene::Scene;
use mpi::traits::Communicator;
use pfem_partition::{imbalance, max_f64, migrate, partition_graph, sum_f64, Comm};
use std::path::Path;

/// Repartition when the largest rank holds this much more than the mean.
const IMBALANCE_LIMIT: f64 = 1.2;

pub struct Simulation {
    pub(super) model: Model,
    pub(super) header: CaseHeader,
    pub(super) particles: Particles,
    pub(super) ghosts: Ghosts,
    pub(super) tri_states: TriStates,
    /// This rank's share of the last step's footing/platen reaction and body area.
    pub(super) last_reaction: [f64; 2],
    pub(super) last_area: f64,
    /// This rank's share of the last step's reaction on each `[[fixed]]` then `[[prescribed]]`
    /// entry, and of the soil's force on each rigid body.
    pub(super) last_set_reactions: Vec<[f64; 2]>,
    pub(super) last_body_force: Vec<[f64; 2]>,
    /// This rank's triangles the last remesh dropped for reaching into each rigid body: a body
    /// that has some lies in the soil.
    pub(super) crossing: std::cell::RefCell<Vec<usize>>,
    /// Contact pressure and shear per contact node of the last increment.
    pub(super) last_contact: std::cell::RefCell<super::contact::ContactState>,
    /// Contact status changes between Newton iterations since the last step report.
    pub(super) contact_switches: std::cell::Cell<u64>,
    /// The current piece is being retried with the other line search.
    pub(super) alternate_search: std::cell::Cell<bool>,
    /// Seconds spent on contact since the last step report.
    pub(super) contact_seconds: std::cell::Cell<f64>,
    /// Newton and Krylov iterations of the tries that failed since the last step report (a
    /// diverged or unsettled piece costs as much as a converged one: the reported counts are
    /// the work done).
    pub(super) failed_tries: std::cell::Cell<[usize; 2]>,
    /// PETSc objects of the last increment (kept while the matrix pattern stays the same).
    pub(super) solver: std::cell::RefCell<Option<super::step::SolverObjects>>,
    /// The run's linear path, chosen at its first use (`super::step`).
    pub(super) linear_plan: std::cell::OnceCell<crate::solve::linear_path::LinearPlan>,
    /// The last increment's nodal solution by global node ([gid, gid] for a vertex, the sorted
    /// end ids for a midside node): displacement per whole step and pressure. The next predictor.
    pub(super) last_nodes: std::cell::RefCell<super::node_values::NodeValues>,
    /// Owned triangles interpolated by `map` since the last step report.
    pub(super) remapped: std::cell::Cell<u64>,
    /// The halo of the last mesh built (`build_mesh`), for exchanges on that mesh.
    pub(super) halo: Option<pfem_partition::Halo>,
    /// The step after which `[mesh.adapt]` last set the spacings (once per step, not per piece).
    pub(super) adapted_at: Option<u64>,
    /// The curves of the last mesh's boundary edges (`super::curved_edges`), every rank's.
    pub(super) bulges: super::curved_edges::Bulges,
    first_step: u64,
}

#[derive(Debug, Clone, Copy, Default)]
pub struct StepReport {
    pub newton_iterations: usize,
    /// Krylov iterations of the step's linear solves (one per Newton iteration when direct).
    pub linear_iterations: usize,
    /// Times the step's increment was halved after a Newton divergence.
    pub cuts: usize,
    pub residual_norm: f64,
    /// Triangles whose Gauss states were interpolated (new since the last mesh), all ranks.
    pub remapped: u64,
    pub particles: u64,
    pub triangles: u64,
    /// Contact status changes (touching, sticking, slipping) between the step's Newton
    /// iterations, all ranks.
    pub contact_switches: usize,
    /// Deepest particle penetration into a rigid body, as a fraction of its spacing.
    pub penetration: f64,
    /// Seconds of the step spent on contact (part of the solve phase); 0 without bodies.
    pub contact_seconds: f64,
    /// Under `steps.until_collapse`: the bracket `[held, failed]` on the collapse load factor
    /// when equilibrium failed in this step (the run then ends).
    pub collapse: Option<[f64; 2]>,
}

impl Simulation {
    /// Collective. Reads a case or checkpoint on any rank count and partitions it with METIS.
    pub fn load(world: &Comm, path: &Path) -> Result<Simulation, RunError> {
        let (header, set, gauss) = read_checkpoint(world, path)?;
        let same_partition = header.step > 0 && header.rank_counts.len() == world.size() as usize;
        let scene = Scene::from_toml(&header.scene_toml, &path.display().to_string(), &[])?;
        let model = Model::new(&scene).map_err(|message| RunError::Model {
            case: path.to_path_buf(),
            message,
        })?;
        let mut particles = Particles {
            gid: set.gid,
            position: set.position,
            displacement: set.displacement,
            increment: set.increment,
            h: set.h,
            state: set.state,
            flags: set.flags,
            material: set.material,
        };
        for (g, f) in particles.gid.iter().zip(particles.flags.iter_mut()) {
            if header.tracked_gids.contains(g) {
                *f |= flag::TRACKED;
            }
        }
        particles.sort_by_gid();
        let mut sim = Simulation {
            model,
            first_step: header.step,
            header,
            particles,
            ghosts: Ghosts::default(),
            tri_states: TriStates::default(),
            last_reaction: [0.0; 2],
            last_area: 0.0,
            last_set_reactions: Vec::new(),
            last_body_force: Vec::new(),
            crossing: Default::default(),
            last_contact: Default::default(),
            contact_switches: Default::default(),
            contact_seconds: Default::default(),
            failed_tries: Default::default(),
            alternate_search: Default::default(),
            solver: Default::default(),
            linear_plan: Default::default(),
            last_nodes: Default::default(),
            remapped: Default::default(),
            halo: None,
            adapted_at: None,
            bulges: Vec::new(),
        };
        if world.size() > 1 && !same_partition {
            sim.repartition(world, Repartition::Always)?;
        }
        sim.restore_gauss(world, gauss);
        Ok(sim)
    }

    pub fn step(&self) -> u64 {
        self.header.step
    }

    pub fn first_step(&self) -> u64 {
        self.first_step
    }

    pub fn total_steps(&self) -> u64 {
        self.model.scene.steps.count as u64
    }

    pub fn load_factor(&self) -> f64 {
        self.header.load_factor
    }

    /// The pseudo-time of the quasi-static analysis at the end of the last step.
    pub fn time(&self) -> f64 {
        self.header.time
    }

    pub fn scene(&self) -> &Scene {
        &self.model.scene
    }

    /// Collective. Delaunay of owned particles plus halo, alpha shape, triangles around owned
    /// particles; the spacings adapted first where `[mesh.adapt]` asks.
    pub fn remesh(&mut self, world: &Comm) -> Result<LocalMesh, RunError> {
        // The previous mesh's boundary, before refinement forgets triangles of `tri_states`.
        let previous = self.previous_boundary();
        let mut mesh = self.build_mesh(world, &previous)?;
        self.adapt_spacing(world, &mut mesh);
        if self.refine(world, &mesh)? {
            mesh = self.build_mesh(world, &previous)?;
        }
        self.curve_boundary(world, &mut mesh);
        Ok(mesh)
    }

    /// Collective. The mesh of the current particles, without refinement; `previous` is the last
    /// mesh's boundary (`previous_boundary`), whose notches the new mesh keeps open.
    pub(super) fn build_mesh(
        &mut self,
        world: &Comm,
        previous: &[[u64; 2]],
    ) -> Result<LocalMesh, RunError> {
        let h_max = max_f64(world, self.particles.h.iter().copied().fold(0.0, f64::max));
        let width = halo_width(self.model.scene.mesh.alpha, h_max);
        let (halo, ghosts) = self.particles.ghosts(world, width)?;
        self.ghosts = ghosts;
        self.halo = Some(halo);
        #[cfg(debug_assertions)]
        check_halo(world, &self.particles, &self.ghosts, width)?;
        let p = &self.particles;
        let g = &self.ghosts;
        let rank = world.rank();
        let points = p.position.iter().chain(&g.position).copied().collect();
        let gids = p.gid.iter().chain(&g.gid).copied().collect();
        let owner = std::iter::repeat_n(rank, p.len())
            .chain(g.owner.iter().copied())
            .collect();
        let h: Vec<f64> = p.h.iter().chain(&g.h).copied().collect();
        let alpha = self.model.scene.mesh.alpha;
        let n = p.len();
        let mut mesh = LocalMesh::build(points, gids, owner, h, n, rank, alpha, true)?;
        // One rank's unsettled near ties put every rank back on the exact Delaunay mesh.
        if max_f64(world, if mesh.ties_settled { 0.0 } else { 1.0 }) > 0.0 {
            let LocalMesh {
                points,
                gids,
                owner,
                h,
                ..
            } = mesh;
            mesh = LocalMesh::build(points, gids, owner, h, n, rank, alpha, false)?;
        }
        self.drop_crossing(&mut mesh, rank);
        self.respect_boundary(world, &mut mesh, previous);
        Ok(mesh)
    }

    /// Removes the triangles that cross a rigid body (`crate::rigid::crosses`).
    fn drop_crossing(&self, mesh: &mut LocalMesh, rank: i32) {
        if self.model.bodies.is_empty() {
            return;
        }
        let lambda = self.header.load_factor;
        let shapes: Vec<_> = self.model.bodies.iter().map(|b| b.shape(lambda)).collect();
        let crossing = std::cell::RefCell::new(vec![0; shapes.len()]);
        mesh.drop_triangles(rank, |p, h| {
            let hit = shapes.iter().position(|s| crate::rigid::crosses(s, p, h));
            if let Some(b) = hit {
                crossing.borrow_mut()[b] += 1;
            }
            hit.is_some()
        });
        *self.crossing.borrow_mut() = crossing.into_inner();
    }

    /// Start-of-step Gauss states on the new mesh (rank-local). The old mesh's states are
    /// consumed: the step sets new ones when it converges, and kept beside the solve they were
    /// 16 % of its memory peak from the second step on (the cantilever at h = 1/128, 1 rank:
    /// 880 MB at step 2 against 758 at step 1).
    pub fn map(&mut self, mesh: &LocalMesh) -> StartStates {
        let mut at_points = self.particles.state.clone();
        at_points.append(&mut self.ghosts.state.clone());
        let mut old = std::mem::take(&mut self.tri_states);
        if self.model.scene.mesh.remap_all {
            old = TriStates::default();
        }
        let w = self.model.layout().len();
        let tri_law = self.triangle_materials(mesh);
        let materials = &self.model.materials;
        let (states, stats) = map_states_admitted(&old, mesh, &at_points, |t, row| {
            admit_rows(materials[tri_law[t] as usize].as_ref(), row, w)
        });
        drop(old);
        self.remapped
            .set(self.remapped.get() + stats.interpolated_owned as u64);
        StartStates::new(states)
    }

    /// Raises every owned particle's recovered internal variables to their bounds (eps_q,
    /// xi ≥ 0: linear extrapolation overshoots them); how many changed. The stress is left as
    /// recovered: the Gauss points interpolated from it are returned to the yield surface when
    /// a triangle is made ([`crate::material::Material::admit`]). Returning the particles'
    /// stresses as well changed the path enough that the untuned rough footing
    /// (`tests/contact_untuned.rs`) stopped at step 4; without it, it runs.
    pub(super) fn admit_particles(&mut self) -> usize {
        let materials = &self.model.materials;
        let w = self.particles.state.width();
        let mut changed = 0;
        for i in 0..self.particles.state.len() {
            let m = materials[self.particles.material[i] as usize].as_ref();
            let row = self.particles.state.row_mut(i);
            for chunk in row.chunks_exact_mut(w) {
                let mut st = crate::material::GaussState::from_row(chunk);
                if crate::material::layout::clamp_to_bounds(
                    m.internal_variables(),
                    &mut st.internal,
                ) {
                    st.write_to(chunk);
                    changed += 1;
                }
            }
        }
        changed
    }

    pub(super) fn reference_position(&self, mesh: &LocalMesh, p: usize) -> [f64; 2] {
        let n = mesh.n_owned;
        if p < n {
            self.particles.reference_position(p)
        } else {
            let (x, u) = (self.ghosts.position[p - n], self.ghosts.displacement[p - n]);
            [x[0] - u[0], x[1] - u[1]]
        }
    }

    /// Collective. The global measures history.csv needs.
    pub fn measures(&self, world: &Comm) -> Measures {
        let mut tip = [0.0; 2];
        if let Some(&gid) = self.header.tracked_gids.first() {
            if let Ok(i) = self.particles.gid.binary_search(&gid) {
                tip = self.particles.displacement[i];
            }
        }
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..self.particles.len() {
            if self.model.in_first_prescribed(
                self.particles.reference_position(i),
                self.particles.position[i],
                self.header.load_factor,
            ) {
                lo = lo.min(self.particles.position[i][0]);
                hi = hi.max(self.particles.position[i][0]);
            }
        }
        let s = sum_f64(
            world,
            &[
                tip[0],
                tip[1],
                self.last_reaction[0],
                self.last_reaction[1],
                self.last_area,
            ],
        );
        let right = max_f64(world, hi);
        let width = right + max_f64(world, -lo);
        // Probes follow the point loads in `tracked_gids`.
        let n_loads = self.model.scene.point_load.len();
        let mut local = Vec::new();
        for k in 0..self.model.scene.probe.len() {
            let gid = self.header.tracked_gids.get(n_loads + k);
            let u = gid
                .and_then(|g| self.particles.gid.binary_search(g).ok())
                .map_or([0.0; 2], |i| self.particles.displacement[i]);
            local.extend(u);
        }
        let n_sets = self.model.scene.fixed.len() + self.model.scene.prescribed.len();
        for k in 0..n_sets {
            local.extend(self.last_set_reactions.get(k).copied().unwrap_or([0.0; 2]));
        }
        for k in 0..self.model.bodies.len() {
            local.extend(self.last_body_force.get(k).copied().unwrap_or([0.0; 2]));
        }
        let summed = sum_f64(world, &local);
        let pairs = |v: &[f64]| v.chunks_exact(2).map(|c| [c[0], c[1]]).collect::<Vec<_>>();
        let n_probe = 2 * self.model.scene.probe.len();
        let lambda = self.header.load_factor;
        Measures {
            time: self.header.time,
            probes: pairs(&summed[..n_probe]),
            set_reactions: pairs(&summed[n_probe..n_probe + 2 * n_sets]),
            rigid_force: pairs(&summed[n_probe + 2 * n_sets..]),
            rigid_displacement: self
                .model
                .bodies
                .iter()
                .map(|b| b.displacement(lambda))
                .collect(),
            load_factor: self.header.load_factor,
            tracked_displacement: [s[0], s[1]],
            reaction: [s[2], s[3]],
            area: s[4],
            driven_width: width,
            driven_right: right,
        }
    }

    /// Collective. Repartitions with METIS when the load is out of balance and a better balance
    /// exists: with N particles on P ranks no partition beats ceil(N/P) on the largest rank (9
    /// particles on 4 ranks stay at 3, 2, 2, 2).
    pub fn rebalance_if_needed(&mut self, world: &Comm) -> Result<(), RunError> {
        if world.size() > 1 && super::test_hooks::rotate_partition() {
            return self.repartition(world, Repartition::Rotated);
        }
        if world.size() == 1 || imbalance(world, self.particles.len()) <= IMBALANCE_LIMIT {
            return Ok(());
        }
        let counts = rank_counts(world, self.particles.len());
        let total: u64 = counts.iter().sum();
        let best = total.div_ceil(counts.len() as u64);
        if counts.iter().max().copied().unwrap_or(0) > best {
            self.repartition(world, Repartition::IfBetter)?;
        }
        Ok(())
    }

    /// Collective. METIS k-way on the mesh graph of the particles, then migration (see
    /// [`Repartition`] for when).
    /// The Gauss states of the last
    /// mesh, the Newton predictor at its nodes and the contact state go with the particles (by
    /// triangle and node key, as on restart), so a repartition does not change the results.
    fn repartition(&mut self, world: &Comm, mode: Repartition) -> Result<(), RunError> {
        let previous = self.previous_boundary();
        let mesh = self.build_mesh(world, &previous)?;
        let n = mesh.n_owned;
        let mut adj: Vec<Vec<u64>> = vec![Vec::new(); n];
        for t in &mesh.tris {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                if a < n {
                    adj[a].push(mesh.gids[b]);
                }
                if b < n {
                    adj[b].push(mesh.gids[a]);
                }
            }
        }
        let mut xadj = vec![0usize];
        let mut adjncy = Vec::new();
        for mut a in adj {
            a.sort_unstable();
            a.dedup();
            adjncy.extend(a);
            xadj.push(adjncy.len());
        }
        let mut dest = partition_graph(world, &self.particles.gid, &xadj, &adjncy)?;
        let size = world.size() as usize;
        if mode == Repartition::Rotated {
            dest.iter_mut().for_each(|r| *r = (*r + 1) % size as i32);
        }
        let mut to = vec![0.0; size];
        for &r in &dest {
            to[r as usize] += 1.0;
        }
        let now = rank_counts(world, self.particles.len());
        let after = sum_f64(world, &to);
        let largest = |c: &mut dyn Iterator<Item = f64>| c.fold(0.0, f64::max);
        if mode == Repartition::IfBetter
            && largest(&mut after.into_iter()) >= largest(&mut now.iter().map(|&c| c as f64))
        {
            return Ok(());
        }
        let records = self.gauss_records();
        let flags: Vec<u64> = self.particles.flags.iter().map(|&f| f as u64).collect();
        let (gid, rec, fl) = migrate(
            world,
            &dest,
            &self.particles.gid,
            &self.particles.records(),
            self.particles.record_len(),
            &flags,
            1,
        );
        let width = self.particles.state.width();
        let flags = fl.into_iter().map(|f| f as u32).collect();
        self.particles = Particles::from_records(gid, &rec, width, flags);
        self.restore_gauss(world, records);
        Ok(())
    }
}

/// When [`Simulation::repartition`] moves the particles.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Repartition {
    /// To METIS's partition.
    Always,
    /// To METIS's partition if its largest rank is smaller than the current largest.
    IfBetter,
    /// To METIS's partition with every part on the next rank (`PFEM_TEST_REPARTITION`).
    Rotated,
}

/// Collective. The particle count of every rank.
fn rank_counts(world: &Comm, n_local: usize) -> Vec<u64> {
    let mut mine = vec![0.0; world.size() as usize];
    mine[world.rank() as usize] = n_local as f64;
    sum_f64(world, &mine)
        .into_iter()
        .map(|c| c as u64)
        .collect()
}

/// Debug builds: every particle within the halo width of an owned one is on this rank, checked
/// against the full cloud gathered everywhere (too costly for release runs).
#[cfg(debug_assertions)]
fn check_halo(world: &Comm, p: &Particles, g: &Ghosts, width: f64) -> Result<(), RunError> {
    use pfem_partition::allgather_u64;
    let mine: Vec<u64> = (0..p.len())
        .flat_map(|i| {
            [
                p.gid[i],
                p.position[i][0].to_bits(),
                p.position[i][1].to_bits(),
            ]
        })
        .collect();
    let all = allgather_u64(world, &mine);
    let present: std::collections::HashSet<u64> = p.gid.iter().chain(&g.gid).copied().collect();
    let mut missing = None;
    'outer: for c in all.chunks_exact(3) {
        if present.contains(&c[0]) {
            continue;
        }
        let q = [f64::from_bits(c[1]), f64::from_bits(c[2])];
        for x in &p.position {
            if (x[0] - q[0]).powi(2) + (x[1] - q[1]).powi(2) <= width * width {
                missing = Some(c[0]);
                break 'outer;
            }
        }
    }
    let rank = world.rank();
    let missing = missing.map(|gid| RunError::Halo { gid, width, rank });
    super::error::agree(world, missing)
}
