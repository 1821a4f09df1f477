//! The state of a running analysis on one rank and one function per phase of the method.

use crate::case_file::{read_checkpoint, CaseHeader};
use crate::history::{self, HistoryFile, Measures};
use crate::mapping::{map_states, recover_at_particles, TriStates};
use crate::material::GaussState;
use crate::mesh::local::halo_width;
use crate::mesh::LocalMesh;
use crate::model::Model;
use crate::particles::{flag, Ghosts, Particles};
use crate::petsc::{Mat, PVec, Petsc, Snes};
use crate::scene::Scene;
use crate::solve::{Constraints, DofMap, StepProblem, StepSetup};
use mpi::traits::Communicator;
use pfem_partition::{imbalance, max_f64, migrate, partition_graph, sum_f64, Comm};
use std::path::{Path, PathBuf};

/// Repartition when the largest rank holds this much more than the mean.
const IMBALANCE_LIMIT: f64 = 1.2;

pub struct Simulation {
    pub(super) model: Model,
    pub(super) header: CaseHeader,
    pub(super) particles: Particles,
    pub(super) ghosts: Ghosts,
    pub(super) tri_states: TriStates,
    first_step: u64,
}

/// The solved step, before particles move.
pub struct Solved {
    dofs: DofMap,
    du: Vec<[f64; 2]>,
    states: Vec<[GaussState; 3]>,
    newton_iterations: usize,
    residual_norm: f64,
}

#[derive(Debug, Clone, Copy, Default)]
pub struct StepReport {
    pub newton_iterations: usize,
    pub residual_norm: f64,
    pub particles: u64,
    pub triangles: u64,
}

fn err<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

impl Simulation {
    /// Collective. Reads a case or checkpoint on any rank count and partitions it with METIS.
    pub fn load(world: &Comm, path: &Path) -> Result<Simulation, String> {
        let (header, set, gauss) = read_checkpoint(world, path).map_err(err)?;
        let same_partition = header.step > 0 && header.rank_counts.len() == world.size() as usize;
        let scene = Scene::from_toml(&header.scene_toml, &path.display().to_string(), &[])
            .map_err(|e| e.to_string())?;
        let model = Model::new(&scene).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut particles = Particles {
            gid: set.gid,
            position: set.position,
            displacement: set.displacement,
            h: set.h,
            state: set.state,
            flags: set.flags,
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
        };
        if world.size() > 1 && !same_partition {
            sim.repartition(world)?;
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

    pub fn scene(&self) -> &Scene {
        &self.model.scene
    }

    /// Collective. Delaunay of owned particles plus halo, alpha shape, triangles around owned
    /// particles.
    pub fn remesh(&mut self, world: &Comm) -> Result<LocalMesh, String> {
        let mesh = self.build_mesh(world)?;
        if self.refine(world, &mesh)? {
            return self.build_mesh(world);
        }
        Ok(mesh)
    }

    /// Collective. The mesh of the current particles, without refinement.
    pub(super) fn build_mesh(&mut self, world: &Comm) -> Result<LocalMesh, String> {
        let h_max = max_f64(world, self.particles.h.iter().copied().fold(0.0, f64::max));
        let width = halo_width(self.model.scene.mesh.alpha, h_max);
        let (_halo, ghosts) = self.particles.ghosts(world, width).map_err(err)?;
        self.ghosts = ghosts;
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
        LocalMesh::build(
            points,
            gids,
            owner,
            h,
            p.len(),
            rank,
            self.model.scene.mesh.alpha,
        )
        .map_err(err)
    }

    /// Start-of-step Gauss states on the new mesh (rank-local).
    pub fn map(&self, mesh: &LocalMesh) -> Vec<[GaussState; 3]> {
        let at_points: Vec<[f64; GaussState::LEN]> = self
            .particles
            .state
            .iter()
            .chain(&self.ghosts.state)
            .copied()
            .collect();
        let none = TriStates::default();
        let old = if self.model.scene.mesh.remap_all {
            &none
        } else {
            &self.tri_states
        };
        map_states(old, mesh, &at_points).0
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

    /// Collective. One implicit updated-Lagrangian increment by Newton (PETSc SNES).
    pub fn solve(
        &self,
        world: &Comm,
        petsc: &Petsc,
        mesh: &LocalMesh,
        states_n: &[[GaussState; 3]],
    ) -> Result<Solved, String> {
        let _ = petsc;
        let step = self.header.step + 1;
        let dofs = DofMap::build(world, mesh).map_err(err)?;
        let constraints = Constraints::build(&dofs, |p| {
            self.model.step_bc(self.reference_position(mesh, p))
        });
        let factor = self.model.load_factor(step);
        let mut point_loads = Vec::new();
        for (load, &gid) in self
            .model
            .scene
            .point_load
            .iter()
            .zip(&self.header.tracked_gids)
        {
            if let Ok(i) = self.particles.gid.binary_search(&gid) {
                let node = dofs.node_of_point[i];
                if node != u32::MAX {
                    point_loads.push((node, [factor * load.force[0], factor * load.force[1]]));
                }
            }
        }
        let setup = StepSetup {
            material: self.model.material.as_ref(),
            states_n,
            body_force: self.model.body_force,
            constraints: &constraints,
            point_loads,
        };
        let x = PVec::mpi(world, dofs.n_owned_dofs).map_err(err)?;
        let (d_nnz, o_nnz) = dofs.preallocation();
        let jac = Mat::aij(world, dofs.n_owned_dofs, &d_nnz, &o_nnz).map_err(err)?;
        let mut problem = StepProblem::new(world, mesh, &dofs, setup, &x).map_err(err)?;
        problem.initial_guess(&x).map_err(err)?;
        let solver = &self.model.scene.solver;
        let mut snes =
            Snes::new(world, solver.newton_rtol, solver.newton_max_it as usize).map_err(err)?;
        let stats = snes
            .solve(&mut problem, &x, &jac)
            .map_err(|e| format!("step {step}: {}", e.message))?;
        let du = problem.local_displacements(x.as_ref()).map_err(err)?;
        let states = problem
            .elements(&du)
            .map_err(|e| format!("step {step}: {e}"))?
            .into_iter()
            .map(|e| e.states)
            .collect();
        drop(problem);
        Ok(Solved {
            dofs,
            du,
            states,
            newton_iterations: stats.newton_iterations,
            residual_norm: stats.residual_norm,
        })
    }

    /// Collective. Moves the particles and carries the new Gauss states to them.
    pub fn update(
        &mut self,
        world: &Comm,
        mesh: &LocalMesh,
        solved: Solved,
    ) -> Result<StepReport, String> {
        for i in 0..self.particles.len() {
            let node = solved.dofs.node_of_point[i];
            if node != u32::MAX {
                let d = solved.du[node as usize];
                for (c, dc) in d.iter().enumerate() {
                    self.particles.position[i][c] += dc;
                    self.particles.displacement[i][c] += dc;
                }
            }
        }
        self.particles.state = recover_at_particles(mesh, &solved.states, &self.particles.state);
        self.tri_states = TriStates::new(mesh, solved.states);
        self.header.step += 1;
        self.header.load_factor = self.model.load_factor(self.header.step);
        let counts = sum_f64(
            world,
            &[self.particles.len() as f64, mesh.n_owned_tris() as f64],
        );
        Ok(StepReport {
            newton_iterations: solved.newton_iterations,
            residual_norm: solved.residual_norm,
            particles: counts[0] as u64,
            triangles: counts[1] as u64,
        })
    }

    /// Collective. The global measures history.csv needs.
    pub fn measures(&self, world: &Comm) -> Measures {
        let mut local = [0.0; 2];
        if let Some(&gid) = self.header.tracked_gids.first() {
            if let Ok(i) = self.particles.gid.binary_search(&gid) {
                local = self.particles.displacement[i];
            }
        }
        let u = sum_f64(world, &local);
        Measures {
            load_factor: self.header.load_factor,
            tracked_displacement: [u[0], u[1]],
        }
    }

    /// Collective. Repartitions with METIS when the load is out of balance.
    pub fn rebalance_if_needed(&mut self, world: &Comm) -> Result<(), String> {
        if world.size() > 1 && imbalance(world, self.particles.len()) > IMBALANCE_LIMIT {
            self.repartition(world)?;
        }
        Ok(())
    }

    /// Collective. METIS k-way on the mesh graph of the particles, then migration. Gauss states
    /// are recovered from the particles afterwards.
    fn repartition(&mut self, world: &Comm) -> Result<(), String> {
        let mesh = self.build_mesh(world)?;
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
        let dest = partition_graph(world, &self.particles.gid, &xadj, &adjncy).map_err(err)?;
        let flags: Vec<u64> = self.particles.flags.iter().map(|&f| f as u64).collect();
        let (gid, rec, fl) = migrate(
            world,
            &dest,
            &self.particles.gid,
            &self.particles.records(),
            crate::particles::RECORD,
            &flags,
            1,
        );
        self.particles =
            Particles::from_records(gid, &rec, fl.into_iter().map(|f| f as u32).collect());
        self.tri_states = TriStates::default();
        Ok(())
    }
}

/// history.csv and checkpoints under the run's output folder.
pub struct Output {
    dir: PathBuf,
    history: Option<HistoryFile>,
}

impl Output {
    /// Collective. Creates `DIR` (rank 0) and opens the history, keeping rows of earlier runs up to
    /// the restart step.
    pub fn open(world: &Comm, sim: &Simulation, dir: &Path) -> Result<Output, String> {
        let mut local = None;
        let mut history = None;
        if world.rank() == 0 {
            match std::fs::create_dir_all(dir.join("checkpoints"))
                .map_err(|e| format!("{}: {e}", dir.display()))
                .and_then(|_| HistoryFile::open(dir, sim.scene().history.kind, sim.step()))
            {
                Ok(h) => history = Some(h),
                Err(e) => local = Some(e),
            }
        }
        if let Some(e) = pfem_partition::agree_on_error(world, local) {
            return Err(e);
        }
        Ok(Output {
            dir: dir.to_path_buf(),
            history,
        })
    }

    /// Collective. Appends the step's row.
    pub fn record(&mut self, world: &Comm, sim: &Simulation) -> Result<(), String> {
        let m = sim.measures(world);
        let mut local = None;
        if let Some(h) = self.history.as_mut() {
            if let Err(e) = history::row(sim.scene(), &m).and_then(|r| h.append(sim.step(), &r)) {
                local = Some(e);
            }
        }
        match pfem_partition::agree_on_error(world, local) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Collective. Checkpoint every K steps (scene setting) and at the last step of the run.
    pub fn checkpoint_if_due(
        &mut self,
        world: &Comm,
        sim: &Simulation,
        last: u64,
    ) -> Result<(), String> {
        let every = sim.scene().output.checkpoint_every as u64;
        let step = sim.step();
        if step != last && (every == 0 || !step.is_multiple_of(every)) {
            return Ok(());
        }
        let path = self
            .dir
            .join("checkpoints")
            .join(format!("step_{step:06}.h5"));
        sim.write_checkpoint(world, &path)?;
        if world.rank() == 0 {
            prune_checkpoints(
                &self.dir.join("checkpoints"),
                sim.scene().output.checkpoint_keep as usize,
            );
        }
        Ok(())
    }
}

/// Keeps the newest `keep` checkpoints.
fn prune_checkpoints(dir: &Path, keep: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut names: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("step_") && n.ends_with(".h5"))
        })
        .collect();
    names.sort();
    let n = names.len();
    for p in names.into_iter().take(n.saturating_sub(keep.max(1))) {
        let _ = std::fs::remove_file(p);
    }
}

/// Debug builds: every particle within the halo width of an owned one is on this rank, checked
/// against the full cloud gathered everywhere (too costly for release runs).
#[cfg(debug_assertions)]
fn check_halo(world: &Comm, p: &Particles, g: &Ghosts, width: f64) -> Result<(), String> {
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
    match pfem_partition::agree_on_error(world, missing.map(|m| format!("halo check: particle {m} is within the halo width {width} of an owned particle but not on rank {}", world.rank()))) {
        Some(e) => Err(e),
        None => Ok(()),
    }
}
