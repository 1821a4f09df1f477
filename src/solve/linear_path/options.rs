//! What the command line says about the linear path: pfem-mpi's own `-pfem_*` options,
//! registered so that `-help` lists them, and the few PETSc options of the user's that must
//! win over a choice of ours.

use super::FactorReuse;
use crate::petsc::options::{self, OptionsBlock};
use crate::petsc::PetscError;
use mpi::topology::SimpleCommunicator;
use std::fmt;

/// A path named by `-pfem_linear_solver`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Named {
    /// As `solver.linear = "auto"`.
    Auto,
    Direct,
    /// As `solver.linear = "iterative"`: the p-multigrid, the yield zone or the field split,
    /// as the mesh and the material need.
    Iterative,
    /// The two-level p-multigrid (P2 meshes).
    Pmg,
    /// GAMG (on the displacement block of a P2–P1 field split).
    Amg,
    /// GAMG and the exact solve on the yielded rows (on the displacement block of a P2–P1
    /// field split).
    YieldZone,
}

/// The option, and its values in the order of [`Named::ALL`].
pub const LINEAR_SOLVER: &str = "-pfem_linear_solver";
const NAMES: [&str; 6] = ["auto", "direct", "iterative", "pmg", "amg", "yield-zone"];

impl Named {
    const ALL: [Named; 6] = [
        Named::Auto,
        Named::Direct,
        Named::Iterative,
        Named::Pmg,
        Named::Amg,
        Named::YieldZone,
    ];

    /// The path named `value`, or an error naming the option and its values.
    pub fn parse(value: &str) -> Result<Named, String> {
        NAMES
            .iter()
            .position(|n| *n == value)
            .map(|i| Named::ALL[i])
            .ok_or_else(|| {
                format!(
                    "{LINEAR_SOLVER} {value:?}: not a linear solver path; choose one of {}",
                    NAMES.join(", ")
                )
            })
    }
}

impl fmt::Display for Named {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let i = Named::ALL.iter().position(|n| n == self).unwrap_or(0);
        f.write_str(NAMES[i])
    }
}

/// The user's PETSc options that win over a choice of ours. Each is a check that PETSc cannot
/// make for us: the object that would read the option is built after the choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct UserOptions {
    /// `-pc_type`: the user's preconditioner replaces the P2 system's.
    pub pc_type: bool,
    /// `-fieldsplit_u_pc_type`: the user's preconditioner on the field split's displacements.
    pub fieldsplit_u_pc_type: bool,
    /// `-pc_factor_mat_solver_type` other than mumps: a package that keeps LU.
    pub other_factor_package: bool,
    /// An option of PCMG's own cycle (its type, cycles, logging, Galerkin products or sweeps
    /// other than one), which our two-level cycle would not honour.
    pub pcmg_cycle: bool,
    /// The fine smoother, its preconditioner (other than Jacobi), its damping, more levels or
    /// a distinct up-smoother named: not the smoother the Jacobian's spectral bound describes.
    pub smoother_named: bool,
    /// The fine smoother works on an upper triangle: point Jacobi (its default) does; SOR and
    /// ILU (`-mg_levels_pc_type`) do not ("SSOR for block size > 1 is not yet implemented").
    pub smoother_takes_upper_triangle: bool,
    /// `-mg_coarse_pc_gamg_reuse_interpolation` (default true).
    pub coarse_keeps_aggregation: bool,
}

impl UserOptions {
    /// Reads them from PETSc's options database.
    pub fn read() -> Result<UserOptions, PetscError> {
        let given = |name: &str| Ok::<_, PetscError>(options::string(name)?.is_some());
        let other_than = |name: &str, value: &str| {
            Ok::<_, PetscError>(options::string(name)?.is_some_and(|v| v != value))
        };
        let mut pcmg_cycle = false;
        for name in [
            "-pc_mg_type",
            "-pc_mg_cycle_type",
            "-pc_mg_multiplicative_cycles",
            "-pc_mg_galerkin",
            "-pc_mg_log",
            "-pc_mg_smoothup",
            "-pc_mg_smoothdown",
        ] {
            pcmg_cycle |= given(name)?;
        }
        for name in ["-mg_levels_ksp_max_it", "-mg_levels_1_ksp_max_it"] {
            pcmg_cycle |= other_than(name, "1")?;
        }
        let mut smoother_named = given("-pc_mg_distinct_smoothup")? || given("-pc_mg_levels")?;
        for prefix in ["-mg_levels_", "-mg_levels_1_"] {
            for name in [
                "ksp_type",
                "ksp_richardson_scale",
                "ksp_richardson_self_scale",
                "pc_jacobi_type",
                "pc_jacobi_abs",
            ] {
                smoother_named |= given(&format!("{prefix}{name}"))?;
            }
            smoother_named |= other_than(&format!("{prefix}pc_type"), "jacobi")?;
        }
        Ok(UserOptions {
            pc_type: given("-pc_type")?,
            fieldsplit_u_pc_type: given("-fieldsplit_u_pc_type")?,
            other_factor_package: other_than("-pc_factor_mat_solver_type", "mumps")?,
            pcmg_cycle,
            smoother_named,
            smoother_takes_upper_triangle: !other_than("-mg_levels_pc_type", "jacobi")?,
            coarse_keeps_aggregation: options::flag(
                "-mg_coarse_pc_gamg_reuse_interpolation",
                true,
            )?,
        })
    }
}

/// Everything the command line says about the linear path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CommandLine {
    /// `-pfem_linear_solver`, overriding `solver.linear`.
    pub named: Option<Named>,
    /// `-pfem_pmg` (default true): `iterative` on an elastic P2 mesh is the p-multigrid, not
    /// GAMG.
    pub pmg: bool,
    /// `-pfem_yield_zone` (default true): `iterative` on a plastic mesh is the yield zone.
    pub yield_zone: bool,
    /// `-pfem_lu_reuse` and its parameters.
    pub reuse: Option<FactorReuse>,
    pub own: UserOptions,
}

const REUSE_CONTRACTION: f64 = 0.1;
const REUSE_MAX_KRYLOV: usize = 4;
const REUSE_RTOL: f64 = 1e-10;

impl CommandLine {
    /// Collective. Reads the options, registering pfem-mpi's own with `-help`; `scene` and
    /// `reuse_factorisation` are the scene's `solver.linear` and default for `-pfem_lu_reuse`.
    pub fn read(
        comm: &SimpleCommunicator,
        scene: crate::scene::LinearChoice,
        reuse_factorisation: bool,
    ) -> Result<CommandLine, PetscError> {
        let as_user_error = |message: String| PetscError {
            code: crate::petsc::error::PETSC_ERR_USER,
            message,
        };
        if let Some(value) = options::string(LINEAR_SOLVER)? {
            Named::parse(&value).map_err(as_user_error)?;
        }
        let mut block = OptionsBlock::begin(comm, "pfem-mpi linear solver options")?;
        let named = block
            .choice(
                LINEAR_SOLVER,
                "The linear solver path, overriding solver.linear (docs/guide/solvers.md)",
                &NAMES,
                super::scene_name(scene),
            )?
            .map(|i| Named::ALL[i]);
        let pmg = block.flag(
            "-pfem_pmg",
            "iterative on an elastic P2 mesh: the two-level p-multigrid (false: GAMG)",
            true,
        )?;
        let yield_zone = block.flag(
            "-pfem_yield_zone",
            "iterative on a plastic mesh: GAMG and an exact solve on the yielded rows \
             (false: GAMG alone)",
            true,
        )?;
        let reuse_on = block.flag(
            "-pfem_lu_reuse",
            "direct: keep a factorisation across Newton iterations, preconditioning GCR",
            reuse_factorisation,
        )?;
        let contraction = block.real(
            "-pfem_lu_reuse_contraction",
            "keep the factors while Newton cuts the residual by this factor",
            REUSE_CONTRACTION,
        )?;
        let max_krylov = block.real(
            "-pfem_lu_reuse_max_krylov",
            "... and the last linear solve took at most this many Krylov iterations",
            REUSE_MAX_KRYLOV as f64,
        )? as usize;
        let rtol = block.real(
            "-pfem_lu_reuse_rtol",
            "relative tolerance of GCR with kept factors",
            REUSE_RTOL,
        )?;
        block.end()?;
        Ok(CommandLine {
            named,
            pmg,
            yield_zone,
            reuse: reuse_on.then_some(FactorReuse {
                contraction,
                max_krylov,
                rtol,
            }),
            own: UserOptions::read()?,
        })
    }
}
