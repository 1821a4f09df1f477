use super::*;
use crate::scene::LinearChoice;

fn facts(mixed: bool, plastic: bool, scene: LinearChoice) -> Facts {
    Facts {
        mixed,
        plastic,
        symmetric: !mixed && !plastic,
        scene,
    }
}

fn command_line(named: Option<Named>) -> CommandLine {
    CommandLine {
        named,
        pmg: true,
        yield_zone: true,
        reuse: None,
        own: UserOptions {
            smoother_takes_upper_triangle: true,
            coarse_keeps_aggregation: true,
            ..UserOptions::default()
        },
    }
}

fn plan(facts: Facts, cl: CommandLine) -> LinearPlan {
    LinearPlan::choose(&facts, &cl).expect("a plan")
}

const PMG: LinearPath = LinearPath::PMultigrid {
    krylov: Krylov::Cg,
    damped: true,
    cycle: Cycle::TwoLevel,
    upper_triangle: true,
    coarse_keeps_aggregation: true,
};

#[test]
fn auto_is_direct_then_the_p_multigrid_for_large_elastic_p2_systems_only() {
    let elastic = plan(facts(false, false, LinearChoice::Auto), command_line(None));
    let cholesky = LinearPath::Direct {
        factor: Factor::Cholesky,
        reuse: None,
    };
    assert_eq!(elastic.path(83_330), cholesky);
    assert_eq!(elastic.path(186_434), PMG);
    // A yielded P2 tangent defeats the p-multigrid; P2–P1 is slower split than direct.
    for (mixed, plastic) in [(false, true), (true, false), (true, true)] {
        let p = plan(
            facts(mixed, plastic, LinearChoice::Auto),
            command_line(None),
        );
        assert!(!p.path(8_000_000).iterative(), "{mixed} {plastic}");
    }
}

#[test]
fn iterative_follows_the_mesh_and_the_material() {
    let iterative = |mixed, plastic| {
        plan(
            facts(mixed, plastic, LinearChoice::Iterative),
            command_line(None),
        )
        .path(10)
    };
    assert_eq!(iterative(false, false), PMG);
    assert_eq!(iterative(false, true), LinearPath::YieldZone);
    assert_eq!(
        iterative(true, false),
        LinearPath::FieldSplit { yield_zone: false }
    );
    assert_eq!(
        iterative(true, true),
        LinearPath::FieldSplit { yield_zone: true }
    );
}

#[test]
fn the_option_overrides_the_scene() {
    let cases = [
        ("direct", false, "direct, MUMPS LDLᵀ"),
        ("pmg", false, "pmg, CG with the two-level p-multigrid"),
        ("amg", false, "amg, CG with GAMG on the P2 system"),
        (
            "yield-zone",
            true,
            "yield-zone, GMRES with GAMG and an exact solve",
        ),
        ("iterative", true, "yield-zone"),
    ];
    for (value, plastic, want) in cases {
        let named = Named::parse(value).expect("a path");
        assert_eq!(named.to_string(), value);
        let p = plan(
            facts(false, plastic, LinearChoice::Direct),
            command_line(Some(named)),
        );
        let shown = p.to_string();
        assert!(shown.starts_with(want), "{value}: {shown}");
        assert!(
            shown.ends_with(&format!("(-pfem_linear_solver {value})")),
            "{shown}"
        );
        assert_eq!(p.large, None);
    }
}

#[test]
fn a_bad_value_names_the_option_and_its_choices() {
    let e = Named::parse("gamg").expect_err("not a path");
    assert!(e.contains("-pfem_linear_solver"), "{e}");
    assert!(e.contains("\"gamg\""), "{e}");
    assert!(
        e.contains("auto, direct, iterative, pmg, amg, yield-zone"),
        "{e}"
    );
}

#[test]
fn the_p_multigrid_on_a_p2p1_mesh_is_an_error() {
    let e = LinearPlan::choose(
        &facts(true, true, LinearChoice::Auto),
        &command_line(Some(Named::Pmg)),
    )
    .expect_err("P2-P1");
    assert!(e.contains("-pfem_linear_solver pmg"), "{e}");
}

#[test]
fn the_users_own_petsc_options_win() {
    let elastic = facts(false, false, LinearChoice::Iterative);
    let with = |own: UserOptions| {
        plan(
            elastic,
            CommandLine {
                own,
                ..command_line(None)
            },
        )
        .path(1)
    };
    let base = command_line(None).own;
    // Their preconditioner replaces ours, on GAMG's AIJ tangent.
    assert_eq!(
        with(UserOptions {
            pc_type: true,
            ..base
        }),
        LinearPath::Amg { krylov: Krylov::Cg }
    );
    // An option of PCMG's cycle brings PCMG back, with the damped smoother.
    let LinearPath::PMultigrid { cycle, damped, .. } = with(UserOptions {
        pcmg_cycle: true,
        ..base
    }) else {
        panic!("not the p-multigrid")
    };
    assert_eq!((cycle, damped), (Cycle::Pcmg, true));
    // A smoother of theirs is PETSc's, on the whole tangent if it cannot take a triangle.
    let path = with(UserOptions {
        smoother_named: true,
        smoother_takes_upper_triangle: false,
        ..base
    });
    assert_eq!(path.storage(), Storage::Blocks);
    assert!(!path.damps_smoother());
    // Another factorisation package keeps LU.
    let direct = plan(
        facts(false, false, LinearChoice::Direct),
        CommandLine {
            own: UserOptions {
                other_factor_package: true,
                ..base
            },
            ..command_line(None)
        },
    );
    assert!(matches!(
        direct.path(1),
        LinearPath::Direct {
            factor: Factor::Lu,
            ..
        }
    ));
    // `-pfem_pmg false` is GAMG; `-pfem_yield_zone false` GAMG alone at yield.
    let off = CommandLine {
        pmg: false,
        yield_zone: false,
        ..command_line(None)
    };
    assert_eq!(
        plan(elastic, off).path(1),
        LinearPath::Amg { krylov: Krylov::Cg }
    );
    let plastic = facts(false, true, LinearChoice::Iterative);
    assert_eq!(
        plan(plastic, off).path(1),
        LinearPath::Amg {
            krylov: Krylov::Gmres
        }
    );
}
