//! The run's linear plan: which [`LinearPath`] solves which system, chosen once from the
//! model's facts and the command line.

use super::{
    CommandLine, Cycle, Factor, Krylov, LinearPath, Named, UserOptions, ITERATIVE_ABOVE_DOFS,
};
use crate::scene::LinearChoice;
use std::fmt;

/// What the model says about its systems.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facts {
    /// P2–P1 (a pressure unknown) rather than P2.
    pub mixed: bool,
    pub plastic: bool,
    /// Every tangent is symmetric.
    pub symmetric: bool,
    /// `solver.linear`.
    pub scene: LinearChoice,
}

/// The run's linear path: one, or (`auto` on an elastic P2 mesh) a direct path up to a size
/// and an iterative one above.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearPlan {
    pub small: LinearPath,
    /// The path past this many global dofs.
    pub large: Option<(usize, LinearPath)>,
    /// Where the choice came from: `solver.linear = "..."` or `-pfem_linear_solver ...`.
    pub origin: Origin,
}

/// Who chose the plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Origin {
    Scene(LinearChoice),
    CommandLine(Named),
}

impl LinearPlan {
    /// The plan for `facts` and the command line: `-pfem_linear_solver` if given, else the
    /// scene's `solver.linear`. Fails on a path that cannot solve these systems.
    pub fn choose(facts: &Facts, cl: &CommandLine) -> Result<LinearPlan, String> {
        let named = cl.named.unwrap_or(match facts.scene {
            LinearChoice::Auto => Named::Auto,
            LinearChoice::Direct => Named::Direct,
            LinearChoice::Iterative => Named::Iterative,
        });
        let origin = match cl.named {
            Some(n) => Origin::CommandLine(n),
            None => Origin::Scene(facts.scene),
        };
        let direct = LinearPath::Direct {
            // LDLᵀ is asked of MUMPS only: a package named on the command line (SuperLU_dist,
            // for bitwise-reproducible multi-rank runs) keeps LU, as the README's
            // reproducibility promise was measured with.
            factor: if facts.symmetric && !cl.own.other_factor_package {
                Factor::Cholesky
            } else {
                Factor::Lu
            },
            reuse: cl.reuse,
        };
        let krylov = if facts.symmetric {
            Krylov::Cg
        } else {
            Krylov::Gmres
        };
        let amg = if facts.mixed {
            LinearPath::FieldSplit { yield_zone: false }
        } else {
            LinearPath::Amg { krylov }
        };
        // The user's own preconditioner replaces ours: the field split's block's, or the whole
        // system's (the p-multigrid's BAIJ tangent would stop GAMG, so GAMG's AIJ is kept).
        let own_pc = if facts.mixed {
            cl.own.fieldsplit_u_pc_type
        } else {
            cl.own.pc_type
        };
        let zone = if own_pc {
            amg
        } else if facts.mixed {
            LinearPath::FieldSplit { yield_zone: true }
        } else {
            LinearPath::YieldZone
        };
        let pmg = if facts.mixed {
            if named == Named::Pmg {
                return Err(format!(
                    "-pfem_linear_solver {named}: the p-multigrid solves P2 systems; this \
                     scene's element is P2-P1 (solver.element)"
                ));
            }
            amg
        } else if own_pc {
            amg
        } else {
            p_multigrid(krylov, &cl.own)
        };
        // `iterative`: the p-multigrid for elastic P2, the yield zone where the tangent
        // yields (GAMG alone does not converge there), unless `-pfem_pmg` or `-pfem_yield_zone`
        // say false.
        let iterative = if facts.plastic && cl.yield_zone {
            zone
        } else if !facts.plastic && !facts.mixed && cl.pmg {
            pmg
        } else {
            amg
        };
        let (small, large) = match named {
            Named::Direct => (direct, None),
            Named::Iterative => (iterative, None),
            Named::Pmg => (pmg, None),
            Named::Amg => (amg, None),
            Named::YieldZone => (zone, None),
            // Plastic scenes are left to an explicit choice: at yield the iterative paths solve
            // the yielded zone exactly, so they cost a direct solve of the zone on top of the
            // iterations: 2–3 times the direct path's time on footing-shallow at 1.8 k–28 k
            // particles (bench/VALIDATION.md, "The field split at yield, solved"). A P2–P1
            // mesh is direct too: its field split is slower at every size measured.
            Named::Auto if !facts.plastic && !facts.mixed => {
                (direct, Some((ITERATIVE_ABOVE_DOFS, iterative)))
            }
            Named::Auto => (direct, None),
        };
        Ok(LinearPlan {
            small,
            large,
            origin,
        })
    }

    /// The path of a system of `global_dofs` unknowns.
    pub fn path(&self, global_dofs: usize) -> LinearPath {
        match self.large {
            Some((above, large)) if global_dofs > above => large,
            _ => self.small,
        }
    }
}

/// The p-multigrid as the user's PETSc options leave it.
fn p_multigrid(krylov: Krylov, own: &UserOptions) -> LinearPath {
    let damped = krylov == Krylov::Cg && !own.smoother_named;
    LinearPath::PMultigrid {
        krylov,
        damped,
        // Our cycle does not honour PCMG's own options: with any of them PCMG runs it.
        cycle: if damped && !own.pcmg_cycle {
            Cycle::TwoLevel
        } else {
            Cycle::Pcmg
        },
        upper_triangle: krylov == Krylov::Cg && own.smoother_takes_upper_triangle,
        coarse_keeps_aggregation: own.coarse_keeps_aggregation,
    }
}

impl fmt::Display for LinearPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.large {
            None => write!(f, "{}", self.small)?,
            Some((above, large)) => write!(
                f,
                "{} up to {above} global dofs; above, {large}",
                self.small
            )?,
        }
        match self.origin {
            Origin::Scene(choice) => write!(f, " (solver.linear = \"{}\")", scene_name(choice)),
            Origin::CommandLine(named) => write!(f, " (-pfem_linear_solver {named})"),
        }
    }
}

/// `solver.linear`'s value as the scene writes it.
pub fn scene_name(choice: LinearChoice) -> &'static str {
    match choice {
        LinearChoice::Auto => "auto",
        LinearChoice::Direct => "direct",
        LinearChoice::Iterative => "iterative",
    }
}
