//! The initial particle cloud of a set of zones: boundary particles on every edge at spacing
//! about `h`, and a global square lattice clipped to each zone's interior, without the lattice
//! points too close to a boundary.
//!
//! Why this shape of cloud: the alpha shape keeps a triangle when its circumradius is at most
//! `alpha * h`. With particles on every edge at spacing at most `h` and no interior particle
//! within [`DROP_FACTOR`]` * h` of an edge, the triangles along an edge are well shaped, so the
//! alpha shape's boundary follows the drawn edges instead of cutting notches into them.

use super::error::FillError;
use super::fill_boundary::{boundary_points, region_points};
use super::locate::Location;
use super::overlap::validate_zones;
use super::segment::Point;
use super::shape::Shape;

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
    /// The local spacing: `FillParams::h`, or that of the finest fine region containing it.
    pub h: f64,
}

/// A region filled at a finer spacing than the rest (`[[mesh.fine]]`). Where regions overlap
/// the finest spacing wins. Its lattice is `anchor + h * (i, j)` too, so a spacing of
/// `FillParams::h / 2^k` nests in the coarser lattice.
#[derive(Debug, Clone)]
pub struct FineRegion {
    pub shape: Shape,
    pub h: f64,
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
    fill_zones_graded(zones, &[], params)
}

/// [`fill_zones`] with finer spacing inside `fine` regions. Each level (the base spacing and
/// every distinct fine spacing) contributes the lattice points whose local spacing is its
/// own, dropped within [`DROP_FACTOR`] of that spacing from a zone boundary or from the
/// outline of a region at that spacing or finer; region outlines inside zones carry particles
/// at the region's spacing, and zone boundary pieces are divided at the local spacing.
pub fn fill_zones_graded(
    zones: &[Shape],
    fine: &[FineRegion],
    params: &FillParams,
) -> Result<Vec<FilledPoint>, FillError> {
    let good = |h: f64| h.is_finite() && h > 0.0;
    if !good(params.h) {
        return Err(FillError::BadSpacing { h: params.h });
    }
    if let Some(r) = fine.iter().find(|r| !good(r.h) || r.h > params.h) {
        return Err(FillError::BadSpacing { h: r.h });
    }
    if !(params.anchor[0].is_finite() && params.anchor[1].is_finite()) {
        return Err(FillError::BadAnchor {
            anchor: params.anchor,
        });
    }
    let mut levels: Vec<f64> = fine.iter().map(|r| r.h).chain([params.h]).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    let count: f64 = levels
        .iter()
        .flat_map(|&h| {
            zones
                .iter()
                .map(move |z| lattice_range(z.bbox(), params.anchor, h).count())
        })
        .sum();
    if count > params.max_points as f64 {
        return Err(FillError::TooManyPoints {
            count,
            limit: params.max_points,
        });
    }
    validate_zones(zones)?;

    let spacing = |p: Point| {
        fine.iter()
            .filter(|r| r.h < params.h && r.shape.contains(p))
            .map(|r| r.h)
            .fold(params.h, f64::min)
    };
    let mut points = boundary_points(zones, params, &spacing, levels[0]);
    points.extend(region_points(zones, fine));
    for &h in &levels {
        // Outlines of regions at this spacing or finer carry particles (`region_points`).
        let outlined: Vec<&FineRegion> = fine.iter().filter(|r| r.h <= h).collect();
        for (z, shape) in zones.iter().enumerate() {
            let r = lattice_range(shape.bbox(), params.anchor, h);
            for j in r.j0..=r.j1 {
                for i in r.i0..=r.i1 {
                    let p = [
                        params.anchor[0] + i as f64 * h,
                        params.anchor[1] + j as f64 * h,
                    ];
                    let keep = shape.locate(p) == Location::Inside
                        && -shape.signed_distance(p) >= DROP_FACTOR * h
                        && spacing(p) == h
                        && outlined
                            .iter()
                            .all(|f| f.shape.signed_distance(p).abs() >= DROP_FACTOR * h);
                    if keep {
                        points.push(FilledPoint {
                            position: p,
                            zone: z,
                            on_boundary: false,
                            h,
                        });
                    }
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

fn lattice_range(bbox: [Point; 2], anchor: Point, h: f64) -> LatticeRange {
    let [lo, hi] = bbox;
    // Saturating float-to-int casts keep absurd inputs finite; the count check refuses them.
    let idx = |x: f64| x.clamp(-4e18, 4e18) as i64;
    LatticeRange {
        i0: idx(((lo[0] - anchor[0]) / h).ceil()),
        i1: idx(((hi[0] - anchor[0]) / h).floor()),
        j0: idx(((lo[1] - anchor[1]) / h).ceil()),
        j1: idx(((hi[1] - anchor[1]) / h).floor()),
    }
}
