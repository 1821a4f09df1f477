mod error;
mod fill;
#[cfg(test)]
mod fill_tests;
mod gmsh;
mod gmsh_header;
#[cfg(test)]
mod gmsh_tests;
mod index;
mod overlap;
mod polygon;
mod segment;
mod shape;
mod validate;

pub use error::{FillError, RingRef, ShapeError, ZonesOverlap};
pub use fill::{fill_shape, fill_zones, FillParams, FilledPoint, DEFAULT_MAX_POINTS, DROP_FACTOR};
pub use gmsh::{
    parse_msh, read_msh, GmshError, GmshErrorKind, GmshMesh, GmshNode, PhysicalCurve, PhysicalSurface,
};
pub use index::Location;
pub use overlap::{overlap, validate_zones};
pub use polygon::{Polygon, Segment};
pub use segment::Point;
pub use shape::{Circle, Rectangle, Shape};
