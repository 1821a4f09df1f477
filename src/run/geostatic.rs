//! `[geostatic] equilibrate = true`: the column stresses brought into equilibrium before step 1.
//!
//! Column weights balance gravity only under level ground. On a slope, or wherever a zone's
//! weight is carried sideways, the first step would settle the difference as if it were load,
//! so the start state is equilibrated first, as Abaqus' geostatic step does: a Newton solve at
//! the starting load factor (no load changes) whose stresses are kept and whose displacements
//! are dropped. The stresses of a solve balance gravity on the slightly displaced mesh, so the
//! solve is repeated from them on the drawn one until its displacements vanish to round-off.

use super::step::SolveError;
use super::{RunError, Simulation};
use crate::mapping::{recover_at_particles, TriStates};
use crate::petsc::Petsc;
use pfem_partition::{max_f64, Comm};

/// Solves before the remaining displacement is taken as round-off anyway.
const PASSES: usize = 8;
/// Largest displacement of a pass, relative to the first pass's, that counts as round-off.
const SETTLED: f64 = 1e-10;

impl Simulation {
    /// Collective. Equilibrates the start state (see the module docs); returns the Newton
    /// iterations and the largest displacement of the last pass relative to the first's.
    pub fn equilibrate_geostatic(
        &mut self,
        world: &Comm,
        petsc: &Petsc,
    ) -> Result<(usize, f64), RunError> {
        let lf = self.header.load_factor;
        let (mut newton, mut first, mut last) = (0, None::<f64>, 0.0);
        for _ in 0..PASSES {
            let mesh = self.remesh(world)?;
            let states = self.map(&mesh);
            let solved = self
                .solve(world, petsc, &mesh, &states, lf, lf)
                .map_err(|e| match e {
                    SolveError::Fatal(_) => RunError::Solve(e),
                    other => RunError::Solve(SolveError::Fatal(format!(
                        "[geostatic] equilibrate: the start state has no equilibrium with \
                         gravity and the supports ({other}); check the supports and the \
                         strength of the soil"
                    ))),
                })?;
            newton += solved.newton_iterations;
            let local = (solved.du.iter())
                .map(|d| d[0].hypot(d[1]))
                .fold(0.0, f64::max);
            let largest = max_f64(world, local);
            self.particles.state =
                recover_at_particles(&mesh, &solved.states, &self.particles.state);
            self.admit_particles();
            self.tri_states = TriStates::new(&mesh, solved.states);
            let reference = *first.get_or_insert(largest);
            last = if reference > 0.0 {
                largest / reference
            } else {
                0.0
            };
            if last <= SETTLED {
                break;
            }
        }
        Ok((newton, last))
    }
}
