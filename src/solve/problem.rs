//! The residual and consistent tangent of one load step, evaluated rank-locally: every rank
//! computes all triangles around its owned nodes (a few interface triangles on two ranks) and adds
//! only its own rows, so assembly needs no off-rank communication and each row is summed in the
//! same order whatever the partition.

use super::{Constraints, DofMap};
use crate::fem::element::{p2_element, ElementOutput, N_DOFS};
use crate::fem::p2::straight_sided;
use crate::material::{GaussState, Material};
use crate::mesh::LocalMesh;
use crate::petsc::snes::{CallbackError, NonlinearProblem};
use crate::petsc::{matrix::MatRef, PVec, PetscError, Scatter, VecRef};
use pfem_partition::{agree_on_error, Comm};

/// What a step needs besides the mesh.
pub struct StepSetup<'a> {
    pub material: &'a dyn Material,
    /// Cauchy state at the start of the step, per local triangle and Gauss point.
    pub states_n: &'a [[GaussState; 3]],
    pub body_force: [f64; 2],
    pub constraints: &'a Constraints,
    /// Total external point forces on owned nodes at the end of the step: (node, force).
    pub point_loads: Vec<(u32, [f64; 2])>,
}

pub struct StepProblem<'a> {
    comm: &'a Comm,
    mesh: &'a LocalMesh,
    dofs: &'a DofMap,
    setup: StepSetup<'a>,
    scatter: Scatter,
    /// Start-of-step nodes of every triangle (straight sided).
    geometry: Vec<[[f64; 2]; 6]>,
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
        let scatter = Scatter::new(template, &dofs.local_to_global())?;
        let geometry = mesh
            .tris
            .iter()
            .map(|t| {
                straight_sided(&[
                    mesh.points[t[0] as usize],
                    mesh.points[t[1] as usize],
                    mesh.points[t[2] as usize],
                ])
            })
            .collect();
        Ok(StepProblem {
            comm,
            mesh,
            dofs,
            setup,
            scatter,
            geometry,
        })
    }

    /// Initial iterate: zero, except prescribed step displacements.
    pub fn initial_guess(&self, x: &PVec) -> Result<(), PetscError> {
        let first = self.dofs.first_dof;
        x.as_ref().write(|xa| {
            xa.fill(0.0);
            for (n, f) in self
                .dofs
                .node_owned
                .iter()
                .zip(&self.setup.constraints.fixed)
                .enumerate()
                .filter_map(|(n, (&o, f))| o.then_some((n, f)))
            {
                for c in 0..2 {
                    if let Some(g) = f[c] {
                        xa[self.dofs.node_global[n] - first + c] = g;
                    }
                }
            }
        })
    }

    /// Collective. Step displacement of every local node (owned and ghost), from the solution.
    pub fn local_displacements(&self, x: VecRef) -> Result<Vec<[f64; 2]>, PetscError> {
        self.scatter
            .gather(x, |l| l.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }

    /// Evaluates every local triangle at step displacement `du` (local node order).
    pub fn elements(&self, du: &[[f64; 2]]) -> Result<Vec<ElementOutput>, String> {
        let mut out = Vec::with_capacity(self.mesh.tris.len());
        for (t, nodes) in self.dofs.tri_nodes.iter().enumerate() {
            let mut d = [[0.0; 2]; 6];
            for (k, &n) in nodes.iter().enumerate() {
                d[k] = du[n as usize];
            }
            let e = p2_element(
                &self.geometry[t],
                &d,
                &self.setup.states_n[t],
                self.setup.material,
                self.setup.body_force,
            )
            .map_err(|e| format!("triangle {:?}: {e}", self.mesh.tri_key(t)))?;
            out.push(e);
        }
        Ok(out)
    }

    /// Collective: all ranks learn whether any element failed, so they fail together.
    fn evaluate(&self, x: VecRef) -> Result<Vec<ElementOutput>, CallbackError> {
        let du = self
            .local_displacements(x)
            .map_err(|e| CallbackError::Fatal(e.to_string()))?;
        let local = self.elements(&du);
        let err = local.as_ref().err().cloned();
        match agree_on_error(self.comm, err) {
            None => local.map_err(CallbackError::Domain),
            Some(msg) => Err(CallbackError::Domain(msg)),
        }
    }

    fn owned_row(&self, node: u32, c: usize) -> Option<usize> {
        let n = node as usize;
        (self.dofs.node_owned[n] && self.setup.constraints.fixed[n][c].is_none())
            .then(|| self.dofs.node_global[n] - self.dofs.first_dof + c)
    }
}

impl NonlinearProblem for StepProblem<'_> {
    fn residual(&mut self, x: VecRef, f: VecRef) -> Result<(), CallbackError> {
        let elems = self.evaluate(x)?;
        let xs: Vec<f64> = x
            .read(|a| a.to_vec())
            .map_err(|e| CallbackError::Fatal(e.to_string()))?;
        f.write(|fa| {
            fa.fill(0.0);
            for (nodes, e) in self.dofs.tri_nodes.iter().zip(&elems) {
                for (k, &n) in nodes.iter().enumerate() {
                    for c in 0..2 {
                        if let Some(row) = self.owned_row(n, c) {
                            fa[row] += e.residual[2 * k + c];
                        }
                    }
                }
            }
            for &(n, force) in &self.setup.point_loads {
                for (c, fc) in force.iter().enumerate() {
                    if let Some(row) = self.owned_row(n, c) {
                        fa[row] -= fc;
                    }
                }
            }
            for (n, fx) in self.setup.constraints.fixed.iter().enumerate() {
                if !self.dofs.node_owned[n] {
                    continue;
                }
                for (c, g) in fx.iter().enumerate() {
                    if let Some(g) = g {
                        let row = self.dofs.node_global[n] - self.dofs.first_dof + c;
                        fa[row] = xs[row] - g;
                    }
                }
            }
        })
        .map_err(|e| CallbackError::Fatal(e.to_string()))
    }

    fn jacobian(&mut self, x: VecRef, j: MatRef) -> Result<(), CallbackError> {
        let elems = self.evaluate(x)?;
        let fatal = |e: PetscError| CallbackError::Fatal(e.to_string());
        j.zero_entries().map_err(fatal)?;
        let mut rows = Vec::with_capacity(N_DOFS);
        let mut row_k = Vec::with_capacity(N_DOFS);
        let mut vals = Vec::with_capacity(N_DOFS * N_DOFS);
        for (nodes, e) in self.dofs.tri_nodes.iter().zip(&elems) {
            let cols: Vec<i32> = nodes
                .iter()
                .flat_map(|&n| {
                    let g = self.dofs.node_global[n as usize] as i32;
                    [g, g + 1]
                })
                .collect();
            rows.clear();
            row_k.clear();
            for (k, &n) in nodes.iter().enumerate() {
                for c in 0..2 {
                    if self.owned_row(n, c).is_some() {
                        rows.push(self.dofs.node_global[n as usize] as i32 + c as i32);
                        row_k.push(2 * k + c);
                    }
                }
            }
            if rows.is_empty() {
                continue;
            }
            vals.clear();
            for &r in &row_k {
                vals.extend_from_slice(&e.tangent[r]);
            }
            j.add_values(&rows, &cols, &vals).map_err(fatal)?;
        }
        for (n, fx) in self.setup.constraints.fixed.iter().enumerate() {
            if !self.dofs.node_owned[n] {
                continue;
            }
            for (c, g) in fx.iter().enumerate() {
                if g.is_some() {
                    let r = (self.dofs.node_global[n] + c) as i32;
                    j.add_values(&[r], &[r], &[1.0]).map_err(fatal)?;
                }
            }
        }
        j.assemble().map_err(fatal)
    }
}
