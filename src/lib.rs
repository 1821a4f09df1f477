//! pfem-mpi: an MPI-parallel Particle Finite Element Method for large-deformation geomechanics.
//!
//! The method (Fig. 1 of the seed paper): particles carry the body; each step meshes them
//! (Delaunay + alpha shape), maps the state onto the new mesh, solves one implicit
//! updated-Lagrangian increment with Newton, and moves the particles. See `run::run`.

pub mod case_file;
pub mod cli;
pub mod commands;
pub mod fem;
pub mod geometry;
pub mod heap;
pub mod history;
pub mod mapping;
pub mod material;
pub mod mesh;
pub mod model;
pub mod output;
pub mod particles;
pub mod petsc;
pub mod plot;
pub mod rigid;
pub mod rng;
pub mod run;
pub mod scene;
pub mod solve;
