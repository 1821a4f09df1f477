//! One implicit load step on the distributed mesh: dof numbering, constraints and the Newton
//! problem handed to PETSc's SNES.

pub mod constraints;
pub mod dofs;
pub mod interpolation;
pub mod linear_path;
pub mod material_pressures;
pub mod nullspace;
pub mod pmg;
pub mod precond;
pub mod problem;
pub mod smoother;
pub mod split;

pub use constraints::Constraints;
pub use dofs::DofMap;
pub use material_pressures::Pressure;
pub use problem::{CoarseOperator, Kernel, Law, SchurPreconditioner, StepProblem, StepSetup};
pub use split::FieldLayout;
