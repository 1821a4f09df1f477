//! Safe PETSc layer: RAII wrappers whose `Drop` destroys the PETSc object, every error code turned
//! into a `Result`. `unsafe` in this crate lives only here and in `ffi`.

pub mod error;
pub mod ffi;
pub mod init;
pub mod matrix;
pub mod scatter;
pub mod snes;
pub mod vector;

pub use error::PetscError;
pub use init::Petsc;
pub use matrix::Mat;
pub use scatter::Scatter;
pub use snes::{NonlinearProblem, Snes, SolveStats};
pub use vector::{PVec, VecRef};
