//! Rigid bodies the particle cloud can resolve: at least one spacing wide across their motion
//! where they meet the soil, and moving at most one spacing a step while they sweep through
//! it. A narrower body passed between the particles with no force (a pipe of radius h/10
//! pushed 0.03 m in: fy = 0), and one that jumped a metre in a step went through the soil
//! untouched; both ended with exit 0.

use super::field_path::FieldPath;
use super::schema::Scene;
use super::validate::Invalid;
use crate::case_file::ParticleSet;
use crate::rigid::Shape;

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

type Box2 = [[f64; 2]; 2];

fn grown(b: Box2, by: f64) -> Box2 {
    [[b[0][0] - by, b[0][1] - by], [b[1][0] + by, b[1][1] + by]]
}

fn union(a: Box2, b: Box2) -> Box2 {
    [
        [a[0][0].min(b[0][0]), a[0][1].min(b[0][1])],
        [a[1][0].max(b[1][0]), a[1][1].max(b[1][1])],
    ]
}

fn overlaps(a: Box2, b: Box2) -> bool {
    (0..2).all(|c| a[0][c] <= b[1][c] && b[0][c] <= a[1][c])
}

/// The box the body sweeps from displacement `from` to `to`.
fn swept(shape: &Shape, from: [f64; 2], to: [f64; 2]) -> Box2 {
    let at = |d: [f64; 2]| {
        let b = shape.bounding_box();
        [
            [b[0][0] + d[0], b[0][1] + d[1]],
            [b[1][0] + d[0], b[1][1] + d[1]],
        ]
    };
    union(at(from), at(to))
}

/// Whether the box comes within `reach` of the soil (the body's rectangles).
fn near_soil(s: &Scene, b: Box2, reach: f64) -> bool {
    let b = grown(b, reach);
    s.body.rectangles.iter().any(|r| {
        let rb = [r.origin, [r.origin[0] + r.size[0], r.origin[1] + r.size[1]]];
        overlaps(b, rb)
    })
}

/// The largest particle spacing inside the box (the coarsest the body meets there), or
/// `mesh.h` when no particle is.
fn spacing_in(s: &Scene, particles: &ParticleSet, b: Box2) -> f64 {
    let inside = |p: &[f64; 2]| (0..2).all(|c| p[c] >= b[0][c] && p[c] <= b[1][c]);
    particles
        .position
        .iter()
        .zip(&particles.h)
        .filter(|(p, _)| inside(p))
        .map(|(_, h)| *h)
        .fold(None, |m: Option<f64>, h| Some(m.map_or(h, |m| m.max(h))))
        .unwrap_or(s.mesh.h)
}

/// Every stage's width across its motion and its motion per step against the spacing of the
/// soil the body sweeps.
pub(super) fn check(s: &Scene, particles: &ParticleSet) -> Result<(), Invalid> {
    for (i, r) in s.rigid.iter().enumerate() {
        let Ok(shape) = super::validate_rigid::shape_of(s, i) else {
            continue;
        };
        let path = FieldPath::key("rigid").at(i);
        let origin = [0.0; 2];
        let path_box = (r.stages.iter()).fold(swept(&shape, origin, origin), |b, st| {
            union(b, swept(&shape, origin, st.to))
        });
        if !near_soil(s, path_box, s.mesh.h) {
            continue;
        }
        // One particle pass per body: the coarsest spacing anywhere along its path.
        let h = spacing_in(s, particles, grown(path_box, s.mesh.h));
        let what = if r.circle.is_some() {
            path.join("circle").join("radius")
        } else {
            path.join("polygon")
        };
        let mut from = origin;
        for (k, st) in r.stages.iter().enumerate() {
            let b = swept(&shape, from, st.to);
            let d = [st.to[0] - from[0], st.to[1] - from[1]];
            let length = d[0].hypot(d[1]);
            // Across its motion the body must span a spacing, or it passes between particles
            // (a flat platen pressed down spans many; a plate pushed edge-first, none).
            let width = shape.extent_along([-d[1] / length, d[0] / length]);
            if length > 0.0 && width < h * (1.0 - 1e-9) && near_soil(s, b, h) {
                return fail(
                    what,
                    format!(
                        "the body is {width:.3e} m wide across its motion in stage {k}, less \
                         than the particle spacing {h} of the soil it meets: it would pass \
                         between the particles; make it at least {h} m wide or refine the soil \
                         there to a spacing of at most {width:.3e} m ([[mesh.fine]])"
                    ),
                );
            }
            let step = length / st.steps as f64;
            if step > h * (1.0 + 1e-9) && near_soil(s, b, h) {
                let needed = ((st.steps as f64) * step / h).ceil();
                return fail(
                    path.join("stages").at(k).join("steps"),
                    format!(
                        "{} steps move the body {step:.3e} m a step through the soil, more than \
                         its particle spacing {h}: the contact would miss the soil it sweeps \
                         through; give the stage at least {needed} steps",
                        st.steps
                    ),
                );
            }
            from = st.to;
        }
    }
    Ok(())
}
