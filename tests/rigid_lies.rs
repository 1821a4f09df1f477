//! Issue 32: runs on its base scene (tests/scenes/pipe-on-ground.toml, a pipe pushed 0.01 m
//! into elastic ground in 3 steps) that used to end with exit 0 and a wrong answer.

mod common;

use common::{history, ok, run, workdir};
use std::path::Path;

const PIPE: &str = include_str!("scenes/pipe-on-ground.toml");

/// Writes the base scene with `sets` to `NAME.h5` in `dir`.
fn new_case(dir: &Path, name: &str, sets: &[&str]) {
    std::fs::write(dir.join("pipe.toml"), PIPE).unwrap();
    let case = format!("{name}.h5");
    let mut args = vec!["new", "pipe.toml", "-o", &case];
    for s in sets {
        args.extend(["--set", s]);
    }
    ok(dir, 1, &args);
}

/// The column `name` of `DIR/NAME.out/history.csv`.
fn column(dir: &Path, name: &str, col: &str) -> Vec<f64> {
    let (header, rows) = history(&dir.join(format!("{name}.out/history.csv")));
    let k = header.iter().position(|h| h == col).expect("column");
    rows.iter().map(|r| r[k]).collect()
}

/// Finding 2: an ambient pressure of 1e9 Pa (1000 E, the largest accepted) used to give
/// fy = −922 N and fx = −7 180 N; every suction that holds the soil gives one force.
#[test]
fn the_force_does_not_depend_on_a_suction_the_soil_never_reaches() {
    let dir = workdir("suction");
    let columns = concat!(
        r#"history.columns=[{ name = "fy", measure = "rigid.pipe.fy" }, "#,
        r#"{ name = "t", measure = "time" }]"#
    );
    for (name, ambient) in [("low", "1e5"), ("high", "1e9")] {
        new_case(
            &dir,
            name,
            &[&format!("rigid[0].ambient_pressure={ambient}"), columns],
        );
        ok(&dir, 2, &[&format!("{name}.h5")]);
    }
    let (low, high) = (column(&dir, "low", "fy"), column(&dir, "high", "fy"));
    for (a, b) in low.iter().zip(&high) {
        assert!(*a > 100.0, "the pipe pushes the soil: fy = {a}");
        assert!((a - b).abs() <= 1e-6 * a.abs(), "fy {a} against {b}");
    }
    // Finding 7: the time measure advances with the load.
    let t = column(&dir, "low", "t");
    let want = [1.0 / 3.0, 2.0 / 3.0, 1.0];
    for (got, want) in t.iter().zip(want) {
        assert!((got - want).abs() < 1e-12, "time {t:?}");
    }
}

/// Finding 7: a scale that overflows used to write `inf` into history.csv and exit 0.
#[test]
fn a_history_value_that_is_not_finite_ends_the_run_with_its_column() {
    let dir = workdir("inf-history");
    new_case(
        &dir,
        "inf",
        &[r#"history.columns=[{ name = "fy", measure = "rigid.pipe.fy", scale = 1e308 }]"#],
    );
    let out = run(&dir, 2, &["inf.h5"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "exit 0 with an infinite history");
    assert!(stderr.contains("history.csv column fy"), "{stderr}");
    assert!(stderr.contains("history.columns[0].scale"), "{stderr}");
}
