//! Hooks for tests only, read once from the environment; a run without these variables never
//! takes any of these paths.
//!
//! - `PFEM_INJECT_FAULT=RANK:PHASE:KIND[:STEP]` makes rank RANK fail at the start of PHASE
//!   (`load`, `remesh`, `map`, `solve`, `output`, `checkpoint`, `balance`) of step STEP (default
//!   1; ignored for `load`): KIND `error` returns an error there on that rank alone, `panic` panics. The tests check
//!   that one rank's failure ends the whole job with its message instead of leaving the other
//!   ranks waiting in a collective.
//! - `PFEM_TEST_REPARTITION=rotate` repartitions after every step and hands every particle to
//!   the next rank, so that the tests can check that a repartition changes no result.

use super::RunError;
use std::sync::OnceLock;

const PHASES: [&str; 7] = [
    "load",
    "remesh",
    "map",
    "solve",
    "output",
    "checkpoint",
    "balance",
];

#[derive(Debug, Clone, PartialEq)]
struct Fault {
    rank: i32,
    phase: String,
    panic: bool,
    step: u64,
}

/// A `PFEM_INJECT_FAULT` that cannot be parsed, and why.
#[derive(Debug, Clone)]
pub struct FaultSpec {
    spec: String,
    why: String,
}

impl std::fmt::Display for FaultSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let FaultSpec { spec, why } = self;
        write!(
            f,
            "PFEM_INJECT_FAULT={spec}: {why} (RANK:PHASE:KIND[:STEP])"
        )
    }
}

fn parse(spec: &str) -> Result<Fault, FaultSpec> {
    let bad = |why: &str| FaultSpec {
        spec: spec.to_string(),
        why: why.to_string(),
    };
    let parts: Vec<&str> = spec.split(':').collect();
    if !(3..=4).contains(&parts.len()) {
        return Err(bad("expected 3 or 4 fields"));
    }
    let rank = parts[0].parse().map_err(|_| bad("RANK is not a number"))?;
    if !PHASES.contains(&parts[1]) {
        return Err(bad(&format!("PHASE is one of {}", PHASES.join(", "))));
    }
    let panic = match parts[2] {
        "error" => false,
        "panic" => true,
        _ => return Err(bad("KIND is error or panic")),
    };
    let step = match parts.get(3) {
        Some(s) => s.parse().map_err(|_| bad("STEP is not a number"))?,
        None => 1,
    };
    Ok(Fault {
        rank,
        phase: parts[1].to_string(),
        panic,
        step,
    })
}

fn fault() -> &'static Result<Option<Fault>, FaultSpec> {
    static FAULT: OnceLock<Result<Option<Fault>, FaultSpec>> = OnceLock::new();
    FAULT.get_or_init(|| match std::env::var("PFEM_INJECT_FAULT") {
        Ok(spec) => parse(&spec).map(Some),
        Err(_) => Ok(None),
    })
}

/// Not collective (that is the point): fails on the injected rank at the start of `phase` of
/// `step` (the step being made), as `PFEM_INJECT_FAULT` asks.
pub(super) fn inject(rank: i32, phase: &str, step: u64) -> Result<(), RunError> {
    let f = match fault() {
        Ok(Some(f)) => f,
        Ok(None) => return Ok(()),
        Err(e) => return Err(e.clone().into()),
    };
    // Loading happens once, before any step.
    if f.rank != rank || f.phase != phase || (f.step != step && phase != "load") {
        return Ok(());
    }
    let error = RunError::InjectedFault {
        phase: phase.to_string(),
        step,
        rank,
    };
    if f.panic {
        panic!("{error}");
    }
    Err(error)
}

/// Whether `PFEM_TEST_REPARTITION=rotate` asks for a rotated repartition after every step.
pub(super) fn rotate_partition() -> bool {
    static ROTATE: OnceLock<bool> = OnceLock::new();
    *ROTATE.get_or_init(|| std::env::var("PFEM_TEST_REPARTITION").is_ok_and(|v| v == "rotate"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fault_specs_parse_or_say_what_is_wrong() {
        let f = parse("1:solve:panic").unwrap();
        assert_eq!(
            (f.rank, f.phase.as_str(), f.panic, f.step),
            (1, "solve", true, 1)
        );
        assert_eq!(parse("0:output:error:3").unwrap().step, 3);
        assert!(parse("1:mesh:error")
            .unwrap_err()
            .to_string()
            .contains("PHASE is one of"));
        assert!(parse("1:solve:crash")
            .unwrap_err()
            .to_string()
            .contains("KIND"));
        assert!(parse("x:solve:error")
            .unwrap_err()
            .to_string()
            .contains("RANK"));
        assert!(parse("1:solve").unwrap_err().to_string().contains("3 or 4"));
    }
}
