//! Safe PETSc layer: RAII wrappers whose `Drop` destroys the PETSc object, every error code turned
//! into a `Result`. `unsafe` in this crate lives only here and in `ffi`.

pub mod error;
pub mod ffi;
pub mod index_set;
pub mod init;
pub mod linear;
pub mod matrix;
pub mod nullspace;
pub mod reason;
pub mod scatter;
pub mod shell;
pub mod snes;
mod two_level;
pub mod vector;
mod yield_zone;

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

/// The context of `pc` if it is a PCSHELL named `name` (our shells tell themselves apart by
/// name: a context of one read as another's would be undefined behaviour).
///
/// # Safety
/// `pc` must be a live PC.
unsafe fn shell_context(
    pc: ffi::PC,
    name: &str,
) -> Result<Option<*mut std::ffi::c_void>, PetscError> {
    // SAFETY: as the caller promises; the name PETSc returns lives as long as the PC.
    unsafe {
        if !has_type(pc as ffi::PetscObject, "shell")? {
            return Ok(None);
        }
        let mut given: *const std::os::raw::c_char = std::ptr::null();
        error::check(ffi::PCShellGetName(pc, &mut given), "PCShellGetName")?;
        if given.is_null() || std::ffi::CStr::from_ptr(given).to_bytes() != name.as_bytes() {
            return Ok(None);
        }
        let mut raw: *mut std::ffi::c_void = std::ptr::null_mut();
        error::check(
            ffi::PCShellGetContext(
                pc,
                &mut raw as *mut *mut std::ffi::c_void as *mut std::ffi::c_void,
            ),
            "PCShellGetContext",
        )?;
        Ok((!raw.is_null()).then_some(raw))
    }
}

pub use error::PetscError;
pub use index_set::IndexSet;
pub use init::Petsc;
pub use linear::{FactorReuse, LinearSolver};
pub use matrix::{Mat, MatRef};
pub use nullspace::NullSpace;
pub use reason::{Divergence, KspDiverged, SnesDiverged, SolveFailure};
pub use scatter::Scatter;
pub use shell::LinearOperator;
pub use snes::{NonlinearProblem, Snes, SolveStats};
pub use vector::{PVec, VecRef};
