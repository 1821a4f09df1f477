//! `[[body.zones]]`: the scene's zone tables as [`crate::geometry`] shapes, their checks, and the
//! particle cloud that fills them.

use super::field_path::FieldPath;
use super::schema::{Scene, Zone};
use crate::case_file::ParticleSet;
use crate::geometry::{self, FillParams, Shape};

/// The shape of zone `z`, checked (simple polygon, holes inside, positive radius and sizes), or
/// the field at fault with a message.
pub fn shape(z: &Zone, at: &FieldPath) -> Result<Shape, (FieldPath, String)> {
    let given = [
        z.polygon.is_some(),
        z.circle.is_some(),
        z.rectangle.is_some(),
    ];
    if given.iter().filter(|g| **g).count() != 1 {
        return Err((
            at.clone(),
            "needs exactly one of `polygon`, `circle` or `rectangle`".to_string(),
        ));
    }
    let finite = |p: &[f64; 2]| p.iter().all(|x| x.is_finite());
    if z.polygon.is_none() {
        let key = match (
            z.holes.is_empty(),
            z.edges.is_empty(),
            z.hole_edges.is_empty(),
        ) {
            (false, _, _) => Some("holes"),
            (_, false, _) => Some("edges"),
            (_, _, false) => Some("hole_edges"),
            _ => None,
        };
        if let Some(key) = key {
            return Err((at.join(key), "belongs to a `polygon` zone".to_string()));
        }
    }
    if let Some(c) = &z.circle {
        if !finite(&c.centre) {
            return Err((
                at.join("circle").join("centre"),
                "must be finite".to_string(),
            ));
        }
        return geometry::Circle::new(c.centre, c.radius)
            .map(Shape::Circle)
            .map_err(|e| (at.join("circle"), e.to_string()));
    }
    if let Some(r) = &z.rectangle {
        if !finite(&r.origin) || !finite(&r.size) {
            return Err((at.join("rectangle"), "must be finite".to_string()));
        }
        return geometry::Rectangle::new(r.origin, r.size)
            .map(Shape::Rectangle)
            .map_err(|e| (at.join("rectangle"), e.to_string()));
    }
    let outer = z.polygon.clone().unwrap_or_default();
    if let Some(k) = outer.iter().position(|p| !finite(p)) {
        return Err((at.join("polygon"), format!("vertex {k} is not finite")));
    }
    for (h, hole) in z.holes.iter().enumerate() {
        if let Some(k) = hole.iter().position(|p| !finite(p)) {
            return Err((at.join("holes").at(h), format!("vertex {k} is not finite")));
        }
    }
    if z.hole_edges.len() > z.holes.len() {
        return Err((
            at.join("hole_edges"),
            format!(
                "names the edges of {} holes but the polygon has {}",
                z.hole_edges.len(),
                z.holes.len()
            ),
        ));
    }
    let named = |n: &String| (!n.trim().is_empty()).then(|| n.clone());
    for (h, names) in z.hole_edges.iter().enumerate() {
        if !names.is_empty() && names.len() != z.holes[h].len() {
            return Err((
                at.join("hole_edges").at(h),
                format!(
                    "names {} edges but hole {h} has {}",
                    names.len(),
                    z.holes[h].len()
                ),
            ));
        }
    }
    let hole_names = z
        .hole_edges
        .iter()
        .map(|names| names.iter().map(named).collect::<Vec<_>>());
    let mut names = if z.edges.is_empty() {
        if z.hole_edges.is_empty() {
            Vec::new()
        } else {
            vec![Vec::new()]
        }
    } else {
        if z.edges.len() != outer.len() {
            return Err((
                at.join("edges"),
                format!(
                    "names {} edges but the polygon has {} (edge k runs from vertex k to k + 1)",
                    z.edges.len(),
                    outer.len()
                ),
            ));
        }
        vec![z.edges.iter().map(named).collect()]
    };
    names.extend(hole_names);
    geometry::Polygon::with_edge_names(outer, z.holes.clone(), names)
        .map(Shape::Polygon)
        .map_err(|e| (at.join("polygon"), e.to_string()))
}

/// The shape of `[[mesh.fine]]` region `r` (at `at`): its polygon or its rectangle.
pub fn fine_region(
    r: &super::schema::FineRegion,
    at: &FieldPath,
) -> Result<Shape, (FieldPath, String)> {
    match &r.polygon {
        Some(p) => {
            if let Some(k) = p.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
                return Err((at.join("polygon"), format!("vertex {k} is not finite")));
            }
            geometry::Polygon::new(p.clone(), Vec::new())
                .map(Shape::Polygon)
                .map_err(|e| (at.join("polygon"), e.to_string()))
        }
        None => geometry::Rectangle::new(r.origin, r.size)
            .map(Shape::Rectangle)
            .map_err(|e| (at.join("size"), e.to_string())),
    }
}

/// Every zone's shape, checked one by one and then pairwise for overlaps.
pub fn shapes(scene: &Scene) -> Result<Vec<Shape>, (FieldPath, String)> {
    let at = FieldPath::key("body").join("zones");
    let shapes = scene
        .body
        .zones
        .iter()
        .enumerate()
        .map(|(i, z)| shape(z, &at.at(i)))
        .collect::<Result<Vec<_>, _>>()?;
    geometry::validate_zones(&shapes).map_err(|e| {
        let [a, b] = e.zones;
        let label = |i: usize| match &scene.body.zones[i].name {
            Some(n) => format!("body.zones[{i}] (\"{n}\")"),
            None => format!("body.zones[{i}]"),
        };
        (
            at.at(b),
            format!("overlaps {}: zones may touch but not overlap", label(a)),
        )
    })?;
    Ok(shapes)
}

/// `[[xmin, ymin], [xmax, ymax]]` of the zones as written (no checks).
pub fn bounding_box(zones: &[Zone]) -> [[f64; 2]; 2] {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    let mut take = |p: [f64; 2]| {
        for c in 0..2 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
    };
    for z in zones {
        z.polygon.iter().flatten().for_each(|p| take(*p));
        if let Some(c) = &z.circle {
            take([c.centre[0] - c.radius, c.centre[1] - c.radius]);
            take([c.centre[0] + c.radius, c.centre[1] + c.radius]);
        }
        if let Some(r) = &z.rectangle {
            take(r.origin);
            take([r.origin[0] + r.size[0], r.origin[1] + r.size[1]]);
        }
    }
    [lo, hi]
}

/// Where every zone's lattice is anchored: the first zone's first vertex (its centre for a
/// circle), so that a rectangle zone on the lattice fills as `body.rectangles` does.
fn anchor(zones: &[Zone]) -> [f64; 2] {
    let z = &zones[0];
    z.polygon
        .as_ref()
        .and_then(|p| p.first().copied())
        .or(z.rectangle.map(|r| r.origin))
        .or(z.circle.map(|c| c.centre))
        .unwrap_or([0.0; 2])
}

/// The particles of a zone body (`width`: scalars of a state row), sorted by y then x, ids
/// `0..n`, each with the spacing `mesh.h`. A scene that fails its checks gives none (the
/// checks report it).
pub fn fill(scene: &Scene, width: usize) -> ParticleSet {
    let mut set = ParticleSet::with_capacity(0, width);
    let Ok(shapes) = shapes(scene) else {
        return set;
    };
    let params = FillParams::new(scene.mesh.h, anchor(&scene.body.zones));
    let at = FieldPath::key("mesh").join("fine");
    let fine: Vec<geometry::FineRegion> = (scene.mesh.fine.iter().enumerate())
        .filter_map(|(i, r)| {
            let shape = fine_region(r, &at.at(i)).ok()?;
            Some(geometry::FineRegion { shape, h: r.h })
        })
        .collect();
    let Ok(points) = geometry::fill_zones_graded(&shapes, &fine, &params) else {
        return set;
    };
    // A particle on the boundary of two zones belongs to the lower-indexed one (the fill's
    // rule), and so does its material.
    let material: Vec<u32> = (scene.body.zones.iter())
        .map(|z| {
            let m = z
                .material
                .as_deref()
                .and_then(|n| scene.material.index_of(n));
            m.unwrap_or(0) as u32
        })
        .collect();
    for (gid, p) in points.iter().enumerate() {
        set.push_new(gid as u64, p.position, p.h);
        set.material[gid] = material[p.zone];
    }
    set
}

/// The names of the `[[material]]` tables that no zone names (with several materials).
pub fn unused_materials(scene: &Scene) -> Vec<String> {
    let all = scene.material.all();
    if all.len() < 2 {
        return Vec::new();
    }
    all.iter()
        .filter_map(|m| m.name.clone())
        .filter(|n| {
            !scene
                .body
                .zones
                .iter()
                .any(|z| z.material.as_deref() == Some(n))
        })
        .collect()
}

/// Length of the vertical segment from (x, y0) up to (x, y1) inside `shape`, as the limit from
/// the left (`from_left`) or the right of x: on a vertical edge of a polygon the two differ, and
/// the line itself crosses nothing.
pub fn vertical_length_inside(shape: &Shape, x: f64, y0: f64, y1: f64, from_left: bool) -> f64 {
    let clip = |lo: f64, hi: f64| (hi.min(y1) - lo.max(y0)).max(0.0);
    match shape {
        Shape::Circle(c) => {
            let (cx, r) = (c.centre(), c.radius());
            let half = (r * r - (x - cx[0]).powi(2)).max(0.0).sqrt();
            clip(cx[1] - half, cx[1] + half)
        }
        Shape::Rectangle(r) => {
            let (o, s) = (r.origin(), r.size());
            let inside = if from_left {
                x > o[0] && x <= o[0] + s[0]
            } else {
                x >= o[0] && x < o[0] + s[0]
            };
            if !inside {
                0.0
            } else {
                clip(o[1], o[1] + s[1])
            }
        }
        Shape::Polygon(p) => {
            // Where the line crosses the rings; an edge counts when it straddles x, one end
            // on each side by a half-open rule, so a vertex on the line counts once. Which
            // end is closed picks the limit from the left or the right.
            let left_of = |v: f64| if from_left { v < x } else { v <= x };
            let mut ys: Vec<f64> = Vec::new();
            for ring in std::iter::once(p.outer()).chain(p.holes().iter().map(|h| h.as_slice())) {
                for k in 0..ring.len() {
                    let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                    if left_of(a[0]) != left_of(b[0]) {
                        ys.push(a[1] + (x - a[0]) * (b[1] - a[1]) / (b[0] - a[0]));
                    }
                }
            }
            ys.sort_by(f64::total_cmp);
            ys.chunks_exact(2).map(|c| clip(c[0], c[1])).sum()
        }
    }
}

/// The geostatic vertical and horizontal stress (compression negative) at `x` of a zone body:
/// the surcharge plus the weight of every zone between `x` and the level `surface` (each with
/// its material's density), and the horizontal stress from the K0 of the zone holding `x` (the
/// first, on a boundary zones share, as for its particle's material).
pub fn geostatic(
    scene: &Scene,
    shapes: &[Shape],
    x: [f64; 2],
    g: &super::rigid::Geostatic,
) -> [f64; 2] {
    let gravity = scene.gravity.g[0].hypot(scene.gravity.g[1]);
    // On a vertical boundary (the body's side, the face of a cut) the column is the one on the
    // side where the body is: the larger of the two one-sided weights.
    let mut weight: f64 = 0.0;
    for from_left in [true, false] {
        let mut side = 0.0;
        for (shape, zone) in shapes.iter().zip(&scene.body.zones) {
            let m = zone
                .material
                .as_deref()
                .and_then(|n| scene.material.index_of(n));
            let density = scene.material.all()[m.unwrap_or(0)].density;
            let length = vertical_length_inside(shape, x[0], x[1], g.surface, from_left);
            side += density * gravity * length;
        }
        weight = weight.max(side);
    }
    let holder = shapes.iter().position(|s| s.contains(x));
    let k0 = holder.and_then(|z| scene.body.zones[z].k0).unwrap_or(g.k0);
    let sv = -(g.surcharge + weight);
    [k0 * sv, sv]
}

/// Total area of the zones (they do not overlap).
pub fn area(scene: &Scene) -> f64 {
    shapes(scene)
        .map(|s| s.iter().map(Shape::area).sum())
        .unwrap_or(0.0)
}

/// Whether `p` lies more than `d` inside a zone (for the jitter).
pub fn deep_inside(shapes: &[Shape], p: [f64; 2], d: f64) -> bool {
    shapes.iter().any(|s| s.signed_distance(p) < -d)
}

/// Checks every `within` polygon of `[[fixed]]`, `[[prescribed]]` and `[[surface_pressure]]`
/// and puts it into the entry's `where`, so that every test of the selection applies it.
pub fn apply_within(scene: &mut Scene) -> Result<(), (FieldPath, String)> {
    let check = |v: &[[f64; 2]], at: FieldPath| {
        if let Some(k) = v.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err((at, format!("vertex {k} is not finite")));
        }
        geometry::Polygon::new(v.to_vec(), Vec::new())
            .map(|_| ())
            .map_err(|e| (at, e.to_string()))
    };
    for (i, f) in scene.fixed.iter_mut().enumerate() {
        if let Some(v) = &f.within {
            check(v, FieldPath::key("fixed").at(i).join("within"))?;
            f.region = f.region.clone().within(v);
        }
    }
    for (i, p) in scene.prescribed.iter_mut().enumerate() {
        if let Some(v) = &p.within {
            let at = FieldPath::key("prescribed").at(i).join("within");
            check(v, at.clone())?;
            if p.select == super::schema::Selection::Current {
                return Err((
                    at,
                    "selects by the body's initial shape, so it needs select = \"initial\""
                        .to_string(),
                ));
            }
            p.region = p.region.clone().within(v);
        }
    }
    for (i, sp) in scene.surface_pressure.iter_mut().enumerate() {
        if let Some(v) = &sp.within {
            check(v, FieldPath::key("surface_pressure").at(i).join("within"))?;
            sp.region = sp.region.clone().within(v);
        }
    }
    Ok(())
}
