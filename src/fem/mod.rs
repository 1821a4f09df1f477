//! Finite-element kernel: quadrature, P2 shape functions, the updated-Lagrangian element and
//! Gauss-point recovery. Pure numerics: no MPI, no PETSc.

pub mod analysis;
pub mod element;
pub mod mixed;
pub mod p1;
pub mod p2;
pub mod quadrature;
pub mod recovery;
pub mod surface_load;
