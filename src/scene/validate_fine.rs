//! Checks of the `[[mesh.fine]]` regions that `check_fields` cannot make alone: where they lie,
//! how their lattices fit the coarser one, and how many particles they would make. All run
//! before any particle is generated.

use super::field_path::FieldPath;
use super::lattice;
use super::schema::{FineRegion, Scene};
use super::validate::{Invalid, MAX_PARTICLES};

fn fail<T>(path: FieldPath, message: String) -> Result<T, Invalid> {
    Err((path, message))
}

fn overlap(a_origin: [f64; 2], a_size: [f64; 2], b_origin: [f64; 2], b_size: [f64; 2]) -> bool {
    (0..2).all(|c| a_origin[c] < b_origin[c] + b_size[c] && b_origin[c] < a_origin[c] + a_size[c])
}

/// Particles a lattice of spacing `h` over `size` holds at most (edges included).
pub(super) fn lattice_count(size: [f64; 2], h: f64) -> f64 {
    (size[0] / h + 1.0) * (size[1] / h + 1.0)
}

/// The spacing region `r` refines: the finest coarser region it overlaps, else `mesh.h`.
fn coarser_spacing(s: &Scene, r: &FineRegion) -> f64 {
    s.mesh
        .fine
        .iter()
        .filter(|o| o.h > r.h && overlap(o.origin, o.size, r.origin, r.size))
        .map(|o| o.h)
        .fold(s.mesh.h, f64::min)
}

/// The refined lattice must pass through the coarser lattice's points, or the graded cloud has
/// slivers and gaps along the region's edges (the schema's rule).
fn check_fits(s: &Scene, i: usize, path: &FieldPath) -> Result<(), Invalid> {
    let r = &s.mesh.fine[i];
    let coarse = coarser_spacing(s, r);
    let ratio = coarse / r.h;
    if lattice::whole(ratio).is_none() {
        return fail(
            path.join("h"),
            format!(
                "{} is not a whole fraction of the coarser spacing {coarse} (ratio {ratio:.4}); \
                 use e.g. {}",
                r.h,
                coarse / ratio.round().max(2.0)
            ),
        );
    }
    let anchor = s.body.rectangles[0].origin;
    for axis in 0..2 {
        let offset = (r.origin[axis] - anchor[axis]) / coarse;
        if lattice::whole(offset).is_none() {
            return fail(
                path.join("origin"),
                format!(
                    "{} along {} is {offset:.4} coarser spacings ({coarse}) from the body's \
                     lattice origin; it must be a whole number",
                    r.origin[axis],
                    ["x", "y"][axis]
                ),
            );
        }
        let count = r.size[axis] / coarse;
        if lattice::whole(count).is_none() {
            return fail(
                path.join("size"),
                format!(
                    "{} along {} is {count:.4} coarser spacings ({coarse}); it must be a whole \
                     number",
                    r.size[axis],
                    ["x", "y"][axis]
                ),
            );
        }
    }
    Ok(())
}

/// Checks every `[[mesh.fine]]` region: it overlaps the body, its spacing and edges fit the
/// coarser lattice, and with the body's own lattice it stays under [`MAX_PARTICLES`], counted
/// from the areas before any particle exists (a tiny `h` would otherwise fill memory first).
pub fn check(s: &Scene) -> Result<(), Invalid> {
    if !s.body.zones.is_empty() {
        return check_in_zones(s);
    }
    let fine = FieldPath::key("mesh").join("fine");
    let body = &s.body.rectangles;
    let mut total: f64 = body.iter().map(|r| lattice_count(r.size, s.mesh.h)).sum();
    let mut largest = None::<(usize, f64)>;
    for (i, r) in s.mesh.fine.iter().enumerate() {
        let count = lattice_count(r.size, r.h);
        total += count;
        if largest.is_none_or(|(_, c)| count > c) {
            largest = Some((i, count));
        }
    }
    if let Some((i, count)) = largest.filter(|_| total > MAX_PARTICLES as f64) {
        return fail(
            fine.at(i).join("h"),
            format!(
                "h = {} would create about {count:.3e} particles in this region, more than the \
                 limit of {MAX_PARTICLES} for the whole body ({})",
                s.mesh.fine[i].h,
                super::validate::LIMIT_REASON
            ),
        );
    }
    for (i, r) in s.mesh.fine.iter().enumerate() {
        let path = fine.at(i);
        if !body
            .iter()
            .any(|b| overlap(b.origin, b.size, r.origin, r.size))
        {
            return fail(
                path.clone(),
                format!(
                    "the region from [{}, {}] of size [{}, {}] lies outside the body (no \
                     rectangle of body.rectangles overlaps it)",
                    r.origin[0], r.origin[1], r.size[0], r.size[1]
                ),
            );
        }
        check_fits(s, i, &path)?;
    }
    Ok(())
}

/// Regions of a zone body: each lies (partly) in the body, its spacing divides `mesh.h` a whole
/// number of times (its lattice nests in the body's), and the particles they would make,
/// counted from the areas, stay under [`MAX_PARTICLES`].
fn check_in_zones(s: &Scene) -> Result<(), Invalid> {
    let fine = FieldPath::key("mesh").join("fine");
    let zones = super::zones::shapes(s)?;
    let mut total = super::zones::area(s) / (s.mesh.h * s.mesh.h);
    for (i, r) in s.mesh.fine.iter().enumerate() {
        let at = fine.at(i);
        let shape = super::zones::fine_region(r, &at)?;
        if !zones.iter().any(|z| crate::geometry::overlap(z, &shape)) {
            return fail(
                at,
                "lies outside the body (it overlaps no zone)".to_string(),
            );
        }
        let ratio = s.mesh.h / r.h;
        if lattice::whole(ratio).is_none() {
            return fail(
                at.join("h"),
                format!(
                    "{} does not divide mesh.h = {} a whole number of times (ratio {ratio:.4}); \
                     use e.g. {}",
                    r.h,
                    s.mesh.h,
                    s.mesh.h / ratio.round().max(2.0)
                ),
            );
        }
        total += shape.area() / (r.h * r.h);
        if total > MAX_PARTICLES as f64 {
            return fail(
                at.join("h"),
                format!(
                    "h = {} would bring the body to about {total:.3e} particles, more than the \
                     limit of {MAX_PARTICLES} ({})",
                    r.h,
                    super::validate::LIMIT_REASON
                ),
            );
        }
    }
    Ok(())
}
