//! A displacement system at yield (a PETSc shell): GAMG on the whole block (the field split's
//! displacement block, or a P2 system), then an exact solve on the rows of the yielded zone.
//! A perfectly plastic tangent has no stiffness along the flow direction at every yielded
//! Gauss point, so the block's near-kernel is as large as the yielded zone and spans it (a
//! mechanism); no smoother or aggregation sees it, and splitting the zone into blocks cuts the
//! mechanism (both measured: bench/VALIDATION.md, "The field split at yield"). The zone's own
//! factorisation captures it whole, and GAMG keeps the elastic rest. Where the soil is elastic
//! the zone is empty and this is GAMG; where it is at yield everywhere it costs a direct solve
//! of the block.

use crate::petsc::matrix::to_int;
use crate::petsc::options;
use crate::petsc::{
    IndexScatter, IndexSet, Int, Ksp, PVec, Pc, PcRef, PetscError, ShellPreconditioner, VecRef,
    ViewerRef,
};

/// The shell's name, as `-ksp_view` shows it.
const NAME: &str = "yield zone (GAMG on the block, exact solve on the yielded rows)";

/// The preconditioner: its two inner solvers and the zone of the last set-up.
pub struct YieldZone {
    /// GAMG on the whole block (options prefix `fieldsplit_u_`, or none on a P2 system).
    amg: Pc,
    /// The zone's exact solver (options prefix GAMG's and `zone_`): MUMPS LU.
    exact: Ksp,
    /// The displacement field in the whole system's numbering (to find the block's rows);
    /// none when the block is the whole system.
    field: Option<IndexSet>,
    /// This rank's yielded rows of the block (the block's numbering), for the next set-up.
    rows: Vec<Int>,
    /// The zone as set up; none while it is empty.
    zone: Option<Zone>,
    /// The zone is every row: the exact solve alone is the preconditioner.
    whole: bool,
    /// Rows of the zone over all ranks, and of the block, at the last set-up.
    zone_size: Int,
    block_size: Int,
    /// The options have been read (at the first set-up).
    configured: bool,
}

/// What a set-up of a non-empty zone makes (its matrix is held by the exact solver).
struct Zone {
    rhs: PVec,
    solution: PVec,
    /// The block's residual.
    residual: PVec,
    /// The zone's rows of a vector of the block (made once per set-up: a sub-vector of an
    /// arbitrary index set would build it at every application).
    scatter: IndexScatter,
}

impl YieldZone {
    /// Collective. Makes `pc` (the displacement block's, `field` its rows in the whole
    /// system; none: `pc` is the whole system's) the yield zone, its GAMG reading options
    /// under `prefix`. Its exact solve orders MUMPS as the direct path does, unless the
    /// command line says otherwise.
    pub fn install(
        pc: PcRef<'_>,
        field: Option<&IndexSet>,
        prefix: &str,
    ) -> Result<(), PetscError> {
        options::set_default(&format!("-{prefix}zone_mat_mumps_icntl_7"), "2")?;
        let amg = Pc::create_like(&pc)?;
        let exact = Ksp::create_like(&pc)?;
        amg.as_ref().set_options_prefix(prefix)?;
        amg.as_ref().set_type("gamg")?;
        // Reused interpolation once made GAMG indefinite (as for GAMG alone).
        amg.as_ref().set_gamg_reuse_interpolation(false)?;
        exact
            .as_ref()
            .set_options_prefix(&format!("{prefix}zone_"))?;
        exact.as_ref().set_type("preonly")?;
        let zone_pc = exact.as_ref().pc()?;
        zone_pc.set_type("lu")?;
        zone_pc.set_factor_package("mumps")?;
        let zone = YieldZone {
            amg,
            exact,
            field: field.map(IndexSet::shared).transpose()?,
            rows: Vec::new(),
            zone: None,
            whole: false,
            zone_size: 0,
            block_size: 0,
            configured: false,
        };
        pc.set_shell(NAME, zone)
    }

    /// Collective. The next set-up's zone: the block rows of `dofs` (global dofs of the whole
    /// system, this rank's and others'; repeats allowed). `template` has the whole system's
    /// layout.
    pub fn set_zone(&mut self, template: VecRef<'_>, dofs: &[usize]) -> Result<(), PetscError> {
        let marker = template.duplicate()?;
        marker.as_ref().set_all(0.0)?;
        let idx = dofs
            .iter()
            .map(|&d| to_int(d, "yielded dof"))
            .collect::<Result<Vec<Int>, _>>()?;
        marker.as_ref().add_at(&idx, &vec![1.0; idx.len()])?;
        let yielded = |v: VecRef<'_>| {
            let first = v.first_owned()?;
            v.read(|m| {
                m.iter()
                    .enumerate()
                    .filter(|(_, &v)| v > 0.0)
                    .map(|(i, _)| first + i as Int)
                    .collect::<Vec<Int>>()
            })
        };
        self.rows = match &self.field {
            Some(field) => marker.as_ref().with_sub_vector(field, yielded)?,
            None => yielded(marker.as_ref())?,
        };
        Ok(())
    }

    /// Collective. Frees the zone's factorisation and GAMG's hierarchy (PCSHELL has no reset
    /// of its own), keeping the configuration.
    pub fn reset(&mut self) -> Result<(), PetscError> {
        self.free_zone();
        self.exact.as_ref().reset()?;
        self.amg.as_ref().reset()
    }

    fn free_zone(&mut self) {
        self.zone = None;
        self.whole = false;
    }

    /// Collective. [`ShellPreconditioner::set_up`]'s work on a freed zone.
    fn make_zone(&mut self, pc: PcRef<'_>) -> Result<(), PetscError> {
        let (a, p) = pc.operators()?;
        let (amg, exact) = (self.amg.as_ref(), self.exact.as_ref());
        if !self.configured {
            amg.set_operators(a, p)?;
            amg.set_from_options()?;
            exact.set_from_options()?;
            self.configured = true;
        }
        self.block_size = p.global_rows()?;
        let zone = IndexSet::general_like(&pc, &self.rows)?;
        self.zone_size = zone.global_size()?;
        // Where everything has yielded GAMG adds nothing to the exact solve.
        self.whole = self.zone_size > 0 && self.zone_size == self.block_size;
        if !self.whole {
            amg.set_operators(a, p)?;
            amg.set_up()?;
            pass_failure(amg, pc)?;
        }
        if self.zone_size == 0 {
            return Ok(());
        }
        let matrix = p.sub_matrix(&zone)?;
        exact.set_operators(matrix.as_ref(), matrix.as_ref())?;
        exact.set_up()?;
        let (solution, rhs) = matrix.as_ref().vectors()?;
        let residual = p.right_vector()?;
        let scatter = IndexScatter::new(residual.as_ref(), &zone, rhs.as_ref())?;
        self.zone = Some(Zone {
            rhs,
            solution,
            residual,
            scatter,
        });
        Ok(())
    }

    /// Collective. x = x + A_zz⁻¹ r on the zone's rows (`add`), or x = A_zz⁻¹ r there (the
    /// zone being every row).
    fn solve_zone(
        &self,
        pc: PcRef<'_>,
        zone: &Zone,
        r: VecRef<'_>,
        x: VecRef<'_>,
        add: bool,
    ) -> Result<(), PetscError> {
        let (rhs, solution) = (zone.rhs.as_ref(), zone.solution.as_ref());
        zone.scatter.forward(r, rhs)?;
        self.exact.as_ref().solve(rhs, solution)?;
        self.exact.as_ref().check_solve(pc, solution)?;
        zone.scatter.reverse(solution, x, add)
    }
}

/// Marks `pc` failed when its inner `amg` failed (the outer Krylov method reports
/// DIVERGED_PC_FAILED).
fn pass_failure(amg: PcRef<'_>, pc: PcRef<'_>) -> Result<(), PetscError> {
    if amg.failed()? {
        pc.set_inner_failure()?;
    }
    Ok(())
}

impl ShellPreconditioner for YieldZone {
    /// Collective. A new block: GAMG set up on it, and the zone's rows extracted and factored.
    fn set_up(&mut self, pc: PcRef<'_>) -> Result<(), PetscError> {
        // The last zone's factors go before GAMG builds its new hierarchy.
        self.free_zone();
        // A new zone is a new matrix, of another size: the factorisation starts afresh.
        self.exact.as_ref().reset()?;
        let made = self.make_zone(pc);
        if made.is_err() {
            self.free_zone();
        }
        made
    }

    /// Collective. x = GAMG(b), then the zone's rows corrected by the exact solve of the zone
    /// on the residual b − A x (multiplicative Schwarz with two subspaces: the whole block, by
    /// GAMG, and the zone, exactly).
    fn apply(&mut self, pc: PcRef<'_>, b: VecRef<'_>, x: VecRef<'_>) -> Result<(), PetscError> {
        if self.whole {
            let zone = self.zone.as_ref().ok_or_else(not_set_up)?;
            return self.solve_zone(pc, zone, b, x, false);
        }
        self.amg.as_ref().apply(b, x)?;
        pass_failure(self.amg.as_ref(), pc)?;
        let Some(zone) = &self.zone else {
            return Ok(());
        };
        let (a, _) = pc.operators()?;
        let r = zone.residual.as_ref();
        a.mult(x, r)?;
        r.aypx(-1.0, b)?;
        self.solve_zone(pc, zone, r, x, true)
    }

    fn view(&self, viewer: ViewerRef<'_>) -> Result<(), PetscError> {
        let how = if self.whole {
            "solved exactly (GAMG skipped)"
        } else {
            "solved exactly after GAMG"
        };
        let line = format!(
            "yielded zone: {} of {} rows, {how}",
            self.zone_size, self.block_size
        );
        viewer.nested(&[line], || {
            if !self.whole {
                self.amg.as_ref().view(viewer)?;
            }
            if self.zone.is_some() {
                self.exact.as_ref().view(viewer)?;
            }
            Ok(())
        })
    }
}

fn not_set_up() -> PetscError {
    PetscError {
        code: crate::petsc::error::PETSC_ERR_USER,
        message: "the yield zone was applied before its set-up".into(),
    }
}
