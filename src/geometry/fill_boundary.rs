//! Boundary particles of a fill: every distinct boundary piece divided once, so that zones
//! sharing a boundary see bit-identical particles, each owned by the lowest zone.

use super::fill::{FillParams, FilledPoint, FineRegion, DROP_FACTOR};
use super::locate::Location;
use super::polygon::{cut_edges, Polygon};
use super::segment::{self, Point};
use super::shape::Shape;
use std::collections::BTreeMap;

/// Boundary points within this many spacings of a lattice node are moved onto it.
pub const SNAP: f64 = 1e-9;

/// Samples per smallest spacing when integrating a variable spacing along an edge.
const SAMPLES_PER_SPACING: f64 = 4.0;

/// At most this many samples per edge piece, whatever the spacings.
const MAX_SAMPLES: f64 = 1e6;

fn key(p: Point) -> [u64; 2] {
    p.map(f64::to_bits)
}

/// Lexicographic order on points (x, then y).
fn lex_less(a: Point, b: Point) -> bool {
    a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])).is_lt()
}

/// `p`, or the lattice node it lies within [`SNAP`]` * h` of in both coordinates. Edges on
/// lattice lines then give exactly the lattice's own coordinates, so a rectangle anchored on
/// the lattice is filled bit for bit as the plain lattice was.
fn snap(p: Point, anchor: Point, h: f64) -> Point {
    let node = |x: f64, o: f64| {
        let q = o + ((x - o) / h).round() * h;
        ((q - x).abs() <= SNAP * h).then_some(q)
    };
    match (node(p[0], anchor[0]), node(p[1], anchor[1])) {
        (Some(x), Some(y)) => [x, y],
        _ => p,
    }
}

/// Equal parts of length at most `h`; the small allowance keeps an edge of exactly `k h`
/// from getting `k + 1` parts through rounding.
fn divisions(len: f64, h: f64) -> usize {
    ((len / h - 1e-9).ceil() as usize).max(1)
}

/// Interior division parameters `t` in (0, 1) of the piece `a b` at the local spacing
/// `spacing`: equal parts where the spacing is constant along the piece, otherwise points at
/// equal steps of the integral of `1 / spacing`, so parts follow the local spacing.
fn division_parameters(a: Point, b: Point, spacing: &dyn Fn(Point) -> f64, h_min: f64) -> Vec<f64> {
    let len = segment::length(a, b);
    let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
    let m = (len / h_min * SAMPLES_PER_SPACING)
        .ceil()
        .clamp(1.0, MAX_SAMPLES) as usize;
    let local: Vec<f64> = (0..m)
        .map(|i| spacing(at((i as f64 + 0.5) / m as f64)))
        .collect();
    if local.iter().all(|&h| h == local[0]) {
        let n = divisions(len, local[0]);
        return (1..n).map(|k| k as f64 / n as f64).collect();
    }
    let mut cumulative = Vec::with_capacity(m + 1);
    cumulative.push(0.0);
    for h in &local {
        let last = cumulative[cumulative.len() - 1];
        cumulative.push(last + len / m as f64 / h);
    }
    let total = cumulative[m];
    let n = ((total - 1e-9).ceil() as usize).max(1);
    let mut out = Vec::with_capacity(n.saturating_sub(1));
    let mut i = 0;
    for k in 1..n {
        let target = total * k as f64 / n as f64;
        while cumulative[i + 1] < target {
            i += 1;
        }
        let frac = (target - cumulative[i]) / (cumulative[i + 1] - cumulative[i]);
        out.push((i as f64 + frac) / m as f64);
    }
    out
}

/// The boundary particles of `zones`, each once with the lowest zone that has it, and its
/// local spacing. `spacing` gives the spacing at a point, `h_min` its smallest value.
pub(super) fn boundary_points(
    zones: &[Shape],
    params: &FillParams,
    spacing: &dyn Fn(Point) -> f64,
    h_min: f64,
) -> Vec<FilledPoint> {
    let polygons: Vec<(usize, &Polygon)> = zones
        .iter()
        .enumerate()
        .filter_map(|(z, s)| s.as_polygon().map(|p| (z, p)))
        .collect();
    // Each distinct piece, from its smaller end, with the lowest zone that has it.
    let mut pieces: BTreeMap<[[u64; 2]; 2], (Point, Point, usize)> = BTreeMap::new();
    for &(z, p) in &polygons {
        let others: Vec<&Polygon> = polygons
            .iter()
            .filter(|&&(y, q)| y != z && boxes_touch(p.bbox(), q.bbox()))
            .map(|&(_, q)| q)
            .collect();
        for [a, b] in cut_edges(p, &others) {
            let (a, b) = if lex_less(b, a) { (b, a) } else { (a, b) };
            let e = pieces.entry([key(a), key(b)]).or_insert((a, b, z));
            e.2 = e.2.min(z);
        }
    }
    let mut owner: BTreeMap<[u64; 2], (Point, usize)> = BTreeMap::new();
    let mut put = |p: Point, z: usize| {
        let p = snap(p, params.anchor, params.h);
        let e = owner.entry(key(p)).or_insert((p, z));
        e.1 = e.1.min(z);
    };
    for &(a, b, z) in pieces.values() {
        put(a, z);
        put(b, z);
        for t in division_parameters(a, b, spacing, h_min) {
            put([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])], z);
        }
    }
    for (z, s) in zones.iter().enumerate() {
        if let Shape::Circle(c) = s {
            // A circle in a fine region is divided at its finest local spacing.
            let n0 = c.arcs(params.h);
            let h = (0..n0)
                .map(|k| spacing(c.point(k, n0)))
                .fold(params.h, f64::min);
            let n = c.arcs(h);
            for k in 0..n {
                put(c.point(k, n), z);
            }
        }
    }
    owner
        .into_values()
        .map(|(position, zone)| FilledPoint {
            position,
            zone,
            on_boundary: true,
            h: spacing(position),
        })
        .collect()
}

/// Particles on the outline of each fine region, where it runs inside a zone, at the region's
/// spacing: without them the fine lattice ends in a staircase along a slanted outline whose
/// slivers the alpha shape drops, leaving holes inside the body. Points crowding a zone
/// boundary or lying in a finer region are left out.
pub(super) fn region_points(zones: &[Shape], fine: &[FineRegion]) -> Vec<FilledPoint> {
    let mut out: BTreeMap<[u64; 2], FilledPoint> = BTreeMap::new();
    for r in fine {
        for s in r.shape.boundary(r.h) {
            let n = divisions(segment::length(s.a, s.b), r.h);
            for k in 0..n {
                let t = k as f64 / n as f64;
                let p = [
                    s.a[0] + t * (s.b[0] - s.a[0]),
                    s.a[1] + t * (s.b[1] - s.a[1]),
                ];
                let finer_clear = fine
                    .iter()
                    .filter(|f| f.h < r.h)
                    .all(|f| f.shape.signed_distance(p) >= DROP_FACTOR * r.h);
                let zone = zones.iter().position(|z| {
                    z.locate(p) == Location::Inside && -z.signed_distance(p) >= DROP_FACTOR * r.h
                });
                if let (true, Some(zone)) = (finer_clear, zone) {
                    out.entry(key(p)).or_insert(FilledPoint {
                        position: p,
                        zone,
                        on_boundary: false,
                        h: r.h,
                    });
                }
            }
        }
    }
    out.into_values().collect()
}

fn boxes_touch(a: [Point; 2], b: [Point; 2]) -> bool {
    a[0][0] <= b[1][0] && b[0][0] <= a[1][0] && a[0][1] <= b[1][1] && b[0][1] <= a[1][1]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_spacing_divides_equally_and_exact_multiples_are_not_split_further() {
        let t = division_parameters([0.0, 0.0], [3.0, 0.0], &|_| 1.0, 1.0);
        assert_eq!(t, vec![1.0 / 3.0, 2.0 / 3.0]);
        let t = division_parameters([0.0, 0.0], [0.3, 0.0], &|_| 0.1, 0.1);
        assert_eq!(t.len(), 2);
        assert!(division_parameters([0.0, 0.0], [0.5, 0.0], &|_| 1.0, 1.0).is_empty());
    }

    #[test]
    fn variable_spacing_follows_the_local_spacing() {
        // Spacing 0.25 on x < 2, 1 beyond: 8 parts then 2 on a 4-long edge.
        let h = |p: Point| if p[0] < 2.0 { 0.25 } else { 1.0 };
        let t = division_parameters([0.0, 0.0], [4.0, 0.0], &h, 0.25);
        let x: Vec<f64> = t.iter().map(|t| t * 4.0).collect();
        assert_eq!(x.len(), 9);
        for w in x.windows(2) {
            let want = h([w[0], 0.0]);
            assert!((w[1] - w[0] - want).abs() < 1e-9, "{x:?}");
        }
    }

    #[test]
    fn snapping_only_onto_lattice_nodes() {
        let a = [0.1, 0.7];
        assert_eq!(
            snap([0.30000000000000004, 0.7], a, 0.1),
            [0.1 + 2.0 * 0.1, 0.7]
        );
        assert_eq!(snap([0.3 + 1e-6, 0.7], a, 0.1), [0.3 + 1e-6, 0.7]);
        assert_eq!(snap([0.3, 0.75], a, 0.1), [0.3, 0.75]);
    }
}
