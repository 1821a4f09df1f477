//! Tresca clay with the mixed P2–P1 element through the whole PFEM loop (remeshing every step):
//! plane-strain compression between smooth rigid platens holds the exact 2·cu once yielded and
//! keeps the volume, on 1 and 2 ranks. (To 15 % strain here: beyond that the homogeneous solution
//! of this perfectly plastic model bifurcates into shear bands, from round-off, at a strain that
//! depends on the rank count — see the README.)

mod common;
use common::*;

#[test]
fn block_compression_holds_two_cu_and_the_volume() {
    let dir = workdir("block");
    ok(
        &dir,
        1,
        &[
            "new",
            "block-compression",
            "-o",
            "b.h5",
            "--set",
            "steps.count=30",
            "--set",
            "prescribed[0].total=[0.0,-0.075]",
            "--set",
            "prescribed[1].total=[0.0,0.075]",
        ],
    );
    for ranks in [1, 2] {
        let out = format!("r{ranks}");
        ok(&dir, ranks, &["b.h5", "--out", &out]);
        let (header, rows) = history(&dir.join(&out).join("history.csv"));
        assert_eq!(header, ["step", "strain", "stress_over_cu", "volume_ratio"]);
        assert_eq!(rows.len(), 30);
        assert!((rows[29][1] - 0.15).abs() < 1e-12, "strain {}", rows[29][1]);
        let mut worst_stress: f64 = 0.0;
        let mut worst_volume: f64 = 0.0;
        for r in &rows[1..] {
            worst_stress = worst_stress.max((r[2] - 2.0).abs() / 2.0);
            worst_volume = worst_volume.max((r[3] - 1.0).abs());
        }
        println!("{ranks} ranks: stress/cu off 2 by at most {worst_stress:.2e} (relative), volume by {worst_volume:.2e}");
        assert!(
            worst_stress < 0.01,
            "stress/cu must stay within 1 % of 2 once yielded"
        );
        assert!(
            worst_volume < 0.005,
            "volume must change by less than 0.5 %"
        );
    }
}
