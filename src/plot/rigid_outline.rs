//! The rigid bodies of a contour picture: each `[[rigid]]` body of the run's `scene.toml`, at
//! the place its stages have moved it to by the frame's step (the motion is prescribed, so the
//! scene and the step say where it is; the frame files hold only the soil).

use crate::rigid::Shape;
use crate::scene::Scene;

/// Points around a body's outline: enough that a circle looks round at any zoom.
const OUTLINE_POINTS: f64 = 180.0;

/// Outline of every rigid body of `scene` after `step` steps, counter-clockwise; a body whose
/// shape the scene cannot make (a damaged `scene.toml`) is left out.
pub(crate) fn outlines(scene: &Scene, step: u64) -> Vec<Vec<[f64; 2]>> {
    (0..scene.rigid.len())
        .filter_map(|i| {
            let shape = crate::scene::validate_rigid::shape_of(scene, i).ok()?;
            let moved = shape.translated(scene.rigid[i].displacement_at(step as f64));
            outline(&moved)
        })
        .collect()
}

fn outline(shape: &Shape) -> Option<Vec<[f64; 2]>> {
    let [[x0, y0], [x1, y1]] = shape.bounding_box();
    let perimeter = 2.0 * ((x1 - x0) + (y1 - y0));
    let spacing = perimeter / OUTLINE_POINTS;
    (spacing > 0.0 && spacing.is_finite()).then(|| shape.surface_points(spacing))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_t_bar_is_drawn_where_its_stage_has_moved_it() {
        let (scene, _) = crate::scene::load_scene("tbar-smooth", &[]).unwrap();
        // The bar, a 0.02 m circle at (0, 0.44), moves 0.06 m down over 150 steps.
        let at = |step: u64| {
            let o = &outlines(&scene, step)[0];
            assert!(o.len() >= 100, "{} points", o.len());
            let lowest = o.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min);
            let r = o.iter().map(|p| p[0]).fold(0.0, f64::max);
            (lowest, r)
        };
        let (bottom, r) = at(0);
        assert!(
            (bottom - 0.42).abs() < 1e-9 && (r - 0.02).abs() < 1e-4,
            "{bottom} {r}"
        );
        let (bottom, _) = at(75);
        assert!((bottom - 0.39).abs() < 1e-9, "{bottom}");
        let (scene, _) = crate::scene::load_scene("cantilever", &[]).unwrap();
        assert!(outlines(&scene, 10).is_empty());
    }
}
