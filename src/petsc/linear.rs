//! The linear solver inside Newton: a direct LU factorisation, or a Krylov method with algebraic
//! multigrid (displacement problems) or with a Schur-complement field split (mixed u–p problems).
//! Everything set here is a default: PETSc options on the command line override it, because
//! `SNESSetFromOptions` runs after.

use super::error::{check, PetscError};
use super::ffi;
use super::index_set::IndexSet;
use super::init::cstring;
use super::matrix::{to_int, Mat};
use super::Scalar;

/// GAMG cycles per coarse solve of the p-multigrid.
const COARSE_CYCLES: ffi::PetscInt = 2;

/// How Newton's linear systems are solved.
pub enum LinearSolver<'a> {
    /// MUMPS LU: robust for any system, cost and memory superlinear in its size. With `reuse`,
    /// the LU factors of one Newton iteration precondition GCR on the next iterations' exact
    /// tangents while Newton converges fast ([`FactorReuse`]); without, every Newton iteration
    /// factors its tangent and solves with it alone (`preonly`). With `symmetric` (the caller
    /// knows the tangent is symmetric), MUMPS factors LDLᵀ from the upper triangle: half the
    /// factor entries and flops of LU (cantilever h = 1/32: 5.3 M entries against 10.6 M).
    Direct {
        reuse: Option<FactorReuse>,
        symmetric: bool,
    },
    /// Right-preconditioned GMRES with GAMG, for the displacement (P2) system: the matrix must
    /// carry block size 2 and the rigid-body near-null space. With `symmetric` (the caller
    /// knows the tangent is symmetric) conjugate gradients instead, with the same tolerance on
    /// the true residual: GMRES keeps one vector per iteration (8 doubles per particle each)
    /// and the solves take 35 and more iterations, where CG keeps four. Measured on the
    /// cantilever at h = 1/128 (165 k particles, 2 ranks, one step): peak RSS 1490 MB per rank
    /// with GMRES, 1255 MB with CG, 182 Krylov iterations against 173, the tracked
    /// displacements equal to 1e-15.
    ///
    /// With `yield_zone` (a plastic tangent; [`yield_zone_from_options`]) GAMG is followed by
    /// an exact solve on the rows of the yielded triangles ([`super::yield_zone`]); the Krylov
    /// method is then GMRES (the pair is not a symmetric preconditioner).
    Amg {
        rtol: Scalar,
        symmetric: bool,
        yield_zone: bool,
    },
    /// As [`LinearSolver::Amg`], preconditioned by a two-level p-multigrid instead of GAMG on
    /// the P2 system: one Jacobi sweep before and after on P2 (Richardson damped by the
    /// Jacobian's spectral bound where the tangent is symmetric,
    /// [`LinearSolver::damps_jacobi_smoother`]; Chebyshev elsewhere), `interpolation` (a shell
    /// operator) from P1 on the particles, and two GAMG cycles (Richardson) on `coarse`, the
    /// Galerkin product of the element tangents that every Jacobian assembles (with its own
    /// rigid-body near-null space). GAMG then sets up on a quarter of the unknowns and on a far
    /// sparser matrix, which is where GAMG on P2 spends its memory.
    PMultigrid {
        rtol: Scalar,
        symmetric: bool,
        interpolation: &'a Mat,
        coarse: &'a Mat,
    },
    /// Right-preconditioned GMRES with an upper block-triangular Schur-complement field split,
    /// for the mixed P2–P1 saddle point: on the displacement block GAMG (its index set carries
    /// the rigid-body near-null space) followed by an exact solve on the rows of the yielded
    /// triangles ([`super::yield_zone`]; GAMG alone cannot hold a yielded block), and on the
    /// Schur complement `pressure_mass`, the pressure mass matrix scaled by −1/G (spectrally
    /// equivalent to the Schur complement of a nearly incompressible solid; a Jacobi sweep
    /// inverts it well enough).
    Schur {
        rtol: Scalar,
        /// The displacement block's preconditioner is the yield zone (a plastic tangent).
        yield_zone: bool,
        displacement: &'a IndexSet,
        pressure: &'a IndexSet,
        pressure_mass: &'a Mat,
    },
}

/// Asks GAMG to form its Galerkin products (P^T A P) all at once, holding no intermediate
/// product: for several ranks where memory and not time bounds the run. Measured on the
/// cantilever, 2 ranks, iterative, one step (Newton and CG iterations the same with either):
/// peak RSS summed over the ranks at h = 1/64 (41 665 particles) 684 → 499 MB, at 1/128
/// (165 249) 2 461 → 1 727 MB, about what one rank needs (456 and 1 558 MB); at 1.03 M
/// particles 10 255 MB (about 15 GB expected without). The price is time: the products took
/// 19–22 s instead of 3.0–3.7 s at 1/64, 234 s of the 1.03 M step's 502 s of solve. A
/// process option, read when a solver is set up: once a run has set it, it keeps it, and the
/// command line wins (`-matptap_via`). Only MPI matrices know the algorithm: never call it on
/// one rank.
pub fn prefer_lean_galerkin_products() -> Result<(), PetscError> {
    default_option("-matptap_via", "allatonce")
}

/// When a direct factorisation is kept for the next Newton iteration. A MUMPS triangular solve
/// costs about a ninth of a numeric factorisation at h = 1/64 on the cantilever (a seventh at
/// 1/32), so a kept factorisation pays only where the tangent barely changes: in Newton's fast
/// phase. The factors are kept while the last Newton iteration cut the residual by `contraction`
/// or more and its linear solve took at most `max_krylov` Krylov iterations; the first
/// iteration of every Newton solve factors afresh. The linear solves stay tight (`rtol`), so
/// Newton's iterates are exact Newton's to that tolerance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorReuse {
    pub contraction: f64,
    pub max_krylov: usize,
    pub rtol: Scalar,
}

impl FactorReuse {
    /// The defaults, or none when the PETSc option `-pfem_lu_reuse false` (or `0`) is given.
    pub fn from_options(default_on: bool) -> Result<Option<FactorReuse>, PetscError> {
        let on = bool_option("-pfem_lu_reuse", default_on)?;
        if !on {
            return Ok(None);
        }
        Ok(Some(FactorReuse {
            contraction: real_option("-pfem_lu_reuse_contraction", REUSE_CONTRACTION)?,
            max_krylov: real_option("-pfem_lu_reuse_max_krylov", REUSE_MAX_KRYLOV as f64)? as usize,
            rtol: real_option("-pfem_lu_reuse_rtol", REUSE_RTOL)?,
        }))
    }
}

/// The PETSc option `name` as a real number, or `default`.
fn real_option(name: &str, default: f64) -> Result<f64, PetscError> {
    let n = cstring(name)?;
    let mut value = default;
    let mut given = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: nul-terminated name; the global options database is live.
    unsafe {
        check(
            ffi::PetscOptionsGetReal(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                &mut value,
                &mut given,
            ),
            "PetscOptionsGetReal",
        )?;
    }
    Ok(value)
}

/// Whether the iterative P2 path uses the two-level p-multigrid ([`LinearSolver::PMultigrid`]):
/// yes unless the PETSc option `-pfem_pmg false` (or `0`) asks for GAMG on the P2 system, or
/// the command line names its own preconditioner (`-pc_type`), which then replaces GAMG: the
/// p-multigrid's tangent is BAIJ or SBAIJ, which GAMG cannot coarsen.
pub fn p_multigrid_from_options() -> Result<bool, PetscError> {
    Ok(bool_option("-pfem_pmg", true)? && option_string("-pc_type")?.is_none())
}

/// Whether the p-multigrid's smoother works on a symmetric tangent stored by its upper
/// triangle (SBAIJ): its default, point Jacobi, does; SOR and ILU, which a user may name with
/// `-mg_levels_pc_type`, do not ("SSOR for block size > 1 is not yet implemented"), and get the
/// whole tangent (BAIJ).
pub fn upper_triangle_smoother_from_options() -> Result<bool, PetscError> {
    Ok(option_string("-mg_levels_pc_type")?.is_none_or(|pc| pc == "jacobi"))
}

/// The PETSc option `name` as a boolean (`true`/`false`, `1`/`0`, ...), or `default`.
pub(super) fn bool_option(name: &str, default: bool) -> Result<bool, PetscError> {
    let n = cstring(name)?;
    let mut on = if default {
        ffi::PetscBool_PETSC_TRUE
    } else {
        ffi::PetscBool_PETSC_FALSE
    };
    let mut given = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: nul-terminated name; the global options database is live.
    unsafe {
        check(
            ffi::PetscOptionsGetBool(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                &mut on,
                &mut given,
            ),
            "PetscOptionsGetBool",
        )?;
    }
    Ok(on == ffi::PetscBool_PETSC_TRUE)
}

const REUSE_CONTRACTION: f64 = 0.1;
const REUSE_MAX_KRYLOV: usize = 4;
const REUSE_RTOL: f64 = 1e-10;

/// Krylov iterations before a linear solve counts as failed (Newton then diverges and the
/// step is cut).
const MAX_LINEAR_IT: usize = 1000;
/// The loosest Eisenstat–Walker tolerance ([`LinearSolver::inexact_newton_cap`]).
const INEXACT_NEWTON_CAP: Scalar = 1e-2;
/// GMRES restart: long enough that the AMG-preconditioned solves here do not restart.
const RESTART: usize = 200;

impl LinearSolver<'_> {
    /// Newton iterations one preconditioner serves (`SNESSetLagPreconditioner`; it is built
    /// afresh at the start of every Newton solve). GAMG's set-up is a third of an iterative
    /// solve on the cantilever, and the tangent of one Newton iteration preconditions the next
    /// well: measured at h = 1/16 (2 steps), lag 2 took 680 Krylov iterations instead of 651
    /// and 3.3-4.6 s of CPU instead of 5.3-6.1 s (elastic). The direct and field-split paths rebuild
    /// every iteration (a lagged LU is a different Newton method; a lagged split misses the
    /// plastic tangent's changes). The p-multigrid rebuilds every iteration: its levels set
    /// themselves up again on first use whenever their operators change (the fine smoother's
    /// eigenvalue estimate and diagonal, the coarse GAMG's products), which they do at every
    /// Jacobian, so a lag changed nothing (cantilever h = 1/32, 5 steps, step 1: the same 16,
    /// 15, 20, 27, 32, 31, 31, 31 CG iterations with lag 1, 2 and 3).
    pub fn preconditioner_lag(&self) -> usize {
        match self {
            // The yield zone follows the plastic tangent: a stale one cut the P2 block's first
            // step (block-compression, `solver.element = "p2"`: 13 Newton iterations and a cut
            // with lag 2, the direct path's 11 with lag 1).
            LinearSolver::Amg {
                yield_zone: true, ..
            } => 1,
            LinearSolver::Amg { .. } => 2,
            LinearSolver::PMultigrid { .. }
            | LinearSolver::Direct { .. }
            | LinearSolver::Schur { .. } => 1,
        }
    }

    /// The loosest relative tolerance Newton may give this linear solver, or `None` for a
    /// solve to its own tolerance every iteration. The p-multigrid follows Eisenstat and
    /// Walker: a Newton iterate far from the root needs only a rough direction, and PETSc's
    /// rule (`SNESKSPSetUseEW`, its default version 2: the last residual reduction to the power
    /// (1 + √5)/2) tightens the tolerance as the residual falls. PETSc's own cap (0.9) let the
    /// cantilever wander off (68 Newton iterations instead of 35); capped at 1e-2 the 5-step
    /// cantilever at h = 1/64 (2 ranks) keeps its 35 Newton iterations and takes 394 CG
    /// iterations instead of 689, 17.96–18.23 s instead of 22.53 s, the tracked displacements
    /// equal to 4e-14 (0.1 took 38 Newton and 361 CG, 0.05 37 and 381: no faster for the
    /// risk). GAMG on P2 is a weaker preconditioner, with which the same rule cost Newton
    /// iterations (the 10-step cantilever at h = 0.25: 24 against 22), and is left tight, as
    /// are the direct and field-split paths. `-snes_ksp_ew false` restores tight solves.
    pub fn inexact_newton_cap(&self) -> Option<Scalar> {
        match self {
            LinearSolver::PMultigrid { .. } => Some(INEXACT_NEWTON_CAP),
            LinearSolver::Amg { .. } | LinearSolver::Direct { .. } | LinearSolver::Schur { .. } => {
                None
            }
        }
    }

    /// Whether the p-multigrid runs as [`super::two_level`]'s cycle: with the damped
    /// Richardson–Jacobi smoother ([`Self::damps_jacobi_smoother`]) and no command-line option
    /// of PCMG's own cycle (its type, cycles, logging, Galerkin products or sweeps), which the
    /// cycle would not honour; otherwise PCMG runs the same two levels.
    pub(crate) fn two_level_cycle(&self) -> Result<bool, PetscError> {
        if !self.damps_jacobi_smoother()? {
            return Ok(false);
        }
        for name in [
            "-pc_mg_type",
            "-pc_mg_cycle_type",
            "-pc_mg_multiplicative_cycles",
            "-pc_mg_galerkin",
            "-pc_mg_log",
            "-pc_mg_smoothup",
            "-pc_mg_smoothdown",
        ] {
            if option_string(name)?.is_some() {
                return Ok(false);
            }
        }
        for name in ["-mg_levels_ksp_max_it", "-mg_levels_1_ksp_max_it"] {
            if option_string(name)?.is_some_and(|sweeps| sweeps != "1") {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Whether the fine level's smoother is Richardson–Jacobi damped by the Jacobian's
    /// spectral bound ([`crate::solve::smoother`]): on the p-multigrid with a symmetric
    /// tangent, unless the command line names the smoother, its preconditioner or its damping
    /// (`-mg_levels_ksp_type`, `-mg_levels_pc_type` other than jacobi,
    /// `-mg_levels_ksp_richardson_scale`, `-mg_levels_pc_jacobi_type`, or the same with
    /// `mg_levels_1_`; `-pc_mg_distinct_smoothup`, `-pc_mg_levels`). Against Chebyshev
    /// with its eigenvalue estimate, this drops six vectors of the fine level and the
    /// estimate's ten matrix products per Newton iteration.
    pub fn damps_jacobi_smoother(&self) -> Result<bool, PetscError> {
        let LinearSolver::PMultigrid { symmetric, .. } = self else {
            return Ok(false);
        };
        if !*symmetric {
            return Ok(false);
        }
        // A distinct up-smoother, more levels or another Jacobi diagonal would not be the
        // smoother the bound describes.
        for name in ["-pc_mg_distinct_smoothup", "-pc_mg_levels"] {
            if option_string(name)?.is_some() {
                return Ok(false);
            }
        }
        for prefix in ["-mg_levels_", "-mg_levels_1_"] {
            for name in [
                "ksp_type",
                "ksp_richardson_scale",
                "ksp_richardson_self_scale",
                "pc_jacobi_type",
                "pc_jacobi_abs",
            ] {
                if option_string(&format!("{prefix}{name}"))?.is_some() {
                    return Ok(false);
                }
            }
            if option_string(&format!("{prefix}pc_type"))?.is_some_and(|pc| pc != "jacobi") {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Collective. Configures `ksp` (borrowed from a SNES).
    pub(crate) fn configure(&self, ksp: ffi::KSP) -> Result<(), PetscError> {
        let mut pc: ffi::PC = std::ptr::null_mut();
        // SAFETY: `ksp` is the live KSP of a SNES we own; the PC is borrowed from it. Index
        // sets and matrices handed to the PC are referenced by PETSc, not taken over.
        unsafe {
            check(ffi::KSPGetPC(ksp, &mut pc), "KSPGetPC")?;
            match self {
                LinearSolver::Direct { reuse, symmetric } => {
                    match reuse {
                        // GCR applies the preconditioner once per iteration (right-preconditioned
                        // GMRES once more per solve, for the solution): a fresh factorisation
                        // costs one triangular solve, as with `preonly`.
                        Some(r) => {
                            set_ksp_type(ksp, "gcr")?;
                            tolerances(ksp, r.rtol)?;
                        }
                        None => set_ksp_type(ksp, "preonly")?,
                    }
                    // LDLᵀ is asked of MUMPS only: a package named on the command line
                    // (SuperLU_dist, for bitwise-reproducible multi-rank runs) keeps LU, as
                    // the README's reproducibility promise was measured with.
                    let other = option_string("-pc_factor_mat_solver_type")?
                        .is_some_and(|package| package != "mumps");
                    let kind = if *symmetric && !other {
                        "cholesky"
                    } else {
                        "lu"
                    };
                    set_pc_type(pc, kind)?;
                    // MUMPS here has neither METIS nor SCOTCH (ICNTL(7) = 5 or 3 fall back to
                    // PORD); of the orderings it has, approximate minimum fill gave the
                    // smallest factors on the cantilever at h = 1/32: LU 9.8 M entries and
                    // 0.95 GFlop against PORD's 10.6 M and 1.14 GFlop (AMD, QAMD: 11.3 M,
                    // 1.51 GFlop), LDLᵀ 5.0 M against 5.3 M. The command line wins.
                    default_option("-mat_mumps_icntl_7", "2")?;
                    let mumps = cstring("mumps")?;
                    check(
                        ffi::PCFactorSetMatSolverType(pc, mumps.as_ptr()),
                        "PCFactorSetMatSolverType",
                    )?;
                }
                LinearSolver::Amg {
                    rtol,
                    symmetric,
                    yield_zone,
                } => {
                    let zone = *yield_zone;
                    if *symmetric && !zone {
                        conjugate_gradients(ksp, *rtol)?;
                    } else {
                        krylov(ksp, *rtol)?;
                    }
                    if zone {
                        return super::yield_zone::install(pc, std::ptr::null_mut(), pc, "");
                    }
                    set_pc_type(pc, "gamg")?;
                    // Reused GAMG interpolation once gave CG an indefinite preconditioner on
                    // the second Newton iteration (DIVERGED_INDEFINITE_PC, PETSc 3.18).
                    check(
                        ffi::PCGAMGSetReuseInterpolation(pc, ffi::PetscBool_PETSC_FALSE),
                        "PCGAMGSetReuseInterpolation",
                    )?;
                }
                LinearSolver::PMultigrid {
                    rtol,
                    symmetric,
                    interpolation,
                    coarse,
                } => {
                    if *symmetric {
                        conjugate_gradients(ksp, *rtol)?;
                    } else {
                        krylov(ksp, *rtol)?;
                    }
                    if *symmetric {
                        // The coarse GAMG's Chebyshev smoothers estimate their eigenvalues by
                        // CG: GMRES's vectors sat under the memory peak (heaptrack, 30 MB of 886
                        // at h = 1/128 on 1 rank; the same iteration counts).
                        default_option("-mg_coarse_mg_levels_esteig_ksp_type", "cg")?;
                    }
                    if self.two_level_cycle()? {
                        let mut coarse_ksp: ffi::KSP = std::ptr::null_mut();
                        let mut comm = mpi::ffi::RSMPI_COMM_NULL;
                        check(
                            ffi::PetscObjectGetComm(ksp as ffi::PetscObject, &mut comm),
                            "PetscObjectGetComm",
                        )?;
                        check(ffi::KSPCreate(comm, &mut coarse_ksp), "KSPCreate(coarse)")?;
                        // Owned by the cycle from here on, options read as PCMG's would be.
                        let prefix = cstring("mg_coarse_")?;
                        let made = check(
                            ffi::KSPSetOptionsPrefix(coarse_ksp, prefix.as_ptr()),
                            "KSPSetOptionsPrefix(coarse)",
                        )
                        .and_then(|()| configure_coarse(coarse_ksp, coarse));
                        if let Err(e) = made {
                            ffi::KSPDestroy(&mut coarse_ksp);
                            return Err(e);
                        }
                        return super::two_level::set(pc, interpolation.raw, coarse_ksp);
                    }
                    set_pc_type(pc, "mg")?;
                    check(
                        ffi::PCMGSetLevels(pc, 2, std::ptr::null_mut()),
                        "PCMGSetLevels",
                    )?;
                    check(
                        ffi::PCMGSetInterpolation(pc, 1, interpolation.raw),
                        "PCMGSetInterpolation",
                    )?;
                    check(
                        ffi::PCMGSetGalerkin(pc, ffi::PCMGGalerkinType_PC_MG_GALERKIN_NONE),
                        "PCMGSetGalerkin",
                    )?;
                    let mut coarse_ksp: ffi::KSP = std::ptr::null_mut();
                    check(
                        ffi::PCMGGetCoarseSolve(pc, &mut coarse_ksp),
                        "PCMGGetCoarseSolve",
                    )?;
                    configure_coarse(coarse_ksp, coarse)?;
                    // Point Jacobi on P2 (PCMG's default smoother is Chebyshev with SOR),
                    // one sweep before and after (two took 30 % longer for 3 % fewer
                    // iterations). Where the tangent is symmetric, Richardson damped by the
                    // Jacobian's own spectral bound (`Snes` sets the damping after every
                    // Jacobian: `super::snes`, `crate::solve::smoother`); elsewhere
                    // Chebyshev, its eigenvalues estimated by GMRES (by CG if the user asks
                    // for Chebyshev on a symmetric tangent: GMRES keeps 30 vectors). By
                    // default that damped sweep runs in `super::two_level`'s cycle, not here.
                    default_option("-mg_levels_pc_type", "jacobi")?;
                    default_option("-mg_levels_ksp_max_it", "1")?;
                    if self.damps_jacobi_smoother()? {
                        let mut smoother: ffi::KSP = std::ptr::null_mut();
                        check(
                            ffi::PCMGGetSmoother(pc, 1, &mut smoother),
                            "PCMGGetSmoother",
                        )?;
                        set_ksp_type(smoother, "richardson")?;
                    }
                    if *symmetric {
                        default_option("-mg_levels_esteig_ksp_type", "cg")?;
                    }
                }
                LinearSolver::Schur {
                    rtol,
                    yield_zone,
                    displacement,
                    pressure,
                    pressure_mass,
                } => {
                    krylov(ksp, *rtol)?;
                    set_pc_type(pc, "fieldsplit")?;
                    let (u, p) = (cstring("u")?, cstring("p")?);
                    check(
                        ffi::PCFieldSplitSetIS(pc, u.as_ptr(), displacement.raw),
                        "PCFieldSplitSetIS(u)",
                    )?;
                    check(
                        ffi::PCFieldSplitSetIS(pc, p.as_ptr(), pressure.raw),
                        "PCFieldSplitSetIS(p)",
                    )?;
                    // The split's inner solvers exist from here, but the Schur type hands
                    // them out only once set up: the displacement block's is taken now.
                    let zone = *yield_zone;
                    if zone {
                        install_yield_zone(pc, displacement)?;
                    }
                    check(
                        ffi::PCFieldSplitSetType(pc, ffi::PCCompositeType_PC_COMPOSITE_SCHUR),
                        "PCFieldSplitSetType",
                    )?;
                    check(
                        ffi::PCFieldSplitSetSchurFactType(
                            pc,
                            ffi::PCFieldSplitSchurFactType_PC_FIELDSPLIT_SCHUR_FACT_UPPER,
                        ),
                        "PCFieldSplitSetSchurFactType",
                    )?;
                    check(
                        ffi::PCFieldSplitSetSchurPre(
                            pc,
                            ffi::PCFieldSplitSchurPreType_PC_FIELDSPLIT_SCHUR_PRE_USER,
                            pressure_mass.raw,
                        ),
                        "PCFieldSplitSetSchurPre",
                    )?;
                    // The split's inner solvers read their options only when the PC is set
                    // up, so their defaults go to the options database, where the command
                    // line wins.
                    if !zone {
                        default_option("-fieldsplit_u_pc_type", "gamg")?;
                    }
                    for (name, value) in [
                        ("-fieldsplit_u_ksp_type", "preonly"),
                        ("-fieldsplit_u_pc_gamg_reuse_interpolation", "false"),
                        ("-fieldsplit_p_ksp_type", "preonly"),
                        ("-fieldsplit_p_pc_type", "jacobi"),
                    ] {
                        default_option(name, value)?;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Whether a plastic displacement system is preconditioned through the yield zone
/// ([`super::yield_zone`]): the field split's displacement block (`split`) or a P2 system,
/// unless the PETSc option `-pfem_yield_zone false` (or `0`) is given or the command line
/// names that system's own preconditioner (`-fieldsplit_u_pc_type`, `-pc_type`). Its exact
/// solve orders MUMPS as the direct path does, unless the command line says otherwise.
pub fn yield_zone_from_options(split: bool) -> Result<bool, PetscError> {
    let (own, prefix) = if split {
        ("-fieldsplit_u_pc_type", "-fieldsplit_u_zone_")
    } else {
        ("-pc_type", "-zone_")
    };
    let on = bool_option("-pfem_yield_zone", true)? && option_string(own)?.is_none();
    if on {
        default_option(&format!("{prefix}mat_mumps_icntl_7"), "2")?;
    }
    Ok(on)
}

/// Collective. Makes the displacement block's preconditioner of the field split `pc` (before
/// its type is Schur) the yield zone.
///
/// # Safety
/// `pc` must be a live field split with its two fields set.
unsafe fn install_yield_zone(pc: ffi::PC, displacement: &IndexSet) -> Result<(), PetscError> {
    let mut n: ffi::PetscInt = 0;
    let mut sub: *mut ffi::KSP = std::ptr::null_mut();
    let (func, file) = (cstring("install_yield_zone")?, cstring(file!())?);
    // SAFETY: as the caller promises; PETSc allocates the array of borrowed KSPs, freed here.
    unsafe {
        check(
            ffi::PCFieldSplitGetSubKSP(pc, &mut n, &mut sub),
            "PCFieldSplitGetSubKSP",
        )?;
        let first = if n > 0 && !sub.is_null() {
            Some(*sub)
        } else {
            None
        };
        let freed = ffi::PetscFreeA(
            1,
            line!() as std::os::raw::c_int,
            func.as_ptr(),
            file.as_ptr(),
            &mut sub as *mut *mut ffi::KSP as *mut std::ffi::c_void,
        );
        check(freed, "PetscFree")?;
        let Some(ksp) = first else {
            return Err(PetscError {
                code: super::error::PETSC_ERR_USER,
                message: "the field split has no displacement block".into(),
            });
        };
        let mut block_pc: ffi::PC = std::ptr::null_mut();
        check(ffi::KSPGetPC(ksp, &mut block_pc), "KSPGetPC(u)")?;
        super::yield_zone::install(block_pc, displacement.raw, pc, "fieldsplit_u_")
    }
}

/// The p-multigrid's coarse solver: two GAMG cycles on the coarse operator `coarse`
/// (Richardson, a fixed linear operator, so CG still sees a symmetric preconditioner). GAMG is
/// the weak part of the pair on slender bodies: cantilever h = 1/64, 5 steps, 2 ranks, 688 CG
/// iterations against 904 with one cycle, and with an exact coarse solve 101, so the fine
/// smoothing is not what limits it.
///
/// # Safety
/// `coarse_ksp` must be a live KSP.
unsafe fn configure_coarse(coarse_ksp: ffi::KSP, coarse: &Mat) -> Result<(), PetscError> {
    // SAFETY: as the caller promises; the operator is referenced by PETSc.
    unsafe {
        check(
            ffi::KSPSetOperators(coarse_ksp, coarse.raw, coarse.raw),
            "KSPSetOperators(coarse)",
        )?;
        set_ksp_type(coarse_ksp, "richardson")?;
        check(
            ffi::KSPSetTolerances(coarse_ksp, 0.0, 0.0, 1e30, COARSE_CYCLES),
            "KSPSetTolerances(coarse)",
        )?;
        check(
            ffi::KSPSetNormType(coarse_ksp, ffi::KSPNormType_KSP_NORM_NONE),
            "KSPSetNormType(coarse)",
        )?;
        let mut coarse_pc: ffi::PC = std::ptr::null_mut();
        check(
            ffi::KSPGetPC(coarse_ksp, &mut coarse_pc),
            "KSPGetPC(coarse)",
        )?;
        set_pc_type(coarse_pc, "gamg")?;
        // The coarse operator is the Galerkin product of each Newton iterate's tangent: GAMG
        // aggregates once per increment and only redoes its products on the next iterations.
        // Its smoothers then estimate their eigenvalues afresh instead of keeping the first
        // aggregation's (a stale bound is how reused GAMG became indefinite: CG stopped with
        // DIVERGED_INDEFINITE_PC on the second Newton iteration).
        check(
            ffi::PCGAMGSetReuseInterpolation(coarse_pc, ffi::PetscBool_PETSC_TRUE),
            "PCGAMGSetReuseInterpolation",
        )?;
        check(
            ffi::PCGAMGSetUseSAEstEig(coarse_pc, ffi::PetscBool_PETSC_FALSE),
            "PCGAMGSetUseSAEstEig",
        )
    }
}

/// GMRES with right preconditioning, so that the tolerance applies to the true residual.
unsafe fn krylov(ksp: ffi::KSP, rtol: Scalar) -> Result<(), PetscError> {
    set_ksp_type(ksp, "gmres")?;
    check(
        ffi::KSPGMRESSetRestart(ksp, to_int(RESTART, "GMRES restart")?),
        "KSPGMRESSetRestart",
    )?;
    check(ffi::KSPSetPCSide(ksp, ffi::PCSide_PC_RIGHT), "KSPSetPCSide")?;
    tolerances(ksp, rtol)
}

/// CG, left-preconditioned (as CG must be) but converged on the unpreconditioned residual,
/// so that `rtol` means what it means for [`krylov`].
unsafe fn conjugate_gradients(ksp: ffi::KSP, rtol: Scalar) -> Result<(), PetscError> {
    set_ksp_type(ksp, "cg")?;
    check(ffi::KSPSetPCSide(ksp, ffi::PCSide_PC_LEFT), "KSPSetPCSide")?;
    check(
        ffi::KSPSetNormType(ksp, ffi::KSPNormType_KSP_NORM_UNPRECONDITIONED),
        "KSPSetNormType",
    )?;
    tolerances(ksp, rtol)
}

/// `rtol` relative to the first residual, no absolute floor, at most [`MAX_LINEAR_IT`]
/// iterations.
unsafe fn tolerances(ksp: ffi::KSP, rtol: Scalar) -> Result<(), PetscError> {
    check(
        ffi::KSPSetTolerances(
            ksp,
            rtol,
            1e-50,
            ffi::PETSC_DEFAULT as Scalar,
            to_int(MAX_LINEAR_IT, "KSP iterations")?,
        ),
        "KSPSetTolerances",
    )
}

unsafe fn set_ksp_type(ksp: ffi::KSP, kind: &str) -> Result<(), PetscError> {
    let kind = cstring(kind)?;
    check(ffi::KSPSetType(ksp, kind.as_ptr()), "KSPSetType")
}

unsafe fn set_pc_type(pc: ffi::PC, kind: &str) -> Result<(), PetscError> {
    let kind = cstring(kind)?;
    check(ffi::PCSetType(pc, kind.as_ptr()), "PCSetType")
}

/// The value of option `name` in PETSc's options database, if given.
fn option_string(name: &str) -> Result<Option<String>, PetscError> {
    let n = cstring(name)?;
    let mut buf = [0 as std::os::raw::c_char; 256];
    let mut given = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: nul-terminated name; PETSc writes at most `buf.len()` bytes, nul-terminated; the
    // global options database is live between PetscInitialize and PetscFinalize.
    unsafe {
        check(
            ffi::PetscOptionsGetString(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                buf.as_mut_ptr(),
                buf.len(),
                &mut given,
            ),
            "PetscOptionsGetString",
        )?;
        if given == ffi::PetscBool_PETSC_FALSE {
            return Ok(None);
        }
        let value = std::ffi::CStr::from_ptr(buf.as_ptr());
        Ok(Some(value.to_string_lossy().into_owned()))
    }
}

/// Puts `name value` into PETSc's options database unless the command line gave `name`.
fn default_option(name: &str, value: &str) -> Result<(), PetscError> {
    let (n, v) = (cstring(name)?, cstring(value)?);
    let mut given = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: nul-terminated strings; the global options database (null) is live between
    // PetscInitialize and PetscFinalize.
    unsafe {
        check(
            ffi::PetscOptionsHasName(
                std::ptr::null_mut(),
                std::ptr::null(),
                n.as_ptr(),
                &mut given,
            ),
            "PetscOptionsHasName",
        )?;
        if given == ffi::PetscBool_PETSC_FALSE {
            check(
                ffi::PetscOptionsSetValue(std::ptr::null_mut(), n.as_ptr(), v.as_ptr()),
                "PetscOptionsSetValue",
            )?;
        }
    }
    Ok(())
}
