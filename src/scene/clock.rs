//! The time of a scene's steps, for rate-dependent materials (and a UMAT's TIME and DTIME).
//!
//! A scene is quasi-static: its steps are load-factor increments. It gets a time in seconds in
//! one of two ways (not both):
//! - `[steps] duration = T`: step k of N runs from (k − 1) T / N to k T / N;
//! - a `duration` (s) or a `velocity` (m/s, the stage lasts its travel over it) on every stage of
//!   one `[[rigid]]` body, the one whose stages set the step count: a stage's steps share its
//!   duration evenly, so a T-bar penetrated and then cycled at 20 mm/s has steps of different
//!   lengths in the two kinds of stage if their step sizes differ.
//!
//! Without either, the scene has no time, and a model that needs one is an error naming its
//! field (a rate-dependent model silently made rate-independent would be a lie).

use super::field_path::FieldPath;
use super::rigid::Rigid;
use super::schema::{MaterialModel, Scene};

type Invalid = (FieldPath, String);

/// The duration (s) of each stage of `r`, when every stage is timed.
fn stage_durations(r: &Rigid) -> Option<Vec<f64>> {
    let mut from = [0.0; 2];
    let mut out = Vec::with_capacity(r.stages.len());
    for s in &r.stages {
        let travel = (s.to[0] - from[0]).hypot(s.to[1] - from[1]);
        from = s.to;
        out.push(match (s.duration, s.velocity) {
            (Some(d), _) => d,
            (None, Some(v)) => travel / v,
            (None, None) => return None,
        });
    }
    (!out.is_empty()).then_some(out)
}

/// The body whose timed stages give the scene its time.
fn timed_body(s: &Scene) -> Option<(usize, Vec<f64>)> {
    s.rigid
        .iter()
        .enumerate()
        .find_map(|(i, r)| stage_durations(r).map(|d| (i, d)))
}

/// Whether the scene's steps have a time in seconds.
pub fn timed(s: &Scene) -> bool {
    s.steps.duration.is_some() || timed_body(s).is_some()
}

/// The time (s) at load factor `lambda` (a cut step's fraction included), None for a scene
/// without time. Linear within a step; past the timed body's last stage, the time stops.
pub fn time_at(s: &Scene, lambda: f64) -> Option<f64> {
    if let Some(t) = s.steps.duration {
        return Some(lambda * t);
    }
    let (i, durations) = timed_body(s)?;
    let step = lambda * s.steps.count as f64;
    let mut start = 0.0;
    let mut time = 0.0;
    for (st, d) in s.rigid[i].stages.iter().zip(&durations) {
        let n = st.steps as f64;
        if step <= start + n {
            return Some(time + (step - start).max(0.0) / n * d);
        }
        start += n;
        time += d;
    }
    Some(time)
}

/// The timing keys are consistent, and a material that needs time has it.
pub fn check(s: &Scene) -> Result<(), Invalid> {
    let steps = FieldPath::key("steps").join("duration");
    if let Some(t) = s.steps.duration {
        if !(t.is_finite() && t > 0.0) {
            return Err((steps, format!("must be > 0 seconds (got {t})")));
        }
    }
    let mut timed_bodies = Vec::new();
    for (i, r) in s.rigid.iter().enumerate() {
        let path = FieldPath::key("rigid").at(i).join("stages");
        let mut from = [0.0; 2];
        let mut any = None;
        let mut untimed = None;
        for (k, st) in r.stages.iter().enumerate() {
            let at = path.at(k);
            let travel = (st.to[0] - from[0]).hypot(st.to[1] - from[1]);
            from = st.to;
            match (st.duration, st.velocity) {
                (Some(_), Some(_)) => {
                    return Err((
                        at.join("velocity"),
                        "and duration both time the stage: give one".to_string(),
                    ))
                }
                (Some(d), None) if !(d.is_finite() && d > 0.0) => {
                    return Err((
                        at.join("duration"),
                        format!("must be > 0 seconds (got {d})"),
                    ))
                }
                (None, Some(v)) if !(v.is_finite() && v > 0.0) => {
                    return Err((at.join("velocity"), format!("must be > 0 m/s (got {v})")))
                }
                (None, Some(_)) if travel == 0.0 => {
                    return Err((
                        at.join("velocity"),
                        "times a stage that does not move the body: give its duration".to_string(),
                    ))
                }
                (None, None) => untimed = untimed.or(Some(k)),
                _ => any = any.or(Some(k)),
            }
        }
        match (any, untimed) {
            (Some(k), Some(u)) => {
                return Err((
                    path.at(u),
                    format!(
                        "has no duration or velocity, but stage {k} of this body is timed: time \
                         every stage of the body"
                    ),
                ))
            }
            (Some(_), None) => timed_bodies.push(i),
            _ => {}
        }
    }
    if let Some(&i) = timed_bodies.get(1) {
        return Err((
            FieldPath::key("rigid").at(i).join("stages"),
            format!(
                "are timed, and so are rigid[{}]'s: the steps take their time from one body",
                timed_bodies[0]
            ),
        ));
    }
    if let Some(&i) = timed_bodies.first() {
        let path = FieldPath::key("rigid").at(i).join("stages");
        if s.steps.duration.is_some() {
            return Err((
                steps,
                format!("and the timed stages of rigid[{i}] both give the steps a time: give one"),
            ));
        }
        if s.rigid[i].stage_steps() != s.steps.count as u64 {
            return Err((
                path,
                format!(
                    "take {} steps but the run takes {}: the timed body must be the one whose \
                     stages set the step count",
                    s.rigid[i].stage_steps(),
                    s.steps.count
                ),
            ));
        }
    }
    let all = s.material.all();
    for (i, m) in all.iter().enumerate() {
        let rate = m.rate_parameter.unwrap_or(0.0);
        if m.model == MaterialModel::TrescaSoftening && rate > 0.0 && !timed(s) {
            let at = match all.len() {
                1 => FieldPath::key("material"),
                _ => FieldPath::key("material").at(i),
            };
            return Err((
                at.join("rate_parameter"),
                format!(
                    "is {rate}: a rate-dependent strength needs the time of the steps, from \
                     [steps] duration (s) or a duration or velocity on every [[rigid]] stage \
                     of the driving body (or rate_parameter = 0)"
                ),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    const TBAR: &str = r#"
name = "t"
[body]
rectangles = [{ origin = [0.0, 0.0], size = [1.0, 1.0] }]
[mesh]
h = 0.25
[material]
model = "tresca"
young = 1e6
poisson = 0.49
cu = 1e3
[[fixed]]
where = "y <= 0"
dofs = ["x", "y"]
[[rigid]]
name = "bar"
circle = { centre = [0.5, 1.2], radius = 0.15 }
stages = [{ to = [0.0, -0.02], steps = 4, velocity = 0.01 }, { to = [0.0, 0.0], steps = 2, duration = 1.0 }, { to = [0.0, 0.0], steps = 2, duration = 6.0 }]
[history]
columns = [{ name = "f", measure = "rigid.bar.fy" }]
"#;

    #[test]
    fn stages_give_each_step_its_time() {
        let s = Scene::from_toml(TBAR, "t.toml", &[]).expect("valid");
        assert_eq!(s.steps.count, 8);
        assert!(timed(&s));
        // 2 s for the first stage's 4 steps, 1 s for the next 2, 6 s for the last 2.
        let t = |step: f64| time_at(&s, step / 8.0).unwrap();
        assert!((t(1.0) - 0.5).abs() < 1e-15);
        assert!((t(4.0) - 2.0).abs() < 1e-15);
        assert!((t(5.0) - 2.5).abs() < 1e-15);
        assert!((t(6.5) - 4.5).abs() < 1e-15);
        assert!((t(8.0) - 9.0).abs() < 1e-15);
    }

    #[test]
    fn a_whole_run_duration_is_spread_evenly() {
        let toml = TBAR
            .replace(", velocity = 0.01", "")
            .replace(", duration = 1.0", "");
        let toml = toml.replace(", duration = 6.0", "") + "[steps]\nduration = 16.0\n";
        let s = Scene::from_toml(&toml, "t.toml", &[]).expect("valid");
        assert!((time_at(&s, 0.25).unwrap() - 4.0).abs() < 1e-15);
        let none = TBAR.replace(", velocity = 0.01", "");
        let none = none
            .replace(", duration = 1.0", "")
            .replace(", duration = 6.0", "");
        let s = Scene::from_toml(&none, "t.toml", &[]).expect("valid");
        assert!(!timed(&s) && time_at(&s, 0.5).is_none());
    }

    #[test]
    fn bad_timing_names_the_field() {
        for (from, to, field) in [
            (
                ", velocity = 0.01",
                ", velocity = -1.0",
                "rigid[0].stages[0].velocity",
            ),
            (", duration = 1.0", "", "rigid[0].stages[1]"),
            (
                ", duration = 1.0",
                ", duration = 0.0",
                "rigid[0].stages[1].duration",
            ),
            (
                ", duration = 6.0",
                ", velocity = 1.0",
                "rigid[0].stages[2].velocity",
            ),
            (
                ", duration = 1.0",
                ", duration = 1.0, velocity = 2.0",
                "rigid[0].stages[1].velocity",
            ),
            (
                "[history]",
                "[steps]\nduration = 3.0\n[history]",
                "steps.duration",
            ),
            (
                "[history]",
                "[steps]\nduration = -3.0\n[history]",
                "steps.duration",
            ),
        ] {
            let toml = TBAR.replace(from, to);
            let err = Scene::from_toml(&toml, "t.toml", &[])
                .expect_err(field)
                .to_string();
            assert!(err.contains(field), "{field}: {err}");
        }
    }
}
