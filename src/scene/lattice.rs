//! The initial particle lattice: one global square grid of spacing `mesh.h` anchored at the
//! first rectangle's origin, restricted to the union of the body rectangles. Using one grid for
//! all rectangles is what makes particles on shared edges coincide, so each is emitted once.

use super::schema::{Rectangle, Scene};
use crate::case_file::ParticleSet;

/// Allowed deviation, in spacings, of a rectangle corner from a lattice line.
pub const ALIGN_TOL: f64 = 1e-6;

/// Rounds `x` to the nearest integer when it is one within `ALIGN_TOL`.
pub fn whole(x: f64) -> Option<i64> {
    let r = x.round();
    ((x - r).abs() <= ALIGN_TOL && r.abs() < 9.0e15).then_some(r as i64)
}

/// Inclusive lattice index ranges `([i0, i1], [j0, j1])` covered by a rectangle, or None when
/// the rectangle is not aligned with the lattice.
pub fn index_box(anchor: [f64; 2], h: f64, r: &Rectangle) -> Option<([i64; 2], [i64; 2])> {
    let mut out = [[0i64; 2]; 2];
    for axis in 0..2 {
        let start = whole((r.origin[axis] - anchor[axis]) / h)?;
        let count = whole(r.size[axis] / h)?;
        out[axis] = [start, start + count];
    }
    Some((out[0], out[1]))
}

/// For each lattice row `j` (ascending), the merged `[i0, i1]` intervals of the rectangles
/// covering it. Rectangles must already be validated as aligned.
fn rows(anchor: [f64; 2], h: f64, rects: &[Rectangle]) -> Vec<(i64, Vec<[i64; 2]>)> {
    let boxes: Vec<_> = rects
        .iter()
        .filter_map(|r| index_box(anchor, h, r))
        .collect();
    let (Some(jmin), Some(jmax)) = (
        boxes.iter().map(|b| b.1[0]).min(),
        boxes.iter().map(|b| b.1[1]).max(),
    ) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for j in jmin..=jmax {
        let mut spans: Vec<[i64; 2]> = boxes
            .iter()
            .filter(|b| b.1[0] <= j && j <= b.1[1])
            .map(|b| b.0)
            .collect();
        spans.sort_unstable();
        let mut merged: Vec<[i64; 2]> = Vec::with_capacity(spans.len());
        for s in spans {
            match merged.last_mut() {
                // Spans sharing an index (a common edge) or overlapping merge, so that no
                // particle is emitted twice.
                Some(last) if s[0] <= last[1] => last[1] = last[1].max(s[1]),
                _ => merged.push(s),
            }
        }
        if !merged.is_empty() {
            out.push((j, merged));
        }
    }
    out
}

/// Number of particles `generate_particles` would produce, without producing them.
pub fn particle_count(scene: &Scene) -> u64 {
    let Some(first) = scene.body.rectangles.first() else {
        return 0;
    };
    rows(first.origin, scene.mesh.h, &scene.body.rectangles)
        .iter()
        .flat_map(|(_, spans)| spans.iter())
        .map(|s| (s[1] - s[0] + 1) as u64)
        .sum()
}

/// Fills the body rectangles with a square lattice of spacing `mesh.h`, rectangle edges
/// included. Global ids are `0..n` in row-major order (by y, then x); every particle gets
/// `h = mesh.h`, zero displacement, zero state and zero flags.
pub fn generate_particles(scene: &Scene) -> ParticleSet {
    let h = scene.mesh.h;
    let width = crate::model::state_layout(scene).len();
    if let Some(nodes) = &scene.body.imported_nodes {
        let mut set = ParticleSet::with_capacity(nodes.len(), width);
        for (gid, n) in nodes.iter().enumerate() {
            set.push_new(gid as u64, n.position, n.h);
            set.material[gid] = n.material;
        }
        return finish(scene, set);
    }
    if !scene.body.zones.is_empty() {
        return finish(scene, super::zones::fill(scene, width));
    }
    let Some(first) = scene.body.rectangles.first() else {
        return ParticleSet::with_capacity(0, width);
    };
    let anchor = first.origin;
    let mut set = ParticleSet::with_capacity(particle_count(scene) as usize, width);
    for (j, spans) in rows(anchor, h, &scene.body.rectangles) {
        let y = anchor[1] + j as f64 * h;
        for span in spans {
            for i in span[0]..=span[1] {
                let gid = set.len() as u64;
                let p = [anchor[0] + i as f64 * h, y];
                set.push_new(gid, p, h);
            }
        }
    }
    if !scene.mesh.fine.is_empty() {
        set = refine_regions(scene, set);
    }
    finish(scene, set)
}

/// The jitter and the rigid bodies' carving, common to every body.
fn finish(scene: &Scene, mut set: ParticleSet) -> ParticleSet {
    let shapes = if scene.body.zones.is_empty() || scene.body.jitter == 0.0 {
        Vec::new()
    } else {
        super::zones::shapes(scene).unwrap_or_default()
    };
    for i in 0..set.len() {
        let (p, h) = (set.position[i], set.h[i]);
        let deep = if scene.body.zones.is_empty() {
            in_rectangles(scene, p, h)
        } else {
            super::zones::deep_inside(&shapes, p, 0.5 * h)
        };
        if deep {
            set.position[i] = jittered(scene, set.gid[i], p, h);
        }
    }
    if !scene.rigid.is_empty() {
        set = carve_rigid(scene, set);
    }
    set
}

/// Removes the particles inside the rigid bodies, and lines the part of a body's surface that
/// lies inside the soil (a body wished in place) with particles at the spacing of the cloud
/// around it, dropping lattice particles closer than half that spacing to them. A body resting
/// on the surface only touches the body's outline and changes nothing there.
fn carve_rigid(scene: &Scene, base: ParticleSet) -> ParticleSet {
    let tol = scene.tolerance();
    let shapes: Vec<_> = (0..scene.rigid.len())
        .filter_map(|i| super::validate_rigid::shape_of(scene, i).ok())
        .collect();
    let zones = super::zones::shapes(scene).unwrap_or_default();
    let strictly_inside = |p: [f64; 2], margin: f64| {
        scene.body.rectangles.iter().any(|r| {
            (0..2).all(|c| p[c] > r.origin[c] + margin && p[c] < r.origin[c] + r.size[c] - margin)
        }) || super::zones::deep_inside(&zones, p, margin)
    };
    let mut ring: Vec<([f64; 2], f64)> = Vec::new();
    for shape in &shapes {
        let near = 2.0 * scene.mesh.h;
        let spacing = base
            .position
            .iter()
            .zip(&base.h)
            .filter(|(p, _)| shape.closest(**p).distance < near)
            .map(|(_, h)| *h)
            .fold(scene.mesh.h, f64::min);
        // An even count on a circle puts points at its top and bottom, where a symmetry plane
        // through the centre cuts it.
        let sample = if shape.core().len() == 1 {
            let half = (std::f64::consts::PI * shape.radius() / spacing).ceil();
            std::f64::consts::PI * shape.radius() / half * (1.0 + 1e-12)
        } else {
            spacing
        };
        let points = shape.surface_points(sample);
        // A body wished in place is lined where it lies in the soil, up to and including the
        // body's outline (a symmetry plane); one resting on the surface is left alone.
        if points.iter().any(|p| strictly_inside(*p, 0.25 * spacing)) {
            ring.extend(
                points
                    .into_iter()
                    .filter(|p| strictly_inside(*p, -tol))
                    .map(|p| (p, spacing)),
            );
        }
    }
    // A lining particle takes the material of the nearest particle it replaces or joins.
    let nearest_material = |q: [f64; 2]| {
        (base.position.iter().zip(&base.material))
            .map(|(p, m)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2), *m))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or(0, |(_, m)| m)
    };
    let mut points: Vec<([f64; 2], f64, u32)> = Vec::with_capacity(base.len() + ring.len());
    for ((p, h), m) in base.position.iter().zip(&base.h).zip(&base.material) {
        let inside = shapes.iter().any(|s| s.closest(*p).distance < -tol);
        let crowded = ring
            .iter()
            .any(|(q, hq)| (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) < 0.25 * hq * hq);
        if !inside && !crowded {
            points.push((*p, *h, *m));
        }
    }
    points.extend(ring.into_iter().map(|(q, h)| (q, h, nearest_material(q))));
    points.sort_by(|a, b| a.0[1].total_cmp(&b.0[1]).then(a.0[0].total_cmp(&b.0[0])));
    let mut set = ParticleSet::with_capacity(points.len(), base.state.width());
    for (gid, (p, h, m)) in points.into_iter().enumerate() {
        set.push_new(gid as u64, p, h);
        set.material[gid] = m;
    }
    set
}

/// Replaces the lattice inside each `[[mesh.fine]]` region by that region's finer lattice:
/// finest regions first, a point already placed (a shared edge) is not placed again, and a
/// coarser point strictly inside a finer region is dropped. Ids are renumbered row-major.
fn refine_regions(scene: &Scene, base: ParticleSet) -> ParticleSet {
    let mut regions = scene.mesh.fine.clone();
    regions.sort_by(|a, b| a.h.total_cmp(&b.h));
    let h_min = regions[0].h;
    let key = |p: [f64; 2]| {
        (
            (p[0] / h_min * 1e3).round() as i64,
            (p[1] / h_min * 1e3).round() as i64,
        )
    };
    let tol = 1e-9 * h_min;
    let inside_open = |p: [f64; 2], r: &super::schema::FineRegion| {
        (0..2).all(|c| p[c] > r.origin[c] + tol && p[c] < r.origin[c] + r.size[c] - tol)
    };
    let in_body = |p: [f64; 2]| {
        scene.body.rectangles.iter().any(|r| {
            (0..2).all(|c| p[c] >= r.origin[c] - tol && p[c] <= r.origin[c] + r.size[c] + tol)
        })
    };
    let mut placed = std::collections::HashSet::new();
    let mut points: Vec<([f64; 2], f64)> = Vec::new();
    for (k, r) in regions.iter().enumerate() {
        let n = [
            (r.size[0] / r.h).round() as i64,
            (r.size[1] / r.h).round() as i64,
        ];
        for j in 0..=n[1] {
            for i in 0..=n[0] {
                let p = [r.origin[0] + i as f64 * r.h, r.origin[1] + j as f64 * r.h];
                let finer = regions[..k].iter().any(|f| inside_open(p, f));
                if in_body(p) && !finer && placed.insert(key(p)) {
                    points.push((p, r.h));
                }
            }
        }
    }
    for (p, h) in base.position.iter().zip(&base.h) {
        if !regions.iter().any(|r| inside_open(*p, r)) && placed.insert(key(*p)) {
            points.push((*p, *h));
        }
    }
    points.sort_by(|a, b| a.0[1].total_cmp(&b.0[1]).then(a.0[0].total_cmp(&b.0[0])));
    let mut set = ParticleSet::with_capacity(points.len(), base.state.width());
    for (gid, (p, h)) in points.into_iter().enumerate() {
        set.push_new(gid as u64, p, h);
    }
    set
}

/// Whether `p` (spacing `h`) lies more than h/2 inside a body rectangle.
fn in_rectangles(scene: &Scene, p: [f64; 2], h: f64) -> bool {
    scene.body.rectangles.iter().any(|r| {
        (0..2).all(|c| p[c] > r.origin[c] + 0.5 * h && p[c] < r.origin[c] + r.size[c] - 0.5 * h)
    })
}

/// `p` (spacing `h`) moved by the scene's `body.jitter`, deterministically per particle id.
fn jittered(scene: &Scene, gid: u64, p: [f64; 2], h: f64) -> [f64; 2] {
    let j = scene.body.jitter;
    if j == 0.0 {
        return p;
    }
    let a = crate::rng::splitmix64(gid.wrapping_mul(2));
    let b = crate::rng::splitmix64(gid.wrapping_mul(2) + 1);
    let unit = |x: u64| (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
    [p[0] + 2.0 * j * h * unit(a), p[1] + 2.0 * j * h * unit(b)]
}

/// Global id of the particle nearest to `p` (ties go to the smaller id), with its distance.
pub fn nearest(set: &ParticleSet, p: [f64; 2]) -> Option<(u64, f64)> {
    nearest_of(set, p, |_| true)
}

/// As [`nearest`], among the particles whose position passes `keep`.
pub fn nearest_of(
    set: &ParticleSet,
    p: [f64; 2],
    keep: impl Fn([f64; 2]) -> bool,
) -> Option<(u64, f64)> {
    let mut best: Option<(u64, f64)> = None;
    for (gid, q) in set.gid.iter().zip(&set.position) {
        if !keep(*q) {
            continue;
        }
        let d2 = (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
        let better = match best {
            None => true,
            Some((bg, bd2)) => d2 < bd2 || (d2 == bd2 && *gid < bg),
        };
        if better {
            best = Some((*gid, d2));
        }
    }
    best.map(|(g, d2)| (g, d2.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;
    use std::collections::HashSet;

    fn scene_with(rects: &str, h: f64) -> Scene {
        let text = format!(
            r#"
name = "t"
[body]
rectangles = {rects}
[mesh]
h = {h}
[material]
model = "linear-elastic"
young = 1.0e6
poisson = 0.3
[[point_load]]
at = [0.0, 0.0]
force = [0.0, -1.0]
[[fixed]]
where = "x >= 1"
dofs = ["x", "y"]
[steps]
count = 1
[history]
kind = "cantilever"
"#
        );
        Scene::from_toml(&text, "test", &[]).unwrap()
    }

    #[test]
    fn cantilever_lattice_is_81_by_9() {
        let s = scene_with("[ { origin = [0.0, 0.0], size = [10.0, 1.0] } ]", 0.125);
        let p = generate_particles(&s);
        assert_eq!(p.len(), 81 * 9);
        assert_eq!(particle_count(&s), 81 * 9);
        assert_eq!(p.gid, (0..729).collect::<Vec<u64>>());
        // Row-major by y then x.
        assert_eq!(p.position[0], [0.0, 0.0]);
        assert_eq!(p.position[80], [10.0, 0.0]);
        assert_eq!(p.position[81], [0.0, 0.125]);
        assert_eq!(p.position[728], [10.0, 1.0]);
        assert!(p.h.iter().all(|&h| h == 0.125));
        assert!(p.state.iter().all(|s| s.iter().all(|&v| v == 0.0)));
    }

    #[test]
    fn shared_edges_are_not_duplicated() {
        // An L shape: a 2x1 base and a 1x1 block on top sharing the edge y = 1, plus a block on
        // the right sharing the edge x = 2 and overlapping the base's corner.
        let s = scene_with(
            "[ { origin = [0.0, 0.0], size = [2.0, 1.0] }, \
               { origin = [0.0, 1.0], size = [1.0, 1.0] }, \
               { origin = [2.0, 0.0], size = [1.0, 0.5] } ]",
            0.25,
        );
        let p = generate_particles(&s);
        let keys: HashSet<(i64, i64)> = p
            .position
            .iter()
            .map(|q| ((q[0] / 0.25).round() as i64, (q[1] / 0.25).round() as i64))
            .collect();
        assert_eq!(keys.len(), p.len(), "duplicate particles");
        // base 9x5 + top 5x4 extra rows + right block 4x3 extra columns
        assert_eq!(p.len(), 9 * 5 + 5 * 4 + 4 * 3);
        for w in p.position.windows(2) {
            assert!(w[0][1] < w[1][1] || (w[0][1] == w[1][1] && w[0][0] < w[1][0]));
        }
    }

    #[test]
    fn nearest_breaks_ties_by_smaller_gid() {
        let s = scene_with("[ { origin = [0.0, 0.0], size = [1.0, 1.0] } ]", 0.5);
        let p = generate_particles(&s);
        // (0.25, 0.25) is equidistant from gids 0, 1, 3, 4.
        assert_eq!(nearest(&p, [0.25, 0.25]).unwrap().0, 0);
        assert_eq!(nearest(&p, [0.75, 0.75]).unwrap().0, 4);
    }
}
