//! The residual and consistent tangent of one load step, evaluated rank-locally: every rank
//! computes all triangles around its owned nodes (a few interface triangles on two ranks) and adds
//! only its own rows, so assembly needs no off-rank communication and each row is summed in the
//! same order whatever the partition.

use super::pmg::CoarseSpace;
use super::smoother::{element_jacobi_bound, jacobi_damping};
use super::{Constraints, DofMap};
use crate::fem::analysis::Analysis;
use crate::fem::element::p2_element_with;
use crate::fem::mixed::p2p1_element;
use crate::fem::surface_load::edge_pressure_in;
use crate::mapping::StartStates;
use crate::mapping::{push_states, POINTS};
use crate::material::{GaussState, Material, Rows};
use crate::mesh::LocalMesh;
use crate::petsc::matrix::{to_int, MatRef};
use crate::petsc::snes::{CallbackError, NonlinearProblem};
use crate::petsc::{Int, Mat, PVec, PetscError, Scatter, VecRef};
use crate::rigid::{node_law_among, ContactPair, NodeLaw, Shape, Status};
use pfem_partition::{agree_on_error, Comm};
use std::cell::{Cell, RefCell};

/// The element family of a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kernel {
    /// 6-node displacement triangle (compressible solids).
    P2,
    /// Taylor–Hood P2–P1 with vertex pressures for nearly incompressible and plastically
    /// incompressible soil. The pressure unknown is p / `scale` (scale = G/h), which has the size
    /// of a displacement and keeps the saddle point well conditioned.
    P2P1 { scale: f64 },
}

/// What one material brings to its triangles.
#[derive(Clone, Copy)]
pub struct Law<'a> {
    pub material: &'a dyn Material,
    /// Bulk modulus of the mixed kernel's pressure–volume relation (Pa).
    pub bulk: f64,
    /// Body force per unit volume (N/m³) at the step's end.
    pub body_force: [f64; 2],
}

/// What a step needs besides the mesh.
pub struct StepSetup<'a> {
    /// The materials' laws, in the scene's order.
    pub laws: Vec<Law<'a>>,
    /// Index into `laws` of each local triangle.
    pub tri_law: Vec<u32>,
    pub kernel: Kernel,
    /// Plane strain or axisymmetry: the element kernels' and the surface loads' measure.
    pub analysis: Analysis,
    /// Cauchy state at the start of the step, per local triangle and Gauss point.
    pub states_n: &'a StartStates,
    pub constraints: &'a Constraints,
    /// Total external point forces on owned nodes at the end of the step: (node, force).
    pub point_loads: Vec<(u32, [f64; 2])>,
    /// Soil nodes facing rigid bodies (owned nodes only), and the bodies at the end of the step.
    pub contact: Vec<ContactPair>,
    pub bodies: Vec<Shape>,
    /// Follower pressures on boundary edges touching an owned node: nodes [a, m, b] (body on
    /// the left of a→b) and the pressure.
    pub surface: Vec<([u32; 3], f64)>,
}

impl StepSetup<'_> {
    /// The law of local triangle `t`.
    pub fn law(&self, t: usize) -> Law<'_> {
        self.laws[self.tri_law[t] as usize]
    }
}

/// One element's contribution: residual, row-major tangent (empty where only the residual and
/// states were asked for), states; dof order as the element's.
pub struct ElementResult {
    pub residual: Vec<f64>,
    pub tangent: Vec<f64>,
    pub states: [GaussState; 3],
}

/// The converged increment ([`StepProblem::converged`]).
pub struct Converged {
    /// Per local triangle, the Gauss states at the end of the increment (its Gauss points' rows
    /// of the material's layout).
    pub states: Rows,
    /// (triangle, displacement residual) of the triangles with a prescribed owned dof.
    residuals: Vec<(usize, [f64; 12])>,
}

pub struct StepProblem<'a> {
    comm: &'a Comm,
    mesh: &'a LocalMesh,
    dofs: &'a DofMap,
    setup: StepSetup<'a>,
    scatter: Scatter,
    /// Element dofs per triangle: 12 displacements, and 3 pressures for the mixed kernel. A
    /// triangle's local and global dof indices are derived from its nodes when needed
    /// ([`Self::local_dof`], [`Self::sorted_columns`]): kept per triangle, they were 108 bytes
    /// a triangle (about 4 % of the memory peak of the iterative path).
    dofs_per_element: usize,
    /// The diagonal of a constrained row: the mean diagonal of the free displacement rows, so
    /// that the constrained rows neither stand out of an AMG hierarchy nor spoil the
    /// conditioning (fixed on the first evaluation of the increment).
    diagonal: Cell<Option<f64>>,
    /// Where the Jacobian also assembles the Schur-complement preconditioner.
    schur: Option<SchurPreconditioner<'a>>,
    /// Where the Jacobian also assembles the p-multigrid's coarse operator.
    coarse: Option<CoarseOperator<'a>>,
    /// Whether every Jacobian bounds the spectrum of diag(J)⁻¹J ([`super::smoother`]) for
    /// the p-multigrid's smoother; the same on every rank (the bound is an allreduce).
    bound_jacobi_spectrum: bool,
    /// The last Jacobian's bound, the same on every rank.
    jacobi_bound: Cell<Option<f64>>,
    /// The element results of the last residual and the local vector they belong to. SNES asks
    /// for the Jacobian at the iterate whose residual it has just evaluated, and the converged
    /// state is read at the last residual's iterate: each evaluation there was a second full
    /// pass over the elements (measured on the cantilever at h = 1/32: 75 element passes for
    /// 35 Newton iterations, now 40).
    /// Kept only with `keep_elements`: on the iterative path the tangents of every triangle
    /// (1.2 kB each, 3 kB per particle) would sit beside the AMG hierarchy and the Krylov
    /// vectors at the memory peak, so there the Jacobian evaluates the elements again and
    /// assembles them one at a time (one more element pass per Newton iteration).
    cache: RefCell<Option<(Vec<f64>, Vec<ElementResult>)>>,
    keep_elements: bool,
    /// Where the linear solver asks for the yielded zone: the global displacement dofs of the
    /// owned triangles with a Gauss point that yields at the last Jacobian's iterate.
    yielded: Option<RefCell<Vec<usize>>>,
    /// The contact pair of each local node (`NO_PAIR` for none), and the triangles around the
    /// contact nodes, whose residuals make the soil's force at them.
    pair_of_node: Vec<u32>,
    contact_tris: Vec<usize>,
    /// The contact statuses at the last Jacobian, and how many changed between Jacobians (the
    /// active set's and stick/slip's settling over the Newton iterations).
    statuses: RefCell<Vec<Status>>,
    switches: Cell<usize>,
    /// Seconds spent on the contact laws.
    contact_seconds: Cell<f64>,
}

/// No contact pair at a node.
const NO_PAIR: u32 = u32::MAX;

/// The pressure mass matrix scaled by −1/G that a Schur-complement preconditioner uses, and
/// each local pressure unknown's row in it ([`DofMap::pressure_unknown`]).
pub struct SchurPreconditioner<'a> {
    pub matrix: &'a Mat,
    pub pressure_index: &'a [usize],
}

/// The coarse level of the p-multigrid: its matrix, assembled with every Jacobian as the
/// Galerkin product of the tangent ([`CoarseSpace::galerkin_element`]).
pub struct CoarseOperator<'a> {
    pub matrix: &'a Mat,
    pub space: &'a CoarseSpace,
}

impl<'a> StepProblem<'a> {
    /// Collective (builds the ghost scatter).
    pub fn new(
        comm: &'a Comm,
        mesh: &'a LocalMesh,
        dofs: &'a DofMap,
        setup: StepSetup<'a>,
        template: &PVec,
    ) -> Result<StepProblem<'a>, PetscError> {
        let scatter = Scatter::new(template, &dofs.ghost_globals())?;
        let mixed = matches!(setup.kernel, Kernel::P2P1 { .. });
        let dofs_per_element = if mixed { 15 } else { 12 };
        // The global columns are PETSc ints; check the largest once here, not per entry.
        if dofs.n_global_dofs > 0 {
            to_int(dofs.n_global_dofs - 1, "dof")?;
        }
        let mut pair_of_node = vec![NO_PAIR; dofs.n_nodes()];
        for (i, c) in setup.contact.iter().enumerate() {
            pair_of_node[c.node as usize] = i as u32;
        }
        let contact_tris = (0..dofs.tri_nodes.len())
            .filter(|&t| {
                dofs.tri_nodes[t]
                    .iter()
                    .any(|&n| pair_of_node[n as usize] != NO_PAIR)
            })
            .collect();
        Ok(StepProblem {
            comm,
            mesh,
            dofs,
            setup,
            scatter,
            dofs_per_element,
            diagonal: Cell::new(None),
            schur: None,
            coarse: None,
            bound_jacobi_spectrum: false,
            jacobi_bound: Cell::new(None),
            cache: RefCell::new(None),
            keep_elements: true,
            yielded: None,
            pair_of_node,
            contact_tris,
            statuses: RefCell::new(Vec::new()),
            switches: Cell::new(0),
            contact_seconds: Cell::new(0.0),
        })
    }

    /// The local node and component of element dof `k` of triangle `t`: x and y of the six
    /// nodes, then the vertices' pressures of the triangle's material.
    fn element_dof(&self, t: usize, k: usize) -> (usize, usize) {
        self.dofs.element_dof(t, k)
    }

    /// The local-vector index of element dof `k` of triangle `t`.
    fn local_dof(&self, t: usize, k: usize) -> usize {
        let (node, c) = self.element_dof(t, k);
        self.dofs.node_local(node) + c
    }

    /// Triangle `t`'s global columns in increasing order into `cols` and, for each, its element
    /// dof into `order`: PETSc's MatSetValues searches a row's columns from the last one found,
    /// so sorted columns make each search short. A node's dofs are consecutive, x first.
    fn sorted_columns(&self, t: usize, cols: &mut [Int], order: &mut [u8]) {
        let global = |k: usize| {
            let (node, c) = self.element_dof(t, k);
            self.dofs.global_dof(node, c)
        };
        let n = self.dofs_per_element;
        let mut keyed = [(0usize, 0u8); 15];
        for (k, slot) in keyed[..n].iter_mut().enumerate() {
            *slot = (global(k), k as u8);
        }
        keyed[..n].sort_unstable();
        for ((c, o), &(g, k)) in cols.iter_mut().zip(order.iter_mut()).zip(&keyed[..n]) {
            // In range: `new` checked the largest global dof.
            *c = g as Int;
            *o = k;
        }
    }

    fn n_triangles(&self) -> usize {
        self.dofs.tri_nodes.len()
    }

    /// Start-of-step nodes of triangle `t` (its curved boundary edges curved).
    fn geometry(&self, t: usize) -> [[f64; 2]; 6] {
        self.mesh.element_nodes(t)
    }

    /// Assembles `schur` with every Jacobian (mixed kernels only).
    pub fn with_schur_preconditioner(mut self, schur: SchurPreconditioner<'a>) -> Self {
        self.schur = Some(schur);
        self
    }

    /// Every Jacobian lists the displacement dofs of the owned triangles that yield at its
    /// iterate ([`super::precond::JacobianProducts::yielded_dofs`]): a Gauss point whose equivalent plastic
    /// strain grows there has the plastic tangent, with no stiffness along its flow direction.
    pub fn with_yielded_zone(mut self) -> Self {
        self.yielded = Some(RefCell::new(Vec::new()));
        self
    }

    /// Assembles the p-multigrid's coarse operator with every Jacobian (P2 kernel only).
    pub fn with_coarse_operator(mut self, coarse: CoarseOperator<'a>) -> Self {
        self.coarse = Some(coarse);
        self
    }

    /// Every Jacobian bounds the spectrum of diag(J)⁻¹J for the p-multigrid's smoother
    /// ([`super::precond::JacobianProducts::smoother_damping`]). Every rank must agree, and the tangent must be
    /// the sum of symmetric element tangents alone: contact and follower pressures add terms
    /// that are neither.
    pub fn with_jacobi_bound(mut self) -> Self {
        self.bound_jacobi_spectrum = true;
        self
    }

    /// Evaluates the elements afresh for every residual and Jacobian instead of keeping the
    /// last residual's (see `cache`).
    pub fn without_element_cache(mut self) -> Self {
        self.keep_elements = false;
        self
    }

    fn pressure_scale(&self) -> f64 {
        match self.setup.kernel {
            Kernel::P2 => 1.0,
            Kernel::P2P1 { scale, .. } => scale,
        }
    }

    /// Initial iterate: the predicted step displacement per node (the last step's increment)
    /// and pressure per vertex and material (scaled), with prescribed step displacements
    /// imposed.
    pub fn initial_guess(
        &self,
        x: &PVec,
        displacement: impl Fn(usize) -> [f64; 2],
        pressure: impl Fn(usize, u32) -> f64,
    ) -> Result<(), PetscError> {
        let first = self.dofs.first_dof;
        let scale = self.pressure_scale();
        x.as_ref().write(|xa| {
            for n in 0..self.dofs.n_nodes() {
                if !self.dofs.node_owned[n] {
                    continue;
                }
                let g = self.dofs.node_global[n] - first;
                let guess = displacement(n);
                for c in 0..2 {
                    xa[g + c] = self.setup.constraints.value(n, c).unwrap_or(guess[c]);
                }
                for c in 2..self.dofs.ndof(n) {
                    xa[g + c] = pressure(n, self.dofs.pressure_material(n, c)) / scale;
                }
            }
        })
    }

    /// Collective. The local vector (owned and ghost dofs) of a global one.
    pub fn local_values(&self, x: VecRef<'_>) -> Result<Vec<f64>, PetscError> {
        // Only the ghosts travel: a scatter of the whole local vector held index arrays and a
        // sequential copy of it (4.7 % of the iterative path's memory peak on one rank).
        self.scatter.gather(x, |ghosts| {
            x.read(|owned| self.dofs.local_vector(owned, ghosts))
        })?
    }

    /// Step displacement of every local node.
    pub fn node_displacements(&self, local: &[f64]) -> Vec<[f64; 2]> {
        (0..self.dofs.n_nodes())
            .map(|n| {
                let o = self.dofs.node_local(n);
                [local[o], local[o + 1]]
            })
            .collect()
    }

    /// Pressure (compression positive) of every local node at `local`; NaN where the node has
    /// no pressure unknown. A vertex where several materials meet has one per material: this
    /// is the one of its lowest material index (see [`Self::material_pressures`] for all). One
    /// of the solution's own values rather than their mean: a mean lies on neither side of the
    /// jump, so it would be a worse predictor for both, and the lowest index is the same
    /// choice on every rank.
    pub fn node_pressures(&self, local: &[f64]) -> Vec<f64> {
        let scale = self.pressure_scale();
        (0..self.dofs.n_nodes())
            .map(|n| {
                if self.dofs.pressure_count(n) > 0 {
                    scale * local[self.dofs.node_local(n) + 2]
                } else {
                    f64::NAN
                }
            })
            .collect()
    }

    /// Where pressures are per material: (vertex node, material, pressure) of every local
    /// pressure unknown at `local`; empty otherwise.
    pub fn material_pressures(&self, local: &[f64]) -> Vec<(usize, u32, f64)> {
        let scale = self.pressure_scale();
        if self.dofs.material_pressures.is_none() {
            return Vec::new();
        }
        let n_vertex = self.dofs.n_nodes() - self.dofs.edges.len();
        (0..n_vertex)
            .flat_map(|n| {
                (2..self.dofs.ndof(n)).map(move |c| {
                    let p = scale * local[self.dofs.node_local(n) + c];
                    (n, self.dofs.pressure_material(n, c), p)
                })
            })
            .collect()
    }

    /// The converged increment at the local vector `local` (the last residual's element results
    /// when it was evaluated there): every triangle's Gauss states and, for the triangles with
    /// a prescribed owned dof, the element residual the reactions sum. Triangles are evaluated
    /// one at a time, so no residual of the others is held: at a million particles on 2 ranks
    /// the whole list of element results was about 0.2 GB a rank above the solve's peak.
    pub fn converged(&self, local: &[f64]) -> Result<Converged, String> {
        let reacting = |t: usize| {
            (0..12).any(|k| {
                let node = self.dofs.tri_nodes[t][k / 2] as usize;
                self.dofs.node_owned[node] && self.setup.constraints.is_fixed(node, k % 2)
            })
        };
        let width = POINTS * self.setup.laws[0].material.layout().len();
        let mut out = Converged {
            states: Rows::with_capacity(width, self.n_triangles()),
            residuals: Vec::new(),
        };
        let mut take = |t: usize, e: &ElementResult| {
            push_states(&mut out.states, &e.states);
            if reacting(t) {
                out.residuals
                    .push((t, std::array::from_fn(|k| e.residual[k])));
            }
        };
        match self.cached(local) {
            Some(elems) => elems.iter().enumerate().for_each(|(t, e)| take(t, e)),
            None => {
                for t in 0..self.n_triangles() {
                    take(t, &self.evaluate_element(t, local, false)?);
                }
            }
        }
        Ok(out)
    }

    /// The cached element results if they were evaluated at exactly `local` (bit for bit);
    /// the cache is emptied either way.
    fn cached(&self, local: &[f64]) -> Option<Vec<ElementResult>> {
        let (at, elems) = self.cache.borrow_mut().take()?;
        let same = at.len() == local.len()
            && at
                .iter()
                .zip(local)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        same.then_some(elems)
    }

    /// Triangle `t` at the local vector `local`, with its tangent if `tangent`.
    fn evaluate_element(
        &self,
        t: usize,
        local: &[f64],
        tangent: bool,
    ) -> Result<ElementResult, String> {
        let s = &self.setup;
        let law = s.law(t);
        let at = |k: usize| local[self.local_dof(t, k)];
        let du: [[f64; 2]; 6] = std::array::from_fn(|k| [at(2 * k), at(2 * k + 1)]);
        let geometry = self.geometry(t);
        crate::material::umat::site::set_element(t, &geometry);
        let flat = |k: &[f64]| if tangent { k.to_vec() } else { Vec::new() };
        let result = match s.kernel {
            Kernel::P2 => p2_element_with(
                &geometry,
                &du,
                &s.states_n.get(t),
                law.material,
                law.body_force,
                s.analysis,
                tangent,
            )
            .map(|e| ElementResult {
                residual: e.residual.to_vec(),
                tangent: flat(e.tangent.as_flattened()),
                states: e.states,
            }),
            Kernel::P2P1 { scale } => {
                let p: [f64; 3] = std::array::from_fn(|k| scale * at(12 + k));
                p2p1_element(
                    &geometry,
                    &du,
                    &p,
                    &s.states_n.get(t),
                    law.material,
                    law.bulk,
                    law.body_force,
                    s.analysis,
                )
                .map(|e| {
                    let e = e.with_pressure_scale(scale);
                    ElementResult {
                        residual: e.residual.to_vec(),
                        tangent: flat(e.tangent.as_flattened()),
                        states: e.states,
                    }
                })
            }
        };
        result.map_err(|e| format!("triangle {:?}: {e}", self.mesh.tri_key(t)))
    }

    /// Collective. Hands every local triangle at the local vector `local`, in order, to `each` (the cached results
    /// when the last residual was evaluated there), and returns `local`. A failing element
    /// or `each` stops the pass, and all ranks learn of it, so they fail together and of the
    /// same kind (`each` may then have seen only some triangles). The first evaluation of the
    /// increment also fixes the constrained diagonal. For the residual (`jacobian` false) the
    /// results are kept for the Jacobian at the same `x` (with `keep_elements`); tangents are
    /// computed only where they are read.
    fn evaluate(
        &self,
        local: Vec<f64>,
        jacobian: bool,
        mut each: impl FnMut(usize, &ElementResult) -> Result<(), CallbackError>,
    ) -> Result<Vec<f64>, CallbackError> {
        let first = self.diagonal.get().is_none();
        let store = !jacobian && self.keep_elements;
        let tangent = jacobian || first || store;
        let mut diagonal_sum = 0.0;
        let mut keep = Vec::new();
        let cached = self.cached(&local);
        let mut failed = None;
        for t in 0..self.n_triangles() {
            let mut fresh = None;
            let e: &ElementResult = match &cached {
                Some(elems) => &elems[t],
                None => match self.evaluate_element(t, &local, tangent) {
                    Ok(e) => fresh.insert(e),
                    Err(msg) => {
                        failed = Some(CallbackError::Domain(msg));
                        break;
                    }
                },
            };
            if first {
                self.add_free_diagonal(t, e, &mut diagonal_sum);
            }
            if let Err(err) = each(t, e) {
                failed = Some(err);
                break;
            }
            if store {
                keep.extend(fresh);
            }
        }
        // Every rank takes part in the agreement, hit or miss, so the collective calls match;
        // the kind travels as the message's first character.
        let encoded = failed.map(|e| match e {
            CallbackError::Domain(m) => format!("D{m}"),
            CallbackError::Fatal(m) => format!("F{m}"),
        });
        if let Some(agreed) = agree_on_error(self.comm, encoded) {
            let (kind, msg) = agreed.split_at(1);
            return Err(match kind {
                "F" => CallbackError::Fatal(msg.to_string()),
                _ => CallbackError::Domain(msg.to_string()),
            });
        }
        if first {
            self.diagonal
                .set(Some(self.mean_free_diagonal(diagonal_sum)));
        }
        if store {
            *self.cache.borrow_mut() = Some((local.clone(), cached.unwrap_or(keep)));
        }
        Ok(local)
    }

    /// Adds the diagonal entries of the free displacement rows of triangle `t`'s tangent to
    /// `sum` one by one (the order of the sum is the triangles' and rows', whatever the cache).
    fn add_free_diagonal(&self, t: usize, e: &ElementResult, sum: &mut f64) {
        let n = e.residual.len();
        for k in 0..12 {
            if self.free_row(t, k).is_some() {
                *sum += e.tangent[k * n + k];
            }
        }
    }

    /// Collective. The mean diagonal of the free displacement rows of the tangent, from this
    /// rank's sum of them (without contact and surface loads; 1 when no row is free).
    fn mean_free_diagonal(&self, diagonal_sum: f64) -> f64 {
        let mut sums = [diagonal_sum, 0.0];
        for n in 0..self.dofs.n_nodes() {
            for c in 0..2 {
                if self.free(n, c) {
                    sums[1] += 1.0;
                }
            }
        }
        positive_mean(self.comm, sums)
    }

    /// The diagonal of constrained rows, and the factor of their residual x − g.
    fn constrained_diagonal(&self) -> f64 {
        self.diagonal.get().unwrap_or(1.0)
    }

    /// Whether element dof `k` of triangle `t` is a prescribed displacement (owned or not).
    fn constrained_column(&self, t: usize, k: usize) -> bool {
        let (node, c) = self.element_dof(t, k);
        self.setup.constraints.is_fixed(node, c)
    }

    /// The owned, unconstrained row of element dof `k` of triangle `t`, as an offset among this
    /// rank's owned rows, if any.
    fn free_row(&self, t: usize, k: usize) -> Option<usize> {
        let (node, c) = self.element_dof(t, k);
        if !self.dofs.node_owned[node] || self.setup.constraints.is_fixed(node, c) {
            return None;
        }
        Some(self.dofs.node_global[node] - self.dofs.first_dof + c)
    }

    fn node_u(&self, local: &[f64], n: usize) -> [f64; 2] {
        let o = self.dofs.node_local(n);
        [local[o], local[o + 1]]
    }

    /// The contact pairs of this increment.
    pub fn contact_pairs(&self) -> &[ContactPair] {
        &self.setup.contact
    }

    /// The contact law of every pair at `local` ([`node_law_among`]), from the soil's residual at
    /// its node: the triangles around the contact nodes, in increasing order as the full pass
    /// adds them, then the surface pressures and point loads. Every residual and Jacobian at
    /// one iterate so decides alike. A triangle that cannot be evaluated is left out: the full
    /// pass over the elements meets it too and fails on every rank together.
    pub fn contact_laws(&self, local: &[f64]) -> Vec<NodeLaw> {
        let s = &self.setup;
        if s.contact.is_empty() {
            return Vec::new();
        }
        let clock = std::time::Instant::now();
        let mut r = vec![[0.0; 2]; s.contact.len()];
        for &t in &self.contact_tris {
            let Ok(e) = self.evaluate_element(t, local, false) else {
                continue;
            };
            for (a, &n) in self.dofs.tri_nodes[t].iter().enumerate() {
                let pair = self.pair_of_node[n as usize];
                if pair != NO_PAIR {
                    r[pair as usize][0] += e.residual[2 * a];
                    r[pair as usize][1] += e.residual[2 * a + 1];
                }
            }
        }
        self.loads(local, |n, c, v| {
            let pair = self.pair_of_node[n];
            if pair != NO_PAIR {
                r[pair as usize][c] -= v;
            }
        });
        let laws = s
            .contact
            .iter()
            .zip(&r)
            .map(|(c, &r)| node_law_among(c, &s.bodies, self.node_u(local, c.node as usize), r))
            .collect();
        self.contact_seconds
            .set(self.contact_seconds.get() + clock.elapsed().as_secs_f64());
        laws
    }

    /// Seconds this problem spent on the contact laws.
    pub fn contact_seconds(&self) -> f64 {
        self.contact_seconds.get()
    }

    /// How many contact statuses (touching, sticking, slipping) changed from one Jacobian to
    /// the next: the active set's settling.
    pub fn contact_switches(&self) -> usize {
        self.switches.get()
    }

    /// Notes the statuses of a Jacobian's laws, counting those that changed since the last.
    fn note_statuses(&self, laws: &[NodeLaw]) {
        let mut last = self.statuses.borrow_mut();
        if last.len() == laws.len() {
            let changed = last
                .iter()
                .zip(laws)
                .filter(|(a, l)| **a != l.status)
                .count();
            self.switches.set(self.switches.get() + changed);
        }
        *last = laws.iter().map(|l| l.status).collect();
    }

    /// The external forces other than contact at `local`, as (local node, component, force):
    /// surface pressures, then point loads.
    fn loads(&self, local: &[f64], mut add: impl FnMut(usize, usize, f64)) {
        for (nodes, p) in &self.setup.surface {
            let x = nodes.map(|n| self.node_position(local, n as usize));
            let load = edge_pressure_in(self.setup.analysis, x, *p);
            for (j, &n) in nodes.iter().enumerate() {
                for k in 0..2 {
                    add(n as usize, k, load.force[2 * j + k]);
                }
            }
        }
        for &(n, force) in &self.setup.point_loads {
            for (c, fc) in force.iter().enumerate() {
                add(n as usize, c, *fc);
            }
        }
    }

    /// Current position of local node `n` (start of step plus the increment in `local`).
    fn node_position(&self, local: &[f64], n: usize) -> [f64; 2] {
        let u = self.node_u(local, n);
        let x0 = self.node_start(n);
        [x0[0] + u[0], x0[1] + u[1]]
    }

    /// Start-of-step position of local node `n` (an edge node on its curve, or at its chord's
    /// midpoint).
    pub fn node_start(&self, n: usize) -> [f64; 2] {
        let n_vertex = self.dofs.n_nodes() - self.dofs.edges.len();
        if n < n_vertex {
            self.mesh.points[self.dofs.node_point[n] as usize]
        } else {
            let [a, b] = self.dofs.edges[n - n_vertex];
            self.mesh.midside(a, b)
        }
    }

    /// Whether component `c` of local node `n` is an owned, unconstrained row.
    fn free(&self, n: usize, c: usize) -> bool {
        self.dofs.node_owned[n] && !self.setup.constraints.is_fixed(n, c)
    }

    /// Reaction forces: the internal force on the constrained owned dofs of the nodes `select`
    /// picks, summed per component.
    pub fn reaction(&self, converged: &Converged, select: impl Fn(usize) -> bool) -> [f64; 2] {
        let mut r = [0.0; 2];
        for (t, residual) in &converged.residuals {
            for (k, f) in residual.iter().enumerate() {
                let node = self.dofs.tri_nodes[*t][k / 2] as usize;
                let c = k % 2;
                if self.dofs.node_owned[node]
                    && self.setup.constraints.is_fixed(node, c)
                    && select(node)
                {
                    r[c] += f;
                }
            }
        }
        r
    }
}

impl StepProblem<'_> {
    /// −d(surface pressure)/du, and the contact laws' own terms at their nodes (`local` of
    /// [`NodeLaw`]), on owned free rows, as (global row, global column, value).
    fn external_tangent(
        &self,
        local: &[f64],
        laws: &[NodeLaw],
        mut add: impl FnMut(Int, Int, f64) -> Result<(), PetscError>,
    ) -> Result<(), PetscError> {
        let g = |n: usize, c: usize| to_int(self.dofs.node_global[n] + c, "dof");
        // A prescribed column adds an explicit zero: the matrix keeps one pattern, and the
        // constrained rows and columns stay symmetric.
        let fixed = |n: usize, k: usize| self.setup.constraints.is_fixed(n, k);
        for (c, law) in self.setup.contact.iter().zip(laws) {
            let n = c.node as usize;
            for i in 0..2 {
                if self.free(n, i) {
                    for k in 0..2 {
                        let v = if fixed(n, k) { 0.0 } else { law.local[i][k] };
                        add(g(n, i)?, g(n, k)?, v)?;
                    }
                }
            }
        }
        for (nodes, p) in &self.setup.surface {
            let x = nodes.map(|n| self.node_position(local, n as usize));
            let load = edge_pressure_in(self.setup.analysis, x, *p);
            for (a, &na) in nodes.iter().enumerate() {
                for i in 0..2 {
                    if !self.free(na as usize, i) {
                        continue;
                    }
                    for (b, &nb) in nodes.iter().enumerate() {
                        for k in 0..2 {
                            let v = if fixed(nb as usize, k) {
                                0.0
                            } else {
                                -load.tangent[2 * a + i][2 * b + k]
                            };
                            add(g(na as usize, i)?, g(nb as usize, k)?, v)?;
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Triangle `t`'s row-major `tangent` with the rows of its contact nodes taken through
    /// their laws' transforms (borrowed unchanged where it has none).
    fn contact_rows<'t>(
        &self,
        t: usize,
        tangent: &'t [f64],
        laws: &[NodeLaw],
    ) -> std::borrow::Cow<'t, [f64]> {
        let nodes = &self.dofs.tri_nodes[t];
        if laws.is_empty()
            || nodes
                .iter()
                .all(|&n| self.pair_of_node[n as usize] == NO_PAIR)
        {
            return std::borrow::Cow::Borrowed(tangent);
        }
        let width = self.dofs_per_element;
        let mut out = tangent.to_vec();
        for (a, &node) in nodes.iter().enumerate() {
            let pair = self.pair_of_node[node as usize];
            if pair == NO_PAIR {
                continue;
            }
            let m = laws[pair as usize].transform;
            let (rx, ry) = (2 * a * width, (2 * a + 1) * width);
            for col in 0..width {
                let (x, y) = (tangent[rx + col], tangent[ry + col]);
                out[rx + col] = m[0][0] * x + m[0][1] * y;
                out[ry + col] = m[1][0] * x + m[1][1] * y;
            }
        }
        std::borrow::Cow::Owned(out)
    }
}

/// Collective. The global mean of the diagonal entries whose rank-local sum and count are
/// `sum_count`: the diagonal given to prescribed rows, or 1 where there is no positive one.
fn positive_mean(comm: &Comm, sum_count: [f64; 2]) -> f64 {
    let totals = pfem_partition::sum_f64(comm, &sum_count);
    let mean = totals[0] / totals[1].max(1.0);
    if mean.is_finite() && mean > 0.0 {
        mean
    } else {
        1.0
    }
}

impl NonlinearProblem for StepProblem<'_> {
    fn residual(&mut self, x: VecRef<'_>, f: VecRef<'_>) -> Result<(), CallbackError> {
        let first = self.dofs.first_dof;
        let local = self
            .local_values(x)
            .map_err(|e| CallbackError::Fatal(e.to_string()))?;
        let mut evaluated = Ok(Vec::new());
        f.write(|fa| {
            fa.fill(0.0);
            evaluated = self.evaluate(local, false, |t, e| {
                for (k, r) in e.residual.iter().enumerate() {
                    if let Some(row) = self.free_row(t, k) {
                        fa[row] += r;
                    }
                }
                Ok(())
            });
        })
        .map_err(|e| CallbackError::Fatal(e.to_string()))?;
        let local = evaluated?;
        // Read after the evaluation: the first one of the increment fixes it.
        let diagonal = self.constrained_diagonal();
        let laws = self.contact_laws(&local);
        f.write(|fa| {
            self.loads(&local, |n, c, v| {
                if self.free(n, c) {
                    fa[self.dofs.node_global[n] - first + c] -= v;
                }
            });
            // A contact node's rows are its law's: the soil's force there where it is free,
            // the closed gap and the stick or slip condition where it touches.
            for (c, law) in self.setup.contact.iter().zip(&laws) {
                let n = c.node as usize;
                for (k, v) in law.rows.iter().enumerate() {
                    if self.free(n, k) {
                        fa[self.dofs.node_global[n] - first + k] = *v;
                    }
                }
            }
            for (n, c, g) in self.setup.constraints.prescribed() {
                if self.dofs.node_owned[n] {
                    fa[self.dofs.node_global[n] - first + c] =
                        diagonal * (local[self.dofs.node_local(n) + c] - g);
                }
            }
        })
        .map_err(|e| CallbackError::Fatal(e.to_string()))?;
        Ok(())
    }

    fn jacobian(&mut self, x: VecRef<'_>, j: MatRef<'_>) -> Result<(), CallbackError> {
        let fatal = |e: PetscError| CallbackError::Fatal(e.to_string());
        j.zero_entries().map_err(fatal)?;
        if let Some(c) = &self.coarse {
            c.matrix.as_ref().zero_entries().map_err(fatal)?;
        }
        let mut coarse_diagonal = 0.0;
        // P2 displacements: every node carries x and y at consecutive global dofs (2 g, 2 g + 1).
        let blocked = self.dofs.block_size() == 2;
        let mut block_cols = Vec::with_capacity(6);
        let mut rows = Vec::new();
        let mut vals = Vec::new();
        let (mut sorted_cols, mut sorted_dofs) = ([0 as Int; 15], [0u8; 15]);
        let mut jacobi_bound: f64 = 0.0;
        let bounded = self.bound_jacobi_spectrum;
        debug_assert!(
            !bounded || (self.setup.contact.is_empty() && self.setup.surface.is_empty()),
            "contact and follower pressures are neither element matrices nor symmetric"
        );
        let mut yielded = self.yielded.as_ref().map(|y| y.borrow_mut());
        if let Some(y) = yielded.as_mut() {
            y.clear();
        }
        let local = self.local_values(x).map_err(fatal)?;
        let laws = self.contact_laws(&local);
        self.note_statuses(&laws);
        let evaluated = self.evaluate(local, true, |t, e| {
            if let Some(y) = yielded.as_mut() {
                // Each triangle once over the ranks: its owner lists it.
                let start = self.setup.states_n.get(t);
                let material = self.setup.law(t).material;
                if self.mesh.tri_owned[t]
                    && e.states
                        .iter()
                        .zip(&start)
                        .any(|(a, b)| material.yielded(b, a))
                {
                    for &n in &self.dofs.tri_nodes[t] {
                        let first = self.dofs.node_global[n as usize];
                        y.extend([first, first + 1]);
                    }
                }
            }
            if let Some(c) = &self.coarse {
                let m = c.matrix.as_ref();
                coarse_diagonal += c
                    .space
                    .galerkin_element(
                        self.dofs,
                        self.setup.constraints,
                        t,
                        &e.tangent,
                        |rows, cols, vals| {
                            let mut ints = [0 as Int; 6];
                            for (i, &g) in rows.iter().chain(cols).enumerate() {
                                ints[i] = to_int(g, "coarse dof")?;
                            }
                            let (rows, cols) = ints[..rows.len() + 3].split_at(rows.len());
                            m.add_blocks(rows, cols, vals)
                        },
                    )
                    .map_err(fatal)?;
            }
            let n = e.residual.len();
            let tangent = self.contact_rows(t, &e.tangent, &laws);
            self.sorted_columns(t, &mut sorted_cols, &mut sorted_dofs);
            let (cols, order) = (&sorted_cols[..n], &sorted_dofs[..n]);
            // Prescribed columns are zeroed (not dropped, so the pattern stays): with the
            // constrained rows holding only their diagonal, the matrix stays as symmetric as
            // the tangent. Newton keeps prescribed dofs at their values, so their columns
            // would multiply a zero update anyway.
            // Most triangles have no prescribed dof: one mask per triangle spares them a test
            // per entry. A row's entries in the sorted column order, prescribed columns zero.
            let fixed = (0..n)
                .filter(|&k| self.constrained_column(t, k))
                .fold(0u16, |m, k| m | 1 << k);
            if bounded {
                jacobi_bound = jacobi_bound.max(element_jacobi_bound(&e.tangent, n, fixed));
            }
            let push_row = |vals: &mut Vec<f64>, k: usize| {
                let row = &tangent[k * n..][..n];
                if fixed == 0 {
                    vals.extend(order.iter().map(|&c| row[c as usize]));
                } else {
                    vals.extend(order.iter().map(|&c| {
                        if fixed & 1 << c != 0 {
                            0.0
                        } else {
                            row[c as usize]
                        }
                    }));
                }
            };
            rows.clear();
            vals.clear();
            if blocked {
                // A node's two dofs are adjacent in the sorted order, x first: whole 2 × 2
                // blocks, with zero rows where a component is prescribed.
                block_cols.clear();
                block_cols.extend(cols.iter().step_by(2).map(|&c| c / 2));
                for (pair, &col) in order.chunks(2).zip(cols.iter().step_by(2)) {
                    let node = self.dofs.tri_nodes[t][pair[0] as usize / 2] as usize;
                    if !self.dofs.node_owned[node] {
                        continue;
                    }
                    rows.push(col / 2);
                    for &k in pair {
                        if fixed & 1 << k != 0 {
                            vals.extend(std::iter::repeat_n(0.0, n));
                        } else {
                            push_row(&mut vals, k as usize);
                        }
                    }
                }
                if !rows.is_empty() {
                    j.add_blocks(&rows, &block_cols, &vals).map_err(fatal)?;
                }
                return Ok(());
            }
            for (&row, &k) in cols.iter().zip(order) {
                let k = k as usize;
                if self.free_row(t, k).is_some() {
                    rows.push(row);
                    push_row(&mut vals, k);
                }
            }
            if !rows.is_empty() {
                j.add_values(&rows, cols, &vals).map_err(fatal)?;
            }
            Ok(())
        });
        let local = match evaluated {
            Ok(local) => local,
            Err(CallbackError::Domain(msg)) => {
                // Every rank failed alike: leave the matrices assembled for the next attempt.
                j.assemble().map_err(fatal)?;
                if let Some(c) = &self.coarse {
                    c.matrix.as_ref().assemble().map_err(fatal)?;
                }
                return Err(CallbackError::Domain(msg));
            }
            Err(e) => return Err(e),
        };
        if bounded {
            // A prescribed row holds only its diagonal: eigenvalue 1 of diag(J)⁻¹J.
            let bound = pfem_partition::max_f64(self.comm, jacobi_bound.max(1.0));
            self.jacobi_bound.set(Some(bound));
        }
        self.external_tangent(&local, &laws, |r, c, v| j.add_values(&[r], &[c], &[v]))
            .map_err(fatal)?;
        let diagonal = self.constrained_diagonal();
        for (n, c, _) in self.setup.constraints.prescribed() {
            if self.dofs.node_owned[n] {
                let r = to_int(self.dofs.node_global[n] + c, "dof").map_err(fatal)?;
                j.add_values(&[r], &[r], &[diagonal]).map_err(fatal)?;
            }
        }
        if let Some(schur) = &self.schur {
            self.assemble_schur_preconditioner(schur, &local)
                .map_err(fatal)?;
        }
        if let Some(c) = &self.coarse {
            self.finish_coarse_operator(c, coarse_diagonal)
                .map_err(fatal)?;
        }
        j.assemble().map_err(fatal)
    }
}

impl super::precond::JacobianProducts for StepProblem<'_> {
    fn yielded_dofs(&mut self) -> Vec<usize> {
        self.yielded
            .as_ref()
            .map(|y| std::mem::take(&mut *y.borrow_mut()))
            .unwrap_or_default()
    }

    fn smoother_damping(&self) -> Option<f64> {
        self.jacobi_bound
            .get()
            .filter(|b| b.is_finite())
            .map(jacobi_damping)
    }
}

impl StepProblem<'_> {
    /// Collective. Gives the prescribed coarse rows the mean free coarse diagonal (from this
    /// rank's sum of its free diagonal entries) and assembles the coarse operator. Contact and
    /// follower pressures stay on the fine level: their terms couple a node, or a boundary
    /// edge's nodes, only, which the smoother reaches.
    fn finish_coarse_operator(
        &self,
        c: &CoarseOperator,
        diagonal_sum: f64,
    ) -> Result<(), PetscError> {
        let constraints = self.setup.constraints;
        let count = c.space.free_count(self.dofs, constraints) as f64;
        let diagonal = positive_mean(self.comm, [diagonal_sum, count]);
        let m = c.matrix.as_ref();
        for r in c.space.fixed_rows(self.dofs, constraints) {
            let r = to_int(r, "coarse dof")?;
            m.add_values(&[r], &[r], &[diagonal])?;
        }
        m.assemble()
    }

    /// Collective. The pressure mass matrix scaled by −(1/G_eff + 1/K) per triangle, in the
    /// scaled pressure unknown: the Schur complement −(K_pp + B A⁻¹ Bᵀ) of a solid with shear
    /// modulus G and bulk modulus K is spectrally close to it. G_eff is the current tangent's
    /// (see [`super::split::effective_shear_modulus`]), so it follows plastic yielding.
    fn assemble_schur_preconditioner(
        &self,
        schur: &SchurPreconditioner,
        local: &[f64],
    ) -> Result<(), PetscError> {
        let Kernel::P2P1 { scale } = self.setup.kernel else {
            return Ok(());
        };
        let m = schur.matrix.as_ref();
        m.zero_entries()?;
        for (t, nodes) in self.dofs.tri_nodes.iter().enumerate() {
            let owned: Vec<usize> = (0..3)
                .filter(|&a| self.dofs.node_owned[nodes[a] as usize])
                .collect();
            if owned.is_empty() {
                continue;
            }
            let du: [[f64; 2]; 6] = std::array::from_fn(|k| self.node_u(local, nodes[k] as usize));
            let x = &self.geometry(t);
            let Law { material, bulk, .. } = self.setup.law(t);
            let g = super::split::effective_shear_modulus(
                x,
                &du,
                &self.setup.states_n.get(t),
                material,
            )
            .unwrap_or(f64::INFINITY);
            let area = crate::fem::p1::area(&[x[0], x[1], x[2]]);
            let factor = -scale * scale * (1.0 / g.max(f64::MIN_POSITIVE) + 1.0 / bulk);
            let mass = super::split::p1_mass(area);
            let cols = (0..3)
                .map(|k| {
                    let n = nodes[k] as usize;
                    let u = self
                        .dofs
                        .pressure_unknown(n, self.dofs.pressure_component(t, k));
                    to_int(schur.pressure_index[u], "pressure")
                })
                .collect::<Result<Vec<Int>, _>>()?;
            for a in owned {
                let vals: Vec<f64> = mass[a].iter().map(|v| factor * v).collect();
                m.add_values(&cols[a..a + 1], &cols, &vals)?;
            }
        }
        m.assemble()
    }
}
