//! Issue 11: a property test over scene TOML. Valid built-in scenes are mutated at random (keys
//! replaced by values of every type, NaN, infinities, huge, negative and zero numbers, empty and
//! long strings, long arrays; keys and whole tables deleted; unknown keys added; bytes of the
//! text flipped or cut; `--set` overrides of random keys and values) and each result goes
//! through the scene parser, validation, model construction and, where its lattice is small,
//! particle generation: in-process, each case within a time limit, with no panic.

mod common;

use common::Rng;
use pfem_mpi::case_file::new_case;
use pfem_mpi::model::Model;
use pfem_mpi::scene::{Scene, BUILTINS};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use toml::Value;

const CASES: usize = 1200;
/// Time one case may take (parse, validate, build the model and at most ~1e5 particles).
const LIMIT: Duration = Duration::from_secs(10);
/// Largest lattice generated in the test (validation itself allows 5e7).
const MAX_TEST_PARTICLES: f64 = 1e5;

fn weird_value(rng: &mut Rng) -> Value {
    match rng.below(16) {
        0 => Value::Float(f64::NAN),
        1 => Value::Float(f64::INFINITY),
        2 => Value::Float(f64::NEG_INFINITY),
        3 => Value::Float(1e308),
        4 => Value::Float(-1.0),
        5 => Value::Float(0.0),
        6 => Value::Integer(i64::MAX),
        7 => Value::Integer(-1),
        8 => Value::String(String::new()),
        9 => Value::String("x".repeat(10_000)),
        10 => Value::Array((0..2000).map(|i| Value::Float(i as f64)).collect()),
        11 => Value::Array(Vec::new()),
        12 => Value::Boolean(rng.below(2) == 0),
        13 => Value::Table(toml::map::Map::new()),
        14 => Value::Float(1e-300),
        _ => Value::Array(vec![Value::Float(f64::NAN), Value::Float(1e300)]),
    }
}

/// Every path to a value in `v` (table keys and array indices).
fn paths(v: &Value, here: Vec<String>, out: &mut Vec<Vec<String>>) {
    match v {
        Value::Table(t) => {
            for (k, x) in t {
                let mut p = here.clone();
                p.push(k.clone());
                out.push(p.clone());
                paths(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate().take(8) {
                let mut p = here.clone();
                p.push(format!("#{i}"));
                out.push(p.clone());
                paths(x, p, out);
            }
        }
        _ => {}
    }
}

fn at<'a>(v: &'a mut Value, path: &[String]) -> Option<&'a mut Value> {
    let mut v = v;
    for k in path {
        v = match (v, k.strip_prefix('#')) {
            (Value::Array(a), Some(i)) => a.get_mut(i.parse::<usize>().ok()?)?,
            (Value::Table(t), None) => t.get_mut(k)?,
            _ => return None,
        };
    }
    Some(v)
}

fn remove(v: &mut Value, path: &[String]) {
    let Some((last, parent)) = path.split_last() else {
        return;
    };
    match (at(v, parent), last.strip_prefix('#')) {
        (Some(Value::Table(t)), None) => {
            t.remove(last);
        }
        (Some(Value::Array(a)), Some(i)) => {
            if let Ok(i) = i.parse::<usize>() {
                if i < a.len() {
                    a.remove(i);
                }
            }
        }
        _ => {}
    }
}

/// One mutated case: scene text and `--set` overrides.
fn case(rng: &mut Rng) -> (String, Vec<String>) {
    let (_, text) = *rng.pick(BUILTINS);
    let mut doc: Value = toml::from_str(text).expect("built-in scenes parse");
    let mut sets = Vec::new();
    for _ in 0..1 + rng.below(2) {
        let mut all = Vec::new();
        paths(&doc, Vec::new(), &mut all);
        if all.is_empty() {
            break;
        }
        let path = rng.pick(&all).clone();
        match rng.below(10) {
            0..=2 => {
                let w = weird_value(rng);
                if let Some(slot) = at(&mut doc, &path) {
                    *slot = w;
                }
            }
            3..=5 => {
                // A plausible number out of its range: scaled by 1e-3 .. 1e3, or negated.
                let k = rng.below(7) as i32 - 3;
                let negate = rng.below(4) == 0;
                if let Some(slot) = at(&mut doc, &path) {
                    let x = match slot {
                        Value::Float(x) => *x,
                        Value::Integer(i) => *i as f64,
                        _ => continue,
                    };
                    let y = x * 10f64.powi(k);
                    *slot = match slot {
                        Value::Integer(_) => {
                            Value::Integer(if negate { -(y as i64) } else { y as i64 })
                        }
                        _ => Value::Float(if negate { -y } else { y }),
                    };
                }
            }
            6 => remove(&mut doc, &path),
            7 => {
                if let Some(Value::Table(t)) = at(&mut doc, &path[..path.len() - 1]) {
                    t.insert("unknown_key".into(), weird_value(rng));
                }
            }
            _ => {
                // A `--set` of the same key (numbers for indices) with a random value.
                let key = path
                    .iter()
                    .map(|k| match k.strip_prefix('#') {
                        Some(i) => format!("[{i}]"),
                        None => format!(".{k}"),
                    })
                    .collect::<String>();
                let key = key.trim_start_matches('.').replace(".[", "[");
                let value = *rng.pick(&[
                    "nan",
                    "inf",
                    "-inf",
                    "1e308",
                    "-1",
                    "0",
                    "\"\"",
                    "[]",
                    "[1e300, -1e300]",
                    "{}",
                    "true",
                    "[[0.0]]",
                    "\"x <= \"",
                    "1e-300",
                    "=",
                    "[0.0,",
                    "9999999999999",
                ]);
                sets.push(format!("{key}={value}"));
            }
        }
    }
    // A valid scene of millions of particles takes validation seconds per million (it checks
    // the generated lattice), which is work, not a hang: kept out of this test's time budget.
    // Beyond the particle limit (5e7) validation refuses before generating, and that stays in.
    let n = lattice_estimate(&doc);
    if n > MAX_TEST_PARTICLES && n < 1e8 {
        return case(rng);
    }
    let mut text = toml::to_string(&doc).unwrap_or_default();
    if rng.below(8) == 0 && !text.is_empty() {
        // Damage the text itself: cut it, or flip a byte (kept valid UTF-8 by String::from_utf8_lossy).
        let mut bytes = text.into_bytes();
        let i = rng.below(bytes.len());
        if rng.below(2) == 0 {
            bytes.truncate(i);
        } else {
            bytes[i] ^= 1 << rng.below(7);
        }
        text = String::from_utf8_lossy(&bytes).into_owned();
    }
    (text, sets)
}

/// Particles the lattice of scene text `doc` would hold, where its numbers say (0 where they
/// are not numbers: the parser rejects those at once).
fn lattice_estimate(doc: &Value) -> f64 {
    let num = |v: Option<&Value>| match v {
        Some(Value::Float(x)) => *x,
        Some(Value::Integer(i)) => *i as f64,
        _ => f64::NAN,
    };
    let count = |r: &Value, h: f64| {
        let size = r.get("size").and_then(Value::as_array);
        let (w, d) = size.map_or((f64::NAN, f64::NAN), |a| (num(a.first()), num(a.get(1))));
        let n = (w / h + 1.0) * (d / h + 1.0);
        if n.is_finite() {
            n.abs()
        } else {
            0.0
        }
    };
    let mesh = doc.get("mesh");
    let h = num(mesh.and_then(|m| m.get("h")));
    let rects = doc
        .get("body")
        .and_then(|b| b.get("rectangles"))
        .and_then(Value::as_array);
    let fine = mesh.and_then(|m| m.get("fine")).and_then(Value::as_array);
    let coarse: f64 = rects.map_or(0.0, |r| r.iter().map(|r| count(r, h)).sum());
    let fine: f64 = fine.map_or(0.0, |f| f.iter().map(|r| count(r, num(r.get("h")))).sum());
    coarse + fine
}

/// Particles the scene's lattice would hold (coarse lattice and fine regions), or infinity.
fn lattice_size(s: &Scene) -> f64 {
    let count = |size: [f64; 2], h: f64| (size[0] / h + 1.0) * (size[1] / h + 1.0);
    let coarse: f64 = s
        .body
        .rectangles
        .iter()
        .map(|r| count(r.size, s.mesh.h))
        .sum();
    let fine: f64 = s.mesh.fine.iter().map(|r| count(r.size, r.h)).sum();
    let n = coarse + fine;
    if n.is_finite() {
        n
    } else {
        f64::INFINITY
    }
}

/// What one case came to: accepted (with its particle count, if generated) or rejected.
fn run_case(text: String, sets: Vec<String>) -> Result<Option<usize>, String> {
    let scene = Scene::from_toml(&text, "fuzz", &sets).map_err(|e| e.to_string())?;
    Model::new(&scene)?;
    if lattice_size(&scene) <= MAX_TEST_PARTICLES {
        let (_, particles) = new_case(&scene, "fuzz");
        return Ok(Some(particles.gid.len()));
    }
    Ok(None)
}

#[test]
fn a_thousand_mutated_scenes_give_an_answer_or_an_error_never_a_panic() {
    // FUZZ_SEED and FUZZ_CASES explore further by hand; CI runs the fixed seed.
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let mut rng = Rng(env("FUZZ_SEED").unwrap_or(0x9e37_79b9_7f4a_7c15) | 1);
    let cases = env("FUZZ_CASES").map_or(CASES, |n| n as usize);
    let (mut accepted, mut rejected, mut generated) = (0, 0, 0);
    let mut slowest = Duration::ZERO;
    for n in 0..cases {
        let (text, sets) = case(&mut rng);
        let (send, recv) = mpsc::channel();
        let shown = (text.clone(), sets.clone());
        std::thread::spawn(move || {
            let start = Instant::now();
            let outcome = catch_unwind(AssertUnwindSafe(|| run_case(text, sets)));
            let _ = send.send((outcome, start.elapsed()));
        });
        let Ok((outcome, took)) = recv.recv_timeout(LIMIT) else {
            panic!(
                "case {n} did not finish within {LIMIT:?}:\n--set {:?}\n{}",
                shown.1, shown.0
            );
        };
        slowest = slowest.max(took);
        match outcome {
            Err(_) => panic!("case {n} panicked:\n--set {:?}\n{}", shown.1, shown.0),
            Ok(Ok(particles)) => {
                accepted += 1;
                generated += usize::from(particles.is_some());
            }
            Ok(Err(message)) => {
                if std::env::var("FUZZ_SHOW").is_ok() {
                    eprintln!("REJ {}", message.chars().take(110).collect::<String>());
                }
                rejected += 1;
                assert!(
                    !message.trim().is_empty(),
                    "case {n}: an empty error message"
                );
            }
        }
    }
    println!(
        "{cases} cases: {accepted} accepted ({generated} with particles generated), {rejected} \
         rejected; slowest {slowest:?}"
    );
    assert!(
        rejected > CASES / 4,
        "the mutations should break most scenes"
    );
    assert!(accepted > 0, "some mutations should leave a valid scene");
}

/// Found by this test: a rigid circle of radius 1e308 made the lining's spacing NaN and panicked
/// in `Shape::surface_points`; a large finite one would exhaust memory.
#[test]
fn a_huge_rigid_body_is_an_error_naming_its_size() {
    for radius in ["1e308", "1e9"] {
        let sets = vec![format!("rigid[0].circle.radius={radius}")];
        let text = BUILTINS.iter().find(|(n, _)| *n == "tbar-rough").unwrap().1;
        let e = run_case(text.to_string(), sets).expect_err("a huge body is refused");
        assert!(e.contains("rigid[0].circle.radius"), "{e}");
        assert!(e.contains("lining particles"), "{e}");
    }
}
