//! Abaqus UMAT plug-ins (`model = "umat"`): Fortran UMATs compiled here with gfortran reproduce
//! the built-in models, carry their state variables by name into the checkpoints, cut the step
//! when they ask for it, and every failure is one message naming the file.

mod common;
use common::*;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Compiles `tests/umat/<name>.f` into `dir/lib<name>.so`; None (a skip, a failure in CI)
/// without gfortran.
fn build_umat(dir: &Path, name: &str) -> Option<PathBuf> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/umat/{name}.f"));
    let lib = dir.join(format!("lib{name}.so"));
    let out = Command::new("gfortran")
        .args(["-shared", "-fPIC", "-O2", "-o"])
        .arg(&lib)
        .arg(&src)
        .output();
    let out = match out {
        Ok(out) => out,
        Err(e) => {
            prerequisite(&format!("gfortran ({e})"), false);
            return None;
        }
    };
    assert!(
        out.status.success(),
        "gfortran {}: {}",
        src.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    Some(lib)
}

/// Largest difference between two histories, relative to each column's largest magnitude.
fn history_difference(a: &Path, b: &Path) -> f64 {
    let ((ha, ra), (hb, rb)) = (history(a), history(b));
    assert_eq!(ha, hb);
    assert_eq!(ra.len(), rb.len(), "histories of different lengths");
    let mut worst: f64 = 0.0;
    for c in 0..ha.len() {
        let scale = ra
            .iter()
            .map(|r| r[c].abs())
            .fold(0.0, f64::max)
            .max(1e-300);
        for (x, y) in ra.iter().zip(&rb) {
            worst = worst.max((x[c] - y[c]).abs() / scale);
        }
    }
    worst
}

/// The plane-strain Tresca UMAT's keys with E = 3 MPa, ν = 0.49, cu = 10 kPa (the built-in
/// block's), `extra` appended to PROPS.
fn tresca_umat_sets(extra: &str) -> Vec<String> {
    vec![
        "material.model=umat".into(),
        "material.library=libtresca.so".into(),
        format!("material.props=[3.0e6, 0.49, 10.0e3{extra}]"),
        "material.state_variables=5".into(),
        r#"material.state_names=["ep_xx", "ep_yy", "ep_zz", "ep_xy", "eps_q"]"#.into(),
    ]
}

/// `new block-compression` to 4 % strain in 10 steps (2cu is reached in step 2), plus `sets`.
fn block_case(dir: &Path, out: &str, sets: &[String]) {
    let mut args: Vec<String> = ["new", "block-compression", "-o", out]
        .map(String::from)
        .to_vec();
    for s in [
        "steps.count=10",
        "prescribed[0].total=[0.0, -0.02]",
        "prescribed[1].total=[0.0, 0.02]",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain(sets.iter().cloned())
    {
        args.push("--set".into());
        args.push(s);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(dir, 1, &args);
}

#[test]
fn elastic_umat_gives_the_builtin_cantilever_history() {
    let dir = workdir("umat-elastic");
    if build_umat(&dir, "elastic").is_none() {
        return;
    }
    small_cantilever(&dir, 5, &[]);
    std::fs::rename(dir.join("c.h5"), dir.join("ref.h5")).expect("rename");
    small_cantilever(
        &dir,
        5,
        &[
            "material.model=umat",
            "material.library=libelastic.so",
            "material.props=[12.0e6, 0.2]",
            "material.nprops=2",
        ],
    );
    for ranks in [1, 2] {
        let (r, u) = (format!("ref{ranks}"), format!("umat{ranks}"));
        ok(&dir, ranks, &["ref.h5", "--out", &r]);
        ok(&dir, ranks, &["c.h5", "--out", &u]);
        let diff = history_difference(
            &dir.join(&r).join("history.csv"),
            &dir.join(&u).join("history.csv"),
        );
        println!("{ranks} ranks: elastic UMAT vs linear-elastic, history differs by {diff:.1e}");
        assert!(diff < 1e-10, "{ranks} ranks: differs by {diff:e}");
    }
}

#[test]
fn a_umat_is_told_where_and_when_it_is_called() {
    let dir = workdir("umat-site");
    if build_umat(&dir, "elastic").is_none() {
        return;
    }
    small_cantilever(
        &dir,
        4,
        &[
            "material.model=umat",
            "material.library=libelastic.so",
            "material.props=[12.0e6, 0.2]",
            "material.state_variables=7",
            r#"material.state_names=["noel", "npt", "x", "y", "celent", "kinc", "time"]"#,
        ],
    );
    ok(&dir, 2, &["c.h5", "--out", "out"]);
    // Per Gauss point of the last step's triangles: NOEL, NPT, COORDS, CELENT, KINC, TIME.
    let rows = h5py_rows(
        &dir.join("out/checkpoints/step_000004.h5"),
        "n = [x.decode() if isinstance(x, bytes) else x for x in f['gauss/state'].attrs['names']]\n\
         s = f['gauss/state'][:]\n\
         w = len(n)\n\
         for row in s:\n\
         \x20   for q in range(3):\n\
         \x20       g = row[q * w:(q + 1) * w]\n\
         \x20       print(*[g[n.index(k)] for k in ['noel', 'npt', 'x', 'y', 'celent', 'kinc', 'time']])",
    );
    assert!(!rows.is_empty());
    for (i, r) in rows.iter().enumerate() {
        assert!(r[0] >= 1.0, "NOEL {r:?}");
        assert_eq!(r[1], (i % 3 + 1) as f64, "NPT {r:?}");
        // The cantilever is 10 m x 1 m, bent down by its end load (to y = -7.8 m here).
        assert!(
            (-0.1..=10.1).contains(&r[2]) && (-10.1..=1.1).contains(&r[3]),
            "COORDS {r:?}"
        );
        assert!(r[4] > 0.05 && r[4] < 1.0, "CELENT {r:?}");
        assert_eq!(r[5], 4.0, "KINC {r:?}");
        assert!((r[6] - 1.0).abs() < 1e-12, "TIME + DTIME {r:?}");
    }
}

#[test]
fn tresca_umat_holds_two_cu_and_checkpoints_its_state_by_name() {
    let dir = workdir("umat-tresca");
    if build_umat(&dir, "tresca").is_none() {
        return;
    }
    block_case(&dir, "ref.h5", &[]);
    block_case(&dir, "b.h5", &tresca_umat_sets(""));
    for ranks in [1, 2] {
        let (r, o) = (format!("ref{ranks}"), format!("out{ranks}"));
        ok(&dir, ranks, &["ref.h5", "--out", &r]);
        let log = ok(&dir, ranks, &["b.h5", "--out", &o]);
        let (header, rows) = history(&dir.join(&o).join("history.csv"));
        assert_eq!(header[2], "stress_over_cu");
        let worst = rows[1..]
            .iter()
            .map(|r| (r[2] - 2.0).abs() / 2.0)
            .fold(0.0, f64::max);
        let diff = history_difference(
            &dir.join(&r).join("history.csv"),
            &dir.join(&o).join("history.csv"),
        );
        println!(
            "Tresca UMAT, {ranks} ranks: stress/cu off 2 by {worst:.1e} once yielded; \
             vs built-in {diff:.1e}"
        );
        // Plane-strain compression between smooth platens: σyy − σxx = 2cu exactly once
        // yielded (from step 2).
        assert!(worst < 1e-6, "stress/cu off 2 by {worst:e}");
        // A UMAT is not declared isochoric, so the mixed element takes its full stress (the P1
        // pressure the projection of the UMAT's own, as for the frictional models) where the
        // built-in Tresca closes the pressure with its elastic volume law: the two
        // formulations agree to 1.2e-6 here (measured), both at 2 cu.
        assert!(diff < 1e-5, "differs from the built-in tresca by {diff:e}");
        assert!(!log.contains("(cut"), "no cut without PNEWDT:\n{log}");
    }
    // The state variables come back from a checkpoint: a restart at step 5 ends where the
    // straight run does.
    ok(&dir, 1, &["b.h5", "--out", "split", "--until-step", "5"]);
    ok(&dir, 1, &["split/checkpoints/step_000005.h5"]);
    let diff = history_difference(
        &dir.join("out1/history.csv"),
        &dir.join("split/history.csv"),
    );
    println!("Tresca UMAT restarted at step 5: history differs by {diff:.1e}");
    assert!(diff < 1e-12, "restart differs by {diff:e}");
    let ckpt = dir.join("out2/checkpoints/step_000010.h5");
    let names = h5py_rows(
        &ckpt,
        "n = [x.decode() if isinstance(x, bytes) else x for x in f['particles/state'].attrs['names']]\n\
         print(n.index('ep_xx'), n.index('eps_q'), n.index('stran_xy'), len(n))\n\
         s = f['particles/state'][:]\n\
         print(s[:, n.index('eps_q')].min(), s[:, n.index('ep_yy')].max())",
    );
    assert_eq!(names[0], [8.0, 12.0, 7.0, 13.0], "state columns");
    // Every particle flowed plastically, shortening vertically.
    assert!(names[1][0] > 0.0 && names[1][1] < 0.0, "{:?}", names[1]);
}

#[test]
fn pnewdt_below_one_cuts_the_step() {
    let dir = workdir("umat-pnewdt");
    if build_umat(&dir, "tresca").is_none() {
        return;
    }
    // PROPS(4): a plastic multiplier above 4e-3 asks for half the step.
    block_case(&dir, "b.h5", &tresca_umat_sets(", 4.0e-3"));
    let log = ok(&dir, 1, &["b.h5", "--out", "out"]);
    let cut = log
        .lines()
        .filter(|l| l.starts_with("step ") && l.contains("(cut"))
        .count();
    assert!(cut >= 8, "steps should be cut where PNEWDT < 1:\n{log}");
    let (_, rows) = history(&dir.join("out/history.csv"));
    assert!((rows[9][2] - 2.0).abs() < 1e-6, "{:?}", rows[9]);
}

fn as_strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

fn fails_naming(dir: &Path, ranks: usize, args: &[&str], needles: &[&str]) {
    let out = run(dir, ranks, args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{args:?}: should name {n:?}:\n{stderr}");
    }
}

#[test]
fn umat_failures_name_the_file_and_field() {
    let dir = workdir("umat-bad");
    let Some(lib) = build_umat(&dir, "tresca") else {
        return;
    };
    let new = |sets: &[&str]| {
        let mut a = vec!["new", "block-compression", "-o", "bad.h5"];
        for s in sets {
            a.extend(["--set", s]);
        }
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let missing = new(&["material.model=umat", "material.library=libnothere.so"]);
    fails_naming(
        &dir,
        1,
        &as_strs(&missing),
        &["material.library", "libnothere.so"],
    );
    // A library without `umat_`: the elastic one renamed would still have it, so a C library.
    std::fs::write(dir.join("nosym.c"), "int not_a_umat(void) { return 0; }\n").expect("write");
    let cc = Command::new("gcc")
        .args(["-shared", "-fPIC", "-o", "libnosym.so", "nosym.c"])
        .current_dir(&dir)
        .status()
        .expect("gcc");
    assert!(cc.success());
    let nosym = new(&["material.model=umat", "material.library=libnosym.so"]);
    fails_naming(
        &dir,
        1,
        &as_strs(&nosym),
        &["material.library", "libnosym.so", "umat_"],
    );
    let count = new(&[
        "material.model=umat",
        "material.library=libtresca.so",
        "material.props=[3.0e6, 0.49]",
        "material.nprops=3",
    ]);
    fails_naming(&dir, 1, &as_strs(&count), &["material.props", "nprops = 3"]);
    let names = new(&[
        "material.model=umat",
        "material.library=libtresca.so",
        "material.state_variables=2",
        r#"material.state_names=["a"]"#,
    ]);
    fails_naming(&dir, 1, &as_strs(&names), &["material.state_names"]);
    // NaN stresses and a PNEWDT < 1 however small the step: the run stops naming the library.
    for (k, (extra, needle)) in [(", -1.0", "non-finite STRESS"), (", 1.0e-30", "PNEWDT")]
        .into_iter()
        .enumerate()
    {
        let case = format!("b{k}.h5");
        block_case(&dir, &case, &tresca_umat_sets(extra));
        fails_naming(
            &dir,
            2,
            &[&case, "--out", &format!("out{k}")],
            &[&lib.display().to_string(), needle],
        );
    }
    // The library gone between `new` and the run.
    block_case(&dir, "b.h5", &tresca_umat_sets(""));
    std::fs::remove_file(&lib).expect("remove");
    fails_naming(
        &dir,
        1,
        &["b.h5", "--out", "out"],
        &["material.library", &lib.display().to_string()],
    );
}
