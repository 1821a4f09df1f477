//! Tresca clay with the mixed P2–P1 element through the whole PFEM loop (remeshing every step,
//! refinement splitting the stretched lattice twice): the built-in plane-strain compression
//! between smooth rigid platens holds the exact 2·cu once yielded and keeps the volume all the
//! way to 50 % strain, on 1, 2 and 3 ranks.

mod common;
use common::*;

#[test]
fn block_compression_holds_two_cu_and_the_volume() {
    let dir = workdir("block");
    ok(&dir, 1, &["new", "block-compression", "-o", "b.h5"]);
    for ranks in [1, 2, 3] {
        let out = format!("r{ranks}");
        let steps = json_steps(&ok(
            &dir,
            ranks,
            &["b.h5", "--out", &out, "--progress", "json"],
        ));
        assert_eq!(steps.len(), 100, "one object a step");
        // The lattice is split as it stretches, so the mapping is exercised, not just skipped.
        let particles: Vec<u64> = steps
            .iter()
            .filter_map(|s| s["particles"].as_u64())
            .collect();
        assert!(
            particles.contains(&121) && particles.contains(&241),
            "refinement should take the block from 121 to 241 particles: {particles:?}"
        );
        // Between the splits the homogeneously compressed lattice keeps its mesh: no triangle is
        // remapped (round-off used to flip its cocircular cells' diagonals every step).
        let step50 = &steps[49];
        assert_eq!(step50["step"], 50);
        assert_eq!(step50["remapped"], 0, "{step50}");
        let (header, rows) = history(&dir.join(&out).join("history.csv"));
        assert_eq!(header, ["step", "strain", "stress_over_cu", "volume_ratio"]);
        assert_eq!(rows.len(), 100);
        assert!((rows[99][1] - 0.5).abs() < 1e-12, "strain {}", rows[99][1]);
        let mut worst_stress: f64 = 0.0;
        let mut worst_volume: f64 = 0.0;
        for r in &rows[1..] {
            worst_stress = worst_stress.max((r[2] - 2.0).abs() / 2.0);
            worst_volume = worst_volume.max((r[3] - 1.0).abs());
        }
        println!("{ranks} ranks: stress/cu off 2 by at most {worst_stress:.2e} (relative), volume by {worst_volume:.2e}");
        // The issue asks for 1 %. The homogeneous flow on this lattice keeps its mesh except where
        // refinement splits it, so 2·cu holds to round-off (measured 1e-12); bands would show far
        // above 1e-6.
        assert!(
            worst_stress < 1e-6,
            "stress/cu off 2 by {worst_stress:e} once yielded"
        );
        assert!(
            worst_volume < 0.005,
            "volume must change by less than 0.5 %"
        );
    }
}
