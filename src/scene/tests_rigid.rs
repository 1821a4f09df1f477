//! Issue 32's validation findings on its base scene (a pipe resting on elastic ground): loads
//! and probes that select nothing or the wrong thing, and stage and contact settings, are
//! refused at `new` with the field that is wrong.

use super::*;

const PIPE: &str = include_str!("../../tests/scenes/pipe-on-ground.toml");

/// The field and message of the error the base scene with `sets` gives.
fn refused(sets: &[&str]) -> (String, String) {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    let e = Scene::from_toml(PIPE, "pipe.toml", &sets).expect_err("the scene must be refused");
    (e.field.clone().unwrap_or_default(), e.message)
}

fn accepted(sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Scene::from_toml(PIPE, "pipe.toml", &sets).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_surface_pressure_on_no_boundary_edge_is_refused() {
    accepted(&[r#"surface_pressure=[{ where = "y >= 0.2", pressure = 1e3 }]"#]);
    for region in [
        "y >= 5",
        "y >= 0.05 and y <= 0.15 and x >= 0.2 and x <= 0.4",
        "y >= 0.2 and x >= 0.295 and x <= 0.305",
    ] {
        let set = format!(r#"surface_pressure=[{{ where = "{region}", pressure = 1e3 }}]"#);
        let (field, message) = refused(&[&set]);
        assert_eq!(field, "surface_pressure[0].where", "{message}");
        assert!(message.contains("selects no boundary edge"), "{message}");
    }
}

#[test]
fn a_probe_off_the_soil_is_refused() {
    accepted(&[r#"probe=[{ name = "top", at = [0.3, 0.2] }]"#]);
    let (field, message) = refused(&[r#"probe=[{ name = "far", at = [10.3, 0.2] }]"#]);
    assert_eq!(field, "probe[0].at", "{message}");
    assert!(message.contains("within one particle spacing"), "{message}");
    let (field, message) = refused(&[r#"probe=[{ name = "in", at = [0.3, 0.22] }]"#]);
    assert_eq!(field, "probe[0].at", "{message}");
    assert!(
        message.contains("inside the rigid body \"pipe\""),
        "{message}"
    );
}

#[test]
fn a_geostatic_surface_below_the_ground_is_refused() {
    accepted(&["geostatic.surface=0.3"]);
    let (field, message) = refused(&["geostatic.surface=-1"]);
    assert_eq!(field, "geostatic.surface", "{message}");
    assert!(message.contains("tension"), "{message}");
}

#[test]
fn stage_errors_name_the_stages_not_the_step_count() {
    let (field, message) = refused(&["rigid[0].stages=[{ to = [0.0, -0.01], steps = 0 }]"]);
    assert_eq!(field, "rigid[0].stages[0].steps", "{message}");
    let (field, message) = refused(&["rigid[0].stages=[]"]);
    assert_eq!(field, "rigid[0].stages", "{message}");
    assert!(message.contains("steps.count is left out"), "{message}");
    assert_eq!(
        accepted(&["rigid[0].stages=[]", "steps.count=2"])
            .steps
            .count,
        2
    );
    let huge = "rigid[0].stages=[{ to = [0.0, -0.01], steps = 4294967295 }, \
                { to = [0.0, -0.02], steps = 4294967295 }]";
    let (field, message) = refused(&[huge]);
    assert_eq!(field, "rigid[0].stages", "{message}");
    assert!(message.contains("8589934590"), "{message}");
}

#[test]
fn contact_settings_out_of_their_working_range_are_refused() {
    for (set, field) in [
        ("contact.penalty=1e30", "contact.penalty"),
        ("contact.penalty=1e-12", "contact.penalty"),
        ("contact.tolerance=1e-300", "contact.tolerance"),
        ("contact.tolerance=0.5", "contact.tolerance"),
    ] {
        let (got, message) = refused(&[set]);
        assert_eq!(got, field, "{set}: {message}");
    }
    accepted(&["contact.penalty=1e7", "contact.tolerance=1e-9"]);
    // No longer read, but older scenes that set it still load.
    accepted(&["contact.max_augmentations=1"]);
}

#[test]
fn an_ambient_pressure_beyond_its_bound_is_refused() {
    accepted(&["rigid[0].ambient_pressure=1e9"]);
    for a in ["1e300", "1.1e9", "-1"] {
        let (field, message) = refused(&[&format!("rigid[0].ambient_pressure={a}")]);
        assert_eq!(field, "rigid[0].ambient_pressure", "{message}");
    }
}

/// Findings 1 and 3: a body that jumps through the soil in a step, or is thinner than the
/// spacing, went through with zero force and exit 0.
#[test]
fn bodies_the_cloud_cannot_resolve_are_refused() {
    let (field, message) = refused(&["rigid[0].stages=[{ to = [0.0, -1.0], steps = 1 }]"]);
    assert_eq!(field, "rigid[0].stages[0].steps", "{message}");
    assert!(message.contains("at least 50 steps"), "{message}");
    let sideways = [
        "rigid[0].circle={ centre = [0.3, 0.1], radius = 0.02 }",
        "rigid[0].stages=[{ to = [1.0, 0.0], steps = 1 }]",
    ];
    assert_eq!(refused(&sideways).0, "rigid[0].stages[0].steps");
    // Far above the soil a body may move fast.
    accepted(&[
        "rigid[0].circle={ centre = [0.3, 2.0], radius = 0.02 }",
        "rigid[0].stages=[{ to = [0.0, 1.0], steps = 1 }]",
    ]);
    for thin in [
        "rigid[0].circle={ centre = [0.3, 0.202], radius = 0.002 }",
        "rigid[0].circle={ centre = [0.3, 0.2000001], radius = 1e-7 }",
    ] {
        let (field, message) = refused(&[thin]);
        assert_eq!(field, "rigid[0].circle.radius", "{message}");
        assert!(message.contains("wide across its motion"), "{message}");
    }
    let plate = "rigid=[{ name = \"pipe\", polygon = { vertices = [[0.299, 0.2], [0.301, 0.2], \
                 [0.301, 0.3], [0.299, 0.3]] }, stages = [{ to = [0.0, -0.01], steps = 3 }] }]";
    let (field, message) = refused(&[plate]);
    assert_eq!(field, "rigid[0].polygon", "{message}");
    // The same plate lying flat, pressed down, spans many particles.
    let flat = "rigid=[{ name = \"pipe\", polygon = { vertices = [[0.2, 0.2], [0.4, 0.2], \
                [0.4, 0.202], [0.2, 0.202]] }, stages = [{ to = [0.0, -0.01], steps = 3 }] }]";
    accepted(&[flat]);
    accepted(&["rigid[0].circle={ centre = [0.3, 0.21], radius = 0.01 }"]);
}
