//! Curved boundary edges. A P2 boundary edge's midside node moves with the body during an
//! increment and ends off its chord (the soil wrapping round a rounded corner, a heaving free
//! surface). Rebuilt straight at the next remesh, that shape is lost: the chord of a rounded
//! corner then cuts into the body by about a fifth of a spacing, and Newton's first iterate pulls
//! the soil out of it. A boundary edge whose two particles are still joined after the remesh keeps
//! its midside offset from the chord instead, as a fraction of the chord's length across it (so
//! that moving an end by refinement or smoothing moves the curve with it).

use crate::fem::p2::{self, N_NODES};

/// Offsets larger than this fraction of the chord are not believed: a P2 edge cannot carry such
/// a curve without folding its triangle.
pub const MAX_BULGE: f64 = 0.25;

/// Offsets smaller than this fraction of the chord are the solver's tolerance, not a shape
/// (Newton's noise at the default tolerance is about 1e-8 to 1e-6 of the chord): they are not
/// kept, so a boundary straight in the exact solution stays exactly straight. Kept, such noise
/// on a cylinder squeezed between platens, whose stress is exactly uniform, spread it by 4e-7 of
/// its strength.
pub const MIN_BULGE: f64 = 1e-5;

/// The smallest Jacobian of a curved triangle at its nodes and centroid, over its straight
/// triangle's, for its curve to be kept.
pub const MIN_JACOBIAN_RATIO: f64 = 0.3;

/// Offset of `m` from the midpoint of chord `a`→`b` along the chord's right-hand normal, over the
/// chord's length (0 for a degenerate chord). Give `a`, `b` in key order (smaller gid first), so
/// that every rank finds the same sign.
pub fn bulge(a: [f64; 2], b: [f64; 2], m: [f64; 2]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    if len2 <= 0.0 {
        return 0.0;
    }
    let off = [m[0] - 0.5 * (a[0] + b[0]), m[1] - 0.5 * (a[1] + b[1])];
    (off[0] * d[1] - off[1] * d[0]) / len2
}

/// The midside node of chord `a`→`b` (key order) with relative offset `s` ([`bulge`]).
pub fn midside(a: [f64; 2], b: [f64; 2], s: f64) -> [f64; 2] {
    let d = [b[0] - a[0], b[1] - a[1]];
    [
        0.5 * (a[0] + b[0]) + s * d[1],
        0.5 * (a[1] + b[1]) - s * d[0],
    ]
}

/// Whether the six-node triangle `x` (vertices CCW) is a fair curved copy of its straight
/// triangle: det J at its six nodes and centroid at least [`MIN_JACOBIAN_RATIO`] of the straight
/// one's. det J of a P2 triangle is quadratic in (ξ, η), so these seven points sample it where it
/// turns.
pub fn keeps_shape(x: &[[f64; 2]; N_NODES]) -> bool {
    let v = [x[0], x[1], x[2]];
    let straight =
        (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
    if straight.is_nan() || straight <= 0.0 {
        return false;
    }
    let centroid = [1.0 / 3.0, 1.0 / 3.0];
    p2::REFERENCE_NODES
        .iter()
        .chain(std::iter::once(&centroid))
        .all(|&xi| match p2::physical_gradients(x, xi) {
            Ok(g) => g.det_j >= MIN_JACOBIAN_RATIO * straight,
            Err(_) => false,
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fem::p2::straight_sided;

    #[test]
    fn bulge_and_midside_are_inverse_and_scale_with_the_chord() {
        let (a, b) = ([0.3, -0.2], [1.9, 0.4]);
        for s in [-0.2, -0.01, 0.0, 0.07, 0.2] {
            let m = midside(a, b, s);
            assert!((bulge(a, b, m) - s).abs() < 1e-15, "{s}");
        }
        // A unit chord along x: a positive offset lies on its right, below.
        let m = midside([0.0, 0.0], [1.0, 0.0], 0.1);
        assert!((m[0] - 0.5).abs() < 1e-15 && (m[1] + 0.1).abs() < 1e-15);
        // Reversing the chord flips the sign; a degenerate chord has none.
        assert!((bulge(b, a, midside(a, b, 0.1)) + 0.1).abs() < 1e-15);
        assert_eq!(bulge(a, a, [5.0, 5.0]), 0.0);
    }

    #[test]
    fn a_circle_arc_keeps_its_sagitta() {
        // Chord of a unit circle over 40°: the arc's midpoint lies the sagitta off the chord.
        let t: f64 = 20f64.to_radians();
        let (a, b) = ([t.sin(), t.cos()], [-t.sin(), t.cos()]);
        let m = [0.0, 1.0];
        let s = bulge(a, b, m);
        let chord = 2.0 * t.sin();
        assert!((s.abs() * chord - (1.0 - t.cos())).abs() < 1e-15);
        // Moved with its chord, the curve follows.
        let shift = |p: [f64; 2]| [p[0] + 3.0, p[1] - 1.0];
        let m2 = midside(shift(a), shift(b), s);
        assert!((m2[0] - 3.0).abs() < 1e-15 && (m2[1] - 0.0).abs() < 1e-15);
    }

    #[test]
    fn shape_check_accepts_mild_curves_and_rejects_folds() {
        let v = [[0.0, 0.0], [1.0, 0.0], [0.4, 0.9]];
        let mut x = straight_sided(&v);
        assert!(keeps_shape(&x));
        // Edge 01 bulging outwards (below) by a tenth of its length.
        x[3] = midside(v[0], v[1], 0.1);
        assert!(keeps_shape(&x));
        // Bulging inwards by 0.45 of the chord nearly reaches the opposite vertex.
        x[3] = midside(v[0], v[1], -0.45);
        assert!(!keeps_shape(&x));
        // Clockwise triangles are never kept.
        let cw = straight_sided(&[v[0], v[2], v[1]]);
        assert!(!keeps_shape(&cw));
    }
}
