//! `--progress json`: one JSON object per line on stdout, for scripts. A step's object carries
//! what its human line does, under stable names, plus its `history.csv` row by column name; the
//! run's last object (`"event": "done"`) its totals. A number that is not finite is `null`.

use super::StepReport;
use serde_json::{json, Map, Value};

/// What the step objects share with the human line, gathered by the caller.
pub struct StepFacts<'a> {
    pub step: u64,
    pub steps: u64,
    pub time: f64,
    pub load_factor: f64,
    pub report: &'a StepReport,
    /// Seconds per phase of the step, in the order they ran.
    pub phases: &'a [(&'static str, f64)],
    pub wall: f64,
    pub left: f64,
    /// The step's `history.csv` row after `step`, with the header's names (None when the step
    /// wrote no row: a collapse in its first piece).
    pub history: Option<(&'a [String], &'a [f64])>,
}

pub fn step_object(f: &StepFacts) -> String {
    let r = f.report;
    let phases: Map<String, Value> = f
        .phases
        .iter()
        .map(|(name, s)| (name.to_string(), json!(s)))
        .collect();
    let history = f.history.map(|(names, values)| {
        names
            .iter()
            .zip(values)
            .map(|(n, v)| (n.clone(), json!(v)))
            .collect::<Map<String, Value>>()
    });
    json!({
        "event": "step",
        "step": f.step,
        "steps": f.steps,
        "progress": f.step as f64 / f.steps.max(1) as f64,
        "time": f.time,
        "load_factor": f.load_factor,
        "newton": r.newton_iterations,
        "cuts": r.cuts,
        "linear": r.linear_iterations,
        "residual": r.residual_norm,
        "particles": r.particles,
        "triangles": r.triangles,
        "remapped": r.remapped,
        "contact_seconds": r.contact_seconds,
        "contact_switches": r.contact_switches,
        "phases": phases,
        "wall": f.wall,
        "left": f.left,
        "history": history,
    })
    .to_string()
}

/// The run's totals, after its last step.
pub fn done_object(step: u64, wall: f64, newton: usize, linear: usize, contact: f64) -> String {
    json!({
        "event": "done",
        "step": step,
        "wall": wall,
        "newton": newton,
        "linear": linear,
        "contact_seconds": contact,
    })
    .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_object_names_every_value_and_its_history_columns() {
        let report = StepReport {
            newton_iterations: 3,
            linear_iterations: 7,
            cuts: 1,
            residual_norm: 2.5e-10,
            particles: 608,
            triangles: 1111,
            ..StepReport::default()
        };
        let names = ["lambda".to_string(), "u_over_L".to_string()];
        let values = [1.0, f64::INFINITY];
        let text = step_object(&StepFacts {
            step: 4,
            steps: 10,
            time: 0.4,
            load_factor: 0.4,
            report: &report,
            phases: &[("remesh", 0.5), ("solve", 1.25)],
            wall: 1.75,
            left: 10.5,
            history: Some((&names, &values)),
        });
        assert!(!text.contains('\n'), "one line: {text}");
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["event"], "step");
        assert_eq!(v["step"], 4);
        assert_eq!(v["progress"], 0.4);
        assert_eq!(v["newton"], 3);
        assert_eq!(v["cuts"], 1);
        assert_eq!(v["linear"], 7);
        assert_eq!(v["residual"], 2.5e-10);
        assert_eq!(v["phases"]["solve"], 1.25);
        assert_eq!(v["wall"], 1.75);
        assert_eq!(v["history"]["lambda"], 1.0);
        assert!(v["history"]["u_over_L"].is_null(), "not finite: null");
        let none = step_object(&StepFacts {
            step: 1,
            steps: 1,
            time: 0.0,
            load_factor: 0.0,
            report: &report,
            phases: &[],
            wall: 0.0,
            left: 0.0,
            history: None,
        });
        let v: Value = serde_json::from_str(&none).unwrap();
        assert!(v["history"].is_null());
    }

    #[test]
    fn the_done_object_has_the_totals() {
        let v: Value = serde_json::from_str(&done_object(10, 0.78, 20, 31, 0.0)).unwrap();
        assert_eq!(v["event"], "done");
        assert_eq!(
            (v["step"].as_u64(), v["newton"].as_u64()),
            (Some(10), Some(20))
        );
        assert_eq!(v["linear"], 31);
    }
}
