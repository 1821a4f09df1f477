//! What every PETSc object has: a type name, a communicator and a reference count.

use super::error::{check, PetscError};
use super::ffi;

/// A live PETSc object of ours or borrowed. Sealed: only this binding's handles are objects.
pub trait Object: private::Sealed {
    /// The raw handle.
    #[doc(hidden)]
    fn object(&self) -> ffi::PetscObject;

    /// Whether the object has the type `name` (`PetscObjectTypeCompare`).
    fn has_type(&self, name: &str) -> Result<bool, PetscError> {
        // SAFETY: the handle is live (every implementor is).
        unsafe { super::has_type(self.object(), name) }
    }
}

pub(super) mod private {
    pub trait Sealed {}
}

/// The communicator of `object` (PETSc's own, on which to make objects that work with it).
pub(super) fn comm_of(object: &impl Object) -> Result<ffi::MPI_Comm, PetscError> {
    // SAFETY: rsmpi's null communicator is a constant it defines; the handle is live and
    // PETSc writes its communicator.
    let mut comm = unsafe { mpi::ffi::RSMPI_COMM_NULL };
    check(
        unsafe { ffi::PetscObjectGetComm(object.object(), &mut comm) },
        "PetscObjectGetComm",
    )?;
    Ok(comm)
}

/// Takes one more reference to `object`, for a new owner of it.
pub(super) fn reference(object: &impl Object) -> Result<(), PetscError> {
    // SAFETY: the handle is live.
    check(
        unsafe { ffi::PetscObjectReference(object.object()) },
        "PetscObjectReference",
    )
}

/// Implements [`Object`] for a handle type whose raw handle is the field `raw`.
macro_rules! object {
    ($($t:ty),*) => {$(
        impl super::object::private::Sealed for $t {}
        impl super::object::Object for $t {
            fn object(&self) -> super::ffi::PetscObject {
                self.raw as super::ffi::PetscObject
            }
        }
    )*};
}
pub(super) use object;

object!(
    super::matrix::Mat,
    super::matrix::MatRef<'_>,
    super::vector::PVec,
    super::vector::VecRef<'_>,
    super::index_set::IndexSet
);
