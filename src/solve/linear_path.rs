//! How Newton's linear systems are solved: the one place that decides it. The path is an
//! explicit value ([`LinearPath`]), chosen once per run from the scene, the model and the
//! command line ([`LinearPlan::choose`]), printed at the start of the run and overridable by
//! `-pfem_linear_solver`. The PETSc binding only applies it (`super::precond::configure`).

mod options;
mod plan;

pub use options::{CommandLine, Named, UserOptions};
pub use plan::{scene_name, Facts, LinearPlan, Origin};

use std::fmt;

/// Relative tolerances of the iterative linear solves: tight enough that Newton's iterates, and
/// so the histories, match the direct solver's (tests/iterative.rs: 1e-11 relative or closer).
/// GMRES+GAMG on the cantilever (h = 1/8, 5 steps): 1e-6 kept the direct path's 35 Newton
/// iterations with 1082 Krylov iterations against 1342 at 1e-8. The field split at 1e-6 added
/// Newton iterations on the ν = 0.4999 block (10 instead of 8 at h = 0.1 and 0.05, 13 instead of
/// 10 at h = 0.025) and so about as many Krylov iterations as 1e-8 (320 vs 332, 343 vs 367, 476
/// vs 494), so it solves to 1e-8.
const AMG_RTOL: f64 = 1e-6;
const SCHUR_RTOL: f64 = 1e-8;
/// The loosest Eisenstat–Walker tolerance ([`LinearPath::inexact_newton_cap`]).
const INEXACT_NEWTON_CAP: f64 = 1e-2;

/// Global dofs above which `solver.linear = "auto"` solves an elastic P2 system iteratively
/// (the p-multigrid). A speed crossover, measured on one step of the 50-step cantilever
/// (bench/VALIDATION.md, 2026-11-25): at 83 k dofs the two paths tie (1.61 against 1.56 s on 1
/// rank, 1.19 against 1.16 s on 2), at 186 k the p-multigrid leads (3.3–3.5 against 3.9–4.1 s,
/// 2.1–2.3 against 3.3–3.5 s) with less than half the memory, and at 333 k and 1.3 M dofs it
/// leads on the large increments of the 5-step cantilever too (23.8–26.8 against 35.6 s and
/// 101 against 158 s, 2 ranks).
pub const ITERATIVE_ABOVE_DOFS: usize = 150_000;

/// Global dofs past which GAMG forms its Galerkin products all at once on several ranks
/// ([`LinearPath::lean_galerkin_products`]).
const LEAN_PRODUCTS_ABOVE_DOFS: usize = 2_000_000;

/// The Krylov method of an iterative path.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Krylov {
    /// Conjugate gradients: the tangent is symmetric (and the preconditioner with it).
    Cg,
    /// Right-preconditioned GMRES.
    Gmres,
}

/// MUMPS's factorisation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Factor {
    Lu,
    /// LDLᵀ from the upper triangle of a symmetric tangent.
    Cholesky,
}

/// Who runs the p-multigrid's V-cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cycle {
    /// Our own cycle (`super::precond::two_level`): fewer vectors of the fine level.
    TwoLevel,
    /// PETSc's PCMG, which honours every `-pc_mg_*` and `-mg_levels_*` option.
    Pcmg,
}

/// How the tangent is stored for its preconditioner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// AIJ: every entry (what GAMG and MUMPS need).
    Aij,
    /// BAIJ: 2 × 2 blocks, for the p-multigrid, which only multiplies and reads the diagonal.
    Blocks,
    /// SBAIJ: the upper triangle's blocks of a symmetric tangent.
    UpperBlocks,
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
    pub rtol: f64,
}

/// One linear solver path of Newton's systems.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LinearPath {
    /// MUMPS: robust for any system, cost and memory superlinear in its size. With `reuse`,
    /// the factors of one Newton iteration precondition GCR on the next iterations' exact
    /// tangents while Newton converges fast; without, every Newton iteration factors its
    /// tangent and solves with it alone (`preonly`). Cholesky has half the factor entries and
    /// flops of LU (cantilever h = 1/32: 5.3 M entries against 10.6 M).
    Direct {
        factor: Factor,
        reuse: Option<FactorReuse>,
    },
    /// GAMG on the P2 system (block size 2, the rigid-body near-null space). CG where the
    /// tangent is symmetric: GMRES keeps one vector per iteration (8 doubles per particle
    /// each) and the solves take 35 and more iterations, where CG keeps four. Measured on the
    /// cantilever at h = 1/128 (165 k particles, 2 ranks, one step): peak RSS 1490 MB per rank
    /// with GMRES, 1255 MB with CG, 182 Krylov iterations against 173, the tracked
    /// displacements equal to 1e-15.
    Amg { krylov: Krylov },
    /// GMRES with GAMG followed by an exact solve on the rows of the yielded triangles, on the
    /// P2 system (`super::precond::yield_zone`): a plastic P2 tangent, which GAMG alone
    /// cannot hold.
    YieldZone,
    /// A two-level p-multigrid on the P2 system: one Jacobi sweep before and after on P2, the
    /// P1 → P2 interpolation (a shell operator) and two GAMG cycles on the Galerkin product of
    /// the element tangents that every Jacobian assembles. GAMG then sets up on a quarter of
    /// the unknowns and on a far sparser matrix, which is where GAMG on P2 spends its memory.
    PMultigrid {
        krylov: Krylov,
        /// The sweeps are Richardson damped by each Jacobian's spectral bound
        /// (`crate::solve::smoother`), not PETSc's Chebyshev with its eigenvalue estimate:
        /// six vectors of the fine level and ten matrix products per Newton iteration fewer.
        damped: bool,
        cycle: Cycle,
        /// Only the upper triangle of the (symmetric) tangent is stored.
        upper_triangle: bool,
        /// The coarse GAMG keeps its first aggregation through a Newton solve, so the coarse
        /// rigid-body modes can be freed after it.
        coarse_keeps_aggregation: bool,
    },
    /// GMRES with an upper block-triangular Schur-complement field split, for the mixed
    /// P2–P1 saddle point: GAMG on the displacement block (followed by the exact solve on the
    /// yielded rows with `yield_zone`), the pressure mass matrix scaled by −1/G on the Schur
    /// complement.
    FieldSplit { yield_zone: bool },
}

impl LinearPath {
    /// Whether this is a Krylov method with an algebraic preconditioner.
    pub fn iterative(&self) -> bool {
        !matches!(self, LinearPath::Direct { .. })
    }

    /// Whether the system's matrix carries the rigid-body near-null space (GAMG on P2).
    pub fn near_null_space_on_tangent(&self) -> bool {
        matches!(self, LinearPath::Amg { .. } | LinearPath::YieldZone)
    }

    /// Whether every Jacobian lists its yielded triangles for the yield zone.
    pub fn yield_zone(&self) -> bool {
        matches!(
            self,
            LinearPath::YieldZone | LinearPath::FieldSplit { yield_zone: true }
        )
    }

    /// Whether the p-multigrid's smoother takes its damping from every Jacobian.
    pub fn damps_smoother(&self) -> bool {
        matches!(self, LinearPath::PMultigrid { damped: true, .. })
    }

    /// How the tangent is stored.
    pub fn storage(&self) -> Storage {
        match self {
            LinearPath::PMultigrid {
                upper_triangle: true,
                ..
            } => Storage::UpperBlocks,
            LinearPath::PMultigrid { .. } => Storage::Blocks,
            _ => Storage::Aij,
        }
    }

    /// The relative tolerance of an iterative solve (a kept factorisation has its own).
    pub fn rtol(&self) -> f64 {
        match self {
            LinearPath::FieldSplit { .. } => SCHUR_RTOL,
            LinearPath::Direct { reuse, .. } => reuse.map_or(AMG_RTOL, |r| r.rtol),
            _ => AMG_RTOL,
        }
    }

    /// Newton iterations one preconditioner serves (`SNESSetLagPreconditioner`; it is built
    /// afresh at the start of every Newton solve). GAMG's set-up is a third of an iterative
    /// solve on the cantilever, and the tangent of one Newton iteration preconditions the next
    /// well: measured at h = 1/16 (2 steps), lag 2 took 680 Krylov iterations instead of 651
    /// and 3.3-4.6 s of CPU instead of 5.3-6.1 s (elastic). The direct and field-split paths
    /// rebuild every iteration (a lagged LU is a different Newton method; a lagged split misses
    /// the plastic tangent's changes). The yield zone follows the plastic tangent: a stale one
    /// cut the P2 block's first step (block-compression, `solver.element = "p2"`: 13 Newton
    /// iterations and a cut with lag 2, the direct path's 11 with lag 1). The p-multigrid
    /// rebuilds every iteration: its levels set themselves up again whenever their operators
    /// change, which they do at every Jacobian, so a lag changed nothing (cantilever h = 1/32,
    /// 5 steps, step 1: the same 16, 15, 20, 27, 32, 31, 31, 31 CG iterations with lag 1, 2
    /// and 3).
    pub fn preconditioner_lag(&self) -> usize {
        match self {
            LinearPath::Amg { .. } => 2,
            _ => 1,
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
    pub fn inexact_newton_cap(&self) -> Option<f64> {
        matches!(self, LinearPath::PMultigrid { .. }).then_some(INEXACT_NEWTON_CAP)
    }

    /// Whether GAMG should form its Galerkin products all at once, holding no intermediate
    /// product (`-matptap_via allatonce`): where memory and not time bounds the run. Measured
    /// on the cantilever, 2 ranks, iterative, one step (Newton and CG iterations the same with
    /// either): peak RSS summed over the ranks at h = 1/64 (41 665 particles) 684 → 499 MB, at
    /// 1/128 (165 249) 2 461 → 1 727 MB, about what one rank needs (456 and 1 558 MB); at
    /// 1.03 M particles 10 255 MB (about 15 GB expected without). The price is time: the
    /// products took 19–22 s instead of 3.0–3.7 s at 1/64, 234 s of the 1.03 M step's 502 s
    /// of solve. Only MPI matrices know the algorithm: never on one rank.
    pub fn lean_galerkin_products(&self, ranks: usize, global_dofs: usize) -> bool {
        self.iterative() && ranks > 1 && global_dofs > LEAN_PRODUCTS_ABOVE_DOFS
    }
}

impl fmt::Display for Krylov {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Krylov::Cg => "CG",
            Krylov::Gmres => "GMRES",
        })
    }
}

impl fmt::Display for LinearPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LinearPath::Direct { factor, reuse } => {
                let kind = match factor {
                    Factor::Lu => "LU",
                    Factor::Cholesky => "LDLᵀ",
                };
                write!(f, "direct, MUMPS {kind}")?;
                match reuse {
                    None => f.write_str(" at every Newton iteration"),
                    Some(r) => write!(
                        f,
                        ", factors kept while Newton contracts by {} (GCR to {:e})",
                        r.contraction, r.rtol
                    ),
                }
            }
            LinearPath::Amg { krylov } => write!(f, "amg, {krylov} with GAMG on the P2 system"),
            LinearPath::YieldZone => f.write_str(
                "yield-zone, GMRES with GAMG and an exact solve on the yielded rows (P2 system)",
            ),
            LinearPath::PMultigrid {
                krylov,
                damped,
                cycle,
                ..
            } => {
                let smoother = if *damped {
                    "damped Richardson-Jacobi"
                } else {
                    "the mg_levels_ smoother"
                };
                let runner = match cycle {
                    Cycle::TwoLevel => "own cycle",
                    Cycle::Pcmg => "PCMG",
                };
                write!(
                    f,
                    "pmg, {krylov} with the two-level p-multigrid ({smoother} on P2, GAMG on P1, \
                     {runner}), inexact Newton"
                )
            }
            LinearPath::FieldSplit { yield_zone: true } => f.write_str(
                "yield-zone, GMRES with a Schur field split (GAMG and an exact solve on the \
                 yielded rows of the displacements)",
            ),
            LinearPath::FieldSplit { yield_zone: false } => {
                f.write_str("amg, GMRES with a Schur field split (GAMG on the displacements)")
            }
        }
    }
}

#[cfg(test)]
mod tests;
