//! Checks, on the generated particles, that what follows a point of the body finds one: point
//! loads and probes sit on the body (within a spacing of a particle, not inside a rigid body),
//! a `[[surface_pressure]]` selects at least one boundary edge, and the geostatic surface is
//! not below the ground it loads.

use super::field_path::FieldPath;
use super::lattice;
use super::schema::Scene;
use super::validate::Invalid;
use crate::case_file::ParticleSet;
use crate::rigid::Shape;

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

/// `at` (of the entry at `path`) must lie within one spacing of the nearest particle and not
/// inside a rigid body: the nearest particle of a point elsewhere is an arbitrary one.
fn check_on_body(
    s: &Scene,
    particles: &ParticleSet,
    shapes: &[Shape],
    path: FieldPath,
    at: [f64; 2],
) -> Result<(), Invalid> {
    let Some((gid, dist)) = lattice::nearest(particles, at) else {
        return Ok(());
    };
    // An imported node's own spacing may exceed mesh.h.
    let h = (particles.gid.iter().position(|&g| g == gid))
        .map_or(s.mesh.h, |i| particles.h[i].max(s.mesh.h));
    if dist > h * (1.0 + 1e-9) {
        return fail(
            path,
            format!(
                "[{}, {}] is {dist:.4} m from the nearest particle; it must lie within one \
                 particle spacing ({h}) of the body",
                at[0], at[1]
            ),
        );
    }
    for (shape, r) in shapes.iter().zip(&s.rigid) {
        if shape.closest(at).distance < -s.tolerance() {
            return fail(
                path,
                format!(
                    "[{}, {}] is inside the rigid body \"{}\", not on the soil",
                    at[0], at[1], r.name
                ),
            );
        }
    }
    Ok(())
}

/// Whether the particle at `p` (spacing `h`) lies on the body's outline: half a spacing from
/// it in one of the four lattice directions is outside every rectangle or inside a rigid body.
fn on_outline(s: &Scene, shapes: &[Shape], p: [f64; 2], h: f64) -> bool {
    let tol = s.tolerance();
    [[0.5, 0.0], [-0.5, 0.0], [0.0, 0.5], [0.0, -0.5]]
        .iter()
        .any(|d| {
            let q = [p[0] + d[0] * h, p[1] + d[1] * h];
            let in_rect = s.body.rectangles.iter().any(|r| {
                (0..2).all(|c| q[c] >= r.origin[c] - tol && q[c] <= r.origin[c] + r.size[c] + tol)
            });
            !in_rect || shapes.iter().any(|sh| sh.closest(q).distance < 0.0)
        })
}

/// A `[[surface_pressure]]` acts on the boundary edges whose two ends start in `where`: it
/// must select two outline particles within one and a half spacings of each other.
fn check_surface_pressure(
    s: &Scene,
    particles: &ParticleSet,
    shapes: &[Shape],
) -> Result<(), Invalid> {
    let tol = s.tolerance();
    let boundaries = crate::model::named_boundaries(s);
    for (k, sp) in s.surface_pressure.iter().enumerate() {
        let on = |p: [f64; 2]| {
            (sp.on.as_deref())
                .is_none_or(|n| crate::model::on_boundary(&boundaries, n, p, s.mesh.h))
        };
        let picked: Vec<([f64; 2], f64)> = particles
            .position
            .iter()
            .zip(&particles.h)
            .filter(|(p, h)| {
                sp.region.matches(**p, tol) && on(**p) && on_outline(s, shapes, **p, **h)
            })
            .map(|(p, h)| (*p, *h))
            .collect();
        let edge = picked.iter().enumerate().any(|(i, (p, hp))| {
            picked[i + 1..].iter().any(|(q, hq)| {
                let reach = 1.5 * hp.max(*hq);
                (p[0] - q[0]).hypot(p[1] - q[1]) <= reach
            })
        });
        if !edge {
            let (key, what) = match (&sp.on, sp.region.is_all()) {
                (Some(on), true) => ("on", format!("on = \"{on}\"")),
                (Some(on), false) => ("where", format!("\"{}\" on \"{on}\"", sp.region)),
                (None, _) => ("where", format!("\"{}\"", sp.region)),
            };
            return fail(
                FieldPath::key("surface_pressure").at(k).join(key),
                format!(
                    "{what} selects no boundary edge of the body ({} particle(s) of its \
                     outline): the pressure would act on nothing",
                    picked.len()
                ),
            );
        }
    }
    Ok(())
}

/// Below the top of the body the geostatic stress of the ground above the surface would be
/// tension.
fn check_geostatic_surface(s: &Scene) -> Result<(), Invalid> {
    let Some(g) = &s.geostatic else {
        return Ok(());
    };
    let top = s.bounding_box()[1][1];
    if g.surface < top - s.tolerance() {
        return fail(
            FieldPath::key("geostatic").join("surface"),
            format!(
                "{} is below the top of the body ({top}): the soil above it would start in \
                 tension; the surface is the level of the ground, usually the body's top",
                g.surface
            ),
        );
    }
    Ok(())
}

/// All the checks of this module, on the particles of the generated lattice.
pub(super) fn check(s: &Scene, particles: &ParticleSet) -> Result<(), Invalid> {
    let shapes: Vec<Shape> = (0..s.rigid.len())
        .filter_map(|i| super::validate_rigid::shape_of(s, i).ok())
        .collect();
    for (i, p) in s.point_load.iter().enumerate() {
        let path = FieldPath::key("point_load").at(i).join("at");
        check_on_body(s, particles, &shapes, path, p.at)?;
    }
    for (i, p) in s.probe.iter().enumerate() {
        let path = FieldPath::key("probe").at(i).join("at");
        check_on_body(s, particles, &shapes, path, p.at)?;
    }
    check_surface_pressure(s, particles, &shapes)?;
    check_geostatic_surface(s)
}
