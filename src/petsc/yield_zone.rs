//! A displacement system at yield (PCSHELL): GAMG on the whole block (the field split's
//! displacement block, or a P2 system), then an exact solve on the rows of the yielded zone.
//! A perfectly plastic tangent has no stiffness along the flow direction at every yielded
//! Gauss point, so the block's near-kernel is as large as the yielded zone and spans it (a
//! mechanism); no smoother or aggregation sees it, and splitting the zone into blocks cuts the
//! mechanism (both measured: bench/VALIDATION.md, "The field split at yield"). The zone's own
//! factorisation captures it whole, and GAMG keeps the elastic rest. Where the soil is elastic
//! the zone is empty and this is GAMG; where it is at yield everywhere it costs a direct solve
//! of the block.

use super::error::{check, PetscError};
use super::ffi;
use super::init::cstring;
use super::matrix::to_int;
use super::vector::VecRef;
use super::Int;

/// The shell's name, which tells our shell from any other.
const NAME: &str = "yield zone (GAMG on the block, exact solve on the yielded rows)";
/// What messages call it.
const WHAT: &str = "yield zone";
/// The key under which the outer preconditioner holds the displacement block's.
const KEY: &str = "pfem_yield_zone";

/// What the shell keeps. Every handle is its own reference, released on destroy.
struct YieldZone {
    /// GAMG on the whole block (options prefix `fieldsplit_u_`, or none on a P2 system).
    amg: ffi::PC,
    /// The zone's exact solver (options prefix GAMG's and `zone_`): MUMPS LU.
    exact: ffi::KSP,
    /// The displacement field in the whole system's numbering (to find the block's rows);
    /// null when the block is the whole system.
    field: ffi::IS,
    /// This rank's yielded rows of the block (the block's numbering), for the next set-up.
    rows: Vec<Int>,
    /// The rows of the zone as set up; null while it is empty.
    zone: ffi::IS,
    zone_matrix: ffi::Mat,
    zone_rhs: ffi::Vec,
    zone_solution: ffi::Vec,
    /// The block's residual.
    residual: ffi::Vec,
    /// The zone's rows of a vector of the block (made once per set-up: a sub-vector of an
    /// arbitrary index set would build it at every application).
    scatter: ffi::VecScatter,
    /// The zone is every row: the exact solve alone is the preconditioner.
    whole: bool,
    /// Rows of the zone over all ranks, and of the block, at the last set-up.
    zone_size: Int,
    block_size: Int,
    /// The options have been read (at the first set-up).
    configured: bool,
}

impl YieldZone {
    /// What a set-up makes (null until then).
    fn made(&mut self) -> ([&mut ffi::Vec; 3], &mut ffi::Mat, &mut ffi::IS) {
        (
            [
                &mut self.zone_rhs,
                &mut self.zone_solution,
                &mut self.residual,
            ],
            &mut self.zone_matrix,
            &mut self.zone,
        )
    }
}

/// Collective. Makes `pc` (the displacement block's, `field` its rows in the whole system;
/// null: `pc` is the whole system's) the yield-zone preconditioner, its GAMG reading options
/// under `prefix`, and lets `outer` (the field split, or `pc` itself) find it.
///
/// # Safety
/// `pc` and `outer` must be live PETSc objects, `field` live or null.
pub(super) unsafe fn install(
    pc: ffi::PC,
    field: ffi::IS,
    outer: ffi::PC,
    prefix: &str,
) -> Result<(), PetscError> {
    let key = cstring(KEY)?;
    // SAFETY: the caller's objects are live; the zone's references go to the preconditioner
    // with it (`make_shell`), or are released on a failure before.
    unsafe {
        let mut comm = mpi::ffi::RSMPI_COMM_NULL;
        check(
            ffi::PetscObjectGetComm(pc as ffi::PetscObject, &mut comm),
            "PetscObjectGetComm",
        )?;
        let mut zone = YieldZone {
            amg: std::ptr::null_mut(),
            exact: std::ptr::null_mut(),
            field,
            rows: Vec::new(),
            zone: std::ptr::null_mut(),
            zone_matrix: std::ptr::null_mut(),
            zone_rhs: std::ptr::null_mut(),
            zone_solution: std::ptr::null_mut(),
            residual: std::ptr::null_mut(),
            scatter: std::ptr::null_mut(),
            whole: false,
            zone_size: 0,
            block_size: 0,
            configured: false,
        };
        if !field.is_null() {
            check(
                ffi::PetscObjectReference(field as ffi::PetscObject),
                "PetscObjectReference(field)",
            )?;
        }
        let made = check(ffi::PCCreate(comm, &mut zone.amg), "PCCreate(amg)")
            .and_then(|()| check(ffi::KSPCreate(comm, &mut zone.exact), "KSPCreate(zone)"));
        if let Err(e) = made {
            release(zone);
            return Err(e);
        }
        let raw = super::shell::make_shell(pc, zone, NAME, release, OPS)?;
        if outer != pc {
            check(
                ffi::PetscObjectCompose(
                    outer as ffi::PetscObject,
                    key.as_ptr(),
                    pc as ffi::PetscObject,
                ),
                "PetscObjectCompose(yield zone)",
            )?;
        }
        let z = &mut *raw;
        let zone_prefix = cstring(&format!("{prefix}zone_"))?;
        let prefix = cstring(prefix)?;
        check(
            ffi::PCSetOptionsPrefix(z.amg, prefix.as_ptr()),
            "PCSetOptionsPrefix(amg)",
        )?;
        let gamg = cstring("gamg")?;
        check(ffi::PCSetType(z.amg, gamg.as_ptr()), "PCSetType(gamg)")?;
        // Reused interpolation once made GAMG indefinite (as for GAMG alone, linear.rs).
        check(
            ffi::PCGAMGSetReuseInterpolation(z.amg, ffi::PetscBool_PETSC_FALSE),
            "PCGAMGSetReuseInterpolation",
        )?;
        check(
            ffi::KSPSetOptionsPrefix(z.exact, zone_prefix.as_ptr()),
            "KSPSetOptionsPrefix(zone)",
        )?;
        let preonly = cstring("preonly")?;
        check(
            ffi::KSPSetType(z.exact, preonly.as_ptr()),
            "KSPSetType(zone)",
        )?;
        let mut zone_pc: ffi::PC = std::ptr::null_mut();
        check(ffi::KSPGetPC(z.exact, &mut zone_pc), "KSPGetPC(zone)")?;
        let lu = cstring("lu")?;
        check(ffi::PCSetType(zone_pc, lu.as_ptr()), "PCSetType(zone)")?;
        let mumps = cstring("mumps")?;
        check(
            ffi::PCFactorSetMatSolverType(zone_pc, mumps.as_ptr()),
            "PCFactorSetMatSolverType(zone)",
        )
    }
}

/// The zone's callbacks.
const OPS: super::shell::ShellOps = super::shell::ShellOps {
    setup: setup_cb,
    apply: apply_cb,
    view: view_cb,
    destroy: destroy_cb,
};

/// The yield-zone preconditioner of the field split `outer`, if it has one.
///
/// # Safety
/// `outer` must be live; the PC is borrowed from it.
pub(super) unsafe fn find(outer: ffi::PC) -> Result<Option<ffi::PC>, PetscError> {
    let key = cstring(KEY)?;
    let mut found: ffi::PetscObject = std::ptr::null_mut();
    // SAFETY: as the caller promises.
    unsafe {
        if context(outer)?.is_some() {
            return Ok(Some(outer));
        }
        // A command-line `-pc_type` replaces the split; the block's PC then lingers unused.
        if !super::has_type(outer as ffi::PetscObject, "fieldsplit")? {
            return Ok(None);
        }
        check(
            ffi::PetscObjectQuery(outer as ffi::PetscObject, key.as_ptr(), &mut found),
            "PetscObjectQuery(yield zone)",
        )?;
        if found.is_null() || context(found as ffi::PC)?.is_none() {
            return Ok(None);
        }
    }
    Ok(Some(found as ffi::PC))
}

/// The zone behind `pc`, if `pc` is our shell (a command-line `-fieldsplit_u_pc_type` may
/// have made it something else).
///
/// # Safety
/// `pc` must be live; the borrow must end before the preconditioner is destroyed.
unsafe fn context<'a>(pc: ffi::PC) -> Result<Option<&'a mut YieldZone>, PetscError> {
    // SAFETY: live PC; a shell named NAME is only ever made by `install`.
    Ok(unsafe { super::shell_context(pc, NAME) }?
        .map(|raw| unsafe { &mut *(raw as *mut YieldZone) }))
}

/// Collective. The next set-up's zone: the block rows of `dofs` (global dofs of the whole
/// system, this rank's and others'; repeats allowed). `template` has the whole system's layout.
///
/// # Safety
/// `pc` must be a live yield-zone preconditioner and `template` a live vector.
pub(super) unsafe fn set_zone(
    pc: ffi::PC,
    template: VecRef<'_>,
    dofs: &[usize],
) -> Result<(), PetscError> {
    // SAFETY: as the caller promises; the marker is ours and destroyed here.
    unsafe {
        let Some(z) = context(pc)? else {
            return Err(super::shell::not_shell(WHAT));
        };
        let marker = template.duplicate()?;
        check(ffi::VecSet(marker.raw, 0.0), "VecSet")?;
        let idx = dofs
            .iter()
            .map(|&d| to_int(d, "yielded dof"))
            .collect::<Result<Vec<Int>, _>>()?;
        let ones = vec![1.0; idx.len()];
        check(
            ffi::VecSetValues(
                marker.raw,
                to_int(idx.len(), "yielded dofs")?,
                idx.as_ptr(),
                ones.as_ptr(),
                ffi::InsertMode_ADD_VALUES,
            ),
            "VecSetValues(yielded)",
        )?;
        check(ffi::VecAssemblyBegin(marker.raw), "VecAssemblyBegin")?;
        check(ffi::VecAssemblyEnd(marker.raw), "VecAssemblyEnd")?;
        let mut sub: ffi::Vec = marker.raw;
        if !z.field.is_null() {
            check(
                ffi::VecGetSubVector(marker.raw, z.field, &mut sub),
                "VecGetSubVector(field)",
            )?;
        }
        let mut first: Int = 0;
        let mut end: Int = 0;
        let read = check(
            ffi::VecGetOwnershipRange(sub, &mut first, &mut end),
            "VecGetOwnershipRange",
        )
        .and_then(|()| {
            VecRef::lent(sub).read(|m| {
                m.iter()
                    .enumerate()
                    .filter(|(_, &v)| v > 0.0)
                    .map(|(i, _)| first + i as Int)
                    .collect::<Vec<Int>>()
            })
        });
        if !z.field.is_null() {
            check(
                ffi::VecRestoreSubVector(marker.raw, z.field, &mut sub),
                "VecRestoreSubVector(field)",
            )?;
        }
        z.rows = read?;
        Ok(())
    }
}

/// Drops every reference the zone holds.
///
/// # Safety
/// The handles must be the zone's own references (or null).
unsafe fn release(mut z: YieldZone) {
    // SAFETY: as the caller promises; destroying a null handle is a no-op in PETSc.
    unsafe {
        free_zone(&mut z);
        ffi::PCDestroy(&mut z.amg);
        ffi::KSPDestroy(&mut z.exact);
        ffi::ISDestroy(&mut z.field);
    }
}

/// Frees what the set-ups made.
///
/// # Safety
/// The handles must be the zone's own references (or null).
unsafe fn free_zone(z: &mut YieldZone) {
    // SAFETY: as the caller promises.
    unsafe {
        let (vectors, matrix, is) = z.made();
        for v in vectors {
            ffi::VecDestroy(v);
        }
        ffi::MatDestroy(matrix);
        ffi::ISDestroy(is);
        ffi::VecScatterDestroy(&mut z.scatter);
        z.whole = false;
    }
}

/// Collective. Frees the zone's factorisation and GAMG's hierarchy (PCSHELL has no reset of
/// its own), keeping the configuration.
///
/// # Safety
/// `pc` must be live.
pub(super) unsafe fn reset(pc: ffi::PC) -> Result<(), PetscError> {
    // SAFETY: as the caller promises.
    unsafe {
        if let Some(z) = context(pc)? {
            free_zone(z);
            check(ffi::KSPReset(z.exact), "KSPReset(zone)")?;
            check(ffi::PCReset(z.amg), "PCReset(amg)")?;
        }
    }
    Ok(())
}

/// Runs `f` on the zone behind `pc`; an error or panic is printed on this rank and becomes
/// PETSc's user-error code.
unsafe fn with_zone(
    pc: ffi::PC,
    f: impl FnOnce(&mut YieldZone) -> Result<(), PetscError>,
) -> ffi::PetscErrorCode {
    // SAFETY: PETSc calls back with the live shell `install` made.
    unsafe { super::shell::with_shell(pc, NAME, WHAT, f) }
}

/// The operators (Amat, Pmat) of `pc`.
unsafe fn operators(pc: ffi::PC) -> Result<(ffi::Mat, ffi::Mat), PetscError> {
    let (mut a, mut p): (ffi::Mat, ffi::Mat) = (std::ptr::null_mut(), std::ptr::null_mut());
    // SAFETY: live PC inside its own callback.
    check(
        unsafe { ffi::PCGetOperators(pc, &mut a, &mut p) },
        "PCGetOperators",
    )?;
    Ok((a, p))
}

/// Collective. A new block: GAMG set up on it, and the zone's rows extracted and factored.
unsafe extern "C" fn setup_cb(pc: ffi::PC) -> ffi::PetscErrorCode {
    // SAFETY: the operators and the zone's objects are live while the preconditioner is.
    unsafe {
        with_zone(pc, |z| {
            // The last zone's factors go before GAMG builds its new hierarchy.
            free_zone(z);
            // A new zone is a new matrix, of another size: the factorisation starts afresh.
            check(ffi::KSPReset(z.exact), "KSPReset(zone)")?;
            let made = set_up(pc, z);
            if made.is_err() {
                free_zone(z);
            }
            made
        })
    }
}

/// Collective. [`setup_cb`]'s work on a freed zone.
///
/// # Safety
/// `pc` must be the live shell whose zone `z` is.
unsafe fn set_up(pc: ffi::PC, z: &mut YieldZone) -> Result<(), PetscError> {
    // SAFETY: as the caller promises; every handle made here is the zone's own.
    unsafe {
        let (a, p) = operators(pc)?;
        if !z.configured {
            check(ffi::PCSetOperators(z.amg, a, p), "PCSetOperators(amg)")?;
            check(ffi::PCSetFromOptions(z.amg), "PCSetFromOptions(amg)")
                .map_err(PetscError::naming_user_options)?;
            check(ffi::KSPSetFromOptions(z.exact), "KSPSetFromOptions(zone)")
                .map_err(PetscError::naming_user_options)?;
            z.configured = true;
        }
        check(
            ffi::MatGetSize(p, &mut z.block_size, std::ptr::null_mut()),
            "MatGetSize",
        )?;
        let mut comm = mpi::ffi::RSMPI_COMM_NULL;
        check(
            ffi::PetscObjectGetComm(pc as ffi::PetscObject, &mut comm),
            "PetscObjectGetComm",
        )?;
        check(
            ffi::ISCreateGeneral(
                comm,
                to_int(z.rows.len(), "zone rows")?,
                z.rows.as_ptr(),
                ffi::PetscCopyMode_PETSC_COPY_VALUES,
                &mut z.zone,
            ),
            "ISCreateGeneral(zone)",
        )?;
        check(ffi::ISGetSize(z.zone, &mut z.zone_size), "ISGetSize(zone)")?;
        // Where everything has yielded GAMG adds nothing to the exact solve.
        z.whole = z.zone_size > 0 && z.zone_size == z.block_size;
        if !z.whole {
            check(ffi::PCSetOperators(z.amg, a, p), "PCSetOperators(amg)")?;
            check(ffi::PCSetUp(z.amg), "PCSetUp(amg)")?;
            pass_failure(z.amg, pc)?;
        }
        if z.zone_size == 0 {
            ffi::ISDestroy(&mut z.zone);
            return Ok(());
        }
        check(
            ffi::MatCreateSubMatrix(
                p,
                z.zone,
                z.zone,
                ffi::MatReuse_MAT_INITIAL_MATRIX,
                &mut z.zone_matrix,
            ),
            "MatCreateSubMatrix(zone)",
        )?;
        check(
            ffi::KSPSetOperators(z.exact, z.zone_matrix, z.zone_matrix),
            "KSPSetOperators(zone)",
        )?;
        check(ffi::KSPSetUp(z.exact), "KSPSetUp(zone)")?;
        check(
            ffi::MatCreateVecs(z.zone_matrix, &mut z.zone_solution, &mut z.zone_rhs),
            "MatCreateVecs(zone)",
        )?;
        check(
            ffi::MatCreateVecs(p, &mut z.residual, std::ptr::null_mut()),
            "MatCreateVecs",
        )?;
        check(
            ffi::VecScatterCreate(
                z.residual,
                z.zone,
                z.zone_rhs,
                std::ptr::null_mut(),
                &mut z.scatter,
            ),
            "VecScatterCreate(zone)",
        )
    }
}

/// Marks `pc` failed (PETSc's `PC_SUBPC_ERROR`, which the outer Krylov method reports as
/// `DIVERGED_PC_FAILED`) when its inner `amg` failed.
///
/// # Safety
/// Both must be live.
unsafe fn pass_failure(amg: ffi::PC, pc: ffi::PC) -> Result<(), PetscError> {
    let mut reason: ffi::PCFailedReason = ffi::PCFailedReason_PC_NOERROR;
    // SAFETY: as the caller promises.
    unsafe {
        check(
            ffi::PCGetFailedReason(amg, &mut reason),
            "PCGetFailedReason(amg)",
        )?;
        if reason != ffi::PCFailedReason_PC_NOERROR {
            check(
                ffi::PCSetFailedReason(pc, ffi::PCFailedReason_PC_SUBPC_ERROR),
                "PCSetFailedReason",
            )?;
        }
    }
    Ok(())
}

/// Collective. x = GAMG(b), then the zone's rows corrected by the exact solve of the zone on
/// the residual b − A x (multiplicative Schwarz with two subspaces: the whole block, by GAMG,
/// and the zone, exactly).
unsafe extern "C" fn apply_cb(pc: ffi::PC, b: ffi::Vec, x: ffi::Vec) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps b and x alive during the callback; the zone's objects are live.
    unsafe {
        with_zone(pc, |z| {
            if z.whole {
                return solve_zone(pc, z, b, x, ffi::InsertMode_INSERT_VALUES);
            }
            check(ffi::PCApply(z.amg, b, x), "PCApply(amg)")?;
            pass_failure(z.amg, pc)?;
            if z.zone.is_null() {
                return Ok(());
            }
            let (a, _) = operators(pc)?;
            let r = z.residual;
            check(ffi::MatMult(a, x, r), "MatMult")?;
            check(ffi::VecAYPX(r, -1.0, b), "VecAYPX")?;
            solve_zone(pc, z, r, x, ffi::InsertMode_ADD_VALUES)
        })
    }
}

/// Collective. x = x + A_zz⁻¹ r on the zone's rows (`ADD_VALUES`), or x = A_zz⁻¹ r there
/// (`INSERT_VALUES`, the zone being every row).
///
/// # Safety
/// `pc` must be the live shell whose set-up zone `z` is; `r`, `x` live vectors of the block.
unsafe fn solve_zone(
    pc: ffi::PC,
    z: &YieldZone,
    r: ffi::Vec,
    x: ffi::Vec,
    mode: ffi::InsertMode,
) -> Result<(), PetscError> {
    // SAFETY: as the caller promises.
    unsafe {
        let forward = ffi::ScatterMode_SCATTER_FORWARD;
        let reverse = ffi::ScatterMode_SCATTER_REVERSE;
        let insert = ffi::InsertMode_INSERT_VALUES;
        check(
            ffi::VecScatterBegin(z.scatter, r, z.zone_rhs, insert, forward),
            "VecScatterBegin(zone)",
        )?;
        check(
            ffi::VecScatterEnd(z.scatter, r, z.zone_rhs, insert, forward),
            "VecScatterEnd(zone)",
        )?;
        check(
            ffi::KSPSolve(z.exact, z.zone_rhs, z.zone_solution),
            "KSPSolve(zone)",
        )?;
        check(
            ffi::KSPCheckSolve(z.exact, pc, z.zone_solution),
            "KSPCheckSolve(zone)",
        )?;
        check(
            ffi::VecScatterBegin(z.scatter, z.zone_solution, x, mode, reverse),
            "VecScatterBegin(zone back)",
        )?;
        check(
            ffi::VecScatterEnd(z.scatter, z.zone_solution, x, mode, reverse),
            "VecScatterEnd(zone back)",
        )
    }
}

unsafe extern "C" fn view_cb(pc: ffi::PC, viewer: ffi::PetscViewer) -> ffi::PetscErrorCode {
    // SAFETY: PETSc keeps the viewer alive during the callback; the inner solvers are live.
    unsafe {
        with_zone(pc, |z| {
            let how = if z.whole {
                "solved exactly (GAMG skipped)"
            } else {
                "solved exactly after GAMG"
            };
            let line = format!(
                "yielded zone: {} of {} rows, {how}",
                z.zone_size, z.block_size
            );
            super::shell::view_nested(viewer, &[line], || {
                if !z.whole {
                    check(ffi::PCView(z.amg, viewer), "PCView(amg)")?;
                }
                if !z.zone.is_null() {
                    check(ffi::KSPView(z.exact, viewer), "KSPView(zone)")?;
                }
                Ok(())
            })
        })
    }
}

unsafe extern "C" fn destroy_cb(pc: ffi::PC) -> ffi::PetscErrorCode {
    // SAFETY: the context is the Box `install` leaked.
    unsafe { super::shell::reclaim::<YieldZone>(pc, release) }
}
