use super::error::{check, PetscError};
use super::ffi;
use super::matrix::to_int;
use super::nullspace::NullSpace;
use super::Int;
use mpi::raw::AsRaw;
use mpi::topology::SimpleCommunicator;

/// A distributed list of global indices (a field of a block system); destroyed on drop.
pub struct IndexSet {
    pub(crate) raw: ffi::IS,
}

impl IndexSet {
    /// Collective. This rank's `indices` (copied), grouped in blocks of `block` consecutive
    /// indices (2: the two displacement components of a node).
    pub fn general(
        comm: &SimpleCommunicator,
        indices: &[Int],
        block: usize,
    ) -> Result<IndexSet, PetscError> {
        let is = IndexSet::create(comm.as_raw(), indices)?;
        // SAFETY: a live index set of ours.
        check(
            unsafe { ffi::ISSetBlockSize(is.raw, to_int(block, "block size")?) },
            "ISSetBlockSize",
        )?;
        Ok(is)
    }

    /// Collective. This rank's `indices` (copied), on the communicator of `like`.
    pub fn general_like(
        like: &impl super::object::Object,
        indices: &[Int],
    ) -> Result<IndexSet, PetscError> {
        IndexSet::create(super::object::comm_of(like)?, indices)
    }

    /// Collective on `comm`. This rank's `indices`, copied.
    fn create(comm: ffi::MPI_Comm, indices: &[Int]) -> Result<IndexSet, PetscError> {
        let mut raw: ffi::IS = std::ptr::null_mut();
        // SAFETY: the index array is valid for its length and copied (PETSC_COPY_VALUES); the
        // handle is owned by the returned value.
        check(
            unsafe {
                ffi::ISCreateGeneral(
                    comm,
                    to_int(indices.len(), "index set")?,
                    indices.as_ptr(),
                    ffi::PetscCopyMode_PETSC_COPY_VALUES,
                    &mut raw,
                )
            },
            "ISCreateGeneral",
        )?;
        Ok(IndexSet { raw })
    }

    /// A reference of our own to this index set.
    pub fn shared(&self) -> Result<IndexSet, PetscError> {
        // SAFETY: live index set.
        check(
            unsafe { ffi::PetscObjectReference(self.raw as ffi::PetscObject) },
            "PetscObjectReference",
        )?;
        Ok(IndexSet { raw: self.raw })
    }

    /// Collective. Indices over all ranks.
    pub fn global_size(&self) -> Result<Int, PetscError> {
        let mut n: Int = 0;
        // SAFETY: live index set.
        check(unsafe { ffi::ISGetSize(self.raw, &mut n) }, "ISGetSize")?;
        Ok(n)
    }

    /// Attaches the near-null space PCFIELDSPLIT hands to this field's diagonal block (it
    /// queries the index set for "nearnullspace" when it extracts the block).
    pub fn compose_near_null_space(&self, space: &NullSpace) -> Result<(), PetscError> {
        let key = super::init::cstring("nearnullspace")?;
        // SAFETY: both handles are live; PETSc takes its own reference to the null space.
        check(
            unsafe {
                ffi::PetscObjectCompose(
                    self.raw as ffi::PetscObject,
                    key.as_ptr(),
                    space.raw as ffi::PetscObject,
                )
            },
            "PetscObjectCompose(nearnullspace)",
        )
    }
}

impl Drop for IndexSet {
    fn drop(&mut self) {
        // SAFETY: we own the handle.
        unsafe {
            ffi::ISDestroy(&mut self.raw);
        }
    }
}
