//! The solve and update phases: one implicit updated-Lagrangian increment by Newton (PETSc SNES),
//! then moving the particles and carrying the new Gauss states to them.

use super::{Simulation, StepReport};
use crate::mapping::{recover_at_particles, StartStates, TriStates};
use crate::material::Rows;
use crate::mesh::LocalMesh;
use crate::petsc::{IndexSet, Mat, NullSpace, PVec, Pc, Petsc, PetscError, Snes, SolveFailure};
use crate::solve::interpolation::{Interpolation, InterpolationMap};
use crate::solve::linear_path::{CommandLine, Facts, LinearPath, LinearPlan, Storage};
use crate::solve::nullspace::orthonormal_rigid_body_modes;
use crate::solve::pmg::CoarseSpace;
use crate::solve::precond::{self, Hooked, Hooks, Parts};
use crate::solve::{
    CoarseOperator, Constraints, DofMap, FieldLayout, SchurPreconditioner, StepProblem, StepSetup,
};
use mpi::traits::Communicator;
use pfem_partition::{max_f64, sum_f64, Comm};

/// PETSc objects reused across increments with the same matrix pattern.
pub struct SolverObjects {
    signature: u64,
    x: PVec,
    jac: Mat,
    /// How the increment's linear systems are solved.
    path: LinearPath,
    /// The iterative path's extras: the near-null space (attached to `jac` for P2, to the
    /// displacement field for P2–P1), the field split of a mixed system, the p-multigrid's
    /// coarse level and the yield zone's preconditioner.
    near_null: Option<NullSpace>,
    split: Option<Split>,
    pmg: Option<PMultigrid>,
    zone: Option<Pc>,
    snes: Snes,
}

/// The coarse level of the two-level p-multigrid (iterative P2 path, `-pfem_pmg`), made with
/// the solver objects at every increment's start: the interpolation (an operator,
/// [`Interpolation`]) and the coarse near-null space from that increment's geometry and
/// constraints; the coarse operator is assembled at every Jacobian (the tangent's Galerkin
/// product).
struct PMultigrid {
    space: CoarseSpace,
    interpolation: Mat,
    coarse: Mat,
}

/// The Schur-complement field split of a mixed system.
struct Split {
    layout: FieldLayout,
    displacement_field: IndexSet,
    pressure_field: IndexSet,
    pressure_mass: Mat,
}

/// FNV-1a over the global dof numbers of every local triangle: equal signatures mean the same
/// matrix pattern on this rank.
fn pattern_signature(dofs: &DofMap) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |v: u64| {
        h ^= v;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    };
    eat(dofs.n_owned_dofs as u64);
    eat(dofs.first_dof as u64);
    eat(dofs.vertex_dofs as u64);
    for nodes in &dofs.tri_nodes {
        for &n in nodes {
            eat(dofs.node_global[n as usize] as u64);
        }
    }
    // With pressures per material, the same nodes may meet other materials' pressures.
    if dofs.material_pressures.is_some() {
        for t in 0..dofs.tri_nodes.len() {
            for k in 12..15 {
                let (n, c) = dofs.element_dof(t, k);
                eat(dofs.global_dof(n, c) as u64);
            }
        }
    }
    h
}

/// Why a solve failed.
#[derive(Debug)]
pub enum SolveError {
    /// Newton did not converge: a smaller increment may.
    Diverged(String),
    /// Newton converged with a contact node off the body's face by more than
    /// `contact.tolerance` of its spacing (a touching node held off it, a free one inside): a
    /// smaller increment may settle them.
    ContactUnsettled(String),
    Fatal(String),
}

impl std::fmt::Display for SolveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SolveError::Diverged(m) | SolveError::ContactUnsettled(m) | SolveError::Fatal(m) => {
                f.write_str(m)
            }
        }
    }
}

/// The solved step, before particles move.
pub struct Solved {
    /// Load-factor increment solved for.
    dlambda: f64,
    dofs: DofMap,
    pub(super) du: Vec<[f64; 2]>,
    /// Pressure of every local node (NaN without a pressure unknown; at a vertex with one per
    /// material, its lowest material's).
    pressure: Vec<f64>,
    /// (vertex node, material, pressure) of every pressure unknown where they are per material.
    material_pressure: Vec<(usize, u32, f64)>,
    /// Per local triangle, its Gauss points' rows of the material's layout.
    pub(super) states: Rows,
    reaction: [f64; 2],
    /// Reaction on each `[[fixed]]`, then `[[prescribed]]` entry (named ones; others zero).
    set_reactions: Vec<[f64; 2]>,
    /// Force of the soil on each rigid body (this rank's nodes).
    body_force: Vec<[f64; 2]>,
    /// Pressure and shear of every contact node at the solution.
    contact_state: super::contact::ContactState,
    pub(super) newton_iterations: usize,
    /// Krylov iterations of the increment's linear solves (1 per Newton iteration when direct).
    linear_iterations: usize,
    residual_norm: f64,
    /// Contact status changes between Newton iterations, all ranks.
    contact_switches: usize,
}

/// The converged increment.
struct Outcome {
    du: Vec<[f64; 2]>,
    pressure: Vec<f64>,
    material_pressure: Vec<(usize, u32, f64)>,
    states: Rows,
    reaction: [f64; 2],
    set_reactions: Vec<[f64; 2]>,
    body_force: Vec<[f64; 2]>,
    contact_state: super::contact::ContactState,
    stats: crate::petsc::SolveStats,
    contact_switches: usize,
}

/// Global identity of local node `n`: a vertex's particle id twice, or an edge's two particle
/// ids in increasing order.
fn node_key(mesh: &LocalMesh, dofs: &DofMap, n: usize) -> [u64; 2] {
    let n_vertex = dofs.n_nodes() - dofs.edges.len();
    if n < n_vertex {
        let g = mesh.gids[dofs.node_point[n] as usize];
        [g, g]
    } else {
        let [a, b] = dofs.edges[n - n_vertex].map(|p| mesh.gids[p as usize]);
        edge_key(a, b)
    }
}

/// Key of the midside node between particles `a` and `b`.
pub(super) fn edge_key(a: u64, b: u64) -> [u64; 2] {
    [a.min(b), a.max(b)]
}

/// Pressure (compression positive) of a particle state.
fn pressure(state: &[f64]) -> f64 {
    -(state[0] + state[1] + state[2]) / 3.0
}

impl Simulation {
    /// The state row of mesh point `p` (owned or ghost).
    pub(super) fn point_state(&self, mesh: &LocalMesh, p: usize) -> &[f64] {
        if p < mesh.n_owned {
            self.particles.state.row(p)
        } else {
            self.ghosts.state.row(p - mesh.n_owned)
        }
    }

    /// The material of each local triangle: that of the zone where the centroid of its
    /// vertices' reference positions lies, so an interface drawn along triangle edges is kept
    /// exactly and one across them is smeared by at most half a triangle. A triangle whose
    /// reference centroid lies in no zone (its particles came together from far apart) takes
    /// the material most of its vertices have, or where all three differ the one of its
    /// smallest-gid vertex. Only data that every copy of a triangle has bit for bit decide, so
    /// every rank gives it the same material.
    pub(super) fn triangle_materials(&self, mesh: &LocalMesh) -> Vec<u32> {
        if self.model.materials.len() == 1 {
            return vec![0; mesh.tris.len()];
        }
        (0..mesh.tris.len())
            .map(|t| {
                let v = mesh.tris[t].map(|p| p as usize);
                let x = v.map(|p| self.reference_position(mesh, p));
                let c = [
                    (x[0][0] + x[1][0] + x[2][0]) / 3.0,
                    (x[0][1] + x[1][1] + x[2][1]) / 3.0,
                ];
                if let Some((_, m)) = self.model.zones.iter().find(|(z, _)| z.contains(c)) {
                    return *m;
                }
                let m = v.map(|p| self.point_material(mesh, p));
                if m[0] == m[1] || m[0] == m[2] {
                    m[0]
                } else if m[1] == m[2] {
                    m[1]
                } else {
                    let first = (0..3).min_by_key(|&k| mesh.gids[v[k]]).unwrap_or(0);
                    m[first]
                }
            })
            .collect()
    }

    /// The material index of mesh point `p` (owned or ghost).
    pub(super) fn point_material(&self, mesh: &LocalMesh, p: usize) -> u32 {
        self.point_value(mesh, p, &self.particles.material, &self.ghosts.material)
    }

    pub(super) fn point_value<T: Copy>(
        &self,
        mesh: &LocalMesh,
        p: usize,
        owned: &[T],
        ghost: &[T],
    ) -> T {
        if p < mesh.n_owned {
            owned[p]
        } else {
            ghost[p - mesh.n_owned]
        }
    }

    /// Collective. One implicit updated-Lagrangian increment by Newton (PETSc SNES) from load
    /// factor `from` to `to`. A Newton divergence is returned as `Err(Diverged)`: a smaller
    /// increment may converge.
    pub fn solve(
        &self,
        world: &Comm,
        petsc: &Petsc,
        mesh: &LocalMesh,
        states_n: &StartStates,
        from: f64,
        to: f64,
    ) -> Result<Solved, SolveError> {
        let _ = petsc;
        let err = |e: String| SolveError::Fatal(e);
        let step = self.header.step + 1;
        let seconds = (self.model.seconds_at(from))
            .zip(self.model.seconds_at(to))
            .map(|(a, b)| [a, b]);
        crate::material::umat::site::set_increment(step, from, to, seconds);
        let tri_law = self.triangle_materials(mesh);
        let dofs = DofMap::build(world, mesh, self.model.pressure(&tri_law))
            .map_err(|e| err(e.to_string()))?;
        let constraints = Constraints::build(&dofs, |p| {
            self.model
                .step_bc(self.reference_position(mesh, p), mesh.points[p], from, to)
        });
        // The last increment scaled to this one is the predictor.
        let scale = self.model.predictor_scale(from, to);
        let factor = to;
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
        let clock = std::time::Instant::now();
        let loads = self.boundary_loads(mesh, &dofs, &constraints, from, to);
        self.add_contact_seconds(clock.elapsed().as_secs_f64());
        self.check_surface_selection(world, &loads.surface_edges, step)?;
        let spacing = loads.spacing;
        let setup = StepSetup {
            laws: self.model.laws(to),
            tri_law,
            kernel: self.model.kernel,
            analysis: self.model.scene.analysis,
            states_n,
            constraints: &constraints,
            point_loads,
            contact: loads.pairs,
            bodies: loads.bodies,
            surface: loads.surface,
        };
        let mut cache = self
            .solver_objects(world, mesh, &dofs, &constraints)
            .map_err(|e| err(e.to_string()))?;
        let outcome = self
            .solve_with(
                world, mesh, &dofs, setup, &spacing, &mut cache, scale, from, step,
            )
            .and_then(|o| {
                self.check_through_bodies(world, mesh, &dofs, &o.du, to, step)
                    .inspect_err(|_| {
                        let s = &o.stats;
                        self.count_failed_try([s.newton_iterations, s.linear_iterations])
                    })?;
                Ok(o)
            });
        // Kept for the next increment on the same pattern (a cut piece, or an unchanged mesh),
        // where a factorisation's symbolic phase is reused. An iterative solver sets up afresh
        // anyway, and its matrices would sit under the peak of the mapping, output and
        // checkpoint that follow (cantilever h = 1/128, 1 rank: 1 466 → 1 194 MB).
        if !cache.path.iterative() {
            *self.solver.borrow_mut() = Some(cache);
        }
        outcome.map(|o| Solved {
            dlambda: to - from,
            dofs,
            du: o.du,
            pressure: o.pressure,
            material_pressure: o.material_pressure,
            states: o.states,
            reaction: o.reaction,
            set_reactions: o.set_reactions,
            body_force: o.body_force,
            contact_state: o.contact_state,
            newton_iterations: o.stats.newton_iterations,
            linear_iterations: o.stats.linear_iterations,
            residual_norm: o.stats.residual_norm,
            contact_switches: o.contact_switches,
        })
    }

    /// Collective. The vector, matrix and SNES for `dofs`: last increment's when the matrix
    /// pattern is the same on every rank (PETSc then keeps the symbolic factorisation), new ones
    /// otherwise (always for an iterative solver, whose interpolation follows `constraints`).
    fn solver_objects(
        &self,
        world: &Comm,
        mesh: &LocalMesh,
        dofs: &DofMap,
        constraints: &Constraints,
    ) -> Result<SolverObjects, crate::petsc::PetscError> {
        // A different line search is a different SNES.
        let alternate = self.alternate_search.get();
        let signature = pattern_signature(dofs) ^ if alternate { 0x9e37_79b9_7f4a_7c15 } else { 0 };
        let cached = self.solver.borrow_mut().take();
        let same = cached.as_ref().is_some_and(|c| c.signature == signature);
        if sum_f64(world, &[if same { 0.0 } else { 1.0 }])[0] == 0.0 {
            if let Some(c) = cached {
                return Ok(c);
            }
        }
        drop(cached);
        let x = PVec::mpi(world, dofs.n_owned_dofs)?;
        let solver = &self.model.scene.solver;
        let line_search =
            super::step_solver::StepSolver::of(&self.model, MAX_CUTS).line_search(alternate);
        let path = self.linear_plan(world)?.path(dofs.n_global_dofs);
        let split = match path {
            LinearPath::FieldSplit { .. } => Some(self.field_split(world, mesh, dofs)?),
            _ => None,
        };
        if path.lean_galerkin_products(world.size() as usize, dofs.n_global_dofs) {
            // A process option, read when a solver is set up: once a run has set it, it keeps
            // it, and the command line wins.
            crate::petsc::options::set_default("-matptap_via", "allatonce")?;
        }
        let pmg = match path {
            LinearPath::PMultigrid { .. } => {
                let space = CoarseSpace::build(world, mesh, dofs).map_err(|e| PetscError {
                    code: -1,
                    message: e.to_string(),
                })?;
                let interpolation = {
                    let map = InterpolationMap::new(dofs, constraints, &space);
                    let op = Interpolation::new(world, map)?;
                    Mat::shell(world, [dofs.n_owned_dofs, space.n_owned], Box::new(op))?
                };
                let coarse = {
                    let (d_nnz, o_nnz) = CoarseSpace::operator_preallocation(dofs);
                    Mat::aij(world, space.n_owned, 2, &d_nnz, &o_nnz)?
                };
                // The coarse nodes' rigid-body modes at the increment's start, for GAMG (the
                // matrix holds its own reference to the space).
                let modes = orthonormal_rigid_body_modes(world, &space.coordinates(mesh, dofs));
                coarse.set_near_null_space(&NullSpace::new(world, space.n_owned, &modes)?)?;
                Some(PMultigrid {
                    space,
                    interpolation,
                    coarse,
                })
            }
            _ => None,
        };
        // The p-multigrid only multiplies by the P2 tangent and reads its diagonal: blocks,
        // and only the upper triangle of a symmetric one.
        let jac = match path.storage() {
            Storage::UpperBlocks => {
                let (d_blocks, o_blocks) = dofs.upper_block_preallocation();
                Mat::sbaij(world, dofs.n_owned_dofs, &d_blocks, &o_blocks)?
            }
            Storage::Blocks => {
                let (d_nnz, o_nnz) = dofs.preallocation();
                Mat::baij(world, dofs.n_owned_dofs, 2, &d_nnz, &o_nnz)?
            }
            Storage::Aij => {
                let (d_nnz, o_nnz) = dofs.preallocation();
                Mat::aij(world, dofs.n_owned_dofs, dofs.block_size(), &d_nnz, &o_nnz)?
            }
        };
        let parts = match (&split, &pmg) {
            (Some(s), _) => Parts::FieldSplit {
                displacement: &s.displacement_field,
                pressure: &s.pressure_field,
                pressure_mass: &s.pressure_mass,
            },
            (None, Some(m)) => Parts::PMultigrid {
                interpolation: &m.interpolation,
                coarse: &m.coarse,
            },
            (None, None) => Parts::None,
        };
        // A residual at round-off of the body's force scale (E h, N/m) is converged: a step
        // with no load at all (a body released from its platen) has no first residual for the
        // relative test to refer to, and its line search fails at 1e-26.
        let scene = &self.model.scene;
        let abstol = 1e-14 * scene.material.young * scene.mesh.h;
        let snes = Snes::new(
            world,
            abstol,
            solver.newton_rtol,
            solver.newton_max_it as usize,
        )?;
        let zone = precond::configure(snes.ksp()?, &path, parts)?;
        snes.set_lag_preconditioner(path.preconditioner_lag())?;
        if let Some(cap) = path.inexact_newton_cap() {
            snes.use_eisenstat_walker(cap)?;
        }
        snes.set_line_search(line_search)?;
        snes.set_from_options()?;
        Ok(SolverObjects {
            signature,
            x,
            jac,
            path,
            near_null: None,
            split,
            pmg,
            zone,
            snes,
        })
    }

    /// Collective. The run's linear path, chosen at the first call from the model and the
    /// command line ([`LinearPlan::choose`]).
    pub(super) fn linear_plan(&self, world: &Comm) -> Result<&LinearPlan, PetscError> {
        if let Some(plan) = self.linear_plan.get() {
            return Ok(plan);
        }
        let solver = &self.model.scene.solver;
        let facts = Facts {
            mixed: self.model.mixed(),
            plastic: self.model.plastic(),
            symmetric: self.symmetric_tangent(),
            scene: solver.linear,
        };
        let cl = CommandLine::read(world, solver.linear, solver.reuse_factorisation)?;
        let plan = LinearPlan::choose(&facts, &cl).map_err(|message| PetscError {
            code: crate::petsc::error::PETSC_ERR_USER,
            message,
        })?;
        Ok(self.linear_plan.get_or_init(|| plan))
    }

    /// Whether every tangent of the scene is symmetric: an elastic P2 solid (the material and
    /// geometric stiffness of a hyperelastic step are), with dead loads only (point loads and
    /// gravity keep their direction; follower pressures and contact do not) and prescribed
    /// displacements eliminated symmetrically. `solver.symmetric = false` or the PETSc options
    /// `-pc_type lu -pc_factor_mat_solver_type mumps` factor LU anyway (and keep GMRES on the
    /// iterative path).
    fn symmetric_tangent(&self) -> bool {
        let m = &self.model;
        m.scene.solver.symmetric
            && !m.plastic()
            && !m.mixed()
            && m.bodies.is_empty()
            && m.scene.surface_pressure.is_empty()
    }

    /// Collective. The index sets of the displacement and pressure fields of a mixed system,
    /// the rigid-body near-null space of the displacement field, and the (empty) pressure mass
    /// matrix the Jacobian assembles for the Schur complement.
    fn field_split(
        &self,
        world: &Comm,
        mesh: &LocalMesh,
        dofs: &DofMap,
    ) -> Result<Split, PetscError> {
        let layout = FieldLayout::new(world, dofs).map_err(|e| PetscError {
            code: -1,
            message: e.to_string(),
        })?;
        let ints = |v: &[usize]| {
            v.iter()
                .map(|&g| crate::petsc::matrix::to_int(g, "dof"))
                .collect::<Result<Vec<_>, _>>()
        };
        let displacement = IndexSet::general(world, &ints(&layout.displacement)?, 2)?;
        let pressure = IndexSet::general(world, &ints(&layout.pressure)?, 1)?;
        let modes = orthonormal_rigid_body_modes(world, &dofs.owned_coordinates(&mesh.points));
        let space = NullSpace::new(world, layout.displacement.len(), &modes)?;
        displacement.compose_near_null_space(&space)?;
        let n_p = layout.pressure.len();
        let pressure_mass = Mat::aij(world, n_p, 1, &layout.mass_d_nnz, &layout.mass_o_nnz)?;
        Ok(Split {
            layout,
            displacement_field: displacement,
            pressure_field: pressure,
            pressure_mass,
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn solve_with(
        &self,
        world: &Comm,
        mesh: &LocalMesh,
        dofs: &DofMap,
        setup: StepSetup,
        spacing: &[f64],
        objects: &mut SolverObjects,
        scale: f64,
        from: f64,
        step: u64,
    ) -> Result<Outcome, SolveError> {
        let err = |e: String| SolveError::Fatal(e);
        let SolverObjects {
            x,
            jac,
            snes,
            path,
            near_null,
            split,
            pmg,
            zone,
            ..
        } = objects;
        let iterative = path.iterative();
        let mut problem =
            StepProblem::new(world, mesh, dofs, setup, x).map_err(|e| err(e.to_string()))?;
        if iterative {
            problem = problem.without_element_cache();
            if path.yield_zone() {
                problem = problem.with_yielded_zone();
            }
        }
        if let Some(m) = pmg {
            problem = problem.with_coarse_operator(CoarseOperator {
                matrix: &m.coarse,
                space: &m.space,
            });
            if path.damps_smoother() {
                problem = problem.with_jacobi_bound();
            }
        }
        if let Some(split) = split {
            problem = problem.with_schur_preconditioner(SchurPreconditioner {
                matrix: &split.pressure_mass,
                pressure_index: &split.layout.pressure_index,
            });
        } else if path.near_null_space_on_tangent() {
            // The modes at this increment's start: the nodes moved since the matrix was made.
            let modes = orthonormal_rigid_body_modes(world, &dofs.owned_coordinates(&mesh.points));
            let space = NullSpace::new(world, dofs.n_owned_dofs, &modes)
                .and_then(|space| jac.set_near_null_space(&space).map(|()| space))
                .map_err(|e| err(e.to_string()))?;
            *near_null = Some(space);
        }
        // Predictor: the last step's increment (a proportional step's best guess, which also keeps
        // Newton off the zero-energy shear-band modes of a plastic limit state) and the current
        // pressure: the last solution's own nodal values where the node survived the remesh (a
        // P2 midside value is not the mean of its ends, and a recovered pressure is smoothed),
        // otherwise the particles' values.
        let last = self.last_nodes.borrow();
        let inc =
            |p: usize| self.point_value(mesh, p, &self.particles.increment, &self.ghosts.increment);
        let state = |p: usize| self.point_state(mesh, p);
        // Where pressures are per material, a vertex's pressure in a material it did not touch
        // in the last increment (or after a restart, whose checkpoint keeps one pressure per
        // vertex) starts from its pressure in its lowest material there: a value of the last
        // solution all the same, nearer than the particle's recovered mean.
        let displacement = |n: usize| {
            if let Some(v) = last.get(&node_key(mesh, dofs, n)) {
                return [scale * v[0], scale * v[1]];
            }
            let p = dofs.node_point[n];
            if p != u32::MAX {
                let d = inc(p as usize);
                [scale * d[0], scale * d[1]]
            } else {
                let [a, b] = dofs.edges[n - (dofs.n_nodes() - dofs.edges.len())];
                let (da, db) = (inc(a as usize), inc(b as usize));
                [0.5 * scale * (da[0] + db[0]), 0.5 * scale * (da[1] + db[1])]
            }
        };
        let vertex_pressure = |n: usize, material: u32| {
            let key = node_key(mesh, dofs, n);
            if let Some(p) = last.pressure(key[0], material) {
                return p;
            }
            match last.get(&key) {
                Some(v) => v[2],
                None => pressure(state(dofs.node_point[n] as usize)),
            }
        };
        problem
            .initial_guess(x, displacement, vertex_pressure)
            .map_err(|e| err(e.to_string()))?;
        let zone = zone.as_ref().map(Pc::as_ref);
        let mut newton = |problem: &mut StepProblem, x: &mut PVec, jac: &mut Mat| {
            let mut hooked = Hooked {
                problem,
                hooks: Hooks::new(*path, zone),
            };
            snes.solve(&mut hooked, x, jac).map_err(|e| match e {
                SolveFailure::Diverged(d) => {
                    self.count_failed_try(d.spent());
                    SolveError::Diverged(format!("step {step}: {d}"))
                }
                SolveFailure::Failed(e) => SolveError::Fatal(format!("step {step}: {}", e.message)),
            })
        };
        let mut stats = newton(&mut problem, x, jac)?;
        // Newton's tolerance is relative to the increment's first residual (1e-3 on the
        // rigid-body built-ins), and a contact row can meet it with its gap still above
        // `contact.tolerance`. Rejecting that increment retried it from the start and then
        // cut it (the coarse sharp-edged footing: gaps of 2e-5 of the spacing, 28 iterations
        // and a cut step where the polish takes one or two); Newton goes on from where it
        // stopped instead, its tolerance now relative to the residual there.
        let mut polishes = 0;
        let (local, laws) = loop {
            let local = problem
                .local_values(x.as_ref())
                .map_err(|e| err(e.to_string()))?;
            let laws = problem.contact_laws(&local);
            let settled =
                self.check_contact_gaps(world, problem.contact_pairs(), &laws, spacing, step);
            match settled {
                Ok(()) => break (local, laws),
                Err(_) if polishes < MAX_POLISHES => {
                    polishes += 1;
                    let more = newton(&mut problem, x, jac).inspect_err(|_| {
                        self.count_failed_try([stats.newton_iterations, stats.linear_iterations])
                    })?;
                    stats.newton_iterations += more.newton_iterations;
                    stats.linear_iterations += more.linear_iterations;
                    stats.residual_norm = more.residual_norm;
                }
                Err(e) => {
                    self.count_failed_try([stats.newton_iterations, stats.linear_iterations]);
                    return Err(e);
                }
            }
        };
        self.add_contact_seconds(problem.contact_seconds());
        // An iterative solver is not kept for the next increment (see `solve`): its hierarchy
        // and vectors are freed now, before the converged state's element pass.
        if iterative {
            precond::hooks::reset(snes, zone).map_err(|e| err(e.to_string()))?;
            // Returned to the system, or the converged pass's new states (216 bytes a
            // triangle) would be placed beside the freed pages and raise the peak RSS (1.03 M
            // particles, 2 ranks: by 120–180 MB a rank).
            crate::heap::release_free_pages();
        }
        let converged = problem
            .converged(&local)
            .map_err(|e| SolveError::Fatal(format!("step {step}: {e}")))?;
        let driven = |n: usize| {
            dofs.node_points(n).iter().all(|&p| {
                let p = p as usize;
                self.model.in_first_prescribed(
                    self.reference_position(mesh, p),
                    mesh.points[p],
                    from,
                )
            })
        };
        let reaction = problem.reaction(&converged, driven);
        let set_reactions = self.set_reactions(mesh, dofs, &problem, &converged, from);
        let mut body_force = vec![[0.0; 2]; self.model.bodies.len()];
        let mut contact_state = super::contact::ContactState::new();
        for (c, law) in problem.contact_pairs().iter().zip(&laws) {
            let b = &mut body_force[law.body as usize];
            b[0] -= law.force[0];
            b[1] -= law.force[1];
            if law.status != crate::rigid::Status::Free {
                let key = node_key(mesh, dofs, c.node as usize);
                contact_state.insert((key, law.body), [law.pressure, law.shear]);
            }
        }
        let du = problem.node_displacements(&local);
        let pressure = problem.node_pressures(&local);
        let material_pressure = problem.material_pressures(&local);
        Ok(Outcome {
            du,
            pressure,
            material_pressure,
            states: converged.states,
            reaction,
            set_reactions,
            body_force,
            contact_state,
            stats,
            contact_switches: sum_f64(world, &[problem.contact_switches() as f64])[0] as usize,
        })
    }

    /// Reactions on the named `[[fixed]]` and `[[prescribed]]` sets (unnamed ones: zero, not
    /// computed).
    fn set_reactions(
        &self,
        mesh: &LocalMesh,
        dofs: &DofMap,
        problem: &StepProblem,
        converged: &crate::solve::problem::Converged,
        from: f64,
    ) -> Vec<[f64; 2]> {
        let scene = &self.model.scene;
        let names = scene
            .fixed
            .iter()
            .map(|f| f.name.is_some())
            .chain(scene.prescribed.iter().map(|p| p.name.is_some()));
        names
            .enumerate()
            .map(|(set, named)| {
                if !named {
                    return [0.0; 2];
                }
                problem.reaction(converged, |n| {
                    dofs.node_points(n).iter().all(|&p| {
                        let p = p as usize;
                        self.model.in_set(
                            set,
                            self.reference_position(mesh, p),
                            mesh.points[p],
                            from,
                        )
                    })
                })
            })
            .collect()
    }

    /// Collective. Moves the particles and carries the new Gauss states to them.
    /// `completes`: the increment ends the step (otherwise it is a piece of a cut step).
    pub fn update(
        &mut self,
        world: &Comm,
        mesh: &LocalMesh,
        solved: Solved,
        completes: bool,
    ) -> Result<StepReport, super::RunError> {
        let to = self.header.load_factor + solved.dlambda;
        self.record_bulges(world, mesh, &solved.dofs, &solved.du, to);
        // Increments are kept per whole step: the predictor of the next increment scales them.
        let per_step = 1.0 / (solved.dlambda * self.model.scene.steps.count as f64);
        for i in 0..self.particles.len() {
            let node = solved.dofs.node_of_point[i];
            let d = if node != u32::MAX {
                solved.du[node as usize]
            } else {
                [0.0; 2]
            };
            for (c, dc) in d.iter().enumerate() {
                self.particles.position[i][c] += dc;
                self.particles.displacement[i][c] += dc;
            }
            self.particles.increment[i] = [per_step * d[0], per_step * d[1]];
        }
        let planes = super::support_plane::support_planes(&self.model.scene.fixed);
        let hoop = self.model.scene.analysis.has_hoop();
        // The bodies at the step's end, built only for a scene that puts particles back.
        let bodies: Vec<_> = if planes.is_empty() && !hoop {
            Vec::new()
        } else {
            self.model.bodies.iter().map(|b| b.shape(to)).collect()
        };
        for plane in planes {
            let outside = |x: [f64; 2]| crate::rigid::gap(&bodies, x) >= 0.0;
            plane.put_back(&mut self.particles, self.model.tol, outside);
        }
        if hoop {
            self.particles
                .snap_to_axis(|x, h| super::axis::out_of_bodies(&bodies, x, h));
        }
        let last = (0..solved.dofs.n_nodes()).map(|n| {
            let d = solved.du[n];
            let v = [per_step * d[0], per_step * d[1], solved.pressure[n]];
            (node_key(mesh, &solved.dofs, n), v)
        });
        let by_material = solved.material_pressure.iter().map(|&(n, m, p)| {
            let gid = node_key(mesh, &solved.dofs, n)[0];
            ((gid, m), p)
        });
        *self.last_nodes.borrow_mut() =
            super::node_values::NodeValues::new(last, self.model.mixed())
                .with_material_pressures(by_material);
        self.particles.state = recover_at_particles(mesh, &solved.states, &self.particles.state);
        self.admit_particles();
        self.tri_states = TriStates::new(mesh, solved.states);
        self.last_reaction = solved.reaction;
        self.last_set_reactions = solved.set_reactions;
        self.last_body_force = solved.body_force;
        *self.last_contact.borrow_mut() = solved.contact_state;
        self.contact_switches
            .set(self.contact_switches.get() + solved.contact_switches as u64);
        self.last_area = owned_area(mesh, &solved.du, &solved.dofs);
        if completes {
            self.header.step += 1;
            self.header.load_factor = self.model.load_factor(self.header.step);
        } else {
            self.header.load_factor += solved.dlambda;
        }
        // The scene's time in seconds where it gives one (`scene::clock`), else the load factor
        // (a quasi-static analysis): history's `time` and the XDMF frames read it.
        let lf = self.header.load_factor;
        self.header.time = self.model.seconds_at(lf).unwrap_or(lf);
        Ok(StepReport {
            newton_iterations: solved.newton_iterations,
            linear_iterations: solved.linear_iterations,
            residual_norm: solved.residual_norm,
            ..self.last_report(world, mesh)
        })
    }

    /// Collective. A report of the particles and triangles now, and the triangles remapped
    /// since the last report; no solver figures.
    fn last_report(&self, world: &Comm, mesh: &LocalMesh) -> StepReport {
        let counts = sum_f64(
            world,
            &[
                self.particles.len() as f64,
                mesh.n_owned_tris() as f64,
                self.remapped.take() as f64,
            ],
        );
        StepReport {
            particles: counts[0] as u64,
            triangles: counts[1] as u64,
            remapped: counts[2] as u64,
            ..StepReport::default()
        }
    }
}

impl Simulation {
    /// Time spent on contact: finding the pairs and evaluating their laws.
    fn add_contact_seconds(&self, seconds: f64) {
        self.contact_seconds
            .set(self.contact_seconds.get() + seconds);
    }
}

/// Halvings of a step's increment before a Newton failure is final: the smallest piece is
/// 1/2⁶ of the step. The budget is the piece's size, not a count of the step's cuts: a step
/// with several hard places (a contact node reaching a corner, then another) cuts at each and
/// grows back in between, and a count over the whole step ended such steps on pieces of 1/8
/// (the coarse `cpt-trial` at z/D = 3.1, the `spudcan` at z/D = 0.11, bench/VALIDATION.md).
/// Every converged piece advances by at least the smallest, so a step ends after at most
/// 2⁶ converged pieces.
pub(super) const MAX_CUTS: usize = 6;

/// How many times Newton goes on from a converged increment whose contact gaps are not yet
/// within `contact.tolerance` (each time to its relative tolerance of the residual there)
/// before the increment counts as diverged.
const MAX_POLISHES: usize = 2;

impl Simulation {
    /// Collective. Solves the next step on `mesh` and moves the particles. When Newton diverges,
    /// the piece is tried once more with the other line search (full steps or backtracking),
    /// then cut in half (down to 1/2⁶ of the step, growing back after each success), each
    /// piece a full remesh–map–solve–update cycle; `mesh` ends as the mesh of the last piece.
    pub fn advance(
        &mut self,
        world: &Comm,
        petsc: &Petsc,
        mesh: &mut LocalMesh,
        states: StartStates,
    ) -> Result<StepReport, super::RunError> {
        let full = 1.0 / self.model.scene.steps.count as f64;
        let target = self.model.load_factor(self.header.step + 1);
        let mut from = self.header.load_factor;
        let mut piece = full;
        let mut states = states;
        let (mut cuts, mut newton, mut linear, mut remapped) = (0, 0, 0, 0);
        let steps = self.model.scene.steps;
        // Under `until_collapse` a failure is cut until it brackets the collapse load factor.
        let smallest = full / (1u64 << MAX_CUTS) as f64;
        let may_cut = |piece: f64| {
            if steps.until_collapse {
                piece > steps.collapse_tolerance
            } else {
                piece > 1.5 * smallest
            }
        };
        let mut converged_pieces = false;
        loop {
            let to = if from + piece >= target - 1e-9 * full {
                target
            } else {
                from + piece
            };
            // The remesh and mapping before a solve, and the solver after it, free much memory
            // that the next phase would not reuse in place.
            crate::heap::release_free_pages();
            let solved = self.solve(world, petsc, mesh, &states, from, to);
            crate::heap::release_free_pages();
            match solved {
                Ok(solved) if steps.until_collapse && self.is_mechanism(world, &solved) => {
                    self.alternate_search.set(false);
                    newton += solved.newton_iterations;
                    linear += solved.linear_iterations;
                    if may_cut(piece) {
                        cuts += 1;
                        piece *= 0.5;
                    } else {
                        let counts = [newton, linear, cuts, remapped as usize];
                        return Ok(self.collapsed(
                            world,
                            mesh,
                            converged_pieces,
                            [from, to],
                            counts,
                        ));
                    }
                }
                Ok(solved) => {
                    self.alternate_search.set(false);
                    let completes = to == target;
                    let mut report = self.update(world, mesh, solved, completes)?;
                    report.penetration = self.check_penetration(world)?;
                    newton += report.newton_iterations;
                    linear += report.linear_iterations;
                    remapped += report.remapped;
                    converged_pieces = true;
                    if completes {
                        let [failed_newton, failed_linear] = self.failed_tries.take();
                        report.newton_iterations = newton + failed_newton;
                        report.linear_iterations = linear + failed_linear;
                        report.remapped = remapped;
                        report.contact_switches = self.contact_switches.take() as usize;
                        report.contact_seconds = self.contact_seconds.take();
                        report.cuts = cuts;
                        return Ok(report);
                    }
                    from = to;
                    piece = (2.0 * piece).min(full);
                    *mesh = self.remesh(world)?;
                    states = self.map(mesh);
                }
                Err(SolveError::Diverged(_) | SolveError::ContactUnsettled(_))
                    if !self.alternate_search.get() =>
                {
                    self.alternate_search.set(true);
                }
                Err(SolveError::Diverged(_) | SolveError::ContactUnsettled(_))
                    if may_cut(piece) =>
                {
                    self.alternate_search.set(false);
                    cuts += 1;
                    piece *= 0.5;
                }
                Err(SolveError::Diverged(_) | SolveError::ContactUnsettled(_))
                    if steps.until_collapse =>
                {
                    let counts = [newton, linear, cuts, remapped as usize];
                    return Ok(self.collapsed(world, mesh, converged_pieces, [from, to], counts));
                }
                Err(e @ (SolveError::Diverged(_) | SolveError::ContactUnsettled(_))) => {
                    let contact = matches!(e, SolveError::ContactUnsettled(_));
                    return Err(super::RunError::Diverged {
                        message: e.to_string(),
                        piece: (full / (to - from)).round(),
                        cuts,
                        from,
                        advice: super::sanity::divergence_advice(&self.model, contact),
                    });
                }
                Err(e) => return Err(super::RunError::Solve(e)),
            }
        }
    }
}

impl Simulation {
    /// Collective. Whether a converged increment is a mechanism (`steps.collapse_compliance`):
    /// its largest displacement per unit load factor against the first increment's, which the
    /// first call records.
    fn is_mechanism(&mut self, world: &Comm, solved: &Solved) -> bool {
        let largest = solved
            .du
            .iter()
            .map(|d| d[0].hypot(d[1]))
            .fold(0.0, f64::max);
        let compliance = max_f64(world, largest) / solved.dlambda;
        match self.header.collapse_reference {
            None => {
                self.header.collapse_reference = Some(compliance);
                false
            }
            Some(first) => compliance > self.model.scene.steps.collapse_compliance * first,
        }
    }

    /// Adds a failed try's Newton and Krylov iterations to the step's report.
    fn count_failed_try(&self, [newton, linear]: [usize; 2]) {
        let [n, l] = self.failed_tries.get();
        self.failed_tries.set([n + newton, l + linear]);
    }

    /// Collective. The report of a step in which the collapse was bracketed in `[held, failed]`:
    /// equilibrium held at `held` (the body is there now) and failed, or was a mechanism, by
    /// `failed`. Pieces of the step that converged make a (shorter) step whose row is the
    /// collapse's. `counts`: Newton and linear iterations, cuts and remapped triangles so far.
    fn collapsed(
        &mut self,
        world: &Comm,
        mesh: &LocalMesh,
        converged_pieces: bool,
        bracket: [f64; 2],
        counts: [usize; 4],
    ) -> StepReport {
        if converged_pieces {
            self.header.step += 1;
        }
        let [failed_newton, failed_linear] = self.failed_tries.take();
        StepReport {
            newton_iterations: counts[0] + failed_newton,
            linear_iterations: counts[1] + failed_linear,
            cuts: counts[2],
            remapped: counts[3] as u64,
            contact_switches: self.contact_switches.take() as usize,
            contact_seconds: self.contact_seconds.take(),
            collapse: Some(bracket),
            ..self.last_report(world, mesh)
        }
    }
}

/// Area of this rank's owned triangles at the end of the step (moved by the vertex increments).
fn owned_area(mesh: &LocalMesh, du: &[[f64; 2]], dofs: &DofMap) -> f64 {
    let mut area = 0.0;
    for (t, tri) in mesh.tris.iter().enumerate() {
        if !mesh.tri_owned[t] {
            continue;
        }
        let [a, b, c] = tri.map(|v| {
            let d = du[dofs.node_of_point[v as usize] as usize];
            let x = mesh.points[v as usize];
            [x[0] + d[0], x[1] + d[1]]
        });
        area += 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    }
    area
}
