//! Frictional soil through the whole PFEM loop (issue 28): a confined biaxial compression of a
//! Mohr–Coulomb block reaches the exact limit σ1 = σ3 (1 + sin φ)/(1 − sin φ) + 2c cos φ/(1 − sin φ)
//! and dilates at the exact rate of ψ, Drucker–Prager matched in plane strain reaches the same
//! limit, and bad parameters are errors naming the field.

mod common;
use common::*;
use std::path::Path;

const BIAXIAL: &str = include_str!("scenes/biaxial-mohr-coulomb.toml");
/// σ3, c, φ of the scene.
const CONFINING: f64 = 100.0e3;
const COHESION: f64 = 10.0e3;
const PHI: f64 = 30.0;

fn exact_limit() -> f64 {
    let s = PHI.to_radians().sin();
    let c = PHI.to_radians().cos();
    CONFINING * (1.0 + s) / (1.0 - s) + 2.0 * COHESION * c / (1.0 - s)
}

/// Runs the biaxial scene with `sets`, the platen moving `total` (m) in all; per step: vertical
/// stress (compression positive), the block's log volume and log height.
fn biaxial(dir: &Path, name: &str, total: f64, sets: &[&str]) -> Vec<[f64; 3]> {
    let scene = dir.join("biaxial.toml");
    std::fs::write(&scene, BIAXIAL).expect("write scene");
    let case = format!("{name}.h5");
    let mut args = vec!["new", "biaxial.toml", "-o", &case];
    for s in sets {
        args.extend(["--set", s]);
    }
    ok(dir, 1, &args);
    ok(dir, 1, &[&case, "--out", name]);
    let (header, rows) = history(&dir.join(name).join("history.csv"));
    assert_eq!(header, ["step", "fy", "area", "lambda"]);
    rows.iter()
        .map(|r| {
            // Smooth platens and a follower side pressure keep the block a rectangle: its width
            // is its area over its height.
            let height = 1.0 - total * r[3];
            let width = r[2] / height;
            [-r[1] / width, r[2].ln(), height.ln()]
        })
        .collect()
}

#[test]
fn confined_mohr_coulomb_block_reaches_the_exact_limit_and_dilation() {
    let dir = workdir("mc-biaxial");
    let limit = exact_limit();
    for psi in [10.0f64, 30.0, 0.0] {
        let set = format!("material.dilation_angle={psi}");
        let rows = biaxial(&dir, &format!("psi{psi}"), 0.001, &[&set]);
        assert_eq!(rows.len(), 10);
        // Elastic to step 2, plastic from step 3 (σ1 rises 110 kPa a step).
        assert!(
            rows[1][0] < limit * 0.99,
            "{psi}: step 2 elastic {}",
            rows[1][0]
        );
        for (k, r) in rows.iter().enumerate().skip(2) {
            let err = r[0] / limit - 1.0;
            println!(
                "ψ = {psi}: step {}: σ1 = {:.6} kPa ({err:+.2e})",
                k + 1,
                r[0] / 1e3
            );
            assert!(err.abs() < 1e-6, "ψ = {psi}, step {}: {err:e}", k + 1);
        }
        // Dilation at the limit: the stress no longer changes, so the strain increments are
        // plastic, Δε_v / (−Δε_yy) = 2 sin ψ / (1 − sin ψ).
        let s = psi.to_radians().sin();
        let want = 2.0 * s / (1.0 - s);
        for k in 3..rows.len() {
            let rate = (rows[k][1] - rows[k - 1][1]) / -(rows[k][2] - rows[k - 1][2]);
            assert!(
                (rate - want).abs() < 1e-6 * want.max(1.0),
                "ψ = {psi}, step {}: dilation rate {rate} vs {want}",
                k + 1
            );
        }
    }
}

#[test]
fn drucker_prager_matched_in_plane_strain_reaches_the_mohr_coulomb_limit() {
    // The cone reaches the limit as σzz settles onto the plane-strain flow (zero plastic zz
    // strain rate); associated flow settles within some tens of plastic steps at this
    // stiffness.
    let dir = workdir("dp-biaxial");
    let limit = exact_limit();
    let rows = biaxial(
        &dir,
        "dp",
        0.0024,
        &[
            "material.model=drucker-prager",
            "material.dilation_angle=30",
            "steps.count=24",
            "prescribed[0].total=[0.0,-0.0024]",
        ],
    );
    let errs: Vec<f64> = rows.iter().map(|r| r[0] / limit - 1.0).collect();
    println!("Drucker–Prager σ1/limit − 1 by step: {errs:?}");
    assert!(errs[2] < -1e-3, "the cone yields below the limit first");
    assert!(errs[23].abs() < 1e-6, "{:e}", errs[23]);
    for k in 3..24 {
        assert!(
            errs[k] <= 1e-9 && errs[k] >= errs[k - 1] - 1e-9,
            "step {}: {errs:?}",
            k + 1
        );
    }
    // The outer cone is stronger in plane strain.
    let outer = biaxial(
        &dir,
        "outer",
        0.001,
        &["material.model=drucker-prager", "material.match=\"outer\""],
    );
    assert!(outer[9][0] > limit * 1.01, "{}", outer[9][0]);
}

fn fails_naming(dir: &Path, sets: &[&str], needles: &[&str]) {
    std::fs::write(dir.join("biaxial.toml"), BIAXIAL).expect("write scene");
    let mut args = vec!["new", "biaxial.toml", "-o", "bad.h5"];
    for s in sets {
        args.extend(["--set", s]);
    }
    let out = run(dir, 1, &args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{sets:?} should fail");
    assert!(!stderr.contains("panicked"), "{sets:?} panicked:\n{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{sets:?}: should name {n:?}:\n{stderr}");
    }
    assert!(!dir.join("bad.h5").exists());
}

#[test]
fn bad_frictional_parameters_name_the_field() {
    let dir = workdir("mc-bad");
    fails_naming(
        &dir,
        &["material.dilation_angle=35"],
        &["material.dilation_angle"],
    );
    fails_naming(
        &dir,
        &["material.friction_angle=90"],
        &["material.friction_angle"],
    );
    fails_naming(&dir, &["material.cohesion=-1"], &["material.cohesion"]);
    fails_naming(
        &dir,
        &[
            "material.cohesion=0",
            "material.friction_angle=0",
            "material.dilation_angle=0",
        ],
        &["material.cohesion"],
    );
    fails_naming(
        &dir,
        &["material.tension_cutoff=-5"],
        &["material.tension_cutoff"],
    );
    fails_naming(&dir, &["material.cu=5e3"], &["material.cu", "tresca"]);
    fails_naming(
        &dir,
        &["material.match=\"outer\""],
        &["material.match", "drucker-prager"],
    );
    fails_naming(
        &dir,
        &[
            "material.model=drucker-prager",
            "material.tension_cutoff=1e3",
        ],
        &["material.tension_cutoff"],
    );
    fails_naming(
        &dir,
        &["material.model=drucker-prager", "material.match=\"middle\""],
        &["match"],
    );
    fails_naming(
        &dir,
        &["material.model=tresca", "material.cu=5e3"],
        &["material.cohesion", "tresca"],
    );
    fails_naming(
        &dir,
        &["history.kind=\"block\""],
        &["history.kind", "mohr-coulomb"],
    );
}
