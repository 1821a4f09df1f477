//! The material state as each model lays it out: version-1 case files (nine state columns for
//! every model, no `names`) load and continue as that program did; new files are as wide as the
//! model's layout and name their columns; the field output carries one field per internal
//! variable. "As that program did" is to 1e-12 of each value: the direct solver's libraries
//! (MUMPS, BLAS) of another build round the last digit differently (4e-15 between two Debian
//! installs), while a misread state column moves the history by far more.
//!
//! `tests/data/v1-*` were written by pfem-mpi at bcc2ea4 (format version 1), with the histories
//! that binary produced from them on 1 rank:
//! - `v1-block-compression-step4.h5`: `new block-compression --set steps.count=8 --set
//!   mesh.h=0.125`, run with `--until-step 4` (a Tresca checkpoint with Gauss states);
//!   `v1-block-compression-continued.csv` is steps 5–8 continued from it.
//! - `v1-cantilever.h5`: `new cantilever --set mesh.h=0.25 --set steps.count=2` (an elastic
//!   case, whose version-1 rows carry zero plastic columns); `v1-cantilever-history.csv`.

mod common;
use common::*;
use std::path::Path;

fn data(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The history file's text (the numbers are printed shortest-round-trip).
fn history_text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Asserts that two history lines have the same fields, numbers within `rtol` of each other.
fn assert_same_line(got: &str, want: &str, rtol: f64, what: &str) {
    let (g, w): (Vec<&str>, Vec<&str>) = (got.split(',').collect(), want.split(',').collect());
    assert_eq!(g.len(), w.len(), "{what}: {got} against {want}");
    for (a, b) in g.iter().zip(&w) {
        match (a.parse::<f64>(), b.parse::<f64>()) {
            (Ok(x), Ok(y)) => assert!(
                (x - y).abs() <= rtol * y.abs(),
                "{what}: {x} against {y} ({got} against {want})"
            ),
            _ => assert_eq!(a, b, "{what}"),
        }
    }
}

/// Asserts that two history files have the same header and rows, numbers within `rtol`.
fn assert_same_history(got: &str, want: &str, rtol: f64, what: &str) {
    let (g, w): (Vec<&str>, Vec<&str>) = (got.lines().collect(), want.lines().collect());
    assert_eq!(g.len(), w.len(), "{what}: {got} against {want}");
    for (a, b) in g.iter().zip(&w) {
        assert_same_line(a, b, rtol, what);
    }
}

fn h5_attr(file: &Path, expr: &str) -> String {
    h5py(file, "r", &format!("print({expr})"))
}

/// Runs `code` with the HDF5 file open as `f` in `mode`; returns what it printed.
fn h5py(file: &Path, mode: &str, code: &str) -> String {
    let script = format!(
        "import h5py\nf = h5py.File({:?}, {mode:?})\n{code}\nf.close()",
        file.display().to_string()
    );
    let out = std::process::Command::new("python3")
        .args(["-c", &script])
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "h5py: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

#[test]
fn a_version_1_tresca_checkpoint_continues_as_the_version_1_program_did() {
    let dir = workdir("v1-tresca");
    let case = dir.join("step4.h5");
    std::fs::copy(data("v1-block-compression-step4.h5"), &case).unwrap();
    let info = ok(&dir, 1, &["info", "step4.h5"]);
    assert!(info.contains("version 1"), "{info}");
    ok(&dir, 1, &["step4.h5", "--out", "cont"]);
    assert_same_history(
        &history_text(&dir.join("cont/history.csv")),
        &history_text(&data("v1-block-compression-continued.csv")),
        1e-12,
        "steps 5-8 from a version-1 checkpoint must be the version-1 program's",
    );
    // Its own checkpoint is version 2, with the Tresca layout named column by column.
    let cp = dir.join("cont/checkpoints/step_000008.h5");
    assert_eq!(h5_attr(&cp, "f.attrs['format_version']"), "2");
    assert_eq!(
        h5_attr(&cp, "list(f['particles/state'].attrs['names'])"),
        "['stress_xx', 'stress_yy', 'stress_zz', 'stress_xy', 'plastic_strain_xx', \
         'plastic_strain_yy', 'plastic_strain_zz', 'plastic_strain_xy', 'eps_q']"
    );
    assert_eq!(h5_attr(&cp, "f['gauss/state'].shape[1]"), "27");
}

#[test]
fn a_version_1_elastic_case_drops_its_zero_plastic_columns() {
    let dir = workdir("v1-elastic");
    std::fs::copy(data("v1-cantilever.h5"), dir.join("c.h5")).unwrap();
    ok(&dir, 1, &["c.h5", "--out", "run"]);
    // Step 1 is the version-1 program's (to 1e-12). Step 2 starts from a mesh whose boundary
    // edges keep the curve the beam's bending gave them in step 1 (`mesh.curved_edges`, newer
    // than version 1): it moved the tip by 3e-4 of its version-1 value, towards the exact one.
    let (got, want) = (
        history_text(&dir.join("run/history.csv")),
        history_text(&data("v1-cantilever-history.csv")),
    );
    let lines = |t: &str| t.lines().map(str::to_string).collect::<Vec<_>>();
    let (got, want) = (lines(&got), lines(&want));
    assert_eq!(got.len(), 3, "{got:?}");
    assert_same_line(&got[0], &want[0], 0.0, "header");
    assert_same_line(&got[1], &want[1], 1e-12, "step 1");
    assert_same_line(&got[2], &want[2], 1e-3, "step 2");
    let cp = dir.join("run/checkpoints/step_000002.h5");
    assert_eq!(h5_attr(&cp, "f['particles/state'].shape[1]"), "4");
    assert_eq!(h5_attr(&cp, "f['gauss/state'].shape[1]"), "12");
}

#[test]
fn a_version_1_elastic_case_with_plastic_values_is_refused() {
    let dir = workdir("v1-elastic-bad");
    let case = dir.join("c.h5");
    std::fs::copy(data("v1-cantilever.h5"), &case).unwrap();
    // A plastic strain in an elastic scene's row: the layout cannot keep it.
    h5py(
        &case,
        "r+",
        "d = f['particles/state']\nv = d[...]\nv[3, 8] = 1e-3\nd[...] = v\n\
         del d.attrs['checksum']",
    );
    let out = run(&dir, 1, &["c.h5", "--out", "run"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("/particles/state") && err.contains("eps_q") && err.contains("c.h5"),
        "{err}"
    );
    assert!(!dir.join("run/history.csv").exists());
}

#[test]
fn new_cases_are_as_wide_as_the_layout_and_output_names_the_variables() {
    let dir = workdir("layout-width");
    ok(
        &dir,
        1,
        &[
            "new",
            "block-compression",
            "-o",
            "b.h5",
            "--set",
            "steps.count=4",
            "--set",
            "mesh.h=0.125",
        ],
    );
    assert_eq!(
        h5_attr(&dir.join("b.h5"), "f['particles/state'].shape[1]"),
        "9"
    );
    small_cantilever(&dir, 1, &[]);
    assert_eq!(
        h5_attr(
            &dir.join("c.h5"),
            "list(f['particles/state'].attrs['names'])"
        ),
        "['stress_xx', 'stress_yy', 'stress_zz', 'stress_xy']"
    );
    ok(&dir, 1, &["b.h5", "--out", "b"]);
    let xdmf = std::fs::read_to_string(dir.join("b/fields.xdmf")).unwrap();
    for field in ["eps_q", "plastic_strain", "sigma_yy"] {
        assert!(
            xdmf.contains(&format!("Name=\"{field}\"")),
            "{field} in {xdmf}"
        );
    }
    assert!(
        xdmf.contains("AttributeType=\"Tensor\""),
        "plastic strain is a tensor"
    );
}
