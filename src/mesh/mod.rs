//! Meshing of the particle cloud: exact predicates, Delaunay, alpha shape and its notch rules, the
//! rank-local mesh, refinement and the rank-count independent fingerprint.

pub mod adapt;
pub mod alpha;
pub mod curved;
pub mod delaunay;
pub mod fingerprint;
pub mod local;
pub mod near_ties;
pub mod notches;
pub mod predicates;
pub mod refine;

pub use local::LocalMesh;
