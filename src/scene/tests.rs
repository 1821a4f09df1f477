//! Scene loading: built-ins, error messages naming their field, `--set` overrides.

use super::*;

const CANTILEVER: &str = include_str!("builtin/cantilever.toml");

/// The cantilever scene file with `from` replaced by `to`, read as file `cantilever.toml`.
fn edited(from: &str, to: &str) -> Result<Scene, SceneError> {
    assert!(
        CANTILEVER.contains(from),
        "test edit target {from:?} not in the scene"
    );
    Scene::from_toml(&CANTILEVER.replacen(from, to, 1), "cantilever.toml", &[])
}

fn with_sets(sets: &[&str]) -> Result<Scene, SceneError> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    load_scene("cantilever", &sets).map(|(s, _)| s)
}

#[test]
fn builtins_parse_validate_and_round_trip() {
    for (name, _) in BUILTINS {
        let (scene, resolved) = load_scene(name, &[]).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(&scene.name, name);
        let again = Scene::from_toml(&resolved, name, &[]).unwrap();
        assert_eq!(
            again, scene,
            "{name} does not round-trip through its resolved TOML"
        );
        assert_eq!(again.to_toml(), resolved);
    }
    let (footing, _) = load_scene("footing-shallow", &[]).unwrap();
    assert_eq!(footing.material.model, MaterialModel::Tresca);
    assert!(footing.material.cu > 0.0);
    let (block, _) = load_scene("block-compression", &[]).unwrap();
    assert_eq!(block.material.model, MaterialModel::Tresca);
    assert_eq!(block.history.kind, Some(HistoryKind::Block));
}

#[test]
fn cantilever_values() {
    let (s, _) = load_scene("cantilever", &[]).unwrap();
    assert_eq!(s.mesh.h, 0.125);
    assert_eq!(s.body.rectangles[0].size, [10.0, 1.0]);
    assert_eq!(s.fixed[0].region.to_string(), "x <= 0");
    assert_eq!(s.fixed[0].dofs, vec![Dof::X, Dof::Y]);
    assert_eq!(s.point_load[0].at, [10.0, 0.5]);
    assert_eq!(s.steps.count, 50);
    assert_eq!(s.tolerance(), 1e-8);
}

#[test]
fn bad_value_message_names_scene_and_field() {
    let e = edited("h = 0.125", "h = -1").unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene 'cantilever.toml': field mesh.h: must be > 0 (got -1)"
    );
    assert_eq!(e.field.as_deref(), Some("mesh.h"));
}

#[test]
fn unknown_key_is_named() {
    let e = edited("alpha = 1.3", "alpah = 1.3").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("mesh.alpah"), "{e}");
    assert!(
        e.to_string().contains("field mesh.alpah: unknown key"),
        "{e}"
    );
    assert!(
        e.message.contains("alpha"),
        "should list the valid keys: {e}"
    );

    let e = edited("[steps]", "[stepz]").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("stepz"), "{e}");

    let e = edited("dofs = [\"x\", \"y\"]", "dofs = [\"x\", \"y\"]\nwehre = 1").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fixed[0].wehre"), "{e}");

    let e = edited("[{ origin", "[{ orgin").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("body.rectangles[0].orgin"), "{e}");
}

#[test]
fn wrong_type_is_named() {
    let e = edited("h = 0.125", "h = \"fine\"").unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene 'cantilever.toml': field mesh.h: expected a number, found string \"fine\""
    );
    let e = edited("count = 50", "count = 2.5").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("steps.count"), "{e}");
    let e = edited("count = 50", "count = -3").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("steps.count"), "{e}");
    let e = edited("refine = true", "refine = 1").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("mesh.refine"), "{e}");
    let e = edited("model = \"linear-elastic\"", "model = \"elastic\"").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("material.model"), "{e}");
    assert!(e.message.contains("\"linear-elastic\", \"tresca\""), "{e}");
    let e = edited("kind = \"cantilever\"", "kind = 3").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("history.kind"), "{e}");
    let e = edited("at = [10.0, 0.5]", "at = [10.0, 0.5, 0.0]").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("point_load[0].at"), "{e}");
    let e = edited("at = [10.0, 0.5]", "at = [10.0]").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("point_load[0].at"), "{e}");
    let e = edited("at = [10.0, 0.5]", "at = [10.0, \"top\"]").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("point_load[0].at[1]"), "{e}");
    let e = edited("dofs = [\"x\", \"y\"]", "dofs = [\"x\", \"z\"]").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fixed[0].dofs[1]"), "{e}");
    let e = edited("[mesh]\nh = 0.125", "mesh = 3\n[mesh2]\nh = 0.125").unwrap_err();
    assert!(e.field.is_some(), "{e}");
}

#[test]
fn missing_key_is_named() {
    let e = edited("young = 12.0e6\n", "").unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene 'cantilever.toml': field material.young: required key is missing"
    );
}

#[test]
fn bad_selector_is_named() {
    let e = edited("where = \"x <= 0\"", "where = \"x < 0\"").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fixed[0].where"), "{e}");
    assert!(e.message.contains("expected comparisons"), "{e}");
    let e = edited("where = \"x <= 0\"", "where = \"x <= -1\"").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("fixed[0].where"), "{e}");
    assert!(e.message.contains("selects no particle"), "{e}");
}

#[test]
fn validation_messages_name_fields() {
    let cases = [
        (
            "poisson = 0.2",
            "poisson = 0.5",
            "material.poisson",
            "must be > -1 and < 0.5 (got 0.5)",
        ),
        (
            "poisson = 0.2",
            "poisson = -1.0",
            "material.poisson",
            "(got -1)",
        ),
        (
            "young = 12.0e6",
            "young = 0.0",
            "material.young",
            "must be > 0 (got 0)",
        ),
        (
            "alpha = 1.3",
            "alpha = 0.0",
            "mesh.alpha",
            "must be > 0 (got 0)",
        ),
        (
            "alpha = 1.3",
            "alpha = 0.5",
            "mesh.alpha",
            "must be >= 0.7071",
        ),
        (
            "count = 50",
            "count = 0",
            "steps.count",
            "must be >= 1 (got 0)",
        ),
        (
            "density = 0.0",
            "density = -1.0",
            "material.density",
            "must be >= 0",
        ),
        (
            "checkpoint_keep = 3",
            "checkpoint_keep = 0",
            "output.checkpoint_keep",
            ">= 1",
        ),
        (
            "newton_rtol = 1e-9",
            "newton_rtol = 0.0",
            "solver.newton_rtol",
            "> 0 and < 1",
        ),
        (
            "newton_max_it = 25",
            "newton_max_it = 0",
            "solver.newton_max_it",
            ">= 1",
        ),
        ("g = [0.0, 0.0]", "g = [0.0, nan]", "gravity.g", "finite"),
        (
            "name = \"cantilever\"",
            "name = \"\"",
            "name",
            "must not be empty",
        ),
        (
            "size = [10.0, 1.0]",
            "size = [10.0, -1.0]",
            "body.rectangles[0].size",
            "> 0",
        ),
        (
            "size = [10.0, 1.0]",
            "size = [10.05, 1.0]",
            "body.rectangles[0].size",
            "whole number",
        ),
        (
            "rectangles = [{ origin = [0.0, 0.0], size = [10.0, 1.0] }]",
            "rectangles = []",
            "body.rectangles",
            "at least one",
        ),
        (
            "at = [10.0, 0.5]",
            "at = [12.0, 0.5]",
            "point_load[0].at",
            "within one particle spacing",
        ),
        (
            "dofs = [\"x\", \"y\"]",
            "dofs = []",
            "fixed[0].dofs",
            "at least one",
        ),
        (
            "dofs = [\"x\", \"y\"]",
            "dofs = [\"x\", \"x\"]",
            "fixed[0].dofs",
            "lists \"x\" twice",
        ),
        (
            "model = \"linear-elastic\"",
            "model = \"tresca\"",
            "material.cu",
            "must be > 0 for model \"tresca\" (got 0)",
        ),
        (
            "kind = \"cantilever\"",
            "kind = \"footing\"",
            "history.kind",
            "no [[prescribed]]",
        ),
        ("h = 0.125", "h = 1e-6", "mesh.h", "more than the limit"),
    ];
    for (from, to, field, text) in cases {
        let e = edited(from, to).expect_err(to);
        assert_eq!(e.field.as_deref(), Some(field), "{to}: {e}");
        assert!(e.message.contains(text), "{to}: {e}");
        assert!(e
            .to_string()
            .starts_with(&format!("scene 'cantilever.toml': field {field}: ")));
    }
}

#[test]
fn toml_syntax_error_gives_line() {
    let e = edited("h = 0.125", "h = = 0.125").unwrap_err();
    assert!(
        e.message.starts_with("invalid TOML at line 9, column 5: "),
        "{e}"
    );
    assert!(!e.message.contains('\n'), "{e}");
    assert!(e.field.is_none());
}

#[test]
fn set_overrides_values() {
    let s = with_sets(&["mesh.h=0.25", "steps.count=20"]).unwrap();
    assert_eq!(s.mesh.h, 0.25);
    assert_eq!(s.steps.count, 20);
    let s = with_sets(&["mesh.h=0.25", "mesh.h=0.5"]).unwrap();
    assert_eq!(s.mesh.h, 0.5, "the last --set wins");
    let s = with_sets(&[
        "material.model=tresca",
        "material.cu=50e3",
        "gravity.g=[0.0, -9.81]",
        "point_load[0].force=[0.0, -5.0e4]",
        "fixed[0].dofs=[\"y\", \"x\"]",
        "mesh.h=1",
    ])
    .unwrap();
    assert_eq!(s.material.model, MaterialModel::Tresca);
    assert_eq!(s.material.cu, 50e3);
    assert_eq!(s.gravity.g, [0.0, -9.81]);
    assert_eq!(s.point_load[0].force, [0.0, -5.0e4]);
    assert_eq!(s.fixed[0].dofs, vec![Dof::Y, Dof::X]);
    assert_eq!(s.mesh.h, 1.0, "an integer is accepted for a number");
}

#[test]
fn set_defaults_that_the_file_omits() {
    // --set must reach tables and keys that are absent from the text (defaults).
    let text = CANTILEVER.replace("[solver]\nnewton_max_it = 25\nnewton_rtol = 1e-9\n", "");
    assert!(!text.contains("[solver]"));
    let sets = vec!["solver.newton_max_it=40".to_string()];
    let s = Scene::from_toml(&text, "cantilever.toml", &sets).unwrap();
    assert_eq!(s.solver.newton_max_it, 40);
    assert_eq!(s.solver.newton_rtol, 1e-9);
}

#[test]
fn set_errors_name_the_path() {
    let e = with_sets(&["mesh.hh=0.2"]).unwrap_err();
    assert_eq!(e.set.as_deref(), Some("mesh.hh=0.2"));
    assert_eq!(e.field.as_deref(), Some("mesh.hh"));
    assert!(
        e.to_string()
            .starts_with("scene 'cantilever': --set mesh.hh=0.2: field mesh.hh: no such key"),
        "{e}"
    );

    let e = with_sets(&["mseh.h=0.2"]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("mseh"), "{e}");
    assert_eq!(e.set.as_deref(), Some("mseh.h=0.2"));

    let e = with_sets(&["point_load[3].force=[0.0, 1.0]"]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("point_load[3]"), "{e}");

    let e = with_sets(&["mesh.h.x=1"]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("mesh.h"), "{e}");
    assert!(e.message.contains("not a table"), "{e}");

    let e = with_sets(&["steps.count=abc"]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene 'cantilever': --set steps.count=abc: field steps.count: \
         expected a whole number >= 0, found string \"abc\""
    );

    let e = with_sets(&["mesh.h=-1"]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "scene 'cantilever': --set mesh.h=-1: field mesh.h: must be > 0 (got -1)"
    );

    let e = with_sets(&["mesh.h"]).unwrap_err();
    assert_eq!(e.set.as_deref(), Some("mesh.h"));
    assert!(e.message.contains("KEY=VALUE"), "{e}");

    let e = with_sets(&["mesh.h=0.1.2"]).unwrap_err();
    assert!(e.message.contains("cannot read value"), "{e}");
}

#[test]
fn load_scene_by_path_and_unknown_name() {
    let e = load_scene("cantileverr", &[]).unwrap_err();
    assert!(
        e.message
            .contains("cantilever, footing-shallow, block-compression"),
        "{e}"
    );
    let e = load_scene("/nonexistent/dir/scene.toml", &[]).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("scene '/nonexistent/dir/scene.toml': cannot read"),
        "{e}"
    );

    let dir = std::env::temp_dir().join(format!("pfem-scene-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("beam.toml");
    std::fs::write(
        &path,
        CANTILEVER.replace("name = \"cantilever\"", "name = \"beam\""),
    )
    .unwrap();
    let (s, resolved) = load_scene(path.to_str().unwrap(), &["steps.count=7".to_string()]).unwrap();
    assert_eq!(s.name, "beam");
    assert_eq!(s.steps.count, 7);
    assert!(resolved.contains("count = 7"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rigid_platen_needs_a_one_sided_face() {
    let set = |w: &str| {
        load_scene("block-compression", &[format!("prescribed[0].where={w}")]).map(|(s, _)| s)
    };
    let (block, _) = load_scene("block-compression", &[]).unwrap();
    assert_eq!(block.prescribed[0].select, Selection::Current);
    let e = set("\"y >= 1 and y <= 2\"").unwrap_err();
    assert_eq!(e.field.as_deref(), Some("prescribed[0].where"), "{e}");
    assert!(e.message.contains("bounded on one side only in y"), "{e}");
    let e = load_scene(
        "block-compression",
        &["prescribed[0].select=\"now\"".into()],
    )
    .unwrap_err();
    assert_eq!(e.field.as_deref(), Some("prescribed[0].select"), "{e}");
}

#[test]
fn line_search_is_a_named_choice() {
    let s = with_sets(&["solver.line_search=\"l2\""]).unwrap();
    assert_eq!(s.solver.line_search, LineSearch::L2);
    let e = with_sets(&["solver.line_search=\"newton\""]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("solver.line_search"), "{e}");
}

#[test]
fn linear_solver_is_a_named_choice() {
    let s = with_sets(&[]).unwrap();
    assert_eq!(s.solver.linear, LinearChoice::Auto);
    let s = with_sets(&["solver.linear=\"iterative\""]).unwrap();
    assert_eq!(s.solver.linear, LinearChoice::Iterative);
    let e = with_sets(&["solver.linear=\"gmres\""]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("solver.linear"), "{e}");
    assert!(e.to_string().contains("gmres"), "{e}");
}

#[test]
fn mesh_adapt_defaults_round_trip_and_bad_values_name_the_field() {
    let s = with_sets(&["mesh.adapt={h_min=0.05,h_max=0.4}"]).unwrap();
    let a = s.mesh.adapt.expect("adapt set");
    assert_eq!((a.h_min, a.h_max), (0.05, 0.4));
    assert_eq!(
        (a.refine_above, a.coarsen_below, a.grading, a.every),
        (0.1, 0.01, 1.5, 1)
    );
    assert_eq!(Scene::from_toml(&s.to_toml(), "x", &[]).unwrap(), s);
    assert!(with_sets(&[]).unwrap().mesh.adapt.is_none());
    assert!(!with_sets(&[]).unwrap().to_toml().contains("adapt"));
    let cases = [
        ("{h_min=0.0,h_max=0.4}", "mesh.adapt.h_min", "must be > 0"),
        (
            "{h_min=0.5,h_max=0.4}",
            "mesh.adapt.h_max",
            "larger than h_min",
        ),
        (
            "{h_min=0.05,h_max=0.4,refine_above=1.5}",
            "mesh.adapt.refine_above",
            "(0, 1]",
        ),
        (
            "{h_min=0.05,h_max=0.4,coarsen_below=0.2}",
            "mesh.adapt.coarsen_below",
            "smaller than refine_above",
        ),
        (
            "{h_min=0.05,h_max=0.4,grading=3.0}",
            "mesh.adapt.grading",
            "[1.2, 2]",
        ),
        ("{h_min=0.05,h_max=0.4,every=0}", "mesh.adapt.every", ">= 1"),
        ("{h_min=1e-6,h_max=0.4}", "mesh.adapt.h_min", "particles"),
        (
            "{h_min=0.05,h_max=0.4,indicator=\"error\"}",
            "mesh.adapt.indicator",
            "error",
        ),
        ("{h_min=0.05,h_max=0.4,hmin=0.1}", "mesh.adapt.hmin", "hmin"),
    ];
    for (value, field, needle) in cases {
        let set = format!("mesh.adapt={value}");
        let e = with_sets(&[&set]).unwrap_err();
        assert_eq!(e.field.as_deref(), Some(field), "{set}: {e}");
        assert!(e.to_string().contains(needle), "{set}: {e}");
        assert!(e.to_string().contains("scene 'cantilever'"), "{e}");
    }
    let e = with_sets(&["mesh.refine=false", "mesh.adapt={h_min=0.05,h_max=0.4}"]).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("mesh.adapt"), "{e}");
    assert!(e.to_string().contains("mesh.refine"), "{e}");
    // In a scene file, the file is named.
    let e = edited(
        "refine = true",
        "refine = true\nadapt = { h_min = 0.05, h_max = 0.01 }",
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("scene 'cantilever.toml': field mesh.adapt.h_max"),
        "{e}"
    );
}

/// The committed scene reference is what the schema generates (regenerate with `pfem-mpi schema >
/// docs/guide/scene-reference.md`).
#[test]
fn the_committed_scene_reference_is_up_to_date() {
    let committed = include_str!("../../docs/guide/scene-reference.md");
    assert!(
        committed == super::REFERENCE,
        "docs/guide/scene-reference.md differs from the schema: regenerate it with \
         `pfem-mpi schema > docs/guide/scene-reference.md`"
    );
    for key in [
        "`[[body.zones]]`",
        "`mesh`",
        "`within`",
        "`equilibrate`",
        "`cu_gradient`",
    ] {
        assert!(committed.contains(key), "{key} is missing");
    }
}

#[test]
fn a_summed_force_names_bodies_that_exist() {
    let sets = |m: &str| vec![format!("history.columns=[{{name=\"F\",measure=\"{m}\"}}]")];
    assert!(load_scene("tbar-smooth", &sets("rigid.tbar+tbar.fy")).is_ok());
    let e = load_scene("tbar-smooth", &sets("rigid.tbar+shaft.fy")).unwrap_err();
    assert_eq!(
        e.field.as_deref(),
        Some("history.columns[0].measure"),
        "{e}"
    );
    assert!(e.to_string().contains("names no"), "{e}");
}

#[test]
fn edge_rounding_belongs_to_axisymmetric_tresca_and_names_its_field() {
    let load = |name: &str, set: &str| load_scene(name, &[set.to_string()]).map(|(s, _)| s);
    let ball = load("ball", "material.edge_rounding=0.05").expect("valid");
    assert_eq!(ball.material.edge_rounding, Some(0.05));
    // It reaches the model: squeezed axially with σr = σθ, the stress ends on the edge of
    // the prism rounded by 5 %.
    let model = crate::model::materials_of(&ball).expect("builds");
    let cu = ball.material.cu;
    let e = 50.0 * cu / ball.material.young;
    let out = model[0]
        .update(
            &crate::material::GaussState::stressed([0.0; 4], 0),
            &[e, -2.0 * e, e, 0.0],
        )
        .expect("returns");
    let spread = out.s[0] - out.s[1];
    let edge = crate::material::rounded_prism::edge_strength(cu, 0.05);
    assert!((spread - edge).abs() < 1e-9 * cu, "{spread} vs {edge}");
    for (scene, set, says) in [
        (
            "ball",
            "material.edge_rounding=0.0",
            "must be > 0 and <= 0.1 (got 0)",
        ),
        ("ball", "material.edge_rounding=0.2", "(got 0.2)"),
        (
            "footing",
            "material.edge_rounding=0.05",
            "applies only with analysis",
        ),
        ("cantilever", "material.edge_rounding=0.05", "\"tresca\""),
    ] {
        let err = load(scene, set).expect_err(set).to_string();
        assert!(
            err.contains("material.edge_rounding") && err.contains(says),
            "{scene} {set}: {err}"
        );
    }
}
