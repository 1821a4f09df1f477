//! Reading a run's `--progress json` stdout: one JSON object per line, nothing else.

use serde_json::Value;

/// Every object of `stdout`, failing the test on a line that is not one (the mode's contract:
/// stdout carries JSON only).
pub fn json_objects(stdout: &str) -> Vec<Value> {
    stdout
        .lines()
        .map(|l| {
            serde_json::from_str(l)
                .unwrap_or_else(|e| panic!("not a JSON object ({e}) under --progress json: {l}"))
        })
        .collect()
}

/// The `"event": "step"` objects of `stdout`, in step order.
pub fn json_steps(stdout: &str) -> Vec<Value> {
    json_objects(stdout)
        .into_iter()
        .filter(|o| o["event"] == "step")
        .collect()
}
