//! The recipe of each [`LinearPath`]: the Krylov method and preconditioner it sets on
//! Newton's linear solver. Everything set here is a default: PETSc options on the command line
//! override it, because `SNESSetFromOptions` runs after (and options that inner solvers read at
//! their set-up go to the options database as defaults, where the command line wins).

use super::two_level::TwoLevel;
use super::yield_zone::YieldZone;
use crate::petsc::ksp::{Norm, Side};
use crate::petsc::options::set_default;
use crate::petsc::{IndexSet, Ksp, KspRef, Mat, Pc, PetscError};
use crate::solve::linear_path::{Cycle, Factor, Krylov, LinearPath};

/// GAMG cycles per coarse solve of the p-multigrid.
const COARSE_CYCLES: usize = 2;
/// Krylov iterations before a linear solve counts as failed (Newton then diverges and the
/// step is cut).
const MAX_LINEAR_IT: usize = 1000;
/// GMRES restart: long enough that the AMG-preconditioned solves here do not restart.
const RESTART: usize = 200;

/// The matrices and fields a path works with, made by the caller for this increment.
pub enum Parts<'a> {
    None,
    /// The p-multigrid's P1 → P2 interpolation (a shell operator) and coarse operator (the
    /// Galerkin product of the element tangents that every Jacobian assembles, with its own
    /// rigid-body near-null space).
    PMultigrid {
        interpolation: &'a Mat,
        coarse: &'a Mat,
    },
    /// The field split's fields (the displacements' index set carries the rigid-body
    /// near-null space) and the Schur complement's preconditioner, the pressure mass matrix
    /// scaled by −1/G (spectrally equivalent to the Schur complement of a nearly
    /// incompressible solid; a Jacobi sweep inverts it well enough).
    FieldSplit {
        displacement: &'a IndexSet,
        pressure: &'a IndexSet,
        pressure_mass: &'a Mat,
    },
}

/// Collective. Sets `path` on `ksp` (Newton's linear solver) with `parts`. Returns the yield
/// zone's preconditioner where the path has one, for the hooks
/// ([`super::hooks::Hooks`]) to give it every Jacobian's yielded rows.
pub fn configure(
    ksp: KspRef<'_>,
    path: &LinearPath,
    parts: Parts<'_>,
) -> Result<Option<Pc>, PetscError> {
    let pc = ksp.pc()?;
    match (path, parts) {
        (LinearPath::Direct { factor, reuse }, _) => {
            match reuse {
                // GCR applies the preconditioner once per iteration (right-preconditioned
                // GMRES once more per solve, for the solution): a fresh factorisation costs
                // one triangular solve, as with `preonly`.
                Some(r) => {
                    ksp.set_type("gcr")?;
                    tolerances(ksp, r.rtol)?;
                }
                None => ksp.set_type("preonly")?,
            }
            pc.set_type(match factor {
                Factor::Cholesky => "cholesky",
                Factor::Lu => "lu",
            })?;
            // MUMPS here has neither METIS nor SCOTCH (ICNTL(7) = 5 or 3 fall back to PORD);
            // of the orderings it has, approximate minimum fill gave the smallest factors on
            // the cantilever at h = 1/32: LU 9.8 M entries and 0.95 GFlop against PORD's
            // 10.6 M and 1.14 GFlop (AMD, QAMD: 11.3 M, 1.51 GFlop), LDLᵀ 5.0 M against 5.3 M.
            set_default("-mat_mumps_icntl_7", "2")?;
            // No scaling: MUMPS's automatic choice (ICNTL(8) = 7 here) computes a row and
            // column scaling at every numeric factorisation, and our rows are already of one
            // size (a constrained row takes the mean free diagonal, a contact row E/h). The
            // rigid-body built-ins run 10-18 % faster with the same Newton iterations and
            // histories to 2e-12 (bench/VALIDATION.md, seventeenth session).
            set_default("-mat_mumps_icntl_8", "0")?;
            pc.set_factor_package("mumps")?;
            Ok(None)
        }
        (LinearPath::Amg { krylov }, _) => {
            krylov_method(ksp, *krylov, path.rtol())?;
            pc.set_type("gamg")?;
            // Reused GAMG interpolation once gave CG an indefinite preconditioner on the
            // second Newton iteration (DIVERGED_INDEFINITE_PC, PETSc 3.18).
            pc.set_gamg_reuse_interpolation(false)?;
            Ok(None)
        }
        (LinearPath::YieldZone, _) => {
            // The pair is not a symmetric preconditioner.
            krylov_method(ksp, Krylov::Gmres, path.rtol())?;
            YieldZone::install(pc, None, "")?;
            Ok(Some(pc.shared()?))
        }
        (
            LinearPath::PMultigrid {
                krylov,
                damped,
                cycle,
                ..
            },
            Parts::PMultigrid {
                interpolation,
                coarse,
            },
        ) => {
            krylov_method(ksp, *krylov, path.rtol())?;
            let symmetric = *krylov == Krylov::Cg;
            if symmetric {
                // The coarse GAMG's Chebyshev smoothers estimate their eigenvalues by CG:
                // GMRES's vectors sat under the memory peak (heaptrack, 30 MB of 886 at
                // h = 1/128 on 1 rank; the same iteration counts).
                set_default("-mg_coarse_mg_levels_esteig_ksp_type", "cg")?;
            }
            if *cycle == Cycle::TwoLevel {
                let coarse_ksp = Ksp::create_like(&ksp)?;
                // Its options read as PCMG's would be.
                coarse_ksp.as_ref().set_options_prefix("mg_coarse_")?;
                configure_coarse(coarse_ksp.as_ref(), coarse)?;
                TwoLevel::install(pc, interpolation.as_ref(), coarse_ksp)?;
                return Ok(None);
            }
            pc.set_type("mg")?;
            pc.set_two_levels(interpolation.as_ref())?;
            configure_coarse(pc.mg_coarse_solver()?, coarse)?;
            // Point Jacobi on P2 (PCMG's default smoother is Chebyshev with SOR), one sweep
            // before and after (two took 30 % longer for 3 % fewer iterations). Where the
            // tangent is symmetric, Richardson damped by the Jacobian's own spectral bound
            // (the hooks set the damping after every Jacobian: `super::hooks`,
            // `crate::solve::smoother`); elsewhere Chebyshev, its eigenvalues estimated by
            // GMRES (by CG if the user asks for Chebyshev on a symmetric tangent: GMRES keeps
            // 30 vectors). By default that damped sweep runs in `TwoLevel`'s cycle, not here.
            set_default("-mg_levels_pc_type", "jacobi")?;
            set_default("-mg_levels_ksp_max_it", "1")?;
            if *damped {
                pc.mg_smoother(1)?.set_type("richardson")?;
            }
            if symmetric {
                set_default("-mg_levels_esteig_ksp_type", "cg")?;
            }
            Ok(None)
        }
        (
            LinearPath::FieldSplit { yield_zone },
            Parts::FieldSplit {
                displacement,
                pressure,
                pressure_mass,
            },
        ) => {
            krylov_method(ksp, Krylov::Gmres, path.rtol())?;
            pc.set_type("fieldsplit")?;
            pc.set_field("u", displacement)?;
            pc.set_field("p", pressure)?;
            // The split's inner solvers exist from here, but the Schur type hands them out
            // only once set up: the displacement block's is taken now.
            let zone = if *yield_zone {
                let block = pc.first_field_solver()?.pc()?;
                YieldZone::install(block, Some(displacement), "fieldsplit_u_")?;
                Some(block.shared()?)
            } else {
                None
            };
            pc.set_upper_schur(pressure_mass.as_ref())?;
            // The split's inner solvers read their options only when the PC is set up, so
            // their defaults go to the options database, where the command line wins.
            if !*yield_zone {
                set_default("-fieldsplit_u_pc_type", "gamg")?;
            }
            for (name, value) in [
                ("-fieldsplit_u_ksp_type", "preonly"),
                ("-fieldsplit_u_pc_gamg_reuse_interpolation", "false"),
                ("-fieldsplit_p_ksp_type", "preonly"),
                ("-fieldsplit_p_pc_type", "jacobi"),
            ] {
                set_default(name, value)?;
            }
            Ok(zone)
        }
        (path, _) => Err(PetscError {
            code: crate::petsc::error::PETSC_ERR_USER,
            message: format!("the linear path {path} was given without its matrices"),
        }),
    }
}

/// The p-multigrid's coarse solver: two GAMG cycles on the coarse operator `coarse`
/// (Richardson, a fixed linear operator, so CG still sees a symmetric preconditioner). GAMG is
/// the weak part of the pair on slender bodies: cantilever h = 1/64, 5 steps, 2 ranks, 688 CG
/// iterations against 904 with one cycle, and with an exact coarse solve 101, so the fine
/// smoothing is not what limits it.
fn configure_coarse(coarse_ksp: KspRef<'_>, coarse: &Mat) -> Result<(), PetscError> {
    coarse_ksp.set_operators(coarse.as_ref(), coarse.as_ref())?;
    coarse_ksp.set_type("richardson")?;
    coarse_ksp.set_tolerances(0.0, 0.0, Some(1e30), COARSE_CYCLES)?;
    coarse_ksp.set_norm_type(Norm::None)?;
    let coarse_pc = coarse_ksp.pc()?;
    coarse_pc.set_type("gamg")?;
    // The coarse operator is the Galerkin product of each Newton iterate's tangent: GAMG
    // aggregates once per increment and only redoes its products on the next iterations.
    // Its smoothers then estimate their eigenvalues afresh instead of keeping the first
    // aggregation's (a stale bound is how reused GAMG became indefinite: CG stopped with
    // DIVERGED_INDEFINITE_PC on the second Newton iteration).
    coarse_pc.set_gamg_reuse_interpolation(true)?;
    coarse_pc.set_gamg_use_sa_est_eig(false)
}

/// CG, left-preconditioned (as CG must be) but converged on the unpreconditioned residual,
/// so that `rtol` means what it means for GMRES; or GMRES with right preconditioning, so that
/// the tolerance applies to the true residual.
fn krylov_method(ksp: KspRef<'_>, krylov: Krylov, rtol: f64) -> Result<(), PetscError> {
    match krylov {
        Krylov::Cg => {
            ksp.set_type("cg")?;
            ksp.set_pc_side(Side::Left)?;
            ksp.set_norm_type(Norm::Unpreconditioned)?;
        }
        Krylov::Gmres => {
            ksp.set_type("gmres")?;
            ksp.set_gmres_restart(RESTART)?;
            ksp.set_pc_side(Side::Right)?;
        }
    }
    tolerances(ksp, rtol)
}

/// `rtol` relative to the first residual, no absolute floor, at most [`MAX_LINEAR_IT`]
/// iterations.
fn tolerances(ksp: KspRef<'_>, rtol: f64) -> Result<(), PetscError> {
    ksp.set_tolerances(rtol, 1e-50, None, MAX_LINEAR_IT)
}
