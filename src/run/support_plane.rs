//! Sliding supports on a straight line (a symmetry plane `x <= 0` holding x) and the particles
//! that pass them.
//!
//! A `[[fixed]]` entry holds the particles whose reference position it selects. A particle born
//! by refinement off the plane (on a rigid body's face beside it: its reference position is
//! interpolated) is free, and where the flow converges on the plane (behind a T-bar, where the
//! soil closes round it) a step can carry it across: on the softening T-bar's coarse cloud one
//! went to x = −0.0047 (spacing 0.01), the plane's boundary ran through it, and the held
//! particles beside it could no longer merge. Put back on the line, it is held from then on.

use crate::particles::Particles;
use crate::scene::{Axis, Fixed};

/// Particles on one side of x_c = `face` are held in component `c`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SupportPlane {
    pub component: usize,
    pub face: f64,
    /// Held below the face (`x <= face`) rather than above it.
    pub below: bool,
}

/// The `[[fixed]]` entries that are sliding supports on a straight line: one held component,
/// `where` a half-plane across it (one bound along that axis, none along the other), no `on`
/// or `within`.
pub(super) fn support_planes(fixed: &[Fixed]) -> Vec<SupportPlane> {
    fixed
        .iter()
        .filter_map(|f| {
            let [d] = f.dofs[..] else {
                return None;
            };
            if f.on.is_some() || f.within.is_some() {
                return None;
            }
            let component = d.index();
            let (axis, other) = if component == 0 {
                (Axis::X, Axis::Y)
            } else {
                (Axis::Y, Axis::X)
            };
            let (olo, ohi) = f.region.interval(other);
            if olo.is_finite() || ohi.is_finite() {
                return None;
            }
            match f.region.interval(axis) {
                (lo, hi) if lo.is_infinite() && hi.is_finite() => Some(SupportPlane {
                    component,
                    face: hi,
                    below: true,
                }),
                (lo, hi) if lo.is_finite() && hi.is_infinite() => Some(SupportPlane {
                    component,
                    face: lo,
                    below: false,
                }),
                _ => None,
            }
        })
        .collect()
}

impl SupportPlane {
    /// Rank-local. Puts every particle the plane does not hold (reference position off it by
    /// more than `tol`) that has passed its face back on the face, its reference position on it
    /// too (its displacement in that component set to zero), so that the plane holds it from
    /// then on; not where that place lies inside a rigid body (`outside(x)` false): a particle
    /// on a T-bar's face beside its lowest point would go into the bar. Returns how many moved.
    pub fn put_back(
        &self,
        particles: &mut Particles,
        tol: f64,
        outside: impl Fn([f64; 2]) -> bool,
    ) -> usize {
        let c = self.component;
        let (face, below) = (self.face, self.below);
        let held = |x0: f64| {
            if below {
                x0 <= face + tol
            } else {
                x0 >= face - tol
            }
        };
        let past = |x: f64| if below { x < face } else { x > face };
        let mut moved = 0;
        for i in 0..particles.position.len() {
            let x = particles.position[i][c];
            let x0 = x - particles.displacement[i][c];
            if held(x0) || !past(x) {
                continue;
            }
            let mut to = particles.position[i];
            to[c] = self.face;
            if !outside(to) {
                continue;
            }
            particles.position[i][c] = self.face;
            particles.displacement[i][c] = 0.0;
            particles.increment[i][c] = 0.0;
            moved += 1;
        }
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene;

    #[test]
    fn symmetry_planes_are_found_and_a_particle_past_one_goes_back_on_it() {
        // The T-bar's half model: symmetry plane x = 0, far side x = 0.4 (both hold x), base
        // (holds both: not a sliding support).
        let (scene, _) = load_scene("tbar-smooth", &[]).expect("built-in scene");
        let planes = support_planes(&scene.fixed);
        assert_eq!(
            planes,
            vec![
                SupportPlane {
                    component: 0,
                    face: 0.0,
                    below: true
                },
                SupportPlane {
                    component: 0,
                    face: 0.4,
                    below: false
                },
            ]
        );
        let mut p = Particles::default();
        // Born off the plane (x0 = 0.05), carried to x = -0.02; one held on it (x0 = 0) that
        // round-off put at -1e-18; one inside.
        for (x, u) in [
            ([-0.02, 0.5], [-0.07, 0.1]),
            ([-1e-18, 0.3], [-1e-18, 0.0]),
            ([0.3, 0.3], [0.01, 0.0]),
        ] {
            p.gid.push(p.gid.len() as u64);
            p.position.push(x);
            p.displacement.push(u);
            p.increment.push(u);
            p.h.push(0.25);
            p.flags.push(0);
            p.material.push(0);
        }
        // Not where its place on the plane lies inside a body.
        assert_eq!(planes[0].put_back(&mut p, 1e-9, |x| x[1] < 0.4), 0);
        assert_eq!(p.position[0], [-0.02, 0.5]);
        assert_eq!(planes[0].put_back(&mut p, 1e-9, |_| true), 1);
        assert_eq!(p.position[0], [0.0, 0.5]);
        assert_eq!(p.displacement[0], [0.0, 0.1]);
        assert_eq!(p.increment[0], [0.0, 0.1]);
        assert_eq!(p.position[1], [-1e-18, 0.3]);
        assert_eq!(p.position[2], [0.3, 0.3]);
        assert_eq!(planes[1].put_back(&mut p, 1e-9, |_| true), 0);
    }
}
