//! Issue 32: the scene fuzz test for rigid bodies. Random bodies (circles and convex polygons
//! from 1e-7 m to 1 km, anywhere on, in or above the ground of tests/scenes/pipe-on-ground.toml),
//! stages (none, tiny, a metre a step, NaN, zero or 4e9 steps), contact settings, ambient
//! pressures, surface pressures and probes go through the parser, validation, the model and
//! particle generation in-process, with no panic and within a time limit; the first accepted
//! ones are also run (1 rank), where exit 0 must leave a history with no NaN or infinity and
//! no step with a zero force on a body that overlaps the ground.

mod common;

use common::{run, workdir, Rng};
use pfem_mpi::case_file::new_case;
use pfem_mpi::model::Model;
use pfem_mpi::rigid::Shape;
use pfem_mpi::scene::Scene;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use toml::Value;

const PIPE: &str = include_str!("scenes/pipe-on-ground.toml");
const CASES: usize = 400;
/// Accepted cases that are also run: about 3 s each.
const RUNS: usize = 8;
const LIMIT: Duration = Duration::from_secs(10);

fn float(rng: &mut Rng, usual: (f64, f64), odd: &[f64]) -> Value {
    if rng.below(8) == 0 {
        Value::Float(*rng.pick(odd))
    } else {
        Value::Float(rng.uniform(usual.0, usual.1))
    }
}

fn point(rng: &mut Rng, x: (f64, f64), y: (f64, f64)) -> Value {
    let odd = [f64::NAN, 1e300, -1e300, 10.0];
    Value::Array(vec![float(rng, x, &odd), float(rng, y, &odd)])
}

fn table(entries: Vec<(&str, Value)>) -> Value {
    Value::Table(
        entries
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
    )
}

/// A body: a circle or a regular convex polygon, of a size from far below to far above the
/// spacing (0.02 m), somewhere from inside the ground to well above it.
fn body(rng: &mut Rng) -> Value {
    let size: f64 = *rng.pick(&[1e-7, 0.002, 0.02, 0.02, 0.03, 0.04, 0.06, 1e3]);
    // Mostly touching the ground: its centre from half a size below the surface to one above.
    let low = 0.2 + size.min(0.1) * rng.uniform(-0.5, 1.1);
    let centre = point(rng, (0.1, 0.5), (low, low));
    let mut entries = vec![("name", Value::String("pipe".into()))];
    if rng.below(2) == 0 {
        entries.push((
            "circle",
            table(vec![("centre", centre), ("radius", Value::Float(size))]),
        ));
    } else {
        let n = *rng.pick(&[3usize, 4, 7, 64]);
        let c = [rng.uniform(0.1, 0.5), low];
        let turn = rng.uniform(0.0, 1.0);
        let vertices = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * (k as f64 + turn) / n as f64;
                let v = [c[0] + size * a.cos(), c[1] + size * a.sin()];
                Value::Array(v.iter().map(|x| Value::Float(*x)).collect())
            })
            .collect();
        let corner = *rng.pick(&[0.0, 0.1 * size, 2.0 * size]);
        entries.push((
            "polygon",
            table(vec![
                ("vertices", Value::Array(vertices)),
                ("corner_radius", Value::Float(corner)),
            ]),
        ));
    }
    let stages = (0..rng.below(4))
        .map(|_| {
            let steps = *rng.pick(&[1i64, 2, 3, 3, 4, 0, 4_294_967_295]);
            table(vec![
                ("to", point(rng, (-0.02, 0.02), (-0.03, 0.0))),
                ("steps", Value::Integer(steps)),
            ])
        })
        .collect();
    entries.push(("stages", Value::Array(stages)));
    entries.push(("adhesion", float(rng, (0.0, 0.0), &[0.5, 2.0])));
    entries.push((
        "ambient_pressure",
        float(rng, (0.0, 1e5), &[1e9, 1e300, -1.0]),
    ));
    table(entries)
}

/// One case: the base scene with a random body, contact, surface pressures and probes.
fn case(rng: &mut Rng) -> String {
    let mut doc: Value = toml::from_str(PIPE).expect("the base scene parses");
    let t = doc.as_table_mut().expect("a table");
    t.insert("rigid".into(), Value::Array(vec![body(rng)]));
    t.remove("steps");
    if rng.below(3) == 0 {
        let contact = table(vec![
            ("penalty", float(rng, (10.0, 1e5), &[1e-12, 1e30, f64::NAN])),
            ("tolerance", float(rng, (1e-8, 1e-4), &[1e-300, 0.5])),
            (
                "max_augmentations",
                Value::Integer(*rng.pick(&[0i64, 1, 2, 12])),
            ),
        ]);
        t.insert("contact".into(), contact);
    }
    if rng.below(3) == 0 {
        let region = *rng.pick(&["y >= 0.2", "y >= 5", "x <= 0", "x >= 0.25 and y <= 0.1"]);
        let sp = table(vec![
            ("where", Value::String(region.into())),
            ("pressure", float(rng, (0.0, 1e3), &[1e300, f64::NAN])),
        ]);
        t.insert("surface_pressure".into(), Value::Array(vec![sp]));
    }
    if rng.below(3) == 0 {
        let probe = table(vec![
            ("name", Value::String("p".into())),
            ("at", point(rng, (0.0, 0.6), (0.0, 0.3))),
        ]);
        t.insert("probe".into(), Value::Array(vec![probe]));
    }
    let columns = ["ux", "uy", "fx", "fy"]
        .iter()
        .map(|c| {
            table(vec![
                ("name", Value::String((*c).into())),
                ("measure", Value::String(format!("rigid.pipe.{c}"))),
            ])
        })
        .collect();
    t.insert(
        "history".into(),
        table(vec![("columns", Value::Array(columns))]),
    );
    toml::to_string(&doc).expect("TOML")
}

/// Parse, validate, build the model and the particles, like `pfem-mpi new`.
fn accept(text: &str) -> Result<Scene, String> {
    let scene = Scene::from_toml(text, "fuzz", &[]).map_err(|e| e.to_string())?;
    Model::new(&scene)?;
    new_case(&scene, "fuzz");
    Ok(scene)
}

/// How deep the body at displacement `d` reaches into the ground's initial rectangle.
fn overlap(scene: &Scene, d: [f64; 2]) -> f64 {
    let r = scene.body.rectangles[0];
    let [x0, y0] = r.origin;
    let [x1, y1] = [x0 + r.size[0], y0 + r.size[1]];
    let shape: Shape = match (&scene.rigid[0].circle, &scene.rigid[0].polygon) {
        (Some(c), _) => Shape::circle(c.centre, c.radius).unwrap(),
        (_, Some(p)) => Shape::polygon(&p.vertices, p.corner_radius).unwrap(),
        _ => unreachable!("validated"),
    };
    let shape = shape.translated(d);
    let a = shape.triangle_depth([[x0, y0], [x1, y0], [x1, y1]]);
    a.max(shape.triangle_depth([[x0, y0], [x1, y1], [x0, y1]]))
}

/// Runs an accepted case on one rank: an error is an answer; exit 0 must leave a history
/// that is all numbers, with a force on the body wherever it reaches into the ground.
fn run_accepted(n: usize, text: &str, scene: &Scene) {
    let dir = workdir(&format!("fuzz-rigid-{n}"));
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let made = run(&dir, 1, &["new", "s.toml", "-o", "c.h5"]);
    assert!(
        made.status.success(),
        "case {n}: new failed after validation:\n{text}"
    );
    let out = run(&dir, 1, &["c.h5"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.code().is_some() && !stderr.contains("panicked"),
        "case {n}: {}\n{stderr}\n{text}",
        out.status
    );
    let last = stderr.lines().last().unwrap_or_default().chars().take(160);
    println!("case {n}: {} {}", out.status, last.collect::<String>());
    if !out.status.success() {
        return;
    }
    let (header, rows) = common::history(&dir.join("c.out/history.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    for row in &rows {
        assert!(
            row.iter().all(|v| v.is_finite()),
            "case {n}: exit 0 with {row:?} in its history\n{text}"
        );
        let d = [row[col("ux")], row[col("uy")]];
        let force = row[col("fx")].abs() + row[col("fy")].abs();
        let depth = overlap(scene, d);
        assert!(
            force > 0.0 || depth <= 0.25 * scene.mesh.h,
            "case {n}: exit 0 with no force on a body {depth} m into the ground\n{text}"
        );
    }
}

#[test]
fn random_bodies_stages_contact_and_loads_give_an_answer_or_an_error() {
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<u64>().ok());
    let mut rng = Rng(env("FUZZ_SEED").unwrap_or(0x5851_f42d_4c95_7f2d) | 1);
    let cases = env("FUZZ_CASES").map_or(CASES, |n| n as usize);
    let (mut accepted, mut ran) = (0, 0);
    for n in 0..cases {
        let text = case(&mut rng);
        let (send, recv) = mpsc::channel();
        let shown = text.clone();
        std::thread::spawn(move || {
            let outcome = catch_unwind(AssertUnwindSafe(|| accept(&text)));
            let _ = send.send(outcome);
        });
        let start = Instant::now();
        let Ok(outcome) = recv.recv_timeout(LIMIT) else {
            panic!("case {n} did not finish within {LIMIT:?}:\n{shown}");
        };
        let took = start.elapsed();
        match outcome {
            Err(_) => panic!("case {n} panicked:\n{shown}"),
            Ok(Err(message)) => assert!(!message.trim().is_empty(), "case {n}: empty error"),
            Ok(Ok(scene)) => {
                accepted += 1;
                if ran < RUNS && scene.steps.count <= 6 && took < Duration::from_secs(1) {
                    ran += 1;
                    run_accepted(n, &shown, &scene);
                }
            }
        }
    }
    println!("{cases} cases: {accepted} accepted, {ran} run");
    assert!(
        ran > 0,
        "no case was accepted and run: the generator lost its way"
    );
}
