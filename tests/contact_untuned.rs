//! Issue 30's footing nobody tuned (tests/scenes/untuned-footing.toml): the augmentation loop
//! stopped at step 4 of its push (six cuts, DIVERGED_LINE_SEARCH), and later the drag stage
//! stopped at step 11 with a particle born at the rounded corner inside the footing. Both
//! stages now run to their end, rough and smooth, on 1 and 2 ranks.

mod common;
use common::*;
use std::path::Path;

const SCENE: &str = include_str!("scenes/untuned-footing.toml");

fn column(dir: &Path, out: &str, name: &str) -> Vec<f64> {
    let (header, rows) = history(&dir.join(out).join("history.csv"));
    let i = header.iter().position(|h| h == name).expect(name);
    rows.iter().map(|r| r[i]).collect()
}

/// Runs the scene (with `sets`) to its end on 1 and 2 ranks; returns the 1-rank V/(B cu) and
/// H/(B cu) after asserting that both runs took all 30 steps and the same path, and that the
/// load at the end of the push is that of a footing between the surface and B/6 deep: with six
/// particles across B it scatters by ±4 % from step to step, so the mean of the push's last four
/// steps (z = 0.07–0.1 m) is compared.
fn both_stages_on_one_and_two_ranks(name: &str, sets: &[&str]) -> (Vec<f64>, Vec<f64>) {
    let dir = workdir(name);
    std::fs::write(dir.join("untuned.toml"), SCENE).unwrap();
    let mut args = vec!["new", "untuned.toml", "-o", "u.h5"];
    for s in sets {
        args.extend(["--set", s]);
    }
    ok(&dir, 1, &args);
    for ranks in [1, 2] {
        ok(&dir, ranks, &["u.h5", "--out", &format!("r{ranks}")]);
    }
    let (v, h) = (
        column(&dir, "r1", "V_over_Bcu"),
        column(&dir, "r1", "H_over_Bcu"),
    );
    println!("V/(B cu): {v:?}\nH/(B cu): {h:?}");
    assert_eq!(v.len(), 30, "the push (10 steps) and the drag (20)");
    // Cut steps included, the two rank counts agree to round-off (measured 4e-14).
    for name in ["V_over_Bcu", "H_over_Bcu"] {
        let two = column(&dir, "r2", name);
        assert_eq!(two.len(), 30, "{name} on 2 ranks");
        for (a, b) in column(&dir, "r1", name).iter().zip(two) {
            assert!(
                (a - b).abs() < 1e-8 * (1.0 + a.abs()),
                "{name}: {a} on 1 rank, {b} on 2"
            );
        }
    }
    // By then the footing is d = 0.07–0.1 m deep (d/B up to 1/6): its load lies between
    // Prandtl's on the surface and that times Salgado et al.'s (2004) depth factor
    // 1 + 0.27 √(d/B) = 1.11, within the scatter of the coarse cloud (3 %).
    let prandtl = 2.0 + std::f64::consts::PI;
    let embedded = prandtl * (1.0 + 0.27 * (1.0f64 / 6.0).sqrt());
    let push = v[6..10].iter().sum::<f64>() / 4.0;
    assert!(
        push > 0.97 * prandtl && push < 1.03 * embedded,
        "V/(B cu) {push} at the end of the push against {prandtl} (surface) to {embedded} (d = B/6)"
    );
    (v, h)
}

#[test]
#[ignore = "coarse benchmark: untuned rough footing pushed and dragged on 1 and 2 ranks"]
fn the_untuned_rough_footing_is_pushed_to_prandtls_load_and_dragged_on_one_and_two_ranks() {
    let (v, h) = both_stages_on_one_and_two_ranks("contact-untuned", &[]);
    // At the end of the push: measured 5.404 (+5.1 % on Prandtl; 5.250 before the corners got
    // their nodes).
    // Dragged at its depth d = B/6, the rough base slides on the clay (B cu) and the side faces
    // add Rankine's 2 cu d' each (passive in front, suction behind), d' the embedment with the
    // heave, at most 2d: H/(B cu) between 1 and 1 + 8 d/B = 2.33 once the base slides.
    // Measured 1.54–1.71 over the last 10 steps.
    for (i, hi) in h.iter().enumerate().skip(20) {
        assert!((1.0..2.33).contains(hi), "step {}: H/(B cu) {hi}", i + 1);
    }
    // Sliding relieves the vertical load: measured 1.70 at the end against 5.40 after the push.
    assert!(
        v[29] < 0.5 * v[9],
        "V/(B cu) {} at the end against {} after the push",
        v[29],
        v[9]
    );
}

#[test]
#[ignore = "coarse benchmark: untuned smooth footing pushed and dragged on 1 and 2 ranks"]
fn the_untuned_smooth_footing_is_pushed_and_dragged_on_one_and_two_ranks() {
    let (_, h) =
        both_stages_on_one_and_two_ranks("contact-untuned-smooth", &["rigid[0].adhesion=0"]);
    // At the end of the push: measured 5.126 (−0.3 % on Prandtl).
    // A smooth base carries no shear: only the side faces resist, at most 8 d/B = 1.33 (as
    // above); measured 0.26–0.62 from step 16 on.
    for (i, hi) in h.iter().enumerate().skip(15) {
        assert!(*hi > 0.0 && *hi < 1.33, "step {}: H/(B cu) {hi}", i + 1);
    }
}
