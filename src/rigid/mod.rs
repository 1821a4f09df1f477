//! Rigid bodies pushed into the soil: convex shapes, their staged motion, and the penalty
//! contact with augmentation between them and the soil's boundary nodes. Pure numerics: no MPI,
//! no PETSc.

pub mod body;
pub mod contact;
pub mod shape;

pub use body::RigidBody;
pub use contact::{pair_force, ContactPair, PairForce};
pub use shape::{Proximity, Shape};
