//! Safe PETSc layer: RAII wrappers whose `Drop` destroys the PETSc object, every error code turned
//! into a `Result`. `unsafe` in this crate lives only here and in `ffi`.

pub mod error;
pub mod ffi;
pub mod index_set;
pub mod init;
pub mod ksp;
pub mod matrix;
pub mod nullspace;
pub mod object;
pub mod options;
pub mod pc;
pub mod pc_shell;
pub mod reason;
pub mod scatter;
pub mod shell;
pub mod snes;
pub mod vector;
pub mod viewer;

/// PETSc's integer as the bindings define it (32 or 64 bits by build): every index and count
/// handed to PETSc has this type, converted with a check ([`matrix::to_int`]).
pub type Int = ffi::PetscInt;
/// PETSc's scalar as the bindings define it. The physics computes in f64, so a PETSc built
/// with another scalar (single precision, complex) fails to compile here instead of
/// reinterpreting memory.
pub type Scalar = ffi::PetscScalar;
const _: () = assert!(std::mem::size_of::<Scalar>() == std::mem::size_of::<f64>());

/// Whether the PETSc object `object` (a KSP, PC, line search, ...) has the type `name`
/// (`PetscObjectTypeCompare`).
///
/// # Safety
/// `object` must be a live PETSc object.
unsafe fn has_type(object: ffi::PetscObject, name: &str) -> Result<bool, PetscError> {
    let name = init::cstring(name)?;
    let mut same = ffi::PetscBool_PETSC_FALSE;
    // SAFETY: as the caller promises; the name outlives the call.
    error::check(
        unsafe { ffi::PetscObjectTypeCompare(object, name.as_ptr(), &mut same) },
        "PetscObjectTypeCompare",
    )?;
    Ok(same == ffi::PetscBool_PETSC_TRUE)
}

pub use error::PetscError;
pub use index_set::IndexSet;
pub use init::Petsc;
pub use ksp::{Ksp, KspRef};
pub use matrix::{Mat, MatRef};
pub use nullspace::NullSpace;
pub use object::Object;
pub use pc::{Pc, PcRef};
pub use pc_shell::ShellPreconditioner;
pub use reason::{Divergence, KspDiverged, SnesDiverged, SolveFailure};
pub use scatter::{IndexScatter, Scatter};
pub use shell::LinearOperator;
pub use snes::{LineSearchRef, NonlinearProblem, Snes, SnesRef, SolveStats};
pub use vector::{PVec, VecRef};
pub use viewer::ViewerRef;
