//! Geometry of the body: the shapes a soil zone can take, their validation, the particle
//! cloud that fills them, Gmsh import, and named boundaries for selections (issue 27, items 3
//! and 4). Pure geometry: no MPI, no scene types; the scene layer maps its tables onto these.
//!
//! - [`Polygon`] (simple, with holes, either orientation, optional edge names), [`Circle`],
//!   [`Rectangle`], behind [`Shape`]: `locate`/`contains` (closed: boundary points are
//!   contained; exact for polygons), `signed_distance` (negative inside), `area`, `bbox`,
//!   `boundary` (named segments, interior on the left). Containment costs O(1) through a grid
//!   over the edges (crowded cells get finer grids), distance O(log n) through a bounding-volume
//!   hierarchy, both built once per polygon.
//! - [`ShapeError`] for a polygon that is not simple (with the ring and edges), and
//!   [`validate_zones`]/[`overlap`] for zones whose interiors intersect (touching is allowed).
//! - [`fill_zones`]: boundary particles at spacing about h on every edge, a global lattice
//!   clipped to each zone, lattice points within [`DROP_FACTOR`] h of a boundary dropped; each
//!   point once (shared boundaries go to the lowest zone index), sorted by y then x;
//!   [`fill_zones_graded`] with finer spacing in [`FineRegion`]s of any shape.
//! - [`read_msh`]: MSH 4.1 (ASCII or binary) nodes, elements and local mesh size per physical
//!   surface, segments per physical curve; [`GmshError`] names the file.
//! - [`NamedBoundaries`]: zone edge names and physical curves by name, to select points.
//!
//! Exact predicates (`robust::orient2d`) decide every orientation and intersection, so zones
//! that touch must share coordinates exactly along the shared part (always true for shared
//! vertices).

mod bvh;
mod error;
mod fill;
mod fill_boundary;
#[cfg(test)]
#[path = "tests/fill.rs"]
mod fill_tests;
mod gmsh;
mod gmsh_header;
mod gmsh_import;
#[cfg(test)]
#[path = "tests/gmsh.rs"]
mod gmsh_tests;
mod index;
mod locate;
mod overlap;
mod polygon;
mod segment;
mod select;
mod shape;
mod validate;

pub use error::{FillError, RingRef, ShapeError, ZonesOverlap};
pub use fill::{
    fill_shape, fill_zones, fill_zones_graded, FillParams, FilledPoint, FineRegion,
    DEFAULT_MAX_POINTS, DROP_FACTOR,
};
pub use fill_boundary::SNAP;
pub use gmsh::{
    parse_msh, read_msh, GmshError, GmshErrorKind, GmshMesh, GmshNode, PhysicalCurve,
    PhysicalSurface,
};
pub use locate::Location;
pub use overlap::{overlap, validate_zones};
pub use polygon::{Polygon, Segment};
pub use segment::{distance as distance_to_segment, Point};
pub use select::{gmsh_segments, zone_segments, NamedBoundaries, UnknownBoundary};
pub use shape::{Circle, Rectangle, Shape};
