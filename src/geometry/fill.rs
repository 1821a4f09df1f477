//! The initial particle cloud of a set of zones: boundary particles on every edge at spacing
//! about `h`, and a global square lattice clipped to each zone's interior, without the lattice
//! points too close to a boundary.
//!
//! Why this shape of cloud: the alpha shape keeps a triangle when its circumradius is at most
//! `alpha * h`. With particles on every edge at spacing at most `h` and no interior particle
//! within [`DROP_FACTOR`]` * h` of an edge, the triangles along an edge are well shaped, so the
//! alpha shape's boundary follows the drawn edges instead of cutting notches into them.

use super::error::FillError;
use super::index::Location;
use super::overlap::validate_zones;
use super::polygon::{cut_edges, Polygon};
use super::segment::{self, Point};
use super::shape::Shape;
use std::collections::BTreeMap;

/// Lattice points closer than `DROP_FACTOR * h` to a zone's boundary are dropped.
///
/// Half a spacing because: (a) it is above the refinement's merge distance (0.4 h), so the
/// first remeshing does not delete the particles next to the boundary; (b) the widest gap it
/// can leave between the boundary row and the first interior particle is 1.5 h, whose
/// triangles have circumradius below 0.9 h (under the default alpha 1.3) and edges below
/// 1.6 h (the refinement's split length), so no notch and no immediate split; (c) below about
/// 0.1 h an interior point next to the middle of a boundary segment makes a sliver whose
/// circumradius exceeds 1.3 h, which the alpha shape would drop, leaving a notch.
pub const DROP_FACTOR: f64 = 0.5;

/// Largest number of lattice candidates a fill will visit unless told otherwise.
pub const DEFAULT_MAX_POINTS: usize = 50_000_000;

/// Where and how densely to fill.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FillParams {
    /// Particle spacing.
    pub h: f64,
    /// A point of the global lattice: the lattice is `anchor + h * (i, j)` for all zones, so
    /// zones that touch share their lattice.
    pub anchor: Point,
    /// Refuse fills that would visit more lattice candidates than this.
    pub max_points: usize,
}

impl FillParams {
    pub fn new(h: f64, anchor: Point) -> FillParams {
        FillParams {
            h,
            anchor,
            max_points: DEFAULT_MAX_POINTS,
        }
    }
}

/// One particle of a fill.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilledPoint {
    pub position: Point,
    /// Index of its zone. A particle on a boundary shared by several zones belongs to the one
    /// with the lowest index.
    pub zone: usize,
    /// Whether it was placed on a zone boundary (rather than taken from the lattice).
    pub on_boundary: bool,
}

/// Fills `zones` (which must not overlap; they may touch) at spacing `params.h`.
///
/// Each point is emitted once, sorted by y, then x (then zone), so its position in the result
/// (its global id) depends only on the geometry and the parameters.
///
/// Boundary particles: every polygon edge, after cutting it at the vertices of other zones
/// lying exactly on it, is divided into `ceil(len / h)` equal parts, its end vertices included;
/// a circle into `ceil(2 pi r / h)` equal arcs. A shared edge is divided once, from its
/// lexicographically smaller end, so both zones see bit-identical points. Boundary points
/// within [`SNAP`]` * h` of a lattice node are put exactly on it.
pub fn fill_zones(zones: &[Shape], params: &FillParams) -> Result<Vec<FilledPoint>, FillError> {
    let h = params.h;
    if !(h.is_finite() && h > 0.0) {
        return Err(FillError::BadSpacing { h });
    }
    if !(params.anchor[0].is_finite() && params.anchor[1].is_finite()) {
        return Err(FillError::BadAnchor {
            anchor: params.anchor,
        });
    }
    let count: f64 = zones.iter().map(|z| lattice_range(z, params).count()).sum();
    if count > params.max_points as f64 {
        return Err(FillError::TooManyPoints {
            count,
            limit: params.max_points,
        });
    }
    validate_zones(zones)?;

    let mut points = boundary_points(zones, params);
    for (z, shape) in zones.iter().enumerate() {
        let r = lattice_range(shape, params);
        for j in r.j0..=r.j1 {
            for i in r.i0..=r.i1 {
                let p = [
                    params.anchor[0] + i as f64 * h,
                    params.anchor[1] + j as f64 * h,
                ];
                if shape.locate(p) == Location::Inside
                    && -shape.signed_distance(p) >= DROP_FACTOR * h
                {
                    points.push(FilledPoint {
                        position: p,
                        zone: z,
                        on_boundary: false,
                    });
                }
            }
        }
    }
    points.sort_by(|a, b| {
        a.position[1]
            .total_cmp(&b.position[1])
            .then(a.position[0].total_cmp(&b.position[0]))
            .then(a.zone.cmp(&b.zone))
    });
    Ok(points)
}

/// [`fill_zones`] for one shape, positions only.
pub fn fill_shape(shape: &Shape, params: &FillParams) -> Result<Vec<Point>, FillError> {
    Ok(fill_zones(std::slice::from_ref(shape), params)?
        .into_iter()
        .map(|p| p.position)
        .collect())
}

/// Inclusive lattice index ranges covering a shape's bounding box (empty if `i0 > i1`).
struct LatticeRange {
    i0: i64,
    i1: i64,
    j0: i64,
    j1: i64,
}

impl LatticeRange {
    fn count(&self) -> f64 {
        ((self.i1 - self.i0 + 1).max(0) as f64) * ((self.j1 - self.j0 + 1).max(0) as f64)
    }
}

fn lattice_range(shape: &Shape, params: &FillParams) -> LatticeRange {
    let [lo, hi] = shape.bbox();
    let (a, h) = (params.anchor, params.h);
    // Saturating float-to-int casts keep absurd inputs finite; the count check refuses them.
    let idx = |x: f64| x.clamp(-4e18, 4e18) as i64;
    LatticeRange {
        i0: idx(((lo[0] - a[0]) / h).ceil()),
        i1: idx(((hi[0] - a[0]) / h).floor()),
        j0: idx(((lo[1] - a[1]) / h).ceil()),
        j1: idx(((hi[1] - a[1]) / h).floor()),
    }
}

type Key = ([u64; 2], [u64; 2]);

fn key(p: Point) -> [u64; 2] {
    p.map(f64::to_bits)
}

/// Lexicographic order on points (x, then y).
fn lex_less(a: Point, b: Point) -> bool {
    a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])).is_lt()
}

/// Boundary points within this many spacings of a lattice node are moved onto it.
pub const SNAP: f64 = 1e-9;

/// `p`, or the lattice node it lies within [`SNAP`]` * h` of in both coordinates. Edges on
/// lattice lines then give exactly the lattice's own coordinates, so a rectangle anchored on
/// the lattice is filled bit for bit as the plain lattice was.
fn snap(p: Point, params: &FillParams) -> Point {
    let (a, h) = (params.anchor, params.h);
    let node = |x: f64, o: f64| {
        let i = ((x - o) / h).round();
        let q = o + i * h;
        ((q - x).abs() <= SNAP * h).then_some(q)
    };
    match (node(p[0], a[0]), node(p[1], a[1])) {
        (Some(x), Some(y)) => [x, y],
        _ => p,
    }
}

fn boundary_points(zones: &[Shape], params: &FillParams) -> Vec<FilledPoint> {
    let h = params.h;
    let polygons: Vec<(usize, &Polygon)> = zones
        .iter()
        .enumerate()
        .filter_map(|(z, s)| s.as_polygon().map(|p| (z, p)))
        .collect();
    // Each distinct piece, from its smaller end, with the lowest zone that has it.
    let mut pieces: BTreeMap<Key, (Point, Point, usize)> = BTreeMap::new();
    for &(z, p) in &polygons {
        let others: Vec<&Polygon> = polygons
            .iter()
            .filter(|&&(y, q)| y != z && boxes_touch(p.bbox(), q.bbox()))
            .map(|&(_, q)| q)
            .collect();
        for [a, b] in cut_edges(p, &others) {
            let (a, b) = if lex_less(b, a) { (b, a) } else { (a, b) };
            let e = pieces.entry((key(a), key(b))).or_insert((a, b, z));
            e.2 = e.2.min(z);
        }
    }
    let mut owner: BTreeMap<[u64; 2], (Point, usize)> = BTreeMap::new();
    let mut put = |p: Point, z: usize| {
        let p = snap(p, params);
        let e = owner.entry(key(p)).or_insert((p, z));
        e.1 = e.1.min(z);
    };
    for &(a, b, z) in pieces.values() {
        let n = divisions(segment::length(a, b), h);
        put(a, z);
        put(b, z);
        for k in 1..n {
            let t = k as f64 / n as f64;
            put([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])], z);
        }
    }
    for (z, s) in zones.iter().enumerate() {
        if let Shape::Circle(c) = s {
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
        })
        .collect()
}

/// Equal parts of length at most `h`; the small allowance keeps an edge of exactly `k h`
/// from getting `k + 1` parts through rounding.
fn divisions(len: f64, h: f64) -> usize {
    ((len / h - 1e-9).ceil() as usize).max(1)
}

fn boxes_touch(a: [Point; 2], b: [Point; 2]) -> bool {
    a[0][0] <= b[1][0] && b[0][0] <= a[1][0] && a[0][1] <= b[1][1] && b[0][1] <= a[1][1]
}
