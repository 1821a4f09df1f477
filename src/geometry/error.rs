//! Why a shape, a set of zones or a fill was refused. Each variant says where: which ring,
//! which vertex or edges (0-based, in the order the caller gave them, before any reorientation),
//! which zones.

use std::fmt;

/// A ring of a polygon: its outer boundary or one of its holes (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum RingRef {
    Outer,
    Hole(usize),
}

impl fmt::Display for RingRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RingRef::Outer => write!(f, "outer boundary"),
            RingRef::Hole(k) => write!(f, "hole {k}"),
        }
    }
}

/// A shape that cannot be used as a zone.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeError {
    /// Fewer than three distinct vertices (a repeated closing vertex is not counted).
    TooFewVertices { ring: RingRef, count: usize },
    /// A coordinate is NaN or infinite.
    NonFinite { ring: RingRef, vertex: usize },
    /// Vertex `vertex` equals the next one: a zero-length edge.
    RepeatedVertex { ring: RingRef, vertex: usize },
    /// All vertices of the ring are collinear.
    ZeroArea { ring: RingRef },
    /// Edges `edges[0]` and `edges[1]` of one ring meet (edge `k` runs from vertex `k` to
    /// vertex `k + 1`), or two adjacent edges fold back onto each other.
    SelfIntersection { ring: RingRef, edges: [usize; 2] },
    /// A hole's edge meets (crosses or touches) an edge of the outer boundary.
    HoleCrossesOuter {
        hole: usize,
        hole_edge: usize,
        outer_edge: usize,
    },
    /// A hole lies outside the outer boundary.
    HoleOutside { hole: usize },
    /// Two holes meet or one lies inside the other.
    HolesOverlap { holes: [usize; 2] },
    /// The edge-name list of a ring does not have one entry per edge.
    EdgeNameCount {
        ring: RingRef,
        edges: usize,
        names: usize,
    },
    /// Edge names were given for a ring the polygon does not have.
    EdgeNamesForMissingRing { rings: usize, names: usize },
    /// A circle's radius is not positive and finite, or its centre not finite.
    BadCircle { centre: [f64; 2], radius: f64 },
    /// A rectangle's size is not positive and finite, or its origin not finite.
    BadRectangle { origin: [f64; 2], size: [f64; 2] },
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use ShapeError::*;
        match self {
            TooFewVertices { ring, count } => {
                write!(
                    f,
                    "{ring} has {count} distinct vertices; a polygon needs at least 3"
                )
            }
            NonFinite { ring, vertex } => {
                write!(
                    f,
                    "{ring}: vertex {vertex} has a coordinate that is not a finite number"
                )
            }
            RepeatedVertex { ring, vertex } => write!(
                f,
                "{ring}: vertex {vertex} equals the next vertex (a zero-length edge)"
            ),
            ZeroArea { ring } => write!(f, "{ring} has zero area (all its vertices are collinear)"),
            SelfIntersection { ring, edges } => write!(
                f,
                "{ring} intersects itself: edges {} and {} meet",
                edges[0], edges[1]
            ),
            HoleCrossesOuter {
                hole,
                hole_edge,
                outer_edge,
            } => write!(
                f,
                "hole {hole} meets the outer boundary: its edge {hole_edge} and outer edge \
                 {outer_edge}"
            ),
            HoleOutside { hole } => write!(f, "hole {hole} lies outside the outer boundary"),
            HolesOverlap { holes } => {
                write!(f, "holes {} and {} overlap or touch", holes[0], holes[1])
            }
            EdgeNameCount { ring, edges, names } => write!(
                f,
                "{ring} has {edges} edges but {names} edge names (one per edge, none to leave \
                 an edge unnamed)"
            ),
            EdgeNamesForMissingRing { rings, names } => write!(
                f,
                "edge names given for {names} rings but the polygon has {rings}"
            ),
            BadCircle { centre, radius } => write!(
                f,
                "circle at {centre:?} with radius {radius}: the radius must be positive and \
                 finite, the centre finite"
            ),
            BadRectangle { origin, size } => write!(
                f,
                "rectangle at {origin:?} of size {size:?}: the size must be positive and \
                 finite, the origin finite"
            ),
        }
    }
}

impl std::error::Error for ShapeError {}

/// Two zones whose interiors intersect (0-based indices into the zone list, `zones[0] <
/// zones[1]`). Zones may touch along edges or at vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ZonesOverlap {
    pub zones: [usize; 2],
}

impl fmt::Display for ZonesOverlap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "zones {} and {} overlap", self.zones[0], self.zones[1])
    }
}

impl std::error::Error for ZonesOverlap {}

/// A fill that was refused before any point was made.
#[derive(Debug, Clone, PartialEq)]
pub enum FillError {
    /// The spacing is not positive and finite.
    BadSpacing {
        h: f64,
    },
    /// The lattice anchor is not finite.
    BadAnchor {
        anchor: [f64; 2],
    },
    /// The zones' lattice would have more candidate points than the limit.
    TooManyPoints {
        count: f64,
        limit: usize,
    },
    Overlap(ZonesOverlap),
}

impl fmt::Display for FillError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FillError::BadSpacing { h } => {
                write!(f, "particle spacing {h} must be positive and finite")
            }
            FillError::BadAnchor { anchor } => {
                write!(f, "lattice anchor {anchor:?} must be finite")
            }
            FillError::TooManyPoints { count, limit } => write!(
                f,
                "the zones at this spacing span about {count:.3e} lattice points, more than \
                 {limit}"
            ),
            FillError::Overlap(o) => o.fmt(f),
        }
    }
}

impl std::error::Error for FillError {}

impl From<ZonesOverlap> for FillError {
    fn from(o: ZonesOverlap) -> Self {
        FillError::Overlap(o)
    }
}
