//! `[mesh.adapt]` on the distributed particles: each owned particle's target spacing from the
//! last step's solution, the gradation limit swept to its fixed point with the ghosts' spacings
//! copied from their owners between sweeps. Only `max` reductions and bitwise ghost copies, so the
//! spacings, and the refined cloud, do not depend on the rank count.

use super::Simulation;
use crate::mesh::adapt::{gradation_sweep, limit_rate, shear_indicator, target_spacing};
use crate::mesh::LocalMesh;
use pfem_partition::{max_f64, Comm};

impl Simulation {
    /// Collective. At the first remesh after every `every` completed steps (none before the
    /// first step: there is no solution yet) sets the owned particles' spacings from the
    /// displacement increments on `mesh`, the mesh of the current particles, and writes them
    /// (and the ghosts' copies) into `mesh.h`, for the refinement that follows. The mesh itself is kept: it was
    /// cut by the alpha shape with the spacings the particles have now, and a finer target
    /// there would open holes until the splits have made the particles that fine.
    pub(super) fn adapt_spacing(&mut self, world: &Comm, mesh: &mut LocalMesh) {
        let Some(a) = self.model.scene.mesh.adapt else {
            return;
        };
        let step = self.header.step;
        if step == 0 || !step.is_multiple_of(u64::from(a.every)) || self.adapted_at == Some(step) {
            return;
        }
        self.adapted_at = Some(step);
        let Some(halo) = self.halo.as_ref() else {
            return;
        };
        let n = mesh.n_owned;
        let (p, g) = (&self.particles, &self.ghosts);
        let du = |i: usize| {
            if i < n {
                p.increment[i]
            } else {
                g.increment[i - n]
            }
        };
        let indicator = shear_indicator(mesh, du);
        let largest = max_f64(world, indicator.iter().copied().fold(0.0, f64::max));
        if !(largest > 0.0 && largest.is_finite()) {
            return;
        }
        let target: Vec<f64> = indicator
            .iter()
            .map(|&v| target_spacing(v, largest, &a))
            .collect();
        let mut owned = target.clone();
        loop {
            let ghosts = halo.exchange_f64(world, &owned, 1);
            let all: Vec<f64> = owned.iter().chain(&ghosts).copied().collect();
            let (next, changed) = gradation_sweep(mesh, &all, &target, a.grading);
            owned = next;
            if max_f64(world, if changed { 1.0 } else { 0.0 }) == 0.0 {
                break;
            }
        }
        for (h, old) in owned.iter_mut().zip(&self.particles.h) {
            *h = limit_rate(*h, *old, &a);
        }
        let ghosts = halo.exchange_f64(world, &owned, 1);
        mesh.h = owned.iter().chain(&ghosts).copied().collect();
        self.particles.h = owned;
    }
}
