//! Where a particle put on the axis of revolution goes when its place there lies inside a rigid
//! body of revolution (`Particles::snap_to_axis`).

use crate::rigid::{exit, gap, nearest, Shape};

/// `x` (on the axis) if it lies outside every body in `bodies`; else the point where the axis
/// leaves the body it lies in, found along the axis in the direction the body's nearest surface
/// faces (down from above a cone's tip, up from inside the top of a ball), if that is within the
/// spacing `h`; else `None` (the particle stays off the axis). Put on the axis where it stood, a
/// particle on a cone's face near the tip lay inside the cone: on the coarse `cpt-trial` cloud
/// 0.47 of its spacing in, so that its triangles crossed the cone and were dropped, and the next
/// step ended the run as soil inside the body. Left off the axis instead, such particles under
/// the `spudcan`'s tip crept towards it and Newton stalled at z/D = 0.05.
pub(super) fn out_of_bodies(bodies: &[Shape], x: [f64; 2], h: f64) -> Option<[f64; 2]> {
    let Some(here) = nearest(bodies, x) else {
        return Some(x);
    };
    if here.distance >= 0.0 {
        return Some(x);
    }
    let dir = if here.normal[1] >= 0.0 { 1.0 } else { -1.0 };
    let outside = |y: f64| gap(bodies, [0.0, y]) >= 0.0;
    let far = x[1] + dir * h;
    if !outside(far) {
        return None;
    }
    Some([0.0, exit(x[1], far, outside)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_place_inside_a_body_moves_along_the_axis_to_its_surface() {
        // A 60° cone with its tip at the origin, pointing down, and a ball below y = 0.
        let cone = Shape::polygon(&[[0.0, 0.0], [1.0, 1.732], [-1.0, 1.732]], 0.0).unwrap();
        let ball = Shape::circle([0.0, -2.0], 1.0).unwrap();
        let bodies = [cone, ball];
        // Outside both: unchanged.
        assert_eq!(out_of_bodies(&bodies, [0.0, -0.5], 1.0), Some([0.0, -0.5]));
        // Above the tip, inside the cone: down to the tip.
        let to = out_of_bodies(&bodies, [0.0, 0.3], 1.0).unwrap();
        assert!(to[1].abs() < 1e-12, "{to:?}");
        // Inside the top of the ball: up to its top.
        let to = out_of_bodies(&bodies, [0.0, -1.1], 0.5).unwrap();
        assert!((to[1] + 1.0).abs() < 1e-12, "{to:?}");
        // Deeper than a spacing: stays off the axis.
        assert_eq!(out_of_bodies(&bodies, [0.0, 0.8], 0.5), None);
        // No bodies: unchanged.
        assert_eq!(out_of_bodies(&[], [0.0, 0.3], 1.0), Some([0.0, 0.3]));
    }
}
