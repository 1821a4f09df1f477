use super::*;

fn close(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12
}

#[test]
fn a_rounded_rectangle_has_its_four_arc_middles_as_corners() {
    let r = 0.02;
    let plate = Shape::polygon(&[[-1.0, 10.0], [1.0, 10.0], [1.0, 10.5], [-1.0, 10.5]], r).unwrap();
    let corners = sharp_corners(&[plate]);
    assert_eq!(corners.len(), 4);
    let off = r * (1.0 - std::f64::consts::FRAC_1_SQRT_2);
    for want in [
        [1.0 - off, 10.0 + off],
        [-1.0 + off, 10.0 + off],
        [1.0 - off, 10.5 - off],
        [-1.0 + off, 10.5 - off],
    ] {
        assert!(
            corners
                .iter()
                .any(|(b, c)| *b == 0 && close(c.middle(), want) && c.radius == r),
            "{want:?} not in {corners:?}"
        );
    }
    for (_, c) in &corners {
        assert!(
            (c.turn() - std::f64::consts::FRAC_PI_2).abs() < 1e-12,
            "{c:?}"
        );
    }
}

#[test]
fn shallow_and_hidden_corners_are_left_out() {
    // A flat cone (13° from the horizontal, its tip turning by 26°) and a sharp triangle whose
    // top corners lie inside a box above it.
    let flat = Shape::polygon(&[[0.0, 0.0], [5.0, 1.154], [-5.0, 1.154]], 0.0).unwrap();
    let tips: Vec<_> = sharp_corners(std::slice::from_ref(&flat))
        .into_iter()
        .filter(|(_, c)| c.middle()[1] < 0.5)
        .collect();
    assert!(tips.is_empty(), "{tips:?}");
    let cone = Shape::polygon(&[[0.0, 0.0], [1.0, 1.732], [-1.0, 1.732]], 0.0).unwrap();
    let shaft = Shape::polygon(&[[-1.1, 1.7], [1.1, 1.7], [1.1, 5.0], [-1.1, 5.0]], 0.0).unwrap();
    let corners = sharp_corners(&[cone, shaft]);
    // The cone's tip and the shaft's four corners; the cone's top corners are inside the shaft.
    assert_eq!(corners.len(), 5, "{corners:?}");
    assert!(corners
        .iter()
        .any(|(b, c)| *b == 0 && close(c.middle(), [0.0, 0.0])));
    assert_eq!(corners.iter().filter(|(b, _)| *b == 1).count(), 4);
}

#[test]
fn the_nearest_particle_within_reach_of_an_unresolved_corner_is_chosen() {
    let at = |radius: f64| Corner {
        vertex: [1.0, 1.0],
        normals: [[1.0, 0.0], [0.0, 1.0]],
        radius,
    };
    // The arc's middle at radius 0 is the vertex itself.
    let sharp = at(0.0);
    let cand = |v: &[(usize, [f64; 2], f64, u64)]| nearest_candidate(&sharp, v.iter().copied());
    // Within 0.3 spacings: the nearer one.
    let got = cand(&[(0, [1.05, 1.0], 0.25, 7), (1, [1.0, 0.96], 0.25, 9)]).unwrap();
    assert_eq!(got.2, 1);
    // Equal distances: the smaller key, whatever the order.
    let got = cand(&[(0, [1.05, 1.0], 0.25, 9), (1, [1.0, 0.95], 0.25, 3)]).unwrap();
    assert_eq!(got.1, 3);
    // Beyond reach: none.
    assert!(cand(&[(0, [1.1, 1.0], 0.25, 1)]).is_none());
    // A corner rounded over a spacing or more is left to the curved edges.
    let resolved = nearest_candidate(&at(0.25), [(0, [1.01, 1.0], 0.25, 1)].into_iter());
    assert!(resolved.is_none());
    // Distances are to the middle of the arc, not to the vertex.
    let rounded = at(0.02);
    let m = rounded.middle();
    let on_middle = nearest_candidate(&rounded, [(4, m, 0.25, 1)].into_iter()).unwrap();
    assert_eq!(on_middle.0, 0.0);
}
