//! What a real run leaves for other tools: ParaView fields read back by an independent reader
//! (Python's h5py), agreeing with history.csv; and the pictures.

mod common;
use common::*;
use std::process::Command;

const CHECK: &str = r#"
import sys, h5py, xml.etree.ElementTree as ET
out, L = sys.argv[1], float(sys.argv[2])
root = ET.parse(out + "/fields.xdmf").getroot()
grids = [g for g in root.iter("Grid") if g.get("GridType") != "Collection"]
assert [g.get("Name") for g in grids] == ["step_000004", "step_000008"], [g.get("Name") for g in grids]
rows = [l.split(",") for l in open(out + "/history.csv").read().split()[1:]]
last = rows[-1]
f = h5py.File(out + "/fields/step_000008.h5", "r")
n = f["geometry"].shape[0]
assert f["geometry"].shape == (n, 2) and f["connectivity"].shape[1] == 3
assert f["connectivity"][:].min() >= 0 and f["connectivity"][:].max() < n
for name in ["displacement", "incremental_displacement"]:
    assert f["point_data/" + name].shape == (n, 3), name
for name in ["eps_q", "sigma_xx", "sigma_yy", "tau_xy", "pressure", "rank"]:
    assert f["point_data/" + name].shape == (n,), name
assert sorted(set(f["point_data/rank"][:])) == [0.0, 1.0]
# The loaded tip: the particle at x = L - u, mid-height; its displacement is history's.
geo, u = f["geometry"][:], f["point_data/displacement"][:]
ref = geo - u[:, :2]
tip = min(range(n), key=lambda i: (ref[i][0] - L) ** 2 + (ref[i][1] - 0.5) ** 2)
assert abs(-u[tip][0] / L - float(last[2])) < 1e-12, (u[tip], last)
assert abs(-u[tip][1] / L - float(last[3])) < 1e-12, (u[tip], last)
print("ok", n, "particles")
"#;

#[test]
fn paraview_fields_agree_with_history_under_an_independent_reader() {
    if !prerequisite("Python's h5py (python3-h5py)", python_has("h5py")) {
        return;
    }
    let dir = workdir("outputs");
    small_cantilever(&dir, 8, &["output.fields_every=4"]);
    ok(&dir, 2, &["c.h5"]);
    let out = Command::new("python3")
        .args(["-c", CHECK, dir.join("c.out").to_str().unwrap(), "10.0"])
        .output()
        .expect("python3");
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    // The cantilever is elastic: its eps_q is zero everywhere, so it gets no picture.
    assert!(
        !dir.join("c.out/plots/eps_q.png").exists(),
        "eps_q.png of an elastic run"
    );
    for png in ["history", "incremental_displacement", "sigma_yy", "tau_xy"] {
        let p = dir.join("c.out/plots").join(format!("{png}.png"));
        assert!(
            std::fs::metadata(&p).is_ok_and(|m| m.len() > 1000),
            "{} missing",
            p.display()
        );
    }
    let replot = ok(&dir, 1, &["plot", "c.out"]);
    assert!(replot.contains("history.png"), "{replot}");
}
